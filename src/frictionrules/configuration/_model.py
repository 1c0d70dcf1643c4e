"""Methods shared by :class:`CylinderOnLayer` and :class:`SphereOnLayer` (private base)."""

from __future__ import annotations

import dataclasses
import warnings

import numpy as np

from ..errors import FrictionRulesError, check_scalar, check_vectors
from ..laws import Coulomb
from . import path as _path
from ._contact import GrainContact, carried_at, check_contact_law, require_sliding_law
from .geometry import Layer
from .state import ForceControlResult, GrainState, PathResult, PeakForcePolar

METHODS = ("exact", "incremental")
#: Limit curves are cut where ``|T|`` exceeds this many ``Q`` (the open branches of a
#: hyperbola or parabola, (2.2) with ``alpha + rho >= pi/2``).
CURVE_CUT = 20.0


def local_law(mu, law, where: str):
    """The grain contacts' local law from the arguments ``mu`` (a number: ``Coulomb(mu)``) and
    ``law``; exactly one of them."""
    if law is None and mu is None:
        raise FrictionRulesError(f"{where}: the contact law is missing; give mu (local Coulomb "
                                 "friction) or law=")
    if law is not None and mu is not None:
        raise FrictionRulesError(f"{where}: give the contact law once, as mu = {mu!r} or as "
                                 f"law = {law!r}")
    if law is None:
        return Coulomb(check_scalar("mu", mu, lo=0.0))
    return check_contact_law(law, where)


def deprecated_load(where: str, Q) -> float:
    """The vertical load given to the constructor (deprecated), validated, with a warning."""
    warnings.warn(f"{where}(..., Q) is deprecated: the vertical load Q is a loading input; pass "
                  "Q= to the methods that need it (displacement_path, force_path, "
                  "breakout_force, limit, limit_curve, ...)", DeprecationWarning, stacklevel=3)
    return check_scalar("Q", Q, lo=0.0, lo_open=True)


class GrainOnLayer:
    """Shared implementation; subclasses are frozen dataclasses with the fields ``diameter``,
    ``law`` and ``_load`` (the vertical load given to the constructor, deprecated; ``None``)."""

    def __repr__(self) -> str:
        shown = [f"{f.name}={getattr(self, f.name)!r}" for f in dataclasses.fields(self)
                 if not f.name.startswith("_")]
        if self._load is not None:
            shown.append(f"Q={self._load!r}")
        return f"{type(self).__name__}({', '.join(shown)})"

    @property
    def layer(self) -> Layer:
        raise NotImplementedError

    @property
    def mu(self) -> float:
        """The local Coulomb coefficient of the grain contacts (a law with a ``mu``)."""
        mu = getattr(self.law, "mu", None)
        if not isinstance(mu, float):
            raise FrictionRulesError(f"{type(self).__name__}.mu: the contact law {self.law!r} "
                                     "has no friction coefficient mu; see .law")
        return mu

    @property
    def Q(self) -> float:
        """The vertical load the methods use when they are not given one: 1, or the load given
        to the constructor (deprecated)."""
        return 1.0 if self._load is None else self._load

    def load(self, Q=None) -> float:
        """The vertical load ``Q`` (``> 0``) of a computation; ``None``: :attr:`Q`."""
        return self.Q if Q is None else check_scalar("Q", Q, lo=0.0, lo_open=True)

    # ---- configuration ---------------------------------------------------------------------
    def state_at(self, position, direction: float = 0.0) -> GrainState:
        """Configuration at horizontal ``position`` for a motion along ``direction`` (radians)."""
        return _path.state_at(self, position, check_scalar("direction", direction))

    def rest_state(self, direction: float = 0.0) -> GrainState:
        """Configuration in the pocket (the origin) for a motion along ``direction``."""
        return self.state_at((0.0, 0.0), direction)

    def contact_law(self, state: GrainState, k: int = 0) -> GrainContact:
        r"""Contact ``k`` of ``state`` as a law in the grain's loads: the local law in the
        contact's frame (:class:`GrainContact`); with local Coulomb friction the wedge (2.2) of
        inclination ``alpha`` seen in the frame rotated by ``psi`` ((3.1), (3.11))."""
        return GrainContact(self.law, state.alpha[k], state.psi[k])

    def limit(self, T, state: GrainState, k: int = 0, Q=None) -> np.ndarray:
        """Limit condition of contact ``k`` of ``state`` ((3.1); (2.2) for local Coulomb
        friction) at the horizontal force ``T`` ``(..., 2)`` and the vertical load ``Q``."""
        T = check_vectors("T", T, (2,))
        return self.contact_law(state, k).limit(T, np.full(T.shape[:-1], self.load(Q)))

    def limit_curve(self, state: GrainState, k: int = 0, n: int = 361, Q=None) -> np.ndarray:
        r"""Points ``(m, 2)`` of the limit curve f = 0 of contact ``k`` in the ``(Tx, Ty)`` plane.

        Parametrized by the local slip angle: the local inverse relation gives the force per
        unit N, :math:`a = \tau_1 t_1 + \tau_2 t_2 - n`, and vertical equilibrium
        :math:`N = -Q/a_z` the load :math:`T = N a_h`. The curve starts down-slope and passes the
        up-slope direction half-way; open branches (a hyperbola or parabola) are cut where
        ``|T| > 20 Q``.
        """
        require_sliding_law(self.law, f"{type(self).__name__}.limit_curve", tangential=False)
        Q = self.load(Q)
        contact = self.contact_law(state, k)
        axes = contact.frame()
        up = np.array([0.0, 0.0, 1.0]) - axes[2, 2] * axes[2]
        phi_up = np.arctan2(up @ axes[1], up @ axes[0]) if np.linalg.norm(up) > 0 else 0.0
        phi = phi_up + np.linspace(-np.pi, np.pi, int(n))
        c = carried_at(self.law, np.broadcast_to(axes, phi.shape + (3, 3)), phi)
        ok = ~c.locked
        T = -Q * c.force[ok, :2] / c.force[ok, 2:3]
        return T[np.hypot(T[:, 0], T[:, 1]) <= CURVE_CUT * Q]

    # ---- path following ----------------------------------------------------------------------
    def displacement_path(self, path, method: str = "exact", scheme: str = "euler",
                          Q=None) -> PathResult:
        """Displacement control along the horizontal trajectory ``path`` ``(n, 2)`` under the
        vertical load ``Q``.

        ``method="exact"``: geometry and equilibrium at every point;
        ``method="incremental"``: the rate relations (3.3)–(3.13) with the consistency
        condition (3.5), integrated with ``scheme`` ``"euler"`` (order 1) or ``"heun"`` (order 2).
        See :mod:`frictionrules.configuration.path`.
        """
        if method not in METHODS:
            raise FrictionRulesError(f"method = {method!r} violates method in {METHODS}")
        if method == "exact":
            return _path.exact_path(self, path, self.load(Q))
        return _path.incremental_path(self, path, scheme, self.load(Q))

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

    def breakout_force(self, directions, Q=None) -> PeakForcePolar:
        """Peak force to push the grain out of its pocket by a force along each of ``directions``
        (radians) under the vertical load ``Q``: the limit load of the pocket's contacts as a
        facet set; see :mod:`.pockets`."""
        from .pockets import breakout_force
        return breakout_force(self, directions, self.load(Q))

    def force_path(self, forces, state: GrainState | None = None, Q=None) -> ForceControlResult:
        """Force control ((3.7), (3.13)) under the vertical load ``Q`` from ``state`` (default:
        the pocket); reports the limit point. See :func:`._force.force_path`."""
        from ._force import force_path
        return force_path(self, forces, state, self.load(Q))
