"""Two keywords of the exported LAMMPS pair style: ``skin S`` (a contact keeps its history,
and a dilatant one its force, until its gap exceeds S, as the DEM engine's ``contact_range``)
and ``affine yes`` (the box's velocity gradient ``L l`` in the tangential increment, as the
engine's ``Δδt = dt Q_t (v_j − v_i + L l − (r_i ω_i + r_j ω_j) × n)``)."""

from __future__ import annotations

import numpy as np
import pytest

import frictionrules as fr
from _lammps_harness import drive, lammps_or_skip
from test_export_lammps import DT, KN, KT, N_GENERIC, R, _check, _job, frame

MU, BETA = 0.3, 0.1
#: Coulomb's cone with a dilatant potential (β < μ): sliding opens the contact by
#: Δδp_n = β |Δδp_t| (the sliding rule (4.3) on g = |T| − β N).
DILATANT = fr.UserLaw("sqrt(T1**2+T2**2) - mu*N", potential="sqrt(T1**2+T2**2) - beta*N",
                      params={"mu": MU, "beta": BETA})
SKIN = 0.02


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    install = lammps_or_skip()
    out = {}
    for key, law in (("dilatant", DILATANT), ("coulomb", fr.Coulomb(10.0))):
        folder = tmp_path_factory.mktemp(f"lammps-{key}")
        fr.export(law, "lammps", folder, kt=KT, kn=KN, name=key, build=True)
        out[key] = folder
    return install, out


def dilating_path(n):
    """Slide 40 steps at overlap 0.01 (dp_n grows to about 0.005), then open along the normal
    by 0.001 a step up to a gap of 0.03 (beyond the skin)."""
    t1 = frame(n)
    zero = np.zeros(3)
    x2 = (2 * R - 0.01) * n
    steps = [(x2, zero, zero, zero, zero)]
    steps += [(x2, zero, 1.3 * t1, zero, zero)] * 40
    steps += [((2 * R - 0.01 + 0.001 * k) * n, zero, zero, zero, zero) for k in range(1, 41)]
    return steps


def _with_skin(job, style, skin):
    k = next(i for i, line in enumerate(job["setup"]) if line.startswith("include"))
    job["setup"].insert(k + 1, f"pair_style frictionrules/{style} skin {skin!r}")
    return job


def test_dilatant_contact_pushes_while_gap_below_dp_n(built, tmp_path):
    """With ``skin``: while 0 < gap < dp_n the contact still carries N = −kn (gap − dp_n) > 0
    (4.2), ContactModel.update's force to 1e-10; then it opens (zero force), and beyond the
    skin it is lost."""
    install, folders = built
    steps = dilating_path(N_GENERIC)
    out = drive(install, tmp_path, _with_skin(_job(folders["dilatant"], steps), "dilatant", SKIN))
    statuses = _check(out, steps, DILATANT, skin=SKIN)
    gaps = np.array([np.linalg.norm(s[0]) - 2 * R for s in steps])
    normal = np.array([row[0][0] for row in out["local"]])
    pushing = (gaps > 0.0) & (normal > 0.0)
    assert pushing.sum() >= 3, (gaps, normal)    # compressive with a positive gap
    assert 2 in statuses                         # then open, within the skin
    assert statuses[-1] == -1 and gaps[-1] > SKIN    # lost beyond it


def test_dilatant_opening_beyond_the_skin_follows_contact_model(built, tmp_path):
    """A long slide at overlap 0.01 (300 steps: the plastic opening dp_n = β × slip grows to
    about 0.036, nearly twice the skin, and N = kn (dp_n − gap) to four times its start), then
    the spheres part by 0.0017 a step: at every step the force of ContactModel.update
    (4.2)-(4.5) to 1e-10, the contact pushing with a positive gap and lost only beyond the
    skin."""
    install, folders = built
    n = N_GENERIC
    t1 = frame(n)
    zero = np.zeros(3)
    x2 = (2 * R - 0.01) * n
    steps = [(x2, zero, zero, zero, zero)] + [(x2, zero, 1.3 * t1, zero, zero)] * 300
    steps += [((2 * R - 0.01 + 0.0017 * k) * n, zero, 0.5 * t1, zero, zero) for k in range(1, 25)]
    out = drive(install, tmp_path, _with_skin(_job(folders["dilatant"], steps), "dilatant", SKIN))
    statuses = _check(out, steps, DILATANT, skin=SKIN)
    gaps = np.array([np.linalg.norm(s[0]) - 2 * R for s in steps])
    normal = np.nan_to_num(np.array([row[0][0] for row in out["local"]]))
    assert normal[300] > 3 * KN * 0.01                      # dilatancy blocked: N grew
    assert np.count_nonzero((gaps > 0.0) & (normal > 0.0)) >= 5
    assert statuses[-1] == -1 and gaps[-1] > SKIN


def test_carrying_count_includes_dilatant_contact_pushing_with_a_gap(built, tmp_path):
    """``fix property/atom i_fr_carrying``: the pair style counts each atom's force-carrying
    contacts (N > 0 of (4.2), N = −kn (gap − dp_n)); ``compute contact/atom`` counts
    overlapping pairs. Along the dilating path both count the contact while it overlaps;
    while 0 < gap < dp_n only the carrying count has it (the contact pushes); once open
    (N = 0) and beyond the skin, neither."""
    install, folders = built
    steps = dilating_path(N_GENERIC)
    job = _with_skin(_job(folders["dilatant"], steps), "dilatant", SKIN)
    job["setup"][2:2] = ["newton off"]
    job["setup"] += ["fix carrying all property/atom i_fr_carrying",
                     "compute overlapping all contact/atom", "variable c atom i_fr_carrying",
                     "compute counts all reduce sum v_c c_overlapping",
                     "variable carried equal c_counts[1]", "variable overlapped equal c_counts[2]",
                     "thermo_style custom step c_counts[1] c_counts[2]", "thermo 1"]
    job["equal"] = ["carried", "overlapped"]
    out = drive(install, tmp_path, job)
    gaps = np.array([np.linalg.norm(s[0]) - 2 * R for s in steps])
    normal = np.nan_to_num(np.array([row[0][0] for row in out["local"]]))
    carried, overlapped = out["equal"][:, 0], out["equal"][:, 1]
    # one contact: counted by both atoms (2) or by neither (0)
    np.testing.assert_array_equal(carried, np.where(normal > 0.0, 2.0, 0.0))
    np.testing.assert_array_equal(overlapped, np.where(gaps < 0.0, 2.0, 0.0))
    assert np.count_nonzero((gaps > 0.0) & (carried == 2.0)) >= 3


def test_dilatant_contact_without_skin_is_lost_at_zero_gap(built, tmp_path):
    """The default (skin 0, LAMMPS's granular convention): the contact and its history go
    as soon as the gap is positive, whatever dp_n."""
    install, folders = built
    steps = dilating_path(N_GENERIC)
    out = drive(install, tmp_path, _job(folders["dilatant"], steps))
    statuses = _check(out, steps, DILATANT)
    gaps = np.array([np.linalg.norm(s[0]) - 2 * R for s in steps])
    assert all(s == -1 for s, g in zip(statuses, gaps) if g >= 0.0)


def _shear_job(folder, affine):
    """Two spheres on the y axis of a triclinic box, at rest, no integrator: one step to form
    the contact, then one under ``fix deform xy erate`` with ``remap x``."""
    d = 2 * R - 0.01
    setup = ["units si", "atom_style sphere", "atom_modify map array", "boundary p p p",
             "region box prism -4 4 -4 4 -4 4 0 0 0", "create_box 1 box",
             "create_atoms 1 single 0.3 -0.2 0.1", f"create_atoms 1 single 0.3 {-0.2 + d} 0.1",
             f"set type 1 diameter {2 * R}", "set type 1 density 1000.0",
             f"include {folder / 'pair.lmp'}", "neighbor 0.5 bin",
             "neigh_modify every 1 delay 0 check yes", f"timestep {DT}",
             "compute pl all pair/local p1 p2 p3 p4", "thermo_style custom step"]
    if affine:
        setup.append("pair_style frictionrules/coulomb affine yes")
    return {"setup": setup, "local": "pl", "width": 4,
            "steps": [{"commands": ["run 1"]},
                      {"commands": [f"fix shear all deform 1 xy erate {RATE!r} remap x",
                                    "run 1"]},
                      {"commands": ["run 1"]}]}, d


RATE = 2.0


@pytest.mark.parametrize("affine", [True, False])
def test_affine_term_in_tangential_increment(built, tmp_path, affine):
    """Homogeneous shear ``L = γ̇ e_x ⊗ e_y`` (fix deform xy erate γ̇), the branch ``l = d e_y``,
    no velocities. fix deform remaps the centres at the end of a step, so the first step under
    it sees no affine motion (|T| = 0) and the next one the remap's ``Δl = (Δxy/ly) l``:
    ``Δδt = Q_t Δl = dt γ̇ d e_x``, |T| = kt dt γ̇ d (sticking: μ = 10); without ``affine yes``
    the velocities carry nothing and |T| = 0 throughout."""
    install, folders = built
    job, d = _shear_job(folders["coulomb"], affine)
    out = drive(install, tmp_path, job)
    assert out["local"][1][0][1] == 0.0
    row = out["local"][2][0]
    # the branch after the remap is (s d, d, 0), s = γ̇ dt: the tangential part of Δl = s d e_x
    # is s d/√(1 + s²), along (1, -s, 0)/√(1 + s²)
    s = RATE * DT
    want = KT * s * d / np.sqrt(1 + s * s) if affine else 0.0
    assert abs(row[1] - want) <= 1e-12 * KT * DT * RATE * d, (row, want)
    # N from the distance after the step's remap: the overlap 0.01 nearly unchanged
    assert row[2] == 0.0 and row[0] == pytest.approx(KN * 0.01, rel=1e-3)
    # the force on the first sphere along x: T t_x - N n_x, t_x = 1/√(1 + s²),
    # n_x = s/√(1 + s²), N = kn (2R - d √(1 + s²)) at that pass
    normal = KN * (2 * R - d * np.sqrt(1 + s * s))
    np.testing.assert_allclose(out["f"][2][0][0], (want - normal * s) / np.sqrt(1 + s * s),
                               rtol=1e-9, atol=1e-12 * KT * DT)


def test_affine_term_follows_the_box_under_deform_pressure(built, tmp_path):
    """``fix deform/pressure x pressure ...`` changes the box at a strain rate it stores in
    LAMMPS's ``h_rate`` as a strain rate (not a length rate, as ``fix deform`` does): the pair
    style takes ``L`` from the box's change itself. Two spheres at rest on the diagonal
    ``n = (e_x + e_z)/√2`` of a cubic box pressed in x at the bound rate: between two force
    passes the remap moves the branch by ``Δl = (Δlx/lx) l_x e_x`` (Δlx from the box's lengths
    LAMMPS reports), whose tangential part at the new branch ``l`` is ``|Δl_x| |l_z|/|l|``, in the
    x-z plane as the turned history, so |T| grows by ``kt |Δl_x| |l_z|/|l|`` a step (sticking)."""
    install, folders = built
    d = 2 * R - 0.01
    c = float(d / np.sqrt(2.0))
    setup = ["units si", "atom_style sphere", "atom_modify map array", "boundary p p p",
             "region box block 0 8 0 8 0 8", "create_box 1 box",
             "create_atoms 1 single 3.0 4.0 3.0",
             f"create_atoms 1 single {3.0 + c!r} 4.0 {3.0 + c!r}",
             f"set type 1 diameter {2 * R}", "set type 1 density 1000.0",
             f"include {folders['coulomb'] / 'pair.lmp'}",
             "pair_style frictionrules/coulomb affine yes", "neighbor 0.5 bin",
             "neigh_modify every 1 delay 0 check yes", f"timestep {DT}",
             "compute pl all pair/local p1 p2 p3 p4", "compute press all pressure NULL virial",
             "fix servo all deform/pressure 1 x pressure 1e9 1.0 normalize/pressure yes "
             "max/rate 2.0 remap x", "fix_modify servo press press",
             "variable lx equal lx", "variable xa equal x[1]", "variable xb equal x[2]",
             "thermo_style custom step lx c_press[1]", "thermo 1"]
    job = {"setup": setup, "local": "pl", "width": 4, "equal": ["lx", "xa", "xb"],
           "steps": [{"commands": ["run 1"]} for _ in range(4)]}
    out = drive(install, tmp_path, job)
    lx, xa, xb = out["equal"].T
    assert np.all(np.diff(lx) < 0)                   # the box closes in x
    tangential = np.array([row[0][1] for row in out["local"]])
    for k in range(2, 4):    # the remap at the end of step k - 1, seen at step k
        dlx = (xb[k - 1] - xa[k - 1]) - (xb[k - 2] - xa[k - 2])
        np.testing.assert_allclose(dlx, (lx[k - 1] / lx[k - 2] - 1) * (xb[k - 2] - xa[k - 2]),
                                   rtol=1e-9)
        grow = tangential[k] - tangential[k - 1]
        lx_now = xb[k - 1] - xa[k - 1]
        want = KT * abs(dlx) * c / np.hypot(lx_now, c)
        assert abs(grow - want) <= 1e-9 * want, (k, grow, want)


def test_affine_refused_with_remap_v(built, tmp_path):
    """``remap v`` gives the velocities their streaming part: ``affine yes`` would count it twice,
    and LAMMPS stops with one line."""
    import subprocess
    import sys

    from _lammps_harness import DRIVER
    install, folders = built
    job, _ = _shear_job(folders["coulomb"], True)
    job["steps"][1]["commands"][0] = job["steps"][1]["commands"][0].replace("remap x", "remap v")
    (tmp_path / "job.json").write_text(__import__("json").dumps(job))
    (tmp_path / "driver.py").write_text(DRIVER)
    run = subprocess.run([sys.executable, "driver.py", "job.json", "r.npz"], cwd=tmp_path,
                         env=install.env(), capture_output=True, text=True, timeout=120)
    assert run.returncode != 0
    assert "affine yes is for fix deform remap x, not remap v" in run.stdout + run.stderr
