"""Benchmark: a large random packing to critical state by the dynamic engine.

One command: ``python benchmarks/assembly_dem_large.py [--grains 10000] [--threads 2]
[--strain 0.25]``.

``Assembly.random`` makes ``--grains`` polydisperse spheres (radii 1 ± 20 %, seed 1; Coulomb
μ = 0.3, kn = kt = 1e4 at p = 1), then ``triaxial(..., method="dem")`` consolidates them
frictionless and compresses them axisymmetrically at I = 4e-4 (damping 0.2) to ``--strain``
axial (Hencky) strain on ``--threads`` threads (``NUMBA_NUM_THREADS``; Numba's OpenMP layer
where it loads, as in the ``assembly`` command: ``frictionrules._threads.prefer_openmp``). The
wall time of the packing and of the run, the steps, the time per step, the peak and end
friction angles (the statistics of ``benchmarks/assembly_yade.py``) and the energy balance →
``results/assembly_dem_large.md``. Progress on a terminal.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--grains", type=int, default=10_000)
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--strain", type=float, default=0.25)
    args = parser.parse_args()
    os.environ["NUMBA_NUM_THREADS"] = str(args.threads)  # before anything imports numba

    import numba
    import numpy as np
    from _dem_compare import Run, statistics
    from _table import write_table

    import frictionrules as fr
    from frictionrules._threads import prefer_openmp

    prefer_openmp()  # a process of its own that does not fork

    progress = None
    if sys.stderr.isatty():
        def progress(done, total):
            print(f"\r{done}/{total} records", end="", file=sys.stderr, flush=True)

    model = fr.ContactModel(fr.Coulomb(0.3), kn=1e4, kt=1e4)
    fr.Assembly.random(40, 3, model, polydispersity=0.2, seed=1)  # compiles the packing's engine
    t0 = time.perf_counter()
    sample = fr.Assembly.random(args.grains, 3, model, polydispersity=0.2, seed=1)
    packing = time.perf_counter() - t0
    t0 = time.perf_counter()
    r = fr.triaxial(sample, "axisymmetric", pressure=1.0, axial_strain=args.strain, method="dem",
                    progress=progress)
    wall = time.perf_counter() - t0
    if progress is not None:
        print(file=sys.stderr)
    meters = r.engine.meters[0]
    steps = int(meters["steps"])
    run = Run(np.asarray(r.strain)[:, 2, 2], np.asarray(r.volumetric_strain), np.asarray(r.stress),
              np.asarray(r.coordination), wall, wall, steps, float(meters["time"]) / steps, {})
    stats = statistics(run, args.strain)
    row = [sample.size, f"{sample.solid_fraction:.3f}", f"{packing:.1f}", f"{wall:.1f}",
           f"{(packing + wall) / 60:.1f}", steps, f"{wall / steps * 1e6:.0f}", f"{stats.peak:.2f}",
           f"{stats.end:.2f}", f"{stats.ev:.4f}", f"{stats.z:.2f}",
           f"{100 * r.energy.relative_error:.3f}", f"{100 * stats.reached:.1f}"]
    write_table("assembly_dem_large", "A large random packing to critical state",
                ["grains", "solid fraction", "packing s", "run s (consolidation + shear)",
                 "total min", "steps", "µs/step", "peak φ (°)", "end φ (°)", "ε_v", "Z",
                 "energy balance error (% of boundary work)", "reached %"], [row],
                notes=f"{args.threads} thread(s), Numba's {numba.threading_layer()} layer; "
                      "Coulomb μ = 0.3, kn = kt = 1e4, p = 1, I = 4e-4, damping 0.2, a record "
                      "every 0.1 %; the first packing's compilation "
                      "excluded (a 40-grain packing before), the run's own included. Load "
                      f"{os.getloadavg()[0]:.1f} at the end.")
    print(r.message)


if __name__ == "__main__":
    main()
