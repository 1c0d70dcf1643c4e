"""One home for the scalar and vectorized 1-D solvers of the package: Brent's root, the
vectorized Illinois root, golden-section minimization and the bisection of a boundary (a ray
to a limit curve, a change of mechanism along the load direction). NumPy only."""

from __future__ import annotations

import numpy as np

#: Machine epsilon: every stopping test is a few ulps of the abscissa.
_EPS = np.finfo(float).eps
#: Bisection steps of :func:`bisect_boundary`: 2**-60 of the bracket is below double precision
#: for any bracket of a few units (angles, fractions of a step).
BISECTIONS = 60


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


#: Iterations of the bracketed root finder; every fifth is a bisection, so 100 halve the bracket
#: at least 20 times on top of the superlinear steps.
MAX_ITER = 100


def bracketed_root(fun, a: np.ndarray, b: np.ndarray, fa: np.ndarray, fb: np.ndarray,
                   xtol: float = 0.0) -> np.ndarray:
    """Roots of ``fun`` in the brackets ``[a, b]`` (``fa * fb <= 0``), one per entry.

    The Illinois variant of regula falsi (Dowell & Jarratt 1971), with a bisection every fifth
    step; ``fun`` maps an array of abscissae (any subset of the entries, passed with their
    indices) to the function values: ``fun(x, idx)``. Converged where the bracket or a secant
    step is below ``xtol + 4 eps |x|``, or a value is exactly zero.
    """
    a, b = np.array(a, dtype=float), np.array(b, dtype=float)
    fa, fb = np.array(fa, dtype=float), np.array(fb, dtype=float)
    done = (fa == 0.0) | (fb == 0.0)
    for it in range(MAX_ITER):
        width = np.abs(b - a)
        done |= width <= xtol + 4.0 * _EPS * np.maximum(np.abs(a), np.abs(b))
        idx = np.flatnonzero(~done)
        if len(idx) == 0:
            break
        ai, bi, fai, fbi = a[idx], b[idx], fa[idx], fb[idx]
        with np.errstate(divide="ignore", invalid="ignore"):
            xi = bi - fbi * (bi - ai) / (fbi - fai)
        lo, hi = np.minimum(ai, bi), np.maximum(ai, bi)
        bisect = ~np.isfinite(xi) | (xi <= lo) | (xi >= hi) | (it % 5 == 4)
        xi = np.where(bisect, 0.5 * (ai + bi), xi)
        fx = np.asarray(fun(xi, idx), dtype=float)
        # a secant step below the tolerance has reached the root
        zero = (fx == 0.0) | (~bisect & (np.abs(xi - bi) <= xtol + 4.0 * _EPS * np.abs(xi)))
        swap = np.sign(fx) != np.sign(fbi)          # the root lies between b and x
        # Illinois: where the end a is kept a second time, halve its value
        a[idx] = np.where(swap, bi, ai)
        fa[idx] = np.where(swap, fbi, np.where(bisect, fai, 0.5 * fai))
        b[idx], fb[idx] = xi, fx
        done[idx[zero]] = True
    return np.where(fa == 0.0, a, b)


def golden_min(fun, lo: np.ndarray, hi: np.ndarray, iters: int = 60):
    """Minimizers and minima of unimodal ``fun`` on ``[lo, hi]`` (golden section), entrywise;
    ``fun`` maps an array of abscissae to values."""
    g = 0.5 * (np.sqrt(5.0) - 1.0)
    lo, hi = np.array(lo, dtype=float), np.array(hi, dtype=float)
    for _ in range(iters):
        a, b = hi - g * (hi - lo), lo + g * (hi - lo)
        left = fun(a) <= fun(b)
        hi = np.where(left, b, hi)
        lo = np.where(left, lo, a)
    x = 0.5 * (lo + hi)
    return x, fun(x)


def bisect_boundary(inside, lo: np.ndarray, hi: np.ndarray, steps: int = BISECTIONS,
                    scale: float = 1.0):
    """The boundary of a region along independent 1-D brackets, by bisection.

    ``inside`` maps an array of abscissae (one per entry) to a boolean array, true at ``lo``
    and false at ``hi``. Returns ``(lo, hi)`` with ``inside(lo)`` and ``not inside(hi)``,
    narrowed to a few ulps of ``max(scale, |lo|, |hi|)`` (``scale = 0``: relative to the
    abscissa) or ``steps`` halvings.
    """
    lo, hi = np.array(lo, dtype=float), np.array(hi, dtype=float)
    for _ in range(steps):
        if np.all(np.abs(hi - lo) <= 4.0 * _EPS * np.maximum(scale, np.maximum(np.abs(lo), np.abs(hi)))):
            break
        mid = 0.5 * (lo + hi)
        ins = np.asarray(inside(mid), dtype=bool)
        lo, hi = np.where(ins, mid, lo), np.where(ins, hi, mid)
    return lo, hi
