"""Ensembles of loading tests (``frictionrules.ensemble``): the 95 % confidence intervals
against Student's t computed apart (scipy.stats), resuming from a run folder (the runs that
ran counted), a process pool giving the serial numbers, the errors of bad input."""

import concurrent.futures
import functools
import math
import multiprocessing

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import stats

import frictionrules
from frictionrules import (Assembly, ContactModel, Coulomb, EnsembleResult, FrictionRulesError,
                           ensemble, triaxial)

#: Tiny dynamic runs: 30 disks, biaxial to 1 % axial strain, a record every 0.1 %.
RUN = dict(pressure=1.0, axial_strain=1e-2, method="dem", record_every=1e-3)
MODEL = ContactModel(Coulomb(0.5), kn=1e4, kt=1e4)


@pytest.fixture(scope="module")
def samples():
    return [Assembly.random(30, 2, MODEL, polydispersity=0.2, seed=s) for s in (1, 2, 3, 4)]


@pytest.fixture(scope="module")
def serial(samples):
    return ensemble(samples, "biaxial", **RUN)


def _student_t(values):
    """The 95 % interval of the mean of ``values`` by scipy.stats: (mean, low, high)."""
    x = np.asarray(values, dtype=float)
    low, high = stats.t.interval(0.95, len(x) - 1, loc=x.mean(), scale=stats.sem(x))
    return x.mean(), low, high


def test_interval_is_student_t_of_the_runs_end_values(serial, samples):
    """mean ± t(0.975, n-1) s/√n of each quantity, from the runs' own results (the critical
    angle: sin φ = (R-1)/(R+1) averaged over the rows of the last fifth of the axial strain)."""
    assert isinstance(serial, EnsembleResult) and len(serial.runs) == len(samples)
    assert [r.sample for r in serial.runs] == list(range(len(samples)))
    assert all(r.status == "new" and r.completed for r in serial.runs)
    (s,) = serial.summary
    assert s.runs == (0, 1, 2, 3) and s.completed == 4
    results = [r.result for r in serial.runs]
    for result, sample in zip(results, samples):  # each run is the single run of its sample
        alone = triaxial(sample, "biaxial", **RUN)
        np.testing.assert_array_equal(alone.volumetric_strain, result.volumetric_strain)

    def critical(r):
        last = r.axial_strain >= r.axial_strain[0] + 0.8 * (r.axial_strain[-1] - r.axial_strain[0])
        ratio = r.stress_ratio[last]
        return np.mean([math.degrees(math.asin((q - 1) / (q + 1))) for q in ratio])

    expected = {
        "critical_friction_angle": [critical(r) for r in results],
        "volumetric_strain_end": [r.volumetric_strain[-1] for r in results],
        "coordination_end": [r.coordination[-1] for r in results],
        "sliding_fraction_end": [r.sliding_fraction[-1] for r in results],
        "peak_friction_angle": [r.peak_friction_angle for r in results if r.failed],
    }
    for name, values in expected.items():
        ci = getattr(s, name)
        assert ci.n == len(values), name
        mean, low, high = _student_t(values)
        assert ci.mean == pytest.approx(mean, rel=1e-12, abs=1e-15), name
        assert ci.low == pytest.approx(low, rel=1e-10, abs=1e-14), name
        assert ci.high == pytest.approx(high, rel=1e-10, abs=1e-14), name
        assert ci.std == pytest.approx(np.std(values, ddof=1), rel=1e-12), name
    # t(0.975, 3) = 3.182446305284263 (tables): the half-width is 3.18 s/√4
    ci = s.volumetric_strain_end
    assert ci.half_width == pytest.approx(3.182446305284263 * ci.std / 2, rel=1e-9)


def test_one_sample_gives_an_unbounded_interval_that_says_so(samples):
    """n = 1: no spread is known, the interval is (-inf, inf) and its text says n = 1."""
    one = ensemble(samples[:1], "biaxial", **RUN)
    ci = one.summary[0].volumetric_strain_end
    assert ci.n == 1 and ci.mean == one.runs[0].result.volumetric_strain[-1]
    assert ci.low == -math.inf and ci.high == math.inf and ci.half_width == math.inf
    assert math.isnan(ci.std)
    assert "n = 1: no interval" in str(ci)
    assert "n = 1: no interval" in one.format_summary()


def test_sequence_options_make_a_grid_of_conditions(samples):
    """pressure = [0.5, 1.0] and two laws: every sample at every pressure, one condition per
    (model, pressure), its runs those of its samples."""
    other = [Assembly(a.positions, a.radii, a.cell, ContactModel(Coulomb(0.3), kn=1e4, kt=1e4))
             for a in samples[:2]]
    grid = ensemble([*samples[:2], *other], "biaxial", **{**RUN, "pressure": [0.5, 1.0]})
    assert [(r.sample, r.options) for r in grid.runs] == [
        (s, {"pressure": p}) for p in (0.5, 1.0) for s in range(4)]
    assert [(s.options, s.runs) for s in grid.summary] == [
        ({"pressure": 0.5}, (0, 1)), ({"pressure": 0.5}, (2, 3)),
        ({"pressure": 1.0}, (4, 5)), ({"pressure": 1.0}, (6, 7))]
    assert "mu=0.5" in grid.summary[0].model and "mu=0.3" in grid.summary[1].model
    for r in grid.runs:
        assert r.result.stress[0, 0, 0] == pytest.approx(r.options["pressure"], rel=0.05)


def test_mean_curve_and_its_band(serial):
    """The mean curve at the runs' common strains: the runs' values interpolated, their mean
    and Student-t band (the end value is the summary's)."""
    c = serial.curve("volumetric_strain")
    results = [r.result for r in serial.runs]
    at_end = [np.interp(c.axial_strain[-1], r.axial_strain, r.volumetric_strain) for r in results]
    mean, low, high = _student_t(at_end)
    assert c.n == 4 and c.mean[-1] == pytest.approx(mean, rel=1e-12)
    assert (c.low[-1], c.high[-1]) == pytest.approx((low, high), rel=1e-10)
    assert np.all(c.low <= c.mean) and np.all(c.mean <= c.high)
    angle = serial.curve("friction_angle")
    assert np.all((angle.mean >= 0) & (angle.mean <= 90))
    with pytest.raises(FrictionRulesError, match="quantity = 'nope' violates: one of"):
        serial.curve("nope")


def test_run_folder_keeps_finished_runs_and_resumes_the_others(samples, serial, tmp_path,
                                                               monkeypatch):
    """A time limit stops the ensemble (statuses say so, nothing completed counted wrongly);
    the same call again resumes the stopped run, starts the others, and a third call runs
    nothing (the engine is entered by no run) and gives the numbers of the serial ensemble."""
    from frictionrules.assembly import _ensemble
    from frictionrules.assembly._dem import _protocol

    entered = []  # the runs that stepped the engine (consolidated or sheared)
    current = {}
    real_triaxial, real_consolidate, real_clock = _ensemble.triaxial, _protocol.consolidate, _protocol._Clock.run

    @functools.wraps(real_triaxial)
    def triaxial_spy(assembly, *a, **k):
        current["sample"] = next(i for i, s in enumerate(samples) if s is assembly)
        return real_triaxial(assembly, *a, **k)

    def consolidate_spy(*a, **k):
        entered.append(current["sample"])
        return real_consolidate(*a, **k)

    def clock_spy(self, *a, **k):
        entered.append(current["sample"])
        return real_clock(self, *a, **k)

    monkeypatch.setattr(_ensemble, "triaxial", triaxial_spy)
    monkeypatch.setattr(_protocol, "consolidate", consolidate_spy)
    monkeypatch.setattr(_protocol._Clock, "run", clock_spy)
    folder = tmp_path / "runs"
    # a millisecond: the first run stops during its consolidation, the others do not start
    first = ensemble(samples[:3], "biaxial", run_folder=folder, max_time=1e-3, **RUN)
    assert [r.status for r in first.runs] == ["new", "not started", "not started"]
    assert first.runs[0].result.message.startswith("stopped")
    assert first.summary[0].completed == 0 and first.summary[0].volumetric_strain_end.n == 0
    assert sorted(set(entered)) == [0]
    entered.clear()
    second = ensemble(samples[:3], "biaxial", run_folder=folder, **RUN)
    assert [r.status for r in second.runs] == ["resumed", "new", "new"]
    assert sorted(set(entered)) == [0, 1, 2]
    entered.clear()
    third = ensemble(samples, "biaxial", run_folder=folder, **RUN)  # one sample more
    assert [r.status for r in third.runs] == ["kept", "kept", "kept", "new"]
    assert sorted(set(entered)) == [3]  # only the new sample ran
    assert len(list(folder.glob("*.h5"))) == 4
    for got, want in zip(third.runs, serial.runs):
        np.testing.assert_array_equal(got.result.volumetric_strain, want.result.volumetric_strain)
        np.testing.assert_array_equal(got.result.stress, want.result.stress)
    assert str(third.summary[0].volumetric_strain_end) == str(serial.summary[0].volumetric_strain_end)


def test_process_pool_gives_the_serial_numbers(samples, serial):
    """The same ensemble on two worker processes (spawned): the same runs, in the same order,
    bit for bit, and the same summary."""
    context = multiprocessing.get_context("spawn")
    with concurrent.futures.ProcessPoolExecutor(2, mp_context=context) as pool:
        pooled = ensemble(samples, "biaxial", executor=pool, **RUN)
    assert [r.sample for r in pooled.runs] == [r.sample for r in serial.runs]
    for got, want in zip(pooled.runs, serial.runs):
        np.testing.assert_array_equal(got.result.stress, want.result.stress)
        np.testing.assert_array_equal(got.result.volumetric_strain, want.result.volumetric_strain)
    assert pooled.table()[0] == serial.table()[0]


def test_table_has_a_row_per_condition_and_quantity(serial):
    cols, units = serial.table()
    assert set(cols) == set(units)
    assert cols["quantity"] == ["peak_friction_angle", "critical_friction_angle",
                                "volumetric_strain_end", "coordination_end", "sliding_fraction_end"]
    k = cols["quantity"].index("volumetric_strain_end")
    assert cols["mean"][k] == serial.summary[0].volumetric_strain_end.mean
    assert cols["completed"][k] == 4


@pytest.mark.parametrize("call, message", [
    (lambda s: ensemble([], "biaxial", **RUN), r"assemblies = \[\] violates: at least one Assembly"),
    (lambda s: ensemble(s[0], "biaxial", **RUN), "violates: a sequence of Assembly"),
    (lambda s: ensemble([s[0], "x"], "biaxial", **RUN), r"assemblies\[1\] = 'x' violates: an Assembly"),
    (lambda s: ensemble(s, "biaxial", presure=1.0), "option 'presure' violates: one of"),
    (lambda s: ensemble(s, "biaxial", run_file="a.h5", **RUN), "run_folder"),
    (lambda s: ensemble(s, "biaxial", axial_strain=0.01), "pressure is missing"),
    (lambda s: ensemble(s, "biaxial", **{**RUN, "pressure": [1.0, -1.0]}),
     r"pressure = -1.0 violates pressure > 0"),
    (lambda s: ensemble(s, "biaxial", **{**RUN, "pressure": []}), r"pressure = \[\] violates"),
    (lambda s: ensemble(s, "axisymmetric", **RUN), "kind = 'axisymmetric' violates"),
    (lambda s: ensemble(s, "biaxial", max_time=0, **RUN), "max_time = 0.0 violates"),
    (lambda s: ensemble(s, "biaxial", executor="pool", **RUN), "executor = 'pool'"),
])
def test_bad_input_raises_before_any_run(samples, call, message, monkeypatch):
    from frictionrules.assembly import _ensemble
    monkeypatch.setattr(_ensemble, "_run_one", lambda task: pytest.fail("a run started"))
    with pytest.raises(FrictionRulesError, match=message):
        call(samples)


def test_repeated_run_in_a_run_folder_is_refused(samples, tmp_path):
    with pytest.raises(FrictionRulesError, match=r"assemblies\[1\] repeats assemblies\[0\]"):
        ensemble([samples[0], samples[0]], "biaxial", run_folder=tmp_path, **RUN)


def test_lammps_runs_keep_no_run_folder(samples, tmp_path, monkeypatch):
    from frictionrules.assembly import _ensemble
    monkeypatch.setattr(_ensemble, "_run_one", lambda task: pytest.fail("a run started"))
    with pytest.raises(FrictionRulesError, match="run_folder = .* violates: None for engine = 'lammps'"):
        ensemble(samples, "biaxial", run_folder=tmp_path, engine="lammps", **RUN)
    with pytest.raises(FrictionRulesError, match="ranks = 2 violates"):
        ensemble(samples, "biaxial", ranks=2, **RUN)


def test_a_failing_run_is_kept_as_failed_and_the_others_go_on(samples, monkeypatch):
    from frictionrules.assembly import _ensemble
    real = _ensemble.triaxial

    @functools.wraps(real)
    def flaky(assembly, *a, **k):
        if assembly is samples[1]:
            raise FrictionRulesError("the sample could not be consolidated")
        return real(assembly, *a, **k)

    monkeypatch.setattr(_ensemble, "triaxial", flaky)
    out = ensemble(samples[:3], "biaxial", **RUN)
    assert [r.status for r in out.runs] == ["new", "failed", "new"]
    assert out.runs[1].result is None and "could not be consolidated" in out.runs[1].error
    assert out.summary[0].completed == 2 and out.summary[0].coordination_end.n == 2
    assert "1 failed" in out.format_summary()


def test_public_names():
    for name in ("ensemble", "EnsembleResult", "EnsembleRun", "EnsembleSummary",
                 "ConfidenceInterval", "MeanCurve"):
        assert name in frictionrules.__all__


# ---- the command line ------------------------------------------------------------------------
CONFIG = """[sample]
random = true
n = 30
dim = 2
polydispersity = 0.2
{seeds}
[model]
kn = 1e4
kt = 1e4
[model.law]
type = "Coulomb"
mu = 0.5
[loading]
kind = "biaxial"
pressure = 1.0
axial_strain = 0.01
method = "dem"
record_every = 1e-3
"""


def _cli(*argv):
    import subprocess
    import sys
    return subprocess.run([sys.executable, "-m", "frictionrules", "assembly", *map(str, argv)],
                          capture_output=True, text=True, timeout=900)


def test_cli_seeds_prints_and_writes_the_summary_and_figure(tmp_path, serial):
    """--seeds 1,2 runs the library's ensemble (the same numbers), prints the summary, writes
    summary.csv/.json and the figure; [sample] seeds = [1, 2, 3, 4] then keeps the two runs and
    runs two more (the statuses printed)."""
    import json
    cfg = tmp_path / "ens.toml"
    cfg.write_text(CONFIG.format(seeds=""))
    out = tmp_path / "runs"
    res = _cli(cfg, "--seeds", "1,2", "--out", out, "--figure", tmp_path / "ens.png")
    assert res.returncode == 0, res.stderr
    assert "seed 1: new (completed)" in res.stdout and "seed 2: new (completed)" in res.stdout
    assert "volumetric_strain_end" in res.stdout and "(n = 2)" in res.stdout
    assert "\r" not in res.stderr  # progress only on a terminal: one summary line here
    table = json.loads((out / "summary.json").read_text())
    k = table["columns"]["quantity"].index("volumetric_strain_end")
    two = ensemble([Assembly.random(30, 2, MODEL, polydispersity=0.2, seed=s) for s in (1, 2)],
                   "biaxial", **RUN)
    assert table["columns"]["mean"][k] == two.summary[0].volumetric_strain_end.mean
    assert table["metadata"]["seeds"] == [1, 2]
    assert (out / "summary.csv").read_text().startswith("condition,model,options,quantity")
    assert (tmp_path / "ens.png").stat().st_size > 10_000
    cfg.write_text(CONFIG.format(seeds="seeds = [1, 2, 3, 4]"))
    res = _cli(cfg, "--out", out, "--quiet")
    assert res.returncode == 0, res.stderr
    assert [line.split(":")[1].split("(")[0].strip() for line in res.stdout.splitlines()
            if line.startswith("seed ")] == ["kept", "kept", "new", "new"]
    table = json.loads((out / "summary.json").read_text())
    assert table["columns"]["mean"][k] == serial.summary[0].volumetric_strain_end.mean


@pytest.mark.parametrize("extra, toml_seeds, message", [
    (["--seeds", "1,x"], "", "'1,x' violates: comma-separated integers"),
    (["--seeds", "1,1"], "", "'1,1' violates: distinct integers >= 0"),
    (["--seeds", "1,2", "--vtk", "v"], "", "v' violates: a single run (no seeds)"),
    (["--seeds", "1,2", "--out", "r.h5"], "", "a folder for the runs' files"),
    ([], "seeds = []", "seeds = [] violates: a non-empty list"),
    ([], "seeds = [1]\nseed = 2", "seed and seeds violates: one of them"),
    (["--workers", "2"], "", "--workers/--scheduler: constraint: an ensemble"),
    (["--seeds", "1,2", "--engine", "lammps"], "", "--engine lammps violates: not with seeds"),
])
def test_cli_bad_seeds_exit_2_with_one_line(tmp_path, extra, toml_seeds, message):
    cfg = tmp_path / "ens.toml"
    cfg.write_text(CONFIG.format(seeds=toml_seeds))
    out = ["--out", tmp_path / "runs"] if "--out" not in extra else []
    res = _cli(cfg, *out, *[tmp_path / e if e in ("v", "r.h5") else e for e in extra])
    assert res.returncode == 2, res.stdout + res.stderr
    assert message in res.stderr and "Traceback" not in res.stderr


def test_cli_seeds_need_a_random_sample(tmp_path):
    cfg = tmp_path / "fcc.toml"
    cfg.write_text('[sample]\nlattice = "fcc"\n[model]\nkn = 1e6\nkt = 1e6\n[model.law]\n'
                   'type = "Coulomb"\nmu = 0.3\n[loading]\nkind = "axisymmetric"\npressure = 1.0\n')
    res = _cli(cfg, "--seeds", "1,2", "--out", tmp_path / "runs")
    assert res.returncode == 2 and "violates: random = true in [sample]" in res.stderr


def test_plot_ensemble_draws_the_mean_curves_with_their_bands(serial, samples):
    """One line per condition at the mean curve, a band between its interval's ends; a
    condition of one run has no band and its legend says n = 1."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from _figure_checks import assert_readable

    from frictionrules.plot.assembly import plot_ensemble
    ax = plot_ensemble(serial, "volumetric_strain")
    curve = serial.curve("volumetric_strain")
    (line,) = ax.lines
    np.testing.assert_array_equal(line.get_xdata(), curve.axial_strain)
    np.testing.assert_array_equal(line.get_ydata(), curve.mean)
    (band,) = ax.collections
    ys = np.concatenate([p.vertices[:, 1] for p in band.get_paths()])
    assert ys.min() == pytest.approx(curve.low.min()) and ys.max() == pytest.approx(curve.high.max())
    assert [t.get_text() for t in ax.get_legend().get_texts()] == ["n = 4"]
    assert_readable(ax)
    plt.close(ax.figure)
    one = ensemble(samples[:1], "biaxial", **RUN)
    ax = plot_ensemble(one, "friction_angle")
    assert len(ax.lines) == 1 and not ax.collections
    assert [t.get_text() for t in ax.get_legend().get_texts()] == ["n = 1"]
    plt.close(ax.figure)


@settings(max_examples=60, deadline=None)
@given(st.lists(st.floats(-1e3, 1e3, allow_nan=False), min_size=2, max_size=40))
def test_interval_is_scipy_student_t_for_any_values(values):
    """The interval of any n >= 2 finite values is scipy.stats.t.interval(0.95, n - 1, x̄,
    s/√n); it holds the mean and is symmetric about it."""
    from frictionrules.assembly._statistics import interval
    ci = interval(values)
    x = np.asarray(values)
    scale = x.std(ddof=1) / math.sqrt(len(x))
    assert ci.n == len(x) and ci.mean == pytest.approx(x.mean(), rel=1e-12, abs=1e-9)
    if scale == 0:
        assert ci.half_width == 0 and ci.low == ci.high == ci.mean
        return
    low, high = stats.t.interval(0.95, len(x) - 1, loc=ci.mean, scale=scale)
    assert ci.low == pytest.approx(low, rel=1e-9, abs=1e-9 * scale)
    assert ci.high == pytest.approx(high, rel=1e-9, abs=1e-9 * scale)
    assert ci.low <= ci.mean <= ci.high
    assert ci.high - ci.mean == pytest.approx(ci.mean - ci.low, rel=1e-9, abs=1e-9 * scale)


def test_interval_of_no_value_is_nan_and_says_so():
    from frictionrules.assembly._statistics import interval
    ci = interval([])
    assert ci.n == 0 and all(math.isnan(v) for v in (ci.mean, ci.low, ci.high, ci.std))
    assert str(ci) == "no run"
