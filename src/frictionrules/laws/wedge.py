r"""A rigid block on a plane inclined at ``alpha``: the wedge asperity of §2, (2.1)–(2.8).

Frame (Fig. 2): x, y horizontal, z up; the plane contains the y axis and its line of greatest
slope :math:`t_1 = (\cos\alpha, 0, \sin\alpha)` points up-slope. For ``alpha < pi/2`` the plane
rises towards +x, for ``alpha > pi/2`` towards -x (slope ``pi - alpha``). The block is loaded by
:math:`F = (T_x, T_y, -Q)` (``Q > 0`` presses it down) and rests on the plane through the
upward unit normal :math:`n = \sigma(-\sin\alpha, 0, \cos\alpha)`, :math:`\sigma =
\operatorname{sign}\cos\alpha`.

Equilibrium (2.1) gives the forces on the plane

.. math:: T_1 = T_x\cos\alpha - Q\sin\alpha,\qquad T_2 = T_y,\qquad
          N = \sigma(T_x\sin\alpha + Q\cos\alpha),

and local Coulomb friction :math:`\sqrt{T_1^2 + T_2^2} \le \mu N` gives the global limit
condition (2.2) (written here in its degree-one form, whose zero set is the physical nappe
``N > 0`` of the quadric (2.2)).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import FrictionRulesError, check_finite
from ._params import parameter
from ._records import InverseRelation
from ._traits import LawTraits
from .base import FrictionLaw, safe_ratio

__all__ = ["WedgeAsperity"]

_LOCALS = ("non-associated", "associated")


@dataclass(frozen=True)
class WedgeAsperity(FrictionLaw):
    r"""Block on an inclined plane with local Coulomb friction, as a law in external loads.

    The protocol's normal argument is the vertical load ``Q`` (compression positive) and the
    tangential force is the horizontal load ``T = (Tx, Ty)``; the generalized slip is the block
    velocity ``(Vx, Vy, Vz)`` with ``Vz > 0`` upwards.

    * limit (2.2): :math:`f = \sqrt{T_1^2 + T_2^2} - \mu N`;
    * ``local="non-associated"`` (the paper's case): potential (2.6)
      :math:`g = \sqrt{T_1^2 + T_2^2}`, slip (2.3)/(2.7)
      :math:`V = \dot\lambda\,(e_1\cos\alpha, e_2, e_1\sin\alpha)`, :math:`e = (T_1, T_2)/|\cdot|`;
      the horizontal slip is not normal to the limit curve ((2.4) against (2.5));
    * ``local="associated"``: the dilatant local rule (1.6), g = f, which adds the separation
      :math:`\dot\lambda\mu n`; the global rule is then associated.

    Outside the domain ``N > 0`` the block leaves the plane: ``limit`` is positive there (the
    load cannot be carried) and ``slip_direction`` raises :class:`FrictionRulesError`.

    Parameters
    ----------
    alpha : float
        Inclination of the plane, radians, in (0, pi).
    mu : float
        Local friction coefficient, ``mu >= 0``; :math:`\varrho = \arctan\mu`.
    local : {"non-associated", "associated"}
        Local sliding rule.
    """

    alpha: float = parameter("inclination of the plane", "rad", lo=0.0, hi=np.pi, lo_open=True,
                             hi_open=True)
    mu: float = parameter("local friction coefficient", lo=0.0)
    local: str = parameter("local sliding rule", kind=str, choices=_LOCALS,
                           default="non-associated")
    normal_name = "Q"
    capabilities = frozenset({"symbolic"})

    def declared_traits(self) -> LawTraits:
        """Local Coulomb through the linear map (2.1): a convex cone of degree one in the loads,
        whose slip lifts the block (2.8); in-plane normality with the associated local rule
        (or ``mu = 0``) only, (2.4) against (2.5)."""
        return LawTraits(degree=1.0, slip_degree=0.0, normal_slip=True,
                         tangentially_associated=self.associated or self.mu == 0.0,
                         tangent_coupling=False, convex=True)

    # ---- geometry --------------------------------------------------------------------------
    @property
    def _cs(self) -> tuple[float, float, float]:
        c, s = np.cos(self.alpha), np.sin(self.alpha)
        return c, s, (1.0 if c >= 0 else -1.0)

    @property
    def associated(self) -> bool:
        return self.local == "associated"

    def plane_forces(self, T, Q) -> np.ndarray:
        """``(T1, T2, N)`` on the plane for the loads ``(T, Q)``, (2.1); shape ``(..., 3)``."""
        T, Q = self._inputs(T, Q)
        c, s, sig = self._cs
        tx, ty = np.broadcast_arrays(T[..., 0], T[..., 1], Q)[:2]
        return np.stack((tx * c - Q * s, ty + 0.0 * Q, sig * (tx * s + Q * c)), axis=-1)

    def normal_force(self, T, Q) -> np.ndarray:
        """Normal force on the plane, :math:`N = \\sigma(T_x\\sin\\alpha + Q\\cos\\alpha)` (2.1)."""
        return self.plane_forces(T, Q)[..., 2]

    def conic(self) -> str:
        r"""Shape of the limit curve at fixed Q > 0: ``"ellipse"`` when
        :math:`\alpha' + \varrho < \pi/2`, ``"parabola"`` when equal, ``"hyperbola"`` when greater,
        with :math:`\alpha' = \min(\alpha, \pi - \alpha)` (sign of the :math:`T_x^2` coefficient
        :math:`\cos^2\alpha - \mu^2\sin^2\alpha` of (2.2))."""
        c, s, _ = self._cs
        a = c**2 - self.mu**2 * s**2
        if abs(a) <= 1e-12 * (c**2 + self.mu**2 * s**2):
            return "parabola"
        return "ellipse" if a > 0 else "hyperbola"

    def centre(self, Q, q=None) -> np.ndarray:
        """Load on the cone axis (no in-plane force): ``(Q tan(alpha), 0)``, the centre of the
        potential ellipse (2.6); for a vertical plane a point inside the limit curve."""
        Q = np.asarray(Q, dtype=float)
        c, s, _ = self._cs
        tx = Q * s / c if abs(c) > 1e-12 else 2.0 * Q / max(self.mu, 1e-300)
        return np.stack(np.broadcast_arrays(tx, 0.0 * Q), axis=-1)

    def limit_point(self, phi, Q=1.0) -> np.ndarray:
        r"""Load ``(Tx, Ty)`` on the limit surface whose in-plane force is
        :math:`(T_1, T_2) = \mu N (\cos\varphi, \sin\varphi)`, from (2.1):

        .. math:: N = \frac{Q}{|\cos\alpha| - \mu\cos\varphi\sin\alpha},\quad
                  T_x = N(\sigma\sin\alpha + \mu\cos\varphi\cos\alpha),\quad
                  T_y = \mu N\sin\varphi .

        ``inf`` where the denominator is not positive (no such point: the block would need a
        tensile normal force; at the asymptotic direction of a parabola or hyperbola it vanishes).
        """
        phi, Q = np.broadcast_arrays(check_finite("phi", phi), self._normal(Q))
        c, s, sig = self._cs
        den = abs(c) - self.mu * np.cos(phi) * s
        ok = den > 1e-12 * (abs(c) + self.mu * s)  # round-off at the parabola's vertex direction
        n = Q / np.where(ok, den, 1.0)
        T = np.stack((n * (sig * s + self.mu * np.cos(phi) * c), self.mu * n * np.sin(phi)), axis=-1)
        T[~ok] = np.inf
        return T

    def limit_curve(self, Q=1.0, num: int = 721, max_load: float = 10.0) -> np.ndarray:
        """Points ``(Tx, Ty)`` of the limit curve at fixed ``Q``, ordered by the in-plane force
        angle in [0, 2 pi] (see :meth:`limit_point`). Unbounded branches (parabola, hyperbola),
        which open around the up-slope angle 0, are cut where ``|T| > max_load * Q``, so the
        points form one arc. Returns an array of shape ``(m, 2)``, ``m <= num``.
        """
        Q = float(self._normal(Q))
        T = self.limit_point(np.linspace(0.0, 2.0 * np.pi, num), Q)
        return T[np.hypot(T[:, 0], T[:, 1]) <= max_load * max(Q, 1e-300)]

    # ---- protocol --------------------------------------------------------------------------
    def limit(self, T, Q, q=None):
        t1, t2, n = np.moveaxis(self.plane_forces(T, Q), -1, 0)
        return np.hypot(t1, t2) - self.mu * n

    def potential(self, T, Q, q=None):
        t1, t2, n = np.moveaxis(self.plane_forces(T, Q), -1, 0)
        return np.hypot(t1, t2) - (self.mu * n if self.associated else 0.0)

    def _gradient(self, T, Q, friction: bool):
        t1, t2, _ = np.moveaxis(self.plane_forces(T, Q), -1, 0)
        c, s, sig = self._cs
        norm = np.hypot(t1, t2)
        e1, e2 = safe_ratio(t1, norm), safe_ratio(t2, norm)
        m = self.mu * sig if friction else 0.0
        return np.stack((c * e1 - m * s, e2, -s * e1 - m * c), axis=-1)

    def limit_gradient(self, T, Q, q=None):
        return self._gradient(T, Q, True)

    def potential_gradient(self, T, Q, q=None):
        return self._gradient(T, Q, self.associated)

    def symbolic_form(self):
        """(2.2) and (2.6) in ``(T1, T2, N) = (Tx, Ty, Q)`` with the symbols ``alpha, mu``."""
        import sympy

        from ._symbolic import SymbolicLaw
        from .symbols import N, T1, T2
        alpha = sympy.Symbol("alpha", positive=True)
        mu = sympy.Symbol("mu", nonnegative=True)
        c, s = sympy.cos(alpha), sympy.sin(alpha)
        t = sympy.sqrt((T1 * c - N * s) ** 2 + T2**2)
        f = t - mu * sympy.sign(c) * (T1 * s + N * c)
        return SymbolicLaw(f, f if self.associated else t, params=(alpha, mu),
                           values=(self.alpha, self.mu))

    def slip_direction(self, T, Q, q=None):
        """Unit block velocity ``(Vx, Vy, Vz)`` (2.3), (2.7); ``Vz > 0`` upwards.

        Raises :class:`FrictionRulesError` where the normal force on the plane is negative.
        """
        n = self.normal_force(T, Q)
        if np.any(n < 0):
            bad = np.argwhere(np.atleast_1d(n) < 0)[0]
            raise FrictionRulesError(
                f"the load leaves the plane: normal force N = {np.atleast_1d(n)[tuple(bad)]!r} at "
                f"index {tuple(int(i) for i in bad)} violates N >= 0 (N = sigma*(Tx sin(alpha) + "
                f"Q cos(alpha)), (2.1))")
        return super().slip_direction(T, Q)

    def dilatancy_angle(self, T, Q) -> np.ndarray:
        r"""Dilatancy angle :math:`\nu`, :math:`\sin\nu = V_z/|V|` (2.8)."""
        return np.arcsin(np.clip(self.slip_direction(T, Q)[..., 2], -1.0, 1.0))

    # ---- inverse ---------------------------------------------------------------------------
    def _plane_angle(self, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """In-plane force angle phi that slides horizontally at ``theta``; mask of solvability."""
        c, s, sig = self._cs
        if not self.associated:
            # in-plane velocity (V1, V2) with V1 cos(alpha) = cos(theta), V2 = sin(theta)
            return np.arctan2(abs(c) * np.sin(theta), sig * np.cos(theta)), np.ones(theta.shape, bool)
        # horizontal slip (c cos(phi) - mu sig s, sin(phi)) parallel to (cos(theta), sin(theta))
        A, B, C = c * np.sin(theta), np.cos(theta), self.mu * sig * s * np.sin(theta)
        R, delta = np.hypot(A, B), np.arctan2(B, A)
        ok = np.abs(C) <= R
        acos = np.arccos(np.clip(C / np.where(R > 0, R, 1.0), -1.0, 1.0))
        phis = np.stack((-delta + acos, -delta - acos))
        along = (c * np.cos(phis) - self.mu * sig * s) * np.cos(theta) + np.sin(phis) * np.sin(theta)
        phi = np.where(along[0] >= along[1], phis[0], phis[1])
        return phi, ok & (np.max(along, axis=0) > 0)

    def _inverse_relation(self, theta, Q, q):
        """Closed-form inverse: the in-plane angle that slides at ``theta``, then
        :meth:`limit_point`. The direction locks (no finite force, ``inf``) where that point does
        not exist."""
        if abs(self._cs[0]) < 1e-9:
            return super()._inverse_relation(theta, Q, q)
        phi, ok = self._plane_angle(theta)
        T = self.limit_point(phi, Q)
        ok = ok & np.isfinite(T[..., 0])
        T[~ok] = np.inf
        return InverseRelation(T, ~ok)
