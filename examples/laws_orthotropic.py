"""Compare the three orthotropic rules of §1 for one surface (mu_x = 0.6, mu_y = 0.3).

For slip directions around the circle: the directional coefficient mu(theta) of the elliptic
law (1.15), Huber's (1.16) and the transformed law (1.17); the angle between force and slip
(1.14); and how far each rule is from normality in the sliding plane.

Run: ``python examples/laws_orthotropic.py`` (prints the results and saves the figure
in the current folder).
"""

from pathlib import Path

import numpy as np

import frictionrules as fr


def main(out_dir=None) -> dict:
    """Print the table; with ``out_dir``, save the figure there. Returns the largest angle
    between slip and the normal of f per law (degrees)."""
    laws = [fr.EllipticOrthotropic(0.6, 0.3), fr.Huber(0.6, 0.3), fr.TransformedCoulomb(0.6, 0.3)]
    theta = np.deg2rad(np.arange(0, 91, 15))
    print(f"{'theta':>6} " + " ".join(f"{type(law).__name__:>20}" for law in laws))
    for t, row in zip(np.rad2deg(theta), np.array([law.friction_coefficient(theta) for law in laws]).T):
        print(f"{t:6.0f} " + " ".join(f"{m:20.4f}" for m in row))
    deviation = {}
    for law in laws:
        T = law.force_for_slip(np.stack((np.cos(theta), np.sin(theta)), -1), 1.0)
        deviation[type(law).__name__] = float(np.rad2deg(np.max(
            fr.compare_rules(law, T, np.ones(theta.shape)).tangential_angle)))
    print("largest angle between slip and the normal of f (deg):", deviation)
    if out_dir is not None:
        import matplotlib
        matplotlib.use("Agg")
        from frictionrules import plot
        ax = plot.directional_friction(mu_x=0.6, mu_y=0.3)
        out = Path(out_dir) / "orthotropic.png"
        ax.figure.savefig(out, dpi=120, bbox_inches="tight")
        print(f"wrote {out}")
    return deviation


if __name__ == "__main__":
    main(out_dir=".")
