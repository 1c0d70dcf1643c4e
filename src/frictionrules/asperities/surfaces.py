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


#: Facet gradients closer than ``_MERGE * (1 + max|p|)`` are one facet: they differ by
#: round-off (a million times the double-precision round-off of slopes of order one), and
#: keeping them apart would make the limit curve change mechanism between identical facets
#: (spurious corners of 180 degrees).
_MERGE = 1e-9


def _merge_close(p: np.ndarray) -> np.ndarray:
    """Merge gradients (K, 2) that differ by less than ``_MERGE * (1 + |p|)``; the first of
    each cluster of such neighbours is kept."""
    if len(p) < 2:
        return p
    require("scipy", extra="solvers")
    from scipy.spatial import cKDTree

    tol = _MERGE * (1.0 + float(np.abs(p).max()) * np.sqrt(2.0))
    pairs = cKDTree(p).query_pairs(tol, output_type="ndarray")
    if len(pairs) == 0:
        return p
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(len(p),) * 2)
    label = connected_components(graph, directed=False)[1]
    return p[np.sort(np.unique(label, return_index=True)[1])]


def _group_line(p: np.ndarray, bins: int) -> np.ndarray:
    """Gradients on one line: both ends exactly, the two nearest to the foot of the origin on
    either side exactly (the flattest facets: they carry the sliding along the line's
    normal, across which every facet rises alike), the inside binned on either side of the
    foot (a bin across it would average the two sides into a flatter facet than any)."""
    c = p.mean(axis=0)
    e = np.linalg.svd(p - c, full_matrices=False)[2][0]
    s = (p - c) @ e
    i0, i1 = int(np.argmin(s)), int(np.argmax(s))
    if s[i1] - s[i0] <= _MERGE * (1.0 + np.abs(p).max()):
        return p[i0:i0 + 1]
    foot = -c @ e
    below, above = np.flatnonzero(s <= foot), np.flatnonzero(s > foot)
    flat = np.concatenate((below[np.argsort(s[below])[-2:]], above[np.argsort(s[above])[:2]]))
    inner = (s > s[i0]) & (s < s[i1])
    inner[flat] = False
    half = max(1, (bins + 1) // 2)
    sides = [_bin_means(s[m], p[m], half) for m in (inner & (s <= foot), inner & (s > foot))]
    return _merge_close(np.concatenate((p[[i0, i1]], p[flat], *sides)))


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
    return _merge_close(np.concatenate(out))


def from_profile(x, z, mu, local: str = "non-associated", bins: int = 64) -> FacetSet:
    r"""Facet set of a 2-D profile ``z(x)`` whose ridges run along y (like Fig. 4).

    Each segment between consecutive points is a facet with the slope
    :math:`s = \Delta z/\Delta x` and the normal :math:`(-s, 0, 1)/\sqrt{1+s^2}`. For a
    periodic profile pass one period including both end points. The steepest rising and
    falling slopes and the flattest ones are kept exactly; the slopes between them are grouped
    into at most ``bins`` groups (they carry the sliding along the ridges). Slopes that differ
    by round-off (``1e-9 (1 + max|s|)``) are one facet.

    Parameters
    ----------
    x, z : array (M,)
        Abscissae (strictly increasing) and heights, any consistent length unit. A masked
        ``z`` (:class:`numpy.ma.MaskedArray`) excludes the segments with an undefined end.
    mu : float
        Local friction coefficient (> 0).
    local : {"non-associated", "associated"}
    bins : int
        Number of slope groups (>= 1).
    """
    return _facet_set(profile_slopes(x, z), mu, local, bins)


def profile_slopes(x, z) -> np.ndarray:
    """Facet gradients ``(dz/dx, 0)`` (K, 2) of the segments of a profile whose two ends are
    defined (``z`` may be a masked array; the masked points are excluded, never filled)."""
    defined = ~np.ma.getmaskarray(z)
    x = check_finite("x", x)
    z = check_finite("z", np.ma.getdata(z)[defined] if np.ndim(z) == 1 else z)
    if x.ndim != 1 or np.shape(defined) != x.shape or len(x) < 2:
        raise FrictionRulesError(f"x and z must be 1-D of the same length >= 2, got shapes "
                                 f"{x.shape} and {np.shape(defined)}")
    dxs = np.diff(x)
    if np.any(dxs <= 0):
        i = int(np.argmin(dxs))
        raise FrictionRulesError(f"x[{i + 1}] = {x[i + 1]!r} violates x strictly increasing "
                                 f"(x[{i}] = {x[i]!r})")
    zz = np.zeros(x.shape)
    zz[defined] = z
    ok = defined[1:] & defined[:-1]
    if not ok.any():
        raise FrictionRulesError("z has no two consecutive defined points: no facet to use")
    s = np.diff(zz)[ok] / dxs[ok]
    return np.stack((s, np.zeros_like(s)), axis=-1)


def heightmap_gradients(h, dx, dy, defined=None) -> np.ndarray:
    r"""Facet gradients ``(dh/dx, dh/dy)`` of a height map, shape ``(K, 2)``.

    ``h[i, j]`` is the height at ``x = j*dx``, ``y = i*dy`` (rows along y). The surface is the
    piecewise-linear interpolant of the samples; each grid cell is split into two triangles by
    either diagonal, and the four triangles' exact plane gradients are the cell's facets:
    :math:`\partial_x h` from the forward difference along the bottom or the top edge,
    :math:`\partial_y h` along the left or the right edge (all four combinations, ``K = 4
    (ny-1)(nx-1)``). Taking both diagonals keeps the set equivariant under quarter turns of
    the grid, and no facet is invented across a kink (central differences would average the
    two sides of a ridge into a flat facet).

    ``defined`` (bool, shape of ``h``), when given, marks the defined points: a triangle is
    kept only when its three corners are defined (undefined points are excluded, never
    filled).
    """
    gx = np.diff(h, axis=1) / dx              # (ny, nx-1): bottom/top edges of the cells
    gy = np.diff(h, axis=0) / dy              # (ny-1, nx): left/right edges
    if defined is not None:                   # a triangle's corners are its two edges' ends
        x_ok, y_ok = defined[:, :-1] & defined[:, 1:], defined[:-1] & defined[1:]
    parts = []
    for ax_rows in (slice(None, -1), slice(1, None)):            # bottom, top edge
        for ay_cols in (slice(None, -1), slice(1, None)):        # left, right edge
            p = np.stack(np.broadcast_arrays(gx[ax_rows], gy[:, ay_cols]), axis=-1)
            parts.append(p.reshape(-1, 2) if defined is None
                         else p[x_ok[ax_rows] & y_ok[:, ay_cols]])
    return np.concatenate(parts)


def heightmap_defined(h, name: str = "h"):
    """Heights (ny, nx) as a float array and the bool array of defined points.

    A :class:`numpy.ma.MaskedArray` marks its masked points undefined (they are excluded from
    the facets, never filled); any other non-finite value is an error.
    """
    defined = ~np.ma.getmaskarray(h)
    data = np.array(np.ma.getdata(h), dtype=float)
    if data.ndim != 2 or min(data.shape) < 2:
        raise FrictionRulesError(f"{name} must be a 2-D array with at least 2 rows and columns, "
                                 f"got shape {data.shape}")
    check_finite(name, data[defined])
    data[~defined] = 0.0     # never read: every triangle touching these points is dropped
    return data, defined


def from_heightmap(h, dx, dy, mu, local: str = "non-associated", bins: int = 64) -> FacetSet:
    r"""Facet set of a height map ``h[i, j] = h(x = j dx, y = i dy)``.

    The facets of the cells' triangles (:func:`heightmap_gradients`) are the facet
    orientations; the ones on the boundary of their convex hull are kept (vertices exactly,
    those on a hull edge grouped into at most ``bins`` groups), see the module notes. A map
    rotated by an angle gives the same set rotated; a map whose gradients are all collinear
    (parallel ridges) is treated like a profile. No tilt is removed and no smoothing is done
    here: :func:`frictionrules.from_topography` does both at a stated scale.

    Parameters
    ----------
    h : array (ny, nx)
        Heights; ``nx, ny >= 2``. A :class:`numpy.ma.MaskedArray` excludes its masked points:
        only the triangles whose three corners are defined are facets.
    dx, dy : float
        Grid spacings (> 0), same unit as ``h``.
    mu : float
        Local friction coefficient (> 0).
    local : {"non-associated", "associated"}
    bins : int
        Number of groups per hull edge (>= 1).
    """
    h, defined = heightmap_defined(h)
    dx = check_scalar("dx", dx, lo=0.0, lo_open=True)
    dy = check_scalar("dy", dy, lo=0.0, lo_open=True)
    p = heightmap_gradients(h, dx, dy, None if defined.all() else defined)
    if len(p) == 0:
        raise FrictionRulesError("h has no grid cell with three defined corners: no facet to use")
    return _facet_set(p, mu, local, bins)


def _facet_set(p: np.ndarray, mu, local: str, bins) -> FacetSet:
    """The facet set of the facet gradients ``p`` (K, 2), grouped (:func:`group_gradients`)."""
    bins = int(check_scalar("bins", bins, lo=1))
    return FacetSet(_normals(group_gradients(p, bins)), mu, local)


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


def self_affine_surface(n: int = 256, dx: float = 1.0, hurst: float = 0.8,
                        rms_slope: float = 0.1, long_cutoff: float | None = None,
                        short_cutoff: float | None = None, seed: int = 0) -> np.ndarray:
    r"""A periodic, isotropic, self-affine random height map ``(n, n)`` with a given rms slope.

    Random phases and the power spectrum :math:`C(q) \propto q^{-2(1+H)}` (``H = hurst``)
    between the wavenumbers :math:`q_r = 2\pi/\text{long\_cutoff}` (flat below: the roll-off)
    and :math:`q_s = 2\pi/\text{short\_cutoff}` (zero above), as in Persson's self-affine
    model. The amplitude makes the rms slope of the (band-limited, smooth) surface,
    :math:`\sqrt{\langle|\nabla h|^2\rangle} = \sqrt{\sum_q q^2|\hat h_q|^2}/n^2`
    (Parseval), equal to ``rms_slope`` exactly; a sampled map's facet slopes approach it as
    ``dx q_s -> 0`` (the finite differences of a wave of wavenumber q scale its slope by
    :math:`\mathrm{sinc}(q\,dx/2)`).

    Parameters
    ----------
    n : int
        Grid points per side (even, >= 8).
    dx : float
        Pixel size (> 0, any length unit; heights in the same unit).
    hurst : float
        Hurst exponent, ``0 < H < 1``.
    rms_slope : float
        Rms slope of the surface (> 0).
    long_cutoff, short_cutoff : float, optional
        Roll-off and short cut-off wavelengths (defaults ``n dx / 4`` and ``16 dx``).
    seed : int
        Seed of :func:`numpy.random.default_rng`.
    """
    n = int(check_scalar("n", n, lo=8))
    if n % 2:
        raise FrictionRulesError(f"n = {n} violates: n even")
    dx = check_scalar("dx", dx, lo=0.0, lo_open=True)
    hurst = check_scalar("hurst", hurst, lo=0.0, hi=1.0, lo_open=True, hi_open=True)
    rms_slope = check_scalar("rms_slope", rms_slope, lo=0.0, lo_open=True)
    long_cutoff = check_scalar("long_cutoff", n * dx / 4 if long_cutoff is None else long_cutoff,
                               lo=0.0, lo_open=True)
    short_cutoff = check_scalar("short_cutoff", 16 * dx if short_cutoff is None else short_cutoff,
                                lo=2.0 * dx, hi=long_cutoff)
    q1 = 2.0 * np.pi * np.fft.fftfreq(n, dx)
    qx, qy = np.meshgrid(q1, q1)
    q = np.hypot(qx, qy)
    qr, qs = 2.0 * np.pi / long_cutoff, 2.0 * np.pi / short_cutoff
    amp = np.where(q <= qs, np.maximum(q, qr) ** -(1.0 + hurst), 0.0)
    amp[0, 0] = 0.0
    rng = np.random.default_rng(seed)
    h = np.fft.ifft2(amp * np.fft.fft2(rng.standard_normal((n, n)))).real
    hq = np.fft.fft2(h)
    slope = np.sqrt(np.sum(q**2 * np.abs(hq) ** 2)) / n**2
    return h * (rms_slope / slope)
