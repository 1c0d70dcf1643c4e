"""Asperity mechanisms (§2): global laws of a rigid block on facets carrying a local friction law.

:class:`FacetSet` (any facets), :class:`TwoFlankAsperity` (the paper's Fig. 4 model with its
closed forms), :func:`from_profile` / :func:`from_heightmap` (facets of real surfaces) and
:func:`fit` (calibration of any law to measured mu(theta)); measured topographies:
:func:`read_surface`, :func:`from_topography` (the law at a stated scale) and
:func:`scale_study`.
"""

from .facets import Corner, FacetSet, LimitCurve, LimitLoad, LimitLoads
from .calibration import FitResult, FittedParameter, compare_fits, fit, format_fits
from .surfaces import from_heightmap, from_profile
from ._surface_law import ScaleStudy, SurfaceFriction, from_topography, scale_study
from ._topography import read_surface
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
    "FittedParameter",
    "compare_fits",
    "format_fits",
    "read_surface",
    "from_topography",
    "scale_study",
    "SurfaceFriction",
    "ScaleStudy",
]
