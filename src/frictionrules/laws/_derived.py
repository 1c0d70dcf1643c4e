"""Derivatives of f and g derived symbolically (SymPy) and compiled to NumPy functions.

Compiled once per law (the cache key is the frozen law itself).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import Callable

import numpy as np


def _broadcast(fun: Callable, shape_fn) -> Callable:
    def call(t1, t2, n):
        t1, t2, n = np.broadcast_arrays(t1, t2, n)
        with np.errstate(divide="ignore", invalid="ignore"):
            out = fun(t1, t2, n)
        return shape_fn(out, t1.shape)
    return call


def _scalar(out, shape):
    return np.broadcast_to(np.asarray(out, dtype=float), shape).copy()


def _vector(out, shape):
    return np.stack([np.broadcast_to(np.asarray(o, dtype=float), shape) for o in out], axis=-1)


def _matrix(out, shape):
    rows = [_vector(row, shape) for row in out]
    return np.stack(rows, axis=-2)


@dataclass(frozen=True)
class Compiled:
    """Compiled f, g and their gradients and Hessians in ``(T1, T2, N)``."""

    f: Callable
    g: Callable
    grad_f: Callable
    grad_g: Callable
    hess_f: Callable
    hess_g: Callable


def compile_expressions(f_expr, g_expr) -> Compiled:
    """Differentiate ``f`` and ``g`` in ``(T1, T2, N)`` and lambdify everything to NumPy."""
    import sympy

    from .symbols import N, T1, T2

    x = (T1, T2, N)

    def lam(expr):
        return sympy.lambdify(x, expr, modules="numpy")

    def parts(expr):
        grad = [sympy.diff(expr, s) for s in x]
        hess = [[sympy.diff(gi, s) for s in x] for gi in grad]
        return (_broadcast(lam(expr), _scalar), _broadcast(lam(grad), _vector),
                _broadcast(lam(hess), _matrix))

    f, gf, hf = parts(f_expr)
    g, gg, hg = parts(g_expr)
    return Compiled(f, g, gf, gg, hf, hg)


@functools.lru_cache(maxsize=256)
def compiled(law) -> Compiled:
    """The compiled derivatives of ``law.symbolic()``."""
    return compile_expressions(*law.symbolic())
