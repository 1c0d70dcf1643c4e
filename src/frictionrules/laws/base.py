r"""The law protocol: what every friction law, built-in or user-defined, offers.

A law is a frozen dataclass of parameters (no history). All methods are pure and vectorized
over leading dimensions: ``T`` has shape ``(..., 2)`` (tangential force in the contact frame),
``N`` shape ``(...)`` (normal force, compression positive) and a slip ``v`` shape ``(..., 3)``
``(v1, v2, vn)`` or ``(..., 2)``, with ``vn > 0`` on opening (see ``docs/conventions.md``).

The generalized force conjugate to the generalized slip ``(v1, v2, vn)`` is ``(T1, T2, -N)``,
so the power of the contact forces is :math:`D = T\cdot v_t - N v_n` ((1.7), (1.12)) and the
sliding rule ((1.1)–(1.2), (2.7)) reads

.. math:: v = \dot\lambda\,\Bigl(\frac{\partial g}{\partial T_1},
          \frac{\partial g}{\partial T_2}, -\frac{\partial g}{\partial N}\Bigr),
          \quad \dot\lambda \ge 0 .

A potential is defined up to an additive constant (the paper's ``- C`` in (2.6), (2.14)):
only its gradient matters, and ``potential`` returns it without the constant.
"""

from __future__ import annotations

import abc
from dataclasses import dataclass

import numpy as np

from ..errors import FrictionRulesError, check_finite, check_nonnegative, check_vectors

__all__ = ["FrictionLaw", "RuleComparison", "compare_rules"]


def rotate(v: np.ndarray, angle: float) -> np.ndarray:
    """Rotate the 2-vectors ``v[..., :2]`` counter-clockwise by ``angle`` (radians)."""
    if angle == 0.0:
        return v
    c, s = np.cos(angle), np.sin(angle)
    x, y = v[..., 0], v[..., 1]
    return np.stack((c * x - s * y, s * x + c * y), axis=-1)


def safe_ratio(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``a / b`` where ``b > 0`` and 0 where ``b == 0``: the minimal-norm subgradient at a kink."""
    a, b = np.broadcast_arrays(a, b)
    return np.divide(a, b, out=np.zeros(a.shape), where=b > 0)


def as_force(T) -> np.ndarray:
    return check_vectors("T", T, (2,))


def as_slip(v) -> np.ndarray:
    v = check_vectors("v", v, (2, 3))
    if np.any(np.hypot(v[..., 0], v[..., 1]) == 0):
        raise FrictionRulesError("v has a zero tangential part: the slip direction is undefined "
                                 "(constraint: v1**2 + v2**2 > 0)")
    return v


def unit3(grad: np.ndarray) -> np.ndarray:
    """Generalized slip direction from a gradient ``(dg/dT1, dg/dT2, dg/dN)``, normalized.

    Returns zeros where the gradient vanishes (no preferred direction, e.g. the minimal-norm
    subgradient of ``|T|`` at ``T = 0``).
    """
    v = np.stack((grad[..., 0], grad[..., 1], 0.0 - grad[..., 2]), axis=-1)
    norm = np.sqrt(v[..., 0] ** 2 + v[..., 1] ** 2 + v[..., 2] ** 2)
    v *= safe_ratio(1.0, norm)[..., None]
    return v


class FrictionLaw(abc.ABC):
    """Interface of a friction law: limit condition f, sliding potential g and what follows.

    Subclasses are frozen dataclasses holding parameters only. A subclass implements
    :meth:`limit`, :meth:`potential`, their gradients and :meth:`symbolic`; everything else
    has a generic implementation here that a subclass may replace with a closed form (the
    tests compare the two).

    Notes
    -----
    ``limit`` is negative inside (stick), zero on the limit surface, positive outside.
    The normal argument is called ``N``; for laws in external loads (e.g. the wedge asperity)
    the vertical load ``Q`` takes its place with the same sign convention.
    """

    #: Name of the normal-force argument in messages (``"N"`` or ``"Q"``).
    normal_name = "N"

    # ---- what a law must provide -------------------------------------------------------
    @abc.abstractmethod
    def limit(self, T, N) -> np.ndarray:
        """Limit condition f(T, N): < 0 stick, 0 limit surface, > 0 inadmissible."""

    @abc.abstractmethod
    def potential(self, T, N) -> np.ndarray:
        """Sliding potential g(T, N), up to an additive constant."""

    @abc.abstractmethod
    def limit_gradient(self, T, N) -> np.ndarray:
        """``(df/dT1, df/dT2, df/dN)``, shape ``(..., 3)``."""

    @abc.abstractmethod
    def potential_gradient(self, T, N) -> np.ndarray:
        """``(dg/dT1, dg/dT2, dg/dN)``, shape ``(..., 3)``."""

    @abc.abstractmethod
    def symbolic(self):
        """``(f, g)`` as SymPy expressions in the symbols ``T1, T2, N`` of :mod:`frictionrules`.

        The derived (symbolic, then compiled) derivatives come from these; the tests compare
        every hand-written gradient with them.
        """

    # ---- properties ----------------------------------------------------------------------
    @property
    def associated(self) -> bool:
        """True when g = f in the full space (T1, T2, N): normality including the normal slip."""
        return False

    @property
    def tangentially_associated(self) -> bool:
        """True when the tangential slip is normal to the limit curve at fixed N."""
        return self.associated

    # ---- derived quantities --------------------------------------------------------------
    def limit_hessian(self, T, N) -> np.ndarray:
        """Second derivatives of f in ``(T1, T2, N)``, shape ``(..., 3, 3)``, derived symbolically.

        Undefined (non-finite) at kinks of f such as the cone apex ``T = 0``.
        """
        from ._derived import compiled
        T, N = self._inputs(T, N)
        return compiled(self).hess_f(T[..., 0], T[..., 1], N)

    def potential_hessian(self, T, N) -> np.ndarray:
        """Second derivatives of g in ``(T1, T2, N)``, shape ``(..., 3, 3)``, derived symbolically."""
        from ._derived import compiled
        T, N = self._inputs(T, N)
        return compiled(self).hess_g(T[..., 0], T[..., 1], N)

    def slip_direction(self, T, N) -> np.ndarray:
        r"""Unit generalized slip ``(v1, v2, vn)`` of the sliding rule at ``(T, N)``.

        .. math:: v = \frac{(g_{,T_1},\, g_{,T_2},\, -g_{,N})}{|(g_{,T_1},\, g_{,T_2},\, -g_{,N})|}

        ((1.2), (2.7)); ``vn > 0`` is opening (dilatancy). Where g has a kink with a zero
        minimal-norm subgradient (``T = 0`` of a cone with no normal slip) the result is 0.
        """
        return unit3(self.potential_gradient(T, N))

    def normal_direction(self, T, N) -> np.ndarray:
        """Unit outward normal of the limit surface in ``(T1, T2, -N)``: the associated slip."""
        return unit3(self.limit_gradient(T, N))

    def force_for_slip(self, v, N) -> np.ndarray:
        """Tangential force on the limit surface whose slip is along the tangential part of ``v``.

        The inverse of the sliding rule ((1.8), (1.13)). For associated-in-plane laws it is
        ``dD/dv``. The generic method scans the limit curve at fixed ``N`` (star-shaped about
        :meth:`centre`) for the points whose tangential slip direction equals that of ``v``
        and refines them by bracketing; when more than one point slides in that direction
        (possible for non-associated or non-convex laws) the one with the smallest ``|T|`` is
        returned. Raises :class:`FrictionRulesError` where no point slides that way.

        Parameters
        ----------
        v : array (..., 2) or (..., 3)
            Slip; only its tangential direction is used.
        N : array (...)
            Normal force (compression positive).

        Returns
        -------
        T : array (..., 2)
        """
        v = as_slip(v)
        theta = np.arctan2(v[..., 1], v[..., 0])
        return self._force_at_angle(theta, self._normal(N))

    def dissipation(self, v, N) -> np.ndarray:
        r"""Power of the contact forces on the slip ``v``: :math:`D = T\cdot v_t - N v_n`.

        ``T = force_for_slip(v, N)`` ((1.7), (1.12)). For a 2-component ``v`` the normal slip is
        the one the sliding rule implies at ``T``; for a 3-component ``v`` its ``vn`` is used.
        """
        v = as_slip(v)
        N = self._normal(N)
        T = self.force_for_slip(v, N)
        vt = v[..., :2]
        if v.shape[-1] == 3:
            vn = v[..., 2]
        else:
            s = self.slip_direction(T, N)
            vn = np.hypot(vt[..., 0], vt[..., 1]) * safe_ratio(s[..., 2], np.hypot(s[..., 0], s[..., 1]))
        return np.sum(T * vt, axis=-1) - N * vn

    def friction_coefficient(self, theta, N=1.0) -> np.ndarray:
        r"""Directional friction coefficient :math:`\mu(\theta) = |T|/N` ((1.15)).

        ``T`` is the force on the limit surface that makes the contact slide at angle
        ``theta`` (radians, from the x axis). Returns ``inf`` where no finite force slides
        that way (self-locking).
        """
        N = self._normal(N)
        theta = check_finite("theta", theta)
        try:
            T = self._force_at_angle(theta, N)
        except _Locked as exc:
            T = exc.T
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.hypot(T[..., 0], T[..., 1]) / N

    def force_angle(self, theta, N=1.0) -> np.ndarray:
        """Angle beta of the force that makes the contact slide at angle ``theta`` ((1.14))."""
        theta = check_finite("theta", theta)
        T = self._force_at_angle(theta, self._normal(N))
        return np.arctan2(T[..., 1], T[..., 0])

    def centre(self, N) -> np.ndarray:
        """A point inside the limit curve at fixed N, about which the curve is star-shaped."""
        N = np.asarray(N, dtype=float)
        return np.zeros(N.shape + (2,))

    # ---- helpers for subclasses ----------------------------------------------------------
    def _normal(self, N) -> np.ndarray:
        return check_nonnegative(self.normal_name, N)

    def _inputs(self, T, N) -> tuple[np.ndarray, np.ndarray]:
        return as_force(T), self._normal(N)

    def _force_at_angle(self, theta: np.ndarray, N: np.ndarray) -> np.ndarray:
        """Force on the limit surface sliding at tangential angle ``theta``; numeric default."""
        from ._inverse import force_at_slip_angle
        return force_at_slip_angle(self, theta, N)


class _Locked(FrictionRulesError):
    """No finite force slides in the requested direction; ``T`` holds the masked result."""

    def __init__(self, message: str, T: np.ndarray):
        super().__init__(message)
        self.T = T


@dataclass(frozen=True)
class RuleComparison:
    """Associated direction (normal to f) against a law's actual slip, at the same forces.

    Attributes
    ----------
    associated : (..., 3) unit normal of f in ``(T1, T2, -N)`` ((2.5) in the sliding plane).
    actual : (..., 3) unit slip of the law's potential g ((2.4)).
    angle : (...) angle between the two 3-vectors, radians.
    tangential_angle : (...) angle between their tangential parts (the sliding plane).
    """

    associated: np.ndarray
    actual: np.ndarray
    angle: np.ndarray
    tangential_angle: np.ndarray


def _angle_between(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    cross = np.linalg.norm(np.cross(a, b), axis=-1) if a.shape[-1] == 3 else np.abs(
        a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0])
    return np.arctan2(cross, np.sum(a * b, axis=-1))


def compare_rules(law: FrictionLaw, T, N) -> RuleComparison:
    """Compare the associated direction (normal to f) with the law's slip at ``(T, N)``.

    For the wedge asperity this is (2.5) against (2.4): the associated ratio ``Vx/Vy`` and the
    actual one differ unless ``mu = 0``.
    """
    assoc = law.normal_direction(T, N)
    actual = law.slip_direction(T, N)
    return RuleComparison(assoc, actual, _angle_between(assoc, actual),
                          _angle_between(assoc[..., :2], actual[..., :2]))
