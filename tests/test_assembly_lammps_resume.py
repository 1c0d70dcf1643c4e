"""The triaxial test in LAMMPS resumed from its own restart files by running the same command
again (``frictionrules assembly ... --engine lammps --lammps-dir DIR --restart-every E``;
``triaxial(..., engine="lammps", lammps_dir=DIR, restart_every=E)``): a run stopped by its
time limit, or anywhere (a restart file or a record half written), then run again, gives the
records and centres of the run that was never stopped, bit for bit (one rank: LAMMPS repeats a
run from a restart file exactly, docs/assembly.md, "Restarts"); a finished run is read back
without running LAMMPS; a bad value exits 2 with one line.

The runs need the ``lammps`` extra and a C and a C++ compiler: they skip without them, except
in CI (``CI=true``), where they fail."""

from __future__ import annotations

import shutil
import types

import numpy as np
import pytest

import frictionrules as fr
from frictionrules import FrictionRulesError
from frictionrules.assembly import read_config
from frictionrules.cli import main
from test_assembly_lammps import need_lammps

#: A small test: 200 spheres with a dilatant UserLaw, records every 0.1 % of axial strain (of
#: 1,364 steps; a record's strain is a little below 0.1 %: 0.45 % takes 5 records).
CONFIG = """[sample]
random = true
n = 200
dim = 3
polydispersity = 0.2
seed = 1
[model]
kn = 1e4
kt = 1e4
[model.law]
type = "UserLaw"
limit = "sqrt(T1**2 + T2**2) - mu*N"
potential = "sqrt(T1**2 + T2**2) - beta*N"
params = {{ mu = 0.3, beta = 0.1 }}
[loading]
kind = "axisymmetric"
pressure = 1.0
axial_strain = {strain}
method = "dem"
record_every = 1e-3
"""


def command(cfg, folder, *extra):
    return ["assembly", str(cfg), "--engine", "lammps", "--lammps-dir", str(folder),
            "--restart-every", "0.002", "--quiet", *extra]


@pytest.fixture(scope="module")
def whole(tmp_path_factory):
    """The uninterrupted run (5 records: segments of 2, 2 and 1 records)."""
    need_lammps()
    root = tmp_path_factory.mktemp("lammps_resume")
    cfg = root / "run.toml"
    cfg.write_text(CONFIG.format(strain=0.0045))
    folder = root / "whole"
    assert main(command(cfg, folder)) == 0
    sample = read_config(cfg)[0]
    return cfg, folder, sample, fr.read_lammps_triaxial(sample, folder)


def same_run(a, b):
    assert len(a.axial_strain) == len(b.axial_strain)
    np.testing.assert_array_equal(a.stress, b.stress)
    np.testing.assert_array_equal(a.axial_strain, b.axial_strain)
    np.testing.assert_array_equal(a.positions, b.positions)
    np.testing.assert_array_equal(a.coordination, b.coordination)
    np.testing.assert_array_equal(a.sliding_fraction, b.sliding_fraction)


def test_the_last_segment_ends_at_the_shears_last_step(whole):
    """5 records and restart files every 2: segments of 2, 2 and 1 records (the shear ends
    where it would without restart files: 5 records, not 6)."""
    _, folder, _, r = whole
    steps = sorted(int(p.name.split(".")[1]) for p in folder.glob("shear.*.restart"))
    assert len(r.axial_strain) == 6 and steps[0] * 5 == steps[-1] * 2
    assert len(steps) == 3 and steps[1] == 2 * steps[0]
    assert r.message.startswith("completed; engine lammps")


def test_a_run_stopped_anywhere_resumes_to_the_uninterrupted_records(whole, tmp_path, capsys):
    """The state a stop leaves (time limit, a killed job): the restart files after the first
    gone, the next one half written, a record and a dump cut short, no "shear done". The same
    command resumes from the last complete restart file and gives the uninterrupted run's
    records and centres, bit for bit."""
    cfg, full, sample, r = whole
    folder = tmp_path / "stopped"
    shutil.copytree(full, folder)
    files = sorted(folder.glob("shear.*.restart"), key=lambda p: int(p.name.split(".")[1]))
    first, second = files[0], files[1]
    data = second.read_bytes()
    second.write_bytes(data[:len(data) // 2])    # killed while writing it
    files[2].unlink()
    step = int(second.name.split(".")[1])
    lines = (folder / "records.txt").read_text().splitlines()
    kept = [ln for ln in lines if ln.startswith("#") or int(ln.split()[0]) <= step]
    (folder / "records.txt").write_text("\n".join(kept) + "\n" + kept[-1][:40])
    dump = (folder / "positions.dump").read_text()
    (folder / "positions.dump").write_text(dump[:int(len(dump) * 0.9)])
    stages = (folder / "stages.txt").read_text().replace(
        [ln for ln in (folder / "stages.txt").read_text().splitlines() if "shear done" in ln][0]
        + "\n", "")
    (folder / "stages.txt").write_text(stages)
    capsys.readouterr()
    assert main(command(cfg, folder)) == 0
    out = capsys.readouterr().out
    assert f"completed (resumed from {first.name})" in out
    same_run(r, fr.read_lammps_triaxial(sample, folder))


def test_time_limit_then_the_same_command(whole, tmp_path, monkeypatch, capsys):
    """``--max-time``: LAMMPS is stopped (here once the third record is in, by a clock that
    jumps then: past the first restart file) with the records so far; the same command
    without the limit resumes and gives the uninterrupted run's records, bit for bit."""
    from frictionrules.assembly._lammps import _runner
    cfg, _, sample, r = whole
    folder = tmp_path / "limited"
    real = _runner.time

    def clock():
        return 1e9 if len(_runner._records(folder)) >= 4 else 0.0
    monkeypatch.setattr(_runner, "time", types.SimpleNamespace(sleep=real.sleep, monotonic=clock))
    main(command(cfg, folder, "--max-time", "100"))
    stopped = capsys.readouterr().out
    monkeypatch.setattr(_runner, "time", real)
    assert main(command(cfg, folder)) == 0
    again = capsys.readouterr().out
    if "stopped: max_time = 100.0 s reached" in stopped:    # after a restart file: resumed
        assert "completed (resumed from shear." in again
    else:    # LAMMPS had finished before the clock stopped it: read back
        assert "completed (read back" in again
    same_run(r, fr.read_lammps_triaxial(sample, folder))


def test_a_finished_run_is_read_back_without_running_lammps(whole, tmp_path, capsys):
    cfg, full, sample, r = whole
    folder = tmp_path / "done"
    shutil.copytree(full, folder)
    (folder / "pair").rename(folder / "moved")    # LAMMPS could not load the law: nothing runs
    log = (folder / "log.lammps").read_text()
    capsys.readouterr()
    assert main(command(cfg, folder)) == 0
    assert "completed (read back: this run had finished in this folder)" in capsys.readouterr().out
    assert (folder / "log.lammps").read_text() == log
    same_run(r, fr.read_lammps_triaxial(sample, folder))


def test_another_run_in_the_folder_starts_afresh(whole, tmp_path, capsys):
    """Other options (here the axial strain: 4 records, segments of 2 and 2) in a folder
    of another run: the files are written anew and the run starts from the sample."""
    cfg, full, sample, _ = whole
    folder = tmp_path / "other"
    shutil.copytree(full, folder)
    other = tmp_path / "other.toml"
    other.write_text(CONFIG.format(strain=0.0035))
    capsys.readouterr()
    assert main(command(other, folder)) == 0
    out = capsys.readouterr().out
    assert "resumed" not in out and "read back" not in out
    r = fr.read_lammps_triaxial(sample, folder)
    assert len(r.axial_strain) == 5
    assert len(list(folder.glob("shear.*.restart"))) == 2


@pytest.mark.parametrize("args, message", [
    (["--restart-every", "0"], "--restart-every = 0.0 violates: > 0"),
    (["--restart-every", "-1e-3"], "--restart-every = -0.001 violates: > 0"),
    (["--restart-every", "0.0015"], "restart_every = 0.0015 violates: a whole number of "
                                    "record_every = 0.001"),
])
def test_bad_restart_every_exits_2_with_one_line(whole, tmp_path, capsys, args, message):
    cfg = whole[0]
    capsys.readouterr()
    code = main(["assembly", str(cfg), "--engine", "lammps", "--lammps-dir",
                 str(tmp_path / "bad"), "--quiet", *args])
    err = capsys.readouterr().err.strip()
    assert code == 2 and message in err and len(err.splitlines()) == 1


def test_restart_every_is_an_option_of_lammps(tmp_path, capsys):
    """Refused with our engine rather than ignored (the command line and triaxial)."""
    cfg = tmp_path / "run.toml"
    cfg.write_text(CONFIG.format(strain=0.0035).replace("n = 200", "n = 20"))
    code = main(["assembly", str(cfg), "--out", str(tmp_path / "r.h5"), "--restart-every",
                 "0.002", "--quiet"])
    err = capsys.readouterr().err.strip()
    assert code == 2 and "--restart-every = 0.002 violates: an option of --engine lammps" in err
    sample = read_config(cfg)[0]
    with pytest.raises(FrictionRulesError, match="restart_every = 0.002 violates: None for "
                                                 "engine = 'frictionrules'"):
        fr.triaxial(sample, "axisymmetric", pressure=1.0, method="dem", restart_every=0.002)
