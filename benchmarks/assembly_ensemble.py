"""Benchmark: an ensemble of random packings (``frictionrules.ensemble``), the means and their
95 % confidence intervals, and how the interval narrows with the number of samples.

One command: ``python benchmarks/assembly_ensemble.py [--seeds 1,...,10] [--grains 100]
[--strain 0.05] [--mu 0.3] [--jobs 2] [--figure FILE]``.

Random packings of ``--grains`` spheres (radii 1 ± 20 %, ``Assembly.random`` with each seed;
Coulomb ``--mu``, kn = kt = 1e4), consolidated without friction to p = 1 and compressed
axisymmetrically to ``--strain`` by the dynamic engine (I = 4e-4, damping 0.2); the runs on a
process pool of ``--jobs`` workers, in a run folder under ``results/assembly_ensemble/`` (a
second call keeps the finished runs). Writes ``results/assembly_ensemble.md``: per quantity,
n, the mean, the 95 % interval and its half-width over all seeds and over the first half of
them (the half-width shrinks about as 1/√n), and the wall time; ``--figure``: the mean curves
of σ1/σ3 and ε_v with their bands.
"""

from __future__ import annotations

import argparse
import concurrent.futures
import multiprocessing
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _table import RESULTS, write_table


def main(argv=None) -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--seeds", default=",".join(str(s) for s in range(1, 11)))
    p.add_argument("--grains", type=int, default=100)
    p.add_argument("--strain", type=float, default=0.05)
    p.add_argument("--mu", type=float, default=0.3)
    p.add_argument("--jobs", type=int, default=2)
    p.add_argument("--figure")
    args = p.parse_args(argv)
    import frictionrules as fr
    seeds = [int(s) for s in args.seeds.split(",")]
    model = fr.ContactModel(fr.Coulomb(args.mu), kn=1e4, kt=1e4)
    t0 = time.perf_counter()
    samples = [fr.Assembly.random(args.grains, 3, model, polydispersity=0.2, seed=s) for s in seeds]
    packing = time.perf_counter() - t0
    options = dict(pressure=1.0, axial_strain=args.strain, method="dem", record_every=args.strain / 50)
    folder = RESULTS / "assembly_ensemble" / f"n{args.grains}-mu{args.mu}-e{args.strain}"
    t0 = time.perf_counter()
    context = multiprocessing.get_context("spawn")
    with concurrent.futures.ProcessPoolExecutor(args.jobs, mp_context=context) as pool:
        result = fr.ensemble(samples, "axisymmetric", executor=pool, run_folder=folder, **options)
    wall = time.perf_counter() - t0
    half = fr.ensemble(samples[:max(1, len(samples) // 2)], "axisymmetric", run_folder=folder,
                       **options)  # the first half: kept runs, read back
    rows = []
    for name in ("peak_friction_angle", "critical_friction_angle", "volumetric_strain_end",
                 "coordination_end", "sliding_fraction_end"):
        for label, res in ((f"all {len(samples)}", result), (f"first {len(half.runs)}", half)):
            ci = getattr(res.summary[0], name)
            rows.append([name, label, ci.n, f"{ci.mean:.5g}", f"[{ci.low:.5g}, {ci.high:.5g}]",
                         f"{ci.half_width:.3g}", f"{ci.std:.3g}"])
    statuses = ", ".join(f"{sum(r.status == s for r in result.runs)} {s}"
                         for s in ("new", "resumed", "kept", "failed", "not started")
                         if any(r.status == s for r in result.runs))
    notes = (f"{args.grains} spheres (radii 1 ± 20 %), Coulomb μ = {args.mu}, kn = kt = 1e4, p = 1, "
             f"axisymmetric to {args.strain:g} at I = 4e-4; seeds {args.seeds}. Runs: {statuses}; "
             f"wall {wall:.1f} s on {args.jobs} worker processes (the packings: {packing:.1f} s "
             "before). The interval: mean ± t(0.975, n-1) s/√n.")
    write_table("assembly_ensemble", "Ensemble of random packings: means and 95 % intervals",
                ["quantity", "runs", "n", "mean", "95 % interval", "half-width", "s"], rows, notes)
    if args.figure:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        from frictionrules.plot.assembly import plot_ensemble
        fig, axes = plt.subplots(1, 2, figsize=(9, 3.6))
        plot_ensemble(result, "stress_ratio", ax=axes[0])
        plot_ensemble(result, "volumetric_strain", ax=axes[1])
        fig.tight_layout()
        fig.savefig(args.figure, dpi=150)
        print(f"wrote {args.figure}")


if __name__ == "__main__":
    main()
