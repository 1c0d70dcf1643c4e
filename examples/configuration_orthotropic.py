"""A sphere in a square pocket whose contacts are orthotropic (§3 with the laws of §1).

Each grain contact carries ``EllipticOrthotropic(mu_x, mu_y)`` in its own frame: ``t1`` the
unit projection of the x axis onto the plane tangent to both grains, ``t2 = n x t1`` (the
frame of ``docs/conventions.md``), so axis 1 of every contact's lay is the direction of x
seen on the contact plane. At rest the grain is a block on four facets: its break-out force in
each direction is the facet set's limit load. A force ramp reaches it (force control), and
displacement control follows the grain past it while the force falls (configuration
softening), exactly and by the rate relations (3.3)-(3.13).

Run: ``python examples/configuration_orthotropic.py``
"""

import numpy as np

from frictionrules import EllipticOrthotropic, SphereOnLayer


def main(mu_x: float = 0.2, mu_y: float = 0.4, Q: float = 1.0) -> dict:
    sph = SphereOnLayer(diameter=1.0, law=EllipticOrthotropic(mu_x, mu_y), packing="square")
    directions = np.radians(np.arange(0.0, 360.0, 30.0))
    bo = sph.breakout_force(directions, Q=Q)
    for th, t, over in zip(directions, bo.peak, bo.mechanism):
        print(f"force at {np.degrees(th):5.0f} deg: break-out |T| = {t / Q:.4f} Q, over {over}")

    beta = np.radians(50.0)
    ramp = Q * np.outer(np.linspace(0.0, 3.0, 61), [np.cos(beta), np.sin(beta)])
    lp = sph.force_path(ramp, Q=Q).limit_point
    print(f"force control at 50 deg: limit point |T| = {np.hypot(*lp.force) / Q:.4f} Q, "
          f"sliding on {lp.state.contacts}")

    V = lp.velocity                       # the mechanism: the grain climbs one layer sphere
    path = sph.straight_path(np.arctan2(V[1], V[0]), 0.4, 81)
    exact = sph.displacement_path(path, Q=Q)
    rate = sph.displacement_path(path, "incremental", "heun", Q=Q)
    error = np.abs(rate.force - exact.force).max() / Q
    print(f"displacement control along the mechanism: |T| from {exact.force_magnitude[0] / Q:.4f} Q "
          f"to {exact.force_magnitude[-1] / Q:.4f} Q, rate form (Heun) within {error:.1e} Q")
    return {"breakout": bo.peak / Q, "limit_point": np.hypot(*lp.force) / Q,
            "start": exact.force_magnitude[0] / Q, "end": exact.force_magnitude[-1] / Q,
            "rate_error": error}


if __name__ == "__main__":
    main()
