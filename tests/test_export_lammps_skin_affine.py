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
                                    "run 1"]}]}, d


RATE = 2.0


@pytest.mark.parametrize("affine", [True, False])
def test_affine_term_in_tangential_increment(built, tmp_path, affine):
    """Homogeneous shear ``L = γ̇ e_x ⊗ e_y`` (fix deform xy erate γ̇: ``h_rate h_inv``), the
    branch ``l = d e_y``, no velocities: ``Δδt = dt Q_t L l = dt γ̇ d e_x``, so |T| =
    kt dt γ̇ d (sticking: μ = 10); without ``affine yes`` the velocities carry nothing and
    |T| = 0."""
    install, folders = built
    job, d = _shear_job(folders["coulomb"], affine)
    out = drive(install, tmp_path, job)
    row = out["local"][1][0]
    want = KT * DT * RATE * d if affine else 0.0
    assert abs(row[1] - want) <= 1e-12 * KT * DT * RATE * d, (row, want)
    # N from the distance after the step's remap: the overlap 0.01 nearly unchanged
    assert row[2] == 0.0 and row[0] == pytest.approx(KN * 0.01, rel=1e-3)
    # the force on the first sphere is the tangential force along +x (l = d e_y, b pulls a)
    np.testing.assert_allclose(out["f"][1][0][0], want, rtol=1e-12, atol=1e-12 * KT * DT)


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
