"""The consolidation of a loading test, one rule for both methods."""

from __future__ import annotations

import numpy as np

from ..errors import FrictionRulesError

__all__ = ["CONSOLIDATIONS", "consolidation_of"]


#: The consolidations of a loading test.
CONSOLIDATIONS = ("auto", "stress", "frictionless")


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
