"""Template of the compiled return mapping: the Numba kernel every generated law module shares.

Not imported: :mod:`frictionrules.contact._generated` writes a module per law structure that
defines the law's local functions (``_local_f``, ``_local_first``, ``_local_full``, printed
from its symbolic form by :mod:`frictionrules.codegen`) and the layout constants, followed by
this text, and imports that module (so Numba's ``cache=True`` can keep it on disk).

The algorithm is the one of :func:`frictionrules.contact.integrate.return_map` and
:func:`frictionrules.contact._step.generic_step`, contact by contact: elastic trial (4.2),
separation, the limit check, backward Euler solved by Newton's method on the dimensionless
residual with a backtracking line search, returns that end at the apex of a cone, and the
consistent tangent (the σ-block of the inverse Jacobian times E). Contacts whose iteration
fails are flagged in a boolean array; the caller substeps them with the NumPy return mapping.

Arrays: ``inputs = (e, p, q, du)`` (n, 3), (n, 3), (n, NQ), (n, 3); ``consts = (kt, kn,
kappa column or -1, *params)``; ``outputs = (e1, p1, q1, res, status, failed, tangent)`` with
``res`` (n, 6) = (T1, T2, N, Δλ, dissipation, slip), ``status`` int8 (0 elastic, 1 plastic,
2 open), ``failed`` bool, ``tangent`` (n, 3, 3) (written when ``want_tangent``).
"""
# ruff: noqa: F821  (the layout constants and the _local_* functions come from the header)

import math

import numpy as np
from numba import get_num_threads, njit, prange

_M = 4 + NQ
_TOL = 1e-13
_MAX_ITER = 60
_MAX_HALVINGS = 12
_ELASTIC, _PLASTIC, _OPEN = 0, 1, 2


@njit(error_model="numpy")
def _eval(s0, s1, s2, q, p, w, level):
    """The law's quantities at (T1, T2, N, q) into ``w``, made finite at kinks: a derivative
    that is not finite (0/0 at the apex of a cone) is the minimal-norm subgradient 0; a limit
    condition that is not finite there is its largest value on a small circle around T."""
    n = max(s2, 0.0) if CLIP else s2
    if level == 0:
        _local_f(s0, s1, n, q, p, w)
        last = 1
    elif level == 1:
        _local_first(s0, s1, n, q, p, w)
        last = SIZE
    else:
        _local_full(s0, s1, n, q, p, w)
        last = SIZE
    for k in range(1, last):
        if not math.isfinite(w[k]):
            w[k] = 0.0
    if not math.isfinite(w[0]):
        r = 1e-9 * (math.sqrt(s0 * s0 + s1 * s1) + abs(n)) + 1e-300
        best = -np.inf
        for j in range(8):
            a = 0.25 * math.pi * j
            _local_f(s0 + r * math.cos(a), s1 + r * math.sin(a), n, q, p, w)
            if w[0] > best:
                best = w[0]
        w[0] = best


@njit(error_model="numpy")
def _residual(w, x, sig_tr, qn, dv, rows, out):
    """Scaled backward-Euler residual at ``x = (σ, q, Δλ)`` into ``out``; returns its norm."""
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


@njit(error_model="numpy")
def _jacobian(w, lam, dv, J):
    """Newton Jacobian of the residual in ``(σ, q, Δλ)`` (unscaled), into ``J``."""
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


@njit(error_model="numpy")
def _factor(J, piv):
    """LU factorization with partial pivoting in place; False when singular."""
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


@njit(error_model="numpy")
def _lu_solve(J, piv, b):
    """Solve with the factors of :func:`_factor`, ``b`` overwritten by the solution."""
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


@njit(error_model="numpy")
def _return(sig_tr, qn, p, dv, V, w, wk, J, piv):
    """Newton return of ``sig_tr`` onto f = 0 from ``x = (σ_tr, q_n, 0)``; True if converged.

    ``V`` holds the vectors of the iteration (rows: iterate, trial iterate, row and column
    scales, residual, trial residual, step). Leaves the last iterate in ``V[0]`` and the law's
    quantities there in ``w``.
    """
    x, xk, rows, cols, R, Rk, step = V[0], V[1], V[2], V[3], V[4], V[5], V[6]
    F = max(math.sqrt(sig_tr[0] ** 2 + sig_tr[1] ** 2 + sig_tr[2] ** 2), 1e-300)
    _eval(sig_tr[0], sig_tr[1], sig_tr[2], qn, p, w, 2)
    full = True
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
    for _ in range(_MAX_ITER):
        if merit <= _TOL:
            break
        if not full:
            _eval(x[0], x[1], x[2], x[3:3 + NQ], p, w, 2)
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
            _eval(xk[0], xk[1], xk[2], xk[3:3 + NQ], p, wk, 1)
            mk = _residual(wk, xk, sig_tr, qn, dv, rows, Rk)
            if math.isfinite(mk) and mk <= (1.0 - 1e-4 * alpha) * merit:
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


@njit(error_model="numpy")
def _apex_region(sig_tr, q, p, dv, w):
    """Trial forces whose return ends at the apex σ = 0 of a cone (see
    :meth:`frictionrules.contact.integrate.Surface.apex_region`)."""
    _eval(0.0, 0.0, 0.0, q, p, w, 0)
    if w[0] != 0.0:
        return False
    _eval(sig_tr[0], sig_tr[1], 0.0, q, p, w, 1)
    gt = math.sqrt(w[OFF_DG] ** 2 + w[OFF_DG + 1] ** 2)
    tt = math.sqrt(sig_tr[0] ** 2 + sig_tr[1] ** 2)
    return w[OFF_DG + 2] > 0.0 and sig_tr[2] * dv[0] * gt <= tt * dv[2] * w[OFF_DG + 2]


@njit(inline="always", error_model="numpy")
def _one(i, e, pl, q, du, kt, kn, kappa_col, e1, p1, q1, res, status, failed, tangent,
         want_tangent, sig_tr, dv, p, qn, V, w, wk, J, piv):
    x, step = V[0], V[6]
    et0 = e[i, 0] + du[i, 0]
    et1 = e[i, 1] + du[i, 1]
    et2 = e[i, 2] + du[i, 2]
    sig_tr[0] = kt * et0
    sig_tr[1] = kt * et1
    sig_tr[2] = -kn * et2
    for j in range(NQ):
        qn[j] = q[i, j]
        q1[i, j] = qn[j]
    failed[i] = False
    kind = _OPEN
    apex = False
    dlam = 0.0
    s0 = s1 = s2 = 0.0
    if sig_tr[2] > 0.0:
        _eval(sig_tr[0], sig_tr[1], sig_tr[2], qn, p, w, 0)
        if w[0] <= 0.0:
            kind = _ELASTIC
            s0, s1, s2 = sig_tr[0], sig_tr[1], sig_tr[2]
        elif _return(sig_tr, qn, p, dv, V, w, wk, J, piv):
            s0, s1, s2 = x[0], x[1], x[2]
            dlam = x[_M - 1]
            ntr = math.sqrt(sig_tr[0] ** 2 + sig_tr[1] ** 2 + sig_tr[2] ** 2)
            if s2 < 0.0 or math.sqrt(s0 * s0 + s1 * s1 + s2 * s2) <= _TOL * ntr:
                apex = True
            else:
                kind = _PLASTIC
                for j in range(NQ):
                    q1[i, j] = x[3 + j]
        else:
            ntr = math.sqrt(sig_tr[0] ** 2 + sig_tr[1] ** 2 + sig_tr[2] ** 2)
            if sig_tr[2] <= _TOL * ntr or _apex_region(sig_tr, qn, p, dv, w):
                apex = True
            else:
                failed[i] = True
                kind = _ELASTIC
                s0, s1, s2 = sig_tr[0], sig_tr[1], sig_tr[2]
    if kind == _OPEN:
        s0 = s1 = s2 = 0.0
        f0, f1, f2 = 0.0, 0.0, max(et2, 0.0)
    elif kind == _ELASTIC:
        f0, f1, f2 = et0, et1, et2
    else:
        f0, f1, f2 = s0 / kt, s1 / kt, -s2 / kn
    d0, d1, d2 = et0 - f0, et1 - f1, et2 - f2
    e1[i, 0], e1[i, 1], e1[i, 2] = f0, f1, f2
    p1[i, 0], p1[i, 1], p1[i, 2] = pl[i, 0] + d0, pl[i, 1] + d1, pl[i, 2] + d2
    res[i, 0], res[i, 1], res[i, 2] = s0, s1, s2
    res[i, 3] = dlam
    slip = 0.0
    if kind == _PLASTIC:
        res[i, 4] = s0 * d0 + s1 * d1 - s2 * d2
        slip = math.sqrt(d0 * d0 + d1 * d1)
    else:
        res[i, 4] = 0.0
    if apex:
        a_slip = math.sqrt(et0 * et0 + et1 * et1)
        slip += a_slip
        if kappa_col >= 0:
            q1[i, kappa_col] = qn[kappa_col] + a_slip
    res[i, 5] = slip
    status[i] = kind
    if want_tangent:
        for a in range(3):
            for b in range(3):
                tangent[i, a, b] = 0.0
        if kind == _ELASTIC:
            tangent[i, 0, 0] = kt
            tangent[i, 1, 1] = kt
            tangent[i, 2, 2] = -kn
        elif kind == _PLASTIC:
            # dσ/dσ_trial: the σ-block of the inverse (unscaled) Jacobian, times E.
            _eval(x[0], x[1], x[2], x[3:3 + NQ], p, w, 2)
            _jacobian(w, dlam, dv, J)
            if _factor(J, piv):
                for c in range(3):
                    for a in range(_M):
                        step[a] = 1.0 if a == c else 0.0
                    _lu_solve(J, piv, step)
                    ec = kt if c < 2 else -kn
                    for a in range(3):
                        tangent[i, a, c] = step[a] * ec
            else:
                failed[i] = True


@njit(inline="always", error_model="numpy")
def _range(lo, hi, e, pl, q, du, consts, e1, p1, q1, res, status, failed, tangent, want_tangent):
    """Contacts ``lo <= i < hi``, with one workspace."""
    kt, kn = consts[0], consts[1]
    kappa_col = int(consts[2])
    dv = np.array([kt, kt, kn])
    p = consts[3:].copy()
    sig_tr, qn = np.empty(3), np.empty(NQ)
    V = np.zeros((7, _M))
    w, wk = np.zeros(SIZE), np.zeros(SIZE)
    J, piv = np.empty((_M, _M)), np.empty(_M, dtype=np.int64)
    for i in range(lo, hi):
        _one(i, e, pl, q, du, kt, kn, kappa_col, e1, p1, q1, res, status, failed, tangent,
             want_tangent, sig_tr, dv, p, qn, V, w, wk, J, piv)


@njit(parallel=True, cache=True, error_model="numpy")
def update(inputs, consts, outputs, want_tangent):
    """All contacts, in parallel chunks (one workspace per chunk)."""
    e, pl, q, du = inputs
    e1, p1, q1, res, status, failed, tangent = outputs
    n = e.shape[0]
    chunks = min(n, 16 * get_num_threads())
    for c in prange(chunks):
        _range(c * n // chunks, (c + 1) * n // chunks, e, pl, q, du, consts, e1, p1, q1, res,
               status, failed, tangent, want_tangent)


@njit(cache=True, error_model="numpy")
def update_serial(inputs, consts, outputs, want_tangent):
    """All contacts, on one thread (small batches)."""
    e, pl, q, du = inputs
    e1, p1, q1, res, status, failed, tangent = outputs
    _range(0, e.shape[0], e, pl, q, du, consts, e1, p1, q1, res, status, failed, tangent,
           want_tangent)
