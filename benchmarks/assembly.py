"""Benchmark: grain assemblies — the fcc unit cell to its limit state, the time of one implicit
increment against the number of contacts, and the sparse LU's column ordering.

One command: ``python benchmarks/assembly.py [--sizes 1,2,4,6] [--random 60] [--lu-random 400,1000]
[--figure FILE]``.

* fcc unit cell (4 spheres, 24 contacts), Coulomb μ = 0.3, kn = kt = 1e6, axisymmetric
  compression at pressure 1 to the plateau (40 increments of 5e-6): median CPU time of 3 runs
  after a warm-up (Numba compiles the contact kernel on first use);
* CPU time of one shear increment (axial strain 2e-6) of fcc arrays of k³ unit cells
  (24 k³ contacts, consolidated by one stress-controlled increment to pressure 1) and of random
  packings of polydisperse spheres (radii 1 ± 0.2, kn = kt = 1e4, μ = 0.3, prepared as
  ``triaxial`` does: frictionless compression to pressure 1, then one increment with the law),
  with the Newton iterations; the slope of log(time) against log(contacts) is the scaling;
* the sparse LU of the Jacobian (the elastic tangents of the fcc arrays' increment, and of the
  touching contacts of random packings as made by ``Assembly.random``, with the mechanism shift
  of ``frictionrules.assembly._newton``) with SciPy's default ordering (COLAMD, partial pivoting
  threshold 1) and with the one the solver uses (minimum degree on ``J + Jᵀ``, threshold
  0.01): median CPU time of the factorization and the fill ``nnz(L) + nnz(U)``.

Writes ``benchmarks/results/assembly.md`` (and the figure when asked). Times are CPU times
(``time.process_time``) with one BLAS thread, medians of repeats.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _table import write_table  # noqa: E402

from frictionrules import Assembly, ContactModel, Coulomb, triaxial  # noqa: E402
from frictionrules.assembly._loading import (_controls, initial_state,  # noqa: E402
                                             prepared_state, run)
from frictionrules.assembly._newton import (FREE_SHIFT, MECHANISM, PERMC_SPEC,  # noqa: E402
                                            PIVOT_THRESHOLD, jacobian, rattlers)
from frictionrules.assembly._solver import (_SIGN, _elastic_tangents, kinematics,  # noqa: E402
                                            solve_increment)


def cpu(fun, repeat: int = 3) -> tuple[float, object]:
    """Median CPU time of ``repeat`` calls of ``fun()`` and the last result."""
    times, out = [], None
    for _ in range(repeat):
        t0 = time.process_time()
        out = fun()
        times.append(time.process_time() - t0)
    return float(np.median(times)), out


def fcc_to_limit() -> tuple[float, float]:
    model = ContactModel(Coulomb(0.3), kn=1e6, kt=1e6)
    run_ = lambda: triaxial(Assembly.lattice("fcc", model), "axisymmetric", pressure=1.0,  # noqa: E731
                            axial_strain=2e-4, increments=40)
    run_()
    t, r = cpu(run_)
    return t, r.peak_ratio


def consolidated(assembly, frictionless: bool):
    cons, _ = _controls("axisymmetric", 3, 1.0, 1e-6, 1, 1)

    def prepare():
        start = prepared_state(assembly, 1.0) if frictionless else initial_state(assembly)
        return run(assembly, start, cons, max_cuts=0)
    t, (rows, _, _) = cpu(prepare, 1)
    return t, rows[-1][0], rows[-1][2]


def increment_time(assembly, state, strain=2e-6, repeat=3):
    _, shear = _controls("axisymmetric", assembly.dim, 1.0, strain, 1, 1)
    c = shear[0]
    free, pres, target = np.array(c.free), -np.array(c.strain), np.array(c.target)
    t, out = cpu(lambda: solve_increment(state.positions, assembly.radii, state.cell,
                                         state.contacts, free, pres, target, gap=assembly.tolerance),
                 repeat)
    return t, out.iterations, out.converged, free


def lu_orderings(assembly, state, free, repeat=3):
    """CPU time and fill of the sparse LU with the default and with the solver's ordering."""
    import scipy.sparse.linalg as spla
    c = state.contacts
    kin = kinematics(state.positions, assembly.radii, state.cell, c)
    holding = c.per_contact("elastic")[:, 2] <= assembly.tolerance
    fixed = rattlers(assembly.size, c.i, c.j, holding)
    cols, _ = kin.columns(free, fixed)
    if isinstance(kin.B, np.ndarray):
        return None
    B = kin.B[:, cols]
    status = c.status if c.status is not None else np.where(holding, 0, 2)
    S = _SIGN[None, :, None] * _elastic_tangents(c, status)
    E = jacobian(B, S, False)
    import scipy.sparse as sp
    scale = float(np.abs(E.diagonal()).mean())
    A = (E + MECHANISM * (E + sp.identity(E.shape[0]) * FREE_SHIFT * scale)).tocsc()
    out = []
    for spec, thresh in (("COLAMD", 1.0), (PERMC_SPEC, PIVOT_THRESHOLD)):
        t, lu = cpu(lambda: spla.splu(A, permc_spec=spec, diag_pivot_thresh=thresh), repeat)
        out.append((t, lu.L.nnz + lu.U.nnz))
    return A.shape[0], out, int(fixed.sum())


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="1,2,4,6", help="fcc repeats k (24 k^3 contacts)")
    parser.add_argument("--random", default="60", help="spheres of the random packings whose "
                        "increment is timed (comma-separated; empty: none)")
    parser.add_argument("--lu-random", default="400,1000", help="spheres of the random packings "
                        "whose LU is timed (comma-separated; empty: none)")
    parser.add_argument("--figure", help="scaling figure (.png)")
    args = parser.parse_args(argv)
    t_fcc, peak = fcc_to_limit()
    rows = [["fcc unit cell to its limit (40 increments)", 24, "-", f"{t_fcc:.3f}",
             f"peak σzz/σxx = {peak:.6f} (closed form {2 * 1.3 / 0.7:.6f})"]]
    lu_rows = []
    samples = [(f"fcc {k}x{k}x{k}", lambda k=k: Assembly.lattice(
        "fcc", ContactModel(Coulomb(0.3), kn=1e6, kt=1e6), cells=k))
        for k in (int(s) for s in args.sizes.split(",") if s)]
    samples += [(f"random {n} spheres", lambda n=n: Assembly.random(
        n, 3, ContactModel(Coulomb(0.3), kn=1e4, kt=1e4), polydispersity=0.2, seed=1))
        for n in (int(s) for s in args.random.split(",") if s)]
    pts = []
    for name, make in samples:
        t0 = time.process_time()
        a = make()
        t_make = time.process_time() - t0
        t_cons, base, ok_cons = consolidated(a, frictionless=name.startswith("random"))
        big = len(base.contacts.i) > 5000
        t, it, ok, free = increment_time(a, base, repeat=1 if big else 3)
        m = base.contacts.size
        pts.append((m, t, name.startswith("fcc")))
        rows.append([f"{name}, one shear increment (sample {t_make:.1f} s, consolidation "
                     f"{t_cons:.2f} s{'' if ok_cons else ', NOT converged'})", m, it, f"{t:.3f}",
                     "converged" if ok else "NOT converged"])
        print(rows[-1], flush=True)
        lu = lu_orderings(a, base, free, repeat=1 if big else 3)
        if lu is not None and name.startswith("fcc"):
            n, ((t_def, f_def), (t_ord, f_ord)), nratt = lu
            lu_rows.append([name, n, nratt, f"{t_def:.3f}", f_def, f"{t_ord:.3f}", f_ord,
                            f"{t_def / t_ord:.1f}"])
            print(lu_rows[-1], flush=True)
    for n in (int(s) for s in args.lu_random.split(",") if s):
        a = Assembly.random(n, 3, ContactModel(Coulomb(0.3), kn=1e4, kt=1e4), polydispersity=0.2,
                            seed=1)
        free = np.ones(6, dtype=bool)
        free[2] = False
        n_unknowns, ((t_def, f_def), (t_ord, f_ord)), nratt = lu_orderings(a, initial_state(a), free)
        lu_rows.append([f"random {n} spheres (as packed)", n_unknowns, nratt, f"{t_def:.3f}", f_def,
                        f"{t_ord:.3f}", f_ord, f"{t_def / t_ord:.1f}"])
        print(lu_rows[-1], flush=True)
    m_arr, t_arr, lat = (np.array(v) for v in zip(*pts))
    use = lat & (m_arr >= 1000)
    slope = np.polyfit(np.log(m_arr[use]), np.log(t_arr[use]), 1)[0] if use.sum() >= 2 else np.nan
    notes = (f"CPU time (`time.process_time`), one BLAS thread, medians of 3 (1 above 5,000 "
             f"contacts). Scaling of the time per increment against the contacts (fcc arrays with "
             f">= 1000 contacts): t ∝ m^{slope:.2f}. One increment = Newton iterations, each a "
             "batched contact update (compiled kernel) and a sparse LU of the grains' "
             "translations and rotations and the free cell components.\n\n"
             "Sparse LU of the increment's Jacobian (SuperLU): SciPy's default COLAMD with "
             f"pivoting threshold 1 against {PERMC_SPEC} (minimum degree on J + Jᵀ, the grain "
             f"graph) with threshold {PIVOT_THRESHOLD} (the solver's):\n\n"
             "| sample | unknowns | rattlers | COLAMD s | COLAMD fill | MMD s | MMD fill | speed-up |\n"
             "|---|---|---|---|---|---|---|---|\n"
             + "\n".join("| " + " | ".join(str(c) for c in r) + " |" for r in lu_rows))
    write_table("assembly", "Grain assemblies: fcc unit cell to its limit, time per increment",
                ["case", "contacts", "Newton iterations", "CPU seconds", "result"], rows, notes)
    if args.figure:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(5, 4))
        ax.loglog(m_arr[lat], t_arr[lat], "o-", label="fcc arrays, one increment")
        if (~lat).any():
            ax.loglog(m_arr[~lat], t_arr[~lat], "s", label="random packings, one increment")
        ref = t_arr[lat][-1] * (m_arr[lat] / m_arr[lat][-1])
        ax.loglog(m_arr[lat], ref, "--", color="grey", label="∝ contacts")
        ax.set_xlabel("contacts")
        ax.set_ylabel("CPU seconds per increment")
        ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(args.figure, dpi=120)
        print(f"wrote {args.figure}")


if __name__ == "__main__":
    main()
