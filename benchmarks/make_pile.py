"""Generate a pile of spheres as an FCLIB problem with Siconos + Bullet (system Python).

Usage (Debian: ``apt-get install python3-siconos python3-h5py``)::

    /usr/bin/python3 benchmarks/make_pile.py OUT.hdf5 [--spheres 2400] [--seed 0] [--steps 20]

Scene: ``--spheres`` polydisperse spheres (radii uniform in [0.04, 0.06] m, density 2500
kg/m^3) started on a jittered cubic lattice of pitch 0.122 m, nearly touching, inside a box
with a floor and four walls (static), gravity 9.81 m/s^2, friction mu = 0.5, Newton impact
coefficient 0; Siconos 4.4 ``MechanicsHdf5Runner`` with the Bullet collision manager,
Moreau–Jean time stepping h = 5e-3, theta = 0.50001, the Siconos NSGS solver (100 sweeps,
tol 1e-4) inside the simulation. After each step the one-step frictional contact problem
``u = W r + q`` (W from Siconos' sparse-block Delassus operator, converted exactly) is kept
when it has more contacts than any before; after ``--steps`` steps the largest is written as
an FCLIB local problem with ``/guesses/1/r`` (the previous step's reactions), Siconos'
in-simulation ``/solution/r`` (not converged: not a reference) and this provenance in
``info/description``. Deterministic for a given seed on one machine.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile

import numpy as np


def scene(io, n, seed):
    from siconos.mechanics.collision.tools import Contactor
    rng = np.random.default_rng(seed)
    side = int(np.ceil((n / 2.0) ** (1.0 / 3.0)))  # a column twice as tall as wide
    pitch = 0.122
    io.add_Newton_impact_friction_nsl("contact", mu=0.5, e=0.0)
    width = side * pitch
    io.add_primitive_shape("Ground", "Box", (width + 0.4, width + 0.4, 0.1))
    io.add_primitive_shape("WallX", "Box", (0.1, width + 0.4, 3 * n / side ** 2 * pitch))
    io.add_primitive_shape("WallY", "Box", (width + 0.4, 0.1, 3 * n / side ** 2 * pitch))
    io.add_object("ground", [Contactor("Ground")], translation=[0, 0, -0.05])
    for k, (sx, sy) in enumerate(((1, 0), (-1, 0), (0, 1), (0, -1))):
        shape = "WallX" if sx else "WallY"
        io.add_object(f"wall{k}", [Contactor(shape)],
                      translation=[sx * (width / 2 + 0.05), sy * (width / 2 + 0.05), 1.5 * n / side ** 2 * pitch])
    radii = rng.uniform(0.04, 0.06, n)
    for i in range(n):
        io.add_primitive_shape(f"S{i}", "Sphere", (radii[i],))
        ix, iy, iz = i % side, (i // side) % side, i // (side * side)
        pos = [(ix + 0.5) * pitch - width / 2, (iy + 0.5) * pitch - width / 2, (iz + 0.5) * pitch + 0.01]
        pos = [c + rng.uniform(-0.005, 0.005) for c in pos]
        mass = 2500.0 * 4.0 / 3.0 * np.pi * radii[i] ** 3
        io.add_object(f"sphere{i}", [Contactor(f"S{i}")], translation=pos, mass=mass,
                      velocity=[0, 0, 0, 0, 0, 0])


class Keeper:
    """After each step, keep the one-step problem with the most contacts."""

    def __init__(self):
        self.best = None
        self.previous_r = None

    def __call__(self, runner):
        import scipy.sparse as sp
        import siconos.numerics as sn
        import siconos.kernel as sk
        osnspb = sk.cast_FrictionContact(runner._simulation.oneStepNSProblem(0))
        n = osnspb.getSizeOutput()
        r = np.array(osnspb.z()).ravel().copy()           # the reactions Siconos found
        previous, self.previous_r = self.previous_r, r
        if n == 0 or (self.best is not None and n <= self.best[0].shape[0]):
            return
        W = sp.csr_matrix(sn.NM_triplet(osnspb.M().numericsMatrix()))
        q = np.array(osnspb.q()).ravel().copy()
        mu = np.array([osnspb.getMu(a) for a in range(n // 3)])
        self.best = (W, q, mu, r, previous, runner._simulation.startingTime())


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out")
    ap.add_argument("--spheres", type=int, default=2400)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--steps", type=int, default=20)
    args = ap.parse_args(argv)
    import h5py
    import siconos.numerics as sn
    from siconos.io.mechanics_run import MechanicsHdf5Runner
    from siconos.mechanics.collision.bullet import SiconosBulletOptions

    with tempfile.TemporaryDirectory() as tmp:
        scene_file = os.path.join(tmp, "scene.hdf5")
        with MechanicsHdf5Runner(mode="w", io_filename=scene_file) as io:
            scene(io, args.spheres, args.seed)
        keeper = Keeper()
        import siconos.kernel as sk
        options = sk.solver_options_create(sn.SICONOS_FRICTION_3D_NSGS)
        options.iparam[sn.SICONOS_IPARAM_MAX_ITER] = 100
        options.dparam[sn.SICONOS_DPARAM_TOL] = 1e-4
        bullet = SiconosBulletOptions()
        with MechanicsHdf5Runner(mode="r+", io_filename=scene_file) as io:
            io.run(t0=0, T=args.steps * 5e-3, h=5e-3, theta=0.50001, solver_options=options,
                   bullet_options=bullet, verbose=False, verbose_progress=False,
                   output_frequency=10 ** 9, end_run_iteration_hook=keeper)
    if keeper.best is None:
        print("no contact in the run", file=sys.stderr)
        return 1
    W, q, mu, r, r_prev, t = keeper.best
    nc = q.size // 3
    description = (f"{args.spheres} polydisperse spheres (radii U[0.04, 0.06] m) settling in a walled box; "
                   f"Siconos 4.4 + Bullet, Moreau-Jean h=5e-3, theta=0.50001, mu=0.5, e=0; the step at "
                   f"t={t:.3f} s with the most contacts ({nc}) of {args.steps}; seed {args.seed}; "
                   "generated by frictionrules benchmarks/make_pile.py")
    with h5py.File(args.out, "w") as h5:
        g = "fclib_local"
        h5[f"{g}/spacedim"] = np.array([3], np.int32)
        W = W.tocsr()
        W.sort_indices()
        for key, value in (("m", W.shape[0]), ("n", W.shape[1]), ("nz", -2), ("nzmax", W.nnz)):
            h5[f"{g}/W/{key}"] = np.array([value], np.int32)
        h5[f"{g}/W/p"], h5[f"{g}/W/i"] = W.indptr.astype(np.int32), W.indices.astype(np.int32)
        h5[f"{g}/W/x"] = W.data
        h5[f"{g}/vectors/q"], h5[f"{g}/vectors/mu"] = q, mu
        h5[f"{g}/info/title"] = np.bytes_(f"SpheresPile-nc{nc}".encode())
        h5[f"{g}/info/description"] = np.bytes_(description.encode())
        h5[f"{g}/info/math_info"] = np.bytes_(b"")
        if r_prev is not None and r_prev.size == q.size:
            h5["guesses/number_of_guesses"] = np.array([1], np.int32)
            h5["guesses/1/r"] = r_prev
        if r is not None and r.size == q.size:
            h5["solution/r"] = r
    print(f"wrote {args.out}: {nc} contacts, nnz(W) = {W.nnz}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
