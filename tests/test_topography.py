"""Measured topographies to friction laws: reading, undefined points, detrending, the scale,
locking, the carrying facets, and the closed forms a tribologist checks.

The topographies here are small objects with SurfaceTopography's interface (``heights()``
indexed ``[ix, iy]``, ``pixel_size``), so that these tests do not need SurfaceTopography;
``test_topography_files.py`` reads the instrument files with it.
"""

import warnings

import numpy as np
import pytest

from frictionrules import (Coulomb, EllipticOrthotropic, FrictionRulesError, Huber, ScaleStudy,
                           SurfaceFriction, UserLaw, from_heightmap, from_profile,
                           from_topography, scale_study)
from frictionrules.asperities.surfaces import heightmap_gradients, self_affine_surface

MU = 0.3


class Topo:
    """A topography with SurfaceTopography's interface, from a map ``h[iy, ix]`` (rows along
    y, as frictionrules indexes) or a profile."""

    def __init__(self, h, pixel_size=(1.0, 1.0), periodic=False, undefined=False, unit="um"):
        h = np.ma.asarray(h) if np.ma.isMaskedArray(h) else np.asarray(h, dtype=float)
        self._h = h.T if h.ndim == 2 else h          # SurfaceTopography indexes [ix, iy]
        self.pixel_size = pixel_size if h.ndim == 2 else pixel_size[:1]
        self.is_periodic = periodic
        self.has_undefined_data = undefined
        self.unit = unit
        self.dim = h.ndim

    def heights(self):
        return self._h


def quiet(*args, **kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        return from_topography(*args, **kwargs)


# ---- closed forms ---------------------------------------------------------------------------
def test_tilted_plane_is_isotropic_after_detrending():
    """A sample's tilt is not friction anisotropy: a tilted plane gives mu(theta) = mu in every
    direction after the default detrending (to 1e-8); without detrending it is a wedge, and
    the tilt reads as an anisotropy ratio of about 1.6."""
    y, x = np.mgrid[0:40, 0:60] * 0.5
    plane = 0.12 * x - 0.07 * y + 3.0
    r = quiet(Topo(plane, (0.5, 0.5)), MU)
    np.testing.assert_allclose(r.mu, MU, rtol=1e-8)
    assert r.anisotropy == pytest.approx(1.0, abs=1e-8) and r.detrend == "plane"
    raw = quiet(Topo(plane, (0.5, 0.5)), MU, detrend="none")
    assert raw.anisotropy > 1.5


def sine(n_per_period, periods=4, amplitude=0.3, wavelength=2.0, rows=6):
    """z = A sin(2 pi x / lambda) sampled with n points per period; ridges along y."""
    h = wavelength / n_per_period
    x = np.arange(n_per_period * periods) * h
    z = amplitude * np.sin(2 * np.pi * x / wavelength)
    return x, z, h, np.tile(z, (rows, 1))


@pytest.mark.parametrize("scale", [0.0, 0.5])
def test_corrugation_across_and_along_the_ridges(scale):
    r"""z = A sin(2 pi x/lambda): across the ridges the block climbs the steepest facet,
    mu(0) = tan(atan s + atan mu) with s the steepest facet slope of the sampled (and, at a
    scale, smoothed) surface, to 1e-8; along the ridges it slides on the flattest facets of
    either sign, +-s0, mu(pi/2) = mu sqrt(1 + s0^2) (docs/surfaces.md). The ISO Gaussian
    filter scales a whole-period sinusoid by exp(-pi (alpha lambda_s / lambda)^2)."""
    x, z, h, m = sine(32)
    gain = np.exp(-np.log(2.0) * (scale / 2.0) ** 2)    # pi alpha^2 = ln 2
    s = np.abs(np.diff(gain * z)) / h
    r = quiet(Topo(m, (h, h), periodic=True), MU, scale=scale, detrend="none", n=8)
    assert r.theta[4] == 0.0 and r.theta[6] == pytest.approx(np.pi / 2)
    assert r.mu[4] == pytest.approx(np.tan(np.arctan(s.max()) + np.arctan(MU)), rel=1e-8)
    assert r.mu[6] == pytest.approx(MU * np.sqrt(1 + s.min() ** 2), rel=1e-8)
    assert r.max_slope == pytest.approx(s.max(), rel=1e-12)


def test_corrugation_steepest_facet_converges_to_2_pi_a_over_lambda():
    """s = (A/h) sin(2 pi h/lambda) -> 2 pi A/lambda at second order in the sampling h."""
    err = []
    for n in (8, 16, 32, 64):
        x, z, h, _ = sine(n)
        err.append(2 * np.pi * 0.3 / 2.0 - np.abs(np.diff(z)).max() / h)
    order = np.polyfit(np.log([8, 16, 32, 64]), np.log(err), 1)[0]
    assert order == pytest.approx(-2.0, abs=0.05)


def test_profile_gives_the_law_of_the_map_extruded_from_it():
    """A 1-D stylus profile and the 2-D map made of copies of it (ridges along y) give the same
    mu(theta) at the same scale and detrending."""
    rng = np.random.default_rng(4)
    z = np.cumsum(rng.standard_normal(300)) * 0.02 + 0.001 * np.arange(300)
    prof = quiet(Topo(z, (0.1, 0.1)), MU, scale=0.4)
    extruded = quiet(Topo(np.tile(z, (7, 1)), (0.1, 0.1)), MU, scale=0.4)
    np.testing.assert_allclose(extruded.mu, prof.mu, rtol=1e-9)
    assert prof.shape == (300,) and extruded.shape == (7, 300)
    np.testing.assert_allclose(extruded.carrying_fraction, prof.carrying_fraction, rtol=1e-12)


def test_self_affine_surface_converges_at_second_order_as_the_scale_shrinks():
    """A seeded self-affine map (H = 0.8, rms slope 0.1, short cut-off 32 pixels): its facets'
    rms slope is 0.1 within 0.5 %, and mu(theta) at the cut-off lambda_s approaches the raw
    map's as lambda_s**2 (a Gaussian changes a smooth field by (sigma^2/2) lap h + O(sigma^4))."""
    h = self_affine_surface(128, 1.0, hurst=0.8, rms_slope=0.1, short_cutoff=32.0, seed=2)
    t = Topo(h, periodic=True)
    raw = quiet(t, MU, scale=0.0, n=72)
    assert raw.rms_slope == pytest.approx(0.1, rel=5e-3)
    scales = np.array([1.0, 2.0, 4.0])
    err = [np.max(np.abs(quiet(t, MU, scale=s, n=72).mu - raw.mu)) for s in scales]
    order = np.polyfit(np.log(scales), np.log(err), 1)[0]
    assert order == pytest.approx(2.0, abs=0.1)
    assert np.all(raw.mu > MU) and np.all(raw.mu <= raw.upper_bound * (1 + 1e-12))


# ---- undefined points, orientation ----------------------------------------------------------
def smooth_map(n=48):
    y, x = np.mgrid[0:n, 0:n] * 0.5
    return 0.6 * np.sin(x / 3.0) + 0.4 * np.cos(y / 2.0 + 0.3 * x)


def test_masked_points_are_excluded_never_filled():
    """A masked band of rows (data 1e20 under the mask, as a reader's fill value): only the
    triangles with three defined corners are facets, so the law is the one of the two
    remaining pieces, to 1e-12; no direction locks (the fill value gave mu ~ 26 and locking)."""
    h = smooth_map()
    data = h.copy()
    data[20:25] = 1e20
    masked = np.ma.MaskedArray(data, mask=np.zeros_like(data, bool))
    masked.mask[20:25] = True
    theta = np.linspace(-np.pi, np.pi, 60, endpoint=False)
    ref_p = np.concatenate((heightmap_gradients(h[:20], 0.5, 0.5),
                            heightmap_gradients(h[25:], 0.5, 0.5)))
    from frictionrules.asperities.surfaces import _facet_set
    ref = _facet_set(ref_p, MU, "non-associated", 64).friction_coefficient(theta)
    law = from_heightmap(masked, 0.5, 0.5, MU)
    np.testing.assert_allclose(law.friction_coefficient(theta), ref, rtol=1e-12)
    r = quiet(Topo(masked, (0.5, 0.5), undefined=True), MU, scale=0.0, detrend="none",
              n=60)
    np.testing.assert_allclose(r.mu, ref, rtol=1e-12)
    assert r.undefined == 5 * 48 and not r.locked.any()
    # SurfaceTopography may hand undefined points as NaN with has_undefined_data set
    nan = h.copy()
    nan[20:25] = np.nan
    r2 = quiet(Topo(nan, (0.5, 0.5), undefined=True), MU, scale=0.0, detrend="none", n=60)
    np.testing.assert_allclose(r2.mu, ref, rtol=1e-12)
    with pytest.raises(FrictionRulesError, match="must be finite"):
        from_topography(Topo(nan, (0.5, 0.5)), MU)


def test_masked_points_with_smoothing_and_detrending_stay_excluded():
    """With a hole, the plane is fitted and the filter normalized over the defined points:
    the result depends only on them (changing the data under the mask changes nothing)."""
    h = smooth_map()
    mask = np.zeros(h.shape, bool)
    mask[10:18, 30:40] = True
    a = quiet(Topo(np.ma.MaskedArray(h, mask), (0.5, 0.5)), MU, scale=2.0, n=36)
    b = quiet(Topo(np.ma.MaskedArray(np.where(mask, -7e9, h), mask), (0.5, 0.5)), MU, scale=2.0,
              n=36)
    np.testing.assert_array_equal(a.mu, b.mu)
    assert a.undefined == 80


def test_heights_indexed_ix_iy_with_non_square_pixels():
    """SurfaceTopography's heights[ix, iy] with dx != dy: grooves across x (ridges along y)
    give their steepest slope across x, whatever the pixel shape."""
    dx, dy = 0.2, 0.7
    x = np.arange(50) * dx
    m = np.tile(0.1 * np.abs(((x / 2.0) % 1.0) - 0.5), (9, 1))    # (ny, nx), V grooves
    s = np.abs(np.diff(m[0])) / dx                                 # 0.05 on both flanks
    r = quiet(Topo(m, (dx, dy)), MU, scale=0.0, detrend="none", n=4)
    np.testing.assert_allclose(r.mu[[0, 2]], np.tan(np.arctan(s.max()) + np.arctan(MU)),
                               rtol=1e-12)
    assert r.mu[1] == pytest.approx(MU * np.sqrt(1 + s.min() ** 2), rel=1e-12)
    assert s.max() == pytest.approx(0.05)
    assert r.pixel_size == (dx, dy) and r.shape == (9, 50)


# ---- locking, carrying, warnings ------------------------------------------------------------
def wedge_map(angle_deg, n=6):
    """One tilted facet rising along +x at ``angle_deg``, in a symmetric V (both flanks)."""
    s = np.tan(np.deg2rad(angle_deg))
    x = np.arange(n) - (n - 1) / 2
    return np.tile(s * np.abs(x), (4, 1))


def test_near_locking_directions_are_reported_locked_with_a_flag():
    """Flanks at 90 - 16.7 - 0.1 deg: climbing them gives mu ~ 573 > 100, classified locked
    (flag, inf); 1 deg steeper they lock outright; sideways they slide."""
    rho = np.rad2deg(np.arctan(MU))
    near = quiet(Topo(wedge_map(90 - rho - 0.1)), MU, scale=0.0, detrend="none", n=4)
    assert near.locked[[0, 2]].all() and near.near_locking[[0, 2]].all()
    assert np.isinf(near.mu[[0, 2]]).all() and np.isfinite(near.mu[1])
    assert near.law.friction_coefficient(0.0) > 100.0
    loose = quiet(Topo(wedge_map(90 - rho - 0.1)), MU, scale=0.0, detrend="none", n=4,
                  locking_mu=1e4)
    assert not loose.locked.any()
    locked = quiet(Topo(wedge_map(90 - rho + 1.0)), MU, scale=0.0, detrend="none", n=4)
    assert locked.locked[[0, 2]].all() and not locked.near_locking.any()
    assert locked.upper_bound == np.inf


def test_a_spike_is_flagged_and_the_scale_removes_it():
    """One pixel of noise (a slope of 0.84 on a surface of rms slope 0.003, as in an
    interferometer map): the raw law is set by it (mu up to 2.3 for mu = 0.3; 0.31 without
    it), and the result warns that a few pixels carry it, still at a scale of 5 pixels; at 16
    pixels the warning is gone and mu(theta) is within 1 % of the clean surface's, which never
    warns."""
    h = self_affine_surface(96, 1.0, rms_slope=0.003, short_cutoff=24.0, seed=5)
    spiked = h.copy()
    spiked[40, 50] += 0.84
    with pytest.warns(UserWarning, match="few pixels"):
        raw = from_topography(Topo(spiked, periodic=True), MU, scale=0.0)
    assert raw.carried_by_few and raw.mu_range[1] > 2.0
    assert raw.carrying.min() <= 4
    assert quiet(Topo(spiked, periodic=True), MU, scale=5.0).carried_by_few
    assert not quiet(Topo(h, periodic=True), MU, scale=0.0).carried_by_few
    with warnings.catch_warnings():
        warnings.simplefilter("error", UserWarning)
        fixed = from_topography(Topo(spiked, periodic=True), MU, scale=16.0)
        clean = from_topography(Topo(h, periodic=True), MU, scale=16.0)
    assert not fixed.carried_by_few and fixed.warnings == ()
    np.testing.assert_allclose(fixed.mu, clean.mu, rtol=1e-2)


def test_scan_line_steps_lock_raw_and_are_levelled_by_rows():
    """AFM scan lines offset from each other by steps of several pixel sizes: the raw map locks
    in most directions across the lines; the result reports them locked and warns;
    detrend="rows" levels each line and nothing locks."""
    rng = np.random.default_rng(7)
    h = self_affine_surface(64, 1.0, rms_slope=0.05, short_cutoff=16.0, seed=7)
    steps = h + np.cumsum(rng.normal(0.0, 4.0, 64))[:, None]      # offset per row (along y)
    raw = quiet(Topo(steps), MU, scale=0.0)
    assert raw.locked.sum() > 100 and any("locked" in w for w in raw.warnings)
    rows = quiet(Topo(steps), MU, scale=0.0, detrend="rows")
    assert not rows.locked.any() and rows.mu_range[1] < 1.0


def test_carrying_facets_of_a_profile_are_counted_exactly():
    """A sawtooth of 10 periods, each a facet rising at slope 0.5 and two falling at 0.25: the
    climb along +x is carried by the 10 rising facets, along -x by the 20 falling ones, along
    y (no climb) by all 30."""
    z = np.concatenate(([0.0], np.cumsum(np.tile([0.5, -0.25, -0.25], 10))))
    r = quiet(Topo(z, (1.0, 1.0)), MU, scale=0.0, detrend="none", n=4)
    assert r.facets == 30
    np.testing.assert_array_equal(r.carrying, [20, 30, 10, 30])   # theta = -pi, -pi/2, 0, pi/2
    np.testing.assert_allclose(r.carrying_fraction, np.array([20, 30, 10, 30]) / 30)


def test_scale_study_records_each_scale_and_plots():
    h = self_affine_surface(64, 1.0, rms_slope=0.05, short_cutoff=16.0, seed=1)
    study = scale_study(Topo(h, periodic=True), MU, scales=[4.0, 1.0, 2.0], n=36)
    assert isinstance(study, ScaleStudy)
    np.testing.assert_array_equal(study.scales, [1.0, 2.0, 4.0])
    assert study.mu.shape == (3, 36) and study.unit == "um"
    assert np.all(np.diff(study.max_slope) < 0)          # smoothing flattens the steepest
    assert np.all(np.nanmax(np.where(study.locked, np.nan, study.mu), axis=1)
                  <= study.upper_bound * (1 + 1e-12))
    ax = study.plot()
    assert ax.get_xscale() == "log" and len(ax.get_legend().get_texts()) >= 4
    default = scale_study(Topo(h, periodic=True), MU, n=12)
    assert default.scales[0] == 2.0 and len(default.scales) == 8


# ---- the local law, inputs -----------------------------------------------------------------
def test_local_law_is_an_argument():
    h = smooth_map(24)
    a = quiet(Topo(h), 0.4, n=12)
    b = quiet(Topo(h), Coulomb(0.4), n=12)
    np.testing.assert_array_equal(a.mu, b.mu)
    c = quiet(Topo(h), Coulomb(0.4, dilatant=True), n=12)
    assert c.law.local == "associated" and np.all(c.mu >= a.mu * (1 - 1e-6))
    # any law whose cone is Coulomb's, not only the class: a user law written for it
    user = UserLaw("sqrt(T1**2 + T2**2) - mu*N", "sqrt(T1**2 + T2**2)", params={"mu": 0.4})
    np.testing.assert_array_equal(quiet(Topo(h), user, n=12).mu, a.mu)
    with pytest.raises(FrictionRulesError, match="isotropic Coulomb cone"):
        from_topography(Topo(h), EllipticOrthotropic(0.4, 0.3))
    with pytest.raises(FrictionRulesError, match="isotropic Coulomb cone"):
        from_topography(Topo(h), Huber(0.4, 0.4))          # no cone capability


def test_from_topography_records_its_settings():
    h = smooth_map(24)
    r = quiet(Topo(h, (0.5, 0.5), unit="nm"), MU)
    assert isinstance(r, SurfaceFriction)
    assert r.scale == 2.5 and r.unit == "nm" and r.detrend == "plane"   # 5 pixels
    assert r.facets == 4 * 23 * 23 and r.undefined == 0
    assert r.mu.shape == r.theta.shape == r.carrying.shape == (360,)


@pytest.mark.parametrize("kwargs, match", [
    (dict(scale=-1.0), "scale"), (dict(detrend="tilt"), "detrend"), (dict(n=0), "n = 0"),
    (dict(locking_mu=0.0), "locking_mu"), (dict(carrying_tolerance=1.0), "carrying_tolerance"),
    (dict(warn_pixels=-1.0), "warn_pixels")])
def test_bad_settings(kwargs, match):
    with pytest.raises(FrictionRulesError, match=match):
        from_topography(Topo(smooth_map(8)), MU, **kwargs)


def test_bad_topographies():
    with pytest.raises(FrictionRulesError, match="SurfaceTopography's interface"):
        from_topography(np.zeros((4, 4)), MU)
    with pytest.raises(FrictionRulesError, match="pixel size dy"):
        from_topography(Topo(smooth_map(8), (1.0, 0.0)), MU)
    with pytest.raises(FrictionRulesError, match="law_or_mu"):
        from_topography(Topo(smooth_map(8)), "0.3")
    with pytest.raises(FrictionRulesError, match="mu = -0.3"):
        from_topography(Topo(smooth_map(8)), -0.3)
    everything = np.ma.MaskedArray(smooth_map(8), np.ones((8, 8), bool))
    with pytest.raises(FrictionRulesError, match="defined points"):
        from_topography(Topo(everything), MU)
    with pytest.raises(FrictionRulesError, match="scales"):
        scale_study(Topo(smooth_map(8)), MU, scales=[0.0, 1.0])


def test_v_profile_has_two_facets_and_no_spurious_corners():
    """A V of 11 points: its slopes differ by round-off (1e-17) and are one facet each side
    (merged within 1e-9 (1 + max|p|)): two facets and the 4 corners of the groove, no
    180-degree corners between identical facets."""
    x = np.linspace(0.0, 1.0, 11)
    law = from_profile(x, np.abs(x - 0.5), MU)
    assert len(law.normals) == 2
    corners = law.limit_curve(1.0, 360).corners
    assert len(corners) == 4
    assert all(abs(np.rad2deg(c.interior) - 180.0) > 1.0 for c in corners)
