r"""Neighbours of the dynamic engine: a compiled cell list in the reduced coordinates of the
periodic cell, with a Verlet skin.

A **pair** is a grain ``i``, a grain ``j`` and an image shift ``K`` (integers) with the branch
vector ``l = x_j + H K - x_i`` (``H`` the cell, its columns the cell vectors; positions are never
wrapped, so a pair keeps its key while the grains move). The pair list holds every pair whose
gap ``|l| - r_i - r_j`` is at most the skin ``s`` when it is built, once (``i < j``, or
``i = j`` and ``K`` lexicographically positive), sorted by ``(i, j, K)``.

Cell list: the reduced coordinates ``H^{-1} x`` wrapped to ``[0, 1)`` are binned, ``n_a =
floor(w_a / c)`` bins along cell vector ``a`` (``w_a`` the distance between the faces of the
cell normal to the reciprocal vector ``a``, ``c = 2 r_max + s`` the cut-off); a direction with
fewer than three bins keeps one bin and searches the images ``K_a = -1, 0, 1`` instead (small
cells: the lattices' unit cells). Each grain looks at the 3 (2-D: 9 in the plane) neighbouring
bins. Both passes (count, fill) run in parallel over grains.

Rebuild rule (jax-md's ``neighbor_list``, YADE's Verlet distance): with ``F = H H_b^{-1}`` the
deformation since the build and ``u_i = x_i - F x_i^b`` each grain's displacement apart from
the affine one, a pair's distance has changed by at most ``2 max|u_i| + |F - I| c``; the list is
rebuilt once ``max|u_i| + |F - I| c / 2`` exceeds half the skin, before any pair beyond it can
touch.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

__all__ = ["build_pairs", "match_keys", "grain_lists", "bins_of"]


@njit(cache=True)
def bins_of(widths, cutoff):
    """Bins along each cell vector: ``floor(w/c)``, or 1 where fewer than 3 would fit (those
    directions search the images instead)."""
    nb = np.ones(3, dtype=np.int64)
    for a in range(3):
        k = int(widths[a] // cutoff)
        nb[a] = k if k >= 3 else 1
    return nb


@njit(cache=True)
def _sort_grains(sw, nb):
    """Counting sort of the grains by bin: (start of each bin, grains in bin order, bin of
    each grain as three indices)."""
    n = sw.shape[0]
    cell = np.empty((n, 3), dtype=np.int64)
    nbins = nb[0] * nb[1] * nb[2]
    count = np.zeros(nbins + 1, dtype=np.int64)
    for i in range(n):
        for a in range(3):
            b = int(sw[i, a] * nb[a])
            cell[i, a] = min(max(b, 0), nb[a] - 1)
        count[(cell[i, 0] * nb[1] + cell[i, 1]) * nb[2] + cell[i, 2] + 1] += 1
    for b in range(nbins):
        count[b + 1] += count[b]
    fill = count[:-1].copy()
    items = np.empty(n, dtype=np.int64)
    for i in range(n):
        b = (cell[i, 0] * nb[1] + cell[i, 1]) * nb[2] + cell[i, 2]
        items[fill[b]] = i
        fill[b] += 1
    return count, items, cell


@njit(inline="always")
def _positive(k0, k1, k2):
    """The image shift is lexicographically positive (one entry per self-image pair)."""
    if k0 != 0:
        return k0 > 0
    if k1 != 0:
        return k1 > 0
    return k2 > 0


@njit(inline="always")
def _wrap(b, o, n):
    """The bin ``b`` (offset ``o`` from a grain's own) along a cell vector of ``n`` bins, and
    the image it lies in: wrapped into the cell, or with one bin the image ``o`` itself."""
    if n == 1:
        return 0, o
    if b < 0:
        return b + n, -1
    if b >= n:
        return b - n, 1
    return b, 0


@njit(inline="always")
def _scan(i, sw, floors, radius, H, nb, lo_z, hi_z, start, items, cell, skin, out_j, out_k, pos, count_only):
    """Visit the candidates of grain ``i``; write them from ``pos`` (unless ``count_only``);
    returns how many there are."""
    found = 0
    ri = radius[i]
    for o0 in range(-1, 2):
        for o1 in range(-1, 2):
            for o2 in range(lo_z, hi_z + 1):
                b0, b1, b2 = cell[i, 0] + o0, cell[i, 1] + o1, cell[i, 2] + o2
                b0, w0 = _wrap(b0, o0, nb[0])
                b1, w1 = _wrap(b1, o1, nb[1])
                b2, w2 = _wrap(b2, o2, nb[2])
                bin_ = (b0 * nb[1] + b1) * nb[2] + b2
                for e in range(start[bin_], start[bin_ + 1]):
                    j = items[e]
                    if j < i or (j == i and not _positive(w0, w1, w2)):
                        continue
                    d0 = sw[j, 0] + w0 - sw[i, 0]
                    d1 = sw[j, 1] + w1 - sw[i, 1]
                    d2 = sw[j, 2] + w2 - sw[i, 2]
                    l0 = H[0, 0] * d0 + H[0, 1] * d1 + H[0, 2] * d2
                    l1 = H[1, 0] * d0 + H[1, 1] * d1 + H[1, 2] * d2
                    l2 = H[2, 0] * d0 + H[2, 1] * d1 + H[2, 2] * d2
                    reach = ri + radius[j] + skin
                    if l0 * l0 + l1 * l1 + l2 * l2 > reach * reach:
                        continue
                    if not count_only:
                        out_j[pos + found] = j
                        # the shift of the unwrapped positions: K = K_w + floor(s_i) - floor(s_j)
                        out_k[pos + found, 0] = w0 + floors[i, 0] - floors[j, 0]
                        out_k[pos + found, 1] = w1 + floors[i, 1] - floors[j, 1]
                        out_k[pos + found, 2] = w2 + floors[i, 2] - floors[j, 2]
                    found += 1
    return found


@njit(inline="always")
def _key_less(ja, ka, jb, kb):
    if ja != jb:
        return ja < jb
    for a in range(3):
        if ka[a] != kb[a]:
            return ka[a] < kb[a]
    return False


@njit(parallel=True, cache=True)
def _pairs(x, radius, H, skin, dim):
    n = x.shape[0]
    Hinv = np.linalg.inv(H)
    s = x @ Hinv.T
    floors = np.floor(s).astype(np.int64)
    sw = s - floors
    widths = np.empty(3)
    for a in range(3):
        widths[a] = 1.0 / np.sqrt(Hinv[a, 0] ** 2 + Hinv[a, 1] ** 2 + Hinv[a, 2] ** 2)
    cutoff = 2.0 * radius.max() + skin
    nb = bins_of(widths, cutoff)
    lo_z, hi_z = -1, 1
    if dim == 2:
        nb[2] = 1
        lo_z, hi_z = 0, 0
    start, items, cell = _sort_grains(sw, nb)
    count = np.zeros(n + 1, dtype=np.int64)
    dummy_j = np.empty(0, dtype=np.int64)
    dummy_k = np.empty((0, 3), dtype=np.int64)
    for i in prange(n):
        count[i + 1] = _scan(i, sw, floors, radius, H, nb, lo_z, hi_z, start, items, cell, skin,
                             dummy_j, dummy_k, 0, True)
    for i in range(n):
        count[i + 1] += count[i]
    m = count[n]
    J = np.empty(m, dtype=np.int64)
    K = np.empty((m, 3), dtype=np.int64)
    I = np.empty(m, dtype=np.int64)
    for i in prange(n):
        lo = count[i]
        hi = lo + _scan(i, sw, floors, radius, H, nb, lo_z, hi_z, start, items, cell, skin, J, K, lo, False)
        # insertion sort of grain i's few pairs by (j, K)
        for a in range(lo + 1, hi):
            jj = J[a]
            kk = K[a].copy()
            b = a - 1
            while b >= lo and _key_less(jj, kk, J[b], K[b]):
                J[b + 1] = J[b]
                K[b + 1] = K[b]
                b -= 1
            J[b + 1] = jj
            K[b + 1] = kk
        for a in range(lo, hi):
            I[a] = i
    return I, J, K


def build_pairs(x, radius, H, skin, dim):
    """Every pair with gap ``<= skin`` at positions ``x`` (n, 3) in the cell ``H`` (3, 3):
    ``(i, j, shift)`` sorted by ``(i, j, K)``."""
    return _pairs(np.ascontiguousarray(x), radius, np.ascontiguousarray(H), float(skin), int(dim))


@njit(cache=True)
def match_keys(i0, j0, k0, i1, j1, k1):
    """For each key of the sorted list 1, its index in the sorted list 0, or -1."""
    out = np.full(i1.shape[0], -1, dtype=np.int64)
    a = 0
    m0 = i0.shape[0]
    for b in range(i1.shape[0]):
        while a < m0:
            if i0[a] < i1[b] or (i0[a] == i1[b] and _key_less(j0[a], k0[a], j1[b], k1[b])):
                a += 1
            else:
                break
        if a < m0 and i0[a] == i1[b] and j0[a] == j1[b] and k0[a, 0] == k1[b, 0] \
                and k0[a, 1] == k1[b, 1] and k0[a, 2] == k1[b, 2]:
            out[b] = a
    return out


@njit(cache=True)
def grain_lists(I, J, n):
    """Each grain's pairs as a CSR list: ``start`` (n + 1) and ``entry`` = ``2 c`` where the
    grain is ``i`` of pair ``c``, ``2 c + 1`` where it is ``j`` (a grain touching its own image
    is both)."""
    m = I.shape[0]
    count = np.zeros(n + 1, dtype=np.int64)
    for c in range(m):
        count[I[c] + 1] += 1
        count[J[c] + 1] += 1
    for g in range(n):
        count[g + 1] += count[g]
    fill = count[:-1].copy()
    entry = np.empty(2 * m, dtype=np.int64)
    for c in range(m):
        entry[fill[I[c]]] = 2 * c
        fill[I[c]] += 1
        entry[fill[J[c]]] = 2 * c + 1
        fill[J[c]] += 1
    return count, entry


@njit(cache=True)
def place_without_overlap(radius, size, dim, candidates, placed):
    """Random sequential addition in the cubic cell of side ``size``: the grains in order take
    the first of their ``candidates`` (rows of uniform points in the unit cell, consumed in
    order) that overlaps no grain placed before (nearest images). Writes the positions into
    ``placed`` and returns how many candidates were used (-1: ran out)."""
    n = radius.shape[0]
    nb = max(1, int(size // (2.0 * radius.max())))
    nz = nb if dim == 3 else 1
    head = np.full(nb * nb * nz, -1, dtype=np.int64)
    nxt = np.full(n, -1, dtype=np.int64)
    used = 0
    for i in range(n):
        ok = False
        while not ok:
            if used >= candidates.shape[0]:
                return -1
            c = candidates[used]
            used += 1
            b = np.empty(3, dtype=np.int64)
            for a in range(3):
                b[a] = min(int(c[a] * nb), nb - 1) if (a < 2 or dim == 3) else 0
            ok = True
            for o0 in range(-1, 2):
                for o1 in range(-1, 2):
                    for o2 in range(-1 if dim == 3 else 0, 2 if dim == 3 else 1):
                        cell = (((b[0] + o0) % nb) * nb + (b[1] + o1) % nb) * nz + (b[2] + o2) % nz
                        k = head[cell]
                        while k >= 0 and ok:
                            d2 = 0.0
                            for a in range(dim):
                                d = (c[a] * size - placed[k, a]) / size
                                d -= np.rint(d)
                                d2 += (d * size) ** 2
                            if d2 < (radius[i] + radius[k]) ** 2:
                                ok = False
                            k = nxt[k]
            if ok:
                for a in range(dim):
                    placed[i, a] = c[a] * size
                cell = (b[0] * nb + b[1]) * nz + b[2]
                nxt[i] = head[cell]
                head[cell] = i
    return used
