r"""Numba kernels of the factored sweeps (:mod:`.factored`): non-smooth Gauss–Seidel on
:math:`u = J M^{-1} J^T r + q` without forming W.

The operator comes as dense blocks per contact and kinematic tree (at most two trees per
contact): ``tree[a, s]`` (-1: none), the block's offset ``off[a, s]`` into the pools ``Jp``
and ``Bp``, each block ``3 x n_t`` row-major over the tree's dofs ``dofadr[t] ..
dofadr[t] + dofnum[t] - 1``: ``Jp`` holds :math:`J_{a,t}`, ``Bp`` holds :math:`B_{a,t} =
J_{a,t} M_t^{-1}`. With :math:`v = M^{-1}J^T r = \sum_a B_a^T r_a` kept up to date,

.. math:: b_a = (W r + q)_a - W_{aa} r_a = J_a v + q_a - D_a r_a, \qquad
          v \leftarrow v + B_a^T (r_a^{new} - r_a),

so a sweep costs :math:`O(\sum_a n_a)` (the contacts' dofs) instead of O(nnz(W)), and W is
never built. The local solvers are the ones of the W sweeps (:func:`._kernels.local_solve`
on the cone path, :func:`._law_kernels._local` on the law path), so a sweep here is the same
sweep to rounding.
"""

from __future__ import annotations

import numpy as np

from .._optional import require
from ._kernels import _EPS, check_interval, error_sum, local_solve, norm2
from ..contact import workspace
from ._law_kernels import contact_local, metric_rows, natural_residual, scratch

njit = require("numba", extra="kernels").njit


@njit(inline="always")
def _jv(tree, off, Jp, dofadr, dofnum, v, q, a):
    """``J_a v + q_a``, contact ``a``'s velocity, as three numbers."""
    i = 3 * a
    u0, u1, u2 = q[i], q[i + 1], q[i + 2]
    for s in range(2):
        t = tree[a, s]
        if t < 0:
            continue
        p, c0, n = off[a, s], dofadr[t], dofnum[t]
        for k in range(n):
            x = v[c0 + k]
            u0 += Jp[p + k] * x
            u1 += Jp[p + n + k] * x
            u2 += Jp[p + 2 * n + k] * x
    return u0, u1, u2


@njit(inline="always")
def _rhs(tree, off, Jp, dofadr, dofnum, v, q, D, r, a, b):
    """``b = J_a v + q_a - D_a r_a`` into ``b`` (3,)."""
    i = 3 * a
    b0, b1, b2 = _jv(tree, off, Jp, dofadr, dofnum, v, q, a)
    b[0] = b0 - (D[a, 0, 0] * r[i] + D[a, 0, 1] * r[i + 1] + D[a, 0, 2] * r[i + 2])
    b[1] = b1 - (D[a, 1, 0] * r[i] + D[a, 1, 1] * r[i + 1] + D[a, 1, 2] * r[i + 2])
    b[2] = b2 - (D[a, 2, 0] * r[i] + D[a, 2, 1] * r[i + 1] + D[a, 2, 2] * r[i + 2])


@njit(inline="always")
def _scatter(tree, off, Bp, dofadr, dofnum, v, a, d0, d1, d2):
    """``v += B_a^T d``."""
    for s in range(2):
        t = tree[a, s]
        if t < 0:
            continue
        p, c0, n = off[a, s], dofadr[t], dofnum[t]
        for k in range(n):
            v[c0 + k] += Bp[p + k] * d0 + Bp[p + n + k] * d1 + Bp[p + 2 * n + k] * d2


@njit(cache=True)
def impulse_velocity(tree, off, Bp, dofadr, dofnum, r, v):
    r""":math:`v = M^{-1}J^T r = \sum_a B_a^T r_a` into ``v`` (zeroed first)."""
    v[:] = 0.0
    for a in range(tree.shape[0]):
        i = 3 * a
        _scatter(tree, off, Bp, dofadr, dofnum, v, a, r[i], r[i + 1], r[i + 2])


@njit(cache=True)
def contact_velocity(tree, off, Jp, dofadr, dofnum, v, q, u):
    """``u = J v + q`` into ``u`` (3 nc,)."""
    for a in range(tree.shape[0]):
        i = 3 * a
        u[i], u[i + 1], u[i + 2] = _jv(tree, off, Jp, dofadr, dofnum, v, q, a)


@njit(cache=True)
def _cone_error(tree, off, Jp, dofadr, dofnum, v, q, u, r, mu, dil, norm_q):
    """Siconos' error of ``r`` with ``u = J v + q`` (written to ``u``)."""
    contact_velocity(tree, off, Jp, dofadr, dofnum, v, q, u)
    scale = max(norm_q, norm2(r), norm2(u))
    err = np.sqrt(error_sum(r, u, mu, dil))
    return err / scale if scale > _EPS else err


@njit(cache=True)
def _law_error(tree, off, Jp, dofadr, dofnum, v, q, u, r, fn, rows_1, ell, ws, resid, norm_q):
    """The law path's error of ``r`` with ``u = J v + q`` (written to ``u``)."""
    contact_velocity(tree, off, Jp, dofadr, dofnum, v, q, u)
    natural_residual(fn, rows_1, ell, r, u, ws, resid)
    err = norm2(resid)
    scale = max(norm_q, norm2(r), norm2(u))
    return err / scale if scale > _EPS else err


@njit(cache=True)
def factored_nsgs(tree, off, Jp, Bp, dofadr, dofnum, D, q, mu, dil, r, v, u, tol, max_iter,
                  hist_err, hist_it, norm_q, max_interval):
    """The cone path's sweeps (:func:`._kernels.nsgs`, the same checks of the error: Siconos'
    measure after the sweeps where the relative change of ``r`` is below ``tol``, at the
    intervals of :func:`._kernels.check_interval` and after the last). ``r`` updated in place,
    ``v`` must be :func:`impulse_velocity` of ``r`` on entry and is on return (kept by the
    updates, computed anew where a check finds the error at most ``tol`` and after the last
    sweep, and the error evaluated again), ``u`` holds ``J v + q`` at the last check. Returns ``(sweeps, error,
    evaluations)``."""
    nc = mu.size
    b = np.empty(3)
    err = np.inf
    it = 0
    nh = 0
    next_check = 1
    for it in range(1, max_iter + 1):
        dr2 = 0.0
        rr = 0.0
        for a in range(nc):
            i = 3 * a
            _rhs(tree, off, Jp, dofadr, dofnum, v, q, D, r, a, b)
            r0, r1, r2 = local_solve(D[a], b, mu[a], dil[a], r[i], r[i + 1], r[i + 2])
            d0, d1, d2 = r0 - r[i], r1 - r[i + 1], r2 - r[i + 2]
            dr2 += d0 * d0 + d1 * d1 + d2 * d2
            rr += r0 * r0 + r1 * r1 + r2 * r2
            r[i], r[i + 1], r[i + 2] = r0, r1, r2
            _scatter(tree, off, Bp, dofadr, dofnum, v, a, d0, d1, d2)
        light = np.sqrt(dr2 / rr) if rr > 0.0 else np.sqrt(dr2)
        if it < next_check and light > tol and it < max_iter:
            continue
        err = _cone_error(tree, off, Jp, dofadr, dofnum, v, q, u, r, mu, dil, norm_q)
        if err <= tol or it == max_iter:      # v anew (no drift from the updates), the error again
            impulse_velocity(tree, off, Bp, dofadr, dofnum, r, v)
            err = _cone_error(tree, off, Jp, dofadr, dofnum, v, q, u, r, mu, dil, norm_q)
        hist_err[nh] = err
        hist_it[nh] = it
        nh += 1
        if err <= tol:
            break
        next_check = it + check_interval(hist_err, hist_it, nh, err, tol, max_interval)
    return it, err, nh


@njit(cache=True)
def factored_law_nsgs(tree, off, Jp, Bp, dofadr, dofnum, D, q, fn, rows_1, ell, dilatant, r, v, u,
                      tol, max_iter, hist_err, hist_it, norm_q, max_interval, local_iter, local_tol):
    """The law path's sweeps (:func:`._law_kernels.law_nsgs`: each contact's own return map,
    the law path's error measure) on the factored operator; as :func:`factored_nsgs`. The
    rows' metric (:func:`._law_kernels.metric_rows`) and the contact layer's workspace are
    formed here (no arrays boxed for Python and unboxed again each step)."""
    nc = D.shape[0]
    rows_k = metric_rows(rows_1, D)
    ws = workspace(0)
    b = np.empty(3)
    s, du, s1, res, tan = scratch(0)
    resid = np.empty(r.size)
    err = np.inf
    it = 0
    nh = 0
    next_check = 1
    for it in range(1, max_iter + 1):
        dr2 = 0.0
        rr = 0.0
        for a in range(nc):
            i = 3 * a
            _rhs(tree, off, Jp, dofadr, dofnum, v, q, D, r, a, b)
            r0, r1, r2 = contact_local(D, a, b, fn, rows_k, ell, dilatant, r, local_iter,
                                       local_tol, s, du, s1, res, ws, tan)
            d0, d1, d2 = r0 - r[i], r1 - r[i + 1], r2 - r[i + 2]
            dr2 += d0 * d0 + d1 * d1 + d2 * d2
            rr += r0 * r0 + r1 * r1 + r2 * r2
            r[i], r[i + 1], r[i + 2] = r0, r1, r2
            _scatter(tree, off, Bp, dofadr, dofnum, v, a, d0, d1, d2)
        light = np.sqrt(dr2 / rr) if rr > 0.0 else np.sqrt(dr2)
        if it < next_check and light > tol and it < max_iter:
            continue
        err = _law_error(tree, off, Jp, dofadr, dofnum, v, q, u, r, fn, rows_1, ell, ws, resid, norm_q)
        if err <= tol or it == max_iter:      # v anew (no drift from the updates), the error again
            impulse_velocity(tree, off, Bp, dofadr, dofnum, r, v)
            err = _law_error(tree, off, Jp, dofadr, dofnum, v, q, u, r, fn, rows_1, ell, ws, resid, norm_q)
        hist_err[nh] = err
        hist_it[nh] = it
        nh += 1
        if err <= tol or not np.isfinite(err):
            break
        next_check = it + check_interval(hist_err, hist_it, nh, err, tol, max_interval)
    return it, err, nh


@njit(cache=True)
def mean_diagonal(D):
    """The mean of the positive ``|W_ii|`` over the diagonal blocks ``D`` (1 where none is)."""
    acc, n = 0.0, 0
    for a in range(D.shape[0]):
        for i in range(3):
            x = abs(D[a, i, i])
            if x > 0.0:
                acc += x
                n += 1
    return acc / n if n else 1.0


@njit(cache=True)
def delassus_csr(tree, off, Jp, Bp, dofadr, dofnum):
    r"""CSR arrays ``(indptr, indices, data)`` of :math:`W = \sum_t J_{\cdot,t} B_{\cdot,t}^T`
    (columns sorted, int32 indices as SciPy keeps them): row block ``a`` has the 3 x 3 blocks
    :math:`W_{ac}` of every contact ``c`` sharing a tree with ``a``."""
    nc = tree.shape[0]
    ntree = dofadr.size
    # the contacts of each tree, ascending
    count = np.zeros(ntree + 1, np.int64)
    for a in range(nc):
        for s in range(2):
            if tree[a, s] >= 0:
                count[tree[a, s] + 1] += 1
    ptr = np.cumsum(count)
    members = np.empty(ptr[-1], np.int64)
    fill = ptr[:-1].copy()
    for a in range(nc):
        for s in range(2):
            t = tree[a, s]
            if t >= 0:
                members[fill[t]] = a
                fill[t] += 1
    # the neighbours of each contact (the union of its trees' members), then the blocks
    mark = np.full(nc, -1, np.int64)
    nbr = np.empty(nc, np.int64)
    nn = np.zeros(nc, np.int64)
    for a in range(nc):
        m = 0
        for s in range(2):
            t = tree[a, s]
            if t < 0:
                continue
            for p in range(ptr[t], ptr[t + 1]):
                c = members[p]
                if mark[c] != a:
                    mark[c] = a
                    m += 1
        nn[a] = m
    indptr = np.zeros(3 * nc + 1, np.int32)
    for a in range(nc):
        for l in range(3):
            indptr[3 * a + l + 1] = indptr[3 * a + l] + 3 * nn[a]
    indices = np.empty(indptr[3 * nc], np.int32)
    data = np.zeros(indptr[3 * nc])
    mark[:] = -1
    for a in range(nc):
        m = 0
        for s in range(2):
            t = tree[a, s]
            if t < 0:
                continue
            for p in range(ptr[t], ptr[t + 1]):
                c = members[p]
                if mark[c] != a:
                    mark[c] = a
                    nbr[m] = c
                    m += 1
        cs = np.sort(nbr[:m])
        for j in range(m):
            c = cs[j]
            for l in range(3):
                base = indptr[3 * a + l] + 3 * j
                for l2 in range(3):
                    indices[base + l2] = 3 * c + l2
                    acc = 0.0
                    for s in range(2):
                        t = tree[a, s]
                        if t < 0:
                            continue
                        s2 = 0 if tree[c, 0] == t else (1 if tree[c, 1] == t else -1)
                        if s2 < 0:
                            continue
                        n = dofnum[t]
                        pa, pc = off[a, s] + l * n, off[c, s2] + l2 * n
                        for k in range(n):
                            acc += Jp[pa + k] * Bp[pc + k]
                    data[base + l2] = acc
    return indptr, indices, data
