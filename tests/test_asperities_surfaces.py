"""Facet sets of real surfaces: profiles and height maps (symmetry, rotation, grouping)."""

import numpy as np
import pytest

from frictionrules import FrictionRulesError, TwoFlankAsperity, from_heightmap, from_profile
from frictionrules.asperities.surfaces import group_gradients

THETA = np.linspace(-np.pi, np.pi, 145)


def sawtooth(x, period, rise, fall):
    """Periodic profile rising at slope ``rise`` over a fraction, falling at ``fall``."""
    frac = (x / period) % 1.0
    xr = fall / (rise + fall)
    return np.where(frac < xr, rise * frac, rise * xr - fall * (frac - xr)) * period


def test_symmetric_sawtooth_profile_gives_symmetric_law():
    x = np.linspace(0.0, 4.0, 9)
    z = np.array([0, 1, 0, 1, 0, 1, 0, 1, 0]) * 0.4       # slopes +-0.8
    law = from_profile(x, z, 0.3)
    mu = law.friction_coefficient(THETA)
    np.testing.assert_allclose(mu, law.friction_coefficient(np.pi - THETA), rtol=1e-12)
    np.testing.assert_allclose(mu, law.friction_coefficient(-THETA), rtol=1e-12)
    # across the ridges: climbing a flank at atan(0.8), mu(0) = tan(atan 0.8 + atan 0.3)
    assert mu[72] == pytest.approx(np.tan(np.arctan(0.8) + np.arctan(0.3)))


def test_two_slope_profile_is_the_two_flank_asperity():
    x = np.array([0.0, 1.0, 1.0 + np.sqrt(3.0) * 3.0])
    a1, a2 = np.pi / 3, 5 * np.pi / 6
    z = np.array([0.0, np.tan(a1), np.tan(a1) - np.tan(np.pi - a2) * np.sqrt(3.0) * 3.0])
    law = from_profile(x, z, 0.5)
    ref = TwoFlankAsperity(a1, a2, 0.5)
    np.testing.assert_allclose(law.friction_coefficient(THETA), ref.friction_coefficient(THETA),
                               rtol=1e-12)


def test_profile_bad_input():
    with pytest.raises(FrictionRulesError, match="strictly increasing"):
        from_profile([0.0, 1.0, 1.0], [0.0, 1.0, 0.0], 0.3)
    with pytest.raises(FrictionRulesError, match="same length"):
        from_profile([0.0, 1.0], [0.0, 1.0, 0.0], 0.3)


def smooth_map(n=256, angle=0.0, h=1.0):
    """Analytic surface of three waves, sampled on a grid rotated by ``angle``."""
    y, x = np.mgrid[0:n, 0:n] * h
    c, s = np.cos(angle), np.sin(angle)
    xr, yr = c * x + s * y, -s * x + c * y              # coordinates of the unrotated surface
    return (3.0 * np.sin(2 * np.pi * xr / 40.0) + 1.0 * np.sin(2 * np.pi * (xr + 2 * yr) / 55.0)
            + 0.6 * np.cos(2 * np.pi * yr / 33.0))


def test_heightmap_rot90_gives_rotated_law_exactly():
    rng = np.random.default_rng(0)
    h = smooth_map(128) + 0.05 * rng.standard_normal((128, 128))
    law = from_heightmap(h, 1.0, 1.0, 0.4)
    turned = from_heightmap(np.rot90(h), 1.0, 1.0, 0.4)
    # np.rot90 maps (x, y) -> (y, -x) for rows along y: the law turns by -90°
    np.testing.assert_allclose(turned.friction_coefficient(THETA),
                               law.friction_coefficient(THETA + np.pi / 2), rtol=1e-10)


def bumps(n=512, angle=0.0, h=0.25):
    """Lattice of skewed elliptical bumps, sampled on a grid rotated by ``angle``."""
    y, x = np.mgrid[0:n, 0:n] * h
    c, s = np.cos(angle), np.sin(angle)
    xr, yr = c * x + s * y, -s * x + c * y              # coordinates of the unrotated surface
    u, v = (xr % 32.0) - 16.0, (yr % 32.0) - 16.0
    return 2.0 * np.exp(-(u / 6.0) ** 2 - (v / 4.0) ** 2) * (1.0 + 0.3 * u / 6.0)


@pytest.mark.parametrize("angle", [np.deg2rad(30.0), np.deg2rad(-65.0)])
def test_heightmap_rotated_by_angle_gives_rotated_law(angle):
    """Up to the sampling of the extreme gradients: the triangles of the piecewise-linear
    surface carry gradients with an O(h) error (3 % here, h = sigma/16)."""
    law = from_heightmap(bumps(), 0.25, 0.25, 0.3)
    turned = from_heightmap(bumps(angle=angle), 0.25, 0.25, 0.3)
    # the surface is rotated by +angle: mu_turned(theta) = mu(theta - angle)
    np.testing.assert_allclose(turned.friction_coefficient(THETA),
                               law.friction_coefficient(THETA - angle), rtol=5e-2)


def test_heightmap_of_parallel_ridges_is_the_profile():
    x = np.arange(200) * 0.1
    z = sawtooth(x, 2.0, 0.5, 0.5)
    h = np.tile(z, (20, 1))                                  # ridges along y
    law = from_heightmap(h, 0.1, 0.1, 0.3)
    ref = from_profile(x, z, 0.3)
    np.testing.assert_allclose(law.friction_coefficient(THETA), ref.friction_coefficient(THETA),
                               rtol=1e-9)


def test_flat_map_is_coulomb():
    law = from_heightmap(np.zeros((8, 8)), 1.0, 1.0, 0.35)
    np.testing.assert_allclose(law.friction_coefficient(THETA), 0.35, rtol=1e-12)
    assert len(law.normals) == 1


def test_grouping_keeps_hull_vertices_and_bins_edges():
    rng = np.random.default_rng(2)
    p = rng.uniform(-1, 1, (5000, 2))
    square = np.array([[-2, -2], [2, -2], [2, 2], [-2, 2.0]])
    edge = np.stack((np.linspace(-2, 2, 1001)[1:-1], np.full(999, -2.0)), axis=-1)
    g = group_gradients(np.concatenate((p, square, edge)), bins=10)
    assert len(g) == 4 + 10
    assert np.all(np.abs(g).max(axis=1) == pytest.approx(2.0))


def test_heightmap_bad_input():
    with pytest.raises(FrictionRulesError, match="2-D"):
        from_heightmap(np.zeros(5), 1.0, 1.0, 0.3)
    with pytest.raises(FrictionRulesError, match="dx"):
        from_heightmap(np.zeros((4, 4)), 0.0, 1.0, 0.3)
    with pytest.raises(FrictionRulesError, match="h"):
        from_heightmap(np.full((4, 4), np.nan), 1.0, 1.0, 0.3)
