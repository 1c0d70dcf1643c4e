"""Batched update of a million-ish contacts, as a host code (FEM/DEM) would call it.

Every contact is pressed and then sheared in a random direction; one call of
``model.update`` integrates all of them (compiled kernel) and returns the new state, the
forces and the consistent tangents.

Run: ``python examples/contact_batched_update.py`` (prints the results and saves the
figure in the current folder).
"""

import time

from pathlib import Path

import numpy as np

from frictionrules import ContactModel, EllipticOrthotropic


def main(n: int = 200_000, out_dir=None) -> dict:
    """Print the time and the range of |T|/N; with ``out_dir``, save the forces there."""
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
    if out_dir is not None:
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(5.0, 5.0))
        shown = slice(0, min(n, 4000))
        ax.plot(res.force[shown, 0], res.force[shown, 1], "C0.", ms=2)
        ax.set_aspect("equal")
        ax.set_xlabel("tangential force $T_1$ ($N$ = 1)")
        ax.set_ylabel("tangential force $T_2$ ($N$ = 1)")
        ax.set_title(f"forces of {shown.stop} of the {n} contacts after one update:\n"
                     r"the limit ellipse, $\mu_x$ = 0.3 along $T_1$, $\mu_y$ = 0.6 along $T_2$",
                     fontsize=9)
        path = Path(out_dir) / "contact_batched_update.png"
        fig.savefig(path, dpi=110, bbox_inches="tight")
        plt.close(fig)
        print(f"wrote {path}")
    return {"plastic": plastic, "mu_min": float(mu_eff.min()), "mu_max": float(mu_eff.max())}


if __name__ == "__main__":
    main(out_dir=".")
