"""Benchmark: 400 polydisperse spheres in axisymmetric compression beside YADE.

One command: ``python benchmarks/assembly_yade.py [--n 400] [--mu 0.3,0.5] [--budget SECONDS]``.

The sample is made once by :meth:`frictionrules.Assembly.random` (seed 1, polydispersity 0.2,
radius 1) and given to both codes as it is (positions, radii, cubic cell). Both prepare it the
same way — frictionless isotropic compression to the pressure p = 1 — then compress it along z
with σxx = σyy = p held, to 12 % axial strain:

* frictionrules: ``triaxial(..., consolidation="frictionless")``, Coulomb μ at every contact,
  kn = kt = 1e4 (kn/(p d) = 5e3), implicit quasi-static increments of 2e-5 (at most 3 cuts),
  bounded by ``--budget`` seconds between increments (the table says how far it got);
* YADE (Debian package ``yade``; ``apt-get install yade``): FrictMat with Young's modulus
  E = kn/r (so that kn = E r1 r2·2/(r1 + r2) ≈ 1e4), ks/kn from poisson = 1 (YADE's
  Ip2_FrictMat_FrictMat_FrictPhys gives ks = kn·poisson), CundallStrack, PeriTriaxController
  (frictionless compaction to p, then friction angle atan μ, strain rate with an inertial
  number ≈ 1e-3), NewtonIntegrator damping 0.2.

Peak friction angle ``asin((σ1 − σ3)/(σ1 + σ3))`` and the angle at 12 % side by side, with
both wall times → ``benchmarks/results/assembly_yade.md``. Without YADE the table holds ours only
and says how to install it.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _table import write_table  # noqa: E402

from frictionrules import Assembly, ContactModel, Coulomb, triaxial  # noqa: E402

KN = 1e4
P = 1.0
STRAIN = 0.12

YADE_SCRIPT = r'''
import json, math, os, time
from yade import *
from yade import utils
d = json.load(open(os.environ["FR_SAMPLE"]))
mu, kn, p, target = d["mu"], d["kn"], d["pressure"], d["strain"]
O.periodic = True
L = d["L"]
O.cell.hSize = Matrix3(L, 0, 0, 0, L, 0, 0, 0, L)
rmean = sum(d["radii"]) / len(d["radii"])
mat = O.materials.append(FrictMat(young=kn / rmean, poisson=1.0, frictionAngle=0.0, density=1.0))
for x, r in zip(d["positions"], d["radii"]):
    O.bodies.append(utils.sphere(Vector3(*x), r, material=mat))
rate = 1e-3 / (2 * rmean) * math.sqrt(p / 1.0)   # inertial number ~ 1e-3
O.engines = [ForceResetter(), InsertionSortCollider([Bo1_Sphere_Aabb()]),
             InteractionLoop([Ig2_Sphere_Sphere_ScGeom()], [Ip2_FrictMat_FrictMat_FrictPhys()],
                             [Law2_ScGeom_FrictPhys_CundallStrack()]),
             PeriTriaxController(label="triax", goal=(-p, -p, -p), stressMask=7, dynCell=True,
                                 maxStrainRate=(10 * rate, 10 * rate, 10 * rate),
                                 maxUnbalanced=0.01, relStressTol=1e-3),
             NewtonIntegrator(damping=0.2)]
O.dt = 0.5 * PWaveTimeStep()
t0 = time.time()
while True:
    O.run(200, True)
    if abs(triax.stress[0] + p) < 1e-3 * p and abs(triax.stress[2] + p) < 1e-3 * p and unbalancedForce() < 0.01:
        break
    if time.time() - t0 > 600:
        break
t_comp = time.time() - t0
for b in O.bodies:
    b.mat.frictionAngle = math.atan(mu)
for i in O.interactions:
    i.phys.tangensOfFrictionAngle = mu
O.cell.trsf = Matrix3.Identity
triax.goal = (-p, -p, -target)
triax.stressMask = 3
triax.maxStrainRate = (10 * rate, 10 * rate, rate)
triax.maxUnbalanced = 10.0
rows = []
t1 = time.time()
while -triax.strain[2] < target:
    O.run(100, True)
    s = triax.stress
    rows.append((-triax.strain[2], -s[0], -s[1], -s[2]))
    if time.time() - t1 > 3600:
        break
json.dump({"rows": rows, "seconds_compaction": t_comp, "seconds_shear": time.time() - t1,
           "steps": O.iter}, open(os.environ["FR_OUT"], "w"))
'''


def angle(s1, s3):
    return math.degrees(math.asin((s1 - s3) / (s1 + s3)))


def run_yade(sample, mu, tmp: Path):
    yade = shutil.which("yade")
    if yade is None:
        return None
    data = dict(sample, mu=mu, kn=KN, pressure=P, strain=STRAIN)
    (tmp / "sample.json").write_text(json.dumps(data))
    (tmp / "run.py").write_text(YADE_SCRIPT)
    env = dict(os.environ, FR_SAMPLE=str(tmp / "sample.json"), FR_OUT=str(tmp / "out.json"))
    t0 = time.perf_counter()
    subprocess.run([yade, "-n", "-x", str(tmp / "run.py")], env=env, check=True,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, cwd=tmp)
    wall = time.perf_counter() - t0
    out = json.loads((tmp / "out.json").read_text())
    rows = np.array(out["rows"])
    ratio = rows[:, 3] / rows[:, 1]
    k = int(np.argmax(ratio))
    return {"peak": angle(rows[k, 3], rows[k, 1]), "end": angle(rows[-1, 3], rows[-1, 1]),
            "strain": rows[-1, 0], "seconds": wall, "steps": out["steps"]}


def run_ours(assembly, mu, budget):
    model = ContactModel(Coulomb(mu), kn=KN, kt=KN)
    a = Assembly(assembly.positions, assembly.radii, assembly.cell, model, tolerance=assembly.tolerance)
    t0 = time.perf_counter()
    r = triaxial(a, "axisymmetric", pressure=P, axial_strain=STRAIN, increments=int(STRAIN / 2e-5),
                 consolidation="frictionless", max_time=budget, max_cuts=3)
    wall = time.perf_counter() - t0
    ok = r.converged
    ratio = np.where(ok, r.stress_ratio, -np.inf)
    k = int(np.argmax(ratio))
    last = int(np.flatnonzero(ok)[-1])
    s = r.stress
    return {"peak": angle(s[k, 2, 2], s[k, 0, 0]), "end": angle(s[last, 2, 2], s[last, 0, 0]),
            "strain": float(r.axial_strain[last]), "seconds": wall, "message": r.message,
            "increments": int(ok.sum()) - 1}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=400)
    parser.add_argument("--mu", default="0.3,0.5")
    parser.add_argument("--budget", type=float, default=600.0, help="seconds for our run of each μ")
    args = parser.parse_args(argv)
    t0 = time.perf_counter()
    sample = Assembly.random(args.n, 3, ContactModel(Coulomb(0.3), kn=KN, kt=KN),
                             polydispersity=0.2, seed=1)
    t_pack = time.perf_counter() - t0
    data = {"positions": sample.positions.tolist(), "radii": sample.radii.tolist(),
            "L": float(sample.cell[0, 0])}
    rows = []
    have_yade = shutil.which("yade") is not None
    for mu in (float(m) for m in args.mu.split(",")):
        with tempfile.TemporaryDirectory() as tmp:
            yade = run_yade(data, mu, Path(tmp)) if have_yade else None
        print(f"mu = {mu}: YADE {yade}", flush=True)
        ours = run_ours(sample, mu, args.budget)
        fmt = lambda d, key: f"{d[key]:.2f}" if d else "-"  # noqa: E731
        rows.append([mu, f"{ours['peak']:.2f}", f"{ours['end']:.2f} (at {100 * ours['strain']:.3f} %)",
                     f"{ours['seconds']:.1f} ({ours['increments']} increments: {ours['message']})",
                     fmt(yade, "peak"), f"{yade['end']:.2f} (at {100 * yade['strain']:.1f} %)" if yade else "-",
                     f"{yade['seconds']:.1f} ({yade['steps']} steps)" if yade else "-"])
        print(rows[-1], flush=True)
    notes = (f"Sample: {args.n} spheres, radii 1 ± 20 %, seed 1, solid fraction "
             f"{sample.solid_fraction:.3f} before consolidation (packing {t_pack:.1f} s, shared by "
             "both). Angles in degrees, asin((σ1 − σ3)/(σ1 + σ3)); wall times in seconds on this "
             "machine in the same run. " + ("" if have_yade else "YADE is not installed: "
                                            "`apt-get install yade` (Debian) and run again."))
    write_table("assembly_yade", "Random packing, axisymmetric compression: frictionrules beside YADE",
                ["μ", "ours: peak angle", "ours: angle at the end", "ours: seconds",
                 "YADE: peak angle", "YADE: angle at 12 %", "YADE: seconds"], rows, notes)


if __name__ == "__main__":
    main()
