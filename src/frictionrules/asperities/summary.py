"""Key numbers of §2's two-flank asperity (Figs. 5 and 7) for ``frictionrules paper``."""

from __future__ import annotations

import numpy as np

from .twoflank import TwoFlankAsperity


def key_numbers() -> list[tuple[str, str, str]]:
    """Rows ``(quantity, value, reference)``: corners of Fig. 5, the ranges (2.13)/(2.17)."""
    rows = []
    law = TwoFlankAsperity(np.pi / 3, 5 * np.pi / 6, 1.0)
    curve = law.limit_curve(1.0, n=1440)
    for c in sorted(curve.concave_corners, key=lambda c: (c.T[0], c.T[1])):
        rows.append(("Fig. 5: concave corner (Tx, Ty)/Q, interior angle",
                     f"({c.T[0]:.4f}, {c.T[1]:.4f}), {np.rad2deg(c.interior):.2f} deg", "(2.9)/(2.12)"))
    lo, hi = law.pair_range()
    rows.append(("Fig. 5: both-flank range tan(phi)", f"({lo:.4f}, {hi:.4f})", "(2.13)"))
    mu_y = float(law.friction_coefficient(np.pi / 2))
    rows.append(("Fig. 5: mu(theta) along the grooves", f"{mu_y:.4f}", "(2.12)"))
    assoc = TwoFlankAsperity(np.pi / 3, 5 * np.pi / 6, 0.5, local="associated")
    non = TwoFlankAsperity(np.pi / 3, 5 * np.pi / 6, 0.5)
    lo, hi = assoc.pair_range()
    rows.append(("Fig. 7 (mu = 0.5): associated both-flank range tan(phi')", f"({lo:.4f}, {hi:.4f})",
                 "(2.17) corrected"))
    ty = [float(x.limit_load([0.0, 1.0]).load) for x in (non, assoc)]
    rows.append(("Fig. 7 (mu = 0.5): limit Ty/Q at Tx = 0, non-assoc. / assoc.",
                 f"{ty[0]:.4f} / {ty[1]:.4f}", "(2.12) / (2.16) corrected"))
    concave = len(non.limit_curve(1.0, 720).concave_corners)
    convex = len(assoc.limit_curve(1.0, 720).concave_corners)
    rows.append(("Fig. 7 (mu = 0.5): concave corners, non-assoc. / assoc.", f"{concave} / {convex}", "Fig. 7"))
    return rows
