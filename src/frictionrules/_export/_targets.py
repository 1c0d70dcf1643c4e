"""The writers of the targets of :func:`frictionrules.export` (the table is :mod:`._table`):
the code each prints and its PROPS and STATEV layouts."""

from __future__ import annotations

from dataclasses import dataclass

from ..errors import FrictionRulesError

@dataclass(frozen=True)
class Entry:
    """One PROPS or STATEV entry: name, meaning, unit."""

    name: str
    meaning: str
    unit: str


@dataclass(frozen=True)
class Written:
    """A target's output before it is written: the code files (texts, in the order of the
    target's ``code`` names), PROPS, STATEV."""

    files: tuple
    props: tuple
    props_entries: tuple
    statev_entries: tuple
    unsymmetric: bool


def _param_entries(spec) -> list[Entry]:
    info = spec.law.parameter_info()
    return [Entry(n, info[n].meaning, info[n].unit) if n in info else
            Entry(n, "law parameter", "as in the law") for n in spec.param_names]


def _state_entries(spec) -> list[Entry]:
    meanings = {"kappa": ("accumulated tangential slip κ (4.5)", "length"),
                "beta": ("real contact area fraction β (4.9)", "1")}
    return [Entry(n, *meanings.get(n, ("internal variable of the law", "as in the law")))
            for n in spec.state_names]


def write_c(spec, target) -> Written:
    from ._ctarget import c_sources
    if spec.kn is None:
        raise FrictionRulesError("kn = None violates: target 'c' needs the normal penalty "
                                 "stiffness kn > 0")
    props = (spec.kt, spec.kn, *spec.param_values)
    entries = [Entry("kt", "tangential (elastic-slip) stiffness", "force/length"),
               Entry("kn", "normal penalty stiffness", "force/length"), *_param_entries(spec)]
    state = [Entry("de_t1", "elastic tangential displacement 1", "length"),
             Entry("de_t2", "elastic tangential displacement 2", "length"),
             Entry("de_n", "elastic normal displacement (positive opening)", "length"),
             Entry("dp_t1", "plastic tangential displacement (slip) 1", "length"),
             Entry("dp_t2", "plastic tangential displacement (slip) 2", "length"),
             Entry("dp_n", "plastic normal displacement (positive opening)", "length"),
             *_state_entries(spec)]
    files = c_sources(spec)
    return Written(tuple(files[n.format(name=spec.name)] for n in target.code), props,
                   tuple(entries), tuple(state), not spec.law.traits.symmetric_tangent)


def write_fric(spec, target) -> Written:
    from ._f_standard import FRIC
    from ._fortran import fill, header, law_subroutines, refit
    if spec.law.traits.normal_slip:
        raise FrictionRulesError(
            f"law = {type(spec.law).__name__}: its sliding rule moves the surfaces normally "
            "(dg/dN != 0, dilatancy or compaction); constraint for target 'abaqus-fric': FRIC "
            "carries only the tangential part at the given pressure: use 'abaqus-uinter'")
    entries = [*_param_entries(spec),
               Entry("kt", "elastic-slip stiffness (shear stress per unit elastic slip)",
                     "stress/length")]
    state = [*_state_entries(spec),
             Entry("e_t1", "elastic slip along local direction 1", "length"),
             Entry("e_t2", "elastic slip along local direction 2 (0 in 2-D)", "length")]
    props = (*spec.param_values, spec.kt)
    lines = ["", "Abaqus/Standard FRIC: penalty stick (kt), implicit return map at the",
             "pressure PRESS (> 0 in compression), consistent tangent DDTDDG, DDTDDP.",
             f"PROPS ({len(props)}): " + ", ".join(e.name for e in entries) + " (kt last)",
             f"STATEV ({len(state)}): " + ", ".join(e.name for e in state),
             "(start-of-increment values in, end values out)"]
    text = header(spec, target.name, lines)
    body = fill(FRIC, spec)
    text = refit(text + body + law_subroutines(spec))
    return Written((text,), props, tuple(entries), tuple(state),
                   not spec.law.traits.symmetric_tangent)


def write_uinter(spec, target) -> Written:
    from ._f_standard import UINTER
    from ._fortran import fill, header, law_subroutines, refit
    if spec.kn is None:
        raise FrictionRulesError("kn = None violates: target 'abaqus-uinter' needs the normal "
                                 "penalty stiffness kn > 0")
    entries = [*_param_entries(spec),
               Entry("kn", "normal penalty stiffness (pressure per unit overclosure)",
                     "stress/length"),
               Entry("kt", "elastic-slip stiffness (shear stress per unit elastic slip)",
                     "stress/length")]
    state = [*_state_entries(spec),
             Entry("de_t1", "elastic slip along local direction 1", "length"),
             Entry("de_t2", "elastic slip along local direction 2 (0 in 2-D)", "length"),
             Entry("de_n", "elastic normal displacement (positive opening)", "length"),
             Entry("dp_t1", "plastic slip along local direction 1", "length"),
             Entry("dp_t2", "plastic slip along local direction 2", "length"),
             Entry("dp_n", "plastic normal displacement (positive opening: dilatancy)",
                   "length")]
    props = (*spec.param_values, spec.kn, spec.kt)
    lines = ["", "Abaqus/Standard UINTER: the whole interface law, normal penalty kn and "
             "elastic-slip stiffness kt, implicit return map, consistent tangent DDSDDR "
             "(STRESS = pressure, shear 1, shear 2; RDISP = overclosure, slip 1, slip 2).",
             f"PROPS ({len(props)}): " + ", ".join(e.name for e in entries) + " (kt last)",
             f"STATEV ({len(state)}): " + ", ".join(e.name for e in state),
             "(start-of-increment values in, end values out)"]
    text = header(spec, target.name, lines)
    body = fill(UINTER, spec)
    text = refit(text + body + law_subroutines(spec))
    traits = spec.law.traits
    return Written((text,), props, tuple(entries), tuple(state),
                   traits.normal_slip or not traits.symmetric_tangent)


def write_vfric(spec, target) -> Written:
    from ._f_explicit import INVERSE, VFRIC
    from ._fortran import fill, header, law_subroutines, refit
    if not spec.law.traits.conical:
        raise FrictionRulesError(
            f"law = {type(spec.law).__name__} violates: target 'abaqus-vfric' needs a law whose "
            "limit surface is a cone in (T, N) (f homogeneous in the forces): VFRIC scales the "
            "force of the inverse relation at N = 1 by the normal force")
    entries = [*_param_entries(spec),
               Entry("frame_angle", "angle of the material axis 1 from the projection of "
                     "global axis 1 (2 where the normal is closer to axis 1), about the normal",
                     "rad")]
    state = _state_entries(spec)
    props = (*spec.param_values, 0.0)
    lines = ["", "Abaqus/Explicit VFRIC: the force of the law's inverse relation (the limit "
             "force that slides in the slip direction) at N = 1, times the normal force, in "
             "the slip frame (1 along the incremental slip, 2 = normal x slip), opposing the "
             "slip, its magnitude at most the stick force.",
             f"PROPS ({len(props)}): " + ", ".join(e.name for e in entries),
             f"STATEV ({len(state)}): " + (", ".join(e.name for e in state) or "none")
             + " (per slave node)"]
    text = header(spec, target.name, lines)
    text = refit(text + fill(VFRIC, spec) + law_subroutines(spec) + fill(INVERSE, spec))
    return Written((text,), props, tuple(entries), tuple(state), False)
