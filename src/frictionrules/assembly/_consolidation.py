"""The consolidation of a loading test, one rule for both methods."""

from __future__ import annotations

import numpy as np

from ..errors import FrictionRulesError, check_scalar

__all__ = ["CONSOLIDATIONS", "consolidation_of", "check_preload", "PRELOAD"]


#: The consolidations of a loading test.
CONSOLIDATIONS = ("auto", "stress", "frictionless")
#: The default preload of a frictionless consolidation, a multiple of the pressure.
PRELOAD = 10.0


def consolidation_of(assembly, consolidation: str) -> str:
    """The consolidation of a loading test, checked: "auto" is "frictionless" for grains of
    unequal radii in a rectangular cell (random packings), "stress" otherwise (lattices)."""
    if consolidation not in CONSOLIDATIONS:
        raise FrictionRulesError(f"consolidation = {consolidation!r} violates: one of "
                                 f"{', '.join(CONSOLIDATIONS)}")
    if consolidation != "auto":
        return consolidation
    h = assembly.cell
    rectangular = np.array_equal(h, np.diag(np.diag(h)))
    return "frictionless" if rectangular and np.ptp(assembly.radii) > 0 else "stress"


def check_preload(preload, consolidation: str) -> float:
    """The preload of a frictionless consolidation (a multiple of the pressure, >= 1; 1: from
    below, no unloading) checked against the consolidation as :func:`consolidation_of`
    resolved it: a consolidation "stress" has no preload, and a value other than the default
    is refused rather than ignored."""
    value = check_scalar("preload", preload, lo=1.0)
    if consolidation != "frictionless" and value != PRELOAD:
        raise FrictionRulesError(f"preload = {value!r} violates: {PRELOAD!r} for consolidation = "
                                 f"{consolidation!r} (the preload is the frictionless "
                                 "consolidation's)")
    return value
