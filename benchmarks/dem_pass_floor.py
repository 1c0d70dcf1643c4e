"""Benchmark: the engine's contact pass beside LAMMPS's ``gran/hooke/history`` arithmetic written
over the engine's own pair arrays, on one thread.

One command: ``python benchmarks/dem_pass_floor.py [--tiles 3] [--rounds 15]``.

The sample of ``dem_vs_lammps.py`` (k = 3: 10,800 spheres), 50 steps into the same shear with
``Coulomb(0.3)``, kn = kt = 1e4. Then, on that state, three passes over the same pairs in the
same order, each timed alone, the least of ``--rounds`` alternating calls (10 passes per call):

* ``engine`` — the engine's contact pass (its chunks, its law's compiled update);
* ``LAMMPS arithmetic, engine's arrays`` — LAMMPS's ``PairGranHookeHistory::compute``
  (hooke, Coulomb cut of the shear, the shear projected on the contact plane, no damping)
  reading and writing the engine's per-pair arrays: the state row, normal, frame vector, gap,
  local force, force, moment, status, slip, active flag;
* ``LAMMPS arithmetic, forces scattered`` — the same arithmetic with a 3-vector history and
  the forces and moments added to the grains (LAMMPS's own layout, one thread).

The second and third bound what the pairs' memory costs: the rest of the engine's pass is its
own kinematics and law (the history turned exactly with the contact and about the normal, the
reference frame, both tangential displacements carried, the running sums). Writes
``results/dem_pass_floor.md``.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _table import write_table  # noqa: E402

os.environ.setdefault("NUMBA_NUM_THREADS", "1")
KN = KT = 1e4
MU = 0.3
PASSES = 10


def _state(tiles: int):
    """The engine on the sample after the warm-up: ``(dynamics, state, one contact pass)``."""
    from dem_vs_lammps import _sample_file, warmed_engine
    from frictionrules.assembly._dem._passes import contact_range
    from numba import njit
    _, dyn, st, _ = warmed_engine(_sample_file(tiles), "coulomb")
    lists = dyn.lists[1]
    laws, ws = dyn.laws(False)
    params = dyn.params(False)
    (s, du, res, tan), (part, _, _, _) = dyn._scratch(st.pairs.state.shape[1])

    @njit
    def engine(reps, lists, grains, cell, pairs, laws, ws, params, s, du, res, tan, part):
        chunk, gstart = lists.chunk, lists.group_start
        groups = laws.fn.shape[0]
        for _ in range(reps):
            for k in range(chunk.shape[0] - 1):
                for g in range(groups):
                    lo, hi = max(chunk[k], gstart[g]), min(chunk[k + 1], gstart[g + 1])
                    if lo < hi:
                        contact_range(lo, hi, laws.fn[g], laws.row[g], laws.virgin[g], ws[k * groups + g], lists,
                                      grains, cell, pairs, params, (s[k], du[k], res[k], tan[k]), part[k])

    def run(reps):
        engine(reps, lists, st.grains, st.cell, st.pairs, laws, ws, params, s, du, res, tan, part)
    return dyn, st, run


def _lammps_passes():
    """The two passes of LAMMPS's arithmetic, compiled."""
    from numba import njit

    @njit(inline="always", fastmath={"contract"})
    def contact(c, PI, PJ, PK, x, v, w, R, H, s1, s2, s3, dt):
        """Pair c, its history ``s``: ``(touching, i, j, dx, dy, dz, rinv, ccel, fs, shear, excess)``
        (LAMMPS's variables)."""
        i, j = PI[c], PJ[c]
        k0, k1, k2 = PK[c, 0], PK[c, 1], PK[c, 2]
        dx = x[i, 0] - x[j, 0] - (H[0, 0] * k0 + H[0, 1] * k1 + H[0, 2] * k2)
        dy = x[i, 1] - x[j, 1] - (H[1, 0] * k0 + H[1, 1] * k1 + H[1, 2] * k2)
        dz = x[i, 2] - x[j, 2] - (H[2, 0] * k0 + H[2, 1] * k1 + H[2, 2] * k2)
        rsq = dx * dx + dy * dy + dz * dz
        rs = R[i] + R[j]
        if rsq >= rs * rs:
            return False, i, j, dx, dy, dz, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
        r = math.sqrt(rsq)
        rinv, rsqinv = 1.0 / r, 1.0 / rsq
        vr1, vr2, vr3 = v[i, 0] - v[j, 0], v[i, 1] - v[j, 1], v[i, 2] - v[j, 2]
        vnnr = (vr1 * dx + vr2 * dy + vr3 * dz) * rsqinv
        wr1 = (R[i] * w[i, 0] + R[j] * w[j, 0]) * rinv
        wr2 = (R[i] * w[i, 1] + R[j] * w[j, 1]) * rinv
        wr3 = (R[i] * w[i, 2] + R[j] * w[j, 2]) * rinv
        ccel = KN * (rs - r) * rinv
        s1 += (vr1 - dx * vnnr - (dz * wr2 - dy * wr3)) * dt
        s2 += (vr2 - dy * vnnr - (dx * wr3 - dz * wr1)) * dt
        s3 += (vr3 - dz * vnnr - (dy * wr1 - dx * wr2)) * dt
        rsht = (s1 * dx + s2 * dy + s3 * dz) * rsqinv
        s1, s2, s3 = s1 - rsht * dx, s2 - rsht * dy, s3 - rsht * dz
        fs1, fs2, fs3 = -KT * s1, -KT * s2, -KT * s3
        fs = math.sqrt(fs1 * fs1 + fs2 * fs2 + fs3 * fs3)
        fn = MU * abs(ccel * r)
        if fs > fn:
            scale = fn / fs if fs > 0.0 else 0.0
            fs1, fs2, fs3 = fs1 * scale, fs2 * scale, fs3 * scale
            s1, s2, s3 = -fs1 / KT, -fs2 / KT, -fs3 / KT
        return True, i, j, dx, dy, dz, rinv, ccel, fs1, fs2, fs3, s1, s2, s3, fs - fn

    @njit(fastmath={"contract"})
    def engine_arrays(reps, order, PI, PJ, PK, x, v, w, R, H, dt, S, NRM, T1, GAP, FRC, GF, TQ, ST, SLIP, ACT):
        width = S.shape[1]
        for _ in range(reps):
            for c in order:
                on, _, _, dx, dy, dz, rinv, ccel, f1, f2, f3, s1, s2, s3, excess = contact(
                    c, PI, PJ, PK, x, v, w, R, H, S[c, 0], S[c, 1], S[c, 3], dt)
                if not on and ACT[c] == 0:
                    continue
                S[c, 0], S[c, 1], S[c, 3] = s1, s2, s3 + 0.0 * (NRM[c, 0] + T1[c, 0] + GAP[c])
                for a in range(5, width):
                    S[c, a] = S[c, a]
                FRC[c, 0], FRC[c, 1], FRC[c, 2] = f1, f2, ccel
                GF[c, 0], GF[c, 1], GF[c, 2] = dx * ccel + f1, dy * ccel + f2, dz * ccel + f3
                TQ[c, 0], TQ[c, 1], TQ[c, 2] = rinv * (dy * f3 - dz * f2), rinv * (dz * f1 - dx * f3), rinv * (
                    dx * f2 - dy * f1)
                NRM[c, 0], NRM[c, 1], NRM[c, 2] = dx * rinv, dy * rinv, dz * rinv
                T1[c, 0], T1[c, 1], T1[c, 2] = f1, f2, f3
                GAP[c] = ccel
                ST[c] = 2 if excess > 0.0 else 1
                SLIP[c] += 0.0
                ACT[c] = 1 if on else 0

    @njit(fastmath={"contract"})
    def scattered(reps, order, PI, PJ, PK, x, v, w, R, H, dt, shear, f, t):
        for _ in range(reps):
            for c in order:
                on, i, j, dx, dy, dz, rinv, ccel, f1, f2, f3, s1, s2, s3, _ = contact(
                    c, PI, PJ, PK, x, v, w, R, H, shear[c, 0], shear[c, 1], shear[c, 2], dt)
                shear[c, 0], shear[c, 1], shear[c, 2] = s1, s2, s3
                if not on:
                    continue
                fx, fy, fz = dx * ccel + f1, dy * ccel + f2, dz * ccel + f3
                t1, t2, t3 = rinv * (dy * f3 - dz * f2), rinv * (dz * f1 - dx * f3), rinv * (dx * f2 - dy * f1)
                f[i, 0] += fx
                f[i, 1] += fy
                f[i, 2] += fz
                f[j, 0] -= fx
                f[j, 1] -= fy
                f[j, 2] -= fz
                t[i, 0] -= R[i] * t1
                t[i, 1] -= R[i] * t2
                t[i, 2] -= R[i] * t3
                t[j, 0] -= R[j] * t1
                t[j, 1] -= R[j] * t2
                t[j, 2] -= R[j] * t3
    return engine_arrays, scattered


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--tiles", type=int, default=3, help="k of the sample (400 k³ grains; default 3)")
    ap.add_argument("--rounds", type=int, default=15, help="alternating calls of each pass (default 15)")
    args = ap.parse_args(argv)
    dyn, st, engine = _state(args.tiles)
    engine_arrays, scattered = _lammps_passes()
    g, p, H = st.grains, st.pairs, st.cell.H
    order, dt = dyn.lists[1].order, dyn.params(False).dt
    copy = type(p)(*[a.copy() for a in p])
    shear, f, t = np.zeros((p.i.size, 3)), np.zeros_like(g.x), np.zeros_like(g.x)
    passes = {
        "engine": engine,
        "LAMMPS arithmetic, engine's arrays": lambda reps: engine_arrays(
            reps, order, copy.i, copy.j, copy.shift, g.x, g.v, g.w, g.radius, H, dt, copy.state, copy.normal,
            copy.t1, copy.gap, copy.force, copy.gforce, copy.torque, copy.status, copy.slip, copy.active),
        "LAMMPS arithmetic, forces scattered": lambda reps: scattered(
            reps, order, p.i, p.j, p.shift, g.x, g.v, g.w, g.radius, H, dt, shear, f, t),
    }
    best = {}
    for name, run in passes.items():
        run(1)
        best[name] = math.inf
    for _ in range(args.rounds):
        for name, run in passes.items():
            t0 = time.perf_counter()
            run(PASSES)
            best[name] = min(best[name], (time.perf_counter() - t0) / PASSES)
    active = int(p.active.sum())
    rows = [[name, f"{1e3 * sec:.3f}", f"{1e9 * sec / active:.1f}", f"{sec / best['engine']:.2f}"]
            for name, sec in best.items()]
    for row in rows:
        print(row, flush=True)
    notes = (f"{g.x.shape[0]} grains, {p.i.size} pairs, {active} in contact; one thread; the least of "
             f"{args.rounds} alternating calls of {PASSES} passes each; the grains stay where they are, each pass "
             "writes pairs' arrays of its own (the engine's, a copy of them, LAMMPS's shear).")
    write_table("dem_pass_floor", "The engine's contact pass beside LAMMPS's arithmetic over the same pairs",
                ["pass", "ms", "ns per contact", "÷ engine"], rows, notes)
    return 0


if __name__ == "__main__":
    sys.exit(main())
