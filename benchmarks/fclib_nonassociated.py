"""Benchmark: the shared FCLIB files with their Coulomb law replaced by the transformed-variable
rule (1.17)-(1.18), beside the same files in Coulomb.

Usage (one command, from the repository root)::

    python benchmarks/fclib_nonassociated.py [--fclib DIR ...] [--time-limit 60] [--ratio 0.5]

For every FCLIB file (``../shared/fclib`` by default) four solves to 1e-8, each with the time
limit:

* Coulomb on the cone path, ``method="auto"`` and ``method="nsgs"`` (Siconos' error);
* Coulomb as ``TransformedCoulomb(mu, mu)`` on the law path (``nsgs``, the law's natural map):
  the same physics, the cost of the law path's per-contact return maps;
* ``TransformedCoulomb(mu, ratio mu)`` at every contact (axis 1 along the contact's T1), the
  non-associated rule, on the law path.

The law path's first call per law structure generates and compiles its kernels; each problem
is solved once with ``max_iter=1`` before it is timed. Writes
``benchmarks/results/fclib_nonassociated.md``.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))
sys.path.insert(0, str(ROOT / "benchmarks"))


def _cell(sol) -> str:
    mark = "" if sol.converged else f" ({sol.reason}, {sol.error:.0e})"
    return f"{sol.iterations}, {sol.seconds:.3f}{mark}"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--fclib", nargs="*")
    ap.add_argument("--time-limit", type=float, default=60.0)
    ap.add_argument("--ratio", type=float, default=0.5)
    args = ap.parse_args(argv)
    from _table import write_table
    from frictionrules import FrictionContactProblem, TransformedCoulomb, read_fclib, solve
    dirs = [Path(d) for d in args.fclib] if args.fclib else [ROOT.parent / "shared" / "fclib"]
    files = sorted((f for d in dirs if d.is_dir() for f in d.glob("*.hdf5")), key=lambda f: f.stat().st_size)
    rows = []
    for f in files:
        p = read_fclib(f)
        mu = p.coulomb_mu()
        same = {m: TransformedCoulomb(m, m) for m in set(mu.tolist())}
        half = {m: TransformedCoulomb(m, args.ratio * m) for m in set(mu.tolist())}
        law_c = FrictionContactProblem(p.W, p.q, [same[m] for m in mu.tolist()], title=p.title)
        law_t = FrictionContactProblem(p.W, p.q, [half[m] for m in mu.tolist()], title=p.title)
        for warm in (p, law_c, law_t):
            solve(warm, method="nsgs", max_iter=1)
        lim = args.time_limit
        auto = solve(p, method="auto", tol=1e-8, time_limit=lim)
        nsgs = solve(p, method="nsgs", tol=1e-8, time_limit=lim)
        lc = solve(law_c, tol=1e-8, time_limit=lim)
        lt = solve(law_t, tol=1e-8, time_limit=lim)
        rows.append([f.stem, p.nc, _cell(auto), _cell(nsgs), _cell(lc), _cell(lt),
                     f"{lt.error:.1e}", f"{float((-(lt.r * lt.u).reshape(-1, 3).sum(1)).min()):.1e}"])
        print(" | ".join(str(x) for x in rows[-1]), flush=True)
    write_table("fclib_nonassociated",
                f"FCLIB files in Coulomb and with TransformedCoulomb(mu, {args.ratio:g} mu) at every contact",
                ["file", "nc", "Coulomb auto: it, s", "Coulomb nsgs: it, s",
                 "TransformedCoulomb(mu, mu), law path: it, s",
                 f"TransformedCoulomb(mu, {args.ratio:g} mu): it, s", "its law error",
                 "min dissipation -r.u"], rows,
                notes=(f"tol 1e-8 (Siconos' error on the cone path, the laws' natural map on the law path), "
                       f"time limit {args.time_limit:g} s per solve; wall seconds of the solve "
                       "(kernels compiled beforehand). it: sweeps (nsgs), all stages (auto)."))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
