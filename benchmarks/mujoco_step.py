"""Benchmark: a pile of 50 boxes stepped by ``frictionrules.mujoco`` against ``mj_step``.

One command: ``python benchmarks/mujoco_step.py [--steps 400] [--rounds 10] [--rest-seconds 10] [--out FILE]``.

The pile (:func:`pile_xml`): 25 columns of two boxes (0.2 m, 1 kg) on a floor, the upper boxes
shifted and turned at random (seed 0), every contact starting at ``dist = 0``; 50 free bodies,
300 dofs, ``margin`` 2 mm, time step 2 ms, sparse Jacobian. Per step (CPU time of this
thread, ``--steps`` steps in ``--rounds`` interleaved rounds after 20 of warm-up: the median
and range over the rounds; collision and dynamics included):

* ``mj_step`` (MuJoCo's Newton solver, its default);
* :class:`frictionrules.mujoco.Simulator` with isotropic Coulomb ``mu = 0.5`` at every contact;
* the same with a non-associated law at every contact (``TransformedCoulomb(0.5, 0.25)``, the
  rule (1.18)) where the many-contact problem accepts it, else the associated
  ``EllipticOrthotropic(0.5, 0.25)`` (the table says which ran).

Then where the library's step spends its time (its stages timed one by one), and the rest
test: the pile stepped ``--rest-seconds`` of simulated time by each, the largest
displacement of a box and its largest speed at the end. Writes
``benchmarks/results/mujoco_step.md``.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _table import write_table  # noqa: E402

H, HALF, MU = 0.002, 0.1, 0.5


def pile_xml(seed: int = 0, columns: int = 5, h: float = H) -> str:
    """25 columns of two boxes; the upper box of each shifted by up to 1 cm and turned by up to
    10 degrees about z (it rests on the lower one, every contact at distance 0)."""
    rng = np.random.default_rng(seed)
    bodies = []
    pitch = 3 * HALF
    for i in range(columns):
        for j in range(columns):
            x, y = (i - columns // 2) * pitch, (j - columns // 2) * pitch
            bodies.append(f'<body pos="{x:.17g} {y:.17g} {HALF}"><freejoint/>'
                          f'<geom type="box" size="{HALF} {HALF} {HALF}" mass="1" margin="0.002"/></body>')
            dx, dy = rng.uniform(-0.01, 0.01, 2)
            yaw = rng.uniform(-10, 10)
            bodies.append(f'<body pos="{x + dx:.17g} {y + dy:.17g} {3 * HALF}" euler="0 0 {yaw:.17g}"><freejoint/>'
                          f'<geom type="box" size="{HALF} {HALF} {HALF}" mass="1" margin="0.002"/></body>')
    return (f'<mujoco><option timestep="{h}" jacobian="sparse"/><size memory="64M"/><worldbody>'
            f'<geom name="floor" type="plane" size="10 10 .1" margin="0.002"/>'
            + "".join(bodies) + "</worldbody></mujoco>")


def non_associated_law():
    """TransformedCoulomb where the problem accepts it, else the elliptic law (and its name)."""
    import frictionrules as fr
    law = fr.TransformedCoulomb(MU, 0.5 * MU)
    try:
        fr.FrictionContactProblem(np.eye(3), np.zeros(3), [law])
        return law, "TransformedCoulomb(0.5, 0.25) (1.18), non-associated"
    except fr.FrictionRulesError:
        return fr.EllipticOrthotropic(MU, 0.5 * MU), ("EllipticOrthotropic(0.5, 0.25), associated "
                                                      "(TransformedCoulomb refused by this build)")


def interleaved(advance: dict, steps: int, rounds: int) -> dict:
    """Per stepper, the CPU time per step of each round (each round: every stepper ``steps //
    rounds`` steps, one after the other)."""
    for f in advance.values():
        for _ in range(20):
            f()
    out = {k: [] for k in advance}
    per = max(1, steps // rounds)
    for _ in range(rounds):
        for k, f in advance.items():
            t0 = time.thread_time()
            for _ in range(per):
                f()
            out[k].append((time.thread_time() - t0) / per)
    return out


def breakdown(model, law, steps: int) -> dict:
    """CPU ms per step of each stage of the library's step (its private stages, timed one by
    one after 30 steps of the pile)."""
    import mujoco
    import scipy.sparse as sp

    from frictionrules.mujoco import Simulator, _assemble, _step
    sim = Simulator(model, {}, default=law)
    sim.step(30)
    h = model.opt.timestep
    p = sim._params
    names = ("MuJoCo forward stages", "blocks of W, q (mj_solveM, compiled)", "laws (reduced once)",
             "warm start", "solve", "integrate (efc_force, mj_mulJacTVec, M^-1 J^T r, mj_Euler)")
    total = dict.fromkeys(names, 0.0)
    for _ in range(steps):
        t = [time.thread_time()]
        _step._forward(mujoco, model, sim.data)
        t.append(time.thread_time())
        A = _assemble.assemble(sp, mujoco, model, sim.data, sim._scene, 0.2)
        t.append(time.thread_time())
        claws = _step._contact_laws(sim._scene, A.geom1, A.geom2)
        t.append(time.thread_time())
        r0, _ = _step._warm_start(sim.last, A, h, sim._scene.ngeom, 0.01)
        t.append(time.thread_time())
        sol = _step._solve(A, claws, r0, p, h)
        t.append(time.thread_time())
        force = np.einsum("ki,kij->kj", sol.r.reshape(-1, 3), A.frames) / h
        efc = np.zeros(int(sim.data.nefc))
        efc[A.rows] = np.einsum("kij,kj->ki", A.mj_frames, force).ravel()
        sim.data.efc_force[:] = efc
        mujoco.mj_mulJacTVec(model, sim.data, sim.data.qfrc_constraint, efc)
        np.add(sim.data.qacc_smooth, A.blocks.impulse_velocity(sol.r) / h, out=sim.data.qacc)
        mujoco.mj_Euler(model, sim.data)
        t.append(time.thread_time())
        for name, a, b in zip(names, t[:-1], t[1:]):
            total[name] += b - a
    return {k: v / steps * 1e3 for k, v in total.items()}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=400)
    ap.add_argument("--rounds", type=int, default=10)
    ap.add_argument("--rest-seconds", type=float, default=10.0)
    ap.add_argument("--out", default="mujoco_step")
    args = ap.parse_args(argv)
    import mujoco

    from frictionrules.mujoco import Simulator
    model = mujoco.MjModel.from_xml_string(pile_xml())
    law, law_name = non_associated_law()
    data = mujoco.MjData(model)
    steppers = {"mj_step (Newton, MuJoCo's default)": (lambda: mujoco.mj_step(model, data), None)}
    for name, entry in (("frictionrules, Coulomb mu = 0.5", MU), (f"frictionrules, {law_name}", law)):
        sim = Simulator(model, {}, default=entry)
        steppers[name] = (sim.step, sim)
    times = interleaved({k: v[0] for k, v in steppers.items()}, args.steps, args.rounds)
    base_name = "mj_step (Newton, MuJoCo's default)"
    rows = []
    for name, (_, sim) in steppers.items():
        t = np.asarray(times[name])
        ratio = t / np.asarray(times[base_name])      # round by round: the same load on both
        if sim is None:
            nc, unconv, its = data.ncon, "", ""
        else:
            nc, unconv = sim.last.nc, f"{sim.unconverged}/{sim.steps}"
            its = f"{sim.last.solution.iterations} ({sim.last.solution.method})"
        rows.append([name, f"{np.median(t) * 1e3:.3f} ({t.min() * 1e3:.3f}-{t.max() * 1e3:.3f})",
                     f"{np.median(ratio):.1f} ({ratio.min():.1f}-{ratio.max():.1f})", nc, unconv, its])
    notes = [f"Per step: CPU time of this thread; {args.rounds} rounds, in each round every stepper "
             f"takes {args.steps // args.rounds} steps in turn (interleaved, so that each round's "
             "load is shared); the median over the rounds and their range; x mj_step is the ratio "
             f"within each round. 20 steps of warm-up each; collision and dynamics included; "
             f"{model.nbody - 1} boxes, {model.nv} dofs. The machine was shared with other jobs (under load)."]
    parts = {name: breakdown(model, entry, args.steps) for name, entry in (("Coulomb", MU), (law_name, law))}
    stages = list(next(iter(parts.values())))
    notes.append("\nWhere the time of the library's step goes (CPU ms per step, each stage timed alone; "
                 "each step warm-started from the 30th step's result, the pile at rest):\n\n"
                 "| stage | " + " | ".join(parts) + " |\n|---|" + "---|" * len(parts) + "\n"
                 + "\n".join(f"| {s} | " + " | ".join(f"{parts[k][s]:.3f}" for k in parts) + " |" for s in stages))

    n = int(round(args.rest_seconds / H))
    rest = []
    for name, advance_factory in (("mj_step", None), ("frictionrules, Coulomb", MU), (f"frictionrules, {law_name}", law)):
        data = mujoco.MjData(model)
        mujoco.mj_forward(model, data)
        start = data.xpos[1:].copy()
        if advance_factory is None:
            for _ in range(n):
                mujoco.mj_step(model, data)
            extra = ""
        else:
            sim = Simulator(model, {}, default=advance_factory, data=data)
            sim.step(n)
            extra = f"{sim.unconverged} unconverged steps, largest error {sim.max_error:.1e}"
        drift = np.linalg.norm(data.xpos[1:] - start, axis=1).max()
        rest.append(f"| {name} | {args.rest_seconds:g} | {drift:.2e} | {np.abs(data.qvel).max():.2e} | {extra} |")
    notes.append("\nRest test (pile from rest, every contact at dist = 0):\n\n"
                 "| stepper | simulated s | largest box displacement (m) | largest |qvel| at the end | solves |\n"
                 "|---|---|---|---|---|\n" + "\n".join(rest))
    write_table(args.out, "MuJoCo pile of 50 boxes: frictionrules.mujoco against mj_step",
                ["stepper", "ms / step, median (range)", "x mj_step, median (range)", "contacts", "unconverged / steps", "last solve iterations"],
                rows, "\n".join(notes))


if __name__ == "__main__":
    main()
