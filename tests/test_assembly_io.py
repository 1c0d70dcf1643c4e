"""Assembly runs: the HDF5 run file and resuming, the CLI, random packings."""

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from frictionrules import Assembly, ContactModel, Coulomb, FrictionRulesError, triaxial
from frictionrules.assembly._random import random_packing

ROOT = Path(__file__).resolve().parents[1]


def fcc():
    return Assembly.lattice("fcc", ContactModel(Coulomb(0.3), kn=1e6, kt=1e6))


def test_run_file_resumes_without_losing_an_increment(tmp_path):
    run = tmp_path / "run.h5"
    full = triaxial(fcc(), "axisymmetric", pressure=1.0, axial_strain=2e-4, increments=12)
    part = triaxial(fcc(), "axisymmetric", pressure=1.0, axial_strain=2e-4, increments=12,
                    run_file=run, max_time=1e-9)
    assert "max_time" in part.message and len(part.converged) < 13
    done = triaxial(fcc(), "axisymmetric", pressure=1.0, axial_strain=2e-4, increments=12, run_file=run)
    assert done.message == "completed" and len(done.converged) == 13
    np.testing.assert_array_equal(done.stress, full.stress)
    np.testing.assert_array_equal(done.contacts[-1].force, full.contacts[-1].force)


def test_run_file_of_another_run_is_refused(tmp_path):
    run = tmp_path / "run.h5"
    triaxial(fcc(), "axisymmetric", pressure=1.0, axial_strain=2e-4, increments=2, run_file=run)
    with pytest.raises(FrictionRulesError, match="holds another run"):
        triaxial(fcc(), "axisymmetric", pressure=2.0, axial_strain=2e-4, increments=2, run_file=run)


def test_cli_assembly(tmp_path):
    out = tmp_path / "fcc.h5"
    cmd = [sys.executable, "-m", "frictionrules", "assembly", str(ROOT / "examples" / "assembly_fcc.toml"),
           "--out", str(out), "--figure", str(tmp_path / "fcc.png")]
    res = subprocess.run(cmd, capture_output=True, text=True)
    assert res.returncode == 0, res.stderr
    assert "peak σ1/σ3 = 3.71429" in res.stdout
    assert out.stat().st_size > 0 and (tmp_path / "fcc.png").stat().st_size > 1000
    again = subprocess.run(cmd, capture_output=True, text=True)
    assert again.returncode == 0 and "40 increments (completed)" in again.stdout
    bad = subprocess.run(cmd[:-4] + ["--out", str(tmp_path / "fcc.csv")], capture_output=True, text=True)
    assert bad.returncode == 2 and bad.stderr.count("\n") == 1 and "--out" in bad.stderr


def test_cli_bad_config(tmp_path):
    cfg = tmp_path / "bad.toml"
    cfg.write_text('[sample]\nlattice = "bcc"\n[model]\nkn = 1.0\nkt = 1.0\n[model.law]\n'
                   'type = "Coulomb"\nmu = 0.3\n[loading]\nkind = "axisymmetric"\npressure = 1.0\n')
    res = subprocess.run([sys.executable, "-m", "frictionrules", "assembly", str(cfg), "--out",
                          str(tmp_path / "r.h5")], capture_output=True, text=True)
    assert res.returncode == 2 and "name = 'bcc'" in res.stderr


def test_random_packing_seeded_and_dense():
    a = random_packing(30, 2, polydispersity=0.2, seed=5)
    b = random_packing(30, 2, polydispersity=0.2, seed=5)
    c = random_packing(30, 2, polydispersity=0.2, seed=6)
    np.testing.assert_array_equal(a.positions, b.positions)
    assert not np.array_equal(a.positions, c.positions)
    phi = np.pi * np.sum(a.radii**2) / np.linalg.det(a.cell)
    assert 0.78 < phi < 0.9 and a.jammed
    assert np.ptp(a.radii) > 0.2 and np.all(np.abs(a.radii - 1) <= 0.2)


def test_random_assembly_biaxial_few_increments():
    """A random packing of disks: frictionless preparation to the pressure, then shear; the
    power balance holds at every increment."""
    model = ContactModel(Coulomb(0.5), kn=1e4, kt=1e4)
    a = Assembly.random(30, 2, model, polydispersity=0.2, seed=5)
    r = triaxial(a, "biaxial", pressure=1.0, axial_strain=3e-5, increments=3)
    assert r.converged.all()
    assert r.stress[0, 0, 0] == pytest.approx(1.0, rel=1e-8)
    assert r.stress_ratio[-1] > r.stress_ratio[1] > 1
    assert np.all(np.abs(r.contact_work[1:] - r.boundary_work[1:]) <= 1e-8 * np.abs(r.boundary_work[1:]))
