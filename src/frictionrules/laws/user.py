"""A law written by the user as SymPy expressions f(T1, T2, N) and g(T1, T2, N)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import FrictionRulesError
from .base import FrictionLaw

__all__ = ["UserLaw"]


def _expression(name: str, value):
    import sympy

    from .symbols import N, T1, T2
    allowed = {"T1": T1, "T2": T2, "N": N}
    try:
        expr = sympy.sympify(value, locals=allowed) if isinstance(value, str) else sympy.sympify(value)
    except (sympy.SympifyError, TypeError, SyntaxError) as exc:
        raise FrictionRulesError(f"{name} = {value!r} is not a SymPy expression") from exc
    unknown = expr.free_symbols - {T1, T2, N}
    if unknown:
        raise FrictionRulesError(
            f"{name} = {expr} uses the symbols {sorted(map(str, unknown))}; constraint: only T1, T2, N "
            "(import them with `from frictionrules import T1, T2, N`, put numbers for parameters)")
    return expr


@dataclass(frozen=True)
class UserLaw(FrictionLaw):
    r"""A friction law given by its limit condition f and sliding potential g.

    Both are SymPy expressions (or strings) in the symbols ``T1, T2, N`` exported by
    :mod:`frictionrules`. Their gradients and Hessians are derived symbolically and compiled to
    NumPy; the inverse relation ``force_for_slip`` is solved numerically (see
    :meth:`FrictionLaw.force_for_slip`).

    Parameters
    ----------
    limit : sympy.Expr or str
        f(T1, T2, N): negative inside, zero on the limit surface.
    potential : sympy.Expr or str, optional
        g(T1, T2, N); the law is associated (g = f) when omitted.

    Examples
    --------
    >>> import sympy
    >>> from frictionrules import UserLaw, T1, T2, N
    >>> law = UserLaw(sympy.sqrt(T1**2 + T2**2) - 0.3 * N, potential=sympy.sqrt(T1**2 + T2**2))
    >>> float(law.limit([0.3, 0.0], 1.0))
    0.0
    """

    limit_expr: object
    potential_expr: object = None

    def __init__(self, limit, potential=None):
        object.__setattr__(self, "limit_expr", _expression("limit", limit))
        object.__setattr__(self, "potential_expr",
                           None if potential is None else _expression("potential", potential))

    def _compiled(self):
        from ._derived import compiled
        return compiled(self)

    @property
    def associated(self) -> bool:
        return self.potential_expr is None

    @property
    def tangentially_associated(self) -> bool:
        """True when f - g depends on N only (a sufficient condition for in-plane normality)."""
        import sympy

        from .symbols import T1, T2
        if self.associated:
            return True
        diff = self.limit_expr - self.potential_expr
        return all(sympy.simplify(sympy.diff(diff, s)) == 0 for s in (T1, T2))

    def symbolic(self):
        return self.limit_expr, (self.limit_expr if self.potential_expr is None else self.potential_expr)

    def _eval(self, fun, T, N):
        T, N = self._inputs(T, N)
        out = fun(T[..., 0], T[..., 1], N)
        if not np.all(np.isfinite(out)):
            raise FrictionRulesError(
                f"the user law is not finite at some of the given points (T, N); f = {self.limit_expr}, "
                f"g = {self.symbolic()[1]}: evaluate it away from its singular points")
        return out

    def limit(self, T, N):
        return self._eval(self._compiled().f, T, N)

    def potential(self, T, N):
        return self._eval(self._compiled().g, T, N)

    def limit_gradient(self, T, N):
        return self._eval(self._compiled().grad_f, T, N)

    def potential_gradient(self, T, N):
        return self._eval(self._compiled().grad_g, T, N)
