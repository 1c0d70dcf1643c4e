"""Errors raised by frictionrules and the checks that raise them where a bad value enters.

Every check names the argument, the offending value and the constraint, e.g.
``FrictionRulesError: mu = -0.3 violates mu >= 0``.
"""

from __future__ import annotations

import numpy as np

__all__ = ["FrictionRulesError"]


class FrictionRulesError(ValueError):
    """A bad parameter, input or file. Subclass of :class:`ValueError`."""


def _describe(name: str, value, bad: np.ndarray | None = None) -> str:
    arr = np.asarray(value)
    if arr.ndim == 0:
        return f"{name} = {arr.item()!r}"
    if bad is None:
        return f"{name} (shape {arr.shape})"
    idx = np.argwhere(bad)
    first = tuple(int(i) for i in idx[0])
    return (f"{name}[{', '.join(map(str, first))}] = {arr[first].item()!r} "
            f"({int(bad.sum())} of {arr.size} entries)")


def check_finite(name: str, value) -> np.ndarray:
    """Return ``value`` as a float array; raise if any entry is NaN or infinite."""
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise FrictionRulesError(f"{name} = {value!r} is not a real number or array") from exc
    with np.errstate(over="ignore"):    # a sum of huge finite terms may overflow: then look
        if np.isfinite(np.sum(arr)):    # one fast pass: a finite sum has no NaN or inf term
            return arr
    bad = ~np.isfinite(arr)
    if bad.any():
        raise FrictionRulesError(f"{_describe(name, arr, bad)} violates: must be finite")
    return arr


def check_scalar(name: str, value, *, lo=None, hi=None, lo_open=False, hi_open=False) -> float:
    """Return ``value`` as a finite float inside ``[lo, hi]`` (or the open variants)."""
    arr = check_finite(name, value)
    if arr.ndim != 0:
        raise FrictionRulesError(f"{name} must be a scalar, got shape {arr.shape}")
    x = float(arr)
    if lo is not None and (x <= lo if lo_open else x < lo):
        raise FrictionRulesError(f"{name} = {x!r} violates {name} {'>' if lo_open else '>='} {lo}")
    if hi is not None and (x >= hi if hi_open else x > hi):
        raise FrictionRulesError(f"{name} = {x!r} violates {name} {'<' if hi_open else '<='} {hi}")
    return x


def check_nonnegative(name: str, value) -> np.ndarray:
    """Return ``value`` as a finite float array with every entry ``>= 0``."""
    arr = check_finite(name, value)
    if arr.size and arr.min() < 0:
        raise FrictionRulesError(
            f"{_describe(name, arr, arr < 0)} violates {name} >= 0 (compression positive)")
    return arr


def check_vectors(name: str, value, sizes: tuple[int, ...]) -> np.ndarray:
    """Return ``value`` as a finite float array whose last axis has one of ``sizes``."""
    arr = check_finite(name, value)
    if arr.ndim == 0 or arr.shape[-1] not in sizes:
        want = " or ".join(f"(..., {s})" for s in sizes)
        raise FrictionRulesError(f"{name} must have shape {want}, got shape {arr.shape}")
    return arr
