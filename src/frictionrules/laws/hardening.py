r"""Slip hardening of any law: a law with the internal variable κ, the accumulated slip (4.5).

:math:`\hat f(T, N, \kappa) = f(T, s(\kappa)N)`, :math:`\hat g(T, N, \kappa) = g(T, s(\kappa)N)`,
:math:`s(\kappa) = 1 + h(1 - e^{-\kappa/\kappa_h})`, :math:`\dot\kappa = \dot\lambda\,|\partial\hat
g/\partial T|` (the length of the tangential plastic slip). For a law linear in N (Coulomb, the
orthotropic laws) this multiplies every friction coefficient by ``s(κ)``: hardening for
``h > 0``, softening for ``-1 < h < 0``. The hardening modulus (4.7) is
:math:`H = -\hat f_{,\kappa}|\hat g_{,T}| = -f_{,N}\,N s'(\kappa)\,|\hat g_{,T}|`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import FrictionRulesError
from ._params import Parameterized, parameter
from ._records import Cone
from .base import FrictionLaw, require

__all__ = ["SlipHardening", "HardenedLaw"]


@dataclass(frozen=True)
class SlipHardening(Parameterized):
    r"""Slip hardening :math:`s(\kappa) = 1 + h(1 - e^{-\kappa/\kappa_h})` of the normal force
    in a law's f and g.

    Parameters
    ----------
    h : float
        Relative gain at saturation, ``h > -1`` (``h < 0``: softening).
    kappa_h : float
        Slip over which the gain saturates (length), ``> 0``.

    ``SlipHardening(h, kappa_h).apply(law)`` is the hardening law :class:`HardenedLaw`.
    """

    h: float = parameter("relative hardening at saturation", lo=-1.0, lo_open=True)
    kappa_h: float = parameter("hardening slip scale", "length", lo=0.0, lo_open=True)

    def scale(self, kappa):
        """:math:`s(\\kappa)`."""
        return 1.0 + self.h * (1.0 - np.exp(-np.asarray(kappa) / self.kappa_h))

    def scale_derivative(self, kappa):
        """:math:`s'(\\kappa) = (h/\\kappa_h) e^{-\\kappa/\\kappa_h}`."""
        return self.h / self.kappa_h * np.exp(-np.asarray(kappa) / self.kappa_h)

    def apply(self, law) -> "HardenedLaw":
        """The law ``law`` with this slip hardening."""
        return HardenedLaw(law, self)


@dataclass(frozen=True)
class HardenedLaw(FrictionLaw):
    r"""A law with slip hardening: state ``(kappa,)``, :math:`\hat f = f(T, s(\kappa)N)`.

    Parameters
    ----------
    law : FrictionLaw
        A law without internal variables and with a symbolic form.
    hardening : SlipHardening
        :math:`s(\kappa)`.
    """

    law: FrictionLaw
    hardening: SlipHardening
    state_names = ("kappa",)

    def __post_init__(self):
        require(self.law, "symbolic", "HardenedLaw(law=...)")
        if self.law.state_names:
            raise FrictionRulesError(f"law = {self.law!r} violates: slip hardening applies to a law "
                                     "without internal variables")
        if not isinstance(self.hardening, SlipHardening):
            raise FrictionRulesError(f"hardening = {self.hardening!r} violates: must be a SlipHardening")
        clash = {"h", "kappa_h"} & set(self.law.parameters)
        if clash:
            raise FrictionRulesError(f"law = {self.law!r} has parameters {sorted(clash)} that clash "
                                     "with the hardening's h, kappa_h")

    @property
    def capabilities(self) -> frozenset:
        return frozenset({"symbolic"} | ({"cone"} & self.law.capabilities))

    @property
    def normal_name(self) -> str:
        return self.law.normal_name

    @property
    def associated(self) -> bool:
        return self.law.associated

    def initial_values(self) -> dict[str, float]:
        return {"kappa": 0.0}

    def _check_state(self, q):
        if np.any(q[..., 0] < 0):
            raise FrictionRulesError("kappa violates kappa >= 0 (accumulated slip)")

    @property
    def parameters(self) -> dict[str, float]:
        return {**self.law.parameters, "h": self.hardening.h, "kappa_h": self.hardening.kappa_h}

    @property
    def parameter_descriptions(self) -> dict[str, str]:
        return self.law.parameter_descriptions

    def parameter_info(self) -> dict:
        return {**self.law.parameter_info(), **self.hardening.parameter_table()}

    def replace(self, **changes) -> "HardenedLaw":
        own = {k: changes.pop(k) for k in ("h", "kappa_h") if k in changes}
        law = self.law.replace(**changes) if changes else self.law
        hard = SlipHardening(own.get("h", self.hardening.h), own.get("kappa_h", self.hardening.kappa_h))
        return HardenedLaw(law, hard)

    def symbolic_form(self):
        import sympy

        from ._symbolic import SymbolicLaw, form_of, slip_rate
        from .symbols import N
        base = form_of(self.law)
        kappa = sympy.Symbol("kappa", nonnegative=True)
        h, kh = sympy.Symbol("h", real=True), sympy.Symbol("kappa_h", positive=True)
        s = 1 + h * (1 - sympy.exp(-kappa / kh))
        f, g = (e.xreplace({N: s * N}) for e in (base.f, base.g))
        return SymbolicLaw(f, g, state=(kappa,), rates=(slip_rate(g),), params=(*base.params, h, kh),
                           values=(*base.values, self.hardening.h, self.hardening.kappa_h))

    # f, g and their gradients from the base law's own (closed-form) functions at s(κ)N
    def _scaled(self, T, N, q):
        T, N = self._inputs(T, N)
        shape = np.broadcast_shapes(T.shape[:-1], N.shape)
        kappa = self._state(q, shape)[..., 0]
        return T, N, self.hardening.scale(kappa)

    def limit(self, T, N, q=None):
        T, N, s = self._scaled(T, N, q)
        return self.law.limit(T, s * N)

    def potential(self, T, N, q=None):
        T, N, s = self._scaled(T, N, q)
        return self.law.potential(T, s * N)

    def limit_gradient(self, T, N, q=None):
        T, N, s = self._scaled(T, N, q)
        grad = self.law.limit_gradient(T, s * N)
        return np.concatenate((grad[..., :2], (s * grad[..., 2])[..., None]), axis=-1)

    def potential_gradient(self, T, N, q=None):
        T, N, s = self._scaled(T, N, q)
        grad = self.law.potential_gradient(T, s * N)
        return np.concatenate((grad[..., :2], (s * grad[..., 2])[..., None]), axis=-1)

    def cone(self, q=None) -> Cone:
        """The base law's cone with the friction coefficients scaled by ``s(κ)`` (one state)."""
        require(self, "cone", "HardenedLaw.cone()")
        kappa = float(np.asarray(self._state(q))[..., 0])
        c, s = self.law.cone(), float(self.hardening.scale(kappa))
        return Cone(c.mu_x * s, c.mu_y * s, c.angle, c.dilatancy)

    def centre(self, N, q=None) -> np.ndarray:
        return self.law.centre(N)
