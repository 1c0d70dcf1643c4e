r"""Numba kernels of the MuJoCo step: the contacts' blocks of :math:`W = J M^{-1} J^T` and the
warm start.

**W by its factors, without MuJoCo's** ``efc_AR``. The mass matrix couples only the dofs of
one kinematic tree (MuJoCo's ``dof_treeid``; a tree's dofs are contiguous, from
``tree_dofadr``), so :math:`M^{-1}` is block diagonal by tree and one ``mj_solveM`` of ``m``
right-hand sides (``m`` the largest tree's dof count), the ``k``-th holding :math:`e_{a_t +
k}` for every tree ``t`` at once, gives every block: ``X[k, c]`` is :math:`(M^{-1})_{c,\,a_t
+ k}` for a dof ``c`` of tree ``t`` (:func:`minv_rhs`). A contact's rows of ``efc_J`` touch
at most two trees; :func:`contact_blocks` gives, per contact and tree, the dense blocks
:math:`J_{a,t}` and :math:`B_{a,t} = J_{a,t}M_t^{-1}` that
:class:`frictionrules.multicontact.factored.TreeBlocks` takes, with
:math:`W_{ac} = \sum_t J_{a,t}B_{c,t}^T` (what MuJoCo's ``mj_projectConstraint`` computes
for its dual solvers, ``efc_AR`` minus the regularisation ``efc_R``), never formed unless
asked for.
"""

from __future__ import annotations

import numpy as np

from .._optional import require

njit = require("numba", extra="kernels").njit

__all__ = ["minv_rhs", "contact_blocks", "warm_start"]


def minv_rhs(tree_dofadr: np.ndarray, tree_dofnum: np.ndarray, nv: int) -> np.ndarray:
    """The ``(m, nv)`` right-hand sides of :func:`contact_blocks`'s ``mj_solveM`` (built once per model)."""
    m = int(tree_dofnum.max()) if tree_dofnum.size else 0
    rhs = np.zeros((m, nv))
    for k in range(m):
        has = tree_dofnum > k
        rhs[k, tree_dofadr[has] + k] = 1.0
    return rhs


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


@njit(cache=True)
def contact_blocks(addr, rowadr, rownnz, colind, jdata, dof_tree, tree_dofadr, tree_dofnum, X, C, turned,
                   vfree, gap_velocity):
    r"""The blocks of :class:`frictionrules.multicontact.factored.TreeBlocks` and ``q`` of the
    contacts whose rows N, T1, T2 start at ``addr`` (nc,) in ``efc_J`` (CSR as MuJoCo stores
    it). Per contact and tree: :math:`J_{a,t}` (the rows T1, T2 turned by ``C[a]`` (2 x 2)
    where ``turned[a]``: MuJoCo's tangents to the law's), :math:`B_{a,t} = J_{a,t} M_t^{-1}`
    (``(M_t^{-1})_{c,c'} = X[c' - a_t, c]``, ``X`` from ``mj_solveM`` of :func:`minv_rhs`),
    :math:`D_a = \sum_t J_{a,t}B_{a,t}^T`, and :math:`q_a = J_a v_{free} + \gamma_a/h\,e_N`,
    ``gap_velocity`` (nc,) the normal parts :math:`\gamma_a/h` of
    :func:`._consistent.gap_term`. Returns ``(tree, offset, J, B, D, q)``."""
    nc = addr.size
    tree = np.full((nc, 2), -1, np.int64)
    for a in range(nc):
        for l in range(3):
            r = addr[a] + l
            for k in range(rowadr[r], rowadr[r] + rownnz[r]):
                t = dof_tree[colind[k]]
                if tree[a, 0] == t or tree[a, 1] == t:
                    continue
                if tree[a, 0] < 0:
                    tree[a, 0] = t
                elif tree[a, 1] < 0:
                    tree[a, 1] = t
                else:
                    raise ValueError("a contact touches more than two kinematic trees")
    off = np.zeros((nc, 2), np.int64)
    size = 0
    for a in range(nc):
        for s in range(2):
            t = tree[a, s]
            if t >= 0:
                off[a, s] = size
                size += 3 * tree_dofnum[t]
    # the non-zeros of each tree's block of M^-1, row by row (a free body's is diagonal where
    # its principal axes are the body's: 6 of 36), so that B skips the zeros
    ntree = tree_dofadr.size
    nzptr = np.zeros(ntree + 1, np.int64)
    for t in range(ntree):
        c0, n = tree_dofadr[t], tree_dofnum[t]
        m = 0
        for j in range(n):
            for k in range(n):
                if X[j, c0 + k] != 0.0:
                    m += 1
        nzptr[t + 1] = nzptr[t] + m
    nzj = np.empty(nzptr[ntree], np.int64)
    nzk = np.empty(nzptr[ntree], np.int64)
    nzv = np.empty(nzptr[ntree])
    for t in range(ntree):
        c0, n = tree_dofadr[t], tree_dofnum[t]
        e = nzptr[t]
        for j in range(n):
            for k in range(n):
                if X[j, c0 + k] != 0.0:
                    nzj[e], nzk[e], nzv[e] = j, k, X[j, c0 + k]
                    e += 1
    Jp = np.zeros(size)
    Bp = np.zeros(size)
    D = np.zeros((nc, 3, 3))
    q = np.empty(3 * nc)
    for a in range(nc):
        for l in range(3):
            r = addr[a] + l
            for k in range(rowadr[r], rowadr[r] + rownnz[r]):
                c = colind[k]
                t = dof_tree[c]
                s = 0 if tree[a, 0] == t else 1
                Jp[off[a, s] + l * tree_dofnum[t] + c - tree_dofadr[t]] += jdata[k]
        u0 = u1 = u2 = 0.0
        for s in range(2):
            t = tree[a, s]
            if t < 0:
                continue
            p, c0, n = off[a, s], tree_dofadr[t], tree_dofnum[t]
            if turned[a]:
                for k in range(n):
                    x1, x2 = Jp[p + n + k], Jp[p + 2 * n + k]
                    Jp[p + n + k] = C[a, 0, 0] * x1 + C[a, 0, 1] * x2
                    Jp[p + 2 * n + k] = C[a, 1, 0] * x1 + C[a, 1, 1] * x2
            for l in range(3):
                row = p + l * n
                for e in range(nzptr[t], nzptr[t + 1]):      # B[l, j] = sum_k J[l, k] X[j, c0 + k]
                    Bp[row + nzj[e]] += Jp[row + nzk[e]] * nzv[e]
            for k in range(n):
                x = vfree[c0 + k]
                u0 += Jp[p + k] * x
                u1 += Jp[p + n + k] * x
                u2 += Jp[p + 2 * n + k] * x
            for l in range(3):
                for l2 in range(3):
                    acc = 0.0
                    for k in range(n):
                        acc += Jp[p + l * n + k] * Bp[p + l2 * n + k]
                    D[a, l, l2] += acc
        q[3 * a] = u0 + gap_velocity[a]
        q[3 * a + 1] = u1
        q[3 * a + 2] = u2
    return tree, off, Jp, Bp, D, q
