"""Benchmark: Coulomb's problem beside its associated (dilatant, convex) relaxation, every file.

Usage (one command, from the repository root)::

    python benchmarks/relaxation.py [--fclib DIR ...] [--method auto] [--time-limit 60]

For every FCLIB file (``../shared/fclib``, ``../shared/fclib-large``, ``benchmarks/data``):
:func:`frictionrules.compare_relaxation` solves the Coulomb problem and its associated
relaxation (``problem.associated()``, dilatancy ratio 1 at every contact) to 1e-8, and Coulomb's
again from the relaxation's answer. The table gives the error of the relaxation's answer under
Coulomb's measure, the dissipation -r.u of both answers, the tangential (friction) work of the
relaxed one, the largest normal velocity at a loaded contact, the sliding contacts, and the
iterations and time of Coulomb's problem from zero and from the relaxation's answer (the warm
start). Writes ``benchmarks/results/relaxation.md``.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))
sys.path.insert(0, str(ROOT / "benchmarks"))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--fclib", nargs="*")
    ap.add_argument("--method", default="auto")
    ap.add_argument("--time-limit", type=float, default=60.0)
    args = ap.parse_args(argv)
    from _table import write_table
    from frictionrules import FrictionContactProblem, compare_relaxation, read_fclib, solve
    shared = ROOT.parent / "shared"
    dirs = [Path(d) for d in args.fclib] if args.fclib else [shared / "fclib", shared / "fclib-large",
                                                              ROOT / "benchmarks" / "data"]
    files = sorted((f for d in dirs if d.is_dir() for f in d.glob("*.hdf5")), key=lambda f: f.stat().st_size)
    solve(FrictionContactProblem([[1.0, 0, 0], [0, 1, 0], [0, 0, 1]], [-1.0, 2.0, 0.0], [0.5]))
    rows = []
    for f in files:
        p = read_fclib(f)
        c = compare_relaxation(p, method=args.method, tol=1e-8, time_limit=args.time_limit)
        rows.append([f.stem, p.nc, f"{c.coulomb.error:.1e}", f"{c.associated.error:.1e}",
                     f"{c.coulomb_error_of_associated:.1e}", f"{c.dissipation_coulomb:.3e}",
                     f"{c.dissipation_associated:.1e}", f"{c.friction_work_associated:.3e}",
                     f"{c.normal_velocity_coulomb:.1e}", f"{c.normal_velocity_associated:.1e}",
                     f"{c.sliding_coulomb} / {c.sliding_associated}",
                     f"{c.coulomb.iterations}, {c.coulomb.seconds:.3f}",
                     f"{c.warm_started.iterations}, {c.warm_started.seconds:.3f}"])
        print(" | ".join(str(x) for x in rows[-1]), flush=True)
    write_table("relaxation", "Coulomb's problem beside its associated relaxation",
                ["file", "nc", "error C", "error A", "C-error of A's answer", "D = -r.u (C)", "D (A)",
                 "friction work (A)", "max u_N loaded (C)", "(A)", "sliding C / A", "C from 0: it, s",
                 "C from A's answer: it, s"], rows,
                notes=f"method {args.method}, tol 1e-8, time limit {args.time_limit:g} s per solve.")
    return 0


if __name__ == "__main__":
    sys.exit(main())
