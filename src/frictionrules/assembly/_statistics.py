r"""The statistics of an ensemble of loading tests: each run's end values, the mean of a
quantity over the samples with its 95 % confidence interval (Student's t), and mean curves
against the axial strain with their bands.

For ``n`` values :math:`x_i` of one condition, the mean :math:`\bar x`, the sample standard
deviation :math:`s = \sqrt{\sum (x_i - \bar x)^2/(n - 1)}` and the interval

.. math:: \bar x \pm t_{0.975,\,n-1}\, s/\sqrt n ,

which holds the mean of the population with probability 0.95 where the values are
independent draws of a normal distribution (approximately so for other distributions as
``n`` grows). With one value the interval is unbounded (``low = -inf``, ``high = inf``): one
sample says nothing of the spread; with none, every field but ``n`` is NaN.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["ConfidenceInterval", "MeanCurve", "QUANTITIES", "CURVES", "interval", "t_quantile",
           "end_values", "friction_angle", "mean_curve"]

#: The quantities of an ensemble's summary, with their units (``docs/conventions.md``).
QUANTITIES = {"peak_friction_angle": "deg", "critical_friction_angle": "deg",
              "volumetric_strain_end": "1", "coordination_end": "1", "sliding_fraction_end": "1"}

#: The curves :func:`mean_curve` averages, with their units.
CURVES = {"stress_ratio": "1", "friction_angle": "deg", "volumetric_strain": "1",
          "coordination": "1"}

#: Confidence level of the intervals.
LEVEL = 0.95


def t_quantile(df: int) -> float:
    """The two-sided 95 % quantile :math:`t_{0.975,\\,df}` of Student's t distribution."""
    from .._optional import require
    require("scipy", extra="solvers", purpose="confidence intervals")
    from scipy.special import stdtrit
    return float(stdtrit(df, 0.5 + LEVEL / 2))


@dataclass(frozen=True)
class ConfidenceInterval:
    """The mean of ``n`` values and its 95 % confidence interval (module docstring).

    Attributes
    ----------
    n : int
        Number of values (runs) the mean is over.
    mean : float
        Their mean (NaN for ``n = 0``).
    low, high : float
        The interval's ends: ``mean ∓ half_width`` (``-inf``, ``inf`` for ``n = 1``; NaN for
        ``n = 0``).
    half_width : float
        :math:`t_{0.975,n-1}\\,s/\\sqrt n` (``inf`` for ``n = 1``).
    std : float
        The sample standard deviation ``s`` (``ddof = 1``; NaN for ``n <= 1``: undefined).
    """

    n: int
    mean: float
    low: float
    high: float
    half_width: float
    std: float

    def __str__(self) -> str:
        if self.n == 0:
            return "no run"
        if self.n == 1:
            return f"{self.mean:.6g} (n = 1: no interval)"
        return f"{self.mean:.6g} ± {self.half_width:.3g} (n = {self.n})"


def interval(values) -> ConfidenceInterval:
    """The :class:`ConfidenceInterval` of a sequence of finite values."""
    x = np.asarray(values, dtype=float).ravel()
    n = len(x)
    if n == 0:
        nan = math.nan
        return ConfidenceInterval(0, nan, nan, nan, nan, nan)
    mean = float(np.mean(x))
    if n == 1:
        return ConfidenceInterval(1, mean, -math.inf, math.inf, math.inf, math.nan)
    std = float(np.std(x, ddof=1))
    half = t_quantile(n - 1) * std / math.sqrt(n)
    return ConfidenceInterval(n, mean, mean - half, mean + half, half, std)


def friction_angle(ratio) -> np.ndarray:
    r"""Mobilized friction angle (degrees) of the stress ratio :math:`R = \sigma_1/\sigma_3`:
    :math:`\sin\varphi = (R - 1)/(R + 1)` (90 for ``R = inf``)."""
    r = np.asarray(ratio, dtype=float)
    with np.errstate(invalid="ignore", divide="ignore"):
        s = np.where(np.isinf(r), 1.0, (r - 1) / (r + 1))
    return np.degrees(np.arcsin(np.clip(s, -1.0, 1.0)))


def _sliding_fraction(result) -> float:
    """The fraction of the force-carrying contacts that slide, at the last row."""
    if result.sliding_fraction is not None:
        return float(result.sliding_fraction[-1])
    snap = result.contacts[-1]
    carrying = snap.force[:, 2] > 0
    return float(np.count_nonzero(carrying & (snap.status == 1)) / max(1, np.count_nonzero(carrying)))


def end_values(result) -> dict:
    """The summary's quantities of one completed run (:data:`QUANTITIES`); the peak is None
    where the sample did not fail.

    ``critical_friction_angle`` is the mean of the friction angle over the rows of the last
    fifth of the axial strain, ``ε_a >= ε_a0 + 0.8 (ε_a,end - ε_a0)``.
    """
    ok = np.asarray(result.converged, dtype=bool)
    ax = result.axial_strain[ok]
    last = ax >= ax[0] + 0.8 * (ax[-1] - ax[0])
    return {"peak_friction_angle": float(result.peak_friction_angle) if result.failed else None,
            "critical_friction_angle": float(np.mean(friction_angle(result.stress_ratio[ok][last]))),
            "volumetric_strain_end": float(result.volumetric_strain[ok][-1]),
            "coordination_end": float(result.coordination[ok][-1]),
            "sliding_fraction_end": _sliding_fraction(result)}


@dataclass(frozen=True, eq=False)
class MeanCurve:
    """The mean of a curve over the runs of one condition, against the axial strain, with its
    95 % band (the confidence interval of the mean at each strain).

    Attributes
    ----------
    quantity : str
        One of :data:`CURVES`.
    axial_strain : (k,)
        The common strains: from the largest first to the smallest last strain of the runs,
        as many points as the longest run has rows.
    mean, low, high : (k,)
        The mean and the interval's ends at each strain (``±inf`` where ``n = 1``).
    n : int
        Number of runs.
    """

    quantity: str
    axial_strain: np.ndarray
    mean: np.ndarray
    low: np.ndarray
    high: np.ndarray
    n: int


def _curve(result, quantity: str) -> np.ndarray:
    if quantity == "friction_angle":
        return friction_angle(result.stress_ratio)
    return np.asarray(getattr(result, quantity), dtype=float)


def mean_curve(results, quantity: str) -> MeanCurve:
    """The :class:`MeanCurve` of ``quantity`` over ``results`` (completed runs, each sampled
    linearly at the common strains)."""
    results = list(results)
    if not results:
        empty = np.zeros(0)
        return MeanCurve(quantity, empty, empty, empty, empty, 0)
    ok = [np.asarray(r.converged, dtype=bool) for r in results]
    axes = [r.axial_strain[k] for r, k in zip(results, ok)]
    a0, a1 = max(a[0] for a in axes), min(a[-1] for a in axes)
    grid = np.linspace(a0, a1, max(len(a) for a in axes))
    values = np.array([np.interp(grid, a, _curve(r, quantity)[k]) for r, a, k in zip(results, axes, ok)])
    n = len(results)
    mean = values.mean(axis=0)
    if n == 1:
        half = np.full_like(mean, np.inf)
    else:
        half = t_quantile(n - 1) * values.std(axis=0, ddof=1) / math.sqrt(n)
    return MeanCurve(quantity, grid, mean, mean - half, mean + half, n)
