"""The elliptic return the code generator recognises from a law's symbolic form
(:mod:`frictionrules.codegen._structure`): one scalar equation in the principal frame, called
by the law's generated step and by the general compiled return (with the tangent)."""

import math

from numba import njit

from .layout import RET_ALPHA1, RET_ALPHA2, RET_C, RET_COS, RET_SIN
from .._returnspec import SCALAR_MAX_ITER as _SCALAR_MAX_ITER
from .._returnspec import SCALAR_TOL as _SCALAR_TOL


@njit(inline="always", error_model="numpy", _nrt=False)
def elliptic_return(law, x0, x1, kt, f_tr):
    """The elliptic return (:mod:`frictionrules.codegen._structure`): in the principal frame
    ``(c, s)`` of ``g² = TᵀAT`` (eigenvalues α1, α2), ``T'_i = a_i/(1 + x α_i)``, N kept, and
    ``Σ α_i a_i²/(1 + x α_i)² = R²``, ``R = g_tr - f_tr/c``, convex and decreasing in
    ``x = kt Δλ/g``: Newton's iteration from a point left of the root (from x = 0, or from
    the root of the same equation with the larger α in both terms, which is smaller) converges
    monotonically. Returns ``(ok, T1, T2, Δλ)`` for the trial ``(x0, x1)``; not ok where
    R <= 0 (a return through the apex: the general return takes over)."""
    c, s = law[RET_COS], law[RET_SIN]
    al1, al2 = law[RET_ALPHA1], law[RET_ALPHA2]
    a1 = c * x0 + s * x1
    a2 = -s * x0 + c * x1
    g = math.sqrt(al1 * a1 * a1 + al2 * a2 * a2)
    r = g - f_tr / law[RET_C]
    if not r > 0.0:
        return False, 0.0, 0.0, 0.0
    ok, y = ellipse_root(a1, a2, al1, al2, al1, al2, g, r)
    if not ok:
        return False, 0.0, 0.0, 0.0
    b1 = a1 / (1.0 + y * al1)
    b2 = a2 / (1.0 + y * al2)
    return True, c * b1 - s * b2, s * b1 + c * b2, y * r / kt


@njit(inline="always", error_model="numpy", _nrt=False)
def ellipse_root(a1, a2, al1, al2, pi1, pi2, k, r):
    """The multiplier ``y`` of a return along ``g² = α1 a1² + α2 a2²`` (principal frame) onto
    ``π1 b1² + π2 b2² = r²``, ``b_i = a_i/(1 + y α_i)``: the root of
    ``Σ π_i a_i²/(1 + y α_i)² = r²``, convex and decreasing in y, by Newton's iteration from a
    point left of the root (the root with the larger α in both terms: ``k/(1 + y max α) = r``,
    ``k² = Σ π_i a_i²``), where it rises monotonically. Returns ``(ok, y)``; not ok after
    ``SCALAR_MAX_ITER`` steps. The associated elliptic return (π = α) and the projection of
    two coaxial elliptic cones in the many-contact solvers share it."""
    r2 = r * r
    y = max((k / r - 1.0) / max(al1, al2), 0.0)
    for _ in range(_SCALAR_MAX_ITER):
        d1 = 1.0 + y * al1
        d2 = 1.0 + y * al2
        q1 = pi1 * a1 * a1 / (d1 * d1)
        q2 = pi2 * a2 * a2 / (d2 * d2)
        dy = (q1 + q2 - r2) / (2.0 * (q1 * al1 / d1 + q2 * al2 / d2))
        y += dy
        if dy <= _SCALAR_TOL * y:
            return True, y
    return False, y
