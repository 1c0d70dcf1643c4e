"""Grain assemblies: rigid grains in a periodic cell with a library law at every contact,
loaded quasi-statically (the paper's programme of §5, the limit condition (4.12)).

Public: :class:`Assembly`, :func:`triaxial` and the records :class:`TriaxialResult`,
:class:`ContactSnapshot`, :class:`SampleState`, :func:`write_vtk` (VTK files for
ParaView), :func:`ensemble` (many samples with confidence intervals) and its records, and the
same test in LAMMPS: :func:`write_lammps_triaxial`, :func:`read_lammps_triaxial`,
:class:`LammpsFiles` (re-exported by :mod:`frictionrules`).
"""

from ._config import read_config, read_samples
from ._ensemble import EnsembleResult, EnsembleRun, EnsembleSummary, ensemble
from ._geometry import Assembly
from ._lammps import (LammpsFiles, read_lammps_triaxial, resume_lammps_triaxial,
                      write_lammps_triaxial)
from ._loading import load_cell, triaxial
from ._results import ContactSnapshot, SampleState, TriaxialResult
from ._statistics import ConfidenceInterval, MeanCurve
from ._vtk import write_vtk

__all__ = ["Assembly", "triaxial", "load_cell", "TriaxialResult", "ContactSnapshot", "SampleState", "read_config", "read_samples",
           "write_vtk", "ensemble", "EnsembleResult", "EnsembleRun", "EnsembleSummary",
           "ConfidenceInterval", "MeanCurve", "write_lammps_triaxial", "read_lammps_triaxial", "LammpsFiles",
           "resume_lammps_triaxial"]
