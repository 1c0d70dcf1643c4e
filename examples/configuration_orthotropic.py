"""A sphere in a square pocket whose contacts are orthotropic (§3 with the laws of §1).

Each grain contact carries ``EllipticOrthotropic(mu_x, mu_y)`` in its own frame: ``t1`` the
unit projection of the x axis onto the plane tangent to both grains, ``t2 = n x t1`` (the
frame of ``docs/conventions.md``), so axis 1 of every contact's lay is the direction of x
seen on the contact plane. At rest the grain is a block on four facets: its break-out force in
each direction is the facet set's limit load. A force ramp reaches it (force control), and
displacement control follows the grain past it while the force falls (configuration
softening), exactly and by the rate relations (3.3)-(3.13).

Run: ``python examples/configuration_orthotropic.py`` (prints the results and saves the
figure in the current folder).
"""

from pathlib import Path

import numpy as np

from frictionrules import EllipticOrthotropic, SphereOnLayer


def main(mu_x: float = 0.2, mu_y: float = 0.4, Q: float = 1.0, out_dir=None) -> dict:
    """Print the break-out forces, the limit point and the path; with ``out_dir``, save the
    figure there."""
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
    if out_dir is not None:
        import matplotlib.pyplot as plt
        fig = plt.figure(figsize=(10, 4.2))
        polar = fig.add_subplot(1, 2, 1, projection="polar")
        fine = np.linspace(0.0, 2 * np.pi, 145)
        polar.plot(fine, sph.breakout_force(fine, Q=Q).peak / Q, "k-")
        polar.plot(beta, np.hypot(*lp.force) / Q, "C3o", label="limit point of the force ramp")
        polar.set_rticks([1.0, 2.0])
        polar.set_rlabel_position(200.0)        # in the gap of the rounded corner
        polar.set_title("break-out force $|T|/Q$ against its direction", fontsize=9)
        polar.legend(loc="upper center", bbox_to_anchor=(0.5, -0.08), fontsize=8)
        a = fig.add_subplot(1, 2, 2)
        a.plot(exact.distance, exact.force_magnitude / Q, "k-", label="exact")
        a.plot(rate.distance, rate.force_magnitude / Q, "C0o", ms=2.5, mfc="none",
               label="rate form (3.3)–(3.13), Heun")
        a.set_xlabel("distance travelled $|u|/d$ along the mechanism")
        a.set_ylabel("force to keep sliding $|T|/Q$")
        a.set_title("configuration softening past the limit point", fontsize=9)
        a.legend(fontsize=8)
        fig.tight_layout()
        path = Path(out_dir) / "configuration_orthotropic.png"
        fig.savefig(path, dpi=110, bbox_inches="tight")
        plt.close(fig)
        print(f"wrote {path}")
    return {"breakout": bo.peak / Q, "limit_point": np.hypot(*lp.force) / Q,
            "start": exact.force_magnitude[0] / Q, "end": exact.force_magnitude[-1] / Q,
            "rate_error": error}


if __name__ == "__main__":
    main(out_dir=".")
