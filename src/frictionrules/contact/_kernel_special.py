"""The special returns the code generator recognises from a law's symbolic form
(:mod:`frictionrules.codegen._structure`): radial (one scalar equation along a fixed flow
direction) and elliptic (one scalar equation in the principal frame)."""

import math

from numba import njit

from .layout import RET_ALPHA1, RET_ALPHA2, RET_C, RET_COS, RET_LINEAR, RET_SIN
from .._returnspec import SCALAR_MAX_ITER as _SCALAR_MAX_ITER
from .._returnspec import SCALAR_TOL as _SCALAR_TOL
from .._returnspec import TOL as _TOL
from ._kernel_law import _eval, _layout


@njit(inline="always", error_model="numpy", _nrt=False)
def _radial(lf, l1, clip, law, sig_tr, qn, p, dv, w, wk, x):
    """The radial return (:mod:`frictionrules.codegen._structure`): along the flow direction
    ``v = (-D∇g, h)`` of the trial, which does not turn, ``x = x_tr + Δλ v`` with
    ``f(x) = 0`` — in closed form where f is linear along it, else by Newton's iteration on
    that one scalar equation. On entry ``w`` holds the first-level quantities at the trial.
    Writes ``x = (σ, q, Δλ)``; False where the path leaves the smooth part of the cone (T
    reverses, N <= 0) or the iteration fails: the general return takes over."""
    NQ = qn.shape[0]
    OFF_DF, OFF_DFQ, OFF_DG, OFF_HGG, OFF_HGQ, OFF_H, OFF_DHS, OFF_DHQ, SIZE = _layout(NQ)
    v0, v1, v2 = -dv[0] * w[OFF_DG], -dv[1] * w[OFF_DG + 1], -dv[2] * w[OFF_DG + 2]
    slope = w[OFF_DF] * v0 + w[OFF_DF + 1] * v1 + w[OFF_DF + 2] * v2
    for j in range(NQ):
        slope += w[OFF_DFQ + j] * w[OFF_H + j]
    if not slope < 0.0:
        return False
    lam = -w[0] / slope
    if law[RET_LINEAR] == 0.0:
        fs = math.sqrt(w[OFF_DF] ** 2 + w[OFF_DF + 1] ** 2 + w[OFF_DF + 2] ** 2) * math.sqrt(
            sig_tr[0] ** 2 + sig_tr[1] ** 2 + sig_tr[2] ** 2)
        for it in range(_SCALAR_MAX_ITER + 1):
            if it == _SCALAR_MAX_ITER or not (lam >= 0.0):
                return False
            for j in range(NQ):
                x[3 + j] = qn[j] + lam * w[OFF_H + j]
            _eval(lf, l1, l1, clip, sig_tr[0] + lam * v0, sig_tr[1] + lam * v1,
                  sig_tr[2] + lam * v2, x[3:3 + NQ], p, wk, 1)
            if abs(wk[0]) <= _TOL * fs:
                break
            d = wk[OFF_DF] * v0 + wk[OFF_DF + 1] * v1 + wk[OFF_DF + 2] * v2
            for j in range(NQ):
                d += wk[OFF_DFQ + j] * w[OFF_H + j]
            if not d < 0.0:
                return False
            lam -= wk[0] / d
    x[0] = sig_tr[0] + lam * v0
    x[1] = sig_tr[1] + lam * v1
    x[2] = sig_tr[2] + lam * v2
    for j in range(NQ):
        x[3 + j] = qn[j] + lam * w[OFF_H + j]
    x[3 + NQ] = lam
    return lam >= 0.0 and x[2] > 0.0 and x[0] * sig_tr[0] + x[1] * sig_tr[1] > 0.0


@njit(inline="always", error_model="numpy", _nrt=False)
def _elliptic(law, sig_tr, kt, f_tr, x):
    """The elliptic return (:mod:`frictionrules.codegen._structure`): in the principal frame
    ``(c, s)`` of ``g² = TᵀAT`` (eigenvalues α1, α2), ``T'_i = a_i/(1 + x α_i)``, N kept, and
    ``Σ α_i a_i²/(1 + x α_i)² = R²``, ``R = g_tr - f_tr/c``, convex and decreasing in
    ``x = kt Δλ/g``: Newton from 0 converges monotonically. Writes ``x = (σ, Δλ)``; False
    where R <= 0 (a return through the apex: the general return takes over)."""
    c, s = law[RET_COS], law[RET_SIN]
    al1, al2 = law[RET_ALPHA1], law[RET_ALPHA2]
    a1 = c * sig_tr[0] + s * sig_tr[1]
    a2 = -s * sig_tr[0] + c * sig_tr[1]
    r = math.sqrt(al1 * a1 * a1 + al2 * a2 * a2) - f_tr / law[RET_C]
    if not r > 0.0:
        return False
    r2 = r * r
    y = 0.0
    for it in range(_SCALAR_MAX_ITER + 1):
        if it == _SCALAR_MAX_ITER:
            return False
        d1 = 1.0 + y * al1
        d2 = 1.0 + y * al2
        q1 = al1 * a1 * a1 / (d1 * d1)
        q2 = al2 * a2 * a2 / (d2 * d2)
        dy = (q1 + q2 - r2) / (2.0 * (q1 * al1 / d1 + q2 * al2 / d2))
        y += dy
        if dy <= _SCALAR_TOL * y:
            break
    b1 = a1 / (1.0 + y * al1)
    b2 = a2 / (1.0 + y * al2)
    x[0] = c * b1 - s * b2
    x[1] = s * b1 + c * b2
    x[2] = sig_tr[2]
    x[3] = y * r / kt
    return True
