"""Methods shared by :class:`CylinderOnLayer` and :class:`SphereOnLayer` (private base)."""

from __future__ import annotations

import numpy as np

from ..errors import FrictionRulesError, check_scalar
from ..laws.base import rotate
from ..laws.coulomb import Coulomb
from ..laws.wedge import WedgeAsperity
from . import path as _path
from .geometry import Layer
from .state import ForceControlResult, GrainState, PathResult, PeakForcePolar

METHODS = ("exact", "incremental")


class GrainOnLayer:
    """Shared implementation; subclasses are frozen dataclasses with ``diameter, mu, Q``."""

    def _check(self):
        object.__setattr__(self, "diameter", check_scalar("diameter", self.diameter, lo=0.0,
                                                          lo_open=True))
        object.__setattr__(self, "mu", check_scalar("mu", self.mu, lo=0.0))
        object.__setattr__(self, "Q", check_scalar("Q", self.Q, lo=0.0, lo_open=True))

    @property
    def layer(self) -> Layer:
        raise NotImplementedError

    # ---- configuration ---------------------------------------------------------------------
    def state_at(self, position, direction: float = 0.0) -> GrainState:
        """Configuration at horizontal ``position`` for a motion along ``direction`` (radians)."""
        return _path.state_at(self, position, check_scalar("direction", direction))

    def rest_state(self, direction: float = 0.0) -> GrainState:
        """Configuration in the pocket (the origin) for a motion along ``direction``."""
        return self.state_at((0.0, 0.0), direction)

    def contact_law(self, state: GrainState, k: int = 0):
        r"""The core law of contact ``k``: ``WedgeAsperity(alpha, mu)`` (``Coulomb(mu)`` on the top)
        acting on the force in the contact frame, ``rotate(T, -psi)`` ((3.11)).

        A negative (cylinder) inclination ``alpha`` is the wedge ``pi + alpha``: the same limit
        condition with the up-slope direction reversed.
        """
        a = state.alpha[k]
        if a == 0.0:
            return Coulomb(self.mu)
        return WedgeAsperity(a if a > 0 else np.pi + a, self.mu)

    def limit(self, T, state: GrainState, k: int = 0) -> np.ndarray:
        """Limit condition (2.2) of contact ``k`` with the configuration ``state``, (3.1);
        ``T`` is the horizontal force ``(..., 2)`` in the x, y frame."""
        T = np.asarray(T, dtype=float)
        return self.contact_law(state, k).limit(rotate(T, -state.psi[k]), np.full(T.shape[:-1], self.Q))

    def limit_curve(self, state: GrainState, k: int = 0, n: int = 361) -> np.ndarray:
        r"""Points ``(m, 2)`` of the limit curve f = 0 of contact ``k`` in the ``(Tx, Ty)`` plane.

        Parametrized by the in-plane force direction :math:`\varphi`:
        :math:`N = Q/(\cos\alpha - \mu\cos\varphi\sin\alpha)`,
        :math:`T' = N(\sin\alpha + \mu\cos\varphi\cos\alpha,\ \mu\sin\varphi)`, rotated by psi;
        the open branches of a hyperbola are cut where ``|T| > 20 Q``.
        """
        a, p = state.alpha[k], state.psi[k]
        phi = np.linspace(-np.pi, np.pi, n)
        den = np.cos(a) - self.mu * np.cos(phi) * np.sin(a)
        ok = den > np.cos(a) * 1e-3
        N = self.Q / den[ok]
        Tp = np.stack((N * (np.sin(a) + self.mu * np.cos(phi[ok]) * np.cos(a)),
                       self.mu * N * np.sin(phi[ok])), axis=-1)
        T = rotate(Tp, p)
        return T[np.hypot(T[:, 0], T[:, 1]) <= 20 * self.Q]

    # ---- path following ----------------------------------------------------------------------
    def displacement_path(self, path, method: str = "exact", scheme: str = "euler") -> PathResult:
        """Displacement control along the horizontal trajectory ``path`` ``(n, 2)``.

        ``method="exact"``: geometry and equilibrium at every point;
        ``method="incremental"``: the rate relations (3.3)–(3.13) with the consistency
        condition (3.5), integrated with ``scheme`` ``"euler"`` (order 1) or ``"heun"`` (order 2).
        See :mod:`frictionrules.configuration.path`.
        """
        if method not in METHODS:
            raise FrictionRulesError(f"method = {method!r} violates method in {METHODS}")
        if method == "exact":
            return _path.exact_path(self, path)
        return _path.incremental_path(self, path, scheme)

    def straight_path(self, direction: float = 0.0, length: float | None = None,
                      n: int = 201) -> np.ndarray:
        """Points ``(n, 2)`` of a straight trajectory from the pocket along ``direction``
        (radians), ``length`` defaulting to one diameter."""
        length = self.diameter if length is None else check_scalar("length", length, lo=0.0,
                                                                   lo_open=True)
        if int(n) < 2:
            raise FrictionRulesError(f"n = {n!r} violates n >= 2")
        s = np.linspace(0.0, length, int(n))
        return np.stack((s * np.cos(direction), s * np.sin(direction)), axis=-1)

    def breakout_force(self, directions) -> PeakForcePolar:
        """Peak force to push the grain out of its pocket by a force along each of ``directions``
        (radians), and whether it climbs over one or two layer grains; see :mod:`.pockets`."""
        from .pockets import breakout_force
        return breakout_force(self, directions)

    def force_path(self, forces, state: GrainState | None = None) -> ForceControlResult:
        """Force control ((3.7), (3.13)) from ``state`` (default: the pocket, moving along the
        first nonzero force); reports the limit point. See :func:`.path.force_path`."""
        forces = np.asarray(forces, dtype=float)
        if state is None:
            nz = np.flatnonzero(np.hypot(forces[..., 0], forces[..., 1]) > 0) if forces.ndim == 2 else []
            direction = float(np.arctan2(*forces[nz[0]][::-1])) if len(nz) else 0.0
            state = self.rest_state(direction)
        return _path.force_path(self, forces, state)
