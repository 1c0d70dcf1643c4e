r"""Calibration: fit a law's parameters to a measured directional friction coefficient mu(theta).

Any law of the protocol with numeric parameters can be fitted: the law passed in is the
initial guess, and the fit touches it only through ``law.parameters`` (name -> value) and
``law.replace(**changes)``. :func:`scipy.optimize.least_squares` minimizes the sum of squares
of

.. math:: r_i = \frac{\arctan\mu_{model}(\theta_i) - \arctan\mu_i}{\sigma_{\phi,i}}
          \;\Bigl[,\ \frac{\psi_{model}(\theta_i) - \psi_i}{\sigma_{\psi,i}}\Bigr],
          \qquad \sigma_{\phi,i} = \frac{\sigma_i}{1 + \mu_i^2},

the friction-angle misfit (bounded, so a trial law that locks in some direction,
``mu = inf``, still gives a finite residual of at most pi/2; :math:`\sigma_{\phi}` is the
uncertainty ``sigma`` of mu carried to the friction angle :math:`\phi = \arctan\mu`) and,
when measured, the misfit of the angle :math:`\psi = \beta - \theta` between force and slip
((1.14)).

Confidence intervals are linearized: :math:`C = (J^TJ)^{-1}` at the optimum (``J`` the
Jacobian of ``r``). With ``sigma`` given it is the covariance (the uncertainties are taken as
absolute) and the interval is ``value +- z stderr`` (normal quantile); without, ``C`` is
scaled by the residual variance :math:`\chi^2/(m - p)` and the Student-t quantile with
``m - p`` degrees of freedom is used.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._optional import require
from ..errors import FrictionRulesError, check_finite, check_scalar

__all__ = ["fit", "FitResult", "FittedParameter", "compare_fits", "format_fits"]

#: Default bounds by parameter name (override with ``bounds=``).
DEFAULT_BOUNDS = {
    "mu": (1e-6, 10.0), "mu_x": (1e-6, 10.0), "mu_y": (1e-6, 10.0), "mu_1": (1e-6, 10.0),
    "mu_2": (1e-6, 10.0), "angle": (-np.pi, np.pi), "alpha": (1e-3, np.pi - 1e-3),
    "alpha1": (1e-3, np.pi / 2 - 1e-3), "alpha2": (np.pi / 2 + 1e-3, np.pi - 1e-3),
}


@dataclass(frozen=True)
class FittedParameter:
    """One fitted parameter with its linearized confidence interval.

    Attributes
    ----------
    name : str
    value : float
    stderr : float
        Standard error (``inf`` when the data do not determine the parameter: a zero singular
        value of the Jacobian involves it).
    low, high : float
        Confidence interval at the fit's ``confidence`` level (clipped to the bounds).
    at_bound : bool
        The optimum sits on a bound: the interval is then not a confidence interval.
    """

    name: str
    value: float
    stderr: float
    low: float
    high: float
    at_bound: bool


@dataclass(frozen=True)
class FitResult:
    """Outcome of :func:`fit` for one data set.

    Attributes
    ----------
    law : the fitted law (same class as the initial one).
    parameters : tuple of :class:`FittedParameter`, in the order fitted.
    confidence : float, level of the intervals.
    theta, mu_measured : (M,) the data; ``sigma`` (M,) their uncertainties or None.
    mu_model : (M,) mu(theta) of the fitted law (``inf`` where it locks).
    locked : (M,) bool, where the fitted law locks.
    residuals : (M,) ``mu_model - mu_measured`` (``inf`` where locked).
    normalized_residuals : (M,) the friction-angle residuals of the fit, in units of their
        uncertainty (of the estimated noise when ``sigma`` is None).
    angle_residuals : (M,) force-slip angle misfit in radians (``inf`` where locked), or None
        if not fitted.
    rms : root mean square of the finite ``residuals``.
    chi2 : sum of squares of the fit residuals; ``dof`` = residuals - parameters.
    covariance : (P, P) linearized covariance of the parameters.
    cost, success, message, n_eval : from :func:`scipy.optimize.least_squares`.
    """

    law: object
    parameters: tuple
    confidence: float
    theta: np.ndarray
    mu_measured: np.ndarray
    sigma: np.ndarray | None
    mu_model: np.ndarray
    locked: np.ndarray
    residuals: np.ndarray
    normalized_residuals: np.ndarray
    angle_residuals: np.ndarray | None
    rms: float
    chi2: float
    dof: int
    covariance: np.ndarray
    cost: float
    success: bool
    message: str
    n_eval: int

    @property
    def params(self) -> dict:
        """The fitted values by name (as ``law.parameters`` gives them)."""
        return {p.name: p.value for p in self.parameters}

    @property
    def reduced_chi2(self) -> float:
        """``chi2 / dof``: about 1 when the model fits within the given uncertainties."""
        return self.chi2 / self.dof if self.dof > 0 else np.inf

    def parameter(self, name: str) -> FittedParameter:
        """The fitted parameter ``name``."""
        for p in self.parameters:
            if p.name == name:
                return p
        raise FrictionRulesError(f"name = {name!r} violates: one of the fitted parameters "
                                 f"{[p.name for p in self.parameters]}")


def _wrap(a):
    return (a + np.pi) % (2.0 * np.pi) - np.pi


def _model(law, theta, want_angle):
    """mu(theta), the force-slip angle (or None) and the locked flags of ``law``."""
    inv = law.inverse_relation(theta, 1.0)
    T = np.where(inv.locked[:, None], 0.0, inv.force)
    mu = np.where(inv.locked, np.inf, np.hypot(T[:, 0], T[:, 1]))
    psi = _wrap(np.arctan2(T[:, 1], T[:, 0]) - theta) if want_angle else None
    return mu, psi, inv.locked


def _data(name, value, shape, lo=None):
    """``value`` broadcast to ``shape`` (finite, optionally ``> lo``), or None."""
    if value is None:
        return None
    arr = check_finite(name, value)
    try:
        arr = np.broadcast_to(arr, shape).astype(float)
    except ValueError as exc:
        raise FrictionRulesError(f"{name} of shape {np.shape(value)} violates: the shape of "
                                 f"mu_measured {shape} (or broadcastable to it)") from exc
    if lo is not None and np.any(arr <= lo):
        raise FrictionRulesError(f"{name} = {float(arr.min())!r} violates {name} > {lo}")
    return arr


def fit(law, theta, mu_measured, *, sigma=None, params=None, angle=None, angle_sigma=None,
        bounds=None, confidence: float = 0.95, executor=None, **least_squares_options):
    """Fit the parameters ``params`` of ``law`` to measured ``mu(theta)``.

    Parameters
    ----------
    law : FrictionLaw
        The initial guess (its class is the model); any law with numeric parameters
        (``law.parameters``, ``law.replace``).
    theta : array (M,) or (S, M)
        Slip angles (radians, from x).
    mu_measured : array (M,) or (S, M)
        Measured friction coefficients (> 0). A 2-D array is ``S`` data sets, fitted
        independently (see ``executor``).
    sigma : float or array, optional
        Standard uncertainty of ``mu_measured`` (> 0), broadcast to its shape.
    params : sequence of str, optional
        Parameter names to vary; default all of ``law.parameters``.
    angle : array, optional
        Measured angle between force and slip, ``beta - theta`` (radians), same shape.
    angle_sigma : float or array, optional
        Its uncertainty (radians); required with ``sigma`` when ``angle`` is given.
    bounds : dict name -> (lo, hi), optional
        Bounds per parameter, overriding :data:`DEFAULT_BOUNDS`.
    confidence : float
        Level of the confidence intervals, ``0 < confidence < 1``.
    executor : concurrent.futures.Executor, optional
        Fits several data sets concurrently (``executor.submit``); the results are identical
        to the serial ones, in the order of the data sets.
    **least_squares_options
        Passed to :func:`scipy.optimize.least_squares`.

    Returns
    -------
    FitResult, or a tuple of them (one per data set) for a 2-D ``mu_measured``.
    """
    mu_m = check_finite("mu_measured", mu_measured)
    if mu_m.ndim not in (1, 2) or mu_m.shape[-1] == 0:
        raise FrictionRulesError(f"mu_measured of shape {mu_m.shape} violates: (M,) or (S, M) "
                                 "with M >= 1")
    theta = _data("theta", theta, mu_m.shape)
    if theta is None:
        raise FrictionRulesError("theta = None violates: the measured slip angles")
    mu_m = _data("mu_measured", mu_m, mu_m.shape, lo=0.0)
    sig = _data("sigma", sigma, mu_m.shape, lo=0.0)
    psi = _data("angle", angle, mu_m.shape)
    psi_sig = _data("angle_sigma", angle_sigma, mu_m.shape, lo=0.0)
    if psi is not None and (sig is None) != (psi_sig is None):
        raise FrictionRulesError("angle_sigma violates: give both sigma and angle_sigma, or "
                                 "neither (the two misfits are weighted alike then)")
    confidence = check_scalar("confidence", confidence, lo=0.0, hi=1.0, lo_open=True,
                              hi_open=True)
    names = _names(law, params)
    data = dict(theta=theta, mu_m=mu_m, sig=sig, psi=psi, psi_sig=psi_sig)
    if mu_m.ndim == 1:
        jobs = [data]
    else:
        jobs = [{k: None if v is None else v[i] for k, v in data.items()}
                for i in range(len(mu_m))]
    common = dict(names=names, bounds=bounds, confidence=confidence,
                  options=least_squares_options)
    if executor is None:
        out = [_fit_one(law, **job, **common) for job in jobs]
    else:
        futures = [executor.submit(_fit_one, law, **job, **common) for job in jobs]
        out = [f.result() for f in futures]
    return tuple(out) if mu_m.ndim == 2 else out[0]


def _names(law, params) -> list[str]:
    values = law.parameters
    names = list(values) if params is None else list(params)
    for name in names:
        if name not in values:
            raise FrictionRulesError(f"params entry {name!r} violates: a numeric parameter of "
                                     f"{type(law).__name__} ({sorted(values)})")
    if not names:
        raise FrictionRulesError(f"params violates: {type(law).__name__} has no numeric "
                                 "parameter to fit")
    return names


def _fit_one(law, *, theta, mu_m, sig, psi, psi_sig, names, bounds, confidence,
             options) -> FitResult:
    """One data set (module level, so that process pools can run it)."""
    least_squares = require("scipy.optimize", purpose="fit").least_squares
    stats = require("scipy.stats", purpose="fit")

    bnd = {**DEFAULT_BOUNDS, **(bounds or {})}
    lo = np.array([bnd.get(k, (-np.inf, np.inf))[0] for k in names], dtype=float)
    hi = np.array([bnd.get(k, (-np.inf, np.inf))[1] for k in names], dtype=float)
    start = law.parameters
    x0 = np.clip(np.array([float(start[k]) for k in names]), lo, hi)
    s_phi = np.ones_like(mu_m) if sig is None else sig / (1.0 + mu_m**2)
    s_psi = None if psi is None else (np.ones_like(psi) if psi_sig is None else psi_sig)

    def make(x):
        return law.replace(**dict(zip(names, map(float, x))))

    def residual(x):
        mu, model_psi, locked = _model(make(x), theta, psi is not None)
        r = (np.arctan(mu) - np.arctan(mu_m)) / s_phi
        if psi is not None:   # no force slides a locked direction: the largest misfit, pi/2
            miss = np.where(locked, np.pi / 2, _wrap(model_psi - psi))
            r = np.concatenate((r, miss / s_psi))
        return r

    sol = least_squares(residual, x0, bounds=(lo, hi), **options)
    fitted = make(sol.x)
    mu, model_psi, locked = _model(fitted, theta, psi is not None)
    r = sol.fun
    m, p = len(r), len(names)
    dof = m - p
    chi2 = float(r @ r)
    cov = _covariance(sol.jac, sol.x)
    if sig is None:
        cov = cov * (chi2 / dof if dof > 0 else np.inf)
        q = float(stats.t.ppf(0.5 + confidence / 2.0, dof)) if dof > 0 else np.inf
    else:
        q = float(stats.norm.ppf(0.5 + confidence / 2.0))
    with np.errstate(invalid="ignore"):
        stderr = np.sqrt(np.where(np.isfinite(np.diag(cov)), np.abs(np.diag(cov)), np.inf))
    at_bound = np.asarray(sol.active_mask) != 0
    pars = tuple(FittedParameter(
        name=k, value=float(v), stderr=float(e), at_bound=bool(b),
        low=float(max(v - q * e, lo_k)) if np.isfinite(e) else float(lo_k),
        high=float(min(v + q * e, hi_k)) if np.isfinite(e) else float(hi_k))
        for k, v, e, b, lo_k, hi_k in zip(names, sol.x, stderr, at_bound, lo, hi))
    res = mu - mu_m
    fin = np.isfinite(res)
    noise = 1.0 if sig is not None else (np.sqrt(chi2 / dof) if dof > 0 else 1.0)
    return FitResult(
        law=fitted, parameters=pars, confidence=confidence, theta=theta, mu_measured=mu_m,
        sigma=sig, mu_model=mu, locked=locked, residuals=res,
        normalized_residuals=r[:len(theta)] / (noise if noise > 0 else 1.0),
        angle_residuals=None if psi is None else np.where(locked, np.inf,
                                                          _wrap(model_psi - psi)),
        rms=float(np.sqrt(np.mean(res[fin] ** 2))) if fin.any() else np.inf,
        chi2=chi2, dof=dof, covariance=cov, cost=float(sol.cost), success=bool(sol.success),
        message=str(sol.message), n_eval=int(sol.nfev))


#: A combination of parameters is undetermined when changing them by 100 % (or by 1 where
#: they are smaller than 1) moves the residual vector by less than this fraction of
#: ``max(largest such move, sqrt(m))``: the Jacobian is finite-differenced to a relative
#: accuracy of about 1e-8, so smaller singular values are not distinguishable from zero.
_RANK_RTOL = 1e-6


def _covariance(J: np.ndarray, x: np.ndarray) -> np.ndarray:
    """``(J^T J)^-1`` by SVD of the Jacobian in relative parameter changes; directions of
    zero singular value (:data:`_RANK_RTOL`) get infinite variance."""
    scale = np.maximum(np.abs(x), 1.0)
    _, s, vt = np.linalg.svd(J * scale, full_matrices=False)
    tiny = s <= _RANK_RTOL * max(s[0] if len(s) else 0.0, np.sqrt(len(J)))
    cov = (vt[~tiny].T / s[~tiny] ** 2) @ vt[~tiny]
    if tiny.any():
        free = np.any(np.abs(vt[tiny]) > 1e-8, axis=0)      # parameters in the null space
        cov[free, :] = np.inf
        cov[:, free] = np.inf
    return cov * scale[:, None] * scale[None, :]


def compare_fits(theta, mu_measured, laws: dict, **options) -> dict:
    """Fit every law of ``{name: initial law}`` to the same data; ``{name: FitResult}``."""
    return {name: fit(law, theta, mu_measured, **options) for name, law in laws.items()}


def format_fits(results: dict) -> str:
    """A plain-text table: model, rms of mu, max |residual|, reduced chi2, fitted parameters
    with their confidence intervals."""
    head = ("model", "rms(mu)", "max|res|", "chi2/dof", "parameters")
    rows = []
    for name, r in results.items():
        fin = np.isfinite(r.residuals)
        mx = float(np.max(np.abs(r.residuals[fin]))) if fin.any() else float("inf")
        rows.append((name, f"{r.rms:.4g}", f"{mx:.4g}", f"{r.reduced_chi2:.3g}",
                     ", ".join(f"{p.name}={p.value:.4g} [{p.low:.4g}, {p.high:.4g}]"
                               + (" (at bound)" if p.at_bound else "")
                               for p in r.parameters)))
    widths = [max(len(x[i]) for x in [head, *rows]) for i in range(len(head))]
    line = "  ".join("{:<%d}" % w for w in widths)
    return "\n".join([line.format(*head), line.format(*("-" * w for w in widths)),
                      *(line.format(*r) for r in rows)])
