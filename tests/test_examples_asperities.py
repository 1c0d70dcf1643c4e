"""The asperity examples run and give their numbers."""

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


def test_asperity_two_flank_example(capsys):
    mu_y = load("asperity_two_flank").main()
    # distance from the origin to the line (2.12): (s1 + s2) / sqrt((c1 + c2)^2 + sin^2(a2 - a1))
    a1, a2 = np.pi / 3, 5 * np.pi / 6
    want = (np.sin(a1) + np.sin(a2)) / np.hypot(np.cos(a1) + np.cos(a2), np.sin(a2 - a1))
    assert mu_y == pytest.approx(want, rel=1e-9)
    assert "226.67" in capsys.readouterr().out


def test_asperity_heightmap_fit_example():
    rms = load("asperity_heightmap_fit").main(n=128)
    assert rms < 0.05
