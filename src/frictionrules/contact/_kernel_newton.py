"""The compiled Newton return of :mod:`frictionrules.contact._return_kernel`: the scaled
backward-Euler residual, its Jacobian and LU, the closed-form first step, the line-searched
iteration, the apex region of a cone and the closed-form tangent of a law without internal
variables."""

import math

from numba import njit

from .._returnspec import MAX_HALVINGS as _MAX_HALVINGS
from .._returnspec import MAX_ITER as _MAX_ITER
from .._returnspec import TOL as _TOL
from .._returnspec import sufficient_decrease as _sufficient_decrease
from ._kernel_law import _eval, _layout

#: Armijo's rule of every compiled line search: the specification's own function, compiled.
sufficient_decrease = njit(inline="always", error_model="numpy", _nrt=False)(
    _sufficient_decrease)


@njit(inline="always", error_model="numpy", _nrt=False)
def _residual(w, x, sig_tr, qn, dv, rows, out):
    """Scaled backward-Euler residual at ``x = (σ, q, Δλ)`` into ``out``; returns its norm."""
    NQ = qn.shape[0]
    _M = 4 + NQ
    OFF_DF, OFF_DFQ, OFF_DG, OFF_HGG, OFF_HGQ, OFF_H, OFF_DHS, OFF_DHQ, SIZE = _layout(NQ)
    lam = x[_M - 1]
    acc = 0.0
    for a in range(3):
        r = (x[a] - sig_tr[a] + lam * dv[a] * w[OFF_DG + a]) * rows[a]
        out[a] = r
        acc += r * r
    for j in range(NQ):
        r = (x[3 + j] - qn[j] - lam * w[OFF_H + j]) * rows[3 + j]
        out[3 + j] = r
        acc += r * r
    r = w[0] * rows[_M - 1]
    out[_M - 1] = r
    acc += r * r
    return math.sqrt(acc)


@njit(error_model="numpy", _nrt=False)
def _jacobian(w, lam, dv, J):
    """Newton Jacobian of the residual in ``(σ, q, Δλ)`` (unscaled), into ``J``."""
    NQ = J.shape[0] - 4
    OFF_DF, OFF_DFQ, OFF_DG, OFF_HGG, OFF_HGQ, OFF_H, OFF_DHS, OFF_DHQ, SIZE = _layout(NQ)
    m = 3 + NQ
    for a in range(3):
        for b in range(3):
            J[a, b] = (1.0 if a == b else 0.0) + lam * dv[a] * w[OFF_HGG + 3 * a + b]
        for j in range(NQ):
            J[a, 3 + j] = lam * dv[a] * w[OFF_HGQ + NQ * a + j]
        J[a, m] = dv[a] * w[OFF_DG + a]
    for j in range(NQ):
        for b in range(3):
            J[3 + j, b] = -lam * w[OFF_DHS + 3 * j + b]
        for k in range(NQ):
            J[3 + j, 3 + k] = (1.0 if j == k else 0.0) - lam * w[OFF_DHQ + NQ * j + k]
        J[3 + j, m] = -w[OFF_H + j]
    for b in range(3):
        J[m, b] = w[OFF_DF + b]
    for k in range(NQ):
        J[m, 3 + k] = w[OFF_DFQ + k]
    J[m, m] = 0.0


@njit(error_model="numpy", _nrt=False)
def _factor(J, piv):
    """LU factorization with partial pivoting in place; False when singular."""
    _M = J.shape[0]
    for c in range(_M):
        best, k = abs(J[c, c]), c
        for r in range(c + 1, _M):
            if abs(J[r, c]) > best:
                best, k = abs(J[r, c]), r
        piv[c] = k
        if best == 0.0 or not math.isfinite(best):
            return False
        if k != c:
            for j in range(_M):
                J[c, j], J[k, j] = J[k, j], J[c, j]
        inv = 1.0 / J[c, c]
        for r in range(c + 1, _M):
            J[r, c] *= inv
            l = J[r, c]
            if l != 0.0:
                for j in range(c + 1, _M):
                    J[r, j] -= l * J[c, j]
    return True


@njit(error_model="numpy", _nrt=False)
def _lu_solve(J, piv, b):
    """Solve with the factors of :func:`_factor`, ``b`` overwritten by the solution."""
    _M = J.shape[0]
    for c in range(_M):
        k = piv[c]
        if k != c:
            b[c], b[k] = b[k], b[c]
    for r in range(1, _M):
        acc = b[r]
        for j in range(r):
            acc -= J[r, j] * b[j]
        b[r] = acc
    for r in range(_M - 1, -1, -1):
        acc = b[r]
        for j in range(r + 1, _M):
            acc -= J[r, j] * b[j]
        b[r] = acc / J[r, r]


@njit(inline="always", error_model="numpy", _nrt=False)
def _first_step(w, R, rows, dv, step):
    """Newton step from ``Δλ = 0`` (unscaled, into ``step``): with the unscaled residual
    ``r = (r_σ, r_q, f)``, ``Δλ = (f - ∇f·r_σ - ∂f/∂q·r_q) / (∇f·D∇g - ∂f/∂q·h)``,
    ``Δσ = -r_σ - Δλ D∇g``, ``Δq = -r_q + Δλ h``. False where the denominator vanishes."""
    _M = R.shape[0]
    NQ = _M - 4
    OFF_DF, OFF_DFQ, OFF_DG, OFF_HGG, OFF_HGQ, OFF_H, OFF_DHS, OFF_DHQ, SIZE = _layout(NQ)
    num = R[_M - 1] / rows[_M - 1]
    den = 0.0
    for a in range(3):
        num -= w[OFF_DF + a] * R[a] / rows[a]
        den += w[OFF_DF + a] * dv[a] * w[OFF_DG + a]
    for j in range(NQ):
        num -= w[OFF_DFQ + j] * R[3 + j] / rows[3 + j]
        den -= w[OFF_DFQ + j] * w[OFF_H + j]
    if den == 0.0 or not math.isfinite(den):
        return False
    lam = num / den
    for a in range(3):
        step[a] = -R[a] / rows[a] - lam * dv[a] * w[OFF_DG + a]
    for j in range(NQ):
        step[3 + j] = -R[3 + j] / rows[3 + j] + lam * w[OFF_H + j]
    step[_M - 1] = lam
    return True


@njit(error_model="numpy", _nrt=False)
def _return(lf, l1, l2, clip, sig_tr, qn, p, dv, V, w, wk, J, piv):
    """Newton return of ``sig_tr`` onto f = 0 from ``x = (σ_tr, q_n, 0)``; True if converged.
    On entry ``w`` holds the law's first-level quantities at the trial.

    ``V`` holds the vectors of the iteration (rows: iterate, trial iterate, row and column
    scales, residual, trial residual, step). Leaves the last iterate in ``V[0]`` and the law's
    quantities there in ``w``.
    """
    NQ = qn.shape[0]
    _M = 4 + NQ
    OFF_DF, OFF_DFQ, OFF_DG, OFF_HGG, OFF_HGQ, OFF_H, OFF_DHS, OFF_DHQ, SIZE = _layout(NQ)
    x, xk, rows, cols, R, Rk, step = V[0], V[1], V[2], V[3], V[4], V[5], V[6]
    F = max(math.sqrt(sig_tr[0] ** 2 + sig_tr[1] ** 2 + sig_tr[2] ** 2), 1e-300)
    full = False
    dfn = math.sqrt(w[OFF_DF] ** 2 + w[OFF_DF + 1] ** 2 + w[OFF_DF + 2] ** 2)
    fs = max(dfn * F, 1e-300)
    gs = max(math.sqrt((dv[0] * w[OFF_DG]) ** 2 + (dv[1] * w[OFF_DG + 1]) ** 2
                       + (dv[2] * w[OFF_DG + 2]) ** 2), 1e-300)
    lam_s = F / gs
    for a in range(3):
        rows[a] = 1.0 / F
        cols[a] = F
        x[a] = sig_tr[a]
    for j in range(NQ):
        qs = max(max(abs(w[OFF_H + j]) * lam_s, abs(qn[j])), 1e-300)
        rows[3 + j] = 1.0 / qs
        cols[3 + j] = qs
        x[3 + j] = qn[j]
    rows[_M - 1] = 1.0 / fs
    cols[_M - 1] = lam_s
    x[_M - 1] = 0.0
    merit = _residual(w, x, sig_tr, qn, dv, rows, R)
    for it in range(_MAX_ITER):
        if merit <= _TOL:
            break
        if it == 0:
            # At Δλ = 0 the Jacobian is [[I, 0, D∇g], [0, I, -h], [∇f, ∂f/∂q, 0]]: its
            # Newton step in closed form (the scaled system has the same solution).
            if not _first_step(w, R, rows, dv, step):
                return False
        else:
            if not full:
                _eval(lf, l1, l2, clip, x[0], x[1], x[2], x[3:3 + NQ], p, w, 2)
            _jacobian(w, x[_M - 1], dv, J)
            for a in range(_M):
                for b in range(_M):
                    J[a, b] *= rows[a] * cols[b]
            if not _factor(J, piv):
                return False
            for a in range(_M):
                step[a] = -R[a]
            _lu_solve(J, piv, step)
            for a in range(_M):
                step[a] *= cols[a]
        alpha = 1.0
        accepted = False
        for _h in range(_MAX_HALVINGS):
            for a in range(_M):
                xk[a] = x[a] + alpha * step[a]
            _eval(lf, l1, l2, clip, xk[0], xk[1], xk[2], xk[3:3 + NQ], p, wk, 1)
            mk = _residual(wk, xk, sig_tr, qn, dv, rows, Rk)
            if sufficient_decrease(mk, merit, alpha):
                for a in range(_M):
                    x[a] = xk[a]
                    R[a] = Rk[a]
                for k in range(SIZE):
                    w[k] = wk[k]
                merit = mk
                full = False
                accepted = True
                break
            alpha *= 0.5
        if not accepted:
            return False
    return merit <= _TOL and x[_M - 1] >= 0.0




@njit(error_model="numpy", _nrt=False)
def _apex_region(lf, l1, l2, clip, sig_tr, q, p, dv, w):
    """Trial forces whose return ends at the apex σ = 0 of a cone (see
    :meth:`frictionrules.contact.integrate.Surface.apex_region`)."""
    OFF_DG = 4 + q.shape[0]
    _eval(lf, l1, l2, clip, 0.0, 0.0, 0.0, q, p, w, 0)
    if w[0] != 0.0:
        return False
    _eval(lf, l1, l2, clip, sig_tr[0], sig_tr[1], 0.0, q, p, w, 1)
    gt = math.sqrt(w[OFF_DG] ** 2 + w[OFF_DG + 1] ** 2)
    tt = math.sqrt(sig_tr[0] ** 2 + sig_tr[1] ** 2)
    return w[OFF_DG + 2] > 0.0 and sig_tr[2] * dv[0] * gt <= tt * dv[2] * w[OFF_DG + 2]


@njit(error_model="numpy", _nrt=False)
def _tangent_cone(w, lam, dv, out):
    """Consistent tangent of a law without internal variables, in closed form: with
    ``A = I + Δλ D ∇²g``, ``u = A⁻¹ D∇g``, ``v = ∇f A⁻¹``,
    ``dσ/dσ_trial = A⁻¹ - u v / (v·D∇g)`` (the σ-block of the inverse Jacobian), times
    ``E = diag(kt, kt, -kn)``, into ``out`` (3, 3). False where A or the Schur complement is
    singular (the caller factorizes the whole Jacobian)."""
    h = 7  # offset of ∇²g for nq = 0
    a00 = 1.0 + lam * dv[0] * w[h]
    a01 = lam * dv[0] * w[h + 1]
    a02 = lam * dv[0] * w[h + 2]
    a10 = lam * dv[1] * w[h + 3]
    a11 = 1.0 + lam * dv[1] * w[h + 4]
    a12 = lam * dv[1] * w[h + 5]
    a20 = lam * dv[2] * w[h + 6]
    a21 = lam * dv[2] * w[h + 7]
    a22 = 1.0 + lam * dv[2] * w[h + 8]
    c00 = a11 * a22 - a12 * a21
    c01 = a02 * a21 - a01 * a22
    c02 = a01 * a12 - a02 * a11
    det = a00 * c00 + a10 * c01 + a20 * c02
    if det == 0.0 or not math.isfinite(det):
        return False
    r = 1.0 / det
    b00, b01, b02 = c00 * r, c01 * r, c02 * r
    b10, b11, b12 = (a12 * a20 - a10 * a22) * r, (a00 * a22 - a02 * a20) * r, (a02 * a10 - a00 * a12) * r
    b20, b21, b22 = (a10 * a21 - a11 * a20) * r, (a01 * a20 - a00 * a21) * r, (a00 * a11 - a01 * a10) * r
    g0, g1, g2 = dv[0] * w[4], dv[1] * w[5], dv[2] * w[6]
    f0, f1, f2 = w[1], w[2], w[3]
    u0 = b00 * g0 + b01 * g1 + b02 * g2
    u1 = b10 * g0 + b11 * g1 + b12 * g2
    u2 = b20 * g0 + b21 * g1 + b22 * g2
    v0 = f0 * b00 + f1 * b10 + f2 * b20
    v1 = f0 * b01 + f1 * b11 + f2 * b21
    v2 = f0 * b02 + f1 * b12 + f2 * b22
    s = f0 * u0 + f1 * u1 + f2 * u2
    if s == 0.0 or not math.isfinite(s):
        return False
    k = 1.0 / s
    e0, e2 = dv[0], -dv[2]
    out[0, 0] = (b00 - u0 * v0 * k) * e0
    out[0, 1] = (b01 - u0 * v1 * k) * e0
    out[0, 2] = (b02 - u0 * v2 * k) * e2
    out[1, 0] = (b10 - u1 * v0 * k) * e0
    out[1, 1] = (b11 - u1 * v1 * k) * e0
    out[1, 2] = (b12 - u1 * v2 * k) * e2
    out[2, 0] = (b20 - u2 * v0 * k) * e0
    out[2, 1] = (b21 - u2 * v1 * k) * e0
    out[2, 2] = (b22 - u2 * v2 * k) * e2
    return True
