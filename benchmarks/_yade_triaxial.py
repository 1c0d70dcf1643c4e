"""Run by YADE (``yade -j1 -n -x _yade_triaxial.py``), not imported: the YADE side of
``assembly_yade.py``.

The job is a JSON file named by ``$FR_YADE_JOB``:

* ``{"task": "sample", "seed", "n", "radius", "fuzz", "solid_fraction", "out"}``: a loose
  periodic cloud by YADE's own generator (``SpherePack.makeCloud``, radii uniform in
  ``radius (1 ± fuzz)``) in the cube holding ``solid_fraction``; writes ``positions``,
  ``radii``, ``cell`` (columns: cell vectors) to ``out``.
* ``{"task": "triaxial", "sample", "mu", "kn", "kt", "pressure", "inertial_number",
  "damping", "density", "axial_strain", "record_every", "stress_tol", "unbalanced_tol",
  "dt_safety", "consolidation_rate", "lateral_rate_cap", "cell_mass", "cell_damping",
  "max_consolidation_steps", "out"}``: frictionless isotropic compression to ``pressure``
  (PeriTriaxController with cell inertia, friction 0) until every normal stress is within
  ``stress_tol`` of it and YADE's unbalanced-force ratio is below ``unbalanced_tol``; then
  friction μ on the materials and on every existing contact, the cell's deformation reset,
  and axisymmetric compression along z at the constant logarithmic rate
  ``ε̇ = I √(p/ρ) / d`` (``d`` the mean diameter) with σxx = σyy = p held, to
  ``axial_strain``. A record every ``record_every`` of axial strain.

The cell's inertia (``dynCell``) is ``cell_mass`` times the grains' mass, its damping
``cell_damping`` (PeriTriaxController's ``growDamping``): with the default inertia (the grains'
mass) the lateral stress swings by ±7 % at a period of ~2000 steps during the shear; at 0.01 of
it and damping 0.8 it holds within ±0.3 %. (The stiffness servo, ``dynCell=False``, chatters at
its rate cap and never settles the frictionless sample.) The cell stays a rectangular box: the
controller drives the normal components only.

Contact stiffness: every sphere has its own FrictMat with ``young = kn / r`` and
``poisson = kt / kn``, so that Ip2_FrictMat_FrictMat_FrictPhys's
``kn = 2 E1 r1 E2 r2 / (E1 r1 + E2 r2)`` is exactly ``kn`` for every pair (and ``ks = kt``).
Time step: ``dt_safety × PWaveTimeStep()``, fixed for the run.

Output (JSON, compression positive): ``axial_strain`` (−ln of the cell's axial stretch),
``volumetric_strain`` (−ln det F), ``stress`` (k, 3, 3; Love–Weber, ``-getStress()``),
``coordination`` (2 × force-carrying contacts / N), ``coordination_mechanical`` (Thornton's
``(2C − N1)/(N − N0 − N1)``), ``unbalanced``, ``steps``, ``cpu`` (process time since the start
of the shear), and the consolidation's ``dt``, steps, CPU and state.
"""

import json
import math
import os
import time

import numpy as np
from yade import O, pack, utils
from yade.wrapper import (Bo1_Sphere_Aabb, ForceResetter, FrictMat, Ig2_Sphere_Sphere_ScGeom,
                          InsertionSortCollider, InteractionLoop, Ip2_FrictMat_FrictMat_FrictPhys,
                          Law2_ScGeom_FrictPhys_CundallStrack, NewtonIntegrator,
                          PeriTriaxController)
from yade.minieigenHP import Matrix3, Vector3

CHECK_EVERY = 200  # steps between the consolidation's checks


def write_json(path, data):
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        json.dump(data, f)
    os.replace(tmp, path)


def make_sample(job):
    n, r, fuzz = job["n"], job["radius"], job["fuzz"]
    solid = n * 4.0 / 3.0 * math.pi * r**3 * (1 + fuzz**2)   # E[r³] for r uniform in r(1 ± fuzz)
    side = (solid / job["solid_fraction"]) ** (1 / 3)
    sp = pack.SpherePack()
    made = sp.makeCloud(Vector3(0, 0, 0), Vector3(side, side, side), rMean=r, rRelFuzz=fuzz,
                        num=n, periodic=True, seed=job["seed"])
    if made != n:
        raise RuntimeError(f"makeCloud placed {made} of {n} spheres")
    positions = [[c[0], c[1], c[2]] for c, _ in sp]
    radii = [float(rad) for _, rad in sp]
    write_json(job["out"], {"positions": positions, "radii": radii,
                            "cell": [[side, 0, 0], [0, side, 0], [0, 0, side]],
                            "seed": job["seed"], "generator": "yade.pack.SpherePack.makeCloud"})


def stress():
    """Compression-positive Love–Weber stress (3 × 3)."""
    s = utils.getStress()
    return [[-s[i, j] for j in range(3)] for i in range(3)]


def contact_counts(n):
    per = np.zeros(n, dtype=int)
    for i in O.interactions:
        if i.isReal and i.phys.normalForce.norm() > 0:
            per[i.id1] += 1
            per[i.id2] += 1
    c = per.sum() // 2
    n0, n1 = np.sum(per == 0), np.sum(per == 1)
    z = 2.0 * c / n
    zm = (2.0 * c - n1) / (n - n0 - n1) if n - n0 - n1 > 0 else 0.0
    return z, zm


def cell_strain():
    """(axial Hencky strain, volumetric strain), compression positive, from the cell's F."""
    t = O.cell.trsf
    f = np.array([[t[i, j] for j in range(3)] for i in range(3)])
    w, v = np.linalg.eigh(f.T @ f)
    hencky = 0.5 * (v * np.log(w)) @ v.T            # ln U, U = sqrt(FᵀF)
    return -hencky[2, 2], -math.log(np.linalg.det(f))


def triaxial(job):
    sample = json.load(open(job["sample"]))
    mu, kn, kt, p, rho = job["mu"], job["kn"], job["kt"], job["pressure"], job["density"]
    radii = sample["radii"]
    n = len(radii)
    O.periodic = True
    h = sample["cell"]
    O.cell.hSize = Matrix3(*[h[i][j] for i in range(3) for j in range(3)])
    for x, r in zip(sample["positions"], radii):
        mat = O.materials.append(FrictMat(young=kn / r, poisson=kt / kn, frictionAngle=0.0,
                                          density=rho))
        O.bodies.append(utils.sphere(Vector3(*x), r, material=mat))
    d_mean = 2 * sum(radii) / n
    rate = job["inertial_number"] * math.sqrt(p / rho) / d_mean
    O.engines = [
        ForceResetter(),
        InsertionSortCollider([Bo1_Sphere_Aabb()]),
        InteractionLoop([Ig2_Sphere_Sphere_ScGeom()], [Ip2_FrictMat_FrictMat_FrictPhys()],
                        [Law2_ScGeom_FrictPhys_CundallStrack()]),
        PeriTriaxController(label="triax", dynCell=True, goal=(-p, -p, -p), stressMask=7,
                            maxStrainRate=(job["consolidation_rate"],) * 3,
                            growDamping=job["cell_damping"], maxUnbalanced=job["unbalanced_tol"],
                            relStressTol=job["stress_tol"], absStressTol=job["stress_tol"] * p),
        NewtonIntegrator(damping=job["damping"]),
    ]
    triax = O.engines[3]
    triax.mass = job["cell_mass"] * sum(b.state.mass for b in O.bodies)
    O.dt = job["dt_safety"] * utils.PWaveTimeStep()
    cpu0, wall0 = time.process_time(), time.time()
    tol = job["stress_tol"] * p
    max_steps = job["max_consolidation_steps"]
    while True:
        O.run(CHECK_EVERY, True)
        s = stress()
        if (all(abs(s[i][i] - p) <= tol for i in range(3))
                and utils.unbalancedForce() < job["unbalanced_tol"]):
            break
        if O.iter >= max_steps:
            raise RuntimeError(f"consolidation did not converge in {O.iter} steps: stress "
                               f"{[s[i][i] for i in range(3)]}, unbalanced {utils.unbalancedForce()}")
    consolidation = {"steps": O.iter, "cpu": time.process_time() - cpu0,
                     "wall": time.time() - wall0, "stress": s,
                     "unbalanced": utils.unbalancedForce(),
                     "solid_fraction": sum(4 / 3 * math.pi * r**3 for r in radii) / O.cell.volume,
                     "coordination": contact_counts(n)[0]}
    # friction on: the materials (new contacts) and the contacts that exist
    for m in O.materials:
        m.frictionAngle = math.atan(mu)
    for i in O.interactions:
        if i.isReal:
            i.phys.tangensOfFrictionAngle = mu
    O.cell.trsf = Matrix3(1, 0, 0, 0, 1, 0, 0, 0, 1)
    triax.goal = (-p, -p, -1.0)          # a strain goal beyond the end: the rate stays at its cap
    triax.stressMask = 3
    triax.maxStrainRate = (job["lateral_rate_cap"] * rate, job["lateral_rate_cap"] * rate, rate)
    step_strain = -math.log(1 - rate * O.dt)     # axial Hencky strain per step at the cap
    rec = {k: [] for k in ("axial_strain", "volumetric_strain", "stress", "coordination",
                           "coordination_mechanical", "unbalanced", "steps", "cpu")}
    cpu1, wall1, iter1 = time.process_time(), time.time(), O.iter

    def record():
        ea, ev = cell_strain()
        z, zm = contact_counts(n)
        rec["axial_strain"].append(ea)
        rec["volumetric_strain"].append(ev)
        rec["stress"].append(stress())
        rec["coordination"].append(z)
        rec["coordination_mechanical"].append(zm)
        rec["unbalanced"].append(utils.unbalancedForce())
        rec["steps"].append(O.iter - iter1)
        rec["cpu"].append(time.process_time() - cpu1)
        return ea

    ea = record()
    k = 1
    target_end = job["axial_strain"]
    every = job["record_every"]
    while ea < target_end - 1e-12:
        target = min(k * every, target_end)
        O.run(max(1, math.ceil((target - ea) / step_strain - 1e-9)), True)
        ea = record()
        k = int(round(ea / every)) + 1
    out = {"dt": O.dt, "rate": rate, "mean_diameter": d_mean, "consolidation": consolidation,
           "shear": {"steps": O.iter - iter1, "cpu": time.process_time() - cpu1,
                     "wall": time.time() - wall1},
           "records": rec, "job": job}
    write_json(job["out"], out)


job = json.load(open(os.environ["FR_YADE_JOB"]))
{"sample": make_sample, "triaxial": triaxial}[job["task"]](job)
