"""A sphere in a pocket of a close-packed layer, pushed in any direction (beyond §3).

Pushed towards a layer sphere it climbs over that one; pushed between two it rides the ridge
between them (over two at once), which needs much less force. The polar plot of the peak force
is drawn with ``frictionrules.plot.pocket_peak_force``. Along a straight path beside the top of
the sphere it climbs, the limit curve translates, shrinks and rotates (Fig. 9).

Run: ``python examples/configuration_sphere_pocket.py`` (prints the results and saves the
figure in the current folder).
"""

from pathlib import Path

import numpy as np

from frictionrules import SphereOnLayer


def main(mu: float = 0.3, out_dir=None) -> dict:
    """Print the peaks and the path; with ``out_dir``, save the polar plot there."""
    sph = SphereOnLayer(diameter=1.0, mu=mu, packing="hexagonal")
    directions = np.radians(np.arange(0, 360, 30))
    bo = sph.breakout_force(directions)
    for th, t, c in zip(directions, bo.peak, bo.count):
        print(f"force at {np.degrees(th):5.0f} deg: peak |T| = {t:.4f} Q, over {c} sphere(s)")
    res = sph.displacement_path(sph.straight_path(np.radians(30), 0.5, 101))
    print(f"straight path at 30 deg: psi turns from {np.degrees(res.psi[0]):.0f} to "
          f"{np.degrees(res.psi[-1]):.0f} deg, |T| from {res.force_magnitude[0]:.4f} to "
          f"{res.force_magnitude[-1]:.4f} Q, dilatancy {res.height[-1] - res.height[0]:.4f} d")
    if out_dir is not None:
        import matplotlib.pyplot as plt

        from frictionrules.plot import pocket_peak_force
        ax = pocket_peak_force(mu=mu, n=181)
        path = Path(out_dir) / "configuration_sphere_pocket.png"
        ax.figure.savefig(path, dpi=110, bbox_inches="tight")
        plt.close(ax.figure)
        print(f"wrote {path}")
    return {"ridge_peak": float(bo.peak[2]), "over_one_peak": float(bo.peak[0])}


if __name__ == "__main__":
    main(out_dir=".")
