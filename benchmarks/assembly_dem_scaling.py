"""Benchmark: the dynamic engine's cost per step against the number of contacts, on one and two
threads.

One command: ``python benchmarks/assembly_dem_scaling.py [--tiles 1,2,3,4,5] [--steps 400]
[--memory-tiles 7]``.

A random packing of 400 spheres (radii 1 ± 20 %, ``Assembly.random``, seed 1; Coulomb μ = 0.3,
kn = kt = 1e4) is tiled k × k × k times into a periodic cell k times larger (400 k³ grains:
the same packing, repeated), squeezed frictionless towards p = 1 for 2000 steps, then sheared
at I = 4e-4; the CPU and wall time of ``--steps`` steps of the shear on 1 and 2 threads (each
in its own process: ``NUMBA_NUM_THREADS``, Numba's OpenMP layer where it loads), the pairs
and contacts, the peak memory; the slope of log(time per step) against log(contacts) →
``results/assembly_dem_scaling.md``; the peak memory of one run at ``--memory-tiles`` (7:
137,200 grains) → ``results/assembly_dem_memory.md``.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _table import write_table

#: Timed runs of ``--steps`` steps per measurement; the table has the fastest.
REPEATS = 3


def _sample(k: int):
    import frictionrules as fr
    base = fr.Assembly.random(400, 3, fr.ContactModel(fr.Coulomb(0.3), kn=1e4, kt=1e4),
                              polydispersity=0.2, seed=1)
    h = base.cell
    shifts = np.array([[a, b, c] for a in range(k) for b in range(k) for c in range(k)], float)
    x = (base.positions[None, :, :] + (shifts @ h.T)[:, None, :]).reshape(-1, 3)
    r = np.tile(base.radii, len(shifts))
    return fr.Assembly(x, r, k * h, base.model)


def _child(k: int, steps: int) -> dict:
    """One measurement (in a process of its own)."""
    from frictionrules._threads import prefer_openmp
    prefer_openmp()
    from frictionrules.assembly._dem import _protocol as P
    from frictionrules.assembly._dem._dynamics import Dynamics
    a = _sample(k)
    dyn = Dynamics(a, density=1.0, damping=0.2)
    st = dyn.init()
    rate = P.unit_rate(4e-4, a.radii, 1.0, 1.0)
    comps = P.components(3)
    iso = np.array([1.0 if i == j else 0.0 for i, j in comps])
    squeeze = P._control(np.ones(len(comps)), iso, iso, np.zeros(len(comps)), 0.0, 10 * rate, 1.0,
                         False, 3)
    st, _ = dyn.run(st, squeeze, 1e9, 2000, True)
    dyn.bring_in_laws(st)
    P.start_stage(st)
    spec = P.triaxial_stage("axisymmetric", 3, 1.0, 0.25, rate, "rectangular")
    ctl = P._control(spec.free, spec.start, spec.end, spec.rate, spec.duration, 10 * rate, 1.0,
                     False, 3)
    st, _ = dyn.run(st, ctl, 1e9, 50)
    best = None
    for _ in range(REPEATS):  # the least of a few: the machine's other load only slows a run
        c0, w0, s0 = time.process_time(), time.perf_counter(), int(st.meters[0]["steps"])
        st, _ = dyn.run(st, ctl, 1e9, steps)
        n = int(st.meters[0]["steps"]) - s0
        run = ((time.perf_counter() - w0) / n * 1e6, (time.process_time() - c0) / n * 1e6)
        best = run if best is None or run[0] < best[0] else best
    return {"grains": a.size, "pairs": len(st.pairs.i), "contacts": int(st.meters[0]["closed"]),
            "cpu_us": best[1], "wall_us": best[0],
            "memory_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tiles", default="1,2,3,4,5")
    parser.add_argument("--steps", type=int, default=400)
    parser.add_argument("--memory-tiles", type=int, default=7,
                        help="k of the memory row (1 thread, 20 steps); 0 for none")
    parser.add_argument("--child", type=int, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child is not None:
        print(json.dumps(_child(args.child, args.steps)))
        return
    rows = []
    for k in (int(t) for t in args.tiles.split(",")):
        one, two = (_measure(k, args.steps, threads) for threads in (1, 2))
        rows.append([one["grains"], one["pairs"], one["contacts"], f"{one['cpu_us']:.0f}",
                     f"{one['wall_us']:.0f}", f"{two['wall_us']:.0f}",
                     f"{one['wall_us'] / two['wall_us']:.2f}", f"{max(one['memory_mb'], two['memory_mb']):.0f}"])
    c = np.array([float(r[2]) for r in rows])
    t = np.array([float(r[4]) for r in rows])
    slope = float(np.polyfit(np.log(c), np.log(t), 1)[0]) if len(rows) > 1 else float("nan")
    write_table("assembly_dem_scaling",
                "The dynamic engine: cost per step against contacts",
                ["grains", "pairs", "contacts", "1 thread: CPU µs/step", "1 thread: wall µs/step",
                 "2 threads: wall µs/step", "speed-up", "peak memory MB"], rows,
                notes=f"slope of log(wall per step, 1 thread) against log(contacts): {slope:.2f}. "
                      f"{args.steps} steps of axisymmetric shear (I = 4e-4) after 2000 steps of "
                      "frictionless isotropic compression; the 400-sphere packing tiled k³ times. Wall times on "
                      f"{os.cpu_count()} cores (load {os.getloadavg()[0]:.1f} at the end).")
    print(f"slope {slope:.2f}")
    if args.memory_tiles:
        big = _measure(args.memory_tiles, 20, 1)
        write_table("assembly_dem_memory", "The dynamic engine: memory of a large sample",
                    ["grains", "pairs", "contacts", "1 thread: wall µs/step", "peak memory MB"],
                    [[big["grains"], big["pairs"], big["contacts"], f"{big['wall_us']:.0f}",
                      f"{big['memory_mb']:.0f}"]],
                    notes="the peak resident memory of the whole process (Python, NumPy, Numba "
                          "and the compiled engine included), 20 steps of the shear above.")


def _measure(k: int, steps: int, threads: int) -> dict:
    """One child process on ``threads`` threads (``NUMBA_NUM_THREADS``)."""
    env = dict(os.environ, NUMBA_NUM_THREADS=str(threads))
    proc = subprocess.run([sys.executable, __file__, "--child", str(k), "--steps", str(steps)],
                          env=env, capture_output=True, text=True, check=True)
    out = json.loads(proc.stdout.strip().splitlines()[-1])
    print(k, threads, out, flush=True)
    return out


if __name__ == "__main__":
    main()
