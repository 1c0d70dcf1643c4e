"""The compiled dynamic (DEM) engine of grain assemblies (private to :mod:`..assembly`):
:func:`dem_triaxial` and :func:`dem_load_cell` behind ``triaxial(..., method="dem")`` and
``load_cell(..., method="dem")``."""

from ._api import check_dem_options, dem_load_cell, dem_triaxial
from ._prepare import compress_to, frictionless_compression

__all__ = ["dem_triaxial", "dem_load_cell", "check_dem_options", "compress_to",
           "frictionless_compression"]
