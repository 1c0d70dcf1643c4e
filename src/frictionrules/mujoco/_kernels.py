r"""Numba kernels of the MuJoCo step: the Delassus operator from ``efc_J`` and the warm start.

**W without MuJoCo's** ``efc_AR``. The mass matrix couples only the dofs of one kinematic tree
(MuJoCo's ``dof_treeid``; a tree's dofs are contiguous, from ``tree_dofadr``), so
:math:`M^{-1}` is block diagonal by tree and one ``mj_solveM`` of ``m`` right-hand sides
(``m`` the largest tree's dof count), the ``k``-th holding :math:`e_{a_t + k}` for every tree
``t`` at once, gives every block: ``X[k, c]`` is :math:`(M^{-1})_{c,\,a_t + k}` for a dof
``c`` of tree ``t`` (:func:`minv_rhs`). Then, for the selected rows ``i`` of
:math:`J` (CSR, MuJoCo's ``efc_J``),

.. math:: W_{ij} = \sum_{c,c'} J_{ic} (M^{-1})_{cc'} J_{jc'},

non-zero only for rows ``j`` touching a tree that row ``i`` touches (:func:`delassus`). This
is what MuJoCo's ``mj_projectConstraint`` computes for its dual solvers (``efc_AR`` minus the
regularisation ``efc_R``), without setting ``opt.solver`` to one of them.
"""

from __future__ import annotations

import numpy as np

from .._optional import require

njit = require("numba", extra="kernels").njit

__all__ = ["minv_rhs", "delassus", "warm_start"]


def minv_rhs(tree_dofadr: np.ndarray, tree_dofnum: np.ndarray, nv: int) -> np.ndarray:
    """The ``(m, nv)`` right-hand sides of :func:`delassus`'s ``mj_solveM`` (built once per model)."""
    m = int(tree_dofnum.max()) if tree_dofnum.size else 0
    rhs = np.zeros((m, nv))
    for k in range(m):
        has = tree_dofnum > k
        rhs[k, tree_dofadr[has] + k] = 1.0
    return rhs


@njit(cache=True)
def delassus(rows, rowadr, rownnz, colind, jdata, dof_tree, tree_dofadr, tree_dofnum, X):
    """CSR arrays ``(indptr, indices, data)`` of :math:`W = J_S M^{-1} J_S^T` for the rows ``S =
    rows`` of ``J`` (``rowadr``, ``rownnz``, ``colind``, ``jdata`` as MuJoCo stores ``efc_J``),
    columns sorted. ``X`` from ``mj_solveM`` of :func:`minv_rhs`.

    Tree by tree: the dense block :math:`J_T` (the rows touching tree ``T``, its dofs), then
    :math:`W_T = J_T M_T^{-1} J_T^T`; row ``i`` of ``W`` is the sum of the rows of the (at
    most two) :math:`W_T` of its trees."""
    n = rows.size
    ntree = tree_dofadr.size
    # the trees each selected row touches (at most two for a contact), and the rows of each tree
    tcount = np.zeros(ntree + 1, np.int64)
    row_trees = np.full((n, 2), -1, np.int64)
    for i in range(n):
        r = rows[i]
        for k in range(rowadr[r], rowadr[r] + rownnz[r]):
            t = dof_tree[colind[k]]
            if row_trees[i, 0] == t or row_trees[i, 1] == t:
                continue
            if row_trees[i, 0] < 0:
                row_trees[i, 0] = t
            elif row_trees[i, 1] < 0:
                row_trees[i, 1] = t
            else:
                raise ValueError("a constraint row touches more than two kinematic trees")
            tcount[t + 1] += 1
    tptr = np.cumsum(tcount)
    trows = np.empty(tptr[-1], np.int64)
    loc = np.zeros((n, 2), np.int64)
    fill = tptr[:-1].copy()
    for i in range(n):
        for s in range(2):
            t = row_trees[i, s]
            if t >= 0:
                loc[i, s] = fill[t] - tptr[t]
                trows[fill[t]] = i
                fill[t] += 1
    # W_T of every tree, row-major, at woff[T]
    woff = np.zeros(ntree + 1, np.int64)
    for t in range(ntree):
        m = tptr[t + 1] - tptr[t]
        woff[t + 1] = woff[t] + m * m
    wt = np.zeros(woff[ntree])
    mmax, ndmax = 0, 0
    for t in range(ntree):
        mmax = max(mmax, tptr[t + 1] - tptr[t])
        ndmax = max(ndmax, tree_dofnum[t])
    JT = np.empty((mmax, ndmax))
    BT = np.empty((mmax, ndmax))
    for t in range(ntree):
        m = tptr[t + 1] - tptr[t]
        if m == 0:
            continue
        a, nd = tree_dofadr[t], tree_dofnum[t]
        JT[:m, :nd] = 0.0
        for l in range(m):
            r = rows[trows[tptr[t] + l]]
            for k in range(rowadr[r], rowadr[r] + rownnz[r]):
                c = colind[k] - a
                if 0 <= c < nd:
                    JT[l, c] += jdata[k]
        # B_T = J_T M_T^-1, (M_T^-1)[c, cc] = X[cc, a + c]
        for l in range(m):
            for cc in range(nd):
                acc = 0.0
                for c in range(nd):
                    acc += JT[l, c] * X[cc, a + c]
                BT[l, cc] = acc
        base = woff[t]
        for l in range(m):
            for l2 in range(l, m):     # W_T is symmetric (M_T^-1 is)
                acc = 0.0
                for c in range(nd):
                    acc += BT[l, c] * JT[l2, c]
                wt[base + l * m + l2] = acc
                wt[base + l2 * m + l] = acc
    # row i: the merge of its trees' rows of W_T (ascending), summed where both have a column
    indptr = np.zeros(n + 1, np.int32)        # SciPy's own index type for such sizes
    for i in range(n):
        indptr[i + 1] = indptr[i] + _merge_rows(trows, tptr, woff, wt, row_trees[i], loc[i], None, None, 0)
    indices = np.empty(indptr[n], np.int32)
    data = np.empty(indptr[n])
    for i in range(n):
        _merge_rows(trows, tptr, woff, wt, row_trees[i], loc[i], indices, data, indptr[i])
    return indptr, indices, data


@njit(cache=True)
def _merge_rows(trows, tptr, woff, wt, trees, loc, indices, data, start):
    """The ascending union of the rows of the trees ``trees`` (-1: none) with the row ``loc`` of
    each tree's ``W_T`` summed, written from ``start`` unless ``indices`` is None; its length."""
    t1, t2 = trees[0], trees[1]
    p, pe, q, qe, w1, w2 = 0, 0, 0, 0, 0, 0
    if t1 >= 0:
        p, pe = tptr[t1], tptr[t1 + 1]
        w1 = woff[t1] + loc[0] * (pe - p) - p
    if t2 >= 0:
        q, qe = tptr[t2], tptr[t2 + 1]
        w2 = woff[t2] + loc[1] * (qe - q) - q
    m = 0
    while p < pe or q < qe:
        if q >= qe or (p < pe and trows[p] < trows[q]):
            j, v = trows[p], wt[w1 + p]
            p += 1
        elif p >= pe or trows[q] < trows[p]:
            j, v = trows[q], wt[w2 + q]
            q += 1
        else:
            j, v = trows[p], wt[w1 + p] + wt[w2 + q]
            p += 1
            q += 1
        if indices is not None:
            indices[start + m] = j
            data[start + m] = v
        m += 1
    return m


@njit(cache=True)
def warm_start(key_new, pos_new, frames_new, key_old, pos_old, force_old, h, distance, r0):
    """Each new contact takes the world force of the previous contact with the same key nearest
    to it within ``distance``, turned into its frame and times ``h`` (``r0`` (nc, 3), filled;
    a compressive normal kept >= 0). Returns the count of contacts so started."""
    order = np.argsort(key_old, kind="mergesort")
    sk = key_old[order]
    d2max = distance * distance
    count = 0
    for a in range(key_new.size):
        k = key_new[a]
        lo = np.searchsorted(sk, k, "left")
        best, bd = -1, np.inf
        p = lo
        while p < sk.size and sk[p] == k:
            j = order[p]
            dx = pos_new[a, 0] - pos_old[j, 0]
            dy = pos_new[a, 1] - pos_old[j, 1]
            dz = pos_new[a, 2] - pos_old[j, 2]
            d2 = dx * dx + dy * dy + dz * dz
            if d2 < bd:
                best, bd = j, d2
            p += 1
        if best < 0 or bd > d2max:
            r0[a, 0] = r0[a, 1] = r0[a, 2] = 0.0
            continue
        count += 1
        for i in range(3):
            r0[a, i] = h * (frames_new[a, i, 0] * force_old[best, 0] + frames_new[a, i, 1] * force_old[best, 1]
                            + frames_new[a, i, 2] * force_old[best, 2])
        if r0[a, 0] < 0.0:
            r0[a, 0] = 0.0
    return count
