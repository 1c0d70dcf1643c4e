r"""Numba kernels of the law path (:mod:`._law_path`): every contact's own return map.

A contact's law enters as its compiled contact update
(:func:`frictionrules.contact.contact_update`: the law's step and general return generated
from its symbolic form, called by address), so this module is compiled once for every law.
With the contact's state at zero and the displacement increment chosen so that the elastic
trial force is ``x``, that update is the law's projection along its potential,

.. math::

    P_K(x) = x - \Delta\lambda\,K\,\nabla G(P_K(x)), \qquad F(P_K(x)) = 0,

(or ``x`` when :math:`F(x) \le 0`, or 0 when :math:`x_N \le 0` or the return ends at the
apex), with the stiffness ``K = diag(kn, kt, kt)`` of the law's row as metric; in FCLIB's
ordering ``(N, T1, T2)`` with :math:`F(r) = f(-r_T, r_N)`, :math:`G(r) = g(-r_T, r_N)`.
The rows given to these kernels carry each contact's ``kt, kn``.
"""

from __future__ import annotations

import numpy as np

from .._optional import require
from .._returnspec import TOL as RETURN_TOL
from ..contact import contact_update, limit_value
from ..contact.layout import LAW_KN, LAW_KT, RES_FORCE, RES_SIZE
from ._cones_kernels import MAX_HALVINGS, block_of, cones_local, cones_of, cones_project
from ._kernels import check_interval, csr_matvec, local_rhs

njit = require("numba", extra="kernels").njit

_EPS = np.finfo(float).eps
#: Divisions by 4 of a dilatant contact's trial weight ω (down to 4^-6).
MAX_SHRINK = 6


@njit(cache=True)
def project_law(fn, row, ell, x0, x1, x2, s, du, s1, res, ws, tan, want=False):
    r""":math:`P_K(x)` of one contact, ``x = (x_N, x_T1, x_T2)``: returns ``(r_N, r_T1, r_T2,
    kind, failed)`` (``kind`` 0 inside: ``P_K(x) = x``, 1 returned, 2 zero). With ``want``
    the consistent tangent of the return, ``d(T1, T2, N)/d(du)``, is written to ``tan``
    (:func:`tangent_of` turns it into :math:`\partial P_K/\partial x`). A law of two coaxial
    elliptic cones (``ell[0]`` 1: :func:`frictionrules.codegen.elliptic_cones`) is projected
    by :func:`._cones_kernels.cones_project` where no tangent is wanted; every other law, and
    the tangent of every law, by the contact layer's update (the polish's Newton steps with
    the cones' own derivative took 35 times the sweeps on spheres-in-a-box under the
    transformed rule (1.18): 25,516 against 717)."""
    kt, kn = row[LAW_KT], row[LAW_KN]
    if ell[0] != 0.0 and not want:
        p0, p1, p2, kind, ok, _DP = cones_project((ell[1], ell[2], ell[3], ell[4], ell[5],
                                                   ell[6], ell[7]), x0, x1, x2)
        if ok:
            return p0, p1, p2, kind, False
    if x0 > 0.0 and limit_value(fn, row, ws.qn, -x1, -x2, x0, ws) <= 0.0:
        # inside the limit surface: P_K(x) = x, the elastic tangent; the limit check alone
        # (the update's own, its kink rule included) costs a few percent of the whole update
        if want:
            for i in range(3):
                for k in range(3):
                    tan[i, k] = 0.0
            tan[0, 0] = kt
            tan[1, 1] = kt
            tan[2, 2] = -kn
        return x0, x1, x2, 0, False
    du[0] = -x1 / kt
    du[1] = -x2 / kt
    du[2] = -x0 / kn
    kind, failed = contact_update(fn, row, s, du, s1, res, ws, 0, want, tan)
    return res[RES_FORCE + 2], -res[RES_FORCE], -res[RES_FORCE + 1], kind, failed


@njit(cache=True)
def tangent_of(row, tan, out):
    r""":math:`\partial P_K/\partial x` in FCLIB's ordering from the return's tangent ``tan``
    (``r = (N, -T1, -T2)``, ``du = (-x_T1/kt, -x_T2/kt, -x_N/kn)``)."""
    kt, kn = row[LAW_KT], row[LAW_KN]
    force = (2, 0, 1)
    sign = (1.0, -1.0, -1.0)
    disp = (2, 0, 1)
    factor = (-1.0 / kn, -1.0 / kt, -1.0 / kt)
    for i in range(3):
        for k in range(3):
            out[i, k] = sign[i] * tan[force[i], disp[k]] * factor[k]


@njit(cache=True)
def scratch(nq):
    """Zero state row and scratch arrays of :func:`project_law`."""
    return (np.zeros(6 + nq), np.empty(3), np.empty(6 + nq), np.empty(RES_SIZE),
            np.empty((3, 3)))


@njit(cache=True)
def metric_rows(rows, D):
    """The laws' rows (nc, L) with each contact's ``kt, kn`` from its diagonal block ``D`` (nc,
    3, 3) of W: ``kn = 1/W_NN``, ``kt = 2/(W_T1T1 + W_T2T2)`` (1 where not positive)."""
    out = rows.copy()
    for a in range(rows.shape[0]):
        wn = D[a, 0, 0]
        wt = 0.5 * (D[a, 1, 1] + D[a, 2, 2])
        out[a, LAW_KN] = 1.0 / wn if wn > 0.0 else 1.0
        out[a, LAW_KT] = 1.0 / wt if wt > 0.0 else 1.0
    return out


@njit(cache=True)
def trial_weight(rn, un):
    r"""The weight :math:`\rho` of the natural map's trial :math:`r - \rho u`: 1, or
    :math:`r_N/(2u_N)` where :math:`0 < r_N < 2u_N`, so that the trial of a compressed contact
    that opens (a dilatant law sliding) stays compressed, where the return is the law's
    projection (a tensile trial opens the contact). Any :math:`\rho > 0` has the same fixed
    points among the solutions; with this one every solution is one."""
    if rn > 0.0 and un > 0.5 * rn:
        return 0.5 * rn / un
    return 1.0


@njit(cache=True)
def natural_residual(fn, rows, ell, r, u, ws, out):
    r"""Per contact :math:`r_a - P_{I}(r_a - \rho_a u_a)` into ``out``
    (:func:`trial_weight`; the rows' stiffnesses must be 1: the identity metric); returns the
    number of failed projections."""
    s, du, s1, res, tan = scratch(0)
    bad = 0
    for a in range(rows.shape[0]):
        i = 3 * a
        rho = trial_weight(r[i], u[i])
        if ell[a, 0] != 0.0:        # scalars only: no arrays passed per contact
            p0, p1, p2, _kind, ok, _DP = cones_project(cones_of(ell, a), r[i] - rho * u[i],
                                                       r[i + 1] - rho * u[i + 1], r[i + 2] - rho * u[i + 2])
            failed = not ok
        else:
            p0, p1, p2, _kind, failed = project_law(fn[a], rows[a], ell[a], r[i] - rho * u[i],
                                                    r[i + 1] - rho * u[i + 1], r[i + 2] - rho * u[i + 2],
                                                    s, du, s1, res, ws, tan)
        out[i], out[i + 1], out[i + 2] = r[i] - p0, r[i + 1] - p1, r[i + 2] - p2
        bad += failed
    return bad


@njit(cache=True)
def law_error(indptr, indices, data, q, fn, rows, ell, r, norm_q, ws):
    r"""The normalized natural map :math:`|r - P_I(r - \rho u)|/\max(|q|, |r|, |u|)` and
    ``u``."""
    u = csr_matvec(indptr, indices, data, r, q)
    res = np.empty(r.size)
    natural_residual(fn, rows, ell, r, u, ws, res)
    err = np.sqrt(np.sum(res * res))
    scale = max(norm_q, np.sqrt(np.sum(r * r)), np.sqrt(np.sum(u * u)))
    if scale > _EPS:
        err /= scale
    return err, u


@njit(cache=True)
def _local(A, b, fn, row, ell, dilatant, r0, r1, r2, local_iter, local_tol, s, du, s1, res, ws, tan):
    r"""One contact's problem :math:`A r + b \in N_g(r)` with the others frozen: separation
    (``b_N >= 0``), stick (:math:`r = -A^{-1}b` inside the limit surface), otherwise
    :func:`_newton` on the fixed point :math:`r = P_K(r - \omega K(Ar + b))` from the
    contact's last reactions. For a law with normal slip a solution whose trial is tensile
    (:math:`\omega k_n u_N \ge r_N`) is no fixed point: ω is divided by 4 (at most
    ``MAX_SHRINK`` times) until Newton's iteration converges."""
    if b[0] >= 0.0:
        return 0.0, 0.0, 0.0
    # stick: solve A r = -b (3 x 3, Cramer), accepted where the projection keeps it
    det = (A[0, 0] * (A[1, 1] * A[2, 2] - A[1, 2] * A[2, 1])
           - A[0, 1] * (A[1, 0] * A[2, 2] - A[1, 2] * A[2, 0])
           + A[0, 2] * (A[1, 0] * A[2, 1] - A[1, 1] * A[2, 0]))
    if det != 0.0:
        c0 = -b[0]
        c1 = -b[1]
        c2 = -b[2]
        s0 = (c0 * (A[1, 1] * A[2, 2] - A[1, 2] * A[2, 1])
              - A[0, 1] * (c1 * A[2, 2] - A[1, 2] * c2)
              + A[0, 2] * (c1 * A[2, 1] - A[1, 1] * c2)) / det
        s1_ = (A[0, 0] * (c1 * A[2, 2] - A[1, 2] * c2)
               - c0 * (A[1, 0] * A[2, 2] - A[1, 2] * A[2, 0])
               + A[0, 2] * (A[1, 0] * c2 - c1 * A[2, 0])) / det
        s2 = (A[0, 0] * (A[1, 1] * c2 - c1 * A[2, 1])
              - A[0, 1] * (A[1, 0] * c2 - c1 * A[2, 0])
              + c0 * (A[1, 0] * A[2, 1] - A[1, 1] * A[2, 0])) / det
        if s0 > 0.0:
            _p0, _p1, _p2, kind, failed = project_law(fn, row, ell, s0, s1_, s2, s, du, s1, res, ws,
                                                      tan)
            if not failed and kind == 0:
                return s0, s1_, s2
    om = 1.0
    t0, t1, t2 = r0, r1, r2
    for _ in range(MAX_SHRINK + 1 if dilatant else 1):
        t0, t1, t2, ok = _newton(A, b, fn, row, ell, om, r0, r1, r2, local_iter, local_tol, s, du,
                                 s1, res, ws, tan)
        if ok:
            break
        om *= 0.25
    return t0, t1, t2


@njit(cache=True)
def contact_local(D, a, b, fn, rows_k, ell, dilatant, r, local_iter, local_tol, s, du, s1, res,
                  ws, tan):
    """Contact ``a``'s local problem in a sweep (``b`` its right-hand side, ``r`` the current
    reactions): :func:`._cones_kernels.cones_local` on scalars for a law of two coaxial elliptic
    cones, :func:`_local` for every other law."""
    i = 3 * a
    if ell[a, 0] != 0.0:
        return cones_local(block_of(D, a), b[0], b[1], b[2], cones_of(ell, a), rows_k[a, LAW_KN],
                           rows_k[a, LAW_KT], r[i], r[i + 1], r[i + 2], local_iter, local_tol)
    return _local(D[a], b, fn[a], rows_k[a], ell[a], dilatant[a], r[i], r[i + 1], r[i + 2],
                  local_iter, local_tol, s, du, s1, res, ws, tan)


@njit(cache=True)
def _residual(A, b, fn, row, ell, om, r0, r1, r2, s, du, s1, res, ws, tan, want):
    r""":math:`R(r) = r - P_K(r - \omega K(Ar + b))` and, with ``want``, the return's tangent
    in ``tan``."""
    kt, kn = om * row[LAW_KT], om * row[LAW_KN]
    u0 = A[0, 0] * r0 + A[0, 1] * r1 + A[0, 2] * r2 + b[0]
    u1 = A[1, 0] * r0 + A[1, 1] * r1 + A[1, 2] * r2 + b[1]
    u2 = A[2, 0] * r0 + A[2, 1] * r1 + A[2, 2] * r2 + b[2]
    p0, p1, p2, _kind, failed = project_law(fn, row, ell, r0 - kn * u0, r1 - kt * u1, r2 - kt * u2,
                                            s, du, s1, res, ws, tan, want)
    return r0 - p0, r1 - p1, r2 - p2, failed


@njit(cache=True)
def _newton(A, b, fn, row, ell, om, r0, r1, r2, local_iter, local_tol, s, du, s1, res, ws, tan):
    r"""Semismooth Newton on :math:`R(r) = r - P_K(r - K(Ar + b))`, the generalized Jacobian
    :math:`I - \partial P_K (I - KA)` from the return's consistent tangent, a step halved
    while it does not lower :math:`|R|`; where no step lowers it, the fixed point
    :math:`r \leftarrow r - R(r)` is taken instead, and where that does not lower it either
    while :math:`|R| \le` the return's tolerance times :math:`|r|` (the return's round-off)
    the iteration stops, converged. Returns ``(r, converged)``."""
    kt, kn = om * row[LAW_KT], om * row[LAW_KN]
    DP = np.empty((3, 3))
    J = np.empty((3, 3))
    kd = np.array((kn, kt, kt))
    R0, R1, R2, failed = _residual(A, b, fn, row, ell, om, r0, r1, r2, s, du, s1, res, ws, tan, True)
    nR = np.sqrt(R0 * R0 + R1 * R1 + R2 * R2)
    for _ in range(local_iter):
        nr = np.sqrt(r0 * r0 + r1 * r1 + r2 * r2)
        if nR <= local_tol * nr or nR == 0.0:
            return r0, r1, r2, True
        tangent_of(row, tan, DP)
        for i in range(3):          # J = I - DP (I - K A)
            for k in range(3):
                acc = 0.0
                for m in range(3):
                    acc += DP[i, m] * ((1.0 if m == k else 0.0) - kd[m] * A[m, k])
                J[i, k] = (1.0 if i == k else 0.0) - acc
        det = (J[0, 0] * (J[1, 1] * J[2, 2] - J[1, 2] * J[2, 1])
               - J[0, 1] * (J[1, 0] * J[2, 2] - J[1, 2] * J[2, 0])
               + J[0, 2] * (J[1, 0] * J[2, 1] - J[1, 1] * J[2, 0]))
        ok = det != 0.0 and np.isfinite(det) and not failed
        if ok:
            c0, c1, c2 = -R0, -R1, -R2
            d0 = (c0 * (J[1, 1] * J[2, 2] - J[1, 2] * J[2, 1])
                  - J[0, 1] * (c1 * J[2, 2] - J[1, 2] * c2)
                  + J[0, 2] * (c1 * J[2, 1] - J[1, 1] * c2)) / det
            d1 = (J[0, 0] * (c1 * J[2, 2] - J[1, 2] * c2)
                  - c0 * (J[1, 0] * J[2, 2] - J[1, 2] * J[2, 0])
                  + J[0, 2] * (J[1, 0] * c2 - c1 * J[2, 0])) / det
            d2 = (J[0, 0] * (J[1, 1] * c2 - c1 * J[2, 1])
                  - J[0, 1] * (J[1, 0] * c2 - c1 * J[2, 0])
                  + c0 * (J[1, 0] * J[2, 1] - J[1, 1] * J[2, 0])) / det
            ok = np.isfinite(d0) and np.isfinite(d1) and np.isfinite(d2)
        step = 1.0
        accepted = False
        if ok:
            for _h in range(MAX_HALVINGS):
                t0, t1, t2 = r0 + step * d0, r1 + step * d1, r2 + step * d2
                S0, S1, S2, bad = _residual(A, b, fn, row, ell, om, t0, t1, t2, s, du, s1, res, ws, tan,
                                            True)
                nS = np.sqrt(S0 * S0 + S1 * S1 + S2 * S2)
                if not bad and nS < nR:
                    accepted = True
                    break
                step *= 0.5
        if not accepted:            # the fixed point: r <- P_K(r - K u)
            t0, t1, t2 = r0 - R0, r1 - R1, r2 - R2
            S0, S1, S2, bad = _residual(A, b, fn, row, ell, om, t0, t1, t2, s, du, s1, res, ws, tan, True)
            nS = np.sqrt(S0 * S0 + S1 * S1 + S2 * S2)
            if not bad and nS >= nR and nR <= RETURN_TOL * nr:
                # nothing lowers a map already within the return's own tolerance: it is the
                # return's round-off (not a stop far from the solution)
                return r0, r1, r2, True
        r0, r1, r2 = t0, t1, t2
        R0, R1, R2, nR, failed = S0, S1, S2, nS, bad
    return r0, r1, r2, nR <= local_tol * np.sqrt(r0 * r0 + r1 * r1 + r2 * r2) or nR == 0.0


@njit(cache=True)
def law_nsgs(indptr, indices, data, D, q, fn, rows_k, rows_1, ell, dilatant, r, tol, max_iter,
             hist_err, hist_it, norm_q, max_interval, local_iter, local_tol, ws):
    """Non-smooth Gauss–Seidel sweeps with :func:`_local` per contact; the error
    (:func:`law_error`) after the sweeps where the relative change of ``r`` is below ``tol``,
    at intervals predicted from the linear rate (at most ``max_interval`` sweeps apart) and
    after the last. Updates ``r`` in place; returns ``(sweeps, error, evaluations)``."""
    nc = D.shape[0]
    b = np.empty(3)
    s, du, s1, res, tan = scratch(0)
    err = np.inf
    it = 0
    nh = 0
    next_check = 1
    for it in range(1, max_iter + 1):
        dr2 = 0.0
        rr = 0.0
        for a in range(nc):
            i = 3 * a
            local_rhs(indptr, indices, data, q, D, r, a, b)
            r0, r1, r2 = contact_local(D, a, b, fn, rows_k, ell, dilatant, r, local_iter,
                                       local_tol, s, du, s1, res, ws, tan)
            dr2 += (r0 - r[i]) ** 2 + (r1 - r[i + 1]) ** 2 + (r2 - r[i + 2]) ** 2
            rr += r0 * r0 + r1 * r1 + r2 * r2
            r[i], r[i + 1], r[i + 2] = r0, r1, r2
        light = np.sqrt(dr2 / rr) if rr > 0.0 else np.sqrt(dr2)
        if it < next_check and light > tol and it < max_iter:
            continue
        err, _u = law_error(indptr, indices, data, q, fn, rows_1, ell, r, norm_q, ws)
        hist_err[nh] = err
        hist_it[nh] = it
        nh += 1
        if err <= tol or not np.isfinite(err):
            break
        next_check = it + check_interval(hist_err, hist_it, nh, err, tol, max_interval)
    return it, err, nh


@njit(cache=True)
def law_linearization(fn, rows_k, ell, r, u, ws, R, DP, om):
    r"""The law path's global natural map with the rows' metric and its generalized Jacobian
    pieces: per contact :math:`R_a = r_a - P_K(r_a - \omega_a K u_a)` into ``R``,
    :math:`\partial P_K` at the trial into ``DP[a]`` and :math:`\omega_a` into ``om`` (1, or
    what keeps a compressed contact's trial compressed, as :func:`trial_weight`). Returns the
    number of failed returns."""
    s, du, s1, res, tan = scratch(0)
    bad = 0
    for a in range(rows_k.shape[0]):
        i = 3 * a
        kt, kn = rows_k[a, LAW_KT], rows_k[a, LAW_KN]
        w = trial_weight(r[i], kn * u[i])
        om[a] = w
        p0, p1, p2, _kind, failed = project_law(fn[a], rows_k[a], ell[a], r[i] - w * kn * u[i],
                                                r[i + 1] - w * kt * u[i + 1],
                                                r[i + 2] - w * kt * u[i + 2], s, du, s1, res, ws,
                                                tan, True)
        R[i], R[i + 1], R[i + 2] = r[i] - p0, r[i + 1] - p1, r[i + 2] - p2
        tangent_of(rows_k[a], tan, DP[a])
        bad += failed
    return bad
