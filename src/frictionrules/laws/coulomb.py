r"""Isotropic Coulomb friction, (1.4)–(1.8)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._params import parameter
from ._records import Cone, InverseRelation
from ._traits import LawTraits
from .base import FrictionLaw, as_slip, safe_ratio

__all__ = ["Coulomb"]


@dataclass(frozen=True)
class Coulomb(FrictionLaw):
    r"""Isotropic Coulomb friction.

    Limit condition (1.4): :math:`f = |T| - \mu N`.

    * ``dilatant=False`` (default): the sliding rule (1.5), associated in the sliding plane at
      fixed N, with no normal slip: potential :math:`g = |T|`, slip
      :math:`v = \dot\lambda\,(T/|T|, 0)`. Dissipation (1.7) :math:`D = \mu N |v_t|`.
    * ``dilatant=True``: the rule (1.6) associated in the full space, :math:`g = f`, with the
      opening slip :math:`v_n = \mu |v_t|` (the paper's :math:`V_z = -\dot\lambda\mu` with z
      pointing into the support; see ``docs/errata.md``). Its dissipation is zero.

    Parameters
    ----------
    mu : float
        Friction coefficient, ``mu >= 0``.
    dilatant : bool
        Use the associated (dilatant) rule (1.6).
    """

    mu: float = parameter("friction coefficient", lo=0.0)
    dilatant: bool = parameter("the associated (dilatant) rule (1.6)", kind=bool, default=False)
    capabilities = frozenset({"symbolic", "cone", "closed_form_return"})

    @property
    def associated(self) -> bool:
        return self.dilatant

    def declared_traits(self) -> LawTraits:
        """A cone of degree one; normal slip only with the dilatant rule (and ``mu > 0``)."""
        return LawTraits(degree=1.0, slip_degree=0.0, normal_slip=self.dilatant and self.mu > 0,
                         tangentially_associated=True, tangent_coupling=False, convex=True)

    def limit(self, T, N, q=None):
        T, N = self._inputs(T, N)
        return np.hypot(T[..., 0], T[..., 1]) - self.mu * N

    def potential(self, T, N, q=None):
        T, N = self._inputs(T, N)
        norm = np.hypot(T[..., 0], T[..., 1])
        return norm - self.mu * N if self.dilatant else norm + 0.0 * N

    def limit_gradient(self, T, N, q=None):
        T, N = self._inputs(T, N)
        norm = np.hypot(T[..., 0], T[..., 1])
        e1, e2 = safe_ratio(T[..., 0], norm), safe_ratio(T[..., 1], norm)
        return np.stack(np.broadcast_arrays(e1, e2, -self.mu + 0.0 * N), axis=-1)

    def potential_gradient(self, T, N, q=None):
        grad = self.limit_gradient(T, N)
        if not self.dilatant:
            grad[..., 2] = 0.0
        return grad

    def symbolic_form(self):
        import sympy

        from ._symbolic import SymbolicLaw
        from .symbols import N, T1, T2
        mu = sympy.Symbol("mu", nonnegative=True)
        norm = sympy.sqrt(T1**2 + T2**2)
        f = norm - mu * N
        return SymbolicLaw(f, f if self.dilatant else norm, params=(mu,), values=(self.mu,))

    def cone(self, q=None) -> Cone:
        """Circular cone; dilatancy ratio 1 for the dilatant rule (1.6), 0 for (1.5)."""
        return Cone(self.mu, self.mu, 0.0, 1.0 if self.dilatant else 0.0)

    def closed_form_return(self):
        """The radial return of the compiled Coulomb kernel."""
        from ._records import ClosedFormReturn
        return ClosedFormReturn("coulomb", (self.mu, float(self.dilatant)))

    def _inverse_relation(self, theta, N, q):
        """(1.8): :math:`T = \\mu N\\, v_t/|v_t|`."""
        T = self.mu * N[..., None] * np.stack((np.cos(theta), np.sin(theta)), axis=-1)
        return InverseRelation(T, np.zeros(theta.shape, dtype=bool))

    def dissipation(self, v, N, q=None):
        r"""(1.7): :math:`D = \mu N |v_t|` without dilatancy; with it ``-N vn`` is added."""
        v = as_slip(v)
        N = self._normal(N)
        vt = np.hypot(v[..., 0], v[..., 1])
        if v.shape[-1] == 3:
            return self.mu * N * vt - N * v[..., 2]
        return self.mu * N * vt * (0.0 if self.dilatant else 1.0)
