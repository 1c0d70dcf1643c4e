"""Generic inverse of a sliding rule: the force on the limit curve that slides at a given angle.

Used by laws without a closed-form inverse (user laws) and, in the tests, as an independent
check of every closed form.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import brentq

from ..errors import FrictionRulesError

_GRID = 720          # points on the limit curve scanned for brackets
_MAX_DOUBLINGS = 60  # radial bracket growth before a direction is called unbounded


def _wrap(a: np.ndarray) -> np.ndarray:
    return (a + np.pi) % (2.0 * np.pi) - np.pi


def _radius(law, centre: np.ndarray, n: float, phi: np.ndarray, scale: float) -> np.ndarray:
    """Distance from ``centre`` to the limit curve along angles ``phi`` (inf if unbounded)."""
    e = np.stack((np.cos(phi), np.sin(phi)), axis=-1)
    nn = np.full(phi.shape, n)

    def f(r):
        return law.limit(centre + r[:, None] * e, nn)

    lo = np.zeros(phi.shape)
    hi = np.full(phi.shape, scale)
    for _ in range(_MAX_DOUBLINGS):
        grow = f(hi) <= 0
        if not grow.any():
            break
        lo = np.where(grow, hi, lo)
        hi = np.where(grow, 2.0 * hi, hi)
    unbounded = f(hi) <= 0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        inside = f(mid) <= 0
        lo = np.where(inside, mid, lo)
        hi = np.where(inside, hi, mid)
        if np.all(hi - lo <= 4e-16 * np.maximum(hi, 1e-300)):
            break
    r = 0.5 * (lo + hi)
    return np.where(unbounded, np.inf, r)


def _solve_one(law, theta: float, n: float) -> tuple[np.ndarray, bool]:
    centre = np.asarray(law.centre(n), dtype=float)
    f0 = float(law.limit(centre, n))
    if f0 == 0.0:  # the limit curve has shrunk to a point (e.g. a cone at N = 0)
        return centre, False
    if f0 > 0.0:
        raise FrictionRulesError(
            f"the generic inverse needs a point inside the limit curve: f(centre={centre.tolist()}, "
            f"{law.normal_name}={n!r}) = {f0!r} violates f < 0")
    scale = max(abs(n), float(np.hypot(*centre)), 1.0)
    phi = np.linspace(-np.pi, np.pi, _GRID, endpoint=False)
    r = _radius(law, centre, n, phi, scale)

    def point(ph, rad):
        return centre + rad * np.array([np.cos(ph), np.sin(ph)])

    def mismatch(ph):
        rad = float(_radius(law, centre, n, np.array([ph]), scale)[0])
        s = law.slip_direction(point(ph, rad), n)
        return float(_wrap(np.arctan2(s[1], s[0]) - theta))

    finite = np.isfinite(r)
    P = centre + np.where(finite, r, 0.0)[:, None] * np.stack((np.cos(phi), np.sin(phi)), axis=-1)
    s = law.slip_direction(P, np.full(phi.shape, n))
    d = _wrap(np.arctan2(s[:, 1], s[:, 0]) - theta)
    d_next, fin_next = np.roll(d, -1), np.roll(finite, -1)
    brackets = np.flatnonzero(finite & fin_next & (d * d_next <= 0) & (np.abs(d - d_next) < np.pi))
    best, best_norm = None, np.inf
    for k in brackets:
        a = phi[k]
        b = phi[k] + 2.0 * np.pi / _GRID
        ph = a if d[k] == 0 else brentq(mismatch, a, b, xtol=1e-15, rtol=4 * np.finfo(float).eps)
        rad = float(_radius(law, centre, n, np.array([ph]), scale)[0])
        T = point(ph, rad)
        if np.hypot(*T) < best_norm:
            best, best_norm = T, float(np.hypot(*T))
    if best is None:
        return np.array([np.inf, np.inf]), True
    return best, False


def force_at_slip_angle(law, theta, N) -> np.ndarray:
    """Force on the limit curve at fixed ``N`` whose tangential slip is at angle ``theta``.

    Raises the law module's locked error (a :class:`FrictionRulesError`) when no point of the
    limit curve slides in one of the requested directions; the error carries the result with
    ``inf`` there.
    """
    from .base import _Locked

    theta, N = np.broadcast_arrays(np.asarray(theta, dtype=float), np.asarray(N, dtype=float))
    out = np.empty(theta.shape + (2,))
    locked = np.zeros(theta.shape, dtype=bool)
    for idx in np.ndindex(theta.shape):
        out[idx], locked[idx] = _solve_one(law, float(theta[idx]), float(N[idx]))
    if locked.any():
        first = tuple(np.argwhere(locked)[0])
        raise _Locked(
            f"no force on the limit curve slides at theta = {float(theta[first])!r} rad "
            f"({law.normal_name} = {float(N[first])!r}): the contact locks in that direction", out)
    return out
