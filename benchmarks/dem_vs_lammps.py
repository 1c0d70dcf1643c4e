"""Benchmark: the dynamic engine's cost per step and per contact beside LAMMPS's
``gran/hooke/history``, on one core each and on two.

One command: ``python benchmarks/dem_vs_lammps.py [--tiles 3,7] [--threads 1,2] [--steps 300]
[--rounds 5]``.

The sample: the 400-sphere packing of ``assembly_dem_scaling.py`` (``Assembly.random``, seed 1,
radii 1 ± 20 %, density 1) tiled k × k × k (k = 3: 10,800 spheres; k = 7: 137,200), squeezed
frictionless towards p = 1 for 2000 steps by the engine. Its positions, radii and cell are then
the start of every run of both codes: contacts kn = kt = 1e4, Coulomb μ = 0.3, no viscous
damping, at rest, no tangential history; the same time step ``0.25 √(m_min / kn)``, the same
skin (0.1 mean radius, rebuilt when a grain has moved half of it); the cell deformed at the
same isochoric axisymmetric rate (``ε̇_zz = -ε̇``, ``ε̇_xx = ε̇_yy = ε̇/2``, ε̇ of the inertial
number 4e-4, true strain rates: LAMMPS ``fix deform ... trate``). Three runs, each in a process
of its own on ``--threads`` cores (``NUMBA_NUM_THREADS``; LAMMPS as that many MPI ranks by the
venv's ``mpirun``, ``OMP_NUM_THREADS=1``):

* ``engine Coulomb`` — the engine with ``ContactModel(Coulomb(0.3), kn=1e4, kt=1e4)``;
* ``engine UserLaw`` — the same with ``UserLaw("sqrt(T1**2 + T2**2) - mu*N",
  "sqrt(T1**2 + T2**2)", {"mu": 0.3})``, Coulomb written by a user (its generated kernel);
* ``LAMMPS`` — ``pair_style gran/hooke/history 1e4 1e4 0 0 0.3 0``, ``fix nve/sphere``.

Each run: 50 steps of warm-up, then ``--steps`` timed steps (in proportion fewer on larger
samples): wall clock and CPU time (LAMMPS's own "Loop time" and its "% CPU use"). The runs are
interleaved, A B C A B C ..., ``--rounds`` times per sample and number of cores: the machine's
other load falls on all three alike. The table has the median and the range over the rounds,
per step and per contact (the contacts carrying a force at the end of the run), and the
engine's peak memory → ``results/dem_vs_lammps.md``; the raw numbers →
``results/dem_vs_lammps.json``.

The engine's Cundall damping (0.2) has no counterpart in ``gran/hooke/history``; it costs the
grain pass a few operations per grain. LAMMPS remaps positions affinely (``remap x``) and its
contact velocities lack the affine part ``L l`` the engine adds: the same work per contact.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from _table import RESULTS, write_table  # noqa: E402

KN = KT = 1e4
MU = 0.3
DAMPING = 0.2
INERTIAL = 4e-4
WARMUP = 50
LMP = Path(sys.executable).parent / "lmp"
MPIRUN = Path(sys.executable).parent / "mpirun"
USER_LIMIT, USER_POTENTIAL = "sqrt(T1**2 + T2**2) - mu*N", "sqrt(T1**2 + T2**2)"


def _model(law: str):
    import frictionrules as fr
    if law == "coulomb":
        return fr.ContactModel(fr.Coulomb(MU), kn=KN, kt=KT)
    return fr.ContactModel(fr.UserLaw(USER_LIMIT, USER_POTENTIAL, params={"mu": MU}), kn=KN, kt=KT)


def _prepare(k: int, path: Path) -> None:
    """The squeezed sample (positions, radii, cell) into ``path`` (an ``.npz``)."""
    from assembly_dem_scaling import _sample

    from frictionrules.assembly._dem import _protocol as P
    from frictionrules.assembly._dem._dynamics import Dynamics
    a = _sample(k)
    dyn = Dynamics(a, density=1.0, damping=DAMPING)
    st = dyn.init()
    rate = P.unit_rate(INERTIAL, a.radii, 1.0, 1.0)
    comps = P.components(3)
    iso = np.array([1.0 if i == j else 0.0 for i, j in comps])
    squeeze = P._control(np.ones(len(comps)), iso, iso, np.zeros(len(comps)), 0.0, 10 * rate, 1.0,
                         False, 3)
    st, _ = dyn.run(st, squeeze, 1e9, 2000, True)
    np.savez(path, x=st.grains.x, radius=st.grains.radius, H=st.cell.H, rate=rate)


def warmed_engine(path: Path, law: str):
    """The engine on the sample ``path`` with ``law`` ("coulomb" or "user"), after the
    ``WARMUP`` steps of the shear: ``(assembly, dynamics, state, control)``."""
    import frictionrules as fr
    from frictionrules.assembly._dem import _protocol as P
    from frictionrules.assembly._dem._dynamics import Dynamics
    d = np.load(path)
    a = fr.Assembly(d["x"], d["radius"], d["H"], _model(law))
    rate = float(d["rate"])
    dyn = Dynamics(a, density=1.0, damping=DAMPING)
    st = dyn.init()
    comps = P.components(3)
    rates = np.array([-rate / 2 if (i, j) in ((0, 0), (1, 1)) else (rate if i == j else 0.0)
                      for i, j in comps])  # compression positive
    zero = np.zeros(len(comps))
    ctl = P._control(zero, zero, zero, rates, 0.0, 10 * rate, 1.0, False, 3)
    st, _ = dyn.run(st, ctl, 1e9, WARMUP)
    return a, dyn, st, ctl


def _engine(path: Path, law: str, steps: int) -> dict:
    """One timed run of the engine (in a process of its own)."""
    a, dyn, st, ctl = warmed_engine(path, law)
    s0 = int(st.meters[0]["steps"])
    w0, c0 = time.perf_counter(), time.process_time()
    st, _ = dyn.run(st, ctl, 1e9, steps)
    wall, cpu = time.perf_counter() - w0, time.process_time() - c0
    n = int(st.meters[0]["steps"]) - s0
    import resource
    return {"us_step": wall / n * 1e6, "cpu_us_step": cpu / n * 1e6,
            "memory_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
            "contacts": int(st.meters[0]["closed"]),
            "pairs": len(st.pairs.i), "grains": a.size, "dt": dyn.params().dt}


def _lammps_input(path: Path, tmp: Path, steps: int) -> Path:
    """The data file and input script of the LAMMPS run."""
    d = np.load(path)
    x, r, H, rate = d["x"], d["radius"], d["H"], float(d["rate"])
    # LAMMPS's cell is upper triangular (columns a, b, c): H = Q R, positions turned by Qᵀ
    Q, R = np.linalg.qr(H)
    sign = np.sign(np.diag(R))
    Q, R = Q * sign, (R.T * sign).T
    y = x @ Q
    frac = np.linalg.solve(R, y.T).T
    y = (frac - np.floor(frac)) @ R.T
    lines = ["frictionrules sample", "", f"{len(x)} atoms", "1 atom types", "",
             f"0 {R[0, 0]:.17g} xlo xhi", f"0 {R[1, 1]:.17g} ylo yhi", f"0 {R[2, 2]:.17g} zlo zhi",
             f"{R[0, 1]:.17g} {R[0, 2]:.17g} {R[1, 2]:.17g} xy xz yz", "", "Atoms # sphere", ""]
    lines += [f"{n + 1} 1 {2 * r[n]:.17g} 1.0 {y[n, 0]:.17g} {y[n, 1]:.17g} {y[n, 2]:.17g}"
              for n in range(len(x))]
    (tmp / "sample.data").write_text("\n".join(lines) + "\n")
    dt = 0.25 * math.sqrt(float((4.0 / 3.0 * np.pi * r**3).min()) / max(KN, KT))
    script = f"""units lj
atom_style sphere
atom_modify map array
boundary p p p
newton off
comm_modify vel yes
read_data {tmp / 'sample.data'}
pair_style gran/hooke/history {KN} {KT} 0.0 0.0 {MU} 0
pair_coeff * *
neighbor {0.1 * float(np.mean(r))} bin
neigh_modify delay 0 every 1 check yes
timestep {dt:.17g}
fix integrate all nve/sphere
fix shear all deform 1 x trate {rate / 2:.17g} y trate {rate / 2:.17g} z trate {-rate:.17g}
compute touching all contact/atom
compute contacts all reduce sum c_touching
thermo_style custom step c_contacts
thermo {steps}
thermo_modify norm no
run {WARMUP}
run {steps}
"""
    (tmp / "in.shear").write_text(script)
    return tmp / "in.shear"


def _lammps(path: Path, steps: int, ranks: int) -> dict:
    with tempfile.TemporaryDirectory() as t:
        script = _lammps_input(path, Path(t), steps)
        env = dict(os.environ, OMP_NUM_THREADS="1")
        cmd = [str(LMP), "-in", str(script), "-log", "none", "-echo", "none"]
        if ranks > 1:
            cmd = [str(MPIRUN), "-np", str(ranks)] + cmd
        out = subprocess.run(cmd, env=env, capture_output=True, text=True, check=True).stdout
    loops = re.findall(rf"Loop time of ([0-9.eE+-]+) on {ranks} procs for (\d+) steps "
                       r"with (\d+) atoms", out)
    wall, n, atoms = float(loops[-1][0]), int(loops[-1][1]), int(loops[-1][2])
    share = re.findall(r"^([0-9.]+)% CPU use", out, re.M)  # per rank
    pair = re.findall(r"^Pair\s*\|\s*[0-9.eE+-]+\s*\|\s*([0-9.eE+-]+)", out, re.M)
    rows = re.findall(rf"^\s*{WARMUP + steps}\s+([0-9.eE+-]+)\s*$", out, re.M)
    return {"us_step": wall / n * 1e6,
            "cpu_us_step": ranks * wall * float(share[-1]) / 100 / n * 1e6,
            "contacts": int(round(float(rows[-1]) / 2)),
            "grains": atoms, "pair_us_step": float(pair[-1]) / n * 1e6 if pair else float("nan")}


def _child(kind: str, path: Path, steps: int, threads: int = 1) -> dict:
    cmd = [sys.executable, __file__, "--child", kind, "--sample", str(path), "--steps", str(steps),
           "--threads", str(threads)]
    env = dict(os.environ, NUMBA_NUM_THREADS=str(threads), OMP_NUM_THREADS="1")
    proc = subprocess.run(cmd, env=env, capture_output=True, text=True)
    if proc.returncode:
        raise RuntimeError(f"{kind} failed:\n{proc.stderr[-3000:]}")
    return json.loads(proc.stdout.strip().splitlines()[-1])


RUNS = (("engine Coulomb", "coulomb"), ("engine UserLaw", "user"),
        ("LAMMPS gran/hooke/history", "lammps"))


def _sample_file(tiles: int) -> Path:
    store = RESULTS / "dem_vs_lammps"
    store.mkdir(parents=True, exist_ok=True)
    sample = store / f"sample_k{tiles}.npz"
    if not sample.exists():
        subprocess.run([sys.executable, __file__, "--child", "prepare", "--tiles", str(tiles),
                        "--sample", str(sample)], check=True,
                       env=dict(os.environ, NUMBA_NUM_THREADS="1"))
    return sample


def _steps(steps: int, grains: int) -> int:
    """The timed steps of a sample: ``--steps`` for 10,800 grains, fewer for larger ones."""
    return max(40, round(steps * 10800 / grains))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tiles", default="3,7", help="k of the samples (400 k³ grains)")
    parser.add_argument("--steps", type=int, default=300,
                        help="timed steps at 10,800 grains (in proportion fewer, at least 40, "
                             "for larger samples)")
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--threads", default="1,2",
                        help="engine threads and LAMMPS MPI ranks (1: one core each)")
    parser.add_argument("--runs", default="coulomb,user,lammps",
                        help="which of coulomb, user, lammps")
    parser.add_argument("--name", default="dem_vs_lammps", help="results/<name>.md")
    parser.add_argument("--child", help=argparse.SUPPRESS)
    parser.add_argument("--sample", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        path = Path(args.sample)
        if args.child == "prepare":
            _prepare(int(args.tiles), path)
            print("{}")
            return
        threads = int(args.threads)
        if args.child == "lammps":
            print(json.dumps(_lammps(path, args.steps, threads)))
        else:
            if threads > 1:
                from frictionrules._threads import prefer_openmp
                prefer_openmp()
            print(json.dumps(_engine(path, args.child, args.steps)))
        return
    wanted = args.runs.split(",")
    runs = [(label, kind) for label, kind in RUNS if kind in wanted]
    rows, raw_all = [], {}
    for tiles in (int(t) for t in args.tiles.split(",")):
        sample = _sample_file(tiles)
        steps = _steps(args.steps, 400 * tiles**3)
        for _, kind in runs:  # compile (and cache) each engine's kernels before timing anything
            if kind != "lammps":
                _child(kind, sample, 5)
        for threads in (int(t) for t in args.threads.split(",")):
            raw = {kind: [] for _, kind in runs}
            for r in range(args.rounds):
                for label, kind in runs:
                    out = _child(kind, sample, steps, threads)
                    raw[kind].append(out)
                    print(f"k={tiles} threads={threads} round {r + 1} {label}: "
                          f"{out['us_step']:.0f} µs/step, {out['contacts']} contacts", flush=True)
            raw_all[f"k{tiles}_threads{threads}"] = raw
            ref = (statistics.median(o["us_step"] for o in raw["lammps"]) if "lammps" in raw
                   else None)
            for label, kind in runs:
                t = [o["us_step"] for o in raw[kind]]
                c = statistics.median(o["contacts"] for o in raw[kind])
                per = [o["us_step"] * 1e3 / o["contacts"] for o in raw[kind]]
                cpu = [o["cpu_us_step"] for o in raw[kind]]
                mem = max(o.get("memory_mb", float("nan")) for o in raw[kind])
                rows.append([label, raw[kind][0]["grains"], threads, f"{c:.0f}", steps,
                             f"{statistics.median(t):.0f} ({min(t):.0f}–{max(t):.0f})",
                             f"{statistics.median(cpu):.0f} ({min(cpu):.0f}–{max(cpu):.0f})",
                             f"{statistics.median(per):.0f} ({min(per):.0f}–{max(per):.0f})",
                             f"{statistics.median(t) / ref:.2f}" if ref else "–",
                             "–" if kind == "lammps" else f"{mem:.0f}"])
            (RESULTS / f"{args.name}.json").write_text(json.dumps(raw_all, indent=1))
    write_table(args.name, "The engine beside LAMMPS gran/hooke/history",
                ["run", "grains", "cores", "contacts", "timed steps",
                 "wall µs/step: median (range)",
                 "CPU µs/step: median (range)", "wall ns/contact: median (range)",
                 "÷ LAMMPS (wall)", "peak memory MB"], rows,
                notes=f"{args.rounds} rounds interleaved per sample and number of cores, "
                      f"{WARMUP} steps of warm-up before the timed ones; cores: the engine's "
                      "threads (OpenMP layer) or LAMMPS's MPI ranks. Wall clock on "
                      f"{os.cpu_count()} cores (load {os.getloadavg()[0]:.1f} at the end; where "
                      "other processes hold the cores, CPU time is the steadier figure). Peak "
                      "memory: the engine's whole process (Python, NumPy, Numba included).")


if __name__ == "__main__":
    main()
