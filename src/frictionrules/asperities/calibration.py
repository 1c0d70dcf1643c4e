r"""Calibration: fit a law's parameters to a measured directional friction coefficient mu(theta).

Any law of the protocol that is a frozen dataclass can be fitted: the law passed in is the
initial guess, the parameters named in ``params`` are varied with
:func:`dataclasses.replace`, and :func:`scipy.optimize.least_squares` minimizes

.. math:: r_i = \arctan\mu_{model}(\theta_i) - \arctan\mu_i
          \;\Bigl[,\ w\,\bigl(\psi_{model}(\theta_i) - \psi_i\bigr)\Bigr],

the friction-angle misfit (bounded, so a trial law that locks in some direction, ``mu = inf``,
still gives a finite residual of at most pi/2) and, when measured, the misfit of the angle
:math:`\psi = \beta - \theta` between force and slip ((1.14)), weighted by ``w``.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from .._optional import require
from ..errors import FrictionRulesError, check_finite, check_scalar

__all__ = ["fit", "FitResult", "compare_fits", "format_fits"]

#: Default bounds by parameter name (override with ``bounds=``).
DEFAULT_BOUNDS = {
    "mu": (1e-6, 10.0), "mu_x": (1e-6, 10.0), "mu_y": (1e-6, 10.0), "mu_1": (1e-6, 10.0),
    "mu_2": (1e-6, 10.0), "angle": (-np.pi, np.pi), "alpha": (1e-3, np.pi - 1e-3),
    "alpha1": (1e-3, np.pi / 2 - 1e-3), "alpha2": (np.pi / 2 + 1e-3, np.pi - 1e-3),
}


@dataclass(frozen=True)
class FitResult:
    """Outcome of :func:`fit`.

    Attributes
    ----------
    law : the fitted law (same class as the initial one).
    params : dict of the fitted parameter values.
    residuals : (M,) ``mu_model - mu_measured`` (``inf`` where the fitted law locks).
    angle_residuals : (M,) force-slip angle misfit in radians, or ``None`` if not fitted.
    rms : root mean square of the finite ``residuals``.
    cost : final least-squares cost (half the sum of squared fit residuals).
    success, message, n_eval : from :func:`scipy.optimize.least_squares`.
    """

    law: object
    params: dict
    residuals: np.ndarray
    angle_residuals: np.ndarray | None
    rms: float
    cost: float
    success: bool
    message: str
    n_eval: int


def _wrap(a):
    return (a + np.pi) % (2.0 * np.pi) - np.pi


def _model(law, theta, want_angle):
    mu = np.asarray(law.friction_coefficient(theta), dtype=float)
    if not want_angle:
        return mu, None
    fin = np.isfinite(mu)
    psi = np.zeros_like(theta)
    if fin.any():
        psi[fin] = _wrap(law.force_angle(theta[fin]) - theta[fin])
    return mu, psi


def fit(law, theta, mu_measured, *, params=None, angle=None, angle_weight: float = 1.0,
        bounds=None, **least_squares_options) -> FitResult:
    """Fit the parameters ``params`` of ``law`` to measured ``mu(theta)``.

    Parameters
    ----------
    law : frozen dataclass law
        The initial guess (its class is the model).
    theta : array (M,)
        Slip angles (radians, from x).
    mu_measured : array (M,)
        Measured friction coefficients (> 0).
    params : sequence of str, optional
        Parameter names to vary; default all float fields of ``law``.
    angle : array (M,), optional
        Measured angle between force and slip, ``beta - theta`` (radians).
    angle_weight : float
        Weight of the angle misfit against the friction-angle misfit.
    bounds : dict name -> (lo, hi), optional
        Bounds per parameter, overriding :data:`DEFAULT_BOUNDS`.
    **least_squares_options
        Passed to :func:`scipy.optimize.least_squares`.

    Returns
    -------
    FitResult
    """
    least_squares = require("scipy.optimize", extra="solvers").least_squares

    if not dataclasses.is_dataclass(law):
        raise FrictionRulesError(f"law = {law!r} violates: must be a dataclass law")
    theta = check_finite("theta", theta).ravel()
    mu_m = check_finite("mu_measured", mu_measured).ravel()
    if theta.shape != mu_m.shape or len(theta) == 0:
        raise FrictionRulesError(f"theta and mu_measured must have the same nonzero length, got "
                                 f"{theta.shape} and {mu_m.shape}")
    if np.any(mu_m <= 0):
        raise FrictionRulesError(f"mu_measured = {mu_m.min()!r} violates mu_measured > 0")
    psi_m = None
    if angle is not None:
        psi_m = check_finite("angle", angle).ravel()
        if psi_m.shape != theta.shape:
            raise FrictionRulesError(f"angle must have the shape of theta {theta.shape}, got "
                                     f"{psi_m.shape}")
    angle_weight = check_scalar("angle_weight", angle_weight, lo=0.0)
    fields = {f.name: getattr(law, f.name) for f in dataclasses.fields(law)}
    if params is None:
        params = [k for k, v in fields.items() if isinstance(v, float)]
    params = list(params)
    for name in params:
        if name not in fields or not isinstance(fields[name], (float, int)):
            raise FrictionRulesError(f"params entry {name!r} violates: a float field of "
                                     f"{type(law).__name__} ({sorted(fields)})")
    bnd = {**DEFAULT_BOUNDS, **(bounds or {})}
    lo = np.array([bnd.get(k, (-np.inf, np.inf))[0] for k in params], dtype=float)
    hi = np.array([bnd.get(k, (-np.inf, np.inf))[1] for k in params], dtype=float)
    x0 = np.clip(np.array([float(fields[k]) for k in params]), lo, hi)

    def make(x):
        return dataclasses.replace(law, **dict(zip(params, map(float, x))))

    def residual(x):
        mu, psi = _model(make(x), theta, psi_m is not None)
        r = np.arctan(mu) - np.arctan(mu_m)
        if psi_m is not None:
            r = np.concatenate((r, angle_weight * _wrap(psi - psi_m)))
        return r

    sol = least_squares(residual, x0, bounds=(lo, hi), **least_squares_options)
    fitted = make(sol.x)
    mu, psi = _model(fitted, theta, psi_m is not None)
    res = mu - mu_m
    fin = np.isfinite(res)
    rms = float(np.sqrt(np.mean(res[fin] ** 2))) if fin.any() else float("inf")
    return FitResult(law=fitted, params=dict(zip(params, map(float, sol.x))), residuals=res,
                     angle_residuals=None if psi_m is None else _wrap(psi - psi_m), rms=rms,
                     cost=float(sol.cost), success=bool(sol.success), message=str(sol.message),
                     n_eval=int(sol.nfev))


def compare_fits(theta, mu_measured, laws: dict, **options) -> dict:
    """Fit every law of ``{name: initial law}`` to the same data; ``{name: FitResult}``."""
    return {name: fit(law, theta, mu_measured, **options) for name, law in laws.items()}


def format_fits(results: dict) -> str:
    """A plain-text table: model, rms of mu, max |residual|, fitted parameters."""
    head = ("model", "rms(mu)", "max|res|", "parameters")
    rows = []
    for name, r in results.items():
        fin = np.isfinite(r.residuals)
        mx = float(np.max(np.abs(r.residuals[fin]))) if fin.any() else float("inf")
        rows.append((name, f"{r.rms:.4g}", f"{mx:.4g}",
                     ", ".join(f"{k}={v:.4g}" for k, v in r.params.items())))
    widths = [max(len(x[i]) for x in [head, *rows]) for i in range(4)]
    line = "  ".join("{:<%d}" % w for w in widths)
    return "\n".join([line.format(*head), line.format(*("-" * w for w in widths)),
                      *(line.format(*r) for r in rows)])
