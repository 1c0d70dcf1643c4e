"""Batched update of a million-ish contacts, as a host code (FEM/DEM) would call it.

Every contact is pressed and then sheared in a random direction; one call of
``model.update`` integrates all of them (compiled kernel) and returns the new state, the
forces and the consistent tangents. Run: ``python examples/contact_batched_update.py``.
"""

import time

import numpy as np

from frictionrules import ContactModel, EllipticOrthotropic


def main(n: int = 200_000) -> dict:
    model = ContactModel(EllipticOrthotropic(0.3, 0.6), kn=1e3, kt=5e2)
    rng = np.random.default_rng(0)
    state = model.update(model.initial_state((n,)), [0.0, 0.0, -1e-3]).state     # N = 1 everywhere
    theta = rng.uniform(0, 2 * np.pi, n)
    du = np.column_stack((2e-3 * np.cos(theta), 2e-3 * np.sin(theta), np.zeros(n)))
    t0 = time.perf_counter()
    res = model.update(state, du, tangent=True)
    dt = time.perf_counter() - t0
    plastic = float(np.mean(res.status == 1))
    mu_eff = np.hypot(res.force[:, 0], res.force[:, 1]) / res.force[:, 2]
    print(f"{n} contacts in {dt * 1e3:.1f} ms ({plastic:.0%} sliding); |T|/N in "
          f"[{mu_eff.min():.3f}, {mu_eff.max():.3f}] (mu_y, mu_x = 0.3, 0.6)")
    return {"plastic": plastic, "mu_min": float(mu_eff.min()), "mu_max": float(mu_eff.max())}


if __name__ == "__main__":
    main()
