"""The compiled return mapping shared by every law: one Numba kernel, the law's functions as
arguments.

A law enters as three compiled C-callable functions printed from its symbolic form by
:mod:`frictionrules.contact._generated` (``lf``: f only; ``l1``: f, ∇f, ∂f/∂q, ∇g, h; ``l2``:
every quantity of :func:`frictionrules.codegen.local_layout`), each
``(T1, T2, N, *q, *p, *w) -> int`` writing into the flat layout ``w``
(:data:`LOCAL_SIGNATURE`), passed by address, so this kernel is compiled once, for every law,
and cached by Numba; a new law compiles only its three small functions.

The algorithm is the one of :func:`frictionrules.contact.integrate.return_map` and
:func:`frictionrules.contact._step.generic_step`, contact by contact: elastic trial (4.2),
separation, the limit check, backward Euler solved by Newton's method on the dimensionless
residual with a backtracking line search, returns that end at the apex of a cone, the
consistent tangent (the σ-block of the inverse Jacobian times E), and substeps where Newton's
iteration fails.

:func:`contact_update` is the one compiled entry for one contact of any law, called from the
batch kernel :func:`update` here (:meth:`ContactModel.update`) and from the time loop of the
grain assemblies' dynamic engine; it reads and writes the named rows of
:mod:`frictionrules.contact.layout` (a law's row, a contact's state row, its result row) with
a per-thread :class:`Workspace`.
"""

import math
from typing import NamedTuple

import numpy as np
from llvmlite import ir
from numba import njit, types
from numba.extending import intrinsic

from .layout import (LAW_CLIP, LAW_HAS_KAPPA, LAW_KAPPA, LAW_KN, LAW_KT, LAW_NQ, LAW_PARAMS,
                      RES_DISSIPATION, RES_DLAM, RES_FORCE, RES_SLIP, STATE_E, STATE_P, STATE_Q)
from .integrate import MAX_HALVINGS as _MAX_HALVINGS
from .integrate import MAX_ITER as _MAX_ITER
from .integrate import TOL as _TOL
from .state import ELASTIC as _ELASTIC
from .state import OPEN as _OPEN
from .state import PLASTIC as _PLASTIC

_PTR = types.CPointer(types.float64)
#: C signature of a law's local function ``(T1, T2, N, *q, *p, *w) -> 0`` (a Numba ``cfunc``).
LOCAL_SIGNATURE = types.int64(types.float64, types.float64, types.float64, _PTR, _PTR, _PTR)


@intrinsic
def _call_local(typingctx, address, x0, x1, x2, q, p, w):
    """Call the local function at ``address`` (:data:`LOCAL_SIGNATURE`) with the data of the
    arrays ``q, p, w``: a plain C call, as cheap as a call between compiled functions."""
    sig = types.int64(address, x0, x1, x2, q, p, w)

    def codegen(context, builder, signature, args):
        dbl = ir.DoubleType()
        fnty = ir.FunctionType(ir.IntType(64), [dbl, dbl, dbl] + [dbl.as_pointer()] * 3)
        data = [builder.bitcast(context.make_array(t)(context, builder, v).data, dbl.as_pointer())
                for t, v in zip(signature.args[4:], args[4:])]
        fn = builder.inttoptr(args[0], fnty.as_pointer())
        return builder.call(fn, list(args[1:4]) + data)

    return sig, codegen


@njit(inline="always")
def _layout(nq):
    """Offsets of df, dfq, dg, hgg, hgq, h, dhs, dhq in the flat layout, and its size: the
    layout of :func:`frictionrules.codegen.local_layout`, as compiled code needs it (a test
    checks that the two agree)."""
    return (1, 4, 4 + nq, 7 + nq, 16 + nq, 16 + 4 * nq, 16 + 5 * nq, 16 + 8 * nq,
            16 + 8 * nq + nq * nq)


@njit(inline="always", error_model="numpy", _nrt=False)
def _eval(lf, l1, l2, clip, s0, s1, s2, q, p, w, level):
    """The law's quantities at (T1, T2, N, q) into ``w``, finite at kinks: a derivative that
    is not finite (0/0 at the apex of a cone) is written as 0, the minimal-norm subgradient, by
    the generated function itself; a limit condition that is not finite there is its largest
    value on a small circle around T."""
    n = max(s2, 0.0) if clip else s2
    if level == 0:
        _call_local(lf, s0, s1, n, q, p, w)
    elif level == 1:
        _call_local(l1, s0, s1, n, q, p, w)
    else:
        _call_local(l2, s0, s1, n, q, p, w)
    if not math.isfinite(w[0]):
        r = 1e-9 * (math.sqrt(s0 * s0 + s1 * s1) + abs(n)) + 1e-300
        best = -np.inf
        for j in range(8):
            a = 0.25 * math.pi * j
            _call_local(lf, s0 + r * math.cos(a), s1 + r * math.sin(a), n, q, p, w)
            if w[0] > best:
                best = w[0]
        w[0] = best


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


@njit(inline="always", error_model="numpy", _nrt=False)
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


class Workspace(NamedTuple):
    """Scratch arrays of one thread's contact updates for laws with one number ``nq`` of
    internal variables (:func:`workspace`): the trial forces, the vectors of the Newton
    iteration, the law's quantities at the iterate and at a line-search trial, the Jacobian
    and its pivots, and two state rows and an increment for substeps. Sized exactly (views cut
    per contact from a larger one cost a third of a Coulomb update), so a loop over laws with
    different ``nq`` keeps one workspace per ``nq``."""

    sig_tr: np.ndarray
    dv: np.ndarray
    qn: np.ndarray
    V: np.ndarray
    w: np.ndarray
    wk: np.ndarray
    J: np.ndarray
    piv: np.ndarray
    cur: np.ndarray
    nxt: np.ndarray
    du: np.ndarray


@njit(cache=True)
def workspace(nq):
    """A :class:`Workspace` for laws with ``nq`` internal variables."""
    m = 4 + nq
    size = _layout(nq)[8]
    return Workspace(np.empty(3), np.empty(3), np.empty(nq), np.zeros((7, m)), np.zeros(size),
                     np.zeros(size), np.empty((m, m)), np.empty(m, dtype=np.int64),
                     np.empty(STATE_Q + nq), np.empty(STATE_Q + nq), np.empty(3))


@njit(inline="always", error_model="numpy", _nrt=False)
def _attempt(fn, law, s, du, s1, res, ws, want_tangent, tan):
    """One backward-Euler step of one contact (no substeps): trial, limit check, return,
    outputs. Returns ``(status, failed)``; a failed Newton iteration leaves the trial. ``ws``
    is sized for the law's ``nq``."""
    lf, l1, l2 = fn[0], fn[1], fn[2]
    kt, kn = law[LAW_KT], law[LAW_KN]
    clip = law[LAW_CLIP] != 0.0
    NQ = int(law[LAW_NQ])
    _M = 4 + NQ
    p = law[LAW_PARAMS:]
    dv, sig_tr, qn = ws.dv, ws.sig_tr, ws.qn
    dv[0], dv[1], dv[2] = kt, kt, kn
    V = ws.V
    w, wk = ws.w, ws.wk
    J, piv = ws.J, ws.piv
    x, step = V[0], V[6]
    et0 = s[STATE_E] + du[0]
    et1 = s[STATE_E + 1] + du[1]
    et2 = s[STATE_E + 2] + du[2]
    sig_tr[0] = kt * et0
    sig_tr[1] = kt * et1
    sig_tr[2] = -kn * et2
    for j in range(NQ):
        qn[j] = s[STATE_Q + j]
        s1[STATE_Q + j] = qn[j]
    failed = False
    kind = _OPEN
    apex = False
    dlam = 0.0
    s0 = sv1 = s2 = 0.0
    if sig_tr[2] > 0.0:
        # The residual's quantities at the trial: the limit check, and the return's start.
        _eval(lf, l1, l2, clip, sig_tr[0], sig_tr[1], sig_tr[2], qn, p, w, 1)
        if w[0] <= 0.0:
            kind = _ELASTIC
            s0, sv1, s2 = sig_tr[0], sig_tr[1], sig_tr[2]
        elif _return(lf, l1, l2, clip, sig_tr, qn, p, dv, V, w, wk, J, piv):
            s0, sv1, s2 = x[0], x[1], x[2]
            dlam = x[_M - 1]
            ntr = math.sqrt(sig_tr[0] ** 2 + sig_tr[1] ** 2 + sig_tr[2] ** 2)
            if s2 < 0.0 or math.sqrt(s0 * s0 + sv1 * sv1 + s2 * s2) <= _TOL * ntr:
                apex = True
            else:
                kind = _PLASTIC
                for j in range(NQ):
                    s1[STATE_Q + j] = x[3 + j]
        else:
            ntr = math.sqrt(sig_tr[0] ** 2 + sig_tr[1] ** 2 + sig_tr[2] ** 2)
            if sig_tr[2] <= _TOL * ntr or _apex_region(lf, l1, l2, clip, sig_tr, qn, p, dv, w):
                apex = True
            else:
                failed = True
                kind = _ELASTIC
                s0, sv1, s2 = sig_tr[0], sig_tr[1], sig_tr[2]
    if kind == _OPEN:
        s0 = sv1 = s2 = 0.0
        f0, f1, f2 = 0.0, 0.0, max(et2, 0.0)
    elif kind == _ELASTIC:
        f0, f1, f2 = et0, et1, et2
    else:
        f0, f1, f2 = s0 / kt, sv1 / kt, -s2 / kn
    d0, d1, d2 = et0 - f0, et1 - f1, et2 - f2
    s1[STATE_E], s1[STATE_E + 1], s1[STATE_E + 2] = f0, f1, f2
    s1[STATE_P] = s[STATE_P] + d0
    s1[STATE_P + 1] = s[STATE_P + 1] + d1
    s1[STATE_P + 2] = s[STATE_P + 2] + d2
    res[RES_FORCE], res[RES_FORCE + 1], res[RES_FORCE + 2] = s0, sv1, s2
    res[RES_DLAM] = dlam
    slip = 0.0
    if kind == _PLASTIC:
        res[RES_DISSIPATION] = s0 * d0 + sv1 * d1 - s2 * d2
        slip = math.sqrt(d0 * d0 + d1 * d1)
    else:
        res[RES_DISSIPATION] = 0.0
    if apex:
        a_slip = math.sqrt(et0 * et0 + et1 * et1)
        slip += a_slip
        if law[LAW_HAS_KAPPA] != 0.0:
            kc = int(law[LAW_KAPPA])
            s1[STATE_Q + kc] = qn[kc] + a_slip
    res[RES_SLIP] = slip
    if want_tangent and not failed:
        for a in range(3):
            for b in range(3):
                tan[a, b] = 0.0
        if kind == _ELASTIC:
            tan[0, 0] = kt
            tan[1, 1] = kt
            tan[2, 2] = -kn
        elif kind == _PLASTIC:
            # dσ/dσ_trial: the σ-block of the inverse (unscaled) Jacobian, times E.
            _eval(lf, l1, l2, clip, x[0], x[1], x[2], x[3:3 + NQ], p, w, 2)
            if NQ == 0 and _tangent_cone(w, dlam, dv, tan):
                return kind, failed
            _jacobian(w, dlam, dv, J)
            if _factor(J, piv):
                for c in range(3):
                    for a in range(_M):
                        step[a] = 1.0 if a == c else 0.0
                    _lu_solve(J, piv, step)
                    ec = kt if c < 2 else -kn
                    for a in range(3):
                        tan[a, c] = step[a] * ec
            else:
                failed = True
    return kind, failed


@njit(inline="always", error_model="numpy", _nrt=False)
def contact_update(fn, law, s, du, s1, res, ws, max_depth, want_tangent, tan):
    """One step of one contact with any law: the compiled entry of every consumer.

    Parameters
    ----------
    fn : int64 array (3,)
        Addresses of the law's generated local functions (f; the residual's quantities; the
        Jacobian's) — :attr:`CompiledLaw.fn`.
    law : float64 array
        The law's row (:mod:`frictionrules.contact.layout`: stiffnesses, flags, parameters).
    s : float64 array
        The contact's state row at the start of the step (``e, p, q``); not modified.
    du : float64 array (3,)
        Increment of the local displacement ``(Δδt1, Δδt2, Δδn)``, ``δn > 0`` opening.
    s1, res : float64 arrays
        Written: the state row at the end of the step and the result row (forces, Δλ,
        dissipation, slip).
    ws : Workspace
        Scratch arrays of the calling thread for the law's ``nq`` (:func:`workspace`).
    max_depth : int
        Where Newton's iteration fails the step is halved, recursively, to at most
        ``2**max_depth`` substeps (0: no substeps; the state is left at the trial and
        ``failed`` is True).
    want_tangent : bool
        Write the consistent tangent ``d(T1, T2, N)/d(δt1, δt2, δn)`` into ``tan`` (3, 3)
        (only without substeps: it is not computed for a substepped step).

    Returns
    -------
    status : int
        0 elastic, 1 plastic, 2 open (``frictionrules.contact.state``).
    failed : bool
        True where the step did not converge even after the substeps.
    """
    kind, failed = _attempt(fn, law, s, du, s1, res, ws, want_tangent, tan)
    if not failed or max_depth == 0:
        return kind, failed
    # Halve the step where the iteration fails, as the exported C and Fortran updates do: the
    # substeps of depth d are 2**-d of the step, taken in order from the start's state.
    n = STATE_Q + int(law[LAW_NQ])
    cur, nxt, dus = ws.cur, ws.nxt, ws.du
    for k in range(n):
        cur[k] = s[k]
    full = 1 << max_depth
    pos, depth = 0, 1
    kind = prev = _ELASTIC
    dlam = diss = slip = 0.0
    while pos < full:
        frac = math.ldexp(1.0, -depth)
        for a in range(3):
            dus[a] = du[a] * frac
        now, bad = _attempt(fn, law, cur, dus, nxt, res, ws, False, tan)
        if bad:
            if depth >= max_depth:
                return _ELASTIC, True
            depth += 1
            continue
        prev, kind = kind, now
        dlam += res[RES_DLAM]
        diss += res[RES_DISSIPATION]
        slip += res[RES_SLIP]
        for k in range(n):
            cur[k] = nxt[k]
        pos += full >> depth
        while depth > 0 and pos % (full >> (depth - 1)) == 0:
            depth -= 1
    for k in range(n):
        s1[k] = cur[k]
    res[RES_DLAM], res[RES_DISSIPATION], res[RES_SLIP] = dlam, diss, slip
    if kind == _ELASTIC and prev == _PLASTIC:
        kind = _PLASTIC
    return kind, False


@njit(error_model="numpy", _nrt=False)
def _range(fn, law, S, DU, S1, RES, STATUS, FAILED, TAN, want_tangent, max_depth, lo, hi, ws):
    """Contacts ``lo <= i < hi`` with one workspace (no reference counting in the loop)."""
    for i in range(lo, hi):
        STATUS[i], FAILED[i] = contact_update(fn, law, S[i], DU[i], S1[i], RES[i], ws,
                                              max_depth, want_tangent, TAN[i if want_tangent else 0])


@njit(nogil=True, cache=True, error_model="numpy")
def update(fn, law, inputs, outputs, want_tangent, max_depth, lo, hi):
    """Contacts ``lo <= i < hi`` of one law (without the GIL: the caller runs chunks on
    threads). ``inputs = (S, DU)``: state rows (n, 6 + nq) and increments (n, 3);
    ``outputs = (S1, RES, STATUS, FAILED, TAN)``: state rows, result rows (n, 6), status
    (int8), failure flags (bool) and tangents (n, 3, 3) or (1, 3, 3)."""
    S, DU = inputs
    S1, RES, STATUS, FAILED, TAN = outputs
    ws = workspace(int(law[LAW_NQ]))
    _range(fn, law, S, DU, S1, RES, STATUS, FAILED, TAN, want_tangent, max_depth, lo, hi, ws)
