r"""Inverse problems on a facet set's limit curve: corners, and the load that slides a given way.

Every function takes a *solver*: an object whose ``solve(d)`` returns the
:class:`~._results.Mechanisms` at ``Q = 1`` in the unit directions ``d`` (M, 2).
"""

from __future__ import annotations

import numpy as np

from .._roots import bisect_boundary, golden_min
from ._hull import TOL, unit
from ._results import Corner

#: Directions of the support-point search of the associated inverse.
CURVE_POINTS = 4096


def directions(phi: np.ndarray) -> np.ndarray:
    return np.stack((np.cos(phi), np.sin(phi)), axis=-1)


def corners(solver, lo: np.ndarray, hi: np.ndarray, before: list, Q: float) -> list:
    """Bisect the load directions between ``lo[i]`` (mechanism ``before[i]``) and ``hi[i]``,
    all corners at once, and classify each by the turning of the tangent."""
    lo, hi = np.array(lo, dtype=float), np.array(hi, dtype=float)
    if len(lo) == 0:
        return []

    def same(mid):
        s = solver.solve(directions(mid))
        return np.array([s.mechanism(i) == b for i, b in enumerate(before)])

    lo, hi = bisect_boundary(same, lo, hi)
    s_lo, s_hi = solver.solve(directions(lo)), solver.solve(directions(hi))
    phi = 0.5 * (lo + hi)
    out = []
    for i in range(len(lo)):
        T = Q * float(s_lo.load[i]) * np.array([np.cos(phi[i]), np.sin(phi[i])])
        ma, mb = s_lo.normal[i][:2], s_hi.normal[i][:2]
        ta, tb = np.array([-ma[1], ma[0]]), np.array([-mb[1], mb[0]])
        turning = float(np.arctan2(ta[0] * tb[1] - ta[1] * tb[0], ta @ tb))
        out.append(Corner(T=T, direction=float(np.arctan2(T[1], T[0])), before=s_lo.mechanism(i),
                          after=s_hi.mechanism(i), turning=turning,
                          interior=float(np.pi - turning)))
    return out


def climb_force(geo, u: np.ndarray) -> np.ndarray:
    """Non-associated Coulomb load (``Q = 1``) sliding at horizontal unit slips ``u`` (M, 2)."""
    n, p, mu = geo.n, geo.slope, geo.mu
    rise = u @ p.T                                        # (M, K): p_m . u
    top = np.max(rise, axis=-1, keepdims=True)
    tied = rise >= top - TOL * (1.0 + np.abs(top))

    def single(j, rows):
        V = unit(np.concatenate((u[rows], rise[rows, j][:, None]), axis=-1))
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
        out[row] = nearest_on_segments(loads)
    return out


def nearest_on_segments(loads: np.ndarray) -> np.ndarray:
    """The point of smallest norm on the segments between finite ``loads`` (L, 2) (a flat face
    of the limit curve sliding one way); ``inf`` when none is finite."""
    loads = loads[np.all(np.isfinite(loads), axis=-1)]
    if len(loads) == 0:
        return np.full(2, np.inf)
    best = loads[np.argmin(np.hypot(*loads.T))]
    for a in range(len(loads)):
        for b in range(a + 1, len(loads)):
            seg = loads[b] - loads[a]
            s = np.clip(-(loads[a] @ seg) / max(seg @ seg, 1e-300), 0.0, 1.0)
            cand = loads[a] + s * seg
            if np.hypot(*cand) < np.hypot(*best):
                best = cand
    return best


def support_force(solver, u: np.ndarray) -> np.ndarray:
    """Associated load (``Q = 1``) sliding at ``u``: the support point of the convex curve."""
    phi = -np.pi + 2.0 * np.pi * np.arange(CURVE_POINTS) / CURVE_POINTS
    d = directions(phi)
    t = solver.solve(d).load
    fin = np.isfinite(t)
    P = t[fin, None] * d[fin]
    i = np.argmax(u @ P.T, axis=-1)
    # refine by golden-section search on the load direction within the neighbouring samples
    # (u.T(phi) is unimodal there: the curve is convex)
    step = 2.0 * np.pi / CURVE_POINTS
    lo, hi = phi[fin][i] - step, phi[fin][i] + step

    def height(ph):
        e = directions(ph)
        tt = solver.solve(e).load
        fin = np.isfinite(tt)
        return np.where(fin, np.sum(u * e, axis=-1) * np.where(fin, tt, 0.0), -np.inf), tt, e

    best, _ = golden_min(lambda ph: -height(ph)[0], lo, hi, iters=40)
    h, tt, e = height(best)
    out = np.where((h >= np.sum(u * P[i], axis=-1))[:, None] & np.isfinite(tt)[:, None],
                   np.where(np.isfinite(tt), tt, 0.0)[:, None] * e, P[i])
    # an unbounded convex region contains its locked directions: the support is infinite
    if not fin.all():
        unbounded = np.any(u @ d[~fin].T > 1e-9, axis=-1)
        out = np.where(unbounded[:, None], np.inf, out)
    return out
