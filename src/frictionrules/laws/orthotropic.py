r"""Orthotropic friction: the elliptic law (1.9)–(1.15) and the two alternatives it is
compared with, Huber's (1.16) and the transformed-variable law (1.17)–(1.18).

All three share the principal frame: axis 1 at ``angle`` from x. Writing
:math:`T' = R(-\text{angle})\,T` for the force in that frame, and :math:`\theta' = \theta -
\text{angle}` for a slip angle, the three laws differ as follows.

========================  ======================================  ==================================
law                       limit f(T, N)                           slip direction (no normal slip)
========================  ======================================  ==================================
``EllipticOrthotropic``   :math:`\sqrt{(T'_1/\mu_x)^2+(T'_2/\mu_y)^2}-N` normal to f: :math:`(T'_1/\mu_x^2, T'_2/\mu_y^2)`
``TransformedCoulomb``    the same ellipse                        :math:`(T'_1/\mu_x, T'_2/\mu_y)` (1.18)
``Huber``                 :math:`|T| - N\mu(\beta')`, (1.16)      along T
========================  ======================================  ==================================

Only the first obeys normality in the sliding plane (``tangentially_associated``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._params import parameter
from ._records import Cone, InverseRelation
from ._traits import LawTraits
from .._rotation import rotate
from .base import FrictionLaw, safe_ratio

__all__ = ["EllipticOrthotropic", "Huber", "TransformedCoulomb"]


def _coefficient(axis: str):
    return parameter(f"friction coefficient along principal axis {axis}", lo=0.0, lo_open=True)


#: The angle of the principal axes, a parameter of every orthotropic law.
_ANGLE = parameter("angle of principal axis 1 from local direction 1", "rad", lo=-np.pi,
                   hi=np.pi, default=0.0)


class _Orthotropic(FrictionLaw):
    """Shared frame handling: parameters ``(m1, m2, angle)`` of the concrete dataclasses."""

    _m_names = ("mu_x", "mu_y")

    @property
    def _m(self) -> tuple[float, float]:
        return tuple(getattr(self, name) for name in self._m_names)

    def _local(self, T, N):
        T, N = self._inputs(T, N)
        return rotate(T, -self.angle), N

    def _global_gradient(self, ga, gb, gn):
        g = rotate(np.stack(np.broadcast_arrays(ga, gb), axis=-1), self.angle)
        return np.concatenate((g, np.broadcast_to(gn, g.shape[:-1])[..., None]), axis=-1)

    def _symbols(self):
        """Parameter symbols ``(m1, m2, angle)`` and the force in the principal frame."""
        import sympy

        from .symbols import T1, T2
        m1, m2 = (sympy.Symbol(name, positive=True) for name in self._m_names)
        angle = sympy.Symbol("angle", real=True)
        c, s = sympy.cos(angle), sympy.sin(angle)
        return (m1, m2, angle), (c * T1 + s * T2, -s * T1 + c * T2)

    def _form(self, f, g, params):
        from ._symbolic import SymbolicLaw
        return SymbolicLaw(f, g, params=params, values=(*self._m, self.angle))

    def _inverse_relation(self, theta, N, q):
        t = theta - self.angle
        T = rotate(N[..., None] * self._local_force(np.cos(t), np.sin(t)), self.angle)
        return InverseRelation(T, np.zeros(theta.shape, dtype=bool))


class _EllipseLimit(_Orthotropic):
    r"""Limit ellipse :math:`f = \sqrt{(T'_1/\mu_x)^2+(T'_2/\mu_y)^2} - N`.

    This is the degree-one form of (1.9), :math:`T_x^2/\mu_x^2 + T_y^2/\mu_y^2 - N^2 = 0`:
    the two have the same zero set for N >= 0 and parallel gradients on it.
    """

    def _rho(self, T):
        mx, my = self._m
        # hypot: no overflow of the squares; a value past the largest float is inf (rounded)
        with np.errstate(over="ignore"):
            return np.hypot(T[..., 0] / mx, T[..., 1] / my)

    def limit(self, T, N, q=None):
        T, N = self._local(T, N)
        return self._rho(T) - N

    def limit_gradient(self, T, N, q=None):
        T, N = self._local(T, N)
        mx, my = self._m
        rho = self._rho(T)
        return self._global_gradient(safe_ratio(T[..., 0] / mx**2, rho),
                                     safe_ratio(T[..., 1] / my**2, rho), -1.0 + 0.0 * N)

    def _symbolic_limit(self):
        """Parameter symbols, the symbolic limit and the force in the principal frame."""
        import sympy

        from .symbols import N
        params, (a, b) = self._symbols()
        mx, my, _ = params
        return params, sympy.sqrt((a / mx) ** 2 + (b / my) ** 2) - N, (a, b)


@dataclass(frozen=True)
class EllipticOrthotropic(_EllipseLimit):
    r"""Orthotropic friction with the elliptic limit (1.9) and normality in the sliding plane.

    Limit :math:`f = \sqrt{(T'_1/\mu_x)^2+(T'_2/\mu_y)^2} - N` (degree-one form of (1.9)),
    potential :math:`g = \sqrt{(T'_1/\mu_x)^2+(T'_2/\mu_y)^2}` (no normal slip, (1.10)).
    Dissipation (1.12) :math:`D = N\sqrt{(\mu_x v'_1)^2 + (\mu_y v'_2)^2}`, inverse relation
    (1.13), force angle (1.14) :math:`\tan\theta'/\tan\beta' = \mu_x^2/\mu_y^2`, directional
    coefficient (1.15).

    Parameters
    ----------
    mu_x, mu_y : float
        Friction coefficients along the principal axes (> 0).
    angle : float
        Angle of principal axis 1 from x, radians, in [-pi, pi].
    """

    mu_x: float = _coefficient("1")
    mu_y: float = _coefficient("2")
    angle: float = _ANGLE
    capabilities = frozenset({"symbolic", "cone"})

    def declared_traits(self) -> LawTraits:
        """An elliptic cone with in-plane normality and no normal slip."""
        return LawTraits(degree=1.0, slip_degree=0.0, normal_slip=False,
                         tangentially_associated=True, tangent_coupling=False, convex=True)

    def potential(self, T, N, q=None):
        T, N = self._local(T, N)
        return self._rho(T) + 0.0 * N

    def potential_gradient(self, T, N, q=None):
        grad = self.limit_gradient(T, N)
        grad[..., 2] = 0.0
        return grad

    def cone(self, q=None) -> Cone:
        """The elliptic cone (1.9) with tangential normality and no normal slip."""
        return Cone(self.mu_x, self.mu_y, self.angle, 0.0)

    def slip_direction(self, T, N, q=None):
        r"""(1.10) normalized: the factor 1/rho of the gradient cancels, so the slip is the unit
        vector along :math:`R(\text{angle})(T'_1/\mu_x^2, T'_2/\mu_y^2)` with no normal part."""
        T, N = self._local(T, N)
        mx, my = self._m
        shape = np.broadcast_shapes(T.shape[:-1], N.shape)
        ga, gb = T[..., 0] * (1.0 / mx**2), T[..., 1] * (1.0 / my**2)
        inv = safe_ratio(1.0, np.sqrt(ga * ga + gb * gb))
        ga *= inv
        gb *= inv
        v = np.zeros(shape + (3,))
        v[..., :2] = rotate(np.stack((ga, gb), axis=-1), self.angle)
        return v

    def symbolic_form(self):
        from .symbols import N
        params, f, _ = self._symbolic_limit()
        return self._form(f, f + N, params)

    def _local_force(self, c, s):
        """(1.13) per unit N: :math:`T' = (\\mu_x^2 c, \\mu_y^2 s)/\\sqrt{(\\mu_x c)^2+(\\mu_y s)^2}`."""
        mx, my = self._m
        den = np.sqrt((mx * c) ** 2 + (my * s) ** 2)
        return np.stack((mx**2 * c / den, my**2 * s / den), axis=-1)


@dataclass(frozen=True)
class TransformedCoulomb(_EllipseLimit):
    r"""The transformed-variable law (1.17)–(1.18): Coulomb applied to :math:`T'_i/\mu_i`.

    Limit: the ellipse of (1.9). Slip (1.18): :math:`v' \parallel (T'_1/\mu_x, T'_2/\mu_y)`,
    i.e. the potential :math:`g = \sqrt{T_1'^2/\mu_x + T_2'^2/\mu_y}` — not normal to the
    limit curve. Directional coefficient (1.17) :math:`\mu(\theta') = \sqrt{\mu_x^2\cos^2\theta'
    + \mu_y^2\sin^2\theta'}`.
    """

    mu_x: float = _coefficient("1")
    mu_y: float = _coefficient("2")
    angle: float = _ANGLE
    capabilities = frozenset({"symbolic"})

    def declared_traits(self) -> LawTraits:
        """The elliptic cone of (1.9) with the slip (1.18), normal to it only when it is a
        circle."""
        return LawTraits(degree=1.0, slip_degree=0.0, normal_slip=False,
                         tangentially_associated=self.mu_x == self.mu_y, tangent_coupling=False,
                         convex=True)

    def potential(self, T, N, q=None):
        T, N = self._local(T, N)
        mx, my = self._m
        return np.hypot(T[..., 0] / np.sqrt(mx), T[..., 1] / np.sqrt(my)) + 0.0 * N

    def potential_gradient(self, T, N, q=None):
        T, N = self._local(T, N)
        mx, my = self._m
        g = np.hypot(T[..., 0] / np.sqrt(mx), T[..., 1] / np.sqrt(my))
        return self._global_gradient(safe_ratio(T[..., 0] / mx, g), safe_ratio(T[..., 1] / my, g),
                                     0.0 * N)

    def symbolic_form(self):
        import sympy
        params, f, (a, b) = self._symbolic_limit()
        mx, my, _ = params
        return self._form(f, sympy.sqrt(a**2 / mx + b**2 / my), params)

    def _local_force(self, c, s):
        """(1.18) per unit N: :math:`T' = (\\mu_x c, \\mu_y s)`."""
        mx, my = self._m
        return np.stack((mx * c, my * s), axis=-1)


@dataclass(frozen=True)
class Huber(_Orthotropic):
    r"""Huber's orthotropic friction (1.16): force along the slip, of magnitude
    :math:`\mu(\theta') N` with :math:`\mu(\theta') = \mu_1\cos^2\theta' + \mu_2\sin^2\theta'`.

    Limit :math:`f = |T| - N(\mu_1 T_1'^2 + \mu_2 T_2'^2)/|T|^2` (the polar curve
    :math:`|T| = N\mu(\beta')`, with :math:`\beta' = \theta'`); potential :math:`g = |T|`.
    At ``T = 0`` the limit takes the value :math:`-N\min(\mu_1, \mu_2)` and the tangential
    gradient the minimal-norm subgradient 0.

    Parameters
    ----------
    mu_1, mu_2 : float
        Friction coefficients along the principal axes (> 0).
    angle : float
        Angle of principal axis 1 from x, radians, in [-pi, pi].
    """

    mu_1: float = _coefficient("1")
    mu_2: float = _coefficient("2")
    angle: float = _ANGLE
    _m_names = ("mu_1", "mu_2")
    capabilities = frozenset({"symbolic"})

    def declared_traits(self) -> LawTraits:
        r"""A cone with the slip along T. The polar curve :math:`r = A + B\cos 2\theta'`
        (:math:`A = (\mu_1 + \mu_2)/2`, :math:`B = (\mu_1 - \mu_2)/2`) is convex where
        :math:`r^2 + 2r'^2 - rr'' = A^2 + 6ABc - 3B^2c^2 + 8B^2 \ge 0` for
        :math:`c = \cos 2\theta' \in [-1, 1]`; the minimum, at :math:`c = \pm 1`, is
        :math:`(A - |B|)(A - 5|B|)`: convex when :math:`\max(\mu_1, \mu_2) \le 1.5\min(\mu_1, \mu_2)`."""
        m1, m2 = self._m
        return LawTraits(degree=1.0, slip_degree=0.0, normal_slip=False,
                         tangentially_associated=m1 == m2, tangent_coupling=False,
                         convex=max(m1, m2) <= 1.5 * min(m1, m2))

    def _mu_of_force(self, T):
        """μ(β') of the force's direction and |T| (from the unit direction: no overflow of the
        squares of a huge force)."""
        m1, m2 = self._m
        rho = np.hypot(T[..., 0], T[..., 1])
        c, s = safe_ratio(T[..., 0], rho), safe_ratio(T[..., 1], rho)
        return np.where(rho > 0, m1 * c * c + m2 * s * s, min(m1, m2)), rho

    def limit(self, T, N, q=None):
        T, N = self._local(T, N)
        mu, rho = self._mu_of_force(T)
        return rho - mu * N

    def limit_gradient(self, T, N, q=None):
        T, N = self._local(T, N)
        m1, m2 = self._m
        mu, rho = self._mu_of_force(T)
        a, b = safe_ratio(T[..., 0], rho), safe_ratio(T[..., 1], rho)
        k = safe_ratio(2.0 * N * (m1 - m2) * a * b, rho)
        return self._global_gradient(a - k * b, b + k * a, -mu)

    def potential(self, T, N, q=None):
        T, N = self._inputs(T, N)
        return np.hypot(T[..., 0], T[..., 1]) + 0.0 * N

    def potential_gradient(self, T, N, q=None):
        T, N = self._inputs(T, N)
        rho = np.hypot(T[..., 0], T[..., 1])
        zero = 0.0 * (rho + N)
        return np.stack((safe_ratio(T[..., 0], rho) + zero, safe_ratio(T[..., 1], rho) + zero, zero),
                        axis=-1)

    def symbolic_form(self):
        import sympy

        from .symbols import N, T1, T2
        params, (a, b) = self._symbols()
        m1, m2, _ = params
        rho = sympy.sqrt(T1**2 + T2**2)
        return self._form(rho - N * (m1 * a**2 + m2 * b**2) / (T1**2 + T2**2), rho, params)

    def _local_force(self, c, s):
        """(1.16) per unit N: :math:`T' = \\mu(\\theta')(c, s)`."""
        m1, m2 = self._m
        mu = m1 * c**2 + m2 * s**2
        return np.stack((mu * c, mu * s), axis=-1)
