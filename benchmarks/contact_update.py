"""Benchmark: batched contact updates per second, Numba kernels against plain C.

One command: ``python benchmarks/contact_update.py [--sizes 1e3,1e4,...] [--out FILE]``.
Compiles ``benchmarks/c/contact_kernels.c`` with ``gcc -O3`` into a temporary folder, calls it
through ctypes, and times the Numba kernels of :mod:`frictionrules.contact._kernels` on one
thread and on all cores, for the Coulomb kernel (kn, kt, mu, no hardening: radial return) and
the orthotropic-elliptic kernel (closest-point projection by Newton). Inputs: random contacts,
about 80 % plastic, 10 % elastic, 10 % open. Writes ``benchmarks/results/contact_update.md``.
"""

from __future__ import annotations

import argparse
import ctypes
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
SOURCE = HERE / "c" / "contact_kernels.c"
KT, KN, MU, MUX, MUY, ANGLE = 100.0, 150.0, 0.4, 0.3, 0.6, 0.4


def build_c(tmp: Path):
    lib = tmp / "contact_kernels.so"
    cmd = ["gcc", "-O3", "-shared", "-fPIC", str(SOURCE), "-o", str(lib), "-lm"]
    subprocess.run(cmd, check=True)
    c = ctypes.CDLL(str(lib))
    dp = np.ctypeslib.ndpointer(dtype=np.float64, flags="C_CONTIGUOUS")
    ip = np.ctypeslib.ndpointer(dtype=np.int8, flags="C_CONTIGUOUS")
    d = ctypes.c_double
    outs = [dp, dp, dp, dp, dp, ip, dp]
    c.coulomb_update.argtypes = [ctypes.c_long, dp, dp, dp, dp, d, d, d, ctypes.c_int] + outs
    c.elliptic_update.argtypes = [ctypes.c_long, dp, dp, dp, dp, d, d, d, d, d] + outs
    c.coulomb_update.restype = c.elliptic_update.restype = None
    return c, " ".join(cmd[:2])


def inputs(n: int, seed: int = 0):
    rng = np.random.default_rng(seed)
    e = np.zeros((n, 3))
    p = np.zeros((n, 3))
    kappa = np.zeros(n)
    du = np.empty((n, 3))
    du[:, :2] = rng.normal(scale=0.01, size=(n, 2))
    du[:, 2] = -np.abs(rng.normal(scale=0.01, size=n))
    kind = rng.random(n)
    du[kind < 0.1, 2] *= -1.0            # open
    du[(kind >= 0.1) & (kind < 0.2), :2] *= 0.05   # elastic
    return e, p, kappa, du


def best_times(funs, budget: float = 4.0, min_rounds: int = 3, max_rounds: int = 60) -> list[float]:
    """Best wall time of each callable, measured in interleaved rounds.

    Interleaving gives every variant the same chances of a quiet machine (other processes
    share the cores), and the best of many rounds is the least disturbed one.
    """
    for fun in funs:
        fun()
    best = [np.inf] * len(funs)
    start, rounds = time.perf_counter(), 0
    while rounds < min_rounds or (time.perf_counter() - start < budget and rounds < max_rounds):
        for k, fun in enumerate(funs):
            t0 = time.perf_counter()
            fun()
            best[k] = min(best[k], time.perf_counter() - t0)
        rounds += 1
    return best


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="1e3,1e4,1e5,1e6,1e7")
    parser.add_argument("--out", default=str(HERE / "results" / "contact_update.md"))
    parser.add_argument("--budget", type=float, default=4.0, help="seconds of interleaved rounds per row")
    args = parser.parse_args(argv)
    sizes = [int(float(s)) for s in args.sizes.split(",")]

    import numba

    from frictionrules._atomic import write_text
    from frictionrules.contact import _kernels as K
    cores = numba.config.NUMBA_NUM_THREADS
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        c, ccmd = build_c(Path(tmp))
        for n in sizes:
            e, p, kappa, du = inputs(n)
            out = K.outputs(n)
            out_c = K.outputs(n)
            calls = {
                "Coulomb": (lambda: K.coulomb_update(e, p, kappa, du, KT, KN, MU, False, *out),
                            lambda: c.coulomb_update(n, e, p, kappa, du, KT, KN, MU, 0, *out_c)),
                "elliptic (Newton)": (lambda: K.elliptic_update(e, p, kappa, du, KT, KN, MUX, MUY, ANGLE, *out),
                                      lambda: c.elliptic_update(n, e, p, kappa, du, KT, KN, MUX, MUY, ANGLE, *out_c)),
            }
            for name, (nb, cc) in calls.items():
                def nb_one(nb=nb):
                    numba.set_num_threads(1)
                    nb()

                def nb_all(nb=nb):
                    numba.set_num_threads(cores)
                    nb()

                t_c, t_1, t_all = best_times([cc, nb_one, nb_all], budget=args.budget)
                same = all(np.allclose(a, b, rtol=1e-12, atol=1e-15) for a, b in zip(out, out_c))
                rows.append((name, n, n / t_c, n / t_1, n / t_all, t_c / t_1, t_c / t_all, same))
                print(f"{name:18s} n={n:>9d}  C {n / t_c:10.3e}/s  numba 1 thr {n / t_1:10.3e}/s "
                      f"({t_c / t_1:4.2f}x)  {cores} thr {n / t_all:10.3e}/s ({t_c / t_all:4.2f}x)  same={same}",
                      flush=True)
    lines = [
        "# Batched contact update: Numba kernels against plain C",
        "",
        f"`python benchmarks/contact_update.py` on {platform.processor() or platform.machine()}, "
        f"{os.cpu_count()} cores, Python {platform.python_version()}, NumPy {np.__version__}, "
        f"Numba {numba.__version__}; C: `{ccmd}` (one thread). Best of interleaved rounds "
        f"(C, Numba 1 thread, Numba all threads, for about {args.budget:g} s per row); "
        "inputs about 80 % plastic, 10 % elastic, 10 % open contacts. Ratios are C time / Numba time "
        "(> 1: Numba faster). Goal at n = 1e6: >= 0.8 on one thread, >= 1.6 on all cores. "
        "At n = 1e3 the C time includes the ctypes call (tens of microseconds). The machine is shared "
        "with other processes: all-core rows at n = 1e7 (few rounds of about a second) are the most "
        "exposed to a busy core.",
        "",
        f"| kernel | n | C updates/s | Numba 1 thread | Numba {cores} threads | ratio 1 thread | "
        f"ratio {cores} threads | same result |",
        "|---|---:|---:|---:|---:|---:|---:|---|",
    ]
    for name, n, rc, r1, ra, q1, qa, same in rows:
        lines.append(f"| {name} | {n:.0e} | {rc:.3e} | {r1:.3e} | {ra:.3e} | {q1:.2f} | {qa:.2f} | {same} |")
    write_text(args.out, "\n".join(lines) + "\n")
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
