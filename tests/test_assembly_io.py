"""Assembly runs: the HDF5 run file and resuming, the CLI, random packings."""

import io
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


def test_random_packing_numbers_its_grains_by_position():
    """Grains numbered by the bins they lie in: consecutive grains are neighbours (the dynamic
    engine's passes then read memory in order), the radii unchanged as a set."""
    a = random_packing(2000, 3, polydispersity=0.2, solid_fraction=0.2, seed=1)
    L = a.cell[0, 0]

    def distance(u, v):
        d = (u - v) - L * np.round((u - v) / L)
        return np.linalg.norm(d, axis=1)

    consecutive = distance(a.positions[1:], a.positions[:-1]).mean()
    shuffled = np.random.default_rng(0).permutation(len(a.radii))
    anywhere = distance(a.positions[shuffled[1:]], a.positions[shuffled[:-1]]).mean()
    assert consecutive < 0.5 * anywhere
    rng = np.random.default_rng(1)
    np.testing.assert_allclose(np.sort(a.radii), np.sort(1 + 0.2 * rng.uniform(-1, 1, 2000)))


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


def _write(path, sample, law, loading):
    path.write_text(f"[sample]\n{sample}\n[model]\nkn = 1e6\nkt = 1e6\n[model.law]\n{law}\n"
                    f"[loading]\n{loading}\n")
    return path


def _cli(*args):
    return subprocess.run([sys.executable, "-m", "frictionrules", "assembly", *map(str, args)],
                          capture_output=True, text=True)


def test_cli_run_that_stops_unconverged_exits_1(tmp_path):
    """Without cuts the plateau increment of the associated rule in plane strain does not
    converge: the run stops before a peak is detected; it says so (no infinite strength) and
    exits 1."""
    cfg = _write(tmp_path / "stop.toml", 'lattice = "fcc"\nframe = "layer"',
                 'type = "Coulomb"\nmu = 0.3\ndilatant = true',
                 'kind = "plane_strain"\npressure = 1.0\naxial_strain = 2e-4\nincrements = 40\n'
                 'max_cuts = 0')
    res = _cli(cfg, "--out", tmp_path / "stop.h5")
    assert res.returncode == 1, res.stderr
    assert "did not converge" in res.stdout and "inf" not in res.stdout
    assert "no peak reached before the run stopped at axial strain" in res.stdout
    assert "largest σ1/σ3 4.779" in res.stdout


def test_cli_refuses_a_random_packing_too_small(tmp_path):
    cfg = _write(tmp_path / "two.toml", "random = true\nn = 2\ndim = 3",
                 'type = "Coulomb"\nmu = 0.3', 'kind = "axisymmetric"\npressure = 1.0')
    res = _cli(cfg, "--out", tmp_path / "two.h5")
    assert res.returncode == 2 and res.stderr.count("\n") == 1
    assert "n = 2 violates: an integer >= 10" in res.stderr and "two largest diameters" in res.stderr
    assert not (tmp_path / "two.h5").exists()


class _Terminal(io.StringIO):
    def isatty(self):
        return True


def test_cli_shows_preparation_and_no_peak_without_failure(tmp_path, monkeypatch, capsys):
    """The frictionless compression and the consolidation show on the progress line; a sample
    that never fails (μ = 1.2 locks Thornton's array) reports how far it went, not a peak."""
    from frictionrules.cli import main
    cfg = _write(tmp_path / "lock.toml", 'lattice = "fcc"', 'type = "Coulomb"\nmu = 1.2',
                 'kind = "axisymmetric"\npressure = 1.0\naxial_strain = 1e-4\nincrements = 5\n'
                 'consolidation = "frictionless"')
    terminal = _Terminal()
    monkeypatch.setattr(sys, "stderr", terminal)
    assert main(["assembly", str(cfg), "--out", str(tmp_path / "lock.h5")]) == 0
    shown = terminal.getvalue()
    assert "consolidation (frictionless): p/p* = " in shown
    assert "consolidation to pressure 1" in shown and "\r" in shown
    out = capsys.readouterr().out
    assert "no peak up to axial strain" in out and "inf" not in out
