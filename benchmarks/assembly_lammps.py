"""Benchmark: the same triaxial test in our engine and in LAMMPS (``engine="lammps"``).

One command: ``python benchmarks/assembly_lammps.py [--seeds 1,2,3] [--mu 0.3,0.5]
[--laws coulomb,dilatant,hardening] [--cases coulomb:0.3,dilatant:0.3] [--strain 0.25]
[--pair exported|gran/hooke/history] [--ranks 1,2] [--cost-grains 10000]
[--scale-grains 100000] [--skip-stats] [--skip-cost] [--skip-scale]``.

* **Statistics** (``results/assembly_lammps.md``): ``Assembly.random(400, 3, seed=s,
  polydispersity=0.2)`` (kept under ``results/assembly_lammps/samples``), kn = kt = 1e4, p = 1,
  I = 4e-4, damping 0.2, ρ = 1, frictionless consolidation, axisymmetric compression to
  ``--strain``, a record every 0.1 %; both engines (ours on one thread, LAMMPS on one rank); the
  statistics of ``assembly_yade.py`` (``_dem_compare.statistics``: peak angle on a ±0.25 %
  running mean, the 20–25 % angle and Z, ε_v at 25 %) and its tolerances (means: 1.5°, 2°,
  0.008, 0.15; each run: 2°, 3°, 0.012, 0.2). The laws run in LAMMPS through their exported
  pair style (``--pair exported``, the default; table ``assembly_lammps.md``) or, for Coulomb,
  LAMMPS's own ``gran/hooke/history`` (``--pair gran/hooke/history``; table
  ``assembly_lammps_builtin.md``); our engine's runs are kept and reused by both.
* **Ranks** (``--ranks 1,2``, ``results/assembly_lammps_ranks.md``, in place of the statistics
  beside ours): the same LAMMPS runs (samples, laws, protocol) on 1 and on 2 MPI ranks, their
  statistics side by side and their differences judged by the same tolerances. The law
  ``hardening`` (μ (1 + 0.6 (1 − exp(−κ/0.004))), κ the accumulated slip) runs in LAMMPS only.
  ``--skip-cost --skip-scale`` for the table alone.
* **Cost** (``results/assembly_lammps_cost.md``): ms per step of the shear of the same
  ``--cost-grains`` sample (a jittered cubic array compressed frictionless by LAMMPS) in both
  engines at equal cores (1 thread / 1 rank, 2 threads / 2 ranks).
* **Scale** (``results/assembly_lammps_scale.md``): LAMMPS on 1 and 2 ranks at
  ``--scale-grains`` spheres, a few hundred steps of shear: ms per step, the speed-up, the
  memory LAMMPS reports per rank and the largest resident set of the ranks.

The machine's load average is written beside each table: these are shared machines.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import re
import resource
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
STORE = HERE / "results" / "assembly_lammps"
KN = KT = 1e4
PRESSURE = 1.0
#: --kept-only: tables of the runs kept, nothing run.
KEPT_ONLY = False


def make_law(name: str, mu: float):
    import frictionrules as fr
    if name == "coulomb":
        return fr.Coulomb(mu)
    if name == "dilatant":
        return fr.UserLaw("sqrt(T1**2 + T2**2) - mu*N", potential="sqrt(T1**2 + T2**2) - beta*N",
                          params={"mu": mu, "beta": mu / 3})
    if name == "hardening":     # κ: the accumulated slip; μ grows to 1.6 μ over a slip of a few kh
        return fr.UserLaw("sqrt(T1**2 + T2**2) - mu*(1 + h*(1 - exp(-kappa/kh)))*N",
                          potential="sqrt(T1**2 + T2**2)",
                          params={"mu": mu, "h": 0.6, "kh": 0.004}, state={"kappa": 0.0},
                          rates={"kappa": "slip"})
    raise SystemExit(f"law {name!r}: coulomb, dilatant or hardening")


def sample(seed: int, n: int = 400) -> dict:
    """``Assembly.random(n, 3, seed=seed, polydispersity=0.2)``, kept."""
    import frictionrules as fr
    path = STORE / "samples" / f"random{n}_seed{seed}.npz"
    if not path.exists():
        path.parent.mkdir(parents=True, exist_ok=True)
        a = fr.Assembly.random(n, 3, fr.ContactModel(fr.Coulomb(0.3), kn=KN, kt=KT),
                               polydispersity=0.2, seed=seed)
        np.savez(path, positions=a.positions, radii=a.radii, cell=a.cell)
    d = np.load(path)
    return {"positions": d["positions"], "radii": d["radii"], "cell": d["cell"], "seed": seed}


def assembly_of(s: dict, law):
    import frictionrules as fr
    return fr.Assembly(s["positions"], s["radii"], s["cell"], fr.ContactModel(law, kn=KN, kt=KT))


def run_one(s: dict, law_name: str, mu: float, engine: str, strain: float, pair: str = "exported",
            ranks: int = 1):
    """One run: (Run, message) or (None, reason) where the engine cannot run the law. Our
    engine's runs are kept under ``results/assembly_lammps/ours`` and reused; LAMMPS's under
    ``runs/<tag>_<pair>`` (1 rank) or ``runs/<tag>_<pair>_r<ranks>``."""
    import frictionrules as fr
    from _dem_compare import Run
    a = assembly_of(s, make_law(law_name, mu))
    tag = f"seed{s['seed']}_mu{mu:g}_{law_name}_{100 * strain:g}pc"
    kept = STORE / "ours" / f"{tag}.npz"
    if engine == "frictionrules" and not kept.exists() and KEPT_ONLY:
        return None, "not run (--kept-only)"
    if engine == "frictionrules" and kept.exists():
        d = np.load(kept)
        return Run(axial_strain=d["axial_strain"], volumetric_strain=d["volumetric_strain"],
                   stress=d["stress"], coordination=d["coordination"], wall=float(d["wall"]),
                   cpu=float(d["cpu"]), steps=-1, dt=math.nan, info={}), "kept"
    cpu0 = time.process_time() + _children_cpu()
    t0 = time.perf_counter()
    if engine == "lammps":
        from frictionrules.assembly._lammps._runner import run_lammps
        folder = STORE / "runs" / (f"{tag}_{pair.replace('/', '-')}"
                                   + (f"_r{ranks}" if ranks > 1 else ""))
        stages = folder / "stages.txt"
        if stages.exists() and "shear done" in stages.read_text():  # kept: read it again
            r = fr.read_lammps_triaxial(a, folder, ranks=ranks)
            return Run(axial_strain=np.asarray(r.axial_strain),
                       volumetric_strain=np.asarray(r.volumetric_strain),
                       stress=np.asarray(r.stress), coordination=np.asarray(r.coordination),
                       wall=math.nan, cpu=math.nan, steps=-1, dt=math.nan, info={}), "kept"
        if KEPT_ONLY:
            return None, "not run (--kept-only)"
        try:
            files = fr.write_lammps_triaxial(a, "axisymmetric", folder, pressure=PRESSURE,
                                             axial_strain=strain, consolidation="frictionless",
                                             record_every=1e-3, pair_style=pair)
        except fr.FrictionRulesError as exc:
            return None, str(exc)
        r = fr.read_lammps_triaxial(a, folder, ended=run_lammps(files, ranks=ranks), ranks=ranks)
    else:
        r = fr.triaxial(a, "axisymmetric", pressure=PRESSURE, axial_strain=strain, method="dem",
                        consolidation="frictionless", record_every=1e-3)
    wall = time.perf_counter() - t0
    cpu = time.process_time() + _children_cpu() - cpu0
    run = Run(axial_strain=np.asarray(r.axial_strain), volumetric_strain=np.asarray(r.volumetric_strain),
              stress=np.asarray(r.stress), coordination=np.asarray(r.coordination), wall=wall,
              cpu=cpu, steps=-1, dt=math.nan, info={"message": r.message})
    if engine == "frictionrules":
        kept.parent.mkdir(parents=True, exist_ok=True)
        np.savez(kept, axial_strain=run.axial_strain, volumetric_strain=run.volumetric_strain,
                 stress=run.stress, coordination=run.coordination, wall=wall, cpu=cpu)
    return run, r.message


def _children_cpu() -> float:
    u = resource.getrusage(resource.RUSAGE_CHILDREN)
    return u.ru_utime + u.ru_stime


def _f(x, digits=2):
    return "–" if x is None or (isinstance(x, float) and math.isnan(x)) else f"{x:.{digits}f}"


KEYS = (("peak", 2), ("end", 2), ("ev", 4), ("z", 2))


def _seeds_cases(args):
    seeds = [int(v) for v in args.seeds.split(",")]
    if args.cases:    # law:mu pairs instead of every law at every mu
        cases = [(c.split(":")[0], float(c.split(":")[1])) for c in args.cases.split(",")]
    else:
        cases = [(law, float(mu)) for law in args.laws.split(",") if law
                 for mu in args.mu.split(",")]
    return seeds, cases


def statistics_table(args) -> None:
    from _dem_compare import statistics, within
    from _table import write_table
    seeds, cases = _seeds_cases(args)
    rows, notes, per = [], [], {}
    for law, mu in cases:
        for seed in seeds:
            s = sample(seed)
            ours, _ = run_one(s, law, mu, "frictionrules", args.strain)
            if ours is None:
                continue
            theirs, why = run_one(s, law, mu, "lammps", args.strain, args.pair)
            so = statistics(ours, args.strain)
            sl = statistics(theirs, args.strain) if theirs is not None else None
            per.setdefault((law, mu), []).append((so, sl))
            if theirs is None:
                notes.append(f"{law} μ = {mu:g}: LAMMPS not run: {why}")
            row = [law, mu, seed]
            for k, d in KEYS:
                a = getattr(so, k)
                b = getattr(sl, k) if sl else math.nan
                row += [_f(a, d), _f(b, d), f"{_f(a - b, d)} {within(a - b, k, False)}"]
            row += [_f(ours.wall, 0), _f(theirs.wall, 0) if theirs else "–"]
            rows.append(row)
            print(row, flush=True)
            _write(args, rows, notes, per, KEYS, write_table)
    _write(args, rows, notes, per, KEYS, write_table)


def _write(args, rows, notes, per, keys, write_table):
    out = list(rows)
    for (law, mu), pairs in per.items():
        if not all(sl is not None for _, sl in pairs):
            continue
        out.append(_mean_row(law, mu, pairs, keys, sign=1.0))
    head = ["law", "μ", "seed"]
    for name in ("peak φ (°)", "end φ (°)", "ε_v", "Z"):
        head += [f"ours: {name}", f"LAMMPS: {name}", "ours − LAMMPS"]
    head += ["ours: wall s", "LAMMPS: wall s"]
    text = (f"Assembly.random(400, 3, seed, polydispersity=0.2); kn = kt = {KN:g}, p = {PRESSURE:g}, "
            f"I = 4e-4, damping 0.2, ρ = 1, frictionless consolidation, to {100 * args.strain:g} % "
            f"axial strain. Ours on 1 thread, LAMMPS on 1 rank, the laws' pair style: {args.pair} "
            "(exported: the law's generated return map with our contact kinematics; "
            "gran/hooke/history: LAMMPS's own spring-Coulomb). "
            "Tolerances of assembly_yade.py (✓ within, ✗ outside). "
            f"Load average at the end: {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores. "
            + " ".join(sorted(set(notes))))
    name = "assembly_lammps" + ("" if args.pair == "exported" else "_builtin")
    write_table(name, f"The same triaxial test in our engine and in LAMMPS ({args.pair})", head,
                out, text)


# ---- LAMMPS on 1 and 2 ranks -----------------------------------------------------------------

def _lammps_wall(folder: Path) -> float:
    """LAMMPS's 'Total wall time' of a run (seconds; NaN where the log has none)."""
    found = re.findall(r"Total wall time: (\d+):(\d+):(\d+)", (folder / "log.lammps").read_text())
    if not found:
        return math.nan
    h, m, s = (int(v) for v in found[-1])
    return 3600.0 * h + 60.0 * m + s


def _lammps_folder(seed, law, mu, strain, pair, ranks) -> Path:
    tag = f"seed{seed}_mu{mu:g}_{law}_{100 * strain:g}pc_{pair.replace('/', '-')}"
    return STORE / "runs" / (tag + (f"_r{ranks}" if ranks > 1 else ""))


def ranks_table(args) -> None:
    """The statistics of the same LAMMPS runs on ``--ranks a,b`` ranks (``assembly_lammps_ranks
    .md``), one run at a time, kept under ``runs/`` (``_r<ranks>`` for more than one rank);
    the differences judged by the tolerances against YADE (each run's and the means')."""
    from _dem_compare import statistics, within
    from _table import write_table
    ra, rb = (int(v) for v in args.ranks.split(","))
    seeds, cases = _seeds_cases(args)
    rows, per, notes = [], {}, []
    for law, mu in cases:
        for seed in seeds:
            s = sample(seed)
            runs = [run_one(s, law, mu, "lammps", args.strain, args.pair, r) for r in (ra, rb)]
            if any(run is None for run, _ in runs):
                notes += [f"{law} μ = {mu:g} seed {seed}: {why}" for run, why in runs if run is None]
                continue
            sa, sb = (statistics(run, args.strain) for run, _ in runs)
            per.setdefault((law, mu), []).append((sa, sb))
            row = [law, mu, seed]
            for k, d in KEYS:
                a, b = getattr(sa, k), getattr(sb, k)
                row += [_f(a, d), _f(b, d), f"{_f(b - a, d)} {within(b - a, k, False)}"]
            walls = [_lammps_wall(_lammps_folder(seed, law, mu, args.strain, args.pair, r))
                     for r in (ra, rb)]
            rows.append(row + [_f(w, 0) for w in walls])
            print(rows[-1], flush=True)
            _write_ranks(args, ra, rb, rows, per, notes, write_table)
    _write_ranks(args, ra, rb, rows, per, notes, write_table)


def _mean_row(law, mu, pairs, keys, sign):
    """The bold row of the means over ``pairs`` (statistics of the two sides), each key's two
    means and ``sign`` × (first − second) judged against the tolerances of the means."""
    from _dem_compare import within
    row = [law, mu, f"**mean of {len(pairs)}**"]
    for k, d in keys:
        a = float(np.mean([getattr(first, k) for first, _ in pairs]))
        b = float(np.mean([getattr(second, k) for _, second in pairs]))
        diff = sign * (a - b)
        row += [_f(a, d), _f(b, d), f"{_f(diff, d)} {within(diff, k, True)}"]
    return row + ["", ""]


def _write_ranks(args, ra, rb, rows, per, notes, write_table):
    out = list(rows)
    for (law, mu), pairs in per.items():
        out.append(_mean_row(law, mu, pairs, KEYS, sign=-1.0))
    head = ["law", "μ", "seed"]
    for name in ("peak φ (°)", "end φ (°)", "ε_v", "Z"):
        head += [f"{ra} rank: {name}", f"{rb} ranks: {name}", f"{rb} − {ra}"]
    head += [f"{ra} rank: wall s", f"{rb} ranks: wall s"]
    text = (f"LAMMPS only, the same files run on {ra} and on {rb} MPI ranks (mpich's mpirun); "
            f"Assembly.random(400, 3, seed, polydispersity=0.2); kn = kt = {KN:g}, p = {PRESSURE:g}, "
            f"I = 4e-4, damping 0.2, ρ = 1, frictionless consolidation, to {100 * args.strain:g} % "
            f"axial strain; the laws' pair style: {args.pair}. Statistics of assembly_yade.py "
            "(peak on a ±0.25 % running mean, the 20–25 % angle and Z, ε_v at the end), judged "
            "by its tolerances (each run: 2°, 3°, 0.012, 0.2; means: 1.5°, 2°, 0.008, 0.15; "
            "✓ within, ✗ outside). Wall: LAMMPS's own total (log.lammps), run one at a time "
            f"(load average at the end: {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores). "
            + " ".join(sorted(set(notes))))
    write_table("assembly_lammps_ranks", f"LAMMPS on {ra} and {rb} ranks: the same triaxial test",
                head, out, text)


# ---- cost ------------------------------------------------------------------------------------

def consolidated(seed: int = 1) -> dict:
    """The 400-sphere sample of ``seed`` consolidated frictionless to p by LAMMPS: the centres
    and box at the start of the shear of the statistics' run (``runs/seed1_mu0.3_coulomb``),
    or of a short run made for it."""
    import frictionrules as fr
    folder = STORE / "runs" / f"seed{seed}_mu0.3_coulomb"
    if not (folder / "positions.dump").exists():
        s = sample(seed)
        folder = STORE / "runs" / f"consolidated{seed}"
        fr.triaxial(assembly_of(s, fr.Coulomb(0.3)), "axisymmetric", pressure=PRESSURE,
                    axial_strain=1e-3, method="dem", engine="lammps", lammps_dir=folder,
                    consolidation="frictionless")
    from frictionrules.assembly._lammps._runner import _positions, _records
    s = sample(seed)
    x = _positions(folder, len(s["radii"]))[0]
    row = _records(folder)[0]
    return {"positions": x, "radii": s["radii"], "cell": np.diag(row[2:5]), "seed": seed}


def dense_sample(n: int) -> dict:
    """The consolidated 400-sphere sample tiled periodically to about ``n`` spheres (a periodic
    packing repeated is one: the same contacts, forces and stress)."""
    base = consolidated()
    m0 = len(base["radii"])
    reps = max(1, round((n / m0) ** (1 / 3)))
    counts = [reps, reps, reps]
    while np.prod(counts) * m0 < 0.97 * n:   # the nearest box of repeats to n
        counts[int(np.argmin(counts))] += 1
    h = base["cell"]
    shifts = np.array([[i, j, k] for i in range(counts[0]) for j in range(counts[1])
                       for k in range(counts[2])], float) @ h.T
    x = (base["positions"][None, :, :] + shifts[:, None, :]).reshape(-1, 3)
    r = np.tile(base["radii"], len(shifts))
    return {"positions": x, "radii": r, "cell": h * np.array(counts)[None, :], "seed": 0,
            "tiles": tuple(counts)}


def _loop_ms(folder: Path) -> tuple[float, int, float]:
    """The shear run's (last) loop in ``log.lammps``: ms per step, steps, MB per rank (max)."""
    text = (folder / "log.lammps").read_text()
    loops = re.findall(r"Loop time of ([\d.e+-]+) on (\d+) procs for (\d+) steps", text)
    mem = re.findall(r"Per MPI rank memory allocation \(min/avg/max\) = [\d.]+ \| [\d.]+ \| ([\d.]+) Mbytes", text)
    seconds, _, steps = loops[-1]
    return 1e3 * float(seconds) / int(steps), int(steps), float(mem[-1])


def cost_table(args) -> None:
    """ms/step of the shear, both engines, the same dense sample (``--cost-grains``): LAMMPS
    with its own ``gran/hooke/history`` and with the exported pair style of the same law."""
    from _table import write_table
    s = dense_sample(args.cost_grains)
    rows = []
    for cores in (1, 2):
        ours = _ours_ms(s, cores, args.cost_strain)
        builtin = _lammps_ms(s, cores, args.cost_strain, f"cost{args.cost_grains}_r{cores}")
        exported = _lammps_ms(s, cores, args.cost_strain, f"cost{args.cost_grains}_r{cores}_exported",
                              "exported")
        rows.append([len(s["radii"]), cores, _f(ours, 3), _f(exported[0], 3), _f(builtin[0], 3),
                     _f(ours / exported[0], 2), _f(ours / builtin[0], 2), builtin[1]])
        print(rows[-1], flush=True)
    write_table("assembly_lammps_cost", "Time per step of the shear: our engine beside LAMMPS",
                ["spheres", "cores (threads = ranks)", "ours: ms/step",
                 "LAMMPS, exported pair style: ms/step", "LAMMPS, gran/hooke/history: ms/step",
                 "ours / exported", "ours / gran/hooke/history", "LAMMPS shear steps"], rows,
                f"Coulomb μ = 0.3, kn = kt = {KN:g}; the sample: the 400-sphere seed-1 sample "
                f"consolidated frictionless to p = {PRESSURE:g} by LAMMPS, tiled {s['tiles']}; "
                "ours: the shear stage's steps over its wall time (after a short consolidation "
                "with the laws); LAMMPS: the shear run's loop time over its steps (log.lammps). "
                f"Load average at the end: {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores "
                "(the rows were measured one after the other, each at the load of its moment).")


def _ours_ms(s: dict, threads: int, strain: float) -> float:
    """Our engine's ms per shear step in a fresh interpreter on ``threads`` threads (kept in
    ``results/assembly_lammps/ours/``)."""
    kept = STORE / "ours" / f"cost{len(s['radii'])}_t{threads}.json"
    if kept.exists():
        return json.loads(kept.read_text())["ms"]
    path = STORE / "samples" / f"dense{len(s['radii'])}.npz"
    np.savez(path, positions=s["positions"], radii=s["radii"], cell=s["cell"])
    code = f"""
import json, sys, time, numpy as np
sys.path.insert(0, {str(HERE)!r})
import frictionrules as fr
d = np.load({str(path)!r})
a = fr.Assembly(d["positions"], d["radii"], d["cell"], fr.ContactModel(fr.Coulomb(0.3), kn={KN}, kt={KT}))
fr.triaxial(a, "axisymmetric", pressure={PRESSURE}, axial_strain=2e-4, method="dem",
            consolidation="stress", record_every=1e-4)  # compile and warm
times = []
class P:
    def __call__(self, done, total):
        times.append((time.perf_counter(), done))
    def phase(self, text):
        pass
r = fr.triaxial(a, "axisymmetric", pressure={PRESSURE}, axial_strain={strain}, method="dem",
                consolidation="stress", record_every={strain / 4}, progress=P())
steps = int(r.engine.meters[0]["steps"])
t = [t for t, k in times if k >= 1]
print(json.dumps({{"seconds": t[-1] - t[0], "stage_time": float(r.time[-1] - r.time[1]),
                  "dt": float(r.engine.meters[0]["time"]) / steps}}))
"""
    env = dict(os.environ, NUMBA_NUM_THREADS=str(threads))
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                         check=True).stdout.strip().splitlines()[-1]
    d = json.loads(out)
    ms = 1e3 * d["seconds"] / (d["stage_time"] / d["dt"])
    kept.parent.mkdir(parents=True, exist_ok=True)
    kept.write_text(json.dumps({"ms": ms, "load": os.getloadavg()[0]}))
    return ms


def _lammps_ms(s: dict, ranks: int, strain: float, name: str, pair: str = "gran/hooke/history"):
    """LAMMPS's ms per shear step, shear steps and memory per rank (its own count) of the
    sample on ``ranks`` ranks (``pair``: the laws' pair style); a finished run's folder is
    reused."""
    import frictionrules as fr
    from frictionrules.assembly._lammps._runner import run_lammps
    folder = STORE / "runs" / name
    done = (folder / "stages.txt").exists() and "shear done" in (folder / "stages.txt").read_text()
    if not done:
        a = assembly_of(s, fr.Coulomb(0.3))
        files = fr.write_lammps_triaxial(a, "axisymmetric", folder, pressure=PRESSURE,
                                         axial_strain=strain, consolidation="stress",
                                         record_every=strain / 4, pair_style=pair)
        run_lammps(files, ranks=ranks)
    return _loop_ms(folder)


def scale_table(args) -> None:
    from _table import write_table
    s = dense_sample(args.scale_grains)
    rows, base = [], None
    for ranks in (1, 2):
        ms, steps, mem = _lammps_ms(s, ranks, args.scale_strain, f"scale{args.scale_grains}_r{ranks}")
        base = base or ms
        rows.append([len(s["radii"]), ranks, steps, _f(ms, 2), _f(base / ms, 2), _f(mem, 1),
                     _f(1e3 * ms / len(s["radii"]) * ranks, 2)])
        print(rows[-1], flush=True)
    write_table("assembly_lammps_scale", "LAMMPS on 1 and 2 ranks",
                ["spheres", "ranks", "shear steps", "ms/step", "speed-up over 1 rank",
                 "LAMMPS memory per rank (MB, max)", "µs per sphere-step × ranks"],
                rows,
                "Coulomb μ = 0.3 (gran/hooke/history), kn = kt = 1e4; the 400-sphere seed-1 sample "
                f"consolidated by LAMMPS, tiled {s['tiles']}; a short shear (consolidation='stress' "
                "first: a short settle with the laws). ms/step: the shear loop's time over its "
                "steps; memory: LAMMPS's 'Per MPI rank memory allocation' (log.lammps). "
                f"Load average at the end: {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores "
                "(1- and 2-rank runs were measured one after the other, each at the load of its "
                "moment).")


def figure(path: str, strain: float) -> None:
    """The mobilized angle, ε_v and Z against the axial strain of the kept runs: ours solid,
    LAMMPS dashed (exported) or dotted (gran/hooke/history), a colour per run."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    import frictionrules as fr
    from _dem_compare import mobilized_angle
    fig, axes = plt.subplots(1, 3, figsize=(13, 4))
    tags = sorted(p.stem for p in (STORE / "ours").glob(f"*_{100 * strain:g}pc.npz"))
    for k, tag in enumerate(tags):
        d = np.load(STORE / "ours" / f"{tag}.npz")
        curves = [("ours", "-", d["axial_strain"], d["stress"], d["volumetric_strain"],
                   d["coordination"])]
        seed = int(tag.split("_")[0].removeprefix("seed"))
        for pair, style in (("exported", "--"), ("gran-hooke-history", ":")):
            folder = STORE / "runs" / f"{tag}_{pair}"
            if not (folder / "records.txt").exists():
                continue
            s = sample(seed)
            r = fr.read_lammps_triaxial(assembly_of(s, fr.Coulomb(0.3)), folder)
            curves.append((f"LAMMPS {pair}", style, r.axial_strain, r.stress,
                           r.volumetric_strain, r.coordination))
        for name, style, e, stress, ev, z in curves:
            for ax, y in zip(axes, (mobilized_angle(stress), ev, z)):
                ax.plot(100 * e, y, style, color=f"C{k}", lw=0.8, label=f"{tag}: {name}")
    for ax, name in zip(axes, ("mobilized angle asin((σ1 − σ3)/(σ1 + σ3)) (°)",
                               "volumetric strain (compression +)", "coordination Z")):
        ax.set_xlabel("axial strain (%)")
        ax.set_ylabel(name)
    axes[0].legend(fontsize=6)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    print(f"wrote {path}")


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", default="1,2,3")
    parser.add_argument("--mu", default="0.3,0.5")
    parser.add_argument("--laws", default="coulomb,dilatant")
    parser.add_argument("--cases", default="",
                        help="law:mu pairs (coulomb:0.3,coulomb:0.5,dilatant:0.3) instead of "
                             "--laws × --mu")
    parser.add_argument("--strain", type=float, default=0.25)
    parser.add_argument("--cost-grains", type=int, default=10_000)
    parser.add_argument("--cost-strain", type=float, default=2e-3)
    parser.add_argument("--scale-grains", type=int, default=100_000)
    parser.add_argument("--scale-strain", type=float, default=2e-4)
    parser.add_argument("--pair", default="exported", choices=("exported", "gran/hooke/history"),
                        help="the laws' pair style in LAMMPS")
    parser.add_argument("--ranks", default="",
                        help="a,b: the statistics of LAMMPS on a and on b ranks, side by side "
                             "(results/assembly_lammps_ranks.md), instead of ours beside LAMMPS")
    parser.add_argument("--skip-stats", action="store_true")
    parser.add_argument("--skip-cost", action="store_true")
    parser.add_argument("--skip-scale", action="store_true")
    parser.add_argument("--figure", help="the kept runs' curves, ours beside LAMMPS's (.png)")
    parser.add_argument("--kept-only", action="store_true",
                        help="the tables of the kept runs only (no run)")
    args = parser.parse_args(argv)
    global KEPT_ONLY
    KEPT_ONLY = args.kept_only
    os.environ.setdefault("NUMBA_NUM_THREADS", "1")
    if args.ranks:
        ranks_table(args)
    elif not args.skip_stats:
        statistics_table(args)
    if not args.skip_cost:
        cost_table(args)
    if not args.skip_scale:
        scale_table(args)
    if args.figure:
        figure(args.figure, args.strain)


if __name__ == "__main__":
    main()
