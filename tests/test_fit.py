"""Calibration of laws to measured mu(theta) with scipy least squares."""

import numpy as np
import pytest

from frictionrules import (EllipticOrthotropic, FrictionRulesError, Huber, TransformedCoulomb,
                           TwoFlankAsperity, fit)
from frictionrules.asperities import compare_fits, format_fits

THETA = np.linspace(-np.pi, np.pi, 49)[:-1]


def test_fit_recovers_elliptic_orthotropic_parameters():
    truth = EllipticOrthotropic(0.6, 0.3, 0.4)
    mu = truth.friction_coefficient(THETA)
    r = fit(EllipticOrthotropic(0.5, 0.5, 0.0), THETA, mu)
    assert r.success
    assert r.params["mu_x"] == pytest.approx(0.6, rel=1e-6)
    assert r.params["mu_y"] == pytest.approx(0.3, rel=1e-6)
    assert r.params["angle"] == pytest.approx(0.4, abs=1e-6)
    assert r.rms < 1e-8 and isinstance(r.law, EllipticOrthotropic)


def test_fit_with_force_angle_separates_models():
    """mu(theta) alone cannot tell EllipticOrthotropic from TransformedCoulomb with other
    parameters; the measured force-slip angle can."""
    truth = TransformedCoulomb(0.6, 0.3)
    mu = truth.friction_coefficient(THETA)
    psi = (truth.force_angle(THETA) - THETA + np.pi) % (2 * np.pi) - np.pi
    r = fit(TransformedCoulomb(0.5, 0.4), THETA, mu, angle=psi, params=["mu_x", "mu_y"])
    assert r.params["mu_x"] == pytest.approx(0.6, rel=1e-6)
    np.testing.assert_allclose(r.angle_residuals, 0.0, atol=1e-7)
    e = fit(EllipticOrthotropic(0.5, 0.4), THETA, mu, angle=psi, params=["mu_x", "mu_y"])
    assert e.cost > 1e3 * r.cost


def test_fit_facet_model_and_comparison_table():
    truth = TwoFlankAsperity(0.3, np.pi - 0.25, 0.4)
    rng = np.random.default_rng(1)
    mu = truth.friction_coefficient(THETA) * (1 + 0.005 * rng.standard_normal(THETA.shape))
    res = compare_fits(THETA, mu, {
        "EllipticOrthotropic": EllipticOrthotropic(0.5, 0.4),
        "Huber": Huber(0.5, 0.4),
        "TransformedCoulomb": TransformedCoulomb(0.5, 0.4),
        "TwoFlankAsperity": TwoFlankAsperity(0.4, 2.5, 0.3)})
    best = min(res, key=lambda k: res[k].rms)
    assert best == "TwoFlankAsperity"
    assert res[best].params["alpha1"] == pytest.approx(0.3, abs=0.01)
    table = format_fits(res)
    assert table.splitlines()[0].split()[:3] == ["model", "rms(mu)", "max|res|"]
    assert len(table.splitlines()) == 6


def test_fit_handles_locking_trial_laws():
    """A trial two-flank law that locks in some directions still gives finite residuals."""
    truth = TwoFlankAsperity(0.3, np.pi - 0.3, 0.3)
    mu = truth.friction_coefficient(THETA)
    r = fit(TwoFlankAsperity(1.2, np.pi - 1.2, 0.6), THETA, mu)
    assert np.isfinite(r.cost)
    assert r.params["mu"] == pytest.approx(0.3, rel=1e-3)


def test_fit_bad_input():
    law = EllipticOrthotropic(0.5, 0.4)
    with pytest.raises(FrictionRulesError, match="same nonzero length"):
        fit(law, THETA, np.ones(3))
    with pytest.raises(FrictionRulesError, match="mu_measured"):
        fit(law, THETA, -np.ones_like(THETA))
    with pytest.raises(FrictionRulesError, match="params entry 'nope'"):
        fit(law, THETA, np.ones_like(THETA), params=["nope"])
