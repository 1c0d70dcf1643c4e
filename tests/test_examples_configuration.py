"""The configuration examples run and give their headline numbers."""

import importlib.util
from pathlib import Path

import numpy as np
import pytest

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def load(name):
    spec = importlib.util.spec_from_file_location(name, EXAMPLES / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_cylinder_softening_example():
    out = load("configuration_cylinder_softening").main()
    assert out["order"] == pytest.approx(1.0, abs=0.1)
    assert out["limit_force"] == pytest.approx(np.tan(np.pi / 6 + np.arctan(0.3)), rel=1e-9)


def test_sphere_pocket_example():
    out = load("configuration_sphere_pocket").main()
    assert out["ridge_peak"] == pytest.approx(0.7977, abs=1e-4)     # force at 60 deg, over two
    assert out["over_one_peak"] == pytest.approx(np.tan(np.arcsin(3**-0.5) + np.arctan(0.3)))
