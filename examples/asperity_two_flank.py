"""The paper's two-flank asperity (Fig. 5): mechanisms, concave corners, non-associated rule;
then the same groove with machined (orthotropic) flanks.

Run: ``python examples/asperity_two_flank.py`` (prints the results and saves the
figure in the current folder).
"""

from pathlib import Path

import numpy as np

from frictionrules import EllipticOrthotropic, TwoFlankAsperity


def main(out_dir=None):
    """Print the mechanisms and corners; with ``out_dir``, save Fig. 5 there."""
    law = TwoFlankAsperity(alpha1=np.pi / 3, alpha2=5 * np.pi / 6, mu=1.0)
    for deg in (0.0, 60.0, 90.0, 150.0, 180.0):
        d = np.array([np.cos(np.deg2rad(deg)), np.sin(np.deg2rad(deg))])
        r = law.limit_load(d, Q=1.0)
        print(f"load direction {deg:5.1f} deg: |T|/Q = {r.load:8.4f}, sliding facets "
              f"{r.mechanism}, velocity {np.round(r.velocity, 4)}")
    curve = law.limit_curve(Q=1.0, n=1440)
    print("concave corners of the limit curve (Fig. 5):")
    for c in curve.concave_corners:
        print(f"  T/Q = ({c.T[0]:7.4f}, {c.T[1]:7.4f}), interior angle "
              f"{np.rad2deg(c.interior):7.2f} deg")
    fin = np.isfinite(curve.load)
    print(f"largest angle between global slip and limit-surface normal: "
          f"{np.rad2deg(curve.rule_angle[fin].max()):.1f} deg")
    mu_y = float(law.friction_coefficient(np.pi / 2))
    print(f"mu for sliding along the grooves: {mu_y:.4f}")
    # machined flanks: the local law in each flank's frame (docs/conventions.md), axis 1 (t1)
    # up the slope with mu_x = 1, axis 2 along the groove with half of it
    machined = TwoFlankAsperity(np.pi / 3, 5 * np.pi / 6, EllipticOrthotropic(1.0, 0.5))
    theta = np.deg2rad([0.0, 45.0, 90.0, 135.0, 180.0])
    print("machined flanks, mu(theta) at 0, 45, 90, 135, 180 deg:",
          np.round(machined.friction_coefficient(theta), 4))
    if out_dir is not None:
        import matplotlib.pyplot as plt

        from frictionrules.plot import fig5_two_flank
        ax = fig5_two_flank()
        path = Path(out_dir) / "asperity_two_flank.png"
        ax.figure.savefig(path, dpi=110, bbox_inches="tight")
        plt.close(ax.figure)
        print(f"wrote {path}")
    return mu_y


if __name__ == "__main__":
    main(out_dir=".")
