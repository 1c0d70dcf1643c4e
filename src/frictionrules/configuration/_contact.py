r"""A grain contact: a local friction law of the library acting in the contact's frame.

The §2 wedge is a local law in a tilted frame: with the frame of :mod:`._frame` the load
``F = (Tx, Ty, -Q)`` that the grain passes to one contact has the local forces
:math:`(T_1, T_2, N) = (F\cdot t_1, F\cdot t_2, -F\cdot n)` ((2.1) for ``psi = 0``), the limit
condition of the grain is the local one, :math:`f(T_1, T_2, N) \le 0` ((2.2) for local Coulomb
friction), and the grain slides with the local sliding rule mapped back,
:math:`V = \dot\lambda\,\partial g/\partial F` ((2.3), (2.7), (3.3)). Everything here is that
composition; no wedge formula is written out. The local law is any law of the protocol in
``(T, N)`` without internal variables (``Coulomb(mu)`` by default).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from ..errors import FrictionRulesError, check_scalar
from ..laws import EllipticOrthotropic, FrictionLaw, InverseRelation, require
from ._frame import frame_of_angles, local_forces

__all__ = ["GrainContact", "ContactTerms", "Carried", "Slide", "check_contact_law",
           "require_sliding_law", "carried_force", "carried_at", "slide", "contact_terms"]

#: ``a_z`` of a carried force per unit N above which the contact locks: the grain would need a
#: tensile normal force (relative to the unit normal force; round-off margin).
LOCK_TOL = 1e-12
_S = np.array([1.0, 1.0, -1.0])    # (F.t1, F.t2, F.n) -> (T1, T2, N)


def _short(law) -> str:
    text = repr(law)
    return text if len(text) <= 120 else text[:117] + "..."


def check_contact_law(law, where: str):
    """``law`` if it can be a grain contact's local law, else :class:`FrictionRulesError`."""
    if getattr(law, "capabilities", None) is None:
        raise FrictionRulesError(f"{where}: law = {law!r} violates: a friction law of "
                                 "frictionrules (a FrictionLaw)")
    if getattr(law, "normal_name", "N") != "N":
        raise FrictionRulesError(
            f"{where}: law = {_short(law)} is a law in external loads ({law.normal_name} in the "
            "place of N); constraint: a local law of the contact's forces (T, N)")
    if law.state_names:
        raise FrictionRulesError(
            f"{where}: law = {_short(law)} has the internal variables {list(law.state_names)}; "
            "constraint: a local law without internal variables")
    return law


def _per_law(fun):
    """Cache ``fun(law)`` per law (laws are frozen dataclasses; an unhashable one is not
    cached)."""
    cached = functools.lru_cache(maxsize=256)(fun)

    @functools.wraps(fun)
    def call(law):
        try:
            hash(law)
        except TypeError:
            return fun(law)
        return cached(law)
    return call


def require_sliding_law(law, where: str, tangential: bool = True) -> None:
    """Raise unless rigid grains can slide on contacts of ``law``.

    The force a contact carries for a slip is the law's inverse relation at ``N = 1`` scaled by
    ``N`` (a positively homogeneous limit condition). Path following (``tangential``) keeps the
    centres of touching grains at the distance ``d``, so a sliding contact has no normal slip
    (``dg/dN = 0``).
    """
    require(law, "symbolic", "a grain contact's sliding rule")
    traits = law.traits
    if tangential and traits.normal_slip:
        raise FrictionRulesError(
            f"{where}: law = {_short(law)} has normal slip (dg/dN != 0, a dilatant local rule); "
            "constraint: no normal slip, as rigid grains in contact keep their centres at the "
            "distance d (breakout_force accepts dilatant local laws)")
    if not traits.conical:
        raise FrictionRulesError(
            f"{where}: law = {_short(law)}: f is not positively homogeneous in (T, N) with a "
            "slip direction of degree zero; constraint: a limit curve at N that is N times the "
            "one at N = 1 (a conical law)")


@dataclass(frozen=True)
class Carried:
    """Force a sliding contact passes to its layer grain, per unit normal force.

    ``force`` (..., 3) is :math:`\\tau_1 t_1 + \\tau_2 t_2 - n`, ``tau`` the law's inverse
    relation at ``N = 1``; ``locked`` (...) marks slips no finite force produces (the law locks,
    or the contact would need a tensile normal force to carry the vertical load).
    """

    force: np.ndarray
    locked: np.ndarray


def carried_force(law, axes: np.ndarray, V) -> Carried:
    """The force per unit N of contacts with the frames ``axes`` (..., 3, 3) sliding with the
    grain velocity ``V`` (..., 3) (in their tangent planes): the inverse relation (1.8), (1.13)
    of the local law at the slip angle :math:`\\arctan(V\\cdot t_2 / V\\cdot t_1)`."""
    v = np.einsum("...ij,...j->...i", axes, np.asarray(V, dtype=float))
    return carried_at(law, axes, np.arctan2(v[..., 1], v[..., 0]))


@_per_law
def _inverse_of(law):
    """The law whose inverse relation a contact uses: for a law declaring the capability
    ``"cone"`` without normal slip, its elliptic cone (the closed form (1.13) of
    :class:`frictionrules.EllipticOrthotropic`, the same tangential sliding rule); otherwise the
    law itself (a closed form, or the numeric inverse of the protocol)."""
    if "cone" in law.capabilities:
        c = law.cone()
        if c.dilatancy == 0.0 and min(c.mu_x, c.mu_y) > 0:
            return EllipticOrthotropic(c.mu_x, c.mu_y, c.angle)
    return law


def carried_at(law, axes: np.ndarray, phi) -> Carried:
    """:func:`carried_force` for the local slip angles ``phi`` (from ``t1`` towards ``t2``)."""
    inv = _inverse_of(law).inverse_relation(phi, 1.0)
    tau = np.where(inv.locked[..., None], 0.0, inv.force)
    a = tau[..., 0:1] * axes[..., 0, :] + tau[..., 1:2] * axes[..., 1, :] - axes[..., 2, :]
    return Carried(a, inv.locked)


def _extended(law, fun: str, grad: str, sigma: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``law.fun`` and ``law.grad`` at ``sigma``; for ``N < 0`` (a law not defined in tension)
    their extension linear in N from ``N = 0``, exact for laws linear in N (Coulomb, the
    orthotropic laws): the contact cannot carry a tensile force, ``f > 0`` there."""
    T, N = sigma[..., :2], sigma[..., 2]
    if law.defined_in_tension:
        return getattr(law, fun)(T, N), getattr(law, grad)(T, N)
    Nc = np.maximum(N, 0.0)
    gr = np.asarray(getattr(law, grad)(T, Nc), dtype=float)
    val = np.asarray(getattr(law, fun)(T, Nc), dtype=float) + np.minimum(N, 0.0) * gr[..., 2]
    return val, gr


@dataclass(frozen=True)
class GrainContact(FrictionLaw):
    r"""The local law of one grain contact in the contact's frame, as a law in the grain's loads.

    The contact plane has the inclination ``alpha`` and the up-slope azimuth ``psi`` (3.1):
    unit normal :math:`n = (-\sin\alpha\cos\psi, -\sin\alpha\sin\psi, \cos\alpha)`; the frame
    ``(t1, t2, n)`` is that of ``docs/conventions.md`` (:math:`t_1` the unit projection of x onto
    the plane). The protocol's normal argument is the vertical load ``Q`` and the tangential
    force the horizontal load ``(Tx, Ty)``; the generalized slip is the grain velocity
    ``(Vx, Vy, Vz)``, ``Vz > 0`` upwards.

    * limit: :math:`f(T, Q) = f_\ell(T_1, T_2, N)` with :math:`(T_1, T_2, N) = (F\cdot t_1,
      F\cdot t_2, -F\cdot n)`, :math:`F = (T_x, T_y, -Q)` — for ``Coulomb(mu)`` and ``psi = 0``
      the wedge limit (2.2) of :class:`frictionrules.WedgeAsperity`, with (3.11) for ``psi``;
    * sliding rule: :math:`V = \dot\lambda\,\partial g/\partial F` ((2.3), (2.7), (3.3)).

    Where the contact would be in tension (``N < 0``) and the local law is not defined there,
    ``limit`` is the local law's extension linear in N from ``N = 0`` (positive: no such load is
    carried).

    Parameters
    ----------
    law : FrictionLaw
        The local law, in ``(T, N)``, without internal variables.
    alpha : float
        Inclination of the contact plane, radians, in (-pi/2, pi/2) (negative: a cylinder past
        the top of its neighbour, the plane falling towards +x).
    psi : float
        Up-slope azimuth, radians, counter-clockwise from x.
    """

    law: FrictionLaw
    alpha: float
    psi: float = 0.0
    normal_name = "Q"

    def __post_init__(self):
        check_contact_law(self.law, "GrainContact")
        object.__setattr__(self, "alpha", check_scalar("alpha", self.alpha, lo=-np.pi / 2,
                                                       hi=np.pi / 2, lo_open=True, hi_open=True))
        object.__setattr__(self, "psi", check_scalar("psi", self.psi))

    @functools.cached_property
    def _axes(self) -> np.ndarray:
        return frame_of_angles(self.alpha, self.psi)

    def frame(self) -> np.ndarray:
        """Rows ``t1, t2, n`` of the contact's frame, shape ``(3, 3)``."""
        return self._axes.copy()

    @property
    def normal(self) -> np.ndarray:
        """Unit normal ``n`` (from the layer grain into the upper grain)."""
        return self._axes[2].copy()

    def plane_forces(self, T, Q) -> np.ndarray:
        """``(T1, T2, N)`` in the contact's frame for the loads ``(T, Q)``, shape ``(..., 3)``
        ((2.1) in the contact's frame)."""
        T, Q = self._inputs(T, Q)
        return local_forces(self._axes, T, Q)

    def _global(self, grad: np.ndarray) -> np.ndarray:
        """A gradient in ``(T1, T2, N)`` as one in ``(Tx, Ty, Q)``."""
        dF = np.einsum("ij,...i->...j", self._axes, grad * _S)
        return dF * _S

    def limit(self, T, Q, q=None):
        return _extended(self.law, "limit", "limit_gradient", self.plane_forces(T, Q))[0]

    def potential(self, T, Q, q=None):
        return _extended(self.law, "potential", "potential_gradient", self.plane_forces(T, Q))[0]

    def limit_gradient(self, T, Q, q=None):
        return self._global(_extended(self.law, "limit", "limit_gradient",
                                      self.plane_forces(T, Q))[1])

    def potential_gradient(self, T, Q, q=None):
        return self._global(_extended(self.law, "potential", "potential_gradient",
                                      self.plane_forces(T, Q))[1])

    @functools.cached_property
    def _up(self) -> np.ndarray:
        """Unit up-slope direction of the plane in the frame ``(t1, t2)`` (0 on a level plane)."""
        up = np.array([0.0, 0.0, 1.0]) - self._axes[2, 2] * self._axes[2]
        norm = np.linalg.norm(up)
        return self._axes[:2] @ up / norm if norm > 0 else np.zeros(2)

    def upslope_force(self, T, Q) -> np.ndarray:
        """The in-plane part of the load ``F`` along the up-slope direction of the plane."""
        return self.plane_forces(T, Q)[..., :2] @ self._up

    def climbing_limit(self, T, Q) -> np.ndarray:
        r"""The limit of the load whose in-plane pull down the slope is held by the pocket the
        grain starts from: ``limit`` of :math:`F - \min(F\cdot e_{up}, 0)\,e_{up}`,
        :math:`e_{up}` the unit up-slope direction of the plane (no change on a level plane).
        For local Coulomb friction :math:`\sqrt{\max(T_{up}, 0)^2 + T_\perp^2} - \mu N`."""
        sigma = self.plane_forces(T, Q)
        down = np.minimum(sigma[..., :2] @ self._up, 0.0)
        sigma[..., :2] -= down[..., None] * self._up
        return _extended(self.law, "limit", "limit_gradient", sigma)[0]

    def centre(self, Q, q=None) -> np.ndarray:
        """The load with no in-plane force, ``Q tan(alpha) e_psi``: inside the limit curve."""
        Q = np.asarray(Q, dtype=float)
        n = self._axes[2]
        return np.stack((-Q * n[0] / n[2], -Q * n[1] / n[2]), axis=-1)

    def _inverse_relation(self, theta, Q, q):
        """Closed form for a local law without normal slip (:func:`slide`); the numeric default
        otherwise."""
        if self.law.traits.normal_slip:
            return super()._inverse_relation(theta, Q, q)
        s = slide(self.law, np.broadcast_to(self._axes, theta.shape + (3, 3)),
                  np.stack((np.cos(theta), np.sin(theta)), axis=-1), Q)
        return InverseRelation(np.where(s.locked[..., None], np.inf, s.force), s.locked)


@dataclass(frozen=True)
class Slide:
    """A grain sliding on one contact along a horizontal direction.

    ``force`` (..., 2) is the horizontal load, ``normal`` (...) the contact's normal force,
    ``velocity`` (..., 3) the unit grain velocity; ``locked`` (...) marks directions in which no
    finite load slides the grain (``force`` and ``normal`` are 0 there).
    """

    force: np.ndarray
    normal: np.ndarray
    velocity: np.ndarray
    locked: np.ndarray


def slide(law, axes: np.ndarray, direction, Q) -> Slide:
    r"""The load that slides a grain on contacts with the frames ``axes`` (..., 3, 3) along the
    horizontal ``direction`` (..., 2), for a local law without normal slip.

    The horizontal direction lifted onto the tangent plane, :math:`V \propto (e, -e\cdot n_h /
    n_z)`, is the slip; the local inverse relation gives the force per unit N,
    :math:`a = \tau_1 t_1 + \tau_2 t_2 - n` (:func:`carried_force`), and vertical equilibrium
    :math:`N a_z = -Q` the normal force: :math:`T = N a_h` ((2.1) with the inverse relation;
    for local Coulomb friction the closed form of ``WedgeAsperity.force_for_slip``).
    """
    e = np.asarray(direction, dtype=float)
    n = axes[..., 2, :]
    V = np.concatenate((e, -np.sum(e * n[..., :2], axis=-1, keepdims=True) / n[..., 2:3]), axis=-1)
    V = V / np.linalg.norm(V, axis=-1, keepdims=True)
    c = carried_force(law, axes, V)
    locked = c.locked | (c.force[..., 2] >= -LOCK_TOL)
    N = np.where(locked, 0.0, Q) / np.where(locked, 1.0, -c.force[..., 2])
    return Slide(N[..., None] * c.force[..., :2], N, V, locked)


@dataclass(frozen=True)
class ContactTerms:
    r"""A sliding contact's limit condition and potential, with the derivatives the rate
    relations need, at loads ``(T, Q)`` and the grain position ``u``.

    Attributes
    ----------
    f, N : (...)
        Limit condition and the contact's normal force.
    f_T, f_u : (..., 2)
        :math:`\partial f/\partial T` and :math:`\partial f/\partial u` (the frame moving with
        the grain: :math:`f_{,\alpha}\alpha_{,u} + f_{,\psi}\psi_{,u}` of (3.5)).
    g_T : (..., 2)
        :math:`\partial g/\partial T`, the horizontal slip per unit multiplier (3.3).
    g_Q : (...)
        :math:`\partial g/\partial Q`; :math:`V_z = -\dot\lambda\, g_{,Q}` (3.3).
    g_TT, g_Tu : (..., 2, 2)
        :math:`\partial^2 g/\partial T\partial T` and :math:`\partial^2 g/\partial T\partial u`
        (``[..., a, i]``: component ``a`` of ``g_T``, derivative ``i``).
    """

    f: np.ndarray
    N: np.ndarray
    f_T: np.ndarray
    f_u: np.ndarray
    g_T: np.ndarray
    g_Q: np.ndarray
    g_TT: np.ndarray
    g_Tu: np.ndarray

    @property
    def modulus(self) -> np.ndarray:
        r"""The modulus ``h`` of :math:`\dot\lambda = \dot f_T / h`: :math:`h = -f_{,u}\cdot
        g_{,T}`, the rate of ``f`` per unit multiplier as the slip :math:`V = \dot\lambda g_{,T}`
        moves the frame ((3.5), (3.7), (3.13)); negative: softening."""
        return -np.sum(self.f_u * self.g_T, axis=-1)


def contact_terms(law, axes: np.ndarray, rates: np.ndarray, T, Q, cylindrical: bool) -> ContactTerms:
    r""":class:`ContactTerms` of contacts with the frames ``axes`` (..., 3, 3) and their
    derivatives ``rates`` (..., 2, 3, 3) with respect to the offset.

    The local law's derivatives come from its symbolic form through the protocol
    (``law.local_derivatives``); the frame's from :mod:`._frame`; they are composed by the chain
    rule with :math:`\sigma = S A F`, ``S = diag(1, 1, -1)``:
    :math:`\partial f/\partial F = (SA)^T f_{,\sigma}`,
    :math:`\partial f/\partial r_i = f_{,\sigma}\cdot S A_{,i} F`,
    :math:`\partial^2 g/\partial F^2 = (SA)^T g_{,\sigma\sigma} SA`,
    :math:`\partial^2 g/\partial F\partial r_i = (SA_{,i})^T g_{,\sigma} + (SA)^T
    g_{,\sigma\sigma} SA_{,i}F`. A cylinder's offset has no y part (``u_y`` moves along the
    axes): only ``r_x`` follows the grain.
    """
    T = np.asarray(T, dtype=float)
    Q = np.asarray(Q, dtype=float)
    T, Qb = np.broadcast_arrays(T, Q[..., None])
    F = np.concatenate((T, -Qb[..., :1]), axis=-1)
    B = _S[:, None] * axes                                     # (..., 3, 3) d sigma / dF
    Bi = _S[:, None] * rates                                   # (..., 2, 3, 3)
    sigma = np.einsum("...ij,...j->...i", B, F)
    loc = law.local_derivatives(sigma[..., :2], sigma[..., 2])
    dF_f = np.einsum("...ij,...i->...j", B, loc.df)
    dF_g = np.einsum("...ij,...i->...j", B, loc.dg)
    H = np.einsum("...ai,...ab,...bj->...ij", B, loc.hgg, B)
    dsig = np.einsum("...kij,...j->...ki", Bi, F)              # (..., 2, 3) d sigma / d r_k
    f_r = np.einsum("...ki,...i->...k", dsig, loc.df)
    g_Fr = (np.einsum("...kij,...i->...jk", Bi, loc.dg)
            + np.einsum("...ai,...ab,...kb->...ik", B, loc.hgg, dsig))   # (..., 3, 2)
    if cylindrical:
        f_r = f_r * np.array([1.0, 0.0])
        g_Fr = g_Fr * np.array([1.0, 0.0])
    return ContactTerms(f=loc.f, N=sigma[..., 2], f_T=dF_f[..., :2], f_u=f_r, g_T=dF_g[..., :2],
                        g_Q=-dF_g[..., 2], g_TT=H[..., :2, :2], g_Tu=g_Fr[..., :2, :])


def finite_terms(terms: ContactTerms, where: str) -> ContactTerms:
    """``terms`` if finite; else :class:`FrictionRulesError` (a kink of the local law, e.g. the
    apex of a cone with ``mu = 0``, where the slip direction is undefined)."""
    for name in ("f_T", "f_u", "g_T", "g_TT", "g_Tu"):
        if not np.all(np.isfinite(getattr(terms, name))):
            raise FrictionRulesError(
                f"{where}: the local law's derivatives are not finite at the contact's force, a "
                "kink of its limit condition or potential where the slip direction is undefined; "
                "constraint: a force where the sliding rule is defined (for Coulomb friction "
                "mu > 0: with mu = 0 the limit curve is the apex T = 0; use method='exact')")
    return terms


