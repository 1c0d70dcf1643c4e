"""LAMMPS on 1 and 2 ranks from the same state: where the two runs part.

The triaxial script's own settings (``newton on``, the exported pair style with ``skin`` and
``affine yes``, Cundall damping, ``fix deform/pressure``): the 400-sphere sample of
``assembly_lammps.py`` (``--seed``), ``--law`` (``coulomb``, ``dilatant``, ``hardening``; μ =
0.3), consolidated frictionless and sheared on 1 rank to ``--strain`` with a restart file every
0.2 % (``restart_every``); then ``resume_lammps_triaxial`` from the first restart file on 1 rank
(bit for bit the first run) and on 2 ranks. Each record after the restart: the largest
difference of the stress and of the box from the 1-rank run, and both runs' force-carrying
contacts (Z × N), rattlers and sliding fraction. Two runs that differ only in the order of the
force sums part by round-off growing exponentially (the dynamics of a granular packing are
chaotic); a history lost or negated when a contact changes rank would show as a jump. One
jump that is not the history's: a rattler's spin is exactly zero until its first contact, that
contact's first step (T = 0) gives it a spin of round-off (1e-22), and Cundall's damping
multiplies the next torque by 1 − λ sgn(τ ω), 0.8 or 1.2 by the sign of that round-off: the
two runs part there by about 1e-5 in the grain's spin (the hardening law on seed 1, step 2825).

One command: ``python benchmarks/lammps_ranks_restart.py [--law dilatant] [--seed 1]
[--strain 0.012]`` (about a minute of CPU; ``results/lammps_ranks_restart_<law>.md``; the runs
under ``results/lammps_ranks_restart/``).
"""

from __future__ import annotations

import argparse
import os
import shutil
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
STORE = HERE / "results" / "lammps_ranks_restart"


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--law", default="dilatant")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--strain", type=float, default=0.012)
    args = parser.parse_args(argv)

    import assembly_lammps as bench
    import frictionrules as fr
    from _table import write_table
    from frictionrules.assembly._lammps._runner import _records, run_lammps
    root = STORE / f"seed{args.seed}_{args.law}"
    shutil.rmtree(root, ignore_errors=True)
    a = bench.assembly_of(bench.sample(args.seed), bench.make_law(args.law, 0.3))
    files = fr.write_lammps_triaxial(a, "axisymmetric", root / "one", pressure=bench.PRESSURE,
                                     axial_strain=args.strain, consolidation="frictionless",
                                     record_every=1e-3, restart_every=2e-3)
    run_lammps(files, ranks=1)
    first = min((root / "one").glob("shear.*.restart"), key=lambda p: int(p.name.split(".")[1]))
    for ranks in (1, 2):
        shutil.copytree(root / "one", root / f"resumed{ranks}")
        fr.resume_lammps_triaxial(a, root / f"resumed{ranks}", restart=first.name, ranks=ranks)
    ref = _records(root / "one")
    same = _records(root / "resumed1")
    two = _records(root / "resumed2")
    assert ref.shape == two.shape == same.shape
    start = int(first.name.split(".")[1])
    rows = []
    for k in range(len(ref)):
        if ref[k, 0] < start:
            continue
        rows.append([int(ref[k, 0]), int(ref[k, 0]) - start,
                     f"{np.abs(two[k, 5:11] - ref[k, 5:11]).max():.1e}",
                     f"{np.abs(two[k, 2:5] - ref[k, 2:5]).max():.1e}",
                     f"{int(ref[k, 11])} / {int(two[k, 11])}", f"{int(ref[k, 12])} / {int(two[k, 12])}",
                     f"{ref[k, 14]:.4f} / {two[k, 14]:.4f}"])
    write_table(f"lammps_ranks_restart_{args.law}",
                f"LAMMPS on 1 and 2 ranks from the same restart file ({args.law}, seed {args.seed})",
                ["step", "steps since the restart", "max |Δσ| (p = 1)", "max |Δ box|",
                 "contacts × 2 (1 / 2 ranks)", "rattlers (1 / 2)", "sliding (1 / 2)"], rows,
                f"The triaxial script's settings, μ = 0.3, records every 0.1 % of axial strain; "
                f"resumed from {first.name} on 1 rank: bit for bit the first run: "
                f"{bool(np.array_equal(same, ref))}. Load average at the end: "
                f"{os.getloadavg()[0]:.1f} on {os.cpu_count()} cores.")


if __name__ == "__main__":
    main()
