"""Benchmark: grain assemblies — the fcc unit cell to its limit state, and the time of one
increment against the number of contacts.

One command: ``python benchmarks/assembly.py [--sizes 1,2,4,6,8] [--figure FILE]``.

* fcc unit cell (4 spheres, 24 contacts), Coulomb μ = 0.3, kn = kt = 1e6, axisymmetric
  compression at pressure 1 to the plateau (40 increments of 5e-6): best wall time of 5 runs
  after a warm-up (Numba compiles the contact kernel on first use);
* time per shear increment of fcc arrays of k³ unit cells (24 k³ contacts) and of a random
  packing of 400 polydisperse spheres, with the Newton iterations per increment; the slope of
  log(time) against log(contacts) is the scaling. Writes ``benchmarks/results/assembly.md``
  (and the figure when asked).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _table import best_of, write_table  # noqa: E402

from frictionrules import Assembly, ContactModel, Coulomb, triaxial  # noqa: E402
from frictionrules.assembly._loading import _controls, initial_state, prepared_state, run  # noqa: E402
from frictionrules.assembly._solver import solve_increment  # noqa: E402


def fcc_to_limit() -> tuple[float, float]:
    model = ContactModel(Coulomb(0.3), kn=1e6, kt=1e6)
    run = lambda: triaxial(Assembly.lattice("fcc", model), "axisymmetric", pressure=1.0,  # noqa: E731
                           axial_strain=2e-4, increments=40)
    r = run()
    return best_of(run, repeat=5), r.peak_ratio


def increment_time(assembly, state, kind, strain=2e-6, repeat=3):
    _, shear = _controls(kind, assembly.dim, 1.0, strain, 1, 1)
    c = shear[0]
    free, pres, target = np.array(c.free), -np.array(c.strain), np.array(c.target)
    times, its = [], []
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = solve_increment(state.positions, assembly.radii, state.cell, state.contacts, free,
                              pres, target, gap=assembly.tolerance)
        times.append(time.perf_counter() - t0)
        its.append(out.iterations)
    return min(times), its[0], out.converged


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="1,2,4,6,8", help="fcc repeats k (24 k^3 contacts)")
    parser.add_argument("--random", type=int, default=400, help="spheres of the random packing (0: none)")
    parser.add_argument("--figure", help="scaling figure (.png)")
    args = parser.parse_args(argv)
    t_fcc, peak = fcc_to_limit()
    rows = [["fcc unit cell to its limit (40 increments)", 24, "-", f"{t_fcc:.3f}",
             f"peak σzz/σxx = {peak:.6f} (closed form {2 * 1.3 / 0.7:.6f})"]]
    model = ContactModel(Coulomb(0.3), kn=1e6, kt=1e6)
    pts = []
    for k in (int(s) for s in args.sizes.split(",")):
        a = Assembly.lattice("fcc", model, cells=k)
        cons, _ = _controls("axisymmetric", 3, 1.0, 1e-6, 1, 1)
        t0 = time.perf_counter()
        rows_c, _, _ = run(a, initial_state(a), cons, max_cuts=0)
        t_cons = time.perf_counter() - t0
        base = rows_c[-1][0]
        t, it, ok = increment_time(a, base, "axisymmetric", repeat=1 if k > 4 else 3)
        m = base.contacts.size
        pts.append((m, t))
        rows.append([f"fcc {k}x{k}x{k}, one shear increment (consolidation: {t_cons:.2f} s)", m, it,
                     f"{t:.3f}", "converged" if ok else "NOT converged"])
        print(rows[-1], flush=True)
    if args.random:
        t0 = time.perf_counter()
        a = Assembly.random(args.random, 3, ContactModel(Coulomb(0.3), kn=1e4, kt=1e4),
                            polydispersity=0.2, seed=1)
        t_pack = time.perf_counter() - t0
        state = prepared_state(a, 1.0)
        t, it, ok = increment_time(a, state, "axisymmetric", strain=1e-6, repeat=1)
        rows.append([f"random {args.random} spheres (packing {t_pack:.1f} s), one increment",
                     state.contacts.size, it, f"{t:.3f}", "converged" if ok else "NOT converged"])
    m_arr, t_arr = np.array(pts).T
    slope = np.polyfit(np.log(m_arr[m_arr >= 1000]), np.log(t_arr[m_arr >= 1000]), 1)[0] if np.sum(m_arr >= 1000) >= 2 else np.nan
    notes = (f"Scaling of the time per increment against the contacts (fcc arrays with >= 1000 "
             f"contacts): t ∝ m^{slope:.2f}. One increment = Newton iterations, each a batched "
             "contact update (compiled kernel) and a sparse LU solve (SciPy) of the grains' "
             "translations and rotations and the free cell components.")
    write_table("assembly", "Grain assemblies: fcc unit cell to its limit, time per increment",
                ["case", "contacts", "Newton iterations", "seconds", "result"], rows, notes)
    if args.figure:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(5, 4))
        ax.loglog(m_arr, t_arr, "o-", label="fcc arrays, one increment")
        ref = t_arr[-1] * (m_arr / m_arr[-1])
        ax.loglog(m_arr, ref, "--", color="grey", label="∝ contacts")
        ax.set_xlabel("contacts")
        ax.set_ylabel("seconds per increment")
        ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(args.figure, dpi=120)
        print(f"wrote {args.figure}")


if __name__ == "__main__":
    main()
