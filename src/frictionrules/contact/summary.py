"""Fig. 10 of §4 computed with the default cap, and its key numbers for ``frictionrules paper``."""

from __future__ import annotations

import functools

import numpy as np

#: Parameters of the Fig. 10 reproduction: m, stiffnesses, initial β, the two normal forces
#: (below and above A0 = A(0, β0) = 1) and the imposed slip.
FIG10 = {"m": 0.6, "kn": 100.0, "kt": 100.0, "beta": 0.5, "N": (0.4, 1.6), "slip": 0.8, "steps": 400}


def fig10_model():
    """The ContactModel of Fig. 10: the default :class:`EllipsoidCap` with ``m = 0.6``."""
    from ..laws import EllipsoidCap
    from .model import ContactModel
    return ContactModel(EllipsoidCap(FIG10["m"]), FIG10["kn"], FIG10["kt"])


@functools.lru_cache(maxsize=1)
def fig10c_results() -> dict:
    """Shear at fixed N (points A and B of Fig. 10a): ``{N: DriveResult}``."""
    from .driver import drive
    model = fig10_model()
    out = {}
    for N in FIG10["N"]:
        out[N] = drive(model, [{"N": N, "dt1": 0.0, "T2": 0.0, "steps": 10},
                               {"dt1": FIG10["slip"], "steps": FIG10["steps"]}], beta=FIG10["beta"])
    return out


def key_numbers() -> list[tuple[str, str, str]]:
    """Peaks and asymptotes of the T–δ curves of Fig. 10c (default cap, m = 0.6)."""
    m = FIG10["m"]
    rows = []
    for N, r in fig10c_results().items():
        T = r.force[:, 0]
        k = int(np.argmax(T))
        rows.append((f"cap, N = {N}: peak T (at δt1)", f"{T[k]:.4f} ({r.displacement[k, 0]:.4f})", "Fig. 10c"))
        rows.append((f"cap, N = {N}: final T/N (asymptote m = {m})", f"{T[-1] / N:.4f}", "Fig. 10c, (4.9)"))
        rows.append((f"cap, N = {N}: final β (β0 = {FIG10['beta']})", f"{r.beta[-1]:.4f}", "(4.5)"))
    return rows
