r"""The protocol of a facet set as a law in external loads, shared by every facet law.

A facet law uses the vertical load ``Q`` in the place of ``N`` and the block velocity as the
generalized slip:

.. math:: f(T, Q) = |T| - Q\,t_1(T/|T|),

with :math:`t_1` the limit load at ``Q = 1``: negative inside, zero on the limit surface,
positive outside, ``-inf`` in locked directions (``t_1 = inf``). At ``T = 0`` the direction is
taken as +x. Everything is homogeneous of degree one in ``(T, Q)``.
"""

from __future__ import annotations

import numpy as np

from ..errors import FrictionRulesError, check_finite, check_scalar
from ..laws import FrictionLaw, InverseRelation
from ._hull import unit
from ._inverse import corners, directions
from ._results import LimitCurve, LimitLoads

_FLIP = np.array([1.0, 1.0, -1.0])   # d/dF -> d/d(Tx, Ty, Q) with F = (Tx, Ty, -Q)


class FacetLaw(FrictionLaw):
    """Protocol implementation shared by :class:`FacetSet` and the two-flank asperity.

    A subclass provides ``_facets`` (the :class:`FacetSet` it is).
    """

    normal_name = "Q"

    @property
    def _facets(self):  # pragma: no cover - abstract
        raise NotImplementedError

    @property
    def associated(self) -> bool:
        """True when every facet's local law is associated (g = f): the dilatant rule (1.6) for
        local Coulomb friction. The global law is then associated too."""
        return self._facets._solver.associated

    def mechanism_name(self, label: str) -> str:
        """The name of a mechanism of :meth:`limit_curve` by its label (``"0"``, ``"0+1"``:
        the sliding facets)."""
        return f"facet{'s' if '+' in label else ''} {label}"

    # ---- mechanisms ----------------------------------------------------------------------
    def limit_load(self, direction, Q=1.0):
        """Limit load in the horizontal ``direction`` ``(dx, dy)`` at vertical load ``Q``.

        The smallest load factor ``t >= 0`` at which ``F = (t d, -Q)`` (``d`` the unit
        direction) admits a kinematically admissible mechanism, with the sliding facets, their
        normal forces and the block velocity: one facet where its local limit condition is
        met (a root in ``t``: a quadratic for cone laws), two facets where their velocity
        (fixed by the two local sliding rules) and equilibrium (a 3×3 linear system) allow
        it. Locked (``load = inf``, ``mechanism = None``) when no mechanism exists in that
        direction.

        Parameters
        ----------
        direction : array (2,) or (M, 2)
            Horizontal load direction(s), nonzero.
        Q : float
            Vertical load, ``Q >= 0``.

        Returns
        -------
        LimitLoad
            For one direction ``(2,)``.
        LimitLoads
            For ``(M, 2)`` directions: the same fields as arrays, with a ``locked`` flag.
        """
        d = check_finite("direction", direction)
        if d.ndim not in (1, 2) or d.shape[-1] != 2:
            raise FrictionRulesError(f"direction must have shape (2,) or (M, 2), got shape "
                                     f"{d.shape}")
        norm = np.hypot(d[..., 0], d[..., 1])
        if np.any(norm == 0):
            bad = d if d.ndim == 1 else d[int(np.argmin(norm))]
            raise FrictionRulesError(f"direction = {bad.tolist()!r} violates: a nonzero 2-vector")
        Q = check_scalar("Q", Q, lo=0.0)
        dd = (d / norm[..., None]).reshape(-1, 2)
        sol = self._facets._solver.solve(dd)
        K = len(self._facets.normals)
        forces = np.zeros((len(dd), K))
        for s in range(2):
            rows = np.flatnonzero(sol.active[:, s])
            forces[rows, sol.facets[rows, s]] = Q * sol.forces[rows, s]
        locked = ~sol.active[:, 0]
        t = np.where(locked, np.inf, np.where(locked, 0.0, sol.load) * Q)
        T = np.where(locked[:, None], np.inf, np.where(locked, 0.0, t)[:, None] * dd)
        out = LimitLoads(load=t, T=T, locked=locked, facets=sol.facets, active=sol.active,
                         normal_forces=forces, velocity=sol.velocity,
                         quasi_static=sol.quasi_static)
        return out[0] if d.ndim == 1 else out

    def limit_curve(self, Q=1.0, n: int = 720) -> LimitCurve:
        """The limit curve at fixed ``Q`` over ``n`` load directions, with corners.

        Corners are located by bisection on the load direction between two samples with
        different mechanisms and classified by the turning of the tangent (the tangents of the
        two mechanisms' limit surfaces at the corner).
        """
        Q = check_scalar("Q", Q, lo=0.0, lo_open=True)
        phi = -np.pi + 2.0 * np.pi * np.arange(n) / n
        solver = self._facets._solver
        sol = solver.solve(directions(phi))
        load = Q * sol.load
        fin = np.isfinite(load)
        T = np.where(fin[:, None], np.where(fin, load, 0.0)[:, None] * directions(phi), np.inf)
        vel, nrm = sol.velocity, sol.normal
        lo, hi, before = [], [], []
        for i in range(n):
            i2 = (i + 1) % n
            a, b = sol.mechanism(i), sol.mechanism(i2)
            if np.isfinite(load[i]) and np.isfinite(load[i2]) and a != b:
                lo.append(phi[i])
                hi.append(phi[i2] + (2.0 * np.pi if i2 == 0 else 0.0))
                before.append(a)
        return LimitCurve(Q=Q, direction=phi, T=T, load=load, facets=sol.labelled_facets(),
                          normal_forces=Q * sol.forces, velocity=vel, normal=nrm,
                          rule_angle=_angle(vel, nrm), tangential_rule_angle=_angle(vel[:, :2],
                                                                                    nrm[:, :2]),
                          corners=tuple(corners(solver, lo, hi, before, Q)),
                          quasi_static=sol.quasi_static)

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
        sol = self._facets._solver.solve(unit(d.reshape(-1, 2)))
        return T, Q, r, sol

    def limit(self, T, Q, q=None):
        """:math:`f = |T| - Q\\,t_1(T/|T|)`: < 0 inside, 0 on the limit surface, -inf locked."""
        T, Q, r, sol = self._at(T, Q)
        with np.errstate(invalid="ignore"):
            f = r - Q * sol.load.reshape(r.shape)
        return np.where(Q > 0, f, r)

    def _terms(self, T, Q):
        """Per point: the gradients (in ``F = (Tx, Ty, -Q)``) of the active mechanism's limit
        function and potential, and the potential."""
        T, Q, r, sol = self._at(T, Q)
        F = np.concatenate((T, -Q[..., None]), axis=-1).reshape(-1, 3)
        single = sol.active[:, 0] & ~sol.active[:, 1]
        df, g1, dg1 = self._facets._solver.one_facet_terms(F, sol.facets[:, 0], sol.quasi_static)
        V = sol.velocity
        df = np.where(single[:, None], df, sol.normal)
        g = np.where(single, g1, np.sum(F * V, axis=-1))
        dg = np.where(single[:, None], dg1, V)
        shape = r.shape
        return df.reshape(shape + (3,)), g.reshape(shape), dg.reshape(shape + (3,))

    def potential(self, T, Q, q=None):
        """Global potential of the mechanism active in the direction of ``T``.

        One facet ``j``: the local potential :math:`g_j` at the facet's local forces
        :math:`(F\\cdot t_1, F\\cdot t_2, -F\\cdot n_j)`; for local Coulomb friction
        :math:`g = |F - (F\\cdot n_j)n_j|` (the wedge potential (2.6), (2.14)), with the dilatant
        rule :math:`g = |F_t| + \\mu F\\cdot n_j`. Two facets: :math:`g = V\\cdot F` with the
        mechanism's unit velocity ``V`` ((2.15): ``g = ±Ty`` for the two-flank asperity). Zero in
        locked directions. Where the static maximum limits a set of non-associated local laws
        (``quasi_static`` False) the potential of their associated twins (g = f) is used.
        """
        return self._terms(T, Q)[1]

    def potential_gradient(self, T, Q, q=None):
        """``(dg/dTx, dg/dTy, dg/dQ)`` of :meth:`potential`."""
        return self._terms(T, Q)[2] * _FLIP

    def limit_gradient(self, T, Q, q=None):
        """Gradient of the active mechanism's limit function ``f_m``.

        One facet: the local limit condition at the facet's local forces (for local Coulomb
        friction :math:`f_j = |F_t| + \\mu F\\cdot n_j`, the wedge limit (2.2) in its
        degree-one form, gradient :math:`w + \\mu n_j`); two facets: the plane of the mechanism
        with its unit outward normal. Returned in ``(Tx, Ty, Q)``; zero in locked directions.
        """
        return self._terms(T, Q)[0] * _FLIP

    # No symbolic form (capability "symbolic"): the global law is piecewise, each piece valid
    # on a range of loads that depends on kinematic admissibility; everything here is
    # closed-form per mechanism.

    def centre(self, Q, q=None) -> np.ndarray:
        Q = np.asarray(Q, dtype=float)
        return np.zeros(Q.shape + (2,))

    def _inverse_relation(self, theta, Q, q):
        """Load on the limit curve whose block velocity slides at the horizontal angle ``theta``.

        Local Coulomb friction, non-associated: for the horizontal slip ``u`` every admissible
        velocity has :math:`V_z \\ge \\max_m p_m\\cdot u` (``p_m`` the facet gradients), so the
        block climbs the facet ``j`` that attains the maximum (a support function of the
        gradients) with :math:`V = (u, p_j\\cdot u)`, and equilibrium gives
        :math:`N_j = Q/(n_{jz} - \\mu \\hat V_z)`, :math:`T = -N_j(n_j - \\mu\\hat V)_h`;
        locked where :math:`n_{jz} - \\mu\\hat V_z \\le 0`. Where several facets attain the
        maximum (the velocity runs along their intersection) the loads form a segment and the
        smallest ``|T|`` on it is returned. Associated: the limit curve is convex and the load
        is its support point in the direction ``u`` (found on a dense curve). Other local laws:
        the points of the limit curve of :meth:`limit_load` whose block velocity slides at
        ``theta``, found by bisection on the load direction (the smallest ``|T|`` of them; at a
        corner whose velocities fan over ``theta``, the corner).

        This is the velocity-driven load, unique for every ``theta``. For a non-associated
        Coulomb set whose mechanism pieces fold it can lie beyond the first mechanism met on
        its radial load path (:meth:`limit_load`), where ``limit > 0``; see
        ``docs/asperities.md``.
        """
        theta, Q = np.broadcast_arrays(np.asarray(theta, dtype=float), np.asarray(Q, dtype=float))
        T = self._facets._solver.slide_force(directions(theta.reshape(-1)))
        T = Q.reshape(-1)[:, None] * T
        T = np.where(np.isfinite(T), T, np.inf).reshape(theta.shape + (2,))
        return InverseRelation(T, ~np.all(np.isfinite(T), axis=-1))


def _angle(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    na, nb = np.linalg.norm(a, axis=-1), np.linalg.norm(b, axis=-1)
    ok = (na > 0) & (nb > 0)
    c = np.sum(a * b, axis=-1) / np.where(ok, na * nb, 1.0)
    return np.where(ok, np.arccos(np.clip(c, -1.0, 1.0)), 0.0)
