"""Benchmark: every FCLIB file by every method of ours, beside Siconos and Pinocchio when installed.

Usage (one command, from the repository root)::

    python benchmarks/fclib.py [--fclib DIR ...] [--only SUBSTRING] [--no-peers] [--figures]
                               [--pinocchio-python PATH] [--time-limit SECONDS] [--peer-limit SECONDS]

Files: ``../shared/fclib``, ``../shared/fclib-large`` and ``benchmarks/data`` (or the folders
given). For each file and target error (1e-8 and 1e-4) every solver runs in a subprocess of its
own (so that its peak memory, the process's maximum resident set, is its own): ours (``nsgs``,
``newton``, ``prox``, ``admm``, ``polish`` from zero, ``auto``), Siconos' NSGS, NSN_AC, PROX and ADMM and
Pinocchio's ADMM and PGS (see ``benchmarks/_peers.py`` for how each is installed and fed),
every one on one thread. Times are CPU seconds of the solver call in its thread
(``time.thread_time``), so that other jobs on a shared machine slow the wall clock but not the
measure; a run is repeated until its CPU time adds up to 0.3 s (at most 400 times: a tiny
problem's call is timed hundreds of times), and the median is reported with the spread
(min-max). The load average is noted at the start and the end. A run stops at
``--time-limit`` CPU seconds (ours, through the callback) or is killed by the kernel after
``--peer-limit`` CPU seconds (peers, ``RLIMIT_CPU``). Every answer, the peers'
included, is measured with our Siconos error (:func:`frictionrules.multicontact.fc3d_error`); a
run reaches the target when that error is at most the target. On the tiny files Siconos' whole
Python call (its options and arrays made, the driver, the results read) is timed too, as the
rows ``siconos-SOLVER-call``: ours is timed that way (``solve`` from its arguments to its
``Solution``). Each of our methods first makes an untimed run on the file (at most
``WARM_UP_SECONDS``), which loads its compiled kernels from Numba's cache. Pinocchio stops on its own
measures: it runs with its tolerances at the target, then at 1e-2 and 1e-4 of it while our
error of its answer misses the target.

Writes ``benchmarks/results/fclib.csv`` (every run), ``fclib.md`` (the table per file: best
of ours, best peer) and, with ``--figures``, the Dolan–Moré performance profiles
(``fclib_profiles.png``) and the CPU time per iteration against nnz(W) (``fclib_scaling.png``,
from ``--per-iteration`` runs of every method on every file, with the fill of the polish
stage's sparse LU), also copied to ``docs/figures/``.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))
sys.path.insert(0, str(ROOT / "benchmarks"))
OURS = ("nsgs", "newton", "prox", "admm", "polish", "auto")
TARGETS = (1e-8, 1e-4)
HEADER = ("file,contacts,nnz,target,solver,iterations,error,reached,cpu_median,cpu_min,cpu_max,repeats,"
          "peak_mb,info")
#: Repetitions: until the CPU time adds up to this, at most REPEATS_MAX runs (as the peers').
REPEAT_SECONDS, REPEATS_MAX = 0.3, 400
#: Wall seconds of the untimed run of each of our methods on the file before the timed ones.
WARM_UP_SECONDS = 2.0


def folders(args) -> list[Path]:
    if args.fclib:
        return [Path(f) for f in args.fclib]
    shared = ROOT.parent / "shared"
    return [shared / "fclib", shared / "fclib-large", ROOT / "benchmarks" / "data"]


def worker(path: str, method: str, time_limit: float, targets=TARGETS) -> None:
    """Our runs of one method on one file, to every target (in its own process): JSON on stdout."""
    from frictionrules import FrictionContactProblem, read_fclib, solve
    p = read_fclib(path)
    for nc in (1, 17):                       # load the kernels (both paths) outside the timing
        solve(FrictionContactProblem(np.eye(3 * nc) + 0.1, np.tile([-1.0, 2.0, 0.0], nc), [0.5] * nc),
              method=method, max_iter=3)
    # and those of the sparse path (its orderings, the augmented system of Newton's
    # Levenberg-Marquardt steps), which only a run on the file itself reaches: an untimed run
    # of at most WARM_UP_SECONDS (without it, Numba's cache was loaded inside the first timed
    # run: spheres-in-a-box by newton 0.45 s against 0.09 s)
    solve(p, method=method, time_limit=WARM_UP_SECONDS)
    out = {}
    for tol in targets:
        times, spent = [], 0.0
        while len(times) < REPEATS_MAX and (not times or spent < REPEAT_SECONDS):
            c0 = time.thread_time()
            # a CPU-time limit (the wall clock of a loaded machine would cut runs short); the
            # compiled small path takes no callback and needs none
            stop = None if p.nc <= 16 else (lambda info, c0=c0: time.thread_time() - c0 > time_limit)
            s = solve(p, method=method, tol=tol, callback=stop)
            times.append(time.thread_time() - c0)
            spent += times[-1]
        out[f"{tol:.0e}"] = {"iterations": s.iterations, "error": s.error, "times": times, "info": s.reason,
                             "ran": s.method}
    out["peak_mb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(json.dumps(out))


#: Iterations timed per method for the scaling figure (tol = 0: none stops early).
#: Iterations timed per method: Newton's cost changes along a run (its Levenberg–Marquardt
#: steps come once it stalls), so ten of them. Each timing is repeated, as the runs are (until
#: REPEAT_SECONDS of CPU, at most PER_ITERATION_REPEATS times), and its median kept: a single
#: run put the slope of Newton's line anywhere between 1.15 and 1.25 from one run to the next;
#: with the medians, 1.16-1.19 over three runs.
PER_ITERATION = {"nsgs": 40, "newton": 10, "prox": 1, "admm": 60, "polish": 2}
PER_ITERATION_REPEATS = 15


def per_iteration_worker(path: str) -> None:
    """CPU seconds per iteration of every method on one file, and the fill of the polish
    stage's LU of J under two orderings (JSON on stdout)."""
    import scipy.sparse as sp
    import scipy.sparse.linalg as spla

    from frictionrules import read_fclib, solve
    from frictionrules.multicontact import _kernels as K
    p = read_fclib(path)
    out = {}
    start = solve(p, method="admm", tol=1e-4, max_iter=200).r
    for method, k in PER_ITERATION.items():
        r0 = start if method == "polish" else None
        # the same path as the timed runs (a time limit: not the small path), its kernels loaded
        solve(p, method=method, tol=0.0, max_iter=1, r0=r0, time_limit=120)
        per_iteration = []
        while len(per_iteration) < PER_ITERATION_REPEATS and (
                not per_iteration or sum(per_iteration) * k < REPEAT_SECONDS):
            s = solve(p, method=method, tol=0.0, max_iter=k, r0=r0, time_limit=120)
            if not s.iterations:
                break
            per_iteration.append(s.cpu_seconds / s.iterations)
        if per_iteration:
            out[method] = float(np.median(per_iteration))
    W = p.W
    u = W @ start + p.q
    _phi, B1, B2, _ = K.natural_map(start, u, p.mu_bar, p.dilatancy, np.ones(p.nc))
    jptr, jind, jdat = K.jacobian_csr(W.indptr.astype(np.int32), W.indices.astype(np.int32), W.data, B1, B2)
    J = sp.csc_matrix(sp.csr_matrix((jdat, jind, jptr), shape=W.shape))
    fill = {}
    from frictionrules.multicontact._ordering import contact_ordering, shifted_permuted_csc
    perm = contact_ordering(W.indptr.astype(np.int32), W.indices.astype(np.int32), p.nc)
    ptr, rows, vals = shifted_permuted_csc(jptr, jind, jdat, perm, 0.0)
    symmetric = {"diag_pivot_thresh": 0.0, "options": {"SymmetricMode": True}}
    for order, A, kw in (("contacts", sp.csc_matrix((vals, rows, ptr), shape=W.shape), {"permc_spec": "NATURAL", **symmetric}),
                         ("MMD_AT_PLUS_A", J, {"permc_spec": "MMD_AT_PLUS_A", **symmetric}),
                         ("COLAMD", J, {"permc_spec": "COLAMD"})):
        try:
            lu = spla.splu(A, **kw)
            fill[order] = (lu.L.nnz + lu.U.nnz) / J.nnz
        except RuntimeError:
            fill[order] = float("nan")
    out["fill"] = fill
    print(json.dumps(out))


def ours(path: Path, method: str, time_limit: float, targets) -> dict:
    try:
        out = subprocess.run([sys.executable, __file__, "--worker", str(path), method, str(time_limit),
                              ",".join(f"{t:.0e}" for t in targets)],
                             capture_output=True, text=True, timeout=len(targets) * (20 * time_limit + 120))
    except subprocess.TimeoutExpired:
        return {}
    if out.returncode != 0:
        return {"message": out.stderr.strip()[-300:]}
    return json.loads(out.stdout.strip().splitlines()[-1])


def peer_rows(problem, data: Path, tmp: Path, target: float, limit: float, sic, pin, skip=()) -> list[dict]:
    import _peers
    from frictionrules.multicontact import fc3d_error
    rows = []
    runs = []
    if sic:
        runs += [("siconos", sic, _peers.SICONOS_RUNNER, s, m) for s, m in _peers.SICONOS]
    if pin:
        runs += [("pinocchio", pin, _peers.PINOCCHIO_RUNNER, s, m) for s, m in _peers.PINOCCHIO
                 if s == "ADMM" or 3 * problem.nc <= _peers.PGS_MAX_UNKNOWNS]
    for family, python, runner, solver, max_iter in runs:
        if f"{family}-{solver}" in skip:
            continue
        tolerances = (target, 1e-2 * target, 1e-4 * target) if family == "pinocchio" else (target,)
        for tol in tolerances:
            res = _peers.run_peer(python, runner, data, solver, max_iter, tol, tmp, limit)
            err = fc3d_error(problem, res["r"]) if res["r"] is not None else float("nan")
            if err <= target or res["r"] is None:
                break
        rows.append({"solver": f"{family}-{solver}", "iterations": res["iterations"], "error": err,
                     "times": res["times"], "peak_mb": res["peak_mb"], "info": res["info"]})
        if res.get("times_call"):           # the whole Python call, as ``solve`` is timed
            from _fclib_report import CALL_SUFFIX
            rows.append(dict(rows[-1], solver=f"{family}-{solver}{CALL_SUFFIX}", times=res["times_call"]))
    return rows


def _load() -> str:
    one, five, fifteen = os.getloadavg()
    return f"load average {one:.2f} {five:.2f} {fifteen:.2f} on {os.cpu_count()} cores"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--fclib", nargs="*", help="folders of FCLIB files (default: the shared ones)")
    ap.add_argument("--only", help="only files whose name contains this (or one of these, comma-separated)")
    ap.add_argument("--no-peers", action="store_true", help="do not run Siconos and Pinocchio")
    ap.add_argument("--pinocchio-python", help="a Python that imports pinocchio (or $PINOCCHIO_PYTHON)")
    ap.add_argument("--time-limit", type=float, default=15.0, help="CPU seconds per run of ours (default 15)")
    ap.add_argument("--peer-limit", type=float, default=15.0, help="CPU seconds before a peer is killed (default 15)")
    ap.add_argument("--figures", action="store_true", help="also draw the profiles and scaling figures")
    ap.add_argument("--reuse-peers", metavar="CSV",
                    help="take the peers' rows found in an earlier run's CSV instead of running them again "
                         "(their times are CPU times of one thread: the load of that run matters little); "
                         "the peers missing there are run")
    ap.add_argument("--out", default=str(ROOT / "benchmarks" / "results" / "fclib.csv"))
    ap.add_argument("--targets", type=float, nargs="+", default=list(TARGETS), help="target errors (default 1e-8 1e-4)")
    ap.add_argument("--methods", default=",".join(OURS), help="our methods, comma-separated (default: all)")
    ap.add_argument("--keep", metavar="CSV", help="also report the rows of an earlier run's CSV for the files and "
                                                   "targets not run now")
    ap.add_argument("--worker", nargs=4, help=argparse.SUPPRESS)
    ap.add_argument("--per-iteration", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.worker:
        worker(args.worker[0], args.worker[1], float(args.worker[2]), [float(t) for t in args.worker[3].split(",")])
        return 0
    if args.per_iteration:
        per_iteration_worker(args.per_iteration)
        return 0

    import _peers
    from frictionrules._atomic import write_text
    from frictionrules.io import read_fclib

    every_file = sorted((f for d in folders(args) if d.is_dir() for f in d.glob("*.hdf5")),
                        key=lambda f: f.stat().st_size)
    files = [f for f in every_file if not args.only or any(o in f.name for o in args.only.split(","))]
    methods = tuple(m for m in args.methods.split(",") if m)
    if not files:
        print("no FCLIB files found", file=sys.stderr)
        return 2
    sic = pin = None
    if not args.no_peers:
        sic, pin = _peers.siconos_python(), _peers.pinocchio_python(args.pinocchio_python)
        if not sic:
            print("Siconos is not importable by /usr/bin/python3 (Debian: apt-get install python3-siconos "
                  "python3-scipy): its columns are left out.")
        if not pin:
            print("Pinocchio is not found (python3 -m venv pin && pin/bin/pip install pin scipy; then "
                  "--pinocchio-python pin/bin/python): its columns are left out.")
    earlier = {}
    if args.reuse_peers:
        import csv
        with open(args.reuse_peers, encoding="utf-8") as fh:
            for row in csv.DictReader(line for line in fh if not line.startswith("#")):
                if row["solver"] not in OURS:
                    earlier.setdefault((row["file"], float(row["target"])), []).append(row)
    load_start = _load()
    print(f"start: {load_start}")
    rows = [HEADER]
    run_now = {(f.name, f"{t:.0e}") for f in files for t in args.targets}
    if args.keep:
        with open(args.keep, encoding="utf-8") as fh:
            kept = [line.rstrip("\n") for line in fh if line.strip() and not line.startswith(("#", "file,"))]
        rows += [line for line in kept if tuple(line.split(",")[i] for i in (0, 3)) not in run_now]
    print(f"{'file':40s} {'nc':>5s} {'target':>7s} {'solver':>17s} {'iter':>7s} {'error':>9s} {'cpu/s':>9s} "
          f"{'spread':>19s} {'n':>4s} {'MB':>6s}")

    def emit(f, problem, target, res):
        times = np.array(res.get("times") or [np.inf], dtype=float)
        err = float(res.get("error", np.nan))
        reached = bool(err <= target * (1 + 1e-9))
        med, lo, hi = float(np.median(times)), float(times.min()), float(times.max())
        peak = float(res.get("peak_mb", np.nan))
        print(f"{f.stem[:40]:40s} {problem.nc:5d} {target:7.0e} {res['solver']:>17s} "
              f"{int(res.get('iterations', 0)):7d} {err:9.2e} {med:9.5f} {lo:9.5f}-{hi:9.5f} {times.size:4d} "
              f"{peak:6.0f}{'' if reached else '  (not reached: ' + str(res.get('info')) + ')'}", flush=True)
        rows.append(f"{f.name},{problem.nc},{problem.W.nnz},{target:.0e},{res['solver']},"
                    f"{int(res.get('iterations', 0))},{err:.3e},{int(reached)},{med:.7f},{lo:.7f},{hi:.7f},"
                    f"{times.size},{peak:.1f},{res.get('ran', res.get('info', ''))}")

    with tempfile.TemporaryDirectory() as tmpdir:
        tmp = Path(tmpdir)
        for f in files:
            problem = read_fclib(f)
            data = _peers.save_problem(problem, tmp / "problem.npz")
            mine = {m: ours(f, m, args.time_limit, args.targets) for m in methods}
            for target in args.targets:
                reused = {row["solver"] for row in earlier.get((f.name, target), [])}
                for res in peer_rows(problem, data, tmp, target, args.peer_limit, sic, pin, skip=reused):
                    emit(f, problem, target, res)
                for row in earlier.get((f.name, target), []):
                    rows.append(",".join(row[k] for k in HEADER.split(",")))
                    print(f"{f.stem[:40]:40s} {problem.nc:5d} {target:7.0e} {row['solver']:>17s} "
                          f"{row['iterations']:>7s} {float(row['error']):9.2e} {float(row['cpu_median']):9.5f}"
                          "  (from --reuse-peers)")
                for m in methods:
                    res = dict(mine[m].get(f"{target:.0e}", {"info": "crash", "times": [np.inf]}),
                               solver=m, peak_mb=mine[m].get("peak_mb", np.nan))
                    emit(f, problem, target, res)
            write_text(args.out, "\n".join(rows) + "\n")  # after every file: a cut run keeps it
        if args.figures:
            per_it = {}
            for f in every_file:
                out = subprocess.run([sys.executable, __file__, "--per-iteration", str(f)], capture_output=True,
                                     text=True)
                if out.returncode == 0:
                    per_it[f.name] = (read_fclib(f).W.nnz, json.loads(out.stdout.strip().splitlines()[-1]))
                    print(f.name, per_it[f.name], flush=True)
            write_text(Path(args.out).with_name("fclib_per_iteration.json"), json.dumps(per_it, indent=1))
    load_end = _load()
    from _fclib_report import figures, summary
    table = summary(rows) + f"\nCPU seconds of the solver call (median of the repetitions, one thread each); " \
                            f"start: {load_start}; end: {load_end}.\n"
    write_text(Path(args.out).with_suffix(".md"), table)
    print(table)
    if args.figures:
        for path in figures(rows, Path(args.out).with_name("fclib_per_iteration.json"), Path(args.out).parent):
            print(f"wrote {path}")
    print(f"wrote {args.out} and {Path(args.out).with_suffix('.md')}")
    return 0


if __name__ == "__main__":
    t0 = time.perf_counter()
    code = main()
    if "--worker" not in sys.argv and "--per-iteration" not in sys.argv:
        print(f"total {time.perf_counter() - t0:.0f} s of wall time")
    sys.exit(code)
