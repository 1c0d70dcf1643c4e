"""Benchmark: the quasi-static limit of the dynamic engine — halving the inertial number.

One command: ``python benchmarks/assembly_dem_quasistatic.py [--seeds 1,2,3] [--jobs 2]``.

For each seed, ``Assembly.random`` makes 400 polydisperse spheres (radii 1 ± 20 %; Coulomb
μ = 0.3, kn = kt = 1e4 at p = 1) and ``triaxial(..., method="dem")`` compresses them
axisymmetrically to 25 % axial strain at I = 4e-4 and at I = 2e-4 (damping 0.2); the peak and
end friction angles, ε_v and Z (the statistics of ``benchmarks/assembly_yade.py``) of both,
their differences per sample and over the samples → ``results/assembly_dem_quasistatic.md``.
The runs go ``--jobs`` at a time, each in a process of its own on one thread.
"""

from __future__ import annotations

import argparse
import os
import sys
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

RATES = (4e-4, 2e-4)
STRAIN = 0.25


def one(seed: int, inertial_number: float):
    """Statistics of one run (in a worker process)."""
    os.environ["NUMBA_NUM_THREADS"] = "1"
    import numpy as np

    import frictionrules as fr
    from _dem_compare import Run, statistics
    sample = fr.Assembly.random(400, 3, fr.ContactModel(fr.Coulomb(0.3), kn=1e4, kt=1e4),
                                polydispersity=0.2, seed=seed)
    r = fr.triaxial(sample, "axisymmetric", pressure=1.0, axial_strain=STRAIN, method="dem",
                    inertial_number=inertial_number)
    run = Run(np.asarray(r.strain)[:, 2, 2], np.asarray(r.volumetric_strain), np.asarray(r.stress),
              np.asarray(r.coordination), 0.0, 0.0, 0, 0.0, {})
    return statistics(run, STRAIN)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", default="1,2,3")
    parser.add_argument("--jobs", type=int, default=2)
    args = parser.parse_args()
    from _table import write_table
    seeds = [int(s) for s in args.seeds.split(",")]
    jobs = [(seed, rate) for seed in seeds for rate in RATES]
    with ProcessPoolExecutor(args.jobs) as pool:
        stats = dict(zip(jobs, pool.map(one, *zip(*jobs))))
    rows, diffs = [], []
    for seed in seeds:
        a, b = stats[(seed, RATES[0])], stats[(seed, RATES[1])]
        d = [b.peak - a.peak, b.end - a.end, b.ev - a.ev, b.z - a.z]
        diffs.append(d)
        rows.append([seed, f"{a.peak:.2f}", f"{b.peak:.2f}", f"{d[0]:+.2f}", f"{a.end:.2f}",
                     f"{b.end:.2f}", f"{d[1]:+.2f}", f"{a.ev:.4f}", f"{b.ev:.4f}", f"{d[2]:+.4f}",
                     f"{a.z:.2f}", f"{b.z:.2f}", f"{d[3]:+.2f}"])
        print(rows[-1], flush=True)
    mean = [sum(c) / len(c) for c in zip(*diffs)]
    rows.append(["**mean**", "", "", f"{mean[0]:+.2f}", "", "", f"{mean[1]:+.2f}", "", "",
                 f"{mean[2]:+.4f}", "", "", f"{mean[3]:+.2f}"])
    i1, i2 = (f"I = {r:g}" for r in RATES)
    write_table("assembly_dem_quasistatic", "The quasi-static limit: halving the inertial number",
                ["seed", f"peak φ, {i1}", f"peak φ, {i2}", "Δ", f"end φ, {i1}", f"end φ, {i2}", "Δ",
                 f"ε_v, {i1}", f"ε_v, {i2}", "Δ", f"Z, {i1}", f"Z, {i2}", "Δ"], rows,
                notes="400 spheres, radii 1 ± 20 % (Assembly.random), Coulomb μ = 0.3, "
                      "kn = kt = 1e4, p = 1, damping 0.2, axisymmetric to 25 %; peak: the "
                      "largest ±0.25 % running mean of the mobilized angle, end: its mean over "
                      "20–25 % (benchmarks/_dem_compare.py).")


if __name__ == "__main__":
    main()
