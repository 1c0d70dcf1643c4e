"""Benchmark: the exported Coulomb pair style against LAMMPS's own linear spring-Coulomb styles,
per step, on one rank; and on one and more MPI ranks, with the memory per rank.

One command: ``python benchmarks/lammps_pair.py [--tiles 3] [--steps 500] [--repeats 5]
[--ranks 1]``.

The 400-sphere packing of ``Assembly.random(400, 3, seed=1)`` (radii 1 ± 20 %, density 1) is
tiled k × k × k times into a periodic cell k times larger (``--tiles 3``: 10,800 spheres),
squeezed by 0.5 % (overlaps up to about 1 % of a radius) and sheared in LAMMPS (``fix deform
xy erate 0.05 remap v``, ``fix nve/sphere``, dt = 1e-3, neighbour skin 0.3, no damping) with
kn = kt = 1e4, μ = 0.3, by

- ``gran/hooke/history 1e4 1e4 0 0 0.3 0``;
- ``granular`` with ``hooke 1e4 0 tangential linear_history 1e4 0 0.3 damping mass_velocity``;
- the exported ``Coulomb(0.3)`` (``frictionrules/coulomb``), with the engine's kinematics (the
  default) and with ``history project`` (gran/hooke/history's), each with and without
  ``dissipation no`` (the history without the dissipation and the status), and with μ = 0 in
  its ``pair_coeff`` (frictionless: the structured return's T = 0), and with ``history
  rescale lever contact dissipation no`` (``pair granular``'s kinematics).

After 100 steps of warm-up, ``--steps`` steps are timed. The styles run in turn, one LAMMPS
process each, ``--repeats`` rounds (interleaved, so that the machine's other load falls on all
of them alike); the table gives, per style, the median over the rounds and the spread (least
to largest) of LAMMPS's loop time and of its Pair section per step, in CPU time (wall time
times LAMMPS's "% CPU use": on a loaded machine the process waits for a core, which wall time
counts and CPU time does not) and in wall time, and the ratio of the medians to
``gran/hooke/history`` → ``results/lammps_pair.md``.

``--ranks 1 2`` (more than one count) measures instead ``gran/hooke/history``, the exported
style with the engine's kinematics and the exported style with ``history project dissipation
no`` on each number of ranks (``mpirun -np N``, the ``mpich`` wheel's), all runs interleaved
(every style and rank count in turn, ``--repeats`` rounds), e.g. ``--tiles 6 --steps 300
--repeats 3 --ranks 1 2`` (86,400 spheres): wall and CPU ms per step, the speed-up over one
rank (wall, and CPU: wall × "% CPU use", what an idle machine would give where the ranks
waited for a core), and the largest resident memory of any rank (max RSS, from
``os.wait4`` of each rank's LAMMPS) and it per 10^5 spheres →
``results/lammps_pair_tiles<k>_ranks.md``.
"""

from __future__ import annotations

import argparse
import os
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


#: Runs a command as a child and prints its largest resident memory (kB) to stderr: one per
#: MPI rank when mpirun starts it (fork and exec keep the rank's MPI environment and files).
_RSS = ("import os, sys\npid = os.fork()\nif pid == 0:\n    os.execv(sys.argv[1], sys.argv[1:])\n"
        "_, status, use = os.wait4(pid, 0)\nprint('maxrss_kb', use.ru_maxrss, file=sys.stderr)\n"
        "sys.exit(os.waitstatus_to_exitcode(status))\n")


def _time(install, folder: Path, script: str, steps: int, ranks: int = 1):
    """Loop time and Pair time per step (ms, wall) of the timed ``run``, the fraction of a
    core each rank had then (LAMMPS's "% CPU use") and the largest max RSS of a rank (MB)."""
    (folder / "in.lmp").write_text(script)
    cmd = [sys.executable, "-c", _RSS, str(install.lmp), "-in", "in.lmp", "-screen", "none",
           "-log", "log.lammps"]
    if ranks > 1:
        cmd = [str(install.mpirun), "-np", str(ranks), *cmd]
    out = subprocess.run(cmd, cwd=folder, env=install.env(), capture_output=True, text=True)
    log = (folder / "log.lammps").read_text()
    if out.returncode != 0:
        raise SystemExit(log[-2000:] + out.stderr)
    loop = [float(m) for m in re.findall(r"Loop time of ([0-9.eE+-]+) on", log)][-1]
    pair = [float(m) for m in re.findall(r"^Pair\s*\|\s*([0-9.eE+-]+)", log, re.M)][-1]
    cpu = [float(m) for m in re.findall(r"([0-9.]+)% CPU use", log)][-1] / 100.0
    rss = max(int(m) for m in re.findall(r"maxrss_kb (\d+)", out.stderr)) / 1024.0
    return 1e3 * loop / steps, 1e3 * pair / steps, cpu, rss


def _cell(values) -> str:
    """``median [least–largest]``."""
    return f"{np.median(values):.2f} [{min(values):.2f}–{max(values):.2f}]"


def main(argv=None) -> None:
    import frictionrules as fr
    from frictionrules._export import lammps_install
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--tiles", type=int, default=3)
    ap.add_argument("--steps", type=int, default=500)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--ranks", type=int, nargs="+", default=[1],
                    help="MPI ranks; more than one count: the speed-up and memory table")
    args = ap.parse_args(argv)
    install = lammps_install()
    with tempfile.TemporaryDirectory(prefix="lammps-pair-bench-") as tmp:
        root = Path(tmp)
        n = _data(root / "data.pack", args.tiles)
        res = fr.export(fr.Coulomb(MU), "lammps", root / "coulomb", kt=KT, kn=KN, build=True)
        ours = (root / "coulomb" / "pair.lmp").read_text()
        def keywords(words):
            return ours.replace("axis 1.0 0.0 0.0", "axis 1.0 0.0 0.0 " + words)

        styles = {
            "gran/hooke/history": f"pair_style gran/hooke/history {KN} {KT} 0.0 0.0 {MU} 0\n"
                                  "pair_coeff * *",
            "granular (hooke, linear_history)": "pair_style granular\npair_coeff * * hooke "
                                                f"{KN} 0.0 tangential linear_history {KT} 0.0 "
                                                f"{MU} damping mass_velocity",
            "frictionrules/coulomb": ours,
            "frictionrules/coulomb dissipation no": keywords("dissipation no"),
            "frictionrules/coulomb history project": keywords("history project"),
            "frictionrules/coulomb history project dissipation no":
                keywords("history project dissipation no"),
            "frictionrules/coulomb, mu = 0": ours.replace(f" {MU!r}\n", " 0.0\n"),
            "frictionrules/coulomb history rescale lever contact dissipation no":
                keywords("history rescale lever contact dissipation no"),
        }
        if len(args.ranks) > 1:
            keep = ("gran/hooke/history", "frictionrules/coulomb",
                    "frictionrules/coulomb history project dissipation no")
            runs = {(name, r): [] for name in keep for r in args.ranks}
        else:
            runs = {(name, args.ranks[0]): [] for name in styles}
        for _ in range(args.repeats):
            for name, ranks in runs:
                folder = root / re.sub(r"[^a-z0-9]+", "_", f"{name} {ranks}")
                folder.mkdir(exist_ok=True)
                runs[name, ranks].append(_time(install, folder, _script(
                    root / "data.pack", styles[name], args.steps), args.steps, ranks))
    if len(args.ranks) > 1:
        return _ranks_table(runs, args, n, install, res)
    runs = {name: r for (name, _), r in runs.items()}
    med = {name: np.median([[loop * cpu, pair * cpu, loop, pair] for loop, pair, cpu, _ in r],
                           axis=0) for name, r in runs.items()}
    ref = med["gran/hooke/history"]
    rows = []
    for name, r in runs.items():
        loop_cpu = [loop * cpu for loop, _, cpu, _ in r]
        pair_cpu = [pair * cpu for _, pair, cpu, _ in r]
        rows.append([name, _cell(loop_cpu), _cell(pair_cpu), f"{med[name][0] / ref[0]:.2f}",
                     f"{med[name][1] / ref[1]:.2f}", _cell([loop for loop, _, _, _ in r]),
                     f"{med[name][2] / ref[2]:.2f}"])
    write_table("lammps_pair", f"LAMMPS pair styles: ms per step, {n:,} spheres, "
                f"{args.ranks[0]} rank{'s' if args.ranks[0] > 1 else ''}",
                ["pair style", "CPU ms/step", "Pair CPU ms/step", "× gran/hooke/history",
                 "Pair × gran/hooke/history", "wall ms/step", "wall × gran/hooke/history"], rows,
                f"{args.steps} steps of shear after 100 of warm-up; median [least–largest] of "
                f"{args.repeats} interleaved runs of each; CPU time = wall time × LAMMPS's "
                f"'% CPU use'. Load average at the end: "
                + ", ".join(f"{v:.1f}" for v in os.getloadavg()) + f". LAMMPS {install.version} (PyPI wheel), the plugin built by "
                f"frictionrules.export(..., build=True) ({res.library.name}, -O3 -fno-math-errno, no "
                "-march=native).")



def _ranks_table(runs, args, n, install, res):
    """``results/lammps_pair_tiles<k>_ranks.md``: per style and number of ranks, wall and CPU
    time per step, the speed-up over the fewest ranks, the largest max RSS of a rank."""
    first = min(args.ranks)
    med = {key: np.median([[loop, loop * cpu] for loop, _, cpu, _ in r], axis=0)
           for key, r in runs.items()}
    rows = []
    for (name, ranks), r in runs.items():
        wall, cpu = med[name, ranks]
        rss = max(m for _, _, _, m in r)
        rows.append([name, ranks, _cell([loop for loop, _, _, _ in r]),
                     _cell([loop * c for loop, _, c, _ in r]),
                     f"{med[name, first][0] / wall:.2f}", f"{med[name, first][1] / cpu:.2f}",
                     f"{rss:.0f}", f"{rss * 1e5 / n:.0f}"])
    loads = os.getloadavg()
    write_table(f"lammps_pair_tiles{args.tiles}_ranks",
                f"LAMMPS pair styles on {', '.join(map(str, args.ranks))} MPI ranks: "
                f"{n:,} spheres",
                ["pair style", "ranks", "wall ms/step", "CPU ms/step (wall × % CPU)",
                 f"speed-up over {first} (wall)", f"speed-up over {first} (CPU)",
                 "max RSS of a rank (MB)", "max RSS per 10^5 spheres (MB)"], rows,
                f"{args.steps} steps of shear after 100 of warm-up; median [least–largest] of "
                f"{args.repeats} interleaved runs of each; the CPU speed-up is the one of an "
                "idle machine where the ranks waited for a core (each rank's wall time × its "
                f"'% CPU use'). Load average at the end: {loads[0]:.1f}, {loads[1]:.1f}, "
                f"{loads[2]:.1f}. LAMMPS {install.version} (PyPI wheel), mpirun of the mpich "
                f"wheel, the plugin built by frictionrules.export(..., build=True) "
                f"({res.library.name}, -O3 -fno-math-errno, no -march=native).")


if __name__ == "__main__":
    main()
