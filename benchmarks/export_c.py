"""Benchmark: the exported C kernel (``frictionrules.export(law, "c", ...)``) against the
compiled Numba kernel generated from the same symbolic form.

One command: ``python benchmarks/export_c.py [--n 1e6] [--budget 4]``. For each law (Coulomb,
EllipticOrthotropic with an angle, a non-associated UserLaw, Coulomb with slip hardening,
WedgeAsperity, EllipsoidCap) it exports the C kernel, compiles it with ``gcc -std=c99 -O2``
together with a loop over contacts, and times one step of n random contacts (about 80 %
plastic, 10 % elastic, 10 % open) with the consistent tangent, beside
``frictionrules.contact._generated.generated_kernel(law)`` on one thread and on all cores.
Writes ``benchmarks/results/export_c.md``.
"""

from __future__ import annotations

import argparse
import ctypes
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
KT, KN = 100.0, 150.0

#: A loop over contacts around the exported per-contact function.
LOOP = r"""
#include "{name}.c"
void batch(long n, const double *params, const double *state, const double *du,
           double *state_out, double *force, double *tangent, int *status)
{{
    long i;
    for (i = 0; i < n; i++)
        status[i] = {name}_update(params, state + i * {up}_NSTATE, du + 3 * i,
                                  state_out + i * {up}_NSTATE, force + 3 * i, tangent + 9 * i);
}}
"""


def laws():
    import frictionrules as fr
    return {
        "Coulomb": (fr.Coulomb(0.4), None),
        "EllipticOrthotropic (angle 0.4)": (fr.EllipticOrthotropic(0.6, 0.3, angle=0.4), None),
        "UserLaw, non-associated": (fr.UserLaw(
            "sqrt((T1/mu_x)**2 + (T2/mu_y)**2) - N", potential="sqrt(T1**2 + T2**2)",
            params={"mu_x": 0.5, "mu_y": 0.3}), None),
        "Coulomb + SlipHardening": (fr.Coulomb(0.4), fr.SlipHardening(0.2, 0.05)),
        "WedgeAsperity": (fr.WedgeAsperity(0.3, 0.2), None),
        "EllipsoidCap": (fr.EllipsoidCap(m=0.6), None),
    }


def inputs(n: int, nq: int, q0, seed: int = 0):
    rng = np.random.default_rng(seed)
    du = np.empty((n, 3))
    du[:, :2] = rng.normal(scale=0.01, size=(n, 2))
    du[:, 2] = -np.abs(rng.normal(scale=0.01, size=n))
    kind = rng.random(n)
    du[kind < 0.1, 2] *= -1.0
    du[(kind >= 0.1) & (kind < 0.2), :2] *= 0.05
    q = np.tile(np.asarray(q0, dtype=float), (n, 1)).reshape(n, nq)
    return du, q


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=float, default=1e6)
    parser.add_argument("--budget", type=float, default=3.0, help="seconds of rounds per law")
    args = parser.parse_args(argv)
    n = int(args.n)

    import numba

    import frictionrules as fr
    from _table import write_table
    from contact_update import cpu_times
    from frictionrules.contact._generated import generated_kernel, law_row
    from frictionrules.contact._kernel_batch import Batch
    cores = numba.config.NUMBA_NUM_THREADS
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for label, (law, hard) in laws().items():
            name = "k" + str(len(rows))
            folder = Path(tmp) / name
            res = fr.export(law, "c", folder, kt=KT, kn=KN, hardening=hard, name=name)
            (folder / "batch.c").write_text(LOOP.format(name=name, up=name.upper()))
            lib = folder / "batch.so"
            subprocess.run(["gcc", "-std=c99", "-O2", "-shared", "-fPIC", "-I", str(folder),
                            "-o", str(lib), str(folder / "batch.c"), "-lm"], check=True)
            c = ctypes.CDLL(str(lib))
            effective = fr.HardenedLaw(law, hard) if hard is not None else law
            nq = len(effective.state_names)
            virgin = effective.initial_values()
            q0 = [virgin[k] for k in effective.state_names]
            du, q = inputs(n, nq, q0)
            state = np.zeros((n, 6 + nq))
            state[:, 6:] = q
            params = np.array(res.props)
            outs = (np.empty((n, 6 + nq)), np.empty((n, 3)), np.empty((n, 9)),
                    np.empty(n, dtype=np.int32))
            dp = lambda a: a.ctypes.data_as(ctypes.c_void_p)  # noqa: E731

            def run_c():
                c.batch(ctypes.c_long(n), dp(params), dp(state), dp(du), *(dp(o) for o in outs))

            kernel = generated_kernel(effective)
            row = law_row(effective, KT, KN)
            batch = Batch(np.ascontiguousarray(state[:, :3]), np.ascontiguousarray(state[:, 3:6]),
                          np.ascontiguousarray(state[:, 6:]), du)
            nb_out = []

            def run(threads):
                numba.set_num_threads(threads)
                nb_out[:] = [kernel.run(row, batch, True)]

            t_c, t_1, t_all = cpu_times([run_c, lambda: run(1), lambda: run(cores)],
                                         budget=args.budget)
            nb = nb_out[0]
            ok = ~nb.failed  # contacts the Numba kernel leaves to its caller's substeps
            same = bool(np.allclose(outs[1][ok], nb.force[ok], rtol=1e-9, atol=1e-12)
                        and np.allclose(outs[2].reshape(n, 3, 3)[ok], nb.tangent[ok], rtol=1e-7,
                                        atol=1e-9))
            plastic = float(np.mean(outs[3] == 1))
            rows.append([label, f"{n / t_c:.3e}", f"{n / t_1:.3e}", f"{n / t_all:.3e}",
                         f"{t_1 / t_c:.2f}", f"{plastic:.0%}", int((~ok).sum()), same])
            print(rows[-1], flush=True)
    notes = (f"n = {n:.0e} contacts, one implicit step with the consistent tangent; C: the "
             "exported `<name>_update` in a loop (`gcc -std=c99 -O2`, one thread, ctypes); "
             f"Numba: `generated_kernel(law)` on 1 and {cores} threads; median CPU time of "
             f"interleaved rounds (about {args.budget:g} s per law). 'Numba 1 / C' is the time ratio "
             "(> 1: C faster). 'same' compares forces (1e-9) and tangents (1e-7) "
             "except at the 'substepped' contacts: where Newton fails, the C kernel substeps "
             "itself (inside the timing) while the Numba kernel flags them for its caller "
             f"(ContactModel) to substep (outside the timing). {os.cpu_count()} cores.")
    write_table("export_c", "Exported C kernel beside the generated Numba kernel",
                ["law", "C updates/s", "Numba 1 thread", f"Numba {cores} threads",
                 "Numba 1 / C", "plastic", "substepped", "same"], rows, notes)
    return 0


if __name__ == "__main__":
    sys.exit(main())
