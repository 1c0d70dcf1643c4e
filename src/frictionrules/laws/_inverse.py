"""Generic inverse of a sliding rule: the force on the limit curve that slides at a given angle.

Used by laws without a closed-form inverse (user laws) and, in the tests, as an independent
check of every closed form. NumPy only.
"""

from __future__ import annotations

import numpy as np

from ..errors import FrictionRulesError
from ._records import InverseRelation

_GRID = 720          # points on the limit curve scanned for brackets
_MAX_DOUBLINGS = 60  # radial bracket growth before a direction is called unbounded
_EPS = np.finfo(float).eps


def _wrap(a: np.ndarray) -> np.ndarray:
    return (a + np.pi) % (2.0 * np.pi) - np.pi


def brent(fun, a: float, b: float, fa: float, fb: float, xtol: float = 1e-15,
          max_iter: int = 200) -> float:
    """A root of ``fun`` in ``[a, b]`` with ``fa * fb <= 0`` by Brent's method (inverse quadratic
    interpolation, secant and bisection steps; Brent 1973, ch. 4)."""
    if fa == 0.0:
        return a
    if fb == 0.0:
        return b
    c, fc = a, fa
    d = e = b - a
    for _ in range(max_iter):
        if fb * fc > 0:
            c, fc = a, fa
            d = e = b - a
        if abs(fc) < abs(fb):
            a, b, c = b, c, b
            fa, fb, fc = fb, fc, fb
        tol = 2.0 * _EPS * abs(b) + 0.5 * xtol
        m = 0.5 * (c - b)
        if abs(m) <= tol or fb == 0.0:
            return b
        if abs(e) >= tol and abs(fa) > abs(fb):
            s = fb / fa
            if a == c:
                p, q = 2.0 * m * s, 1.0 - s
            else:
                qq, r = fa / fc, fb / fc
                p = s * (2.0 * m * qq * (qq - r) - (b - a) * (r - 1.0))
                q = (qq - 1.0) * (r - 1.0) * (s - 1.0)
            if p > 0:
                q = -q
            p = abs(p)
            if 2.0 * p < min(3.0 * m * q - abs(tol * q), abs(e * q)):
                e, d = d, p / q
            else:
                d = e = m
        else:
            d = e = m
        a, fa = b, fb
        b += d if abs(d) > tol else (tol if m > 0 else -tol)
        fb = fun(b)
    return b


def _radius(law, centre: np.ndarray, n: float, phi: np.ndarray, scale: float, q) -> np.ndarray:
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
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        inside = f(mid) <= 0
        lo = np.where(inside, mid, lo)
        hi = np.where(inside, hi, mid)
        if np.all(hi - lo <= 4e-16 * np.maximum(hi, 1e-300)):
            break
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
    phi = np.linspace(-np.pi, np.pi, _GRID, endpoint=False)
    r = _radius(law, centre, n, phi, scale, q)

    def point(ph, rad):
        return centre + rad * np.array([np.cos(ph), np.sin(ph)])

    def mismatch(ph):
        rad = float(_radius(law, centre, n, np.array([ph]), scale, q)[0])
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
        b = phi[k] + 2.0 * np.pi / _GRID
        ph = brent(mismatch, a, b, float(d[k]), float(d_next[k]))
        rad = float(_radius(law, centre, n, np.array([ph]), scale, q)[0])
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
