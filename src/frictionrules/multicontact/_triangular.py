r"""Triangular factors of :math:`W + cI` for ADMM (:mod:`._admm`) as CSR arrays, and their
compiled solves.

The factors come from SciPy's SuperLU (:func:`csr_factors`), LAPACK's dense LU
(:func:`dense_factors`) or an earlier pattern refilled (:func:`lu_refactor`, or
:func:`symmetric_refactor` from the lower triangle where W is symmetric); where W is symmetric,
U may be dropped for :math:`D L^T` (:func:`symmetric_form`); and they are solved in 3 x 3 blocks
by contacts where the blocks hold them without many zeros (:func:`block_factors`).
"""

from __future__ import annotations

import numpy as np

from .._optional import require

njit = require("numba", extra="kernels").njit


@njit(cache=True)
def lu_solve(lp, li, lx, up, ui, ux, ud, rows, cols, triples, b):
    r"""The solution x of :math:`A x = b` from the factors :math:`L U = B`,
    :math:`B_{ij} = A_{r_i c_j}` (``rows``, ``cols``): L unit lower triangular (its strictly
    lower part as CSR arrays ``lp, li, lx``), U upper triangular (its strictly upper part
    ``up, ui, ux`` and its diagonal ``ud``). Row by row (a gather, no scattered writes):
    :math:`y_i = b_{r_i} - \sum_{j<i} L_{ij} y_j`, then
    :math:`x_{c_i} = (y_i - \sum_{j>i} U_{ij} x_{c_j}) / U_{ii}`.

    Where ``up`` is empty, :math:`U = D L^T` (:func:`symmetric_form`, ``ud`` the diagonal D):
    the backward solve :math:`L^T x' = D^{-1} y` reads L again, column by column
    (:math:`x'_i` final, then :math:`y_k \leftarrow y_k - L_{ik} x'_i` for L's row i), and
    the factors take half the memory. On the 3,970-sphere pile (11,910 unknowns, 796,062
    entries in each triangle) one solve took 1.16-1.19 ms against 2.04-2.68 ms with U: L
    alone (9.6 MB with its indices, against 19 MB for L and U) stays in the processor's cache.

    Where ``triples[t]`` (:func:`contact_triples`), the rows 3t, 3t + 1, 3t + 2 (a contact's) share
    their columns outside the triple and are summed together: three independent sums where
    one row's sum waited on the last (the solve is bound by the latency of that chain: 2 ns
    an entry on Spheres' factors, 7 entries a row). The forward sums keep their order (the
    same bits); the backward ones take the triple's own columns last.

    Factors in 3 x 3 blocks (:func:`block_factors`: ``lp`` then has one entry per contact and
    one more) are solved by :func:`_block_solve`: the same terms, each block's summed first
    (the same solution to round-off)."""
    n = b.size
    x = np.empty(n)
    lu_solve_into(lp, li, lx, up, ui, ux, ud, rows, cols, triples, b, np.empty(n), x)
    return x


@njit(cache=True)
def lu_solve_into(lp, li, lx, up, ui, ux, ud, rows, cols, triples, b, y, x):
    """:func:`lu_solve` into ``x``, ``y`` (of b's size) its scratch: no array allocated (an
    ADMM iteration on Box_Stacks is 5 µs)."""
    if lp.size - 1 < ud.size:
        _block_solve(lp, li, lx, up, ui, ux, ud, rows, cols, b, y, x)
        return
    n = b.size
    i = 0
    while i < n:
        if i % 3 == 0 and triples[i // 3] & 1:
            p0, p1, p2 = lp[i], lp[i + 1], lp[i + 2]
            m = p1 - p0
            a0, a1, a2 = b[rows[i]], b[rows[i + 1]], b[rows[i + 2]]
            for k in range(m):
                yc = y[li[p0 + k]]
                a0 -= lx[p0 + k] * yc
                a1 -= lx[p1 + k] * yc
                a2 -= lx[p2 + k] * yc
            y[i] = a0
            a1 -= lx[p1 + m] * a0
            y[i + 1] = a1
            a2 -= lx[p2 + m] * a0
            a2 -= lx[p2 + m + 1] * a1
            y[i + 2] = a2
            i += 3
            continue
        acc = b[rows[i]]
        for p in range(lp[i], lp[i + 1]):
            acc -= lx[p] * y[li[p]]
        y[i] = acc
        i += 1
    if up.size == 0:
        _backward_ldl(lp, li, lx, ud, cols, triples, y, x)
    else:
        _backward_lu(up, ui, ux, ud, cols, triples, y, x)


@njit(cache=True, inline="always")
def _backward_lu(up, ui, ux, ud, cols, triples, y, x):
    """:math:`U x' = y` row by row (:func:`lu_solve`), ``x = x'`` in the columns' order."""
    n = y.size
    i = n - 1
    while i >= 0:
        if i % 3 == 2 and triples[i // 3] & 2:
            p0, p1, p2 = up[i - 2], up[i - 1], up[i]
            m = up[i + 1] - p2
            a0, a1, a2 = y[i - 2], y[i - 1], y[i]
            for k in range(m):
                yc = y[ui[p2 + k]]
                a0 -= ux[p0 + 2 + k] * yc
                a1 -= ux[p1 + 1 + k] * yc
                a2 -= ux[p2 + k] * yc
            y[i] = a2 / ud[i]
            y[i - 1] = (a1 - ux[p1] * y[i]) / ud[i - 1]
            y[i - 2] = ((a0 - ux[p0] * y[i - 1]) - ux[p0 + 1] * y[i]) / ud[i - 2]
            x[cols[i]], x[cols[i - 1]], x[cols[i - 2]] = y[i], y[i - 1], y[i - 2]
            i -= 3
            continue
        acc = y[i]
        for p in range(up[i], up[i + 1]):
            acc -= ux[p] * y[ui[p]]
        y[i] = acc / ud[i]
        x[cols[i]] = y[i]
        i -= 1


@njit(cache=True, inline="always")
def _backward_ldl(lp, li, lx, ud, cols, triples, y, x):
    """:math:`L^T x' = D^{-1} y` column by column (:func:`lu_solve`), ``x = x'`` in the
    columns' order; a contact's triple of L's rows (``triples[t] & 1``) scattered together."""
    n = y.size
    for i in range(n):
        y[i] /= ud[i]
    i = n - 1
    while i >= 0:
        if i % 3 == 2 and triples[i // 3] & 1:
            p0, p1, p2 = lp[i - 2], lp[i - 1], lp[i]
            m = p1 - p0
            x2 = y[i]
            x1 = y[i - 1] - lx[p2 + m + 1] * x2
            x0 = (y[i - 2] - lx[p1 + m] * x1) - lx[p2 + m] * x2
            y[i], y[i - 1], y[i - 2] = x2, x1, x0
            for k in range(m):
                y[li[p0 + k]] -= (lx[p0 + k] * x0 + lx[p1 + k] * x1) + lx[p2 + k] * x2
            i -= 3
            continue
        xi = y[i]
        for p in range(lp[i], lp[i + 1]):
            y[li[p]] -= lx[p] * xi
        i -= 1
    for i in range(n):
        x[cols[i]] = y[i]


@njit(cache=True)
def block_pattern(pp, pi, lower):
    """The strict triangle ``pp, pi`` (CSR, each row's columns ascending) in 3 x 3 blocks, the
    rows 3t, 3t + 1, 3t + 2 (contact t's) together: per contact the blocks that hold an entry
    of its rows (columns ascending) and its diagonal block, last in L and first in U, which
    holds the triangle's entries of the contact's own 3 x 3 block. ``(ptr, block columns,
    slots)``: ``slots[p]`` the place of entry p among the values, nine per block, row-major;
    the places no entry takes are zeros."""
    n = pp.size - 1
    nc = n // 3
    mark = np.full(nc, -1, np.int64)
    ptr = np.zeros(nc + 1, np.int32)
    for t in range(nc):
        m = 1
        for p in range(pp[3 * t], pp[3 * t + 3]):
            b = pi[p] // 3
            if b != t and mark[b] != t:
                mark[b] = t
                m += 1
        ptr[t + 1] = ptr[t] + m
    cols = np.empty(ptr[nc], np.int32)
    slots = np.empty(pp[n], np.int64)
    place = np.empty(nc, np.int64)
    mark[:] = -1
    for t in range(nc):
        first = ptr[t] if lower else ptr[t] + 1
        m = 0
        for p in range(pp[3 * t], pp[3 * t + 3]):
            b = pi[p] // 3
            if b != t and mark[b] != t:
                mark[b] = t
                cols[first + m] = b
                m += 1
        cols[first:first + m].sort()
        diag = ptr[t + 1] - 1 if lower else ptr[t]
        cols[diag] = t
        for k in range(ptr[t], ptr[t + 1]):
            place[cols[k]] = k
        for r in range(3):
            for p in range(pp[3 * t + r], pp[3 * t + r + 1]):
                j = pi[p]
                b = j // 3
                slots[p] = 9 * place[b] + 3 * r + j - 3 * b
    return ptr, cols, slots


#: The factors are solved in blocks (:func:`block_factors`) where the blocks' values, zeros
#: included, are at most this many times the entries they hold (and six of each contact's
#: diagonal block): the shared files' factors take 1.0-1.1 (contacts' rows of whole blocks);
#: an ordering that does not keep a contact's rows together would take up to 9.
BLOCK_FILL_MAX = 1.5


def block_factors(arrays, patterns=None):
    r"""``(arrays, patterns)``: the arrays of :func:`lu_solve` with L (and U where kept) in 3 x 3
    blocks by contacts (:func:`block_pattern`; ``patterns``, the blocks of L's and U's
    patterns, computed where not given), or ``arrays`` themselves where the blocks would hold
    more than :data:`BLOCK_FILL_MAX` times the entries. A block's nine values are read in one
    pass and its three entries of the solution in one place, with one index for nine entries:
    one solve on an idle machine, blocks against rows (L alone): the 3,970-sphere pile 473
    against 1,189 µs, the 1,812 spheres 150 against 342, spheres-in-a-box 12.3 against 26.4,
    Box_Stacks 2.3 against 3.5; the same solution as the rows' form to round-off."""
    lp, li, lx, up, ui, ux, ud, rows, cols, triples = arrays
    n = ud.size
    if n % 3:
        return arrays, None
    if patterns is None:
        patterns = (block_pattern(lp, li, True), None)
    if up.size and patterns[1] is None:         # U kept: its blocks too
        patterns = (patterns[0], block_pattern(up, ui, False))
    bp, bc, bs = patterns[0]
    blocks = bc.size + (patterns[1][1].size if up.size else 0)
    if 9 * blocks > BLOCK_FILL_MAX * (lx.size + ux.size + 2 * n):
        return arrays, patterns
    bv = np.zeros(9 * bc.size)
    bv[bs] = lx
    if not up.size:
        return (bp, bc, bv, up, ui, ux, ud, rows, cols, triples), patterns
    cp, cc, cs = patterns[1]
    cv = np.zeros(9 * cc.size)
    cv[cs] = ux
    return (bp, bc, bv, cp, cc, cv, ud, rows, cols, triples), patterns


@njit(cache=True, inline="always")
def _minus_block(vals, q, y, s, a0, a1, a2):
    """``a - B y[s:s + 3]``, B the block of nine values from ``vals[q]`` (row-major): each
    row's three terms summed first, then taken from ``a``. The chain of a row's sum is then
    one subtraction per block, not three (the solve waits on it: local_problem_test's two
    solves 2.16 -> 1.80 µs)."""
    y0, y1, y2 = y[s], y[s + 1], y[s + 2]
    a0 -= (vals[q] * y0 + vals[q + 1] * y1) + vals[q + 2] * y2
    a1 -= (vals[q + 3] * y0 + vals[q + 4] * y1) + vals[q + 5] * y2
    a2 -= (vals[q + 6] * y0 + vals[q + 7] * y1) + vals[q + 8] * y2
    return a0, a1, a2


@njit(cache=True)
def _block_solve(bp, bc, bv, cp, cc, cv, ud, rows, cols, b, y, x):
    """:func:`lu_solve` on factors in 3 x 3 blocks (:func:`block_factors`; ``cp`` empty: U
    is :math:`D L^T`): per contact, its blocks in the order of the rows' entries, each
    block's three terms of a row summed before they are taken from the row's sum
    (:func:`_minus_block`); into ``x``, ``y`` the scratch."""
    n = b.size
    nc = n // 3
    for t in range(nc):
        i = 3 * t
        a0, a1, a2 = b[rows[i]], b[rows[i + 1]], b[rows[i + 2]]
        last = bp[t + 1] - 1
        for k in range(bp[t], last):
            a0, a1, a2 = _minus_block(bv, 9 * k, y, 3 * bc[k], a0, a1, a2)
        q = 9 * last
        y[i] = a0
        a1 -= bv[q + 3] * a0
        y[i + 1] = a1
        a2 -= bv[q + 6] * a0
        a2 -= bv[q + 7] * a1
        y[i + 2] = a2
    if cp.size == 0:                    # L^T x' = D^-1 y, column by column
        for i in range(n):
            y[i] /= ud[i]
        for t in range(nc - 1, -1, -1):
            i = 3 * t
            last = bp[t + 1] - 1
            q = 9 * last
            x2 = y[i + 2]
            x1 = y[i + 1] - bv[q + 7] * x2
            x0 = (y[i] - bv[q + 3] * x1) - bv[q + 6] * x2
            y[i], y[i + 1], y[i + 2] = x0, x1, x2
            for k in range(bp[t], last):
                s = 3 * bc[k]
                q = 9 * k
                y[s] -= (bv[q] * x0 + bv[q + 3] * x1) + bv[q + 6] * x2
                y[s + 1] -= (bv[q + 1] * x0 + bv[q + 4] * x1) + bv[q + 7] * x2
                y[s + 2] -= (bv[q + 2] * x0 + bv[q + 5] * x1) + bv[q + 8] * x2
        for i in range(n):
            x[cols[i]] = y[i]
        return
    for t in range(nc - 1, -1, -1):     # U x' = y, row by row
        i = 3 * t
        a0, a1, a2 = y[i], y[i + 1], y[i + 2]
        first = cp[t]
        for k in range(first + 1, cp[t + 1]):
            a0, a1, a2 = _minus_block(cv, 9 * k, y, 3 * cc[k], a0, a1, a2)
        q = 9 * first
        y[i + 2] = a2 / ud[i + 2]
        y[i + 1] = (a1 - cv[q + 5] * y[i + 2]) / ud[i + 1]
        y[i] = ((a0 - cv[q + 1] * y[i + 1]) - cv[q + 2] * y[i + 2]) / ud[i]
        x[cols[i]], x[cols[i + 1]], x[cols[i + 2]] = y[i], y[i + 1], y[i + 2]


@njit(cache=True)
def contact_triples(lp, li, up, ui):
    """Per triple of rows (3t, 3t + 1, 3t + 2) of the factors' CSR arrays (each row's columns
    ascending): bit 1 when L's rows are ``P``, ``P + [3t]``, ``P + [3t, 3t + 1]`` (one set P
    of columns), bit 2 when U's rows are ``[3t + 1, 3t + 2] + Q``, ``[3t + 2] + Q``, ``Q``."""
    n = lp.size - 1
    out = np.zeros(n // 3, np.uint8)
    for t in range(n // 3):
        i = 3 * t
        if _shared_rows(lp, li, i):
            out[t] |= 1
        q0, q1, q2 = up[i], up[i + 1], up[i + 2]
        m = up[i + 3] - q2
        ok = q2 - q1 == m + 1 and q1 - q0 == m + 2
        if ok:
            ok = ui[q1] == i + 2 and ui[q0] == i + 1 and ui[q0 + 1] == i + 2
            for k in range(m):
                if not ok:
                    break
                ok = ui[q1 + 1 + k] == ui[q2 + k] and ui[q0 + 2 + k] == ui[q2 + k]
        if ok:
            out[t] |= 2
    return out


@njit(cache=True)
def _strict_rows(cp, ci, cx, lower):
    """The strictly lower (``lower``) or upper part of a square CSC matrix as CSR arrays (each
    row's columns ascending), and its diagonal (zero where not stored)."""
    n = cp.size - 1
    count = np.zeros(n + 1, np.int64)
    diag = np.zeros(n)
    for j in range(n):
        for p in range(cp[j], cp[j + 1]):
            i = ci[p]
            if i == j:
                diag[j] = cx[p]
            elif (i > j) == lower:
                count[i + 1] += 1
    for i in range(n):
        count[i + 1] += count[i]
    ptr = count.astype(np.int32)
    idx = np.empty(count[n], np.int32)
    val = np.empty(count[n])
    nxt = count[:n].copy()
    for j in range(n):
        for p in range(cp[j], cp[j + 1]):
            i = ci[p]
            if i != j and (i > j) == lower:
                idx[nxt[i]], val[nxt[i]] = j, cx[p]
                nxt[i] += 1
    return ptr, idx, val, diag


@njit(cache=True)
def dense_factors(lu, piv):
    """``(lp, li, lx, up, ui, ux, ud, rows)`` of :func:`lu_solve` from LAPACK's packed LU (L
    unit lower triangular below the diagonal, U on and above it; their zero entries left out)
    and its row interchanges ``piv`` (row i swapped with row ``piv[i]``, in turn)."""
    n = lu.shape[0]
    rows = np.arange(n)
    for i in range(n):
        rows[i], rows[piv[i]] = rows[piv[i]], rows[i]
    lp, up = np.zeros(n + 1, np.int32), np.zeros(n + 1, np.int32)
    for i in range(n):
        lp[i + 1], up[i + 1] = lp[i], up[i]
        for j in range(n):
            if lu[i, j] != 0.0 and j != i:
                if j < i:
                    lp[i + 1] += 1
                else:
                    up[i + 1] += 1
    li, lx = np.empty(lp[n], np.int32), np.empty(lp[n])
    ui, ux = np.empty(up[n], np.int32), np.empty(up[n])
    ud = np.empty(n)
    for i in range(n):
        a, b = lp[i], up[i]
        for j in range(n):
            e = lu[i, j]
            if j == i:
                ud[i] = e
            elif e != 0.0:
                if j < i:
                    li[a], lx[a] = j, e
                    a += 1
                else:
                    ui[b], ux[b] = j, e
                    b += 1
    return lp, li, lx, up, ui, ux, ud, rows


@njit(cache=True)
def lu_refactor(bp, bi, bx, c, lp, li, up, ui):
    r"""The factors of :math:`B + cI` (B's CSR arrays ``bp, bi, bx``) on the pattern of an
    earlier factorization of B + c'I without pivoting (L's strict rows ``lp, li``, U's ``up,
    ui``, columns ascending; a pattern that holds every fill entry, such as SuperLU's on
    diagonal pivots): ``(lx, ux, ud, ok)`` as :func:`lu_solve` takes them, row by row
    (:math:`w = B_{i\cdot} + c e_i`; for each k of L's row in order,
    :math:`L_{ik} = w_k / U_{kk}`, :math:`w \leftarrow w - L_{ik} U_{k\cdot}`; then U's row
    is w's). ``ok`` false where a pivot is zero or not finite."""
    n = lp.size - 1
    lx, ux, ud = np.empty(li.size), np.empty(ui.size), np.empty(n)
    w = np.zeros(n)
    ok = True
    for i in range(n):
        for p in range(bp[i], bp[i + 1]):
            w[bi[p]] = bx[p]
        w[i] += c
        for p in range(lp[i], lp[i + 1]):
            k = li[p]
            lik = w[k] / ud[k]
            lx[p] = lik
            w[k] = 0.0
            for r in range(up[k], up[k + 1]):
                w[ui[r]] -= lik * ux[r]
        d = w[i]
        ok = ok and d != 0.0 and np.isfinite(d)
        ud[i] = d
        w[i] = 0.0
        for r in range(up[i], up[i + 1]):
            ux[r] = w[ui[r]]
            w[ui[r]] = 0.0
    return lx, ux, ud, ok


@njit(cache=True, inline="always")
def _shared_rows(lp, li, i):
    """Whether L's rows i, i + 1, i + 2 are ``P``, ``P + [i]``, ``P + [i, i + 1]`` (one set P
    of columns, ascending)."""
    p0, p1, p2 = lp[i], lp[i + 1], lp[i + 2]
    m = p1 - p0
    if p2 - p1 != m + 1 or lp[i + 3] - p2 != m + 2:
        return False
    if li[p1 + m] != i or li[p2 + m] != i or li[p2 + m + 1] != i + 1:
        return False
    for k in range(m):
        if li[p1 + k] != li[p0 + k] or li[p2 + k] != li[p0 + k]:
            return False
    return True


@njit(cache=True, inline="always")
def _lower_row(bp, bi, bx, c, i, w):
    """Row i of B's lower triangle, and c on its diagonal, into ``w``."""
    for p in range(bp[i], bp[i + 1]):
        if bi[p] > i:
            break
        w[bi[p]] = bx[p]
    w[i] += c


@njit(cache=True, inline="always")
def _finish_row(i, start, lp, li, lx, up, ui, ux, ud, nxt, w):
    """Row i of :func:`symmetric_refactor` from L's entry ``start`` of the row on, then its
    pivot; ``w`` back to zeros. False where U's pattern is not L's transposed or the pivot is
    zero or not finite."""
    for p in range(start, lp[i + 1]):
        k = li[p]
        r = nxt[k]
        if r >= up[k + 1] or ui[r] != i:
            return False
        x = w[k]
        w[k] = 0.0
        ux[r] = x
        nxt[k] = r + 1
        lik = x / ud[k]
        lx[p] = lik
        for s in range(up[k], r + 1):
            w[ui[s]] -= lik * ux[s]
    d = w[i]
    ud[i] = d
    w[i] = 0.0
    return d != 0.0 and np.isfinite(d)


@njit(cache=True)
def symmetric_refactor(bp, bi, bx, c, lp, li, up, ui):
    r""":func:`lu_refactor` for a symmetric B: its lower triangle alone, by rows, half the work.
    Row i of L from :math:`w = B_{i, \le i} + c e_i`: for each k of L's row in order,
    :math:`U_{ki} = w_k`, :math:`L_{ik} = w_k / U_{kk}`, :math:`w \leftarrow w - L_{ik}
    U_{k, \le i}` (U's row k holds its columns up to i already); then :math:`U_{ii} = w_i`. So
    :math:`U = D L^T` and :math:`L D L^T = B + cI`. ``ok`` false where a pivot is zero or not
    finite, or where U's pattern is not L's transposed (then :func:`lu_refactor` serves).

    A contact's three rows whose L rows share their columns (:func:`_shared_rows`) go
    together through those columns: one read of U's row k serves three updates to three work
    rows, independent of each other (the refill waits on each update's store and load:
    local_problem_test 41 -> 29 µs); each row's operations, and so its bits, are those of the
    row alone."""
    n = lp.size - 1
    lx, ux, ud = np.empty(li.size), np.empty(ui.size), np.empty(n)
    w = np.zeros((3, n))
    w0, w1, w2 = w[0], w[1], w[2]
    nxt = up[:n].astype(np.int64)           # the next entry of U's row k: its column i
    ok = ui.size == li.size
    i = 0
    while i < n and ok:
        if i % 3 != 0 or i + 3 > n or not _shared_rows(lp, li, i):
            _lower_row(bp, bi, bx, c, i, w0)
            ok = _finish_row(i, lp[i], lp, li, lx, up, ui, ux, ud, nxt, w0)
            i += 1
            continue
        _lower_row(bp, bi, bx, c, i, w0)
        _lower_row(bp, bi, bx, c, i + 1, w1)
        _lower_row(bp, bi, bx, c, i + 2, w2)
        p0, p1, p2 = lp[i], lp[i + 1], lp[i + 2]
        m = p1 - p0
        for q in range(m):
            k = li[p0 + q]
            r = nxt[k]
            if r + 2 >= up[k + 1] or ui[r] != i or ui[r + 1] != i + 1 or ui[r + 2] != i + 2:
                ok = False
                break
            nxt[k] = r + 3
            x0, x1, x2 = w0[k], w1[k], w2[k]
            w0[k] = w1[k] = w2[k] = 0.0
            ux[r], ux[r + 1], ux[r + 2] = x0, x1, x2
            dk = ud[k]
            l0, l1, l2 = x0 / dk, x1 / dk, x2 / dk
            lx[p0 + q], lx[p1 + q], lx[p2 + q] = l0, l1, l2
            for s in range(up[k], r):
                col = ui[s]
                u = ux[s]
                w0[col] -= l0 * u
                w1[col] -= l1 * u
                w2[col] -= l2 * u
            w0[i] -= l0 * x0
            w1[i] -= l1 * x0
            w2[i] -= l2 * x0
            w1[i + 1] -= l1 * x1
            w2[i + 1] -= l2 * x1
            w2[i + 2] -= l2 * x2
        ok = ok and _finish_row(i, p0 + m, lp, li, lx, up, ui, ux, ud, nxt, w0)
        ok = ok and _finish_row(i + 1, p1 + m, lp, li, lx, up, ui, ux, ud, nxt, w1)
        ok = ok and _finish_row(i + 2, p2 + m, lp, li, lx, up, ui, ux, ud, nxt, w2)
        i += 3
    for k in range(n):
        ok = ok and nxt[k] == up[k + 1]
    return lx, ux, ud, ok


def csr_factors(L, U):
    """``(lp, li, lx, up, ui, ux, ud)`` of :func:`lu_solve` from the CSC factors L (unit lower
    triangular) and U (upper triangular) of SciPy's SuperLU or of dense triangles."""
    lp, li, lx, _ = _strict_rows(L.indptr, L.indices, L.data, True)
    up, ui, ux, ud = _strict_rows(U.indptr, U.indices, U.data, False)
    return lp, li, lx, up, ui, ux, ud


#: :func:`symmetric_form` takes U as :math:`D L^T` where every entry agrees to this much of
#: U's largest (SuperLU's factors of a symmetric W + cI on diagonal pivots: 2e-15 apart on the
#: 3,970-sphere pile; the 1,264-box pile's W, nonsymmetric by 2e-3, keeps its U).
SYMMETRIC_TOL = 1e-12


@njit(cache=True)
def symmetric_form(lp, li, lx, up, ui, ux, ud):
    """Whether U is :math:`D L^T` (D the diagonal ``ud``): the same pattern (U's row i holds
    the rows j > i of L that hold column i, ascending) and every entry within
    :data:`SYMMETRIC_TOL` of U's largest. Then :func:`lu_solve` needs L alone."""
    n = ud.size
    if up.size != n + 1 or ui.size != li.size:
        return False
    scale = 0.0
    for p in range(ux.size):
        scale = max(scale, abs(ux[p]))
    for i in range(n):
        scale = max(scale, abs(ud[i]))
    tol = SYMMETRIC_TOL * scale
    nxt = up[:n].copy()             # the next entry of U's row i to meet, by L's rows in turn
    for j in range(n):
        for p in range(lp[j], lp[j + 1]):
            i = li[p]
            r = nxt[i]
            if r >= up[i + 1] or ui[r] != j or not abs(ux[r] - ud[i] * lx[p]) <= tol:
                return False
            nxt[i] = r + 1
    return True
