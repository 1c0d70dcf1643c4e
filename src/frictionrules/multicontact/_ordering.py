r"""Fill-reducing ordering on the graph of contacts, for the sparse LUs of ADMM (:math:`W + cI`),
Newton and the polish (:math:`J = B_1 + B_2 W`, the block pattern of W with its diagonal).

SuperLU's own ordering (``permc_spec="MMD_AT_PLUS_A"``) works on the graph of the 3 nc
unknowns and, in symmetric mode, does not postorder its elimination tree. Here the
minimum-degree ordering runs on the graph of the nc contacts (a 3 x 3 block of W per edge),
its elimination tree is postordered, and the matrix is handed to SuperLU already permuted
(``permc_spec="NATURAL"``), built in one pass from W's CSR arrays. Measured on KaplasTower
(570 contacts, nnz(W) = 116,784; each step timed in turn with the factorizations, their page
faults included): ``W + cI`` and ``tocsc`` 1.8 ms, then ``splu`` 7.8 ms (7.4 ms on SuperLU's
final permutation given as NATURAL), fill 301,122, 31.4 Mflop; here the ordering 0.3 ms, the
permuted matrix 1.1 ms, ``splu`` 6.6 ms, fill 287,262, 28.7 Mflop (over 11 random
renumberings of the contacts: fill 283,734-300,780, 27.7-31.8 Mflop). On the other piles,
the old way against this one: 1,264 boxes 4.7 ms against 3.7 ms, 1,812 spheres 17.0 against
16.3, 3,970 spheres 65 against 56 (their ordering 0.4, 1.2 and 3.6 ms; fill 91,074 against
90,606, 493,812 against 500,346, 1,665,786 against 1,615,944).

The minimum degree is the classical one on the explicit elimination graph, stored as one bit
set per contact (nc² / 8 bytes: used up to :data:`BITSET_MAX` contacts), with the two
refinements that make minimum-degree orderings good (George & Liu, SIAM Review 31, 1989):
contacts with the same closed neighbourhood are merged into one supervariable and eliminated
together, and the degree that is minimized is the external one (the supervariable's own
members not counted). Without them the fill was 311,004 on KaplasTower and 605,088 on the
1,812-sphere pile. The postorder (as CHOLMOD's) keeps each subtree's columns together; on
KaplasTower SuperLU's time was the same with or without it (7.3 ms in one run of 25 each).
"""

from __future__ import annotations

import numpy as np

from .._optional import require

njit = require("numba", extra="kernels").njit

#: The bit sets of the elimination graph take nc² / 8 bytes: 8 MB at this many contacts.
#: Above it SuperLU orders the unknowns itself.
BITSET_MAX = 8192

#: SuperLU's panel (columns updated together) for the contacts' ordering, below its default
#: 20: its work arrays, zeroed at every factorization, are fresh memory, and a smaller panel
#: touches fewer pages. Measured on ``W + cI`` (``splu`` alone, 20 runs each; panel 20, 8):
#: KaplasTower 6.97 and 6.82 ms (837 and 747 page faults), 1,264 boxes 3.27 and 2.84, 1,812
#: spheres 14.7 and 14.1, 3,970 spheres 51.9 and 50.9, Capsules 0.50 and 0.42. (SciPy's
#: SuperLU sizes a statistics table by its defaults: a panel above 20 wrote past it and
#: corrupted the heap.)
PANEL_SIZE = 8


@njit(cache=True)
def _popcount(x):
    x = x - ((x >> np.uint64(1)) & np.uint64(0x5555555555555555))
    x = (x & np.uint64(0x3333333333333333)) + ((x >> np.uint64(2)) & np.uint64(0x3333333333333333))
    x = (x + (x >> np.uint64(4))) & np.uint64(0x0F0F0F0F0F0F0F0F)
    return np.int64((x * np.uint64(0x0101010101010101)) >> np.uint64(56))


@njit(cache=True)
def _row_bits(G, u, out):
    """The indices of the set bits of ``G[u]`` into ``out``; returns how many."""
    one = np.uint64(1)
    m = 0
    for w in range(G.shape[1]):
        x = G[u, w]
        while x:
            t = x & (~x + one)
            out[m] = w * 64 + _popcount(t - one)
            m += 1
            x ^= t
    return m


@njit(cache=True)
def _degree(G, u, size):
    d = 0
    for w in range(G.shape[1]):
        d += _popcount(G[u, w])
    return d - (size[u] - 1)


@njit(cache=True)
def contact_graph(indptr, indices, nc):
    """The contacts' graph of the pattern of :math:`A + A^T` (A: 3 nc x 3 nc CSR arrays, each
    row's column indices sorted) as one bit set per contact (no self-loops).

    A whole 3 x 3 block is stepped over at once (Kaplas: 0.13 ms instead of 0.26 ms with
    unsigned index arrays, which spare the compiled code the wrapping of negative indices)."""
    words = (nc + 63) // 64
    one = np.uint64(1)
    G = np.zeros((nc, words), np.uint64)
    for i in range(3 * nc):
        a = i // 3
        k, end = np.int64(indptr[i]), np.int64(indptr[i + 1])
        while k < end:
            j = np.int64(indices[k])
            b = j // 3
            if b != a:
                G[a, b >> 6] |= one << np.uint64(b & 63)
                G[b, a >> 6] |= one << np.uint64(a & 63)
            if j % 3 == 0 and k + 2 < end and indices[k + 2] == j + 2:
                k += 3                                  # the block's three columns
            else:
                k += 1
                while k < end and indices[k] < 3 * b + 3:
                    k += 1
    return G


@njit(cache=True)
def _merge_indistinguishable(G, cand, m, principal, size, next_member, last_member, deg, key):
    """Merge the principal contacts among ``cand[:m]`` whose closed neighbourhoods are equal
    (found by sorting a hash of the rows); updates the degrees of the merged ones."""
    one = np.uint64(1)
    words = G.shape[1]
    for a in range(m):
        u = cand[a]
        h = np.uint64(1469598103934665603)
        for w in range(words):
            x = G[u, w]
            if w == (u >> 6):
                x |= one << np.uint64(u & 63)
            h = (h ^ x) * np.uint64(1099511628211)
        key[a] = h
    idx = np.argsort(key[:m])
    for a in range(m):
        u = cand[idx[a]]
        if not principal[u]:
            continue
        merged = False
        for b in range(a + 1, m):
            if key[idx[b]] != key[idx[a]]:
                break
            v = cand[idx[b]]
            if not principal[v]:
                continue
            same = True
            for w in range(words):
                x, y = G[u, w], G[v, w]
                if w == (u >> 6):
                    x |= one << np.uint64(u & 63)
                if w == (v >> 6):
                    y |= one << np.uint64(v & 63)
                if x != y:
                    same = False
                    break
            if same:
                principal[v] = False
                next_member[last_member[u]] = v
                last_member[u] = last_member[v]
                size[u] += size[v]
                merged = True
        if merged:
            deg[u] = _degree(G, u, size)


_NONE = np.iinfo(np.int64).max


@njit(cache=True)
def _set_key(tree, leaves, u, value):
    """Set the key of contact ``u`` in the tournament tree of minima."""
    t = leaves + u
    tree[t] = value
    while t > 1:
        t //= 2
        tree[t] = min(tree[2 * t], tree[2 * t + 1])


@njit(cache=True)
def minimum_degree(G):
    """Minimum external degree ordering of the graph ``G`` (bit sets, modified in place).

    Returns ``(order, parent)``: ``order[k]`` the k-th contact eliminated, ``parent`` the
    elimination tree (-1 at the roots). The least degree (the first contact among equals) is
    kept at the root of a tree of minima: scanning every contact for it took 2.2 ms of the
    ordering of the 1,812-sphere pile."""
    nc, words = G.shape
    one = np.uint64(1)
    principal = np.ones(nc, np.bool_)
    size = np.ones(nc, np.int64)
    next_member = np.full(nc, -1, np.int64)
    last_member = np.arange(nc)
    deg = np.empty(nc, np.int64)
    for u in range(nc):
        deg[u] = _degree(G, u, size)
    nbrs = np.arange(nc)
    key = np.empty(nc, np.uint64)
    _merge_indistinguishable(G, nbrs, nc, principal, size, next_member, last_member, deg, key)
    leaves = 1
    while leaves < nc:
        leaves *= 2
    tree = np.full(2 * leaves, _NONE, np.int64)     # the least (degree, contact) of a subtree
    for u in range(nc):
        if principal[u]:
            tree[leaves + u] = deg[u] * nc + u
    for t in range(leaves - 1, 0, -1):
        tree[t] = min(tree[2 * t], tree[2 * t + 1])
    order = np.empty(nc, np.int64)
    mask = np.empty(words, np.uint64)
    k = 0
    while k < nc:
        v = tree[1] % nc                # the first of the least degree
        _set_key(tree, leaves, v, _NONE)
        mask[:] = ~np.uint64(0)
        s = v
        while s != -1:                  # the supervariable, eliminated at once
            order[k] = s
            k += 1
            mask[s >> 6] &= ~(one << np.uint64(s & 63))
            s = next_member[s]
        for w in range(words):
            G[v, w] &= mask[w]
        m = _row_bits(G, v, nbrs)
        p = 0
        for a in range(m):              # its neighbours become a clique
            u = nbrs[a]
            if principal[u]:
                for w in range(words):
                    G[u, w] = (G[u, w] | G[v, w]) & mask[w]
                G[u, u >> 6] &= ~(one << np.uint64(u & 63))
                deg[u] = _degree(G, u, size)
                nbrs[p] = u
                p += 1
        _merge_indistinguishable(G, nbrs, p, principal, size, next_member, last_member, deg, key)
        for a in range(p):
            u = nbrs[a]
            _set_key(tree, leaves, u, deg[u] * nc + u if principal[u] else _NONE)
    pos = np.empty(nc, np.int64)
    for i in range(nc):
        pos[order[i]] = i
    parent = np.full(nc, -1, np.int64)
    for v in range(nc):
        if not principal[v]:
            continue
        s = v
        while next_member[s] != -1:     # a supervariable is a chain of the tree
            parent[s] = next_member[s]
            s = next_member[s]
        m = _row_bits(G, v, nbrs)       # G[v]: its neighbours when it was eliminated
        first = nc
        for a in range(m):
            first = min(first, pos[nbrs[a]])
        parent[s] = order[first] if first < nc else -1
    return order, parent


@njit(cache=True)
def postorder(order, parent):
    """A postorder of the elimination tree, the children of a node in elimination order."""
    nc = order.size
    head = np.full(nc, -1, np.int64)
    sibling = np.full(nc, -1, np.int64)
    for i in range(nc - 1, -1, -1):
        v = order[i]
        if parent[v] >= 0:
            sibling[v] = head[parent[v]]
            head[parent[v]] = v
    out = np.empty(nc, np.int64)
    stack = np.empty(nc, np.int64)
    k = 0
    for i in range(nc):
        if parent[order[i]] != -1:
            continue
        top = 0
        stack[0] = order[i]
        while top >= 0:
            v = stack[top]
            c = head[v]
            if c != -1:
                head[v] = sibling[c]
                top += 1
                stack[top] = c
            else:
                out[k] = v
                k += 1
                top -= 1
    return out


def contact_ordering(indptr, indices, nc: int) -> np.ndarray:
    """The permutation of the 3 nc unknowns: the contacts postordered after their minimum
    degree ordering, each contact's three unknowns together."""
    G = contact_graph(indptr.view(np.uint32), indices.view(np.uint32), nc) if (
        indptr.dtype == np.int32 and indices.dtype == np.int32) else contact_graph(indptr, indices, nc)
    order, parent = minimum_degree(G)
    return (3 * postorder(order, parent)[:, None] + np.arange(3)).ravel()


@njit(cache=True)
def _dense_blocks(indptr, indices, nc):
    """Whether A's pattern is made of whole 3 x 3 blocks, the three rows of a contact storing
    the same blocks, each contact's diagonal block among them."""
    for a in range(nc):
        s = indptr[3 * a]
        m = indptr[3 * a + 1] - s
        if m % 3 != 0 or indptr[3 * a + 2] - s != 2 * m or indptr[3 * a + 3] - s != 3 * m:
            return False
        diag = False
        for t in range(0, m, 3):
            j = indices[s + t]
            if j % 3 != 0:
                return False
            diag = diag or j == 3 * a
            for r in range(3):
                for c in range(3):
                    if indices[s + r * m + t + c] != j + c:
                        return False
        if not diag:
            return False
    return True


@njit(cache=True)
def _block_csc(indptr, indices, data, order, c):
    """:func:`shifted_permuted_csc` for a pattern of whole 3 x 3 blocks (see
    :func:`_dense_blocks`), the contacts permuted by ``order``: one pass over the blocks."""
    nc = order.size
    pos = np.empty(nc, np.int64)
    for a in range(nc):
        pos[order[a]] = a
    count = np.zeros(nc, np.int64)          # blocks per block column of B
    for a in range(nc):
        for k in range(indptr[3 * a], indptr[3 * a + 1], 3):
            count[pos[indices[k] // 3]] += 1
    start = np.empty(nc + 1, np.int64)      # offset of block column b: 9 x blocks before it
    start[0] = 0
    for b in range(nc):
        start[b + 1] = start[b] + 9 * count[b]
    ptr = np.empty(3 * nc + 1, np.int32)
    for b in range(nc):
        for col in range(3):
            ptr[3 * b + col] = start[b] + 3 * col * count[b]
    ptr[3 * nc] = start[nc]
    rows = np.empty(start[nc], np.int32)
    vals = np.empty(start[nc])
    slot = np.zeros(nc, np.int64)
    for ra in range(nc):                    # B's block rows in order: rows come sorted
        a = order[ra]
        s = indptr[3 * a]
        m = indptr[3 * a + 1] - s
        for t in range(0, m, 3):
            b = indices[s + t] // 3
            cb = pos[b]
            for col in range(3):
                base = start[cb] + 3 * col * count[cb] + 3 * slot[cb]
                for r in range(3):
                    rows[base + r] = 3 * ra + r
                    v = data[s + r * m + t + col]
                    vals[base + r] = v + c if b == a and r == col else v
            slot[cb] += 1
    return ptr, rows, vals


@njit(cache=True)
def _scalar_csc(indptr, indices, data, perm, c):
    """:func:`shifted_permuted_csc` for any pattern: a transposition with the permutation."""
    n = perm.size
    pinv = np.empty(n, np.int64)
    for i in range(n):
        pinv[perm[i]] = i
    ptr = np.zeros(n + 1, np.int64)
    has_diag = np.zeros(n, np.bool_)
    for i in range(n):
        for k in range(indptr[i], indptr[i + 1]):
            j = indices[k]
            ptr[pinv[j] + 1] += 1
            if j == i:
                has_diag[i] = True
    for i in range(n):
        if not has_diag[i]:
            ptr[pinv[i] + 1] += 1
    for j in range(n):
        ptr[j + 1] += ptr[j]
    rows = np.empty(ptr[n], np.int32)
    vals = np.empty(ptr[n])
    nxt = ptr[:n].copy()
    for r in range(n):                      # B's rows in order: each column's rows come sorted
        i = perm[r]
        if not has_diag[i]:
            s = nxt[r]
            rows[s], vals[s] = r, c
            nxt[r] = s + 1
        for k in range(indptr[i], indptr[i + 1]):
            j = indices[k]
            s = nxt[pinv[j]]
            rows[s] = r
            vals[s] = data[k] + c if j == i else data[k]
            nxt[pinv[j]] = s + 1
    return ptr.astype(np.int32), rows, vals


@njit(cache=True)
def augmented_csr(jptr, jind, jdat, tptr, tind, tdat, lam):
    r"""The CSR arrays (rows sorted) of :math:`\begin{pmatrix} I & J \\ J^T & -\lambda I
    \end{pmatrix}` from J's CSR arrays and those of :math:`J^T` (J's columns), each row
    sorted: one pass, for the Levenberg–Marquardt direction (:func:`._newton.lm_direction`)."""
    n = jptr.size - 1
    nnz = 2 * n + jptr[n] + tptr[n]
    ptr = np.empty(2 * n + 1, np.int32)
    ind = np.empty(nnz, np.int32)
    val = np.empty(nnz)
    ptr[0] = 0
    k = 0
    for i in range(n):                  # row i: the identity's 1, then J's row i
        ind[k], val[k] = i, 1.0
        k += 1
        for p in range(jptr[i], jptr[i + 1]):
            ind[k], val[k] = n + jind[p], jdat[p]
            k += 1
        ptr[i + 1] = k
    for i in range(n):                  # row n + i: J's column i, then -lam
        for p in range(tptr[i], tptr[i + 1]):
            ind[k], val[k] = tind[p], tdat[p]
            k += 1
        ind[k], val[k] = n + i, -lam
        k += 1
        ptr[n + i + 1] = k
    return ptr, ind, val


def shifted_permuted_csc(indptr, indices, data, perm, c: float, dense_blocks=None):
    r"""The CSC arrays (row indices sorted) of :math:`B = P (A + cI) P^T`,
    :math:`B_{ij} = A_{p_i p_j} + c\,\delta_{ij}`, from the CSR arrays of A (square, each row
    sorted); a diagonal entry that A does not store is inserted.

    When ``perm`` keeps each contact's three unknowns together and in order and A is made of
    whole 3 x 3 blocks (a Delassus operator is; ``dense_blocks``: :func:`_dense_blocks` when
    known), the blocks are moved at once: 0.32 ms instead of 0.63 ms on KaplasTower, page
    faults aside (SciPy's ``W + c I`` then ``tocsc``: 0.46 ms).
    """
    nc = perm.size // 3
    blocks = perm[0::3]
    if (perm.size == 3 * nc and np.all(blocks % 3 == 0) and np.all(perm[1::3] == blocks + 1)
            and np.all(perm[2::3] == blocks + 2)
            and (_dense_blocks(indptr, indices, nc) if dense_blocks is None else dense_blocks)):
        return _block_csc(indptr, indices, data, blocks // 3, c)
    return _scalar_csc(indptr, indices, data, perm, c)


def frame_ordering(fr):
    """The permutation of a frame's unknowns by :func:`contact_ordering`, computed once and
    kept in ``fr.cache``; None (SuperLU then orders the unknowns itself) beyond
    :data:`BITSET_MAX` contacts or when W's rows are not sorted. It serves every matrix with
    W's pattern of contacts: ``W + cI`` and the Jacobians ``B_1 + B_2 W``."""
    if "ordering" not in fr.cache:
        fr.cache["ordering"] = (contact_ordering(fr.csr[0], fr.csr[1], fr.nc)
                                if fr.nc <= BITSET_MAX and fr.W.has_sorted_indices else None)
    return fr.cache["ordering"]


def ordered_superlu(indptr, indices, data, perm, c: float = 0.0, dense_blocks=None):
    r"""SuperLU's factorization of :math:`P (A + cI) P^T` (see :func:`ordered_lu`)."""
    import scipy.sparse as sp
    import scipy.sparse.linalg as spla
    n = perm.size
    ptr, rows, vals = shifted_permuted_csc(indptr, indices, data, perm, c, dense_blocks)
    return spla.splu(sp.csc_matrix((vals, rows, ptr), shape=(n, n)), permc_spec="NATURAL",
                     diag_pivot_thresh=0.0, panel_size=PANEL_SIZE, options={"SymmetricMode": True})


def ordered_lu(indptr, indices, data, perm, c: float = 0.0, dense_blocks=None):
    r"""A solver of :math:`(A + cI) x = b` (b a vector or the columns of an array) from one
    SuperLU factorization of :math:`P (A + cI) P^T` (A's CSR arrays, rows sorted; ``perm`` a
    permutation of A's unknowns, moved by whole 3 x 3 blocks where it keeps contacts' three
    unknowns together as :func:`contact_ordering`'s does, see :func:`shifted_permuted_csc`), on
    diagonal pivots in symmetric mode: no pivoting, so the fill is the ordering's. Raises ``RuntimeError`` where a pivot is exactly zero; a tiny
    one costs digits, which the caller measures (by a residual) and refines.
    """
    lu = ordered_superlu(indptr, indices, data, perm, c, dense_blocks)

    def solve(b):
        x = np.empty_like(b)
        x[perm] = lu.solve(b[perm])
        return x
    return solve
