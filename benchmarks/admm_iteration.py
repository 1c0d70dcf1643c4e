"""Benchmark: ADMM's CPU time per iteration on every FCLIB file, ours beside Pinocchio's.

Usage (one command, from the repository root)::

    python benchmarks/admm_iteration.py [--fclib DIR ...] [--only SUBSTRING]
                                        [--pinocchio-python PATH] [--target 1e-8] [--rounds 3]
                                        [--baseline OTHER_CHECKOUT]

For each file (``../shared/fclib``, ``../shared/fclib-large`` by default) and each solver, two
measures, both CPU seconds of the solver call on one thread (``time.thread_time``):

* ``to target``: the run to the target error (our Siconos error of the answer; Pinocchio's
  tolerances are tightened by 1e-2 and 1e-4 while our error of its answer misses the target,
  as ``benchmarks/fclib.py`` does), its iterations, and its time divided by them (what a user
  pays per iteration, the factorizations included);
* ``marginal``: the time of ``K2`` iterations minus that of ``K1`` (tolerance zero: neither
  stops early), divided by ``K2 - K1`` (the factorizations of the start excluded; a change of
  the penalty inside the window is counted, for both solvers). Runs of ``K1`` and ``K2``
  iterations alternate and the median of the pairs' differences is kept, for both solvers: the
  start of one of our solves on a small file (about 1.5 ms on local_problem_test, ordering and
  factorizations) varies by more than 100 iterations cost, and medians of separate series
  moved the marginal by 2-5 µs from run to run.

Ours and Pinocchio's runs are interleaved per file, ``--rounds`` times (ours, Pinocchio, ours,
...), and the medians kept, so that the load of a shared machine falls on both sides. Pinocchio
runs in its own Python (``--pinocchio-python`` or ``$PINOCCHIO_PYTHON``; see
``benchmarks/_peers.py``). Writes ``benchmarks/results/admm_iteration.md``.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))
sys.path.insert(0, str(ROOT / "benchmarks"))

#: The marginal window: iterations K1 and K2 (tolerance zero).
K1, K2 = 20, 120
#: Our repetitions of one measure: until this much CPU, at most REPEATS_MAX (the median kept).
REPEAT_SECONDS, REPEATS_MAX = 0.3, 50
#: Pairs of runs (K1, K2 iterations) for the marginal: until this much CPU, at most PAIRS_MAX
#: (the median of their differences kept; Pinocchio's runner: its own REPEAT_SECONDS, 400 runs).
PAIR_SECONDS, PAIRS_MAX = 0.6, 200
#: CPU seconds allowed to one run of either solver.
TIME_LIMIT = 30.0


def worker(path: str, target: float) -> None:
    """Our ADMM on one file (in its own process): JSON on stdout."""
    from frictionrules import read_fclib, solve
    p = read_fclib(path)
    solve(p, method="admm", tol=target, time_limit=TIME_LIMIT)       # kernels loaded, untimed

    def timed(**kw):
        times, spent, s = [], 0.0, None
        while len(times) < REPEATS_MAX and (not times or spent < REPEAT_SECONDS):
            c0 = time.thread_time()
            s = solve(p, method="admm", time_limit=TIME_LIMIT, **kw)
            times.append(time.thread_time() - c0)
            spent += times[-1]
        return s, float(np.median(times))
    s, t = timed(tol=target)
    pairs, spent = [], 0.0
    while len(pairs) < PAIRS_MAX and (not pairs or spent < PAIR_SECONDS):
        pair = []
        for k in (K1, K2):
            c0 = time.thread_time()
            solve(p, method="admm", time_limit=TIME_LIMIT, tol=0.0, max_iter=k)
            pair.append(time.thread_time() - c0)
        pairs.append(pair[1] - pair[0])
        spent += sum(pair)
    print(json.dumps({"iterations": s.iterations, "error": s.error, "cpu": t,
                      "marginal": float(np.median(pairs)) / (K2 - K1), "reason": s.reason}))


def ours(path: Path, target: float, script: str = __file__) -> dict:
    out = subprocess.run([sys.executable, script, "--worker", str(path), repr(target)], capture_output=True,
                         text=True, env=dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1"))
    if out.returncode != 0:
        return {"iterations": 0, "error": float("nan"), "cpu": float("nan"), "marginal": float("nan"),
                "reason": out.stderr.strip()[-200:]}
    return json.loads(out.stdout.strip().splitlines()[-1])


def pinocchio(python: str, problem, data: Path, tmp: Path, target: float) -> dict:
    import _peers
    from frictionrules.multicontact import fc3d_error
    for tol in (target, 1e-2 * target, 1e-4 * target):
        res = _peers.run_peer(python, _peers.PINOCCHIO_RUNNER, data, "ADMM", 20000, tol, tmp, TIME_LIMIT)
        err = fc3d_error(problem, res["r"]) if res["r"] is not None else float("nan")
        if err <= target or res["r"] is None:
            break
    times = np.array(_peers.run_peer(python, _peers.PINOCCHIO_RUNNER, data, "ADMM", f"{K1},{K2}", 0.0, tmp,
                                     TIME_LIMIT)["times"])
    pairs = times[:times.size // 2 * 2].reshape(-1, 2)
    return {"iterations": int(res["iterations"]), "error": err, "cpu": float(np.median(res["times"])),
            "marginal": float(np.median(pairs[:, 1] - pairs[:, 0])) / (K2 - K1), "reason": res["info"]}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--fclib", nargs="*", help="folders of FCLIB files (default: the shared ones)")
    ap.add_argument("--only", help="only files whose name contains one of these (comma-separated)")
    ap.add_argument("--pinocchio-python", help="a Python that imports pinocchio (or $PINOCCHIO_PYTHON)")
    ap.add_argument("--target", type=float, default=1e-8, help="target error (default 1e-8)")
    ap.add_argument("--rounds", type=int, default=3, help="interleaved rounds per file (default 3)")
    ap.add_argument("--out", default="admm_iteration", help="name of the table in benchmarks/results/")
    ap.add_argument("--baseline", help="another checkout of the library (its sources and this benchmark): its ADMM "
                                       "timed too, interleaved (baseline, ours, Pinocchio), in 'before' columns")
    ap.add_argument("--worker", nargs=2, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.worker:
        worker(args.worker[0], float(args.worker[1]))
        return 0
    import _peers
    from _table import write_table

    from frictionrules.io import read_fclib
    shared = ROOT.parent / "shared"
    dirs = [Path(d) for d in args.fclib] if args.fclib else [shared / "fclib", shared / "fclib-large"]
    files = sorted((f for d in dirs if d.is_dir() for f in d.glob("*.hdf5")), key=lambda f: f.stat().st_size)
    files = [f for f in files if not args.only or any(o in f.name for o in args.only.split(","))]
    pin = _peers.pinocchio_python(args.pinocchio_python)
    if not pin:
        print("Pinocchio is not found (python3 -m venv pin && pin/bin/pip install pin scipy; then "
              "--pinocchio-python pin/bin/python): its columns are left out.")
    load_start = os.getloadavg()
    rows = []
    with tempfile.TemporaryDirectory() as tmpdir:
        tmp = Path(tmpdir)
        for f in files:
            problem = read_fclib(f)
            if problem.nc <= 16:            # the compiled small path: no sparse iteration to time
                continue
            data = _peers.save_problem(problem, tmp / "problem.npz")
            a, b, c = [], [], []
            for _ in range(args.rounds):
                if args.baseline:
                    c.append(ours(f, args.target, str(Path(args.baseline) / "benchmarks" / "admm_iteration.py")))
                a.append(ours(f, args.target))
                if pin:
                    b.append(pinocchio(pin, problem, data, tmp, args.target))

            def med(runs, key):
                return float(np.median([r[key] for r in runs])) if runs else float("nan")

            def cells(runs):
                if not runs:
                    return ["-"] * 5
                it = runs[-1]["iterations"]
                return [str(it), f"{runs[-1]['error']:.1e}", f"{1e3 * med(runs, 'cpu'):.2f}",
                        f"{1e6 * med(runs, 'cpu') / max(it, 1):.1f}", f"{1e6 * med(runs, 'marginal'):.1f}"]
            before = ([str(c[-1]["iterations"]), f"{c[-1]['error']:.1e}", f"{1e6 * med(c, 'marginal'):.1f}"]
                      if args.baseline else [])
            rows.append([f.stem[:32], problem.nc, problem.W.nnz] + before + cells(a) + cells(b))
            print(rows[-1], flush=True)
    load_end = os.getloadavg()
    header = ["file", "contacts", "nnz(W)"] + (["before: iterations", "error", "marginal µs/it"] if args.baseline
                                               else []) + ["ours: iterations", "error", "CPU ms", "µs/iteration", "marginal µs/it",
              "Pinocchio: iterations", "error", "CPU ms", "µs/iteration", "marginal µs/it"]
    notes = (f"Target {args.target:.0e} (our Siconos error of each answer). CPU seconds of the solver call on one "
             f"thread, median of {args.rounds} interleaved rounds (each a median of repetitions); µs/iteration = "
             f"CPU / iterations of the run to the target; marginal = median over alternating pairs of runs of "
             f"(time of {K2} iterations - time of {K1}) / {K2 - K1}, tolerance zero. Load average "
             f"{load_start[0]:.2f} at the start, {load_end[0]:.2f} at the "
             f"end, on {os.cpu_count()} cores." + (f" 'before': the checkout {args.baseline}, run interleaved "
                                                     "with ours and Pinocchio." if args.baseline else ""))
    write_table(args.out, "ADMM per iteration, ours beside Pinocchio", header, rows, notes)
    return 0


if __name__ == "__main__":
    sys.exit(main())
