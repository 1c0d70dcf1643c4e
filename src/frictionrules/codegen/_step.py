r"""The straight-line pieces of a law's whole contact step, for the structures whose return
needs no Newton system (:mod:`frictionrules.codegen._structure`).

Each piece is a :class:`~frictionrules.codegen.Program` whose outputs are named variables
instead of slots of the flat layout; a printer (:func:`~frictionrules.codegen.python_block`)
writes it as lines of a function that reads ``x0, x1, x2`` (the trial forces), ``q0, ...`` (the internal variables at
the start), ``p0, ...`` (the parameters), ``kt, kn`` and, where said, ``lam`` (Δλ) and
``y0, y1, y2, u0, ...`` (forces and internal variables at the end of the return).

``trial``
    ``f`` at the trial.
``radial``
    At the trial: the flow direction :math:`v = (-k_t g_{,T_1}, -k_t g_{,T_2}, -k_n g_{,N})`,
    ``h``, the slope :math:`\phi'(0) = \nabla f\cdot v + \partial_q f\cdot h` of
    :math:`\phi(\Delta\lambda) = f(x^{tr} + \Delta\lambda v, q_n + \Delta\lambda h)` and
    the rate of tangential slip :math:`|\partial g/\partial T|` (the slip of the step is
    :math:`\Delta\lambda|\partial g/\partial T|`, (4.5)). Where φ is linear, the return in
    closed form instead of v and h: ``lam`` :math:`= -f/\phi'(0)`, ``y = x + lam v``,
    ``u = q + lam h`` and ``slip``, each with common factors cancelled (Coulomb's
    :math:`y_t = x_t \mu N/|T|`); where it is not, ``fnorm`` :math:`= |\nabla f|` (the scale
    of the tolerance).
``along``
    ``f`` and :math:`\phi' = \nabla f\cdot v + \partial_q f\cdot h` at ``(y, u)`` with ``v0,
    ...`` and ``h0, ...`` as inputs (the scalar Newton iteration where φ is not linear).
``tangent``
    Where φ is linear, the derivative of the closed form, :math:`\tau_{ij} = \partial_j y_i
    E_j`; else :math:`\tau_{ij} = \big(\delta_{ij} + \Delta\lambda\,\partial_j v_i -
    v_i a_j/b\big) E_j`, :math:`a_j = \sum_k f_{,k}(\delta_{kj} + \Delta\lambda\,\partial_j v_k) + \Delta\lambda
    \sum_l f_{,q_l}\partial_j h_l`, :math:`b = \nabla f\cdot v + \partial_q f\cdot h` (f's
    derivatives at the end, v's and h's at the trial), :math:`E = (k_t, k_t, -k_n)`: the
    derivative of the radial return :math:`\sigma = \sigma^{tr} + \Delta\lambda(\sigma^{tr})
    v(\sigma^{tr})` with :math:`\phi = 0`, which is the consistent tangent because v does not
    turn along the return (the backward-Euler solution is that map in a neighbourhood).
"""

from __future__ import annotations

import functools

from ._program import Program, _renamed

__all__ = ["step_programs"]


def _symbols(nq):
    import sympy
    y = [sympy.Symbol(f"y{i}", real=True) for i in range(3)]
    u = [sympy.Symbol(f"u{i}", real=True) for i in range(nq)]
    kt, kn = sympy.symbols("kt kn", positive=True)
    return y, u, kt, kn, sympy.Symbol("lam", real=True)


def _program(form, temps, outputs) -> Program:
    return Program(len(form.state), len(form.params), form.state_names, form.param_names,
                   tuple(temps), tuple(outputs), len(outputs))


def _blocks(form, groups, prefix) -> list:
    """One program per group of ``(name, expression)`` outputs, from one elimination of common
    subexpressions: each group's program computes the temporaries its outputs need that no
    earlier group computed (so a later group reads the earlier ones' temporaries)."""
    import sympy
    exprs = [e for group in groups for _, e in group]
    temps, reduced = sympy.cse(exprs, symbols=sympy.numbered_symbols(prefix),
                               optimizations="basic")
    depends = {}
    for sym, expr in temps:
        depends[sym] = set().union(*(depends.get(s, set()) | {s} for s in expr.free_symbols))
    out, done, k = [], set(), 0
    for group in groups:
        outputs = [(name, reduced[k + i]) for i, (name, _) in enumerate(group)]
        k += len(group)
        need = set().union(*(depends.get(s, set()) | {s} for _, e in outputs
                             for s in e.free_symbols))
        mine = [(sym, e) for sym, e in temps if sym in need and sym not in done]
        done |= {sym for sym, _ in mine}
        out.append(_program(form, mine, outputs))
    return out


def _cancel(expr):
    """``expr`` with common factors cancelled where that makes it shorter (the slope of a cone
    ``-kt x0²/(x0² + x1²) - kt x1²/(x0² + x1²)`` is ``-kt``)."""
    import sympy
    short = sympy.cancel(expr)
    return short if sympy.count_ops(short) < sympy.count_ops(expr) else expr


@functools.lru_cache(maxsize=256)
def _step_programs(key, form, radial: bool, linear: bool) -> tuple:
    import sympy
    x, q, f, g, rates = _renamed(form)
    nq = len(q)
    y, u, kt, kn, lam = _symbols(nq)
    if not radial:
        return (("trial", _blocks(form, [[("f", f)]], "a")[0]),)
    v = [-kt * sympy.diff(g, x[0]), -kt * sympy.diff(g, x[1]), -kn * sympy.diff(g, x[2])]
    h = [_cancel(r) for r in rates]
    df = [sympy.diff(f, s) for s in x]
    dfq = [sympy.diff(f, s) for s in q]
    slope = _cancel(sum(a * b for a, b in zip(df + dfq, v + h)))
    rate = _cancel(sympy.sqrt(sympy.diff(g, x[0]) ** 2 + sympy.diff(g, x[1]) ** 2))
    if linear:
        step = -f / slope
        ys = [_cancel(x[i] + step * v[i]) for i in range(3)]
        pieces = [("slope", slope), ("lam", step)] + [(f"y{i}", e) for i, e in enumerate(ys)]
        pieces += [(f"u{j}", _cancel(q[j] + step * h[j])) for j in range(nq)]
        pieces.append(("slip", _cancel(step * rate)))
    else:
        pieces = [(f"v{i}", e) for i, e in enumerate(v)] + [(f"h{j}", e) for j, e in enumerate(h)]
        pieces += [("slope", slope), ("slip_rate", rate),
                   ("fnorm", sympy.sqrt(sum(d**2 for d in df)))]
    first, second = _blocks(form, [[("f", f)], pieces], "a")
    out = [("trial", first), ("radial", second)]
    E = (kt, kt, -kn)
    if linear:
        # The derivative of the closed form y(x).
        tangent = [(f"tan{i}{j}", sympy.diff(ys[i], x[j]) * E[j]) for i in range(3)
                   for j in range(3)]
        out.append(("tangent", _blocks(form, [tangent], "d")[0]))
        return tuple(out)
    at_end = dict(zip(x, y)) | dict(zip(q, u))
    fy = [d.xreplace(at_end) for d in df]
    fqy = [d.xreplace(at_end) for d in dfq]
    vs = sympy.symbols("v0:3", real=True)
    hs = sympy.symbols(f"h0:{nq}", real=True) if nq else ()
    dphi = sum(a * b for a, b in zip(fy + fqy, list(vs) + list(hs)))
    out.append(("along", _blocks(form, [[("phi", f.xreplace(at_end)), ("dphi", dphi)]], "c")[0]))
    b = sum(a * c for a, c in zip(fy + fqy, v + h))
    tangent = []
    for i in range(3):
        for j in range(3):
            a_j = sum(fy[k] * ((1 if k == j else 0) + lam * sympy.diff(v[k], x[j])) for k in range(3))
            a_j += lam * sum(fqy[m] * sympy.diff(h[m], x[j]) for m in range(nq))
            d_ij = (1 if i == j else 0) + lam * sympy.diff(v[i], x[j]) - v[i] * a_j / b
            tangent.append((f"tan{i}{j}", d_ij * E[j]))
    out.append(("tangent", _blocks(form, [tangent], "d")[0]))
    return tuple(out)


def step_programs(form, radial: bool, linear: bool) -> tuple:
    """The pieces of a law's step (``(name, Program)`` pairs, in print order): ``trial``
    always; ``radial``, ``along`` (where φ is not linear) and ``tangent`` for a radial return
    (cached per structure)."""
    return _step_programs(form.structure, form, radial, linear)
