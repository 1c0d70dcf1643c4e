r"""The whole step of one contact, printed per law structure: the hot path of the compiled
update, straight-line code behind one indirect call (the compiled entry) or inlined into the
batch loop of :meth:`ContactModel.update`.

The step (:data:`~frictionrules.contact._kernel_law.STEP_SIGNATURE`) reads a contact's state
row, its increment and the law's row, and writes the new state row, the result row and, when
asked, the consistent tangent (:mod:`frictionrules.contact.layout`): the elastic trial (4.2),
separation (``N <= 0``), the limit check and, for the structures whose return needs no Newton
system on the whole of (σ, q, Δλ) (:func:`frictionrules.codegen.return_structure`), the
return itself:

* radial: :math:`\sigma = \sigma^{tr} + \Delta\lambda v`, :math:`q = q_n + \Delta\lambda h`
  along the flow direction of the trial, :math:`\Delta\lambda = -f^{tr}/\phi'(0)` in closed
  form where f is linear along it, else by Newton's iteration on
  :math:`\phi(\Delta\lambda) = f = 0`, with the tangent derived from that map
  (:func:`frictionrules.codegen.step_programs`);
* elliptic: the scalar equation of
  :func:`frictionrules.contact._kernel_special.elliptic_return` (no tangent here);
* affine flow: Newton's iteration on the system reduced to (Δλ, q), the forces in closed form,
  with the line search of the general return (its rule, its limits and its row scales) and
  the tangent by implicit differentiation of the reduced system.

Where a contact leaves these assumptions — f not finite at the trial (the kink rule), a
return through the apex, a tangential force that would reverse, ``N <= 0`` on the way, an
iteration that does not converge, the tangent of an elliptic return, or a law whose return
needs Newton's method on the whole system — the step writes nothing and returns ``GENERAL``:
the general return of :mod:`frictionrules.contact._return_kernel` takes the contact. The
outputs are written by the helpers the general return uses
(:mod:`frictionrules.contact._kernel_outputs`).
"""

from __future__ import annotations

from .._returnspec import RETURN_AFFINE, RETURN_ELLIPTIC, RETURN_RADIAL

__all__ = ["FAST", "STEP_IMPORTS", "step_function"]

#: Division by a reciprocal and fused multiply-add (no assumption on NaN or inf, which the
#: step's checks rely on): within an ulp of the plain arithmetic.
FAST = {"arcp", "contract"}

#: The module's imports the step needs.
STEP_IMPORTS = (
    "import numpy as np",
    "from numba import carray, njit, uint64",
    "",
    "from frictionrules._returnspec import (GENERAL, MAX_HALVINGS, MAX_ITER, RETURN_AFFINE,",
    "                                       RETURN_ELLIPTIC, RETURN_RADIAL, SCALAR_MAX_ITER, TOL)",
    "from frictionrules.contact._kernel_batch import load_row, store_rows",
    "from frictionrules.contact._kernel_law import STEP_SIGNATURE",
    "from frictionrules.contact._kernel_newton import sufficient_decrease",
    "from frictionrules.contact._kernel_outputs import (ContactIn, ContactOut, finish_elastic,",
    "                                                   finish_open, finish_plastic, finish_slip,",
    "                                                   keep_q, row_views, trial, write_result)",
    "from frictionrules.contact._kernel_special import elliptic_return",
    "from frictionrules.contact._return_kernel import general_return, workspace",
    "from frictionrules.contact._step_source import FAST",
    "from frictionrules.contact.layout import LAW_KN, LAW_KT, LAW_PARAMS, RES_SIZE, RET_KIND, STATE_Q",
)

#: The step of one contact ``c`` (:class:`~frictionrules.contact._kernel_outputs.ContactIn`)
#: into ``out`` (``ContactOut``), returning ``(status, Δλ, dissipation, slip)``; inlined into
#: the C-callable step and the batch loop. The stiffnesses and the values after
#: ``LAW_PARAMS`` in the law's row (``values``: parameters and parameter-only subexpressions,
#: :func:`_values`) come as scalars read once by the caller: the batch loop reads them before
#: its loop, so that their quotients are computed once (the law's row could alias an output,
#: and would be read again after every store).
_HEAD = '''@njit(inline="always", error_model="numpy", _nrt=False)
def _values(law):
    return ({values})


@njit(inline="always", error_model="numpy", fastmath=FAST, _nrt=False)
def _body(c, law, kt, kn, values, out, want):
    e0, e1, e2, x0, x1, x2 = trial(c, kt, kn)
    if not x2 > 0.0:
        keep_q(c, out)
        return finish_open(c, out, e0, e1, e2, want)'''

#: The step as :func:`~frictionrules.contact.contact_update` calls it (by address, on a
#: contact's rows), and the batch loop of :meth:`ContactModel.update` on the batch's arrays:
#: the step, else the general return, contact by contact (``out.failed`` where that fails; no
#: substeps: the caller's NumPy return takes those), without reference counting in the loop
#: (the arrays are allocated around it), with and without the tangent as two entries, each
#: compiled when first called (a caller that never asks for the tangent never compiles that
#: loop: each holds a copy of the step and of the general return); an unsigned index (no test
#: for a negative one at every access).
_ENTRIES = '''@cfunc(STEP_SIGNATURE, cache=True, error_model="numpy", fastmath=FAST)
def _step(s, du, law, s1, res, tan, want):
    res = carray(res, (RES_SIZE,))
    c, out = row_views(carray(s, (STATE_Q + {nq},)), carray(du, (3,)),
                       carray(s1, (STATE_Q + {nq},)), res, carray(tan, (3, 3)))
    kind, lam, diss, slip = _body(c, law, law[LAW_KT], law[LAW_KN], _values(law), out, want)
    if kind != GENERAL:
        write_result(res, lam, diss, slip)
    return kind


@njit(inline="always", error_model="numpy", fastmath=FAST, _nrt=False)
def _range(fn, law, batch, out, want, lo, hi, s, s1, res, ws):
    kt, kn, values = law[LAW_KT], law[LAW_KN], _values(law)
    for i in range(uint64(lo), uint64(hi)):
        tan = out.tangent[i] if want else out.tangent[0]
        kind, lam, diss, slip = _body(ContactIn(batch.e[i], batch.p[i], batch.q[i], batch.du[i]),
                                      law, kt, kn, values, ContactOut(out.e[i], out.p[i], out.q[i], out.force[i],
                                                      tan), want)
        failed = False
        if kind == GENERAL:
            load_row(batch, i, s)
            kind, failed = general_return(fn, law, s, batch.du[i], s1, res, ws, want, tan)
            store_rows(out, i, s1, res)
        else:
            out.dlam[i], out.dissipation[i], out.slip[i] = lam, diss, slip
        out.status[i], out.failed[i] = kind, failed


@njit(error_model="numpy", fastmath=FAST, _nrt=False)
def _loop_tangent(fn, law, batch, out, lo, hi, s, s1, res, ws):
    _range(fn, law, batch, out, True, lo, hi, s, s1, res, ws)


@njit(error_model="numpy", fastmath=FAST, _nrt=False)
def _loop_plain(fn, law, batch, out, lo, hi, s, s1, res, ws):
    _range(fn, law, batch, out, False, lo, hi, s, s1, res, ws)


@njit(nogil=True, cache=True, error_model="numpy")
def _batch_tangent(fn, law, batch, out, lo, hi):
    _loop_tangent(fn, law, batch, out, lo, hi, np.empty(STATE_Q + {nq}), np.empty(STATE_Q + {nq}),
                  np.empty(RES_SIZE), workspace({nq}))


@njit(nogil=True, cache=True, error_model="numpy")
def _batch_plain(fn, law, batch, out, lo, hi):
    _loop_plain(fn, law, batch, out, lo, hi, np.empty(STATE_Q + {nq}), np.empty(STATE_Q + {nq}),
                np.empty(RES_SIZE), workspace({nq}))
'''

#: Where the general return takes over.
_GENERAL = "return GENERAL, 0.0, 0.0, 0.0"

#: The limit check; a limit condition that is not finite goes to the general return (the kink
#: rule): -inf here, NaN and +inf by :data:`_FINITE` or the closed-form radial return's test.
_ELASTIC = f'''    if f <= 0.0:
        if f == -math.inf:
            {_GENERAL}
        keep_q(c, out)
        return finish_elastic(c, out, e0, e1, e2, x0, x1, x2, kt, kn, want)'''

_FINITE = f'''    if not math.isfinite(f):
        {_GENERAL}'''

#: The end of a special return at the forces y: back to the general return where it ends at
#: the apex (|σ| <= TOL |σ_tr|, as the general return decides it).
_APEX = f'''    if not y0 * y0 + y1 * y1 + y2 * y2 > TOL * TOL * (x0 * x0 + x1 * x1 + x2 * x2):
        {_GENERAL}'''

_ELLIPTIC = f'''    if want or law[RET_KIND] != RETURN_ELLIPTIC:
        {_GENERAL}
    ok, y0, y1, lam = elliptic_return(law, x0, x1, kt, f)
    y2 = x2
    if not ok:
        {_GENERAL}
{_APEX}
    keep_q(c, out)
    return finish_plastic(c, out, e0, e1, e2, y0, y1, y2, lam, kt, kn)'''

_RADIAL_START = f'''    if law[RET_KIND] != RETURN_RADIAL:
        {_GENERAL}'''

_SLOPE = f'''    if not slope < 0.0:
        {_GENERAL}'''

_SCALAR_NEWTON = f'''    lam = -f / slope
    fs = fnorm * math.sqrt(x0 * x0 + x1 * x1 + x2 * x2)
    for it in range(SCALAR_MAX_ITER + 1):
        if it == SCALAR_MAX_ITER or not lam >= 0.0:
            {_GENERAL}
{{along}}
        if abs(phi) <= TOL * fs:
            break
        if not dphi < 0.0:
            {_GENERAL}
        lam -= phi / dphi'''

_RADIAL_END = f'''    if not (lam >= 0.0 and y2 > 0.0 and y0 * x0 + y1 * x1 > 0.0):
        {_GENERAL}
{_APEX}'''

#: The radial return in closed form: every condition of the radial return (its kind in the
#: law's row, f finite, a falling slope, Δλ >= 0, N > 0, no turn of T, not at the apex) in
#: one test without branches (one branch where there were five).
_RADIAL_CLOSED = f'''    if not ((law[RET_KIND] == RETURN_RADIAL) & (f < math.inf) & (slope < 0.0) & (lam >= 0.0)
            & (y2 > 0.0) & (y0 * x0 + y1 * x1 > 0.0)
            & (y0 * y0 + y1 * y1 + y2 * y2 > TOL * TOL * (x0 * x0 + x1 * x1 + x2 * x2))):
        {_GENERAL}'''


_AFFINE = f'''    if law[RET_KIND] != RETURN_AFFINE:
        {_GENERAL}'''

#: Newton's iteration on the reduced system of an affine flow, from (Δλ, q) = (0, q_n), with the
#: row scales of the general return; the forces of the end follow in closed form.
_REDUCED = f'''    F = math.sqrt(x0 * x0 + x1 * x1 + x2 * x2)
    lam_s = F / max(gnorm, 1e-300)
{{scales}}
    {{z}} = 0.0, {{qn}}
    {{now}} = _reduced(law, kt, kn, x0, x1, x2, {{qn}}, {{z}})
    merit = {{merit}}
    for it in range(MAX_ITER + 1):
        if merit <= TOL:
            break
        if it == MAX_ITER:
            {_GENERAL}
        {{steps}} = _solve({{jr}})
        alpha = 1.0
        for k in range(MAX_HALVINGS + 1):
            if k == MAX_HALVINGS:
                {_GENERAL}
            {{z_k}} = {{moved}}
            {{now_k}} = _reduced(law, kt, kn, x0, x1, x2, {{qn}}, {{z_k}})
            merit_k = {{merit_k}}
            if sufficient_decrease(merit_k, merit, alpha):
                break
            alpha *= 0.5
        {{now}}, {{z}} = {{now_k}}, {{z_k}}
        merit = merit_k
    if not (z0 >= 0.0 and s2 > 0.0):
        {_GENERAL}
    y0, y1, y2 = s0, s1, s2
{_APEX}
{{q_out}}
    if want:
        {{sens}} = _sensitivity(law, kt, kn, x0, x1, x2, {{qn}}, {{z}})
{{tangent}}
    return finish_plastic(c, out, e0, e1, e2, y0, y1, y2, z0, kt, kn)'''


def _affine_lines(nq, block) -> list[str]:
    """The body's lines of the reduced Newton return (:data:`_REDUCED`)."""
    m = nq + 1
    names = ([f"r{a}" for a in range(m)] + [f"j{a}{b}" for a in range(m) for b in range(m)]
             + ["s0", "s1", "s2"])
    z = [f"z{a}" for a in range(m)]

    def merit(suffix):
        return "math.sqrt(" + " + ".join(f"(r{a}{suffix} * w{a}) ** 2" for a in range(m)) + ")"

    scales = ["    w0 = 1.0 / max(fnorm * F, 1e-300)"]
    scales += [f"    w{j + 1} = 1.0 / max(abs(h{j}) * lam_s, abs(q{j}), 1e-300)" for j in range(nq)]
    sens = ([f"g{a}{b}" for a in range(m) for b in range(3)]
            + [f"sx{a}{b}" for a in range(3) for b in range(3)]
            + [f"sz{a}{b}" for a in range(3) for b in range(m)])
    # dz/dx_b = -J⁻¹ ∂r/∂x_b (the Newton step's solve), dσ/dx = ∂σ/∂x + ∂σ/∂z dz/dx, times E.
    tangent = []
    for b, e in enumerate(("kt", "kt", "-kn")):
        jr = ", ".join(names[m:m + m * m] + [f"g{a}{b}" for a in range(m)])
        tangent.append(f"        {', '.join(f'dz{a}' for a in range(m))} = _solve({jr})")
        tangent += [f"        out.tangent[{a}, {b}] = (sx{a}{b} + "
                    + " + ".join(f"sz{a}{k} * dz{k}" for k in range(m)) + f") * {e}"
                    for a in range(3)]
    text = _REDUCED.format(sens=", ".join(sens), tangent="\n".join(tangent),
        scales="\n".join(scales), qn=", ".join(f"q{j}" for j in range(nq)), z=", ".join(z),
        now=", ".join(names), merit=merit(""), steps=", ".join(f"d{a}" for a in range(m)),
        jr=", ".join(names[m:m + m * m] + names[:m]),
        z_k=", ".join(f"{v}_k" for v in z), now_k=", ".join(f"{n}_k" for n in names),
        moved=", ".join(f"z{a} + alpha * d{a}" for a in range(m)), merit_k=merit("_k"),
        q_out="\n".join(f"    out.q[{j}] = z{j + 1}" for j in range(nq)))
    return [_AFFINE, *block("scales"), text]


def _function(name, args, program, hoisted, nparams, outputs) -> str:
    """An inline compiled function of a piece: ``def name(*args)`` returning ``outputs`` (the
    parameters read from ``law``)."""
    from ..codegen import python_block
    lines = ['@njit(inline="always", error_model="numpy", fastmath=FAST, _nrt=False)',
             f"def {name}({', '.join(args)}):"]
    lines += [f"    p{k} = law[LAW_PARAMS + {k}]" for k in range(nparams)]
    lines += python_block(program, "    ", hoisted, param="law[LAW_PARAMS + {}]")
    lines.append(f"    return {', '.join(outputs)}")
    return "\n".join(lines)


def _path(nq, indent):
    """``y = x + Δλ v``, ``u = q + Δλ h``."""
    lines = [f"{indent}y{i} = x{i} + lam * v{i}" for i in range(3)]
    return lines + [f"{indent}u{j} = q{j} + lam * h{j}" for j in range(nq)]


def step_function(pieces: dict, kind: int, nq: int, nparams: int, hoisted: dict) -> str:
    """Source of the law's step ``_step`` (a Numba ``cfunc``).

    Parameters
    ----------
    pieces : dict
        The straight-line pieces by name (:func:`frictionrules.codegen.step_programs`).
    kind : int
        The return's kind (:mod:`frictionrules._returnspec` ``RETURN_*``).
    nq, nparams : int
        Numbers of internal variables and parameters.
    hoisted : dict
        Per piece, its parameter-only temporaries and their index among the values that follow
        the parameters in the law's row.
    """
    from ..codegen import python_block

    def block(name, indent="    "):
        return python_block(pieces[name], indent, hoisted[name], param="values[{}]")

    functions = []
    if "reduced" in pieces:
        m = nq + 1
        functions.append(_function(
            "_reduced", ["law", "kt", "kn", "x0", "x1", "x2"] + [f"qn{j}" for j in range(nq)]
            + ["lam"] + [f"q{j}" for j in range(nq)], pieces["reduced"], hoisted["reduced"],
            nparams, [name for name, _ in pieces["reduced"].outputs]))
        functions.append(_function(
            "_sensitivity", ["law", "kt", "kn", "x0", "x1", "x2"] + [f"qn{j}" for j in range(nq)]
            + ["lam"] + [f"q{j}" for j in range(nq)], pieces["sensitivity"],
            hoisted["sensitivity"], nparams, [name for name, _ in pieces["sensitivity"].outputs]))
        functions.append(_function(
            "_solve", [f"j{a}{b}" for a in range(m) for b in range(m)] + [f"r{a}" for a in range(m)],
            pieces["solve"], hoisted["solve"], 0, [f"d{a}" for a in range(m)]))
    nvalues = max([nparams] + [k + 1 for name in pieces for k in hoisted[name].values()])
    values = "".join(f"law[LAW_PARAMS + {k}], " for k in range(nvalues))
    lines = ["\n\n\n".join(functions) + "\n\n" if functions else "",
             _HEAD.format(values=values)]
    lines += [f"    q{j} = c.q[{j}]" for j in range(nq)]
    lines += [f"    p{k} = values[{k}]" for k in range(nparams)]
    lines += block("trial")
    lines.append(_ELASTIC)
    if kind == RETURN_RADIAL and "along" not in pieces:
        lines += [*block("radial"), _RADIAL_CLOSED]
    else:
        lines.append(_FINITE)
    if kind == RETURN_ELLIPTIC:
        lines.append(_ELLIPTIC)
    elif kind == RETURN_RADIAL:
        if "along" in pieces:
            lines += [_RADIAL_START, *block("radial"), _SLOPE]
            lines.append(_SCALAR_NEWTON.format(along="\n".join(_path(nq, " " * 8)
                                                                + block("along", " " * 8))))
            lines += _path(nq, "    ")
            lines.append("    slip = lam * slip_rate")
            lines.append(_RADIAL_END)
        lines += [f"    out.q[{j}] = u{j}" for j in range(nq)]
        lines.append("    if want:")
        lines += block("tangent", " " * 8)
        lines += [f"        out.tangent[{i}, {j}] = tan{i}{j}" for i in range(3) for j in range(3)]
        lines.append("    return finish_slip(c, out, e0, e1, e2, y0, y1, y2, lam, kt, kn, slip)")
    elif kind == RETURN_AFFINE and "reduced" in pieces:
        lines += _affine_lines(nq, block)
    else:
        lines.append(f"    {_GENERAL}")
    return "\n".join(lines) + "\n\n\n" + _ENTRIES.format(nq=nq)
