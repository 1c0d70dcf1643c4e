r"""The step's gap term made one that some motion of the dofs produces.

The gap term of :math:`q` (:mod:`._assemble`), :math:`g = \gamma/h\,e_N`, asks each contact
for a normal velocity only. Where the contacts of one body lie at slightly different heights
along their normals (three spherical feet pressed in by different depths, ``dist`` differing
by a micrometre), the rotation that meets those normal velocities moves the contact points
tangentially by :math:`\omega \times \Delta z`: :math:`g` is then not in the range of
:math:`J` and :math:`q` has a component in the null space of :math:`W = J M^{-1} J^T`
(the bodies' internal forces; three feet of one rigid body give three such directions).
No stick solution exists: :math:`u = W r + q` keeps that component whatever ``r``, and a
solution of the contact law has to slide at velocities of that size (1e-9 m/s in the sled
example) with its internal forces pushed onto the limit surface. Gauss–Seidel moves ``r``
along the null space by about that size per sweep and stalls (measured: 5,000 sweeps above
1e-8 where the consistent problem takes 10–30).

:func:`consistent_q` keeps the least-squares part of the gap term,
:math:`J x` with :math:`x = \arg\min |J x - g|` (normal equations with a relative shift
:data:`SHIFT` of :math:`J^T J` and one refinement step, sparse LU), and drops the rest:
:math:`q_c = J v_{free} + J x` is in the range of :math:`J`, so the contact problem has the
stick solutions of a consistent system. The dropped part is what no motion can give; the
step applies the solved impulses, and the contacts then slip by that velocity (1e-9 m/s:
1e-12 m per 4 ms step in the sled example).
"""

from __future__ import annotations

import numpy as np

from .._optional import require

njit = require("numba", extra="kernels").njit

__all__ = ["gap_term", "consistent_q", "SHIFT"]

#: The shift of :math:`J^T J`, relative to its largest diagonal entry, in the normal equations
#: of :func:`consistent_q` (one refinement step squares its effect on the kept part).
SHIFT = 1e-10


def gap_term(gap, baumgarte: float, h: float) -> np.ndarray:
    r""":math:`\gamma/h\,e_N` (3 nc,), the gap term of ``q`` (:func:`._assemble.assemble` hands
    its normal parts to :func:`._kernels.contact_blocks`): ``gamma = gap`` where ``gap > 0``,
    else ``baumgarte * gap``."""
    gap = np.asarray(gap, dtype=float)
    g = np.zeros(3 * gap.size)
    g[0::3] = np.where(gap > 0.0, gap, baumgarte * gap) / h
    return g


@njit(cache=True)
def _jacobian_coo(tree, off, Jp, dofadr, dofnum):
    """``(rows, cols, values)`` of J (3 nc x nv) from the blocks of
    :class:`~frictionrules.multicontact.factored.TreeBlocks`."""
    nc = tree.shape[0]
    size = 0
    for a in range(nc):
        for s in range(2):
            if tree[a, s] >= 0:
                size += 3 * dofnum[tree[a, s]]
    rows = np.empty(size, np.int64)
    cols = np.empty(size, np.int64)
    vals = np.empty(size)
    e = 0
    for a in range(nc):
        for s in range(2):
            t = tree[a, s]
            if t < 0:
                continue
            p, c0, n = off[a, s], dofadr[t], dofnum[t]
            for l in range(3):
                for k in range(n):
                    rows[e], cols[e], vals[e] = 3 * a + l, c0 + k, Jp[p + l * n + k]
                    e += 1
    return rows, cols, vals


def consistent_q(blocks, q, g) -> np.ndarray:
    r"""``q`` with the part of its gap term ``g`` that no velocity of the dofs produces
    dropped: :math:`q - (g - J x)`, :math:`x = \arg\min_x |J x - g|` (module docstring).

    Parameters
    ----------
    blocks : TreeBlocks
        The step's operator (its ``J`` blocks).
    q : (3 nc,) array
        :math:`J v_{free} + g`.
    g : (3 nc,) array
        The gap term (:func:`gap_term`).

    Returns
    -------
    (3 nc,) array
        In the range of J (to rounding); ``q`` itself where ``g`` is zero.
    """
    if not np.any(g):
        return q
    import scipy.sparse as sp
    import scipy.sparse.linalg as spla
    b = blocks
    rows, cols, vals = _jacobian_coo(b.tree, b.offset, b.J, b.dofadr, b.dofnum)
    J = sp.csr_matrix((vals, (rows, cols)), shape=(q.size, b.nv))
    A = (J.T @ J).tocsc()
    d = A.diagonal()
    shift = SHIFT * max(float(d.max()), np.finfo(float).tiny)
    lu = spla.splu((A + shift * sp.identity(b.nv, format="csc")).tocsc())
    x = lu.solve(J.T @ g)
    x += lu.solve(J.T @ (g - J @ x))          # one refinement: the shift's bias squared
    return q - (g - J @ x)
