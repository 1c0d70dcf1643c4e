r"""Facet geometry shared by every local law: unit vectors, facet frames, the facets that can slide.

A facet's frame (``docs/conventions.md``): :math:`t_1` is the unit projection of the global x
axis onto the facet plane (of the global y axis where the facet is normal to x),
:math:`t_2 = n\times t_1`, ``n`` the facet's unit normal pointing into the block; a local law's
forces :math:`(T_1, T_2)` and angles are measured in :math:`(t_1, t_2)`.
"""

from __future__ import annotations

import numpy as np

from .._optional import require

#: Tolerance on dot products of unit vectors (admissibility, ties, degenerate directions).
TOL = 1e-9


def unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``a x b`` over the last axis of 3-vectors (``np.cross``'s arithmetic, less overhead)."""
    a0, a1, a2 = a[..., 0], a[..., 1], a[..., 2]
    b0, b1, b2 = b[..., 0], b[..., 1], b[..., 2]
    return np.stack((a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0), axis=-1)


def facet_frames(n: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Tangent axes ``(t1, t2)``, each ``(K, 3)``, of facets with unit normals ``n`` (K, 3)."""
    x = np.array([1.0, 0.0, 0.0])
    t1 = x - n[:, :1] * n
    along_x = np.linalg.norm(t1, axis=-1) <= 1e-12
    if along_x.any():
        t1[along_x] = np.array([0.0, 1.0, 0.0]) - n[along_x, 1:2] * n[along_x]
    t1 = unit(t1)
    return t1, cross(n, t1)


def boundary_facets(n: np.ndarray) -> np.ndarray:
    r"""Indices of the facets that can take part in a mechanism.

    A facet whose gradient :math:`p = -n_h/n_z` lies strictly inside the convex hull of the
    gradients has a normal inside the cone of the others: it separates in every admissible
    motion (:math:`V\cdot n = \sum\lambda_i V\cdot n_i` with :math:`\sum\lambda_i \ge 1`, so
    it clears every bound of the form :math:`V\cdot n_i \ge \phi_i(V) \ge 0` that the others
    meet) and never slides. Kept: hull vertices and gradients on hull edges (all of them
    when the gradients are collinear).
    """
    K = len(n)
    p = -n[:, :2] / n[:, 2:]
    if K <= 3:
        return np.arange(K)
    ev = np.linalg.eigvalsh(np.cov(p.T))
    if ev[0] <= 1e-12 * max(ev[1], 0.0) + 1e-30:
        return np.arange(K)
    if K == 4:
        return _four(p)
    require("scipy", extra="solvers")
    from scipy.spatial import ConvexHull, QhullError
    try:
        hull = ConvexHull(p, qhull_options="Qc")
    except QhullError:
        return np.arange(K)
    dist = np.max(p @ hull.equations[:, :2].T + hull.equations[:, 2], axis=-1)
    return np.flatnonzero(dist >= -1e-9 * (1.0 + np.abs(p).max()))


def _four(p: np.ndarray) -> np.ndarray:
    """Four gradients: drop the one strictly inside the triangle of the other three."""
    tol = 1e-9 * (1.0 + np.abs(p).max())
    keep = np.ones(4, dtype=bool)
    for i in range(4):
        a, b, c = p[[j for j in range(4) if j != i]]
        area = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
        if abs(area) <= tol * (1.0 + np.abs(p).max()):
            continue
        s = np.sign(area)
        edges = [(a, b), (b, c), (c, a)]
        dist = [s * ((v[0] - u[0]) * (p[i, 1] - u[1]) - (v[1] - u[1]) * (p[i, 0] - u[0]))
                / np.hypot(*(v - u)) for u, v in edges]
        keep[i] = min(dist) <= tol
    return np.flatnonzero(keep)
