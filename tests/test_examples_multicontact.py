"""The multi-contact examples run and give their one checked number."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pytest

from test_io import FCLIB, needs_fclib

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def load(name):
    spec = importlib.util.spec_from_file_location(name, EXAMPLES / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_wedge_stack_onset_is_wedge_limit_eq_2_2():
    out = load("multicontact_wedge_stack").main()
    assert out["onset"] == pytest.approx(out["closed_form"], rel=1e-9)


def test_orthotropic_block_slip_obeys_inverse_relation_eq_1_13():
    out = load("multicontact_orthotropic_block").main()
    assert out["inverse_gap"] < 1e-12
    assert abs(out["slip_deg"] - 45.0) > 30.0  # the slip is far from the push direction


@needs_fclib
def test_fclib_example_solves_capsules():
    errors = load("multicontact_fclib").main(FCLIB / "Capsules-i125-1213.hdf5")
    assert min(errors.values()) <= 1e-8
    assert np.isfinite(list(errors.values())).all()
