"""Vectorized bracketed root finding and minimization on arrays of independent 1-D problems."""

from __future__ import annotations

import numpy as np

#: Iterations of the bracketed root finder; every fifth is a bisection, so 100 halve the bracket
#: at least 20 times on top of the superlinear steps.
MAX_ITER = 100
_EPS = np.finfo(float).eps


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
