"""Instrument files read with SurfaceTopography (the ``surfaces`` extra) into friction laws.

The three files in ``../shared/surfaces/`` or ``$FRICTIONRULES_SURFACES`` (an AFM map, an X3P map with non-square pixels, a
stylus profile). Without them or without SurfaceTopography these tests skip, except on CI
(``CI=true``), where they fail: the data and the extra are part of the test setup.
"""

import importlib.util
import os
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

from frictionrules import FrictionRulesError, from_topography, read_surface
from frictionrules.cli import main

SURFACES = Path(__file__).resolve().parents[1].parent / "shared" / "surfaces"
if not SURFACES.is_dir():
    SURFACES = Path(os.environ.get("FRICTIONRULES_SURFACES", SURFACES))
FILES = ("di-1.di", "x3p-2.x3p", "opdx-3.opdx")
MU = 0.3


def shared(name):
    path = SURFACES / name
    missing = [] if path.is_file() else [str(path)]
    if importlib.util.find_spec("SurfaceTopography") is None:
        missing.append("SurfaceTopography (pip install 'frictionrules[surfaces]')")
    if missing:
        if os.environ.get("CI") == "true":
            pytest.fail(f"missing on CI: {missing}")
        pytest.skip(f"missing: {missing}")
    return path


def law(name, **kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        return from_topography(read_surface(shared(name)), MU, **kwargs)


@pytest.mark.parametrize("name", FILES)
def test_default_scale_gives_mu_between_mu_and_the_steepest_climb(name):
    """mu <= mu(theta) <= tan(atan s_max + atan mu) at the default scale (five pixels), and
    the scale is recorded in the file's unit."""
    topo = read_surface(shared(name))
    r = law(name)
    assert r.scale == pytest.approx(5.0 * max(np.atleast_1d(topo.pixel_size)))
    assert r.unit == topo.unit and r.detrend == "plane"
    lo, hi = r.mu_range
    assert MU * (1 - 1e-12) <= lo <= hi <= r.upper_bound * (1 + 1e-12)
    assert not r.locked.any()


def test_x3p_heights_are_turned_to_rows_along_y():
    """X3P map 650 x 650 with pixels 0.128 x 0.315 um: frictionrules' h[iy, ix] is
    SurfaceTopography's heights()[ix, iy] transposed, with dx along the rows."""
    topo = read_surface(shared("x3p-2.x3p"))
    r = law("x3p-2.x3p", scale=0.0, detrend="none", n=8)
    h = topo.heights()
    from frictionrules import from_heightmap
    ref = from_heightmap(h.T, *topo.pixel_size, MU).friction_coefficient(r.theta)
    np.testing.assert_allclose(r.mu, ref, rtol=1e-12)
    assert r.pixel_size == tuple(topo.pixel_size) and r.shape == h.T.shape


def test_afm_map_raw_is_set_by_scan_line_steps_and_warns():
    """The raw AFM map locks in most directions (scan-line steps of 80 deg); the result says
    so (locked flags, warnings); levelling the scan lines removes the locking."""
    raw = law("di-1.di", scale=0.0, n=90)
    assert raw.locked.sum() > 80 and raw.warnings
    rows = law("di-1.di", scale=0.0, detrend="rows", n=90)
    assert not rows.locked.any()


def test_stylus_profile_is_one_dimensional():
    r = law("opdx-3.opdx", n=36)
    assert r.shape == (3001,) and len(r.pixel_size) == 1
    np.testing.assert_allclose(r.mu[[9, 27]], MU, rtol=1e-6)    # along the ridges: flat facets


def test_cli_reads_an_instrument_file(tmp_path, capsys):
    path = shared("opdx-3.opdx")
    assert main(["asperity", str(path), "--mu", "0.3", "--n", "72"]) == 0
    out = capsys.readouterr().out
    assert "scale" in out and "µm" in out and "mu(theta)" in out
    assert not any(tmp_path.iterdir())


def test_read_surface_errors(tmp_path, monkeypatch):
    shared("opdx-3.opdx")
    bad = tmp_path / "bad.di"
    bad.write_bytes(b"not a topography")
    with pytest.raises(FrictionRulesError, match="not a readable topography"):
        read_surface(bad)
    with pytest.raises(FrictionRulesError, match="no such file"):
        read_surface(tmp_path / "missing.x3p")
    monkeypatch.setitem(sys.modules, "SurfaceTopography", None)
    with pytest.raises(FrictionRulesError, match=r"frictionrules\[surfaces\]"):
        read_surface(bad)
