"""Benchmark: the sled of ``examples/mujoco_snake_sled.py`` stepped by ``frictionrules.mujoco``:
solves above ``tol``, sweeps per step and time per step.

One command: ``python benchmarks/mujoco_sled.py [--seconds 3] [--rounds 3] [--tol 1e-8] [--max-iter 200] [--out FILE]``.

The sled (three spherical feet of one rigid body: W of rank 6 for 9 rows) on the wedge
asperity law (``WedgeAsperity(10 deg, 0.5)``, the law path) and on the symmetric elliptic law
(``EllipticOrthotropic(0.52, 0.49)``, the cone path with turned frames), each run
``--seconds`` of simulated time from rest, ``--rounds`` times in turn (interleaved, after one
short run of warm-up each). Per law: the steps whose solve stopped above ``tol``, the largest
final error, the iterations per step (mean and largest: sweeps, plus Newton steps where the
solve went on to them), how the solves ended (the stages they ran), CPU ms per step (the
median over the rounds and their range) and the sled's final position. Writes
``benchmarks/results/<out>.md``.
"""

from __future__ import annotations

import argparse
import collections
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent / "examples"))
from _table import write_table  # noqa: E402


def run(kind: str, seconds: float, tol: float, max_iter: int) -> dict:
    """One run of the sled; its statistics."""
    import mujoco
    import mujoco_snake_sled as ex

    import frictionrules as fr
    from frictionrules.mujoco import Simulator
    model = mujoco.MjModel.from_xml_string(ex.scene_xml())
    data = mujoco.MjData(model)
    law = fr.WedgeAsperity(alpha=ex.ALPHA, mu=ex.MU) if kind == "sawtooth" else fr.EllipticOrthotropic(ex.MU_X, ex.MU_Y)
    sim = Simulator(model, {"floor": law}, axes={"floor": (1.0, 0.0, 0.0)}, data=data, tol=tol, max_iter=max_iter)
    its, stages = [], collections.Counter()
    t0 = time.thread_time()
    for _ in range(int(round(seconds / ex.H))):
        data.ctrl[0] = ex.drive(data.time)
        sol = sim.step().solution
        if sol is not None:
            its.append(sol.iterations)
            stages[sol.method] += 1
    cpu = time.thread_time() - t0
    return dict(cpu=cpu / sim.steps, steps=sim.steps, unconverged=sim.unconverged, max_error=sim.max_error,
                its=np.array(its), stages=stages, x=tuple(data.qpos[:2]))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=3.0)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--tol", type=float, default=1e-8)
    ap.add_argument("--max-iter", type=int, default=200)
    ap.add_argument("--out", default="mujoco_sled")
    args = ap.parse_args(argv)
    kinds = ("sawtooth", "elliptic (frictionrules)")
    for kind in kinds:
        run(kind, 0.1, args.tol, args.max_iter)            # warm-up: compiled kernels
    results = {k: [] for k in kinds}
    for _ in range(args.rounds):
        for kind in kinds:
            results[kind].append(run(kind, args.seconds, args.tol, args.max_iter))
    rows = []
    for kind in kinds:
        rs = results[kind]
        last = rs[-1]
        ms = np.array([r["cpu"] for r in rs]) * 1e3
        stages = ", ".join(f"{m}: {n}" for m, n in last["stages"].most_common())
        rows.append([kind, f"{last['unconverged']}/{last['steps']}", f"{last['max_error']:.1e}",
                     f"{last['its'].mean():.1f} / {last['its'].max()}", stages,
                     f"{np.median(ms):.2f} ({ms.min():.2f}-{ms.max():.2f})",
                     f"({last['x'][0]:+.6f}, {last['x'][1]:+.6f})"])
    notes = (f"tol = {args.tol:g}, max_iter = {args.max_iter}, {args.seconds:g} s of simulated time "
             f"({rows and results[kinds[0]][-1]['steps']} steps of 4 ms), {args.rounds} interleaved rounds; "
             "CPU time of this thread per step, collision and dynamics included. The machine was "
             "shared with other jobs (under load).")
    write_table(args.out, "MuJoCo sled on three feet: the solves of frictionrules.mujoco",
                ["law", "above tol / steps", "largest error", "iterations per step, mean / max",
                 "stages of the solves (count)", "ms / step, median (range)", "final (x, y) (m)"],
                rows, notes)


if __name__ == "__main__":
    main()
