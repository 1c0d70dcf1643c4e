"""The contact examples run and give their headline numbers."""

import importlib.util
from pathlib import Path

import pytest

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def load(name):
    spec = importlib.util.spec_from_file_location(name, EXAMPLES / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_fig10_shear_example():
    out = load("contact_fig10_shear").main()
    assert out[0.4]["peak"] == pytest.approx(0.4803, abs=1e-3)
    assert out[0.4]["final_ratio"] == pytest.approx(0.6, rel=0.01)
    assert out[1.6]["final_ratio"] == pytest.approx(0.6, rel=0.01)


def test_batched_update_example():
    out = load("contact_batched_update").main(n=20_000)
    assert out["plastic"] == 1.0
    assert out["mu_min"] == pytest.approx(0.3, rel=1e-3) and out["mu_max"] == pytest.approx(0.6, rel=1e-3)


def test_drive_toml_example_parses():
    from frictionrules.contact.driver import read_toml
    model, path, opts = read_toml(EXAMPLES / "contact_shear.toml")
    assert len(path) == 410 and opts["beta"] == 0.5
