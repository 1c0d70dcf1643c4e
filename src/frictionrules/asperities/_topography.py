r"""Measured topographies in: instrument files, the grid, undefined points, detrending and
smoothing at a stated length scale.

A topography is any object with SurfaceTopography's interface: ``heights()`` (indexed
``[ix, iy]``, a :class:`numpy.ma.MaskedArray` where data are undefined), ``pixel_size``
(``(dx, dy)`` or ``(dx,)``), optionally ``unit``, ``is_periodic`` and ``has_undefined_data``.
Here heights are turned to ``h[iy, ix]`` (rows along y), the convention of
:func:`frictionrules.from_heightmap`.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._optional import require
from ..errors import FrictionRulesError, check_finite, check_scalar
from .surfaces import heightmap_gradients, profile_slopes

__all__ = ["read_surface"]

#: The detrending modes.
DETRENDS = ("plane", "rows", "none")

#: ISO 16610-21 Gaussian filter: weight :math:`\exp(-\pi (x/(\alpha\lambda_s))^2)/(\alpha
#: \lambda_s)`, :math:`\alpha = \sqrt{\ln 2/\pi}`, transmission 50 % at the wavelength
#: :math:`\lambda_s`; its standard deviation is ``ISO_SIGMA * lambda_s``.
ISO_ALPHA = float(np.sqrt(np.log(2.0) / np.pi))
ISO_SIGMA = ISO_ALPHA / float(np.sqrt(2.0 * np.pi))

#: Default scale: the short-wavelength cut-off five times the (coarser) pixel size, the ratio
#: of cut-off to sampling distance of the standard profile filters (ISO 3274).
DEFAULT_SCALE_PIXELS = 5.0

def read_surface(path, *, physical_sizes=None, unit=None):
    """Read an instrument file (AFM, interferometer, X3P, stylus profile ...) with
    SurfaceTopography.

    Every format that :func:`SurfaceTopography.open_topography` knows is read; the result is
    its topography object (heights indexed ``[ix, iy]`` in SurfaceTopography's convention,
    physical units from the file), ready for :func:`frictionrules.from_topography` and
    :func:`frictionrules.scale_study`.

    Parameters
    ----------
    path : str or path-like
    physical_sizes : tuple of float, optional
        Size of the scan, for files that do not store it.
    unit : str, optional
        Length unit, for files that do not store it.

    Raises
    ------
    FrictionRulesError
        When SurfaceTopography is not installed (the message names the extra
        ``frictionrules[surfaces]``) or the file cannot be read as a topography.
    """
    SurfaceTopography = require("SurfaceTopography", extra="surfaces",
                                purpose="reading instrument files")
    path = Path(path)
    if not path.is_file():
        raise FrictionRulesError(f"{str(path)!r}: no such file")
    options = {k: v for k, v in (("physical_sizes", physical_sizes), ("unit", unit))
               if v is not None}
    try:
        return SurfaceTopography.open_topography(str(path)).topography(**options)
    except Exception as exc:     # any reader failure is a bad file, not a bug of ours
        reason = (str(exc).strip().splitlines() or [""])[0][:200]
        raise FrictionRulesError(f"{str(path)!r}: not a readable topography "
                                 f"({type(exc).__name__}: {reason})") from exc


@dataclass(frozen=True)
class Grid:
    """Heights of a topography on its grid, with the defined points.

    Attributes
    ----------
    heights : (ny, nx) or (n,) float array, ``h[iy, ix]``; undefined entries are 0 and never
        read (every facet touching them is dropped).
    defined : bool array of the same shape.
    pixel_size : ``(dx, dy)`` or ``(dx,)``.
    unit : the length unit (heights and lateral sizes), or None.
    periodic : bool.
    """

    heights: np.ndarray
    defined: np.ndarray
    pixel_size: tuple
    unit: str | None
    periodic: bool

    @property
    def dim(self) -> int:
        return self.heights.ndim


def as_grid(obj) -> Grid:
    """The :class:`Grid` of a topography object (SurfaceTopography's interface)."""
    missing = [a for a in ("heights", "pixel_size") if not hasattr(obj, a)]
    if missing:
        raise FrictionRulesError(
            f"topography = {type(obj).__name__} object violates: needs heights() and "
            f"pixel_size (SurfaceTopography's interface; missing {missing}); for an array use "
            "from_heightmap or from_profile")
    raw = obj.heights() if callable(obj.heights) else obj.heights
    mask = np.ma.getmaskarray(raw)
    data = np.array(np.ma.getdata(raw), dtype=float)
    if data.ndim not in (1, 2):
        raise FrictionRulesError(f"topography heights must be 1-D or 2-D, got shape {data.shape}")
    if getattr(obj, "has_undefined_data", False):
        mask = mask | np.isnan(data)        # SurfaceTopography's undefined points may be NaN
    defined = ~mask
    check_finite("topography heights (defined points)", data[defined])
    data[mask] = 0.0
    px = np.atleast_1d(np.asarray(obj.pixel_size, dtype=float))
    if px.shape != (data.ndim,):
        raise FrictionRulesError(f"topography pixel_size = {px.tolist()!r} violates: one size "
                                 f"per axis of the heights (shape {data.shape})")
    for name, v in zip(("dx", "dy"), px):
        check_scalar(f"topography pixel size {name}", v, lo=0.0, lo_open=True)
    if data.ndim == 2:     # SurfaceTopography indexes [ix, iy]; here rows run along y
        data, defined = data.T.copy(), defined.T.copy()
    if min(data.shape) < 2:
        raise FrictionRulesError(f"topography heights of shape {data.shape} violate: at least 2 "
                                 "points per axis")
    if defined.sum() < 3:
        raise FrictionRulesError(f"topography has {int(defined.sum())} defined points: too few")
    unit = getattr(obj, "unit", None)
    return Grid(heights=data, defined=defined, pixel_size=tuple(float(v) for v in px),
                unit=None if unit is None else str(unit),
                periodic=bool(getattr(obj, "is_periodic", False)))


def detrend(grid: Grid, mode: str) -> np.ndarray:
    """Heights with the trend removed, fitted on the defined points (least squares).

    ``"plane"``: the mean plane :math:`a + b x + c y` (the mean line of a profile);
    ``"rows"``: each row (a scan line along x) its own mean line, for maps whose scan lines
    are offset from each other (AFM); ``"none"``: unchanged. A periodic topography has no
    tilt (its mean gradient is zero, and removing a plane would break the periodicity): only
    the mean height (of each row for ``"rows"``) is removed.
    """
    if mode not in DETRENDS:
        raise FrictionRulesError(f"detrend = {mode!r} violates detrend in {DETRENDS}")
    h, d = grid.heights, grid.defined
    if mode == "none":
        return h.copy()
    x = np.arange(h.shape[-1]) * grid.pixel_size[0]
    if grid.periodic:
        if mode == "plane":
            return np.where(d, h - h[d].mean(), 0.0)
        rows, drows = np.atleast_2d(h), np.atleast_2d(d)
        means = np.array([z[ok].mean() if ok.any() else 0.0 for z, ok in zip(rows, drows)])
        return np.where(d, (rows - means[:, None]).reshape(h.shape), 0.0)
    if mode == "rows" or h.ndim == 1:
        rows = np.atleast_2d(h)
        drows = np.atleast_2d(d)
        out = np.empty_like(rows)
        for i, (z, ok) in enumerate(zip(rows, drows)):
            if ok.sum() >= 2:
                c = np.polyfit(x[ok], z[ok], 1)
                out[i] = z - np.polyval(c, x)
            else:
                out[i] = z - (z[ok].mean() if ok.any() else 0.0)
        return np.where(d, out.reshape(h.shape), 0.0)
    yy, xx = np.nonzero(d)
    A = np.stack((np.ones(len(xx)), x[xx], yy * grid.pixel_size[1]), axis=-1)
    c = np.linalg.lstsq(A, h[d], rcond=None)[0]
    iy, ix = np.indices(h.shape)
    out = h - (c[0] + c[1] * ix * grid.pixel_size[0] + c[2] * iy * grid.pixel_size[1])
    return np.where(d, out, 0.0)


def smooth(h: np.ndarray, defined: np.ndarray, pixel_size, scale: float,
           periodic: bool) -> np.ndarray:
    r"""The heights smoothed by the ISO 16610-21 Gaussian filter of cut-off ``scale``.

    Spectral: the transfer function :math:`\exp(-\pi(\alpha\lambda_s/\lambda)^2)` per axis
    (:math:`\alpha = \sqrt{\ln 2/\pi}`, 50 % at the wavelength :math:`\lambda_s` = ``scale``,
    standard deviation ``0.1874 scale``), exact for the band-limited interpolant of the
    samples. A non-periodic map is extended by reflection (no jump at its edges). With
    undefined points the filter is normalized by the filtered indicator of the defined ones
    (normalized convolution): only defined points enter, and the undefined ones stay
    undefined.
    """
    if scale == 0.0:
        return h
    sigma = ISO_SIGMA * scale
    full = bool(defined.all())
    num = np.where(defined, h, 0.0)
    den = defined.astype(float)
    for axis, px in zip(range(h.ndim - 1, -1, -1), pixel_size):   # x is the last axis
        num = _gauss_axis(num, axis, sigma / px, periodic)
        if not full:
            den = _gauss_axis(den, axis, sigma / px, periodic)
    if full:
        return num
    return np.where(defined, num / np.where(defined, den, 1.0), 0.0)


def _gauss_axis(a: np.ndarray, axis: int, sigma_px: float, periodic: bool) -> np.ndarray:
    n = a.shape[axis]
    ext = a if periodic else np.concatenate((a, np.flip(a, axis=axis)), axis=axis)
    m = ext.shape[axis]
    f = np.fft.rfftfreq(m)                                 # cycles per pixel
    shape = [1] * a.ndim
    shape[axis] = len(f)
    gain = np.exp(-2.0 * (np.pi * sigma_px * f) ** 2).reshape(shape)
    out = np.fft.irfft(np.fft.rfft(ext, axis=axis) * gain, n=m, axis=axis)
    return np.take(out, np.arange(n), axis=axis)


def facet_gradients(h: np.ndarray, defined: np.ndarray, pixel_size) -> np.ndarray:
    """Facet gradients (K, 2): triangles of a map, segments ``(dz/dx, 0)`` of a profile, each
    with all its corners defined."""
    if h.ndim == 1:
        x = np.arange(len(h)) * pixel_size[0]
        return profile_slopes(x, np.ma.MaskedArray(h, mask=~defined))
    return heightmap_gradients(h, pixel_size[0], pixel_size[1],
                               None if defined.all() else defined)
