r"""A rigid block translating on planar facets with local Coulomb friction (§2 generalized).

Frame and signs (``docs/conventions.md``, "Laws in external loads"): x, y horizontal, z up. The
block is loaded by :math:`F = (T_x, T_y, -Q)`, ``Q > 0`` pressing it down, and translates with
the velocity :math:`V = (V_x, V_y, V_z)`, ``Vz > 0`` upwards. Facet ``j`` has the unit normal
:math:`n_j` pointing from the support into the block, with :math:`n_{jz} > 0` (the facets face
upwards; vertical walls and overhangs are not modelled). Its reaction on the block is
:math:`R_j = N_j n_j + f_j`, :math:`N_j \ge 0`, :math:`|f_j| \le \mu N_j`.

Mechanisms
----------
The block is in a sliding state when :math:`F + \sum_j R_j = 0` with a velocity that is
kinematically admissible, :math:`V\cdot n_j \ge 0` for every facet (no interpenetration), a
facet that separates (:math:`V\cdot n_j > 0`) carrying nothing.

* ``local="non-associated"`` (Coulomb with no dilatancy, (1.5), the paper's case): a loaded
  facet slides in its plane, :math:`V\cdot n_j = 0`, with :math:`f_j = -\mu N_j V/|V|`. One
  facet slides along its in-plane load :math:`F - (F\cdot n_j)n_j`; two facets slide along the
  line :math:`\pm n_j\times n_k` of their intersection. Three facets with independent normals
  cannot slide; facets whose normals are coplanar with ``n_j, n_k`` lie on the same line, and
  the smallest load over such a group is always carried by two neighbouring facets of it (the
  load factor is a linear programme with three equality constraints), so pairs suffice.
* ``local="associated"`` (the dilatant rule (1.6)): a loaded facet slides with
  :math:`V\cdot n_j = \sin\varrho\,|V|`, :math:`\varrho = \arctan\mu`, and
  :math:`f_j = -\mu N_j w_j`, :math:`w_j` the unit in-plane part of ``V``; so
  :math:`R_j \perp V` and the mechanism dissipates nothing. Admissibility is
  :math:`V\cdot n_m \ge \sin\varrho\,|V|` for every facet (the dual of the friction cone).

The *limit load* in a horizontal direction ``d`` is the smallest factor :math:`t \ge 0` for
which the load :math:`F = (t d, -Q)` admits a mechanism; it is ``inf`` (locked) when none does.
For the non-associated rule it is capped by the static maximum (the associated limit load:
beyond it no equilibrium exists at all), where the block loses equilibrium without a
quasi-static mechanism (``LimitLoad.quasi_static``); so the non-associated load never exceeds
the associated one (Radenkovic). The facets must carry ``Q`` alone (checked on construction).
Everything is homogeneous of degree one in ``(T, Q)``.

As a law of the core protocol (:class:`frictionrules.FrictionLaw`) a facet set uses the
vertical load ``Q`` in the place of ``N`` and the block velocity as the generalized slip:

.. math:: f(T, Q) = |T| - Q\,t_1(T/|T|),

with :math:`t_1` the limit load at ``Q = 1``: negative inside, zero on the limit surface,
positive outside, ``-inf`` in locked directions (``t_1 = inf``). At ``T = 0`` the direction is
taken as +x.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from .._optional import require
from ..errors import FrictionRulesError, check_finite, check_scalar
from ..laws import FrictionLaw, InverseRelation

__all__ = ["FacetSet", "LimitLoad", "LimitCurve", "Corner"]

_LOCALS = ("non-associated", "associated")
_TOL = 1e-9          # tolerance on dot products of unit vectors (admissibility, ties)
_CURVE_POINTS = 4096  # directions of the support-point search of the associated inverse
_SMOOTH = 1e-7       # |turning| below which a mechanism change is a smooth join, not a corner
_CHUNK_ENTRIES = 1 << 22  # entries per direction chunk of the solver's temporaries


# ---------------------------------------------------------------------------------------------
# results
# ---------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class LimitLoad:
    """The limit load of a facet set in one horizontal direction.

    Attributes
    ----------
    load : float
        Load factor ``t``: the limit load is ``T = t d`` (``|d| = 1``); ``inf`` when locked.
    T : (2,) array
        Horizontal limit load ``(Tx, Ty)`` (``inf`` when locked).
    mechanism : tuple of int or None
        Indices of the sliding facets (one or two); ``None`` when locked.
    normal_forces : (K,) array
        Normal force on every facet (``>= 0``; zero off the mechanism).
    velocity : (3,) array
        Unit block velocity ``(Vx, Vy, Vz)``, ``Vz > 0`` upwards; zeros when locked.
    quasi_static : bool
        True when the block slides in equilibrium (a mechanism of the local rule). False
        (non-associated rule only) when the static maximum comes first: beyond it no
        equilibrium exists, the block accelerates; ``mechanism``, ``normal_forces`` and
        ``velocity`` are then those of the static limit (the associated mechanism, whose
        velocity is the normal of the static limit surface).
    """

    load: float
    T: np.ndarray
    mechanism: tuple[int, ...] | None
    normal_forces: np.ndarray
    velocity: np.ndarray
    quasi_static: bool = True


@dataclass(frozen=True)
class Corner:
    """A corner of the limit curve, where the mechanism changes.

    Attributes
    ----------
    T : (2,) array
        Position ``(Tx, Ty)`` at the ``Q`` of the curve.
    direction : float
        Polar angle of ``T`` (radians).
    before, after : tuple of int
        Mechanisms on either side (counter-clockwise order).
    turning : float
        Signed turning angle of the tangent when the curve is run counter-clockwise
        (radians): ``> 0`` a convex corner, ``< 0`` a concave (re-entrant) one.
    interior : float
        Interior angle ``pi - turning``; ``> pi`` for a concave corner.
    """

    T: np.ndarray
    direction: float
    before: tuple[int, ...]
    after: tuple[int, ...]
    turning: float
    interior: float

    @property
    def concave(self) -> bool:
        """True for a re-entrant corner (``turning < -1e-7``; smaller turnings are smooth
        joins, e.g. the tangent joins of the associated rule)."""
        return self.turning < -_SMOOTH


@dataclass(frozen=True)
class LimitCurve:
    """The limit curve of a facet set at fixed ``Q``, ordered by load direction.

    Attributes
    ----------
    Q : float
    direction : (M,) load directions (polar angles of ``T``), increasing over ``[-pi, pi)``.
    T : (M, 2) limit loads (``inf`` where locked).
    load : (M,) load factors ``|T|``.
    facets : (M, 2) int, sliding facets (``-1`` for none / the second of a one-facet mechanism).
    normal_forces : (M, 2) normal forces on those facets.
    velocity : (M, 3) unit block velocities (the global sliding rule).
    normal : (M, 3) unit outward normals of the limit surface in the space
        ``(Tx, Ty, -Q)`` conjugate to the velocity (the associated direction).
    rule_angle : (M,) angle between ``velocity`` and ``normal``: how non-associated the global
        rule is (0 where it is associated).
    tangential_rule_angle : (M,) the same for the horizontal parts (the sliding plane).
    corners : tuple of :class:`Corner`
    quasi_static : (M,) bool, see :class:`LimitLoad`.
    """

    Q: float
    direction: np.ndarray
    T: np.ndarray
    load: np.ndarray
    facets: np.ndarray
    normal_forces: np.ndarray
    velocity: np.ndarray
    normal: np.ndarray
    rule_angle: np.ndarray
    tangential_rule_angle: np.ndarray
    corners: tuple[Corner, ...]
    quasi_static: np.ndarray

    @property
    def labels(self) -> list[str]:
        """Mechanism label per point: ``"1"``, ``"0+2"``, or ``"locked"`` (facet indices)."""
        return [_label(row) for row in self.facets]

    @property
    def concave_corners(self) -> tuple[Corner, ...]:
        return tuple(c for c in self.corners if c.concave)


def _label(row) -> str:
    ids = [int(i) for i in row if i >= 0]
    return "+".join(map(str, ids)) if ids else "locked"


# ---------------------------------------------------------------------------------------------
# geometry shared by all loads
# ---------------------------------------------------------------------------------------------
def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


@dataclass(frozen=True)
class _Geometry:
    index: np.ndarray    # (K,) facets that can slide (of the user's numbering)
    n: np.ndarray        # (K, 3) their unit normals
    slope: np.ndarray    # (K, 2) gradients p = -n_h / n_z of the facet planes
    mu: float
    associated: bool
    threshold: float     # admissibility V.n_m >= threshold (0 or sin rho)
    pair_j: np.ndarray   # (P,) candidate pairs and their velocities
    pair_k: np.ndarray
    pair_v: np.ndarray   # (P, 3)
    pair_r: np.ndarray   # (P, 2, 3) unit-N reactions r = n - mu w of the two facets
    static: _Geometry | None  # associated twin of a non-associated set (the static maximum)


def _pairs(n: np.ndarray, mu: float, associated: bool, threshold: float):
    """Two-facet mechanisms that are kinematically admissible for some load."""
    K = len(n)
    j, k = np.triu_indices(K, 1)
    e = np.cross(n[j], n[k])
    norm = np.linalg.norm(e, axis=-1)
    ok = norm > 1e-12
    j, k, e = j[ok], k[ok], e[ok] / norm[ok, None]
    if associated:
        g = np.sum(n[j] * n[k], axis=-1)
        a = threshold / (1.0 + g)
        c2 = 1.0 - 2.0 * a**2 * (1.0 + g)
        ok = c2 >= -1e-12
        j, k, e, a, c = j[ok], k[ok], e[ok], a[ok], np.sqrt(np.clip(c2[ok], 0.0, None))
        base = a[:, None] * (n[j] + n[k])
        single = c <= 1e-12  # the two cones touch along one ray
        v = np.concatenate((base + c[:, None] * e, (base - c[:, None] * e)[~single]))
        j, k = np.concatenate((j, j[~single])), np.concatenate((k, k[~single]))
    else:
        v = np.concatenate((e, -e))
        j, k = np.concatenate((j, j)), np.concatenate((k, k))
    admissible = np.all(v @ n.T >= threshold - _TOL, axis=-1)
    j, k, v = j[admissible], k[admissible], v[admissible]
    if not associated and len(j):
        # a facet coplanar with (n_j, n_k) lying strictly between them carries the same line
        # mechanism at a smaller load: keep neighbouring pairs only
        ax = _unit(np.cross(n[j], n[k]))
        coplanar = np.abs(n @ ax.T).T < _TOL                              # (P, K)
        left = np.einsum("pki,pi->pk", np.cross(n[j][:, None, :], n[None, :, :]), ax) > _TOL
        right = np.einsum("pki,pi->pk", np.cross(n[None, :, :], n[k][:, None, :]), ax) > _TOL
        keep = ~np.any(coplanar & left & right, axis=-1)
        j, k, v = j[keep], k[keep], v[keep]
    r = np.stack((_reaction(n[j], v, mu), _reaction(n[k], v, mu)), axis=1)
    return j, k, v, r


def _downward_velocity(n: np.ndarray, mu: float):
    r"""A unit velocity that makes the block descend freely, or ``None`` if there is none.

    The vertical load alone is carried iff :math:`Q z \in \sum_j K_j` (friction cones); by
    duality iff every ``V`` of the dual cone :math:`\bigcap_j\{V: V\cdot n_j \ge
    \sin\varrho|V|\}` has :math:`V_z \ge 0`. The lowest point of that cone on the unit
    sphere is the lowest point of one facet's cone, :math:`\sin\varrho\, n_j +
    \cos\varrho\, w_j` (``w_j`` down-slope), or an intersection of two cones; the candidates
    that are admissible for every facet are checked.
    """
    rho = np.arctan(mu)
    sr = float(np.sin(rho))
    up = np.array([0.0, 0.0, 1.0]) - n[:, 2:] * n
    upn = np.linalg.norm(up, axis=-1, keepdims=True)
    steep = upn[:, 0] > 1e-12
    cands = [np.sin(rho) * n[steep] - np.cos(rho) * up[steep] / upn[steep]]
    cands.append(_pairs(n, mu, True, sr)[2])
    V = np.concatenate(cands)
    V = V[np.all(V @ n.T >= sr - _TOL, axis=-1) & (V[:, 2] < -1e-12)]
    return V[0] if len(V) else None


def _reaction(n: np.ndarray, v: np.ndarray, mu: float) -> np.ndarray:
    """Reaction per unit normal force, :math:`r = n - \\mu w`, ``w`` the unit in-plane part of v."""
    w = v - np.sum(v * n, axis=-1, keepdims=True) * n
    wn = np.linalg.norm(w, axis=-1, keepdims=True)
    w = np.divide(w, wn, out=np.zeros_like(w), where=wn > 0)
    return n - mu * w


# ---------------------------------------------------------------------------------------------
# the law
# ---------------------------------------------------------------------------------------------
class _FacetLaw(FrictionLaw):
    """Protocol implementation shared by :class:`FacetSet` and the two-flank asperity.

    A subclass provides ``_facets`` (the :class:`FacetSet` it is).
    """

    normal_name = "Q"

    @property
    def _facets(self) -> FacetSet:  # pragma: no cover - abstract
        raise NotImplementedError

    @property
    def associated(self) -> bool:
        return self.local == "associated"

    # ---- mechanisms ----------------------------------------------------------------------
    def limit_load(self, direction, Q=1.0) -> LimitLoad:
        """Limit load in the horizontal ``direction`` ``(dx, dy)`` at vertical load ``Q``.

        The smallest load factor ``t >= 0`` at which ``F = (t d, -Q)`` (``d`` the unit
        direction) admits a kinematically admissible mechanism, with the sliding facets, their
        normal forces and the block velocity. Locked (``load = inf``, ``mechanism = None``)
        when no mechanism exists in that direction.
        """
        d = check_finite("direction", direction)
        if d.shape != (2,) or np.hypot(*d) == 0:
            raise FrictionRulesError(f"direction = {d.tolist()!r} violates: a nonzero 2-vector")
        Q = check_scalar("Q", Q, lo=0.0)
        sol = _solve(self._facets._geometry, _unit(d)[None, :])
        K = len(self._facets.normals)
        forces = np.zeros(K)
        ids = tuple(int(i) for i in sol["facets"][0] if i >= 0)
        for i, f in zip(sol["facets"][0], sol["forces"][0]):
            if i >= 0:
                forces[i] = Q * f
        t = float(sol["load"][0]) * Q
        locked = not ids
        return LimitLoad(load=t if not locked else np.inf,
                         T=np.full(2, np.inf) if locked else t * _unit(d),
                         mechanism=None if locked else ids,
                         normal_forces=forces, velocity=sol["velocity"][0],
                         quasi_static=bool(sol["quasi_static"][0]))

    def limit_curve(self, Q=1.0, n: int = 720) -> LimitCurve:
        """The limit curve at fixed ``Q`` over ``n`` load directions, with corners.

        Corners are located by bisection on the load direction between two samples with
        different mechanisms and classified by the turning of the tangent (the tangents of the
        two mechanisms' limit surfaces at the corner).
        """
        Q = check_scalar("Q", Q, lo=0.0, lo_open=True)
        phi = -np.pi + 2.0 * np.pi * np.arange(n) / n
        geo = self._facets._geometry
        sol = _solve(geo, np.stack((np.cos(phi), np.sin(phi)), axis=-1))
        load = Q * sol["load"]
        fin = np.isfinite(load)
        T = np.where(fin[:, None], np.where(fin, load, 0.0)[:, None]
                     * np.stack((np.cos(phi), np.sin(phi)), axis=-1), np.inf)
        vel, nrm = sol["velocity"], sol["normal"]
        corners = []
        for i in range(n):
            i2 = (i + 1) % n
            a, b = sol["facets"][i], sol["facets"][i2]
            if np.isfinite(load[i]) and np.isfinite(load[i2]) and tuple(a) != tuple(b):
                hi = phi[i2] + (2.0 * np.pi if i2 == 0 else 0.0)
                corners.append(_corner(geo, phi[i], hi, tuple(a), Q))
        return LimitCurve(Q=Q, direction=phi, T=T, load=load, facets=sol["facets"],
                          normal_forces=Q * sol["forces"], velocity=vel, normal=nrm,
                          rule_angle=_angle(vel, nrm), tangential_rule_angle=_angle(vel[:, :2],
                                                                                    nrm[:, :2]),
                          corners=tuple(corners), quasi_static=sol["quasi_static"])

    def limit_surface(self, Q, n: int = 720) -> np.ndarray:
        """Points ``(Tx, Ty, Q)`` of the limit surface, shape ``(len(Q), n, 3)``.

        The surface is a cone with apex at the origin: the curve at ``Q`` is ``Q`` times the
        curve at ``Q = 1`` (``inf`` in locked directions, also at ``Q = 0``).
        """
        Q = np.atleast_1d(check_finite("Q", Q))
        if np.any(Q < 0):
            raise FrictionRulesError(f"Q = {Q.tolist()!r} violates Q >= 0")
        T1 = self.limit_curve(1.0, n).T
        fin = np.isfinite(T1)
        T = np.where(fin, Q[:, None, None] * np.where(fin, T1, 0.0)[None], np.inf)
        return np.concatenate((T, np.broadcast_to(Q[:, None, None], T.shape[:2] + (1,))), axis=-1)

    # ---- protocol ------------------------------------------------------------------------
    def _at(self, T, Q):
        """Mechanism data at the limit point in the direction of each ``T`` (``Q = 1``)."""
        T, Q = self._inputs(T, Q)
        T, Q = np.broadcast_arrays(T, Q[..., None])
        Q = Q[..., 0]
        r = np.hypot(T[..., 0], T[..., 1])
        d = np.where(r[..., None] > 0, T, np.array([1.0, 0.0]))
        sol = _solve(self._facets._geometry, _unit(d.reshape(-1, 2)))
        sol = {k: v.reshape(T.shape[:-1] + v.shape[1:]) for k, v in sol.items()}
        return T, Q, r, sol

    def limit(self, T, Q, q=None):
        """:math:`f = |T| - Q\\,t_1(T/|T|)`: < 0 inside, 0 on the limit surface, -inf locked."""
        T, Q, r, sol = self._at(T, Q)
        with np.errstate(invalid="ignore"):
            f = r - Q * sol["load"]
        return np.where(Q > 0, f, r)

    def _mechanism_terms(self, T, Q):
        """Per point: F = (Tx, Ty, -Q), the active facet normal(s) and the velocity/normal."""
        T, Q, r, sol = self._at(T, Q)
        F = np.concatenate((T, -Q[..., None]), axis=-1)
        n = self._facets.normal_array
        j = sol["facets"][..., 0]
        single = (j >= 0) & (sol["facets"][..., 1] < 0)
        nj = n[np.where(j >= 0, j, 0)]
        Ft = F - np.sum(F * nj, axis=-1, keepdims=True) * nj
        Ftn = np.linalg.norm(Ft, axis=-1, keepdims=True)
        w = np.divide(Ft, Ftn, out=np.zeros_like(Ft), where=Ftn > 0)
        return F, single, nj, w, sol

    def potential(self, T, Q, q=None):
        """Global potential of the mechanism active in the direction of ``T``.

        One facet ``j``: :math:`g = |F - (F\\cdot n_j)n_j|` (the wedge potential (2.6), (2.14));
        with ``local="associated"`` :math:`g = f_j = |F_t| + \\mu F\\cdot n_j`. Two facets:
        :math:`g = V\\cdot F` with the mechanism's unit velocity ``V`` ((2.15): ``g = ±Ty`` for
        the two-flank asperity). Zero in locked directions. Where the static maximum limits a
        non-associated set (``quasi_static`` False) the associated potential is used.
        """
        F, single, nj, w, sol = self._mechanism_terms(T, Q)
        dilatant = self.associated | ~sol["quasi_static"]
        g1 = np.sum(F * w, axis=-1) + np.where(dilatant, self._facets.mu, 0.0) * np.sum(F * nj,
                                                                                        axis=-1)
        g2 = np.sum(F * sol["velocity"], axis=-1)
        return np.where(single, g1, g2)

    def potential_gradient(self, T, Q, q=None):
        """``(dg/dTx, dg/dTy, dg/dQ)`` of :meth:`potential`."""
        F, single, nj, w, sol = self._mechanism_terms(T, Q)
        dilatant = self.associated | ~sol["quasi_static"]
        g1 = w + np.where(dilatant, self._facets.mu, 0.0)[..., None] * nj
        g = np.where(single[..., None], g1, sol["velocity"])
        return g * np.array([1.0, 1.0, -1.0])

    def limit_gradient(self, T, Q, q=None):
        """Gradient of the active mechanism's degree-one limit function ``f_m``.

        One facet: :math:`f_j = |F_t| + \\mu F\\cdot n_j` (the wedge limit (2.2) in its
        degree-one form), gradient :math:`w + \\mu n_j`; two facets: the plane of the mechanism
        with its unit outward normal. Returned in ``(Tx, Ty, Q)``; zero in locked directions.
        """
        F, single, nj, w, sol = self._mechanism_terms(T, Q)
        g = np.where(single[..., None], w + self._facets.mu * nj, sol["normal"])
        return g * np.array([1.0, 1.0, -1.0])

    # No symbolic form (capability "symbolic"): the global law is piecewise, each piece valid
    # on a range of loads that depends on kinematic admissibility; everything here is
    # closed-form per mechanism.

    def centre(self, Q, q=None) -> np.ndarray:
        Q = np.asarray(Q, dtype=float)
        return np.zeros(Q.shape + (2,))

    def _inverse_relation(self, theta, Q, q):
        """Load on the limit curve whose block velocity slides at the horizontal angle ``theta``.

        Non-associated: for the horizontal slip ``u`` every admissible velocity has
        :math:`V_z \\ge \\max_m p_m\\cdot u` (``p_m`` the facet gradients), so the block
        climbs the facet ``j`` that attains the maximum (a support function of the gradients)
        with :math:`V = (u, p_j\\cdot u)`, and equilibrium gives
        :math:`N_j = Q/(n_{jz} - \\mu \\hat V_z)`, :math:`T = -N_j(n_j - \\mu\\hat V)_h`;
        locked where :math:`n_{jz} - \\mu\\hat V_z \\le 0`. Where several facets attain the
        maximum (the velocity runs along their intersection) the loads form a segment and the
        smallest ``|T|`` on it is returned. Associated: the limit curve is convex and the load
        is its support point in the direction ``u`` (found on a dense curve).

        This is the velocity-driven load, unique for every ``theta``. For a non-associated set
        whose mechanism pieces fold it can lie beyond the first mechanism met on its radial
        load path (:meth:`limit_load`), where ``limit > 0``; see ``docs/asperities.md``.
        """
        theta, Q = np.broadcast_arrays(np.asarray(theta, dtype=float), np.asarray(Q, dtype=float))
        u = np.stack((np.cos(theta), np.sin(theta)), axis=-1).reshape(-1, 2)
        geo = self._facets._geometry
        T = (_support_force(geo, u) if self.associated else _climb_force(geo, u))
        T = Q.reshape(-1)[:, None] * T
        T = np.where(np.isfinite(T), T, np.inf).reshape(theta.shape + (2,))
        return InverseRelation(T, ~np.all(np.isfinite(T), axis=-1))


def _angle(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    na, nb = np.linalg.norm(a, axis=-1), np.linalg.norm(b, axis=-1)
    ok = (na > 0) & (nb > 0)
    c = np.sum(a * b, axis=-1) / np.where(ok, na * nb, 1.0)
    return np.where(ok, np.arccos(np.clip(c, -1.0, 1.0)), 0.0)


@dataclass(frozen=True)
class FacetSet(_FacetLaw):
    r"""A rigid block on planar facets with local Coulomb friction, as a law in external loads.

    Parameters
    ----------
    normals : array (K, 3)
        Facet normals, pointing from the support into the block, each with ``nz > 0``
        (normalized on input; stored as a tuple of tuples so that the law is hashable).
    mu : float
        Local friction coefficient, ``mu > 0``.
    local : {"non-associated", "associated"}
        Local sliding rule: Coulomb without normal slip (1.5) or the dilatant rule (1.6).

    The facets must carry the vertical load alone (``Q z`` inside the sum of their friction
    cones: the block does not slide down under ``Q`` with ``T = 0``); otherwise
    :class:`FrictionRulesError` is raised.

    Notes
    -----
    Only the set of normal *directions* matters: a rigid block loads whichever facets its
    mechanism needs, whatever their areas. A facet set with one facet of inclination ``alpha``
    is the :class:`frictionrules.WedgeAsperity` ``(alpha, mu)``.
    """

    normals: tuple
    mu: float
    local: str = "non-associated"

    def __post_init__(self):
        n = check_finite("normals", self.normals)
        if n.ndim != 2 or n.shape[-1] != 3 or len(n) == 0:
            raise FrictionRulesError(f"normals must have shape (K, 3) with K >= 1, got shape "
                                     f"{n.shape}")
        norm = np.linalg.norm(n, axis=-1)
        if np.any(norm == 0):
            i = int(np.argmin(norm))
            raise FrictionRulesError(f"normals[{i}] = {n[i].tolist()!r} violates |n| > 0")
        n = n / norm[:, None]
        if np.any(n[:, 2] <= 1e-9):
            i = int(np.argmin(n[:, 2]))
            raise FrictionRulesError(f"normals[{i}] = {n[i].tolist()!r} violates nz > 0 (facets "
                                     "must face upwards, into the block)")
        object.__setattr__(self, "normals", tuple(tuple(float(c) for c in row) for row in n))
        object.__setattr__(self, "mu", check_scalar("mu", self.mu, lo=0.0, lo_open=True))
        if self.local not in _LOCALS:
            raise FrictionRulesError(f"local = {self.local!r} violates local in {_LOCALS}")
        V = _downward_velocity(self.normal_array[self._sliding], self.mu)
        if V is not None:
            raise FrictionRulesError(
                f"the facets (mu = {self.mu!r}) cannot carry the vertical load alone, the block "
                f"slides down under Q with T = 0 (the downward velocity {np.round(V, 6).tolist()} "
                "lies in every facet's dual friction cone); constraint: Q z inside the sum of "
                "the facets' friction cones. Level the surface or check the normals")

    @property
    def _facets(self) -> FacetSet:
        return self

    @property
    def normal_array(self) -> np.ndarray:
        """The unit normals as an array ``(K, 3)``."""
        return np.array(self.normals)

    @functools.cached_property
    def _sliding(self) -> np.ndarray:
        """Indices of the facets that can slide (:func:`_boundary_facets`)."""
        return _boundary_facets(self.normal_array)

    @functools.cached_property
    def _geometry(self) -> _Geometry:
        index = self._sliding
        n = self.normal_array[index]

        def build(associated, static):
            thr = float(np.sin(np.arctan(self.mu))) if associated else 0.0
            j, k, v, r = _pairs(n, self.mu, associated, thr)
            return _Geometry(index=index, n=n, slope=-n[:, :2] / n[:, 2:], mu=self.mu,
                             associated=associated, threshold=thr, pair_j=j, pair_k=k,
                             pair_v=v, pair_r=r, static=static)

        # the associated twin gives the static maximum, an upper bound for both rules
        return build(True, None) if self.associated else build(False, build(True, None))


# ---------------------------------------------------------------------------------------------
# the solver
# ---------------------------------------------------------------------------------------------
def _solve(geo: _Geometry, d: np.ndarray) -> dict:
    """Limit loads (``Q = 1``) in the unit directions ``d`` (M, 2): smallest admissible
    mechanism over all one-facet and two-facet candidates (in chunks of directions that keep
    the admissibility tensor ``(M, K, 2, K)`` to a few million entries)."""
    K = len(geo.n)
    step = max(1, _CHUNK_ENTRIES // (2 * K * K + len(geo.pair_j)))
    parts = [_solve_chunk(geo, d[i:i + step]) for i in range(0, len(d), step)]
    out = {k: np.concatenate([p[k] for p in parts]) for k in parts[0]}
    f = out["facets"]
    out["facets"] = np.where(f >= 0, geo.index[np.where(f >= 0, f, 0)], -1)
    out["quasi_static"] = np.ones(len(d), dtype=bool)
    if geo.static is not None:
        # beyond the static maximum no equilibrium exists with any friction directions: where
        # it comes before every non-associated sliding equilibrium, the block loses
        # equilibrium there (and accelerates) instead
        st = _solve(geo.static, d)
        lose = st["load"] < out["load"] * (1.0 - 1e-9)
        for key in ("load", "facets", "forces", "velocity", "normal"):
            out[key] = np.where(lose.reshape((-1,) + (1,) * (out[key].ndim - 1)), st[key],
                                out[key])
        out["quasi_static"] = ~lose
    return out


def _boundary_facets(n: np.ndarray) -> np.ndarray:
    r"""Indices of the facets that can take part in a mechanism.

    A facet whose gradient :math:`p = -n_h/n_z` lies strictly inside the convex hull of the
    gradients has a normal inside the cone of the others: it separates in every admissible
    motion (:math:`V\cdot n = \sum\lambda_i V\cdot n_i`, also for the associated bound
    :math:`\sin\varrho|V|` since :math:`\sum\lambda_i \ge 1`) and never slides. Kept:
    hull vertices and gradients on hull edges (all of them when the gradients are collinear).
    """
    K = len(n)
    p = -n[:, :2] / n[:, 2:]
    if K <= 3:
        return np.arange(K)
    ev = np.linalg.eigvalsh(np.cov(p.T))
    if ev[0] <= 1e-12 * max(ev[1], 0.0) + 1e-30:
        return np.arange(K)
    require("scipy", extra="solvers")
    from scipy.spatial import ConvexHull, QhullError
    try:
        hull = ConvexHull(p, qhull_options="Qc")
    except QhullError:
        return np.arange(K)
    dist = np.max(p @ hull.equations[:, :2].T + hull.equations[:, 2], axis=-1)
    return np.flatnonzero(dist >= -1e-9 * (1.0 + np.abs(p).max()))


def _solve_chunk(geo: _Geometry, d: np.ndarray) -> dict:
    M, n, mu = len(d), geo.n, geo.mu
    D = np.concatenate((d, np.zeros((M, 1))), axis=-1)
    z = np.array([0.0, 0.0, 1.0])
    best = np.full(M, np.inf)
    facets = np.full((M, 2), -1)
    forces = np.zeros((M, 2))
    vel = np.zeros((M, 3))
    nrm = np.zeros((M, 3))

    # one facet: |F_t| = mu (-F.n), F = t D - z, a quadratic in t
    a = D @ n.T                                     # (M, K)
    nz = n[:, 2][None, :]
    k2 = 1.0 + mu**2
    A, B, C = 1.0 - k2 * a**2, 2.0 * k2 * a * nz, np.broadcast_to(1.0 - k2 * nz**2, a.shape)
    disc = B**2 - 4.0 * A * C
    with np.errstate(divide="ignore", invalid="ignore"):
        sq = np.sqrt(np.where(disc >= 0, disc, np.nan))
        q = -0.5 * (B + np.where(B >= 0, 1.0, -1.0) * sq)
        r1 = np.where(np.abs(A) > 1e-14, q / A, np.where(B != 0, -C / B, np.nan))
        r2 = np.where(q != 0, C / q, np.nan)
    roots = np.stack((r1, r2), axis=-1)             # (M, K, 2)
    roots = np.where(np.isfinite(roots) & (roots >= -1e-12), np.clip(roots, 0.0, None), np.nan)
    F = roots[..., None] * D[:, None, None, :] - z   # (M, K, 2, 3)
    Fn = np.einsum("mkri,ki->mkr", np.nan_to_num(F), n)
    Ft = np.nan_to_num(F) - Fn[..., None] * n[None, :, None, :]
    Ftn = np.linalg.norm(Ft, axis=-1, keepdims=True)
    w = np.divide(Ft, Ftn, out=np.zeros_like(Ft), where=Ftn > 0)
    if geo.associated:
        rho = np.arctan(mu)
        V = np.cos(rho) * w + np.sin(rho) * n[None, :, None, :]
    else:
        V = w
    ok = np.isfinite(roots) & (Fn < 0) & (Ftn[..., 0] > 0)
    ok &= np.all(np.einsum("mkri,li->mkrl", V, n) >= geo.threshold - _TOL, axis=-1)
    t1 = np.where(ok, roots, np.inf)
    flat = t1.reshape(M, -1)
    idx = np.argmin(flat, axis=-1)
    t_single = flat[np.arange(M), idx]
    kk, rr = np.divmod(idx, 2)
    take = t_single < best
    best = np.where(take, t_single, best)
    m_ix = np.arange(M)
    facets[take, 0] = kk[take]
    forces[take, 0] = -Fn[m_ix, kk, rr][take]
    vel[take] = V[m_ix, kk, rr][take]
    nrm[take] = _unit(w[m_ix, kk, rr] + mu * n[kk])[take]

    # two facets: t D + N_j r_j + N_k r_k = z (Cramer)
    if len(geo.pair_j):
        rj, rk = geo.pair_r[:, 0][None], geo.pair_r[:, 1][None]        # (1, P, 3)
        Dm = D[:, None, :]
        cjk = np.cross(rj, rk)
        det = np.sum(Dm * cjk, axis=-1)                                  # (M, P)
        scale = np.linalg.norm(cjk, axis=-1)
        good = np.abs(det) > 1e-12 * scale
        with np.errstate(divide="ignore", invalid="ignore"):
            inv = np.where(good, 1.0 / det, np.nan)
            t = np.sum(z * cjk, axis=-1) * inv
            Nj = np.sum(Dm * np.cross(z, rk), axis=-1) * inv
            Nk = np.sum(Dm * np.cross(rj, z), axis=-1) * inv
        ok2 = good & (t >= -1e-12) & (Nj >= -1e-10) & (Nk >= -1e-10)
        t2 = np.where(ok2, np.clip(t, 0.0, None), np.inf)
        p = np.argmin(t2, axis=-1)
        t_pair = t2[m_ix, p]
        # prefer the one-facet mechanism at a tie (a corner end of the pair's range)
        take = t_pair < best * (1.0 - 1e-12)
        best = np.where(take, t_pair, best)
        facets[take, 0] = geo.pair_j[p][take]
        facets[take, 1] = geo.pair_k[p][take]
        forces[take, 0] = np.clip(Nj[m_ix, p], 0.0, None)[take]
        forces[take, 1] = np.clip(Nk[m_ix, p], 0.0, None)[take]
        vel[take] = geo.pair_v[p][take]
        m = _unit(cjk[0, p]) * np.sign(det[m_ix, p])[:, None]   # outward: m.D > 0
        nrm[take] = m[take]
    return {"load": best, "facets": facets, "forces": forces, "velocity": vel, "normal": nrm}


def _corner(geo: _Geometry, lo: float, hi: float, before: tuple, Q: float) -> Corner:
    """Bisect the load direction between ``lo`` (mechanism ``before``) and ``hi``."""
    def mech(phi):
        return _solve(geo, np.array([[np.cos(phi), np.sin(phi)]]))

    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if tuple(mech(mid)["facets"][0]) == before:
            lo = mid
        else:
            hi = mid
    s_lo, s_hi = mech(lo), mech(hi)
    phi = 0.5 * (lo + hi)
    T = Q * float(s_lo["load"][0]) * np.array([np.cos(phi), np.sin(phi)])

    def tangent(s):
        m = s["normal"][0][:2]
        return np.array([-m[1], m[0]])

    ta, tb = tangent(s_lo), tangent(s_hi)
    turning = float(np.arctan2(ta[0] * tb[1] - ta[1] * tb[0], ta @ tb))
    ids = (tuple(int(i) for i in s_lo["facets"][0] if i >= 0),
           tuple(int(i) for i in s_hi["facets"][0] if i >= 0))
    return Corner(T=T, direction=float(np.arctan2(T[1], T[0])), before=ids[0], after=ids[1],
                  turning=turning, interior=float(np.pi - turning))


def _climb_force(geo: _Geometry, u: np.ndarray) -> np.ndarray:
    """Non-associated load (``Q = 1``) sliding at horizontal unit slips ``u`` (M, 2)."""
    n, p, mu = geo.n, geo.slope, geo.mu
    rise = u @ p.T                                        # (M, K): p_m . u
    top = np.max(rise, axis=-1, keepdims=True)
    tied = rise >= top - _TOL * (1.0 + np.abs(top))

    def single(j, rows):
        V = _unit(np.concatenate((u[rows], rise[rows, j][:, None]), axis=-1))
        den = n[j, 2] - mu * V[:, 2]
        with np.errstate(divide="ignore"):
            N = np.where(den > 0, 1.0 / np.where(den > 0, den, 1.0), np.inf)
        T = -(n[j, :2] - mu * V[:, :2])
        fin = np.isfinite(N)[:, None]
        return np.where(fin, np.where(fin, N[:, None], 0.0) * T, np.inf)

    out = np.empty((len(u), 2))
    j0 = np.argmax(rise, axis=-1)
    for j in np.unique(j0):
        rows = np.flatnonzero(j0 == j)
        out[rows] = single(np.full(len(rows), j), rows)
    for row in np.flatnonzero(tied.sum(axis=-1) > 1):
        js = np.flatnonzero(tied[row])
        loads = np.concatenate([single(np.array([j]), np.array([row])) for j in js])
        loads = loads[np.all(np.isfinite(loads), axis=-1)]
        if len(loads) == 0:
            out[row] = np.inf
            continue
        best = loads[np.argmin(np.hypot(*loads.T))]
        for a in range(len(loads)):
            for b in range(a + 1, len(loads)):
                seg = loads[b] - loads[a]
                s = np.clip(-(loads[a] @ seg) / max(seg @ seg, 1e-300), 0.0, 1.0)
                cand = loads[a] + s * seg
                if np.hypot(*cand) < np.hypot(*best):
                    best = cand
        out[row] = best
    return out


def _support_force(geo: _Geometry, u: np.ndarray) -> np.ndarray:
    """Associated load (``Q = 1``) sliding at ``u``: the support point of the convex curve."""
    phi = -np.pi + 2.0 * np.pi * np.arange(_CURVE_POINTS) / _CURVE_POINTS
    d = np.stack((np.cos(phi), np.sin(phi)), axis=-1)
    t = _solve(geo, d)["load"]
    fin = np.isfinite(t)
    P = t[fin, None] * d[fin]
    i = np.argmax(u @ P.T, axis=-1)
    # refine by golden-section search on the load direction within the neighbouring samples
    # (u.T(phi) is unimodal there: the curve is convex)
    step = 2.0 * np.pi / _CURVE_POINTS
    lo, hi = phi[fin][i] - step, phi[fin][i] + step
    g = 0.5 * (np.sqrt(5.0) - 1.0)

    def height(ph):
        e = np.stack((np.cos(ph), np.sin(ph)), axis=-1)
        tt = _solve(geo, e)["load"]
        fin = np.isfinite(tt)
        return np.where(fin, np.sum(u * e, axis=-1) * np.where(fin, tt, 0.0), -np.inf), tt, e

    for _ in range(40):
        a, b = hi - g * (hi - lo), lo + g * (hi - lo)
        left = height(a)[0] >= height(b)[0]
        hi = np.where(left, b, hi)
        lo = np.where(left, lo, a)
    h, tt, e = height(0.5 * (lo + hi))
    out = np.where((h >= np.sum(u * P[i], axis=-1))[:, None] & np.isfinite(tt)[:, None],
                   np.where(np.isfinite(tt), tt, 0.0)[:, None] * e, P[i])
    # an unbounded convex region contains its locked directions: the support is infinite
    if not fin.all():
        unbounded = np.any(u @ d[~fin].T > 1e-9, axis=-1)
        out = np.where(unbounded[:, None], np.inf, out)
    return out
