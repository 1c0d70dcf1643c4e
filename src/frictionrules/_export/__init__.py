"""Export a law to finite-element codes: Abaqus user subroutines (FRIC, VFRIC, UINTER) in
fixed-form Fortran 77 and a plain C99 kernel, printed from the law's symbolic form by the
printers of :mod:`frictionrules.codegen`."""

from ._api import ExportResult, export
from ._table import EXPORT_TARGETS, ExportTarget

__all__ = ["ExportResult", "export", "EXPORT_TARGETS", "ExportTarget"]
