"""Asperity mechanisms (§2): global laws of a rigid block on facets with local Coulomb friction.

:class:`FacetSet` (any facets), :class:`TwoFlankAsperity` (the paper's Fig. 4 model with its
closed forms), :func:`from_profile` / :func:`from_heightmap` (facets of real surfaces) and
:func:`fit` (calibration of any law to measured mu(theta)).
"""

from .facets import Corner, FacetSet, LimitCurve, LimitLoad, LimitLoads
from .calibration import FitResult, compare_fits, fit, format_fits
from .surfaces import from_heightmap, from_profile
from .twoflank import TwoFlankAsperity

__all__ = [
    "FacetSet",
    "TwoFlankAsperity",
    "from_profile",
    "from_heightmap",
    "fit",
    "LimitLoad",
    "LimitLoads",
    "LimitCurve",
    "Corner",
    "FitResult",
    "compare_fits",
    "format_fits",
]
