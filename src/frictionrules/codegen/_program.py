r"""A law's local derivatives as straight-line code (SymPy → common subexpressions).

The layout of the quantities, for ``nq`` internal variables (row-major blocks, the names of
:class:`~frictionrules.laws.LocalDerivatives`):

====== ============ ===========================================================
name   shape        quantity
====== ============ ===========================================================
f      ()           limit condition :math:`f(T_1, T_2, N, q)`
df     (3,)         :math:`\partial f/\partial(T_1, T_2, N)`
dfq    (nq,)        :math:`\partial f/\partial q`
dg     (3,)         :math:`\partial g/\partial(T_1, T_2, N)` (sliding rule (4.3))
hgg    (3, 3)       :math:`\partial^2 g/\partial\sigma^2`
hgq    (3, nq)      :math:`\partial^2 g/\partial\sigma\,\partial q`
h      (nq,)        evolution :math:`\dot q/\dot\lambda` ((4.5))
dhs    (nq, 3)      :math:`\partial h/\partial\sigma`
dhq    (nq, nq)     :math:`\partial h/\partial q`
====== ============ ===========================================================

Every derivative is taken here, from the law's one symbolic form; printers only print.
Inputs are renamed to plain identifiers: ``x0, x1, x2`` for ``T1, T2, N``, ``q0, q1, ...`` for
the internal variables and ``p0, p1, ...`` for the parameters (in the order of
:attr:`~frictionrules.laws.SymbolicLaw.params`), so that laws that differ only in their
parameter values share one program.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

__all__ = ["LOCAL_FIELDS", "Program", "local_layout", "local_program"]

LOCAL_FIELDS = ("f", "df", "dfq", "dg", "hgg", "hgq", "h", "dhs", "dhq")

#: The quantities each level of a program computes: the limit condition only; what a residual
#: and the scaling of the return mapping need; everything (the Newton Jacobian too).
LEVELS = {
    "f": ("f",),
    "first": ("f", "df", "dfq", "dg", "h"),
    "full": LOCAL_FIELDS,
}


def local_layout(nq: int) -> dict[str, tuple[int, tuple[int, ...]]]:
    """Offset and shape of each quantity in the flat layout, for ``nq`` internal variables."""
    shapes = {"f": (), "df": (3,), "dfq": (nq,), "dg": (3,), "hgg": (3, 3), "hgq": (3, nq),
              "h": (nq,), "dhs": (nq, 3), "dhq": (nq, nq)}
    out, k = {}, 0
    for name in LOCAL_FIELDS:
        out[name] = (k, shapes[name])
        size = 1
        for s in shapes[name]:
            size *= s
        k += size
    return out


@dataclass(frozen=True)
class Program:
    """Straight-line code for a law's local derivatives.

    Attributes
    ----------
    nq, nparams : int
        Numbers of internal variables and of parameters.
    state_names, param_names : tuple of str
        The law's names for ``q0, q1, ...`` and ``p0, p1, ...``.
    temps : tuple of (sympy.Symbol, sympy.Expr)
        Common subexpressions, in evaluation order.
    outputs : tuple of (int, sympy.Expr)
        Slot in the flat layout (:func:`local_layout`) and its expression.
    size : int
        Length of the flat layout.
    """

    nq: int
    nparams: int
    state_names: tuple
    param_names: tuple
    temps: tuple
    outputs: tuple
    size: int


def _renamed(form):
    import sympy

    x = [sympy.Symbol(f"x{i}", real=True) for i in range(3)]
    q = [sympy.Symbol(f"q{i}", real=True) for i in range(len(form.state))]
    p = [sympy.Symbol(f"p{i}", real=True) for i in range(len(form.params))]
    sub = dict(zip(form.variables, x)) | dict(zip(form.state, q)) | dict(zip(form.params, p))
    ren = lambda e: sympy.sympify(e).xreplace(sub)  # noqa: E731
    return x, q, ren(form.f), ren(form.g), [ren(r) for r in form.rates]


def _quantities(form) -> dict:
    """Every quantity of the layout as a (nested) list of SymPy expressions."""
    import sympy

    x, q, f, g, rates = _renamed(form)

    def grad(e, wrt):
        return [sympy.diff(e, s) for s in wrt]

    dg = grad(g, x)
    return {"f": f, "df": grad(f, x), "dfq": grad(f, q), "dg": dg,
            "hgg": [grad(d, x) for d in dg], "hgq": [grad(d, q) for d in dg],
            "h": list(rates), "dhs": [grad(r, x) for r in rates], "dhq": [grad(r, q) for r in rates]}


def _flat(value):
    if isinstance(value, list):
        return [e for v in value for e in _flat(v)]
    return [value]


@functools.lru_cache(maxsize=256)
def _program(structure_key, form, level) -> Program:
    import sympy

    nq = len(form.state)
    layout = local_layout(nq)
    quantities = _quantities(form)
    slots, exprs = [], []
    for name in LEVELS[level]:
        offset, _ = layout[name]
        for k, e in enumerate(_flat(quantities[name])):
            slots.append(offset + k)
            exprs.append(e)
    temps, reduced = sympy.cse(exprs, symbols=sympy.numbered_symbols("t"), optimizations="basic")
    size = sum(_size(s) for _, s in layout.values())
    return Program(nq, len(form.params), form.state_names, form.param_names, tuple(temps),
                   tuple(zip(slots, reduced)), size)


def _size(shape):
    size = 1
    for s in shape:
        size *= s
    return size


def local_program(form, level: str = "full") -> Program:
    """The straight-line program of a symbolic form (cached per structure and level).

    Parameters
    ----------
    form : SymbolicLaw
        A law's symbolic form (``law.symbolic_form()``).
    level : {"f", "first", "full"}
        ``"f"``: the limit condition; ``"first"``: f, ∇f, ∂f/∂q, ∇g and h (a residual of the
        return mapping); ``"full"``: every quantity of the layout (its Jacobian too).
    """
    if level not in LEVELS:
        raise ValueError(f"level must be one of {sorted(LEVELS)}, got {level!r}")
    return _program(form.structure, form, level)
