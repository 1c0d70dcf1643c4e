"""Generic inverse of a sliding rule: the force on the limit curve that slides at a given angle.

Used by laws without a closed-form inverse (user laws) and, in the tests, as an independent
check of every closed form. NumPy only.
"""

from __future__ import annotations

import numpy as np

from ..errors import FrictionRulesError
from .._roots import bisect_boundary, brent
from ._records import InverseRelation

GRID = 720          # points on the limit curve scanned for brackets
_MAX_DOUBLINGS = 60  # radial bracket growth before a direction is called unbounded


def _wrap(a: np.ndarray) -> np.ndarray:
    return (a + np.pi) % (2.0 * np.pi) - np.pi


def radius(law, centre: np.ndarray, n: float, phi: np.ndarray, scale: float, q) -> np.ndarray:
    """Distance from ``centre`` to the limit curve along angles ``phi`` (inf if unbounded)."""
    e = np.stack((np.cos(phi), np.sin(phi)), axis=-1)
    nn = np.full(phi.shape, n)

    def f(r):
        return law.limit(centre + r[:, None] * e, nn, q)

    lo = np.zeros(phi.shape)
    hi = np.full(phi.shape, scale)
    for _ in range(_MAX_DOUBLINGS):
        grow = f(hi) <= 0
        if not grow.any():
            break
        lo = np.where(grow, hi, lo)
        hi = np.where(grow, 2.0 * hi, hi)
    unbounded = f(hi) <= 0
    lo, hi = bisect_boundary(lambda r: f(r) <= 0, lo, np.where(unbounded, lo, hi), steps=200, scale=0.0)
    r = 0.5 * (lo + hi)
    return np.where(unbounded, np.inf, r)


def _solve_one(law, theta: float, n: float, q) -> tuple[np.ndarray, bool]:
    centre = np.asarray(law.centre(n, q), dtype=float)
    f0 = float(law.limit(centre, n, q))
    if f0 == 0.0:  # the limit curve has shrunk to a point (e.g. a cone at N = 0)
        return centre, False
    if f0 > 0.0:
        raise FrictionRulesError(
            f"the generic inverse needs a point inside the limit curve: f(centre={centre.tolist()}, "
            f"{law.normal_name}={n!r}) = {f0!r} violates f < 0")
    scale = max(abs(n), float(np.hypot(*centre)), 1.0)
    phi = np.linspace(-np.pi, np.pi, GRID, endpoint=False)
    r = radius(law, centre, n, phi, scale, q)

    def point(ph, rad):
        return centre + rad * np.array([np.cos(ph), np.sin(ph)])

    def mismatch(ph):
        rad = float(radius(law, centre, n, np.array([ph]), scale, q)[0])
        s = law.slip_direction(point(ph, rad), n, q)
        return float(_wrap(np.arctan2(s[1], s[0]) - theta))

    finite = np.isfinite(r)
    P = centre + np.where(finite, r, 0.0)[:, None] * np.stack((np.cos(phi), np.sin(phi)), axis=-1)
    s = law.slip_direction(P, np.full(phi.shape, n), q)
    d = _wrap(np.arctan2(s[:, 1], s[:, 0]) - theta)
    d_next, fin_next = np.roll(d, -1), np.roll(finite, -1)
    brackets = np.flatnonzero(finite & fin_next & (d * d_next <= 0) & (np.abs(d - d_next) < np.pi))
    best, best_norm = None, np.inf
    for k in brackets:
        a = phi[k]
        b = phi[k] + 2.0 * np.pi / GRID
        ph = brent(mismatch, a, b, float(d[k]), float(d_next[k]))
        rad = float(radius(law, centre, n, np.array([ph]), scale, q)[0])
        T = point(ph, rad)
        if np.hypot(*T) < best_norm:
            best, best_norm = T, float(np.hypot(*T))
    if best is None:
        return np.array([np.inf, np.inf]), True
    return best, False


def inverse_relation(law, theta, N, q=None) -> InverseRelation:
    """Force on the limit curve at fixed ``N`` whose tangential slip is at angle ``theta``.

    Directions in which no point of the limit curve slides are flagged ``locked`` (forces
    ``inf``). ``q`` is one state for all points (``None``: the initial state).
    """
    theta, N = np.broadcast_arrays(np.asarray(theta, dtype=float), np.asarray(N, dtype=float))
    out = np.empty(theta.shape + (2,))
    locked = np.zeros(theta.shape, dtype=bool)
    for idx in np.ndindex(theta.shape):
        out[idx], locked[idx] = _solve_one(law, float(theta[idx]), float(N[idx]), q)
    return InverseRelation(out, locked)
