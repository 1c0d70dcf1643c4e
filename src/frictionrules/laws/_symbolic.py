r"""The symbolic form of a law, and everything derived from it.

A law with the capability ``"symbolic"`` gives :class:`SymbolicLaw`: its limit condition f, its
sliding potential g and the evolution :math:`\dot q = \dot\lambda\,h(T, N, q)` of its internal
variables ((4.5)), as SymPy expressions in ``T1, T2, N``, the state symbols and the parameter
symbols. Every derivative any layer uses (gradients, Hessians, the hardening modulus (4.7),
the return-mapping Jacobian, generated code) is derived here from that one form, never copied.

The derived functions are compiled once per *structure* (the expressions with the parameters
as symbols), so laws that differ only in their parameter values share them.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import Callable

import numpy as np

__all__ = ["SymbolicLaw", "LocalDerivatives", "slip_rate"]


@dataclass(frozen=True)
class SymbolicLaw:
    r"""f, g and the evolution of the internal variables, as SymPy expressions.

    Attributes
    ----------
    f, g : sympy.Expr
        Limit condition and sliding potential in ``T1, T2, N`` (:mod:`frictionrules.laws.symbols`),
        the state symbols and the parameter symbols.
    state : tuple of sympy.Symbol
        Internal variables q (empty for a perfectly plastic law).
    rates : tuple of sympy.Expr
        :math:`h_i = \dot q_i/\dot\lambda` ((4.5)), one per state symbol.
    params : tuple of sympy.Symbol
        Parameters, in the order of ``values``.
    values : tuple of float
        Parameter values of the law.
    """

    f: object
    g: object
    state: tuple = ()
    rates: tuple = ()
    params: tuple = ()
    values: tuple = ()

    def __post_init__(self):
        object.__setattr__(self, "state", tuple(self.state))
        object.__setattr__(self, "rates", tuple(self.rates))
        object.__setattr__(self, "params", tuple(self.params))
        object.__setattr__(self, "values", tuple(float(v) for v in self.values))
        if len(self.rates) != len(self.state) or len(self.values) != len(self.params):
            raise ValueError("SymbolicLaw: one rate per state symbol and one value per parameter")

    @property
    def variables(self) -> tuple:
        """The force symbols ``(T1, T2, N)``."""
        from .symbols import N, T1, T2
        return (T1, T2, N)

    @property
    def state_names(self) -> tuple[str, ...]:
        return tuple(str(s) for s in self.state)

    @property
    def param_names(self) -> tuple[str, ...]:
        return tuple(str(s) for s in self.params)

    def substituted(self):
        """``(f, g, rates)`` with the parameter values put in (SymPy Floats)."""
        import sympy
        sub = {p: sympy.Float(v) for p, v in zip(self.params, self.values)}
        return (self.f.xreplace(sub), self.g.xreplace(sub), tuple(r.xreplace(sub) for r in self.rates))

    @functools.cached_property
    def structure(self) -> str:
        """A key identifying the expressions with symbolic parameters (cache key of generated code)."""
        import sympy
        return sympy.srepr((self.f, self.g, self.state, self.rates, self.params))


def slip_rate(g):
    r"""The rate of the accumulated tangential plastic slip per unit λ̇ ((4.5)):
    :math:`\dot\kappa/\dot\lambda = |\partial g/\partial T| = \sqrt{g_{,T_1}^2 + g_{,T_2}^2}`."""
    import sympy

    from .symbols import T1, T2
    return sympy.sqrt(sympy.diff(g, T1) ** 2 + sympy.diff(g, T2) ** 2)


# ---------------------------------------------------------------------------------------------
# derived numerical functions (NumPy)
# ---------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Derived:
    """Compiled f, g and their derivatives for one law structure.

    Every function takes ``(T1, T2, N, q, p)`` with ``q`` of shape ``(..., nq)`` and ``p`` the
    parameter values, and returns arrays broadcast over the leading dimensions: scalars
    ``(...)``, gradients ``(..., 3)`` in ``(T1, T2, N)``, and the blocks the return mapping
    needs (see :func:`derive`).
    """

    nq: int
    f: Callable
    g: Callable
    grad_f: Callable
    grad_g: Callable
    hess_f: Callable
    hess_g: Callable
    local: Callable


def _shape_fun(fun, kind, nq):
    """Broadcast a lambdified function of ``(T1, T2, N, *q, *p)`` to arrays of a given kind."""
    def call(t1, t2, n, q, p):
        q = np.asarray(q, dtype=float)
        lead = np.broadcast_shapes(np.shape(t1), np.shape(t2), np.shape(n), q.shape[:-1])
        args = [np.broadcast_to(a, lead) for a in (t1, t2, n)]
        args += [np.broadcast_to(q[..., i], lead) for i in range(nq)]
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            out = fun(*args, *p)
        return kind(out, lead)
    return call


def _scalar(out, shape):
    return np.broadcast_to(np.asarray(out, dtype=float), shape).copy()


def _vector(out, shape):
    if len(out) == 0:
        return np.zeros(shape + (0,))
    return np.stack([np.broadcast_to(np.asarray(o, dtype=float), shape) for o in out], axis=-1)


def _matrix(out, shape):
    if len(out) == 0:
        return np.zeros(shape + (0, 0))
    return np.stack([_vector(row, shape) for row in out], axis=-2)


def _local_kind(nq):
    def kind(out, shape):
        f, df, dfq, dg, hgg, hgq, h, dhs, dhq = out
        def mat(rows, ncol):
            if not rows:
                return np.zeros(shape + (0, ncol))
            return _matrix(rows, shape)
        return (_scalar(f, shape), _vector(df, shape), _vector(dfq, shape), _vector(dg, shape),
                _matrix(hgg, shape), mat(hgq, nq) if nq else np.zeros(shape + (3, 0)),
                _vector(h, shape), mat(dhs, 3), mat(dhq, nq))
    return kind


#: Derived functions per law structure (a cache: laws equal but for parameter values share).
_STRUCTURES: dict[str, Derived] = {}


def _build(form: SymbolicLaw) -> Derived:
    import sympy

    x = list(form.variables)
    q = list(form.state)
    args = x + q + list(form.params)
    f, g, rates = form.f, form.g, list(form.rates)
    nq = len(q)

    def grad(e, wrt):
        return [sympy.diff(e, s) for s in wrt]

    df, dfq, dg = grad(f, x), grad(f, q), grad(g, x)
    hgg = [grad(gi, x) for gi in dg]
    hgq = [grad(gi, q) for gi in dg] if nq else []
    dhs = [grad(h, x) for h in rates]
    dhq = [grad(h, q) for h in rates]
    hff = [grad(fi, x) for fi in df]

    def lam(expr, kind):
        return _shape_fun(sympy.lambdify(args, expr, modules="numpy", cse=True), kind, nq)

    local = lam([f, df, dfq, dg, hgg, hgq, rates, dhs, dhq], _local_kind(nq))
    return Derived(nq, lam(f, _scalar), lam(g, _scalar), lam(df, _vector), lam(dg, _vector),
                   lam(hff, _matrix), lam(hgg, _matrix), local)


def derive(form: SymbolicLaw) -> Derived:
    """The compiled derivatives of a symbolic form (cached per structure)."""
    key = form.structure
    out = _STRUCTURES.get(key)
    if out is None:
        out = _STRUCTURES[key] = _build(form)
    return out


@functools.lru_cache(maxsize=1024)
def form_of(law) -> SymbolicLaw:
    """``law.symbolic_form()``, built once per law (SymPy: the extra ``symbolic``)."""
    from .._optional import require
    require("sympy", purpose=f"the symbolic form of {type(law).__name__}")
    return law.symbolic_form()


@functools.lru_cache(maxsize=1024)
def derived(law) -> Derived:
    """The compiled derivatives of ``law.symbolic_form()`` (cached per structure)."""
    return derive(form_of(law))


@dataclass(frozen=True)
class LocalDerivatives:
    r"""Everything the return mapping needs at a batch of points ``(T, N, q)``.

    Attributes
    ----------
    f : (...)
        Limit condition.
    df : (..., 3)
        :math:`\partial f/\partial(T_1, T_2, N)`.
    dfq : (..., nq)
        :math:`\partial f/\partial q`.
    dg : (..., 3)
        :math:`\partial g/\partial(T_1, T_2, N)`.
    hgg : (..., 3, 3)
        :math:`\partial^2 g/\partial\sigma^2`.
    hgq : (..., 3, nq)
        :math:`\partial^2 g/\partial\sigma\,\partial q`.
    h : (..., nq)
        Evolution :math:`\dot q/\dot\lambda` (4.5).
    dhs : (..., nq, 3)
        :math:`\partial h/\partial\sigma`.
    dhq : (..., nq, nq)
        :math:`\partial h/\partial q`.
    """

    f: np.ndarray
    df: np.ndarray
    dfq: np.ndarray
    dg: np.ndarray
    hgg: np.ndarray
    hgq: np.ndarray
    h: np.ndarray
    dhs: np.ndarray
    dhq: np.ndarray
