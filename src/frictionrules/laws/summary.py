"""Key numbers of §1–2 for ``frictionrules paper``."""

from __future__ import annotations

import numpy as np

from .base import compare_rules
from .coulomb import Coulomb
from .orthotropic import EllipticOrthotropic, Huber, TransformedCoulomb
from .wedge import WedgeAsperity


def key_numbers() -> list[tuple[str, str, str]]:
    """Rows ``(quantity, value, equation)``."""
    rows = []
    c = Coulomb(0.3)
    rows.append(("Coulomb mu=0.3: D for unit slip, N=1", f"{float(c.dissipation([1.0, 0.0], 1.0)):.4f}", "(1.7)"))
    rows.append(("Coulomb mu=0.3 dilatant: D for unit slip, N=1",
                 f"{float(Coulomb(0.3, True).dissipation([1.0, 0.0], 1.0)):.4f}", "(1.6)"))
    theta = np.pi / 4
    for law, eq in ((EllipticOrthotropic(0.6, 0.3), "(1.15)"), (Huber(0.6, 0.3), "(1.16)"),
                    (TransformedCoulomb(0.6, 0.3), "(1.17)")):
        rows.append((f"{type(law).__name__} 0.6/0.3: mu(45 deg)",
                     f"{float(law.friction_coefficient(theta)):.4f}", eq))
    e = EllipticOrthotropic(0.6, 0.3)
    rows.append(("EllipticOrthotropic 0.6/0.3: force angle for slip at 45 deg",
                 f"{np.rad2deg(float(e.force_angle(theta))):.2f} deg", "(1.14)"))
    for alpha, mu in ((np.pi / 6, 0.5), (np.pi / 2 - np.arctan(0.5), 0.5), (np.pi / 3, 1.0)):
        w = WedgeAsperity(alpha, mu)
        tag = f"wedge alpha={np.rad2deg(alpha):.1f} deg, mu={mu:g}"
        rows.append((f"{tag}: limit curve", w.conic(), "(2.2)"))
        mu_up = float(w.friction_coefficient(0.0))
        rows.append((f"{tag}: Tx/Q pushing up-slope", f"{mu_up:.4f}" if np.isfinite(mu_up) else "locked",
                     "tan(alpha+rho)"))
        T = w.limit_point(2.0, 1.0)
        cmp = compare_rules(w, T, 1.0)
        rows.append((f"{tag}: sliding-plane angle, associated vs actual slip at phi=2.0",
                     f"{np.rad2deg(float(cmp.tangential_angle)):.2f} deg", "(2.4) vs (2.5)"))
        rows.append((f"{tag}: dilatancy angle at phi=2.0",
                     f"{np.rad2deg(float(w.dilatancy_angle(T, 1.0))):.2f} deg", "(2.8)"))
    return rows
