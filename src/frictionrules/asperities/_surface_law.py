r"""From a measured topography to a friction law at a stated length scale.

The rigid-block-on-facets model (§2, :class:`frictionrules.FacetSet`) applied to a measured
surface answers with the steepest facets it meets, so it needs a length scale: the map is
smoothed by the ISO 16610-21 Gaussian filter of cut-off wavelength ``scale`` (physical units),
after the mean plane is removed. The result records the scale, the detrending, how many
facets carry the limit load in each direction, and warns when that is a negligible part of
the surface (the answer then belongs to a few pixels: noise, spikes, scan-line steps, not to
the surface). :func:`scale_study` shows how the law changes with the scale.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from ..errors import FrictionRulesError, check_scalar
from . import _topography as topo
from .facets import FacetSet
from .surfaces import _normals, group_gradients

__all__ = ["SurfaceFriction", "from_topography", "ScaleStudy", "scale_study"]

#: mu(theta) above this is classified as locked: the friction angle is then within 0.57 deg
#: of 90 deg, where d mu / mu = mu d phi, so an uncertainty of half a degree in a facet angle
#: changes mu(theta) by more than 90 %: the number carries no information.
LOCKING_MU = 100.0

#: Facets whose climb alone would give mu(theta) within this fraction of the steepest
#: climb's count as carrying the limit load in that direction.
CARRYING_TOLERANCE = 0.05

#: Above this many candidate facets, the carrying ones are counted on a regular subsample.
_COUNT_EXACT = 1 << 17

#: A warning is given where the carrying facets are fewer than this many pixels' worth (the
#: facets of 4 pixels: 16 triangles of a map, 4 segments of a profile): there, removing a
#: few pixels would change mu(theta) by more than ``CARRYING_TOLERANCE``.
WARN_PIXELS = 4.0


@dataclass(frozen=True)
class SurfaceFriction:
    """The friction law of a measured topography at one length scale.

    Attributes
    ----------
    law : FacetSet
        The law of the rigid block on the facets (a law of the protocol, ``Q`` for ``N``).
    scale : float
        Cut-off wavelength of the Gaussian smoothing, in ``unit`` (0: none).
    detrend : str
        ``"plane"``, ``"rows"`` or ``"none"`` (see :func:`from_topography`).
    unit : str or None
        Length unit of the topography.
    pixel_size : tuple of float
        ``(dx, dy)`` of a map, ``(dx,)`` of a profile.
    shape : tuple of int
        Grid ``(ny, nx)`` or ``(n,)``.
    undefined : int
        Number of undefined (masked) points, excluded from the facets.
    facets : int
        Number of facets (triangles of a map, segments of a profile) with all corners defined.
    max_slope, rms_slope : float
        Steepest and rms facet slope :math:`|\\nabla h|` at this scale.
    theta : (M,) array
        Slip directions (radians from x).
    mu : (M,) array
        Directional friction coefficient mu(theta) ((1.15)); ``inf`` where locked.
    locked : (M,) bool
        No finite load slides the block that way, or mu(theta) > ``locking_mu``.
    near_locking : (M,) bool
        The part of ``locked`` classified by the threshold (mu finite but above it).
    carrying : (M,) int
        Number of facets whose climb along theta alone would give mu(theta) within
        ``carrying_tolerance`` of the steepest climb's: the facets the block rides on.
    carrying_fraction : (M,) float
        ``carrying / facets``.
    carrying_tolerance, warn_pixels : float
        The settings that define ``carrying`` and the warning.
    warnings : tuple of str
        Why the result may not be a property of the surface (also issued as
        :class:`UserWarning`).
    """

    law: FacetSet
    scale: float
    detrend: str
    unit: str | None
    pixel_size: tuple
    shape: tuple
    undefined: int
    facets: int
    max_slope: float
    rms_slope: float
    theta: np.ndarray
    mu: np.ndarray
    locked: np.ndarray
    near_locking: np.ndarray
    carrying: np.ndarray
    carrying_fraction: np.ndarray
    carrying_tolerance: float
    warn_pixels: float
    warnings: tuple

    @property
    def carried_by_few(self) -> bool:
        """True when in some free direction the carrying facets are fewer than those of
        ``warn_pixels`` pixels: the result belongs to a few pixels."""
        free = ~self.locked
        return bool(free.any() and self.carrying[free].min() < _few(self.warn_pixels,
                                                                    len(self.shape)))

    @property
    def mu_range(self) -> tuple[float, float]:
        """Smallest and largest mu(theta) over the directions that are not locked
        (``(inf, inf)`` when all are)."""
        free = self.mu[~self.locked]
        return (float(free.min()), float(free.max())) if len(free) else (np.inf, np.inf)

    @property
    def anisotropy(self) -> float:
        """Largest over smallest mu(theta) of the directions that are not locked."""
        lo, hi = self.mu_range
        return hi / lo if np.isfinite(lo) else np.inf

    @property
    def upper_bound(self) -> float:
        r""":math:`\tan(\arctan s_{max} + \arctan\mu)`: mu(theta) when climbing straight up
        the steepest facet, the largest value the facets allow (``inf`` past 90 deg)."""
        phi = np.arctan(self.max_slope) + np.arctan(self.law.mu)
        return float(np.tan(phi)) if phi < np.pi / 2 else np.inf


def _local(law_or_mu) -> tuple[float, str]:
    r"""Local friction coefficient and rule of the facets from a number or a law.

    The count of carrying facets and the steepest-facet bound use one friction angle
    :math:`\varrho = \arctan\mu` in every direction: a number ``mu`` (the rule (1.5)), or a
    law whose cone (capability ``"cone"``) is circular with the rule (1.5) or (1.6) —
    :class:`frictionrules.Coulomb`, a user law written for it.
    """
    if getattr(law_or_mu, "capabilities", None) is not None:
        cone = law_or_mu.cone() if "cone" in law_or_mu.capabilities else None
        if (cone is None or abs(cone.mu_x - cone.mu_y) > 1e-12 * cone.mu_x
                or cone.dilatancy not in (0.0, 1.0)):
            raise FrictionRulesError(
                f"law_or_mu = {type(law_or_mu).__name__}(...) violates: the facets of a "
                "measured surface take an isotropic Coulomb cone (capability 'cone' with "
                "mu_x = mu_y and the rule (1.5) or (1.6)) or a number mu")
        return (check_scalar("mu", cone.mu_x, lo=0.0, lo_open=True),
                "associated" if cone.dilatancy == 1.0 else "non-associated")
    if isinstance(law_or_mu, bool) or not isinstance(law_or_mu, (int, float, np.floating,
                                                                 np.integer)):
        raise FrictionRulesError(f"law_or_mu = {law_or_mu!r} violates: a number mu > 0 or a "
                                 "law with an isotropic Coulomb cone")
    return check_scalar("mu", law_or_mu, lo=0.0, lo_open=True), "non-associated"


def _scale(grid: topo.Grid, scale) -> float:
    if scale is None:
        return topo.DEFAULT_SCALE_PIXELS * max(grid.pixel_size)
    return check_scalar("scale", scale, lo=0.0)


def _carrying(p: np.ndarray, theta: np.ndarray, mu: float, tolerance: float,
              support: np.ndarray) -> np.ndarray:
    r"""Per direction, the number of facets whose climb alone would give mu(theta) within
    ``tolerance`` of the steepest climb's: :math:`\tan(\gamma_j + \varrho) \ge (1 - tol)
    \tan(\gamma_{max} + \varrho)`, :math:`\gamma_j = \arctan(p_j\cdot u)`,
    :math:`\varrho = \arctan\mu` (in a locked direction: the facets that lock,
    :math:`\gamma_j \ge \pi/2 - \varrho`). ``support`` is max p.u (from the hull).

    Facets with :math:`|p|` below the smallest threshold never count; when more than
    ``_COUNT_EXACT`` remain they are counted on every k-th of them and the count scaled by
    k (a statistical estimate, relative error about ``1/sqrt(count/k)``).
    """
    rho = np.arctan(mu)
    top = np.arctan(support) + rho
    gamma = np.where(top < np.pi / 2,
                     np.arctan((1.0 - tolerance) * np.tan(np.minimum(top, np.pi / 2 - 1e-15)))
                     - rho, np.pi / 2 - rho)
    thr = np.tan(np.clip(gamma, -np.pi / 2 + 1e-12, np.pi / 2 - 1e-12))
    tmin = float(thr.min())
    cand = p if tmin <= 0.0 else p[np.hypot(*p.T) >= tmin]     # p.u <= |p|: the rest never
    k = max(1, -(-len(cand) // _COUNT_EXACT))
    cand = cand[::k]
    u = np.stack((np.cos(theta), np.sin(theta)))            # (2, M)
    count = np.zeros(len(theta), dtype=np.int64)
    step = max(1, (1 << 23) // max(len(cand), 1))
    for i in range(0, len(theta), step):
        rise = cand @ u[:, i:i + step]                     # (Kc, m)
        count[i:i + step] = np.count_nonzero(rise >= thr[i:i + step], axis=0)
    return np.minimum(count * k, len(p))


def from_topography(obj, law_or_mu, *, scale=None, detrend: str = "plane", n: int = 360,
                    bins: int = 64, locking_mu: float = LOCKING_MU,
                    carrying_tolerance: float = CARRYING_TOLERANCE,
                    warn_pixels: float = WARN_PIXELS) -> SurfaceFriction:
    r"""The friction law of a measured topography at the length scale ``scale``.

    1. Heights ``obj.heights()`` (SurfaceTopography's ``[ix, iy]``, turned to ``h[iy, ix]``)
       at the pixel sizes ``obj.pixel_size``; undefined points (masked) are **excluded**: a
       facet is used only when all its corners are defined, and the smoothing is normalized
       over the defined points. Nothing is filled.
    2. ``detrend``: ``"plane"`` (default) removes the least-squares mean plane (a sample's
       tilt is not friction anisotropy), ``"rows"`` the mean line of each scan line along x
       (AFM scan-line offsets), ``"none"`` nothing.
    3. Smoothing by the ISO 16610-21 Gaussian filter with the cut-off wavelength ``scale``
       (standard deviation ``0.1874 scale``): the block is taken to ride on the surface as
       seen at that scale.
    4. The facets (triangles of the piecewise-linear map, segments of a profile) become a
       :class:`FacetSet` with the local law; mu(theta) ((1.15)) at ``n`` slip directions.

    Parameters
    ----------
    obj : topography
        Any object with ``heights()`` and ``pixel_size`` (SurfaceTopography's interface; see
        :func:`frictionrules.read_surface`), 2-D map or 1-D profile (ridges along y).
    law_or_mu : float or FrictionLaw
        Local law on the facets: ``mu`` (Coulomb with the rule (1.5)) or a law with an
        isotropic Coulomb cone (:class:`frictionrules.Coulomb`, ``dilatant=True``: the rule
        (1.6); a user law written for it).
    scale : float, optional
        Cut-off wavelength in the topography's length unit (``>= 0``; 0: the raw map).
        Default: five times the (coarser) pixel size.
    detrend : {"plane", "rows", "none"}
    n : int
        Number of slip directions (``>= 4``).
    bins : int
        Facet groups per hull edge (:func:`frictionrules.from_heightmap`).
    locking_mu : float
        mu(theta) above this is classified as locked (default 100: a friction angle within
        0.57 deg of 90 deg, where half a degree of facet angle changes mu by over 90 %).
    carrying_tolerance : float
        Facets whose climb alone would give mu(theta) within this fraction (default 5 %) of
        the steepest climb's count as carrying (exact up to 131072 candidate facets, else
        estimated on a regular subsample).
    warn_pixels : float
        Warn where the carrying facets are fewer than those of this many pixels (default 4:
        16 triangles of a map, 4 segments of a profile): there removing a few pixels would
        change mu(theta) by more than ``carrying_tolerance``, so the result belongs to them
        (noise, a spike, a step), not to the surface.

    Returns
    -------
    SurfaceFriction
    """
    grid = topo.as_grid(obj)
    mu, local = _local(law_or_mu)
    lam = _scale(grid, scale)
    n = int(check_scalar("n", n, lo=4))
    locking_mu = check_scalar("locking_mu", locking_mu, lo=0.0, lo_open=True)
    carrying_tolerance = check_scalar("carrying_tolerance", carrying_tolerance, lo=0.0, hi=1.0,
                                      hi_open=True)
    warn_pixels = check_scalar("warn_pixels", warn_pixels, lo=0.0)
    bins = int(check_scalar("bins", bins, lo=1))
    h = topo.smooth(topo.detrend(grid, detrend), grid.defined, grid.pixel_size, lam,
                    grid.periodic)
    p = topo.facet_gradients(h, grid.defined, grid.pixel_size)
    if len(p) == 0:
        raise FrictionRulesError("the topography has no facet with all corners defined")
    groups = group_gradients(p, bins)
    law = _facet_set(groups, mu, local)
    theta = np.linspace(-np.pi, np.pi, n, endpoint=False)
    inv = law.inverse_relation(theta, 1.0)
    with np.errstate(invalid="ignore"):
        mu_theta = np.where(inv.locked, np.inf, np.hypot(*np.moveaxis(inv.force, -1, 0)))
    near = ~inv.locked & (mu_theta > locking_mu)
    locked = inv.locked | near
    mu_theta = np.where(locked, np.inf, mu_theta)
    support = np.max(np.stack((np.cos(theta), np.sin(theta)), -1) @ groups.T, axis=-1)
    carrying = _carrying(p, theta, mu, carrying_tolerance, support)
    fraction = carrying / len(p)
    slopes = np.hypot(*p.T)
    notes = _warnings(theta, locked, near, carrying, len(p), _few(warn_pixels, h.ndim),
                      carrying_tolerance, locking_mu)
    for note in notes:
        warnings.warn(note, UserWarning, stacklevel=2)
    return SurfaceFriction(
        law=law, scale=lam, detrend=detrend, unit=grid.unit, pixel_size=grid.pixel_size,
        shape=grid.heights.shape, undefined=int((~grid.defined).sum()), facets=len(p),
        max_slope=float(slopes.max()), rms_slope=float(np.sqrt(np.mean(slopes**2))),
        theta=theta, mu=mu_theta, locked=locked, near_locking=near, carrying=carrying,
        carrying_fraction=fraction, carrying_tolerance=carrying_tolerance,
        warn_pixels=warn_pixels,
        warnings=tuple(notes))


def _facet_set(gradients: np.ndarray, mu: float, local: str) -> FacetSet:
    """The seam where the local law enters the facet set (its normals from the gradients)."""
    return FacetSet(_normals(gradients), mu, local)


def _few(pixels: float, dim: int) -> float:
    """Facets of ``pixels`` pixels: four triangles per pixel of a map, a segment of a profile."""
    return pixels * (4.0 if dim == 2 else 1.0)


def _warnings(theta, locked, near, carrying, total, few, tolerance, locking_mu) -> list[str]:
    notes = []
    free = ~locked
    if free.any() and carrying[free].min() < few:
        i = np.flatnonzero(free)[np.argmin(carrying[free])]
        count = int(np.count_nonzero(free & (carrying < few)))
        notes.append(
            f"in {count} of {len(theta)} directions mu(theta) is carried by fewer than "
            f"{few:g} facets (at theta = {np.rad2deg(theta[i]):.1f} deg by {int(carrying[i])} "
            f"of {total} within {100 * tolerance:.2g} % of the steepest climb): the result "
            "belongs to a few pixels (noise, spikes, steps), not to the surface; look at "
            "scale_study and choose a larger scale")
    if locked.any():
        notes.append(f"{int(locked.sum())} of {len(theta)} directions locked "
                     f"({int(near.sum())} of them with mu(theta) > {locking_mu:g})")
    return notes


@dataclass(frozen=True)
class ScaleStudy:
    """mu(theta) of one topography at several length scales (:func:`scale_study`).

    Attributes
    ----------
    scales : (S,) cut-off wavelengths, in ``unit``.
    unit : str or None
    theta : (M,) slip directions.
    mu : (S, M) mu(theta) (``inf`` where locked).
    locked : (S, M) bool.
    max_slope, rms_slope : (S,) facet slopes at each scale.
    min_carrying : (S,) the fewest carrying facets over the free directions.
    min_carrying_fraction : (S,) the same as a fraction of all facets.
    upper_bound : (S,) :math:`\\tan(\\arctan s_{max} + \\arctan\\mu)`.
    mu_local : float, the local friction coefficient.
    warned : (S,) bool, a warning was given at that scale.
    """

    scales: np.ndarray
    unit: str | None
    theta: np.ndarray
    mu: np.ndarray
    locked: np.ndarray
    max_slope: np.ndarray
    rms_slope: np.ndarray
    min_carrying: np.ndarray
    min_carrying_fraction: np.ndarray
    upper_bound: np.ndarray
    mu_local: float
    warned: np.ndarray

    def plot(self, ax=None):
        """mu(theta) against the scale: the range over theta (band), the median, the bound
        from the steepest facet (dashed) and the local mu (dotted); hollow markers where a
        warning was given. Returns the Axes."""
        import matplotlib.pyplot as plt
        if ax is None:
            ax = plt.figure(figsize=(6.0, 4.0)).add_subplot(111)
        free = np.where(self.locked, np.nan, self.mu)
        lo, hi = np.nanmin(free, axis=1), np.nanmax(free, axis=1)
        med = np.nanmedian(free, axis=1)
        s = self.scales
        ax.fill_between(s, lo, hi, color="0.85", label=r"range of $\mu(\theta)$")
        ax.plot(s, med, "k-", lw=1.2, label=r"median of $\mu(\theta)$")
        ok = ~self.warned
        ax.plot(s[ok], med[ok], "ko", ms=4, label="carried by the surface")
        ax.plot(s[~ok], med[~ok], "o", mfc="white", mec="k", ms=5,
                label="carried by a few pixels (warning)")
        ax.plot(s, self.upper_bound, "k--", lw=0.8,
                label=r"$\tan(\arctan s_{max} + \arctan\mu)$")
        ax.axhline(self.mu_local, color="k", ls=":", lw=0.8, label=fr"local $\mu$ = {self.mu_local:g}")
        ax.set_xscale("log")
        top = np.nanmax(hi) if np.isfinite(np.nanmax(hi)) else self.mu_local
        ax.set_ylim(0.0, 1.15 * max(top, self.mu_local))
        ax.set_xlabel(f"smoothing cut-off wavelength $\\lambda_s$ [{self.unit or 'length unit'}]")
        ax.set_ylabel(r"$\mu(\theta)$")
        ax.legend(fontsize=7, loc="upper right", framealpha=0.9)
        return ax


def scale_study(obj, law_or_mu, scales=None, *, detrend: str = "plane", n: int = 180,
                **options) -> ScaleStudy:
    """mu(theta) of a topography against the smoothing length: does the law converge?

    Parameters
    ----------
    obj, law_or_mu, detrend, n
        As :func:`from_topography` (``options`` too; warnings are recorded, not issued).
    scales : array, optional
        Cut-off wavelengths (``> 0``, topography units). Default: 8 values from twice the
        (coarser) pixel size to an eighth of the smaller side of the map, spaced
        geometrically.

    Returns
    -------
    ScaleStudy
    """
    grid = topo.as_grid(obj)
    if scales is None:
        px = max(grid.pixel_size)
        side = min(np.array(grid.heights.shape[::-1]) * np.array(grid.pixel_size))
        scales = np.geomspace(2.0 * px, max(side / 8.0, 4.0 * px), 8)
    scales = np.atleast_1d(np.asarray(scales, dtype=float))
    if scales.ndim != 1 or len(scales) == 0 or not np.all(np.isfinite(scales)) \
            or np.any(scales <= 0):
        raise FrictionRulesError(f"scales = {scales.tolist()!r} violates: a nonempty list of "
                                 "finite lengths > 0")
    results = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        for lam in np.sort(scales):
            results.append(from_topography(obj, law_or_mu, scale=lam, detrend=detrend, n=n,
                                           **options))
    return ScaleStudy(
        scales=np.sort(scales), unit=grid.unit, theta=results[0].theta,
        mu=np.stack([r.mu for r in results]), locked=np.stack([r.locked for r in results]),
        max_slope=np.array([r.max_slope for r in results]),
        rms_slope=np.array([r.rms_slope for r in results]),
        min_carrying=np.array([r.carrying[~r.locked].min() if (~r.locked).any() else 0
                               for r in results]),
        min_carrying_fraction=np.array([
            r.carrying_fraction[~r.locked].min() if (~r.locked).any() else 0.0
            for r in results]),
        upper_bound=np.array([r.upper_bound for r in results]), mu_local=results[0].law.mu,
        warned=np.array([r.carried_by_few for r in results]))
