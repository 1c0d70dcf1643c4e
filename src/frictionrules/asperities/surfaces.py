r"""Facet sets of real surfaces: a periodic profile or a height map (e.g. a machined surface).

The counter-surface is taken as the mated replica of the measured one (as in the paper's
two-plate model, Fig. 4), so every facet orientation present is a potential contact. Only the
set of facet *orientations* enters the rigid-block mechanisms, and of those only few can ever
slide. With the facet gradient :math:`p = (\partial h/\partial x, \partial h/\partial y)` (normal
:math:`n \propto (-p, 1)`), a block sliding horizontally along ``u`` must rise at least
:math:`\max_m p_m\cdot u` (no interpenetration), so:

* only the gradients on the boundary of their convex hull can carry a mechanism (vertices and,
  for the two-facet mechanisms along a hull edge, the gradients on that edge); gradients
  strictly inside never slide;
* facets are *grouped* (:func:`group_gradients`): the hull vertices that carry the support
  function in ``2 * bins`` directions are kept exactly, the gradients on a straight hull edge
  (or, for a profile or a surface of parallel ridges, along the line of gradients) are binned
  into at most ``bins`` groups represented by their mean. This keeps the mechanism search to a
  bounded number of facets for any map size.
"""

from __future__ import annotations

import numpy as np

from .._optional import require
from ..errors import FrictionRulesError, check_finite, check_scalar
from .facets import FacetSet

__all__ = ["from_profile", "from_heightmap"]


def _normals(p: np.ndarray) -> np.ndarray:
    """Unit normals ``(-p, 1)/|.|`` of facets with gradients ``p`` (K, 2)."""
    n = np.concatenate((-p, np.ones((len(p), 1))), axis=-1)
    return n / np.linalg.norm(n, axis=-1, keepdims=True)


def _bin_means(s: np.ndarray, values: np.ndarray, bins: int) -> np.ndarray:
    """Means of ``values`` grouped by ``s`` into ``bins`` equal bins over the range of ``s``."""
    if len(s) == 0:
        return values[:0]
    lo, hi = float(s.min()), float(s.max())
    if hi <= lo:
        idx = np.zeros(len(s), int)
    else:
        idx = np.minimum(((s - lo) / (hi - lo) * bins).astype(int), bins - 1)
    counts = np.bincount(idx, minlength=bins)
    sums = np.stack([np.bincount(idx, weights=values[:, k], minlength=bins)
                     for k in range(values.shape[1])], axis=-1)
    keep = counts > 0
    return sums[keep] / counts[keep, None]


def _group_line(p: np.ndarray, bins: int) -> np.ndarray:
    """Gradients on one line: both ends exactly, the inside binned."""
    c = p.mean(axis=0)
    e = np.linalg.svd(p - c, full_matrices=False)[2][0]
    s = (p - c) @ e
    i0, i1 = int(np.argmin(s)), int(np.argmax(s))
    if s[i1] - s[i0] <= 1e-12 * (1.0 + np.abs(p).max()):
        return p[i0:i0 + 1]
    inner = (s > s[i0]) & (s < s[i1])
    return np.concatenate((p[[i0, i1]], _bin_means(s[inner], p[inner], bins)))


def _support_points(p: np.ndarray, m: int) -> np.ndarray:
    """Indices of the points of ``p`` (few) that attain the support function in ``m``
    equally spaced directions."""
    a = 2.0 * np.pi * np.arange(m) / m
    U = np.stack((np.cos(a), np.sin(a)), axis=-1)
    return np.unique(np.argmax(p @ U.T, axis=0))


def group_gradients(p, bins: int = 64) -> np.ndarray:
    r"""The gradients (K, 2) that represent the facets ``p`` (M, 2) in the mechanism search.

    Of the convex hull of the gradients, the vertices that attain the support function
    :math:`\max_m p_m\cdot u` in ``2 * bins`` equally spaced directions ``u`` are kept (all
    vertices of a polygonal hull with fewer corners; a finely curved hull is approximated
    from inside, with a relative error of order ``(pi / (2 bins))**2 / 2`` in the support
    function); the gradients lying on the edges between kept vertices (a straight hull edge,
    e.g. from ridges) are binned into at most ``bins`` groups per edge. When all gradients are
    collinear (parallel ridges) both ends are kept and the inside is binned, as for a profile.
    """
    require("scipy", extra="solvers")
    from scipy.spatial import ConvexHull, QhullError

    p = np.asarray(p, dtype=float).reshape(-1, 2)
    scale = 1.0 + float(np.abs(p).max())
    tol = 1e-9 * scale
    ev = np.linalg.eigvalsh(np.cov(p.T)) if len(p) > 1 else np.zeros(2)
    if len(p) < 3 or ev[0] <= 1e-12 * max(ev[1], 0.0) + 1e-30 * scale**2:
        return _group_line(p, bins)
    try:
        hull = ConvexHull(p, qhull_options="Qc")    # Qc: also report points on the edges
    except QhullError:
        return _group_line(p, bins)
    verts = p[hull.vertices]
    kept = verts[_support_points(verts, 2 * bins)] if len(verts) > 2 * bins else verts
    kept = kept[np.argsort(np.arctan2(*(kept - kept.mean(axis=0)).T[::-1]))]  # counter-clockwise
    cand = p[np.unique(hull.coplanar[:, 0])] if len(hull.coplanar) else p[:0]
    out = [kept]
    for a, b in zip(kept, np.roll(kept, -1, axis=0)):
        ab = b - a
        L = float(np.hypot(*ab))
        s = (cand - a) @ ab / L
        dist = np.abs((cand - a) @ np.array([-ab[1], ab[0]]) / L)
        on = (dist <= tol) & (s > tol) & (s < L - tol)
        if on.any():
            out.append(_bin_means(s[on], cand[on], bins))
    return np.concatenate(out)


def from_profile(x, z, mu, local: str = "non-associated", bins: int = 64) -> FacetSet:
    r"""Facet set of a 2-D profile ``z(x)`` whose ridges run along y (like Fig. 4).

    Each segment between consecutive points is a facet with the slope
    :math:`s = \Delta z/\Delta x` and the normal :math:`(-s, 0, 1)/\sqrt{1+s^2}`. For a
    periodic profile pass one period including both end points. The steepest rising and
    falling slopes are kept exactly; the slopes between them are grouped into at most ``bins``
    groups (they carry the sliding along the ridges).

    Parameters
    ----------
    x, z : array (M,)
        Abscissae (strictly increasing) and heights, any consistent length unit.
    mu : float
        Local friction coefficient (> 0).
    local : {"non-associated", "associated"}
    bins : int
        Number of slope groups (>= 1).
    """
    x, z = check_finite("x", x), check_finite("z", z)
    if x.ndim != 1 or x.shape != z.shape or len(x) < 2:
        raise FrictionRulesError(f"x and z must be 1-D of the same length >= 2, got shapes "
                                 f"{x.shape} and {z.shape}")
    dxs = np.diff(x)
    if np.any(dxs <= 0):
        i = int(np.argmin(dxs))
        raise FrictionRulesError(f"x[{i + 1}] = {x[i + 1]!r} violates x strictly increasing "
                                 f"(x[{i}] = {x[i]!r})")
    bins = int(check_scalar("bins", bins, lo=1))
    s = np.diff(z) / dxs
    p = _group_line(np.stack((s, np.zeros_like(s)), axis=-1), bins)
    return FacetSet(_normals(p), mu, local)


def heightmap_gradients(h, dx, dy) -> np.ndarray:
    r"""Facet gradients ``(dh/dx, dh/dy)`` of a height map, shape ``(4 (ny-1)(nx-1), 2)``.

    ``h[i, j]`` is the height at ``x = j*dx``, ``y = i*dy`` (rows along y). The surface is the
    piecewise-linear interpolant of the samples; each grid cell is split into two triangles by
    either diagonal, and the four triangles' exact plane gradients are the cell's facets:
    :math:`\partial_x h` from the forward difference along the bottom or the top edge,
    :math:`\partial_y h` along the left or the right edge (all four combinations). Taking both
    diagonals keeps the set equivariant under quarter turns of the grid, and no facet is
    invented across a kink (central differences would average the two sides of a ridge into a
    flat facet).
    """
    gx = np.diff(h, axis=1) / dx              # (ny, nx-1): bottom/top edges of the cells
    gy = np.diff(h, axis=0) / dy              # (ny-1, nx): left/right edges
    parts = [np.stack(np.broadcast_arrays(ax.ravel(), ay.ravel()), axis=-1)
             for ax in (gx[:-1], gx[1:]) for ay in (gy[:, :-1], gy[:, 1:])]
    return np.concatenate(parts)


def from_heightmap(h, dx, dy, mu, local: str = "non-associated", bins: int = 64) -> FacetSet:
    r"""Facet set of a height map ``h[i, j] = h(x = j dx, y = i dy)``.

    The facets of the cells' triangles (:func:`heightmap_gradients`) are the facet
    orientations; the ones on the
    boundary of their convex hull are kept (vertices exactly, those on a hull edge grouped into
    at most ``bins`` groups), see the module notes. A map rotated by an angle gives the same
    set rotated; a map whose gradients are all collinear (parallel ridges) is treated like a
    profile.

    Parameters
    ----------
    h : array (ny, nx)
        Heights; ``nx, ny >= 2``.
    dx, dy : float
        Grid spacings (> 0), same unit as ``h``.
    mu : float
        Local friction coefficient (> 0).
    local : {"non-associated", "associated"}
    bins : int
        Number of groups per hull edge (>= 1).
    """
    h = check_finite("h", h)
    if h.ndim != 2 or min(h.shape) < 2:
        raise FrictionRulesError(f"h must be a 2-D array with at least 2 rows and columns, got "
                                 f"shape {h.shape}")
    dx = check_scalar("dx", dx, lo=0.0, lo_open=True)
    dy = check_scalar("dy", dy, lo=0.0, lo_open=True)
    bins = int(check_scalar("bins", bins, lo=1))
    p = group_gradients(heightmap_gradients(h, dx, dy), bins)
    return FacetSet(_normals(p), mu, local)


def machined_surface(n: int = 512, dx: float = 1.0, period: float = 32.0, rise: float = 0.35,
                     fall: float = 0.2, lay: float = 0.0, roughness: float = 0.4,
                     correlation: float = 3.0, seed: int = 0) -> np.ndarray:
    """A synthetic machined height map ``(n, n)``: asymmetric grooves plus random roughness.

    Grooves of the given ``period`` run along the lay direction ``lay`` (radians from y); across
    the lay the profile rises at the slope ``rise`` and falls at ``fall``. The roughness is white
    noise smoothed by a Gaussian of ``correlation`` grid steps and scaled to the standard
    deviation ``roughness`` (same length unit as ``dx``), reproducible through ``seed``.
    """
    gaussian_filter = require("scipy.ndimage", extra="solvers").gaussian_filter

    y, x = np.mgrid[0:n, 0:n] * dx
    across = x * np.cos(lay) + y * np.sin(lay)
    frac = (across / period) % 1.0
    split = fall / (rise + fall)
    grooves = np.where(frac < split, rise * frac, rise * split - fall * (frac - split)) * period
    noise = gaussian_filter(np.random.default_rng(seed).standard_normal((n, n)), correlation,
                            mode="wrap")
    return grooves + roughness * noise / noise.std()
