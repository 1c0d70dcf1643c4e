"""Key numbers of §3 for ``frictionrules paper``."""

from __future__ import annotations

import numpy as np


def key_numbers() -> list[tuple[str, str, str]]:
    """Rows ``(quantity, value, reference)``: cylinder forces at rest and on the top, the
    observed convergence order of the incremental rate form, the force-control limit point and
    the pocket peak forces (mu = 0.3, Q = 1, d = 1)."""
    from .cylinder import CylinderOnLayer
    from .sphere import SphereOnLayer

    mu = 0.3
    cyl = CylinderOnLayer(1.0, mu)
    ex = cyl.displacement_path(cyl.straight_path(0.0, 0.5, 3))
    hs, errs = [], []
    for n in (21, 41, 81):
        path = cyl.straight_path(0.0, 0.5, n)
        inc = cyl.displacement_path(path, "incremental")
        hs.append(0.5 / (n - 1))
        errs.append(np.abs(inc.force - cyl.displacement_path(path).force).max())
    order = np.polyfit(np.log(hs), np.log(errs), 1)[0]
    ramp = np.stack((np.linspace(0.0, 2.0, 201), np.zeros(201)), axis=-1)
    lp = cyl.force_path(ramp).limit_point
    rows = [
        ("cylinder, mu = 0.3: T/Q at rest (alpha = 30 deg)", f"{ex.force[0, 0]:.4f}",
         "Fig. 8: Q tan(pi/6 + rho) = 1.0611"),
        ("cylinder, mu = 0.3: T/Q on top of the neighbour", f"{ex.force[-1, 0]:.4f}",
         "§3: mu Q = 0.3"),
        ("cylinder, mu = 0.3: incremental (Euler) convergence order", f"{order:.2f}",
         "(3.6)-(3.10): 1"),
        ("cylinder, mu = 0.3: force control, limit point T/Q", f"{lp.force[0]:.4f}",
         "(3.7): softening from rest"),
    ]
    for packing in ("square", "hexagonal"):
        sph = SphereOnLayer(1.0, mu, packing=packing)
        bo = sph.breakout_force(np.linspace(0.0, 2 * np.pi, 73))
        for which, i in (("least", int(np.argmin(bo.peak))), ("largest", int(np.argmax(bo.peak)))):
            rows.append((f"{packing} pocket: {which} break-out |T|/Q over the force direction "
                         f"({climbing(bo.count[i])})",
                         f"{bo.peak[i]:.4f} at {np.degrees(bo.direction[i]):.0f} deg",
                         "beyond the paper"))
    return rows


def climbing(count: int) -> str:
    """What the break-out mechanism does: ``"climbing over 2 layer spheres"`` (riding the
    ridge between two) or ``"climbing over 1 layer sphere"``."""
    return f"climbing over {count} layer sphere{'' if count == 1 else 's'}"
