"""The "scaled" preparation of ``benchmarks/assembly_yade.py`` (``benchmarks/_dem_compare.py``):
a compacted packing scaled up by the least factor that leaves no overlap."""

from __future__ import annotations

import importlib.util
import itertools
import sys
from pathlib import Path

import numpy as np
import pytest

BENCHMARKS = Path(__file__).resolve().parents[1] / "benchmarks"


def _module(name):
    spec = importlib.util.spec_from_file_location(name, BENCHMARKS / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules.setdefault(name, module)     # its dataclasses look their module up there
    spec.loader.exec_module(module)
    return module


def _closest_gap_over_images(x, radii, lengths):
    """The smallest surface gap ``|xi − xj + n L| − ri − rj`` over every pair and the 27
    images ``n ∈ {−1, 0, 1}³`` (an independent count: no minimum-image rounding)."""
    best = np.inf
    for shift in itertools.product((-1, 0, 1), repeat=3):
        d = x[:, None, :] - x[None, :, :] + np.array(shift) * lengths
        gap = np.linalg.norm(d, axis=-1) - radii[:, None] - radii[None, :]
        if shift == (0, 0, 0):
            np.fill_diagonal(gap, np.inf)
        best = min(best, float(gap.min()))
    return best


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_scaled_packing_just_touches(seed):
    """After ``_scale_to_contact`` the closest pair (through the periodic images) touches:
    the least gap is 0 to round-off, none is negative; the cell and positions scale by one
    factor (a homogeneous dilation keeps the positions in the cell's frame)."""
    compare = _module("_dem_compare")
    rng = np.random.default_rng(seed)
    lengths = np.array([9.0, 10.0, 11.0])
    x = rng.uniform(0, 1, (40, 3)) * lengths
    radii = rng.uniform(0.8, 1.2, 40)
    y, cell = compare._scale_to_contact(x, radii, np.diag(lengths))
    s = cell[0, 0] / lengths[0]
    assert np.allclose(np.diag(cell), s * lengths, rtol=1e-14) and np.allclose(y, s * x, rtol=1e-14)
    gap = _closest_gap_over_images(y, radii, np.diag(cell))
    assert -1e-12 <= gap <= 1e-9


def test_scaled_packing_without_overlap_is_left_alone():
    """A packing whose grains do not touch is not shrunk (the factor is at least 1)."""
    compare = _module("_dem_compare")
    x = np.array([[1.0, 1.0, 1.0], [5.0, 5.0, 5.0]])
    y, cell = compare._scale_to_contact(x, np.array([1.0, 1.0]), 10 * np.eye(3))
    assert np.allclose(y, x) and np.allclose(cell, 10 * np.eye(3))
