"""Calibration of laws to measured mu(theta): parameters, confidence intervals, residuals."""

import concurrent.futures

import numpy as np
import pytest

from frictionrules import (EllipticOrthotropic, FitResult, FrictionRulesError, Huber,
                           TransformedCoulomb, TwoFlankAsperity, UserLaw, fit)
from frictionrules.asperities import compare_fits, format_fits

THETA = np.linspace(-np.pi, np.pi, 49)[:-1]


def noisy(law, sigma, seed, theta=THETA):
    """mu(theta) of ``law`` with Gaussian noise of standard deviation ``sigma`` (absolute)."""
    rng = np.random.default_rng(seed)
    return law.friction_coefficient(theta) + sigma * rng.standard_normal(np.shape(theta))


def test_fit_recovers_elliptic_orthotropic_parameters():
    truth = EllipticOrthotropic(0.6, 0.3, 0.4)
    mu = truth.friction_coefficient(THETA)
    r = fit(EllipticOrthotropic(0.5, 0.5, 0.0), THETA, mu)
    assert isinstance(r, FitResult) and r.success
    assert r.params["mu_x"] == pytest.approx(0.6, rel=1e-6)
    assert r.params["mu_y"] == pytest.approx(0.3, rel=1e-6)
    assert r.params["angle"] == pytest.approx(0.4, abs=1e-6)
    assert r.rms < 1e-8 and isinstance(r.law, EllipticOrthotropic)
    assert r.law.parameters == pytest.approx(r.params)


def test_confidence_intervals_cover_the_truth_at_their_level():
    """The linearized 95 % intervals of mu_x over 200 seeded noisy data sets with known sigma
    cover the true value in 95 % of them (binomial: 190 expected, 99.7 % range 181-199), and
    chi2/dof averages 1."""
    truth = EllipticOrthotropic(0.6, 0.3, 0.4)
    theta = THETA[::2]
    sigma = 0.02
    data = np.stack([noisy(truth, sigma, seed, theta) for seed in range(200)])
    results = fit(truth, theta, data, sigma=sigma, params=["mu_x", "mu_y"])
    assert len(results) == 200
    covered = sum(r.parameter("mu_x").low <= 0.6 <= r.parameter("mu_x").high for r in results)
    assert 181 <= covered <= 199
    assert np.mean([r.reduced_chi2 for r in results]) == pytest.approx(1.0, abs=0.05)
    r = results[0]
    np.testing.assert_allclose(r.residuals, r.mu_model - data[0], rtol=1e-12)
    # normalized residuals: the friction-angle misfit over sigma carried to the angle
    phi = (np.arctan(r.mu_model) - np.arctan(data[0])) * (1 + data[0] ** 2) / sigma
    np.testing.assert_allclose(r.normalized_residuals, phi, rtol=1e-9)


def test_interval_without_sigma_uses_the_residual_scatter():
    """Without sigma the covariance is scaled by chi2/dof: the interval width follows the
    noise (10 x noise, about 10 x width)."""
    truth = EllipticOrthotropic(0.6, 0.3, 0.4)
    w = [fit(truth, THETA, noisy(truth, s, 3)).parameter("mu_y") for s in (0.002, 0.02)]
    ratio = (w[1].high - w[1].low) / (w[0].high - w[0].low)
    assert 6.0 < ratio < 14.0
    assert not w[0].at_bound


def test_undetermined_parameter_has_an_infinite_interval():
    """Isotropic data cannot fix the orientation of an elliptic law: angle has an infinite
    standard error (zero singular value of the Jacobian)."""
    iso = EllipticOrthotropic(0.4, 0.4, 0.0)
    r = fit(EllipticOrthotropic(0.4, 0.4, 0.2), THETA, noisy(iso, 0.01, 0), sigma=0.01,
            params=["angle"])
    p = r.parameter("angle")
    assert p.stderr == np.inf and (p.low, p.high) == (-np.pi, np.pi)
    r = fit(EllipticOrthotropic(0.5, 0.3), THETA, noisy(iso, 0.01, 0), sigma=0.01,
            bounds={"mu_x": (0.45, 1.0)})
    assert r.parameter("mu_x").at_bound and r.parameter("mu_x").value == pytest.approx(0.45)


def test_fit_user_law_with_named_parameters():
    """Any law with numeric parameters: a UserLaw's params are fitted through
    law.parameters / law.replace."""
    theta = np.linspace(-np.pi, np.pi, 9)[:-1]
    mu = np.full_like(theta, 0.37)
    law = UserLaw("sqrt(T1**2 + T2**2) - mu*N", params={"mu": 0.5})
    r = fit(law, theta, mu)
    assert isinstance(r.law, UserLaw)
    assert r.params["mu"] == pytest.approx(0.37, rel=1e-6)
    assert r.law.parameters["mu"] == pytest.approx(0.37, rel=1e-6)


@pytest.mark.parametrize("pool", [concurrent.futures.ThreadPoolExecutor,
                                  concurrent.futures.ProcessPoolExecutor])
def test_executor_gives_the_serial_results(pool):
    truth = TransformedCoulomb(0.6, 0.3)
    data = np.stack([noisy(truth, 0.01, seed) for seed in range(4)])
    serial = fit(TransformedCoulomb(0.5, 0.4), THETA, data, sigma=0.01)
    with pool(max_workers=2) as ex:
        parallel = fit(TransformedCoulomb(0.5, 0.4), THETA, data, sigma=0.01, executor=ex)
    assert len(parallel) == 4
    for a, b in zip(serial, parallel):
        assert a.params == b.params            # bit-identical
        np.testing.assert_array_equal(a.covariance, b.covariance)


def test_fit_with_force_angle_separates_models():
    """mu(theta) alone cannot tell EllipticOrthotropic from TransformedCoulomb with other
    parameters; the measured force-slip angle (1.14) can."""
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
    p = res[best].parameter("alpha1")
    assert p.low <= 0.3 <= p.high and p.high - p.low < 0.02
    table = format_fits(res)
    assert table.splitlines()[0].split()[:4] == ["model", "rms(mu)", "max|res|", "chi2/dof"]
    assert len(table.splitlines()) == 6


def test_fit_handles_locking_trial_laws():
    """A trial two-flank law that locks in some directions still gives finite residuals."""
    truth = TwoFlankAsperity(0.3, np.pi - 0.3, 0.3)
    mu = truth.friction_coefficient(THETA)
    start = TwoFlankAsperity(1.2, np.pi - 1.2, 0.6)
    assert start.inverse_relation(THETA).locked.any()
    r = fit(start, THETA, mu)
    assert np.isfinite(r.cost)
    assert r.params["mu"] == pytest.approx(0.3, rel=1e-3)
    assert not r.locked.any()


def test_fit_bad_input():
    law = EllipticOrthotropic(0.5, 0.4)
    with pytest.raises(FrictionRulesError, match="theta of shape"):
        fit(law, THETA, np.ones(3))
    with pytest.raises(FrictionRulesError, match="mu_measured"):
        fit(law, THETA, -np.ones_like(THETA))
    with pytest.raises(FrictionRulesError, match="params entry 'nope'"):
        fit(law, THETA, np.ones_like(THETA), params=["nope"])
    with pytest.raises(FrictionRulesError, match="sigma"):
        fit(law, THETA, np.ones_like(THETA), sigma=0.0)
    with pytest.raises(FrictionRulesError, match="angle_sigma"):
        fit(law, THETA, np.ones_like(THETA), sigma=0.1, angle=np.zeros_like(THETA))
    with pytest.raises(FrictionRulesError, match="confidence"):
        fit(law, THETA, np.ones_like(THETA), confidence=1.0)
    with pytest.raises(FrictionRulesError, match="no numeric parameter"):
        fit(UserLaw("sqrt(T1**2 + T2**2) - 0.3*N"), THETA, np.ones_like(THETA))
