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
``scales`` (affine flow)
    At the trial, with ``f``: ``fnorm`` :math:`= |\nabla f|`, ``gnorm`` :math:`= |D\nabla g|`
    and ``h`` (the scales of the residual's rows and of Δλ, as the general return takes them).
``reduced`` (affine flow)
    At ``(lam, q0, ...)`` for the trial ``x`` and the start ``qn0, ...``: the reduced
    residual ``r0`` :math:`= f(\sigma, q)`, ``r1, ...`` :math:`= q - q_n - \Delta\lambda h`,
    its Jacobian ``j00, j01, ...`` in :math:`(\Delta\lambda, q)` and the forces ``s0, s1,
    s2`` :math:`= \sigma(\Delta\lambda, q)`.
``sensitivity`` (affine flow)
    At the same point, the derivatives of the residual and of the forces in the trial forces,
    ``g..`` :math:`= \partial r/\partial x`, ``sx..`` :math:`= \partial\sigma/\partial x`,
    and of the forces in the unknowns, ``sz..`` :math:`= \partial\sigma/\partial(\Delta
    \lambda, q)`: the consistent tangent is :math:`(\partial\sigma/\partial x - \partial
    \sigma/\partial z\, J^{-1}\partial r/\partial x) E`.
``solve`` (affine flow)
    The Newton step ``d0, ...`` :math:`= -J^{-1}r` from ``j..`` and ``r..`` (Cramer's rule, for
    at most :data:`MAX_REDUCED` unknowns; a law with more internal variables takes the general
    return).
``tangent``
    Where φ is linear, the derivative of the closed form, :math:`\tau_{ij} = \partial_j y_i
    E_j`; else :math:`\tau_{ij} = \big(\delta_{ij} + \Delta\lambda\,\partial_j v_i -
    v_i a_j/b\big) E_j`, :math:`a_j = \sum_k f_{,k}(\delta_{kj} + \Delta\lambda\,\partial_j v_k) + \Delta\lambda
    \sum_l f_{,q_l}\partial_j h_l`, :math:`b = \nabla f\cdot v + \partial_q f\cdot h` (f's
    derivatives at the end, v's and h's at the trial), :math:`E = (k_t, k_t, -k_n)`: the
    derivative of the radial return :math:`\sigma = \sigma^{tr} + \Delta\lambda(\sigma^{tr})
    v(\sigma^{tr})` with :math:`\phi = 0`, which is the consistent tangent because v does not
    turn along the return (the backward-Euler solution is that map in a neighbourhood).

On the axis (``axis=True``, for a law that depends on T through :math:`|T|` only, whose
trial is taken in the frame of its own tangential force: :math:`x_1 = 0`, :math:`x_0 > 0`)
the radial pieces are the same expressions at :math:`x_1 = 0` with :math:`x_0` positive, so
that :math:`|T| = \sqrt{x_0^2 + x_1^2}` is :math:`x_0` and Coulomb's
:math:`y_0 = x_0\,\mu N/|T|` is :math:`\mu N`; ``along`` at :math:`y_1 = 0` (its
:math:`y_0` keeps its sign); no ``tangent``.
"""

from __future__ import annotations

import functools

from ._program import Program, _renamed

__all__ = ["step_programs", "MAX_REDUCED"]

#: Unknowns of the reduced system of an affine flow solved by Cramer's rule in the printed
#: step (Δλ and up to two internal variables: the cap's κ, β).
MAX_REDUCED = 3


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


def _radial(form, x, q, f, g, rates, linear, axis=False) -> list:
    import sympy
    nq = len(q)
    y, u, kt, kn, lam = _symbols(nq)
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
    f_trial = f
    if axis:
        on = {x[1]: 0, x[0]: sympy.Symbol("x0", positive=True)}
        f_trial = f.xreplace(on)
        pieces = [(name, _cancel(e.xreplace(on))) for name, e in pieces]
    first, second = _blocks(form, [[("f", f_trial)], pieces], "a")
    out = [("trial", first), ("radial", second)]
    E = (kt, kt, -kn)
    if linear and axis:
        return out
    if linear:
        # The derivative of the closed form y(x).
        tangent = [(f"tan{i}{j}", sympy.diff(ys[i], x[j]) * E[j]) for i in range(3)
                   for j in range(3)]
        return out + [("tangent", _blocks(form, [tangent], "d")[0])]
    at_end = dict(zip(x, y)) | dict(zip(q, u))
    fy = [d.xreplace(at_end) for d in df]
    fqy = [d.xreplace(at_end) for d in dfq]
    vs = sympy.symbols("v0:3", real=True)
    hs = sympy.symbols(f"h0:{nq}", real=True) if nq else ()
    dphi = sum(a * b for a, b in zip(fy + fqy, list(vs) + list(hs)))
    phi = f.xreplace(at_end)
    if axis:
        phi, dphi = phi.xreplace({y[1]: 0}), dphi.xreplace({y[1]: 0})
    out.append(("along", _blocks(form, [[("phi", phi), ("dphi", dphi)]], "c")[0]))
    if axis:
        return out
    b = sum(a * c for a, c in zip(fy + fqy, v + h))
    tangent = []
    for i in range(3):
        for j in range(3):
            a_j = sum(fy[k] * ((1 if k == j else 0) + lam * sympy.diff(v[k], x[j])) for k in range(3))
            a_j += lam * sum(fqy[m] * sympy.diff(h[m], x[j]) for m in range(nq))
            d_ij = (1 if i == j else 0) + lam * sympy.diff(v[i], x[j]) - v[i] * a_j / b
            tangent.append((f"tan{i}{j}", d_ij * E[j]))
    return out + [("tangent", _blocks(form, [tangent], "d")[0])]


def _affine(form, x, q, f, g, rates) -> list:
    import sympy
    nq = len(q)
    _, _, kt, kn, lam = _symbols(nq)
    D = (kt, kt, kn)
    dg = [sympy.diff(g, s) for s in x]
    df = [sympy.diff(f, s) for s in x]
    scales = [("fnorm", sympy.sqrt(sum(d**2 for d in df))),
              ("gnorm", sympy.sqrt(sum((Da * d)**2 for Da, d in zip(D, dg))))]
    scales += [(f"h{j}", r) for j, r in enumerate(rates)]
    first, second = _blocks(form, [[("f", f)], scales], "a")
    # The forces in closed form for given (Δλ, q): ∇g = H σ + c with H diagonal.
    zero = dict.fromkeys(x, 0)
    sigma = {x[a]: (x[a] - lam * D[a] * dg[a].xreplace(zero))
             / (1 + lam * D[a] * sympy.diff(g, x[a], 2)) for a in range(3)}
    qn = [sympy.Symbol(f"qn{j}", real=True) for j in range(nq)]
    res = [f.xreplace(sigma)] + [q[j] - qn[j] - lam * rates[j].xreplace(sigma) for j in range(nq)]
    z = [lam] + list(q)
    m = len(z)
    pieces = [(f"r{a}", e) for a, e in enumerate(res)]
    pieces += [(f"j{a}{b}", sympy.diff(res[a], z[b])) for a in range(m) for b in range(m)]
    pieces += [(f"s{a}", sigma[x[a]]) for a in range(3)]
    J = sympy.Matrix(m, m, lambda a, b: sympy.Symbol(f"j{a}{b}", real=True))
    r = sympy.Matrix(m, 1, lambda a, _: sympy.Symbol(f"r{a}", real=True))
    d = -(J.adjugate() * r) / J.det()
    sens = [(f"g{a}{b}", sympy.diff(res[a], x[b])) for a in range(m) for b in range(3)]
    sens += [(f"sx{a}{b}", sympy.diff(sigma[x[a]], x[b])) for a in range(3) for b in range(3)]
    sens += [(f"sz{a}{b}", sympy.diff(sigma[x[a]], z[b])) for a in range(3) for b in range(m)]
    return [("trial", first), ("scales", second), ("reduced", _blocks(form, [pieces], "c")[0]),
            ("solve", _blocks(form, [[(f"d{a}", d[a]) for a in range(m)]], "b")[0]),
            ("sensitivity", _blocks(form, [sens], "d")[0])]


@functools.lru_cache(maxsize=256)
def _step_programs(key, form, axis) -> tuple:
    from .._returnspec import RETURN_AFFINE, RETURN_RADIAL
    from ._structure import return_structure
    x, q, f, g, rates = _renamed(form)
    s = return_structure(form)
    if s.kind == RETURN_RADIAL:
        return tuple(_radial(form, x, q, f, g, rates, s.linear, axis))
    if axis:
        return ()
    if s.kind == RETURN_AFFINE and len(q) <= MAX_REDUCED - 1:
        return tuple(_affine(form, x, q, f, g, rates))
    return (("trial", _blocks(form, [[("f", f)]], "a")[0]),)


def step_programs(form, axis: bool = False) -> tuple:
    """The pieces of a law's step (``(name, Program)`` pairs, in print order, by the
    structure of its return, :func:`~frictionrules.codegen.return_structure`): ``trial``
    always; ``radial``, ``along`` (where φ is not linear) and ``tangent`` for a radial return;
    ``scales``, ``reduced``, ``solve`` and ``sensitivity`` for an affine flow with at most
    ``MAX_REDUCED - 1`` internal variables (cached per structure). With ``axis``, the radial
    return's pieces on the axis :math:`x_1 = 0`, :math:`x_0 > 0` (none where the return is
    not radial), for a law that depends on T through :math:`|T|` only: the caller checks
    that."""
    return _step_programs(form.structure, form, bool(axis))
