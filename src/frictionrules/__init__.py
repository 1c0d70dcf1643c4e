"""frictionrules: contact friction treated as plasticity.

Limit conditions f, sliding potentials g and the sliding rules, dissipation and inverse
relations they imply (Michałowski & Mróz, 1978), asperity mechanisms, contact integration and
multi-contact solvers. The public API is re-exported here; the SymPy symbols ``T1, T2, N``
for user laws are imported lazily (SymPy loads on first use).
"""

from ._version import __version__
from .errors import FrictionRulesError
from .laws import (
    Cone,
    Coulomb,
    EllipsoidCap,
    EllipticOrthotropic,
    FrictionLaw,
    LAWS,
    HardenedLaw,
    Huber,
    InverseRelation,
    LawState,
    LawTraits,
    RuleComparison,
    SlipHardening,
    SymbolicLaw,
    TransformedCoulomb,
    UserLaw,
    WedgeAsperity,
    compare_rules,
    law_from_mapping,
    law_to_toml,
    read_law,
)
# multi-contact problems and FCLIB files; frictionrules.io is the FCLIB module
from .io import read_fclib, write_fclib
from .multicontact import (ADMMOptions, FrictionContactProblem, IterationInfo, NewtonOptions,
                           NSGSOptions, PolishOptions, ProxOptions, RelaxationComparison, Solution,
                           compare_relaxation, solve, solve_batch)
from .batch import SolveRecord, solve_many
from .parallel import SweepPoint, sweep
# elastic-plastic contact with hardening and softening (§4)
from .contact import ContactModel, ContactState, DriveResult, UpdateResult, drive

__all__ = [
    "FrictionRulesError",
    # asperity mechanisms (§2)
    "FacetSet",
    "TwoFlankAsperity",
    "from_profile",
    "from_heightmap",
    "fit",
    "FitResult",
    "FittedParameter",
    "read_surface",
    "from_topography",
    "scale_study",
    "SurfaceFriction",
    "ScaleStudy",
    # laws (§1, §2 wedge)
    "FrictionLaw",
    "Coulomb",
    "EllipticOrthotropic",
    "Huber",
    "TransformedCoulomb",
    "UserLaw",
    "WedgeAsperity",
    "RuleComparison",
    "compare_rules",
    "LawState",
    "SymbolicLaw",
    "InverseRelation",
    "Cone",
    "SlipHardening",
    "HardenedLaw",
    "LawTraits",
    "LAWS",
    "read_law",
    "law_from_mapping",
    "law_to_toml",
    "T1",
    "T2",
    "N",
    # multi-contact problems
    "FrictionContactProblem",
    "solve",
    "solve_batch",
    "Solution",
    "read_fclib",
    "write_fclib",
    "NSGSOptions",
    "NewtonOptions",
    "ProxOptions",
    "ADMMOptions",
    "PolishOptions",
    "IterationInfo",
    "solve_many",
    "SolveRecord",
    "sweep",
    "SweepPoint",
    "compare_relaxation",
    "RelaxationComparison",
    # elastic-plastic contact (§4)
    "ContactModel",
    "EllipsoidCap",
    "drive",
    "ContactState",
    "UpdateResult",
    "DriveResult",
    # export to finite-element codes
    "export",
    "ExportResult",
    "EXPORT_TARGETS",
    # configuration softening (§3)
    "CylinderOnLayer",
    "SphereOnLayer",
    "GrainContact",
    "GrainState",
    "PathResult",
    "LimitPoint",
    "ForceControlResult",
    "PeakForcePolar",
    # grain assemblies
    "Assembly",
    "triaxial",
    "load_cell",
    "TriaxialResult",
    "write_vtk",
    "ContactSnapshot",
    "SampleState",
    "ensemble",
    "write_lammps_triaxial",
    "read_lammps_triaxial",
    "resume_lammps_triaxial",
    "LammpsFiles",
    "EnsembleResult",
    "EnsembleRun",
    "EnsembleSummary",
    "ConfidenceInterval",
    "MeanCurve",
]

_SYMBOLS = ("T1", "T2", "N")

#: The layers a call may not need, re-exported on first use (PEP 562): a ``solve`` or a
#: ``drive`` does not import the asperities, the export, the configurations or the assemblies.
_LAZY = {
    # asperity mechanisms, real surfaces and calibration (§2)
    "asperities": ("FacetSet", "TwoFlankAsperity", "fit", "from_heightmap", "from_profile",
                   "FitResult", "FittedParameter", "ScaleStudy", "SurfaceFriction",
                   "from_topography", "read_surface", "scale_study"),
    # export to finite-element codes (Abaqus user subroutines, C, LAMMPS)
    "_export": ("EXPORT_TARGETS", "ExportResult", "export"),
    # configuration softening: grains sliding over layers (§3)
    "configuration": ("CylinderOnLayer", "ForceControlResult", "GrainContact", "GrainState",
                      "LimitPoint", "PathResult", "PeakForcePolar", "SphereOnLayer"),
    # grain assemblies: many grains, a law at every contact (§5, (4.12))
    "assembly": ("Assembly", "ContactSnapshot", "SampleState", "TriaxialResult", "load_cell",
                 "triaxial", "write_vtk", "ConfidenceInterval", "EnsembleResult", "EnsembleRun",
                 "EnsembleSummary", "MeanCurve", "ensemble", "LammpsFiles",
                 "read_lammps_triaxial", "resume_lammps_triaxial", "write_lammps_triaxial"),
}
_LAZY_NAMES = {name: module for module, names in _LAZY.items() for name in names}


def __getattr__(name):
    if name in _SYMBOLS:
        from .laws import symbols
        return getattr(symbols, name)
    module = _LAZY_NAMES.get(name)
    if module is not None:
        import importlib
        value = getattr(importlib.import_module(f".{module}", __name__), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'frictionrules' has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | set(__all__))
