"""The targets of :func:`frictionrules.export`: what each writes, PROPS and STATEV layouts."""

from __future__ import annotations

from dataclasses import dataclass

from ..errors import FrictionRulesError

TARGETS = ("abaqus-fric", "abaqus-vfric", "abaqus-uinter", "c")


@dataclass(frozen=True)
class Entry:
    """One PROPS or STATEV entry: name, meaning, unit."""

    name: str
    meaning: str
    unit: str


@dataclass(frozen=True)
class Written:
    """A target's output before it is written: files (name -> text), PROPS, STATEV."""

    files: dict
    props: tuple
    props_entries: tuple
    statev_entries: tuple
    unsymmetric: bool


_UNITS = {"angle": ("frame angle of the law's axes from local direction 1", "rad"),
          "alpha": ("inclination angle", "rad"),
          "mu": ("friction coefficient", "1"), "mu_x": ("friction coefficient along x", "1"),
          "mu_y": ("friction coefficient along y", "1"), "m": ("friction coefficient", "1"),
          "h": ("relative hardening", "1"), "kappa_h": ("hardening slip scale", "length"),
          "p": ("pressure scale of the cap", "stress"),
          "normal_ratio": ("weight of the normal part of g", "1"),
          "b": ("area growth rate", "1")}


def _param_entries(spec) -> list[Entry]:
    own = spec.law.parameter_descriptions   # a user law's parameters: its words, no guess
    out = []
    for n in spec.param_names:
        meaning, unit = ((own[n], "as in the law") if n in own
                         else _UNITS.get(n, ("law parameter", "as in the law")))
        out.append(Entry(n, meaning, unit))
    return out


def _state_entries(spec) -> list[Entry]:
    meanings = {"kappa": ("accumulated tangential slip κ (4.5)", "length"),
                "beta": ("real contact area fraction β (4.9)", "1")}
    return [Entry(n, *meanings.get(n, ("internal variable of the law", "as in the law")))
            for n in spec.state_names]


def unsymmetric_tangent(spec) -> bool:
    """True unless the tangential sliding rule is associated and the internal variables do not
    couple the tangential directions (then the consistent tangent is symmetric)."""
    import sympy

    from ..laws.symbols import T1, T2
    f, g = spec.form.f, spec.form.g
    if any(sympy.simplify(sympy.diff(f - g, s)) != 0 for s in (T1, T2)):
        return True
    for q, h in zip(spec.form.state, spec.form.rates):
        dgq = [sympy.diff(g, s, q) for s in (T1, T2)]
        dhs = [sympy.diff(h, s) for s in (T1, T2)]
        if any(sympy.simplify(e) != 0 for e in dgq + dhs):
            return True
    return False


def write_c(spec) -> Written:
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
    return Written(c_sources(spec), props, tuple(entries), tuple(state), unsymmetric_tangent(spec))


def write_fric(spec) -> Written:
    from ._f_standard import FRIC
    from ._fortran import fill, header, law_subroutines, refit
    if not spec.dg_dn_vanishes():
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
    text = header(spec, "abaqus-fric", lines)
    body = fill(FRIC, spec)
    text = refit(text + body + law_subroutines(spec))
    return Written({f"{spec.name}_fric.f": text}, props, tuple(entries), tuple(state),
                   unsymmetric_tangent(spec))


def write_uinter(spec) -> Written:
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
    text = header(spec, "abaqus-uinter", lines)
    body = fill(UINTER, spec)
    text = refit(text + body + law_subroutines(spec))
    return Written({f"{spec.name}_uinter.f": text}, props, tuple(entries), tuple(state),
                   True if not spec.dg_dn_vanishes() else unsymmetric_tangent(spec))


def write_vfric(spec) -> Written:
    from ._f_explicit import INVERSE, VFRIC
    from ._fortran import fill, header, law_subroutines, refit
    if not spec.conical():
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
    text = header(spec, "abaqus-vfric", lines)
    text = refit(text + fill(VFRIC, spec) + law_subroutines(spec) + fill(INVERSE, spec))
    return Written({f"{spec.name}_vfric.f": text}, props, tuple(entries), tuple(state), False)
