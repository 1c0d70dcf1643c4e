"""The first call of the command line after install, and the same call again.

Each command runs as its own process, the way a user types it, with ``NUMBA_CACHE_DIR`` and
``FRICTIONRULES_CACHE_DIR`` set to a new empty folder (the first call: everything compiled),
then again with the same folders (later calls: the compiled kernels loaded from the cache).
The time is the whole process as ``time`` measures it: wall time, and the user + system CPU
time of the process and its children. Each source is copied and its bytecode compiled before
(``compileall``, as ``pip install`` does), so that a call reads it also where the environment
sets ``PYTHONDONTWRITEBYTECODE`` (which would otherwise make every call compile the package's
sources, a tenth of a second).

``--source LABEL=DIR`` (repeatable) runs the same commands with ``PYTHONPATH=DIR`` for each
label, interleaved (every command: first label cold and warm, then the next label), so that a
before/after comparison on a shared machine sees the same background load; the load average
is noted on every row.

::

    python benchmarks/first_call.py
    python benchmarks/first_call.py --source before=/tmp/base/src --source after=src --rounds 2
"""

from __future__ import annotations

import argparse
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _table import write_table  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SHARED = ROOT.parent / "shared"


def commands(tmp: Path) -> dict[str, list[str]]:
    """The measured command lines (arguments after ``frictionrules``)."""
    return {
        "law": ["law", "elliptic", "--mu-x", "0.6", "--mu-y", "0.3", "--force", "0.3", "0.2",
                "--normal", "1", "--json"],
        "solve CubeH8": ["solve", str(SHARED / "fclib" / "CubeH8.hdf5")],
        "solve SpheresPile-nc3970 --time-limit 5": [
            "solve", str(SHARED / "fclib-large" / "SpheresPile-nc3970.hdf5"), "--time-limit", "5"],
        "drive contact_shear.toml": ["drive", str(ROOT / "examples" / "contact_shear.toml"),
                                     "--out", str(tmp / "shear.csv")],
        "assembly assembly_fcc.toml": ["assembly", str(ROOT / "examples" / "assembly_fcc.toml"),
                                       "--out", str(tmp / "run.h5")],
        "paper": ["paper", "--out", str(tmp / "figures")],
    }


def run_once(argv, env, timeout) -> tuple[float, float, int]:
    """``(wall seconds, CPU seconds, exit code)`` of one process (``-1``: timed out)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    try:
        proc = subprocess.run([sys.executable, "-m", "frictionrules", *argv], env=env, timeout=timeout,
                              stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        code = proc.returncode
    except subprocess.TimeoutExpired:
        code = -1
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu, code


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--source", action="append", default=None, metavar="LABEL=DIR",
                    help="a label and the folder put on PYTHONPATH (default: this checkout's src)")
    ap.add_argument("--only", default=None, help="comma-separated command names (default: all)")
    ap.add_argument("--rounds", type=int, default=1, help="cold+warm pairs per command and source")
    ap.add_argument("--timeout", type=float, default=900.0, help="seconds before a run is stopped")
    args = ap.parse_args()

    sources = [s.split("=", 1) for s in (args.source or [f"this checkout={ROOT / 'src'}"])]
    rows = []
    with tempfile.TemporaryDirectory(prefix="first-call-") as scratch:
        installed = {}
        for label, src in sources:          # a copy with the bytecode an installation has
            installed[label] = Path(scratch) / f"src-{label}"
            shutil.copytree(Path(src).resolve(), installed[label], ignore=shutil.ignore_patterns("__pycache__"))
            subprocess.run([sys.executable, "-m", "compileall", "-q", str(installed[label])], check=True,
                           stdout=subprocess.DEVNULL)
        names = list(commands(Path(scratch)))
        if args.only:
            names = [n for n in names if any(n.startswith(o.strip()) for o in args.only.split(","))]
        for name in names:
            for rnd in range(args.rounds):
                for label, _src in sources:
                    tmp = Path(scratch) / f"{label}-{rnd}-{names.index(name)}"
                    for sub in ("first", "again"):      # outputs apart: a run file would resume
                        (tmp / sub).mkdir(parents=True)
                    env = dict(os.environ, PYTHONPATH=str(installed[label]), MPLBACKEND="Agg",
                               NUMBA_CACHE_DIR=str(tmp / "numba"), FRICTIONRULES_CACHE_DIR=str(tmp / "kernels"))
                    load = os.getloadavg()[0]
                    cold = run_once(commands(tmp / "first")[name], env, args.timeout)
                    warm = run_once(commands(tmp / "again")[name], env, args.timeout)
                    row = [name, label, f"{cold[0]:.1f}", f"{cold[1]:.1f}", f"{warm[0]:.2f}", f"{warm[1]:.2f}",
                           f"{cold[2]}/{warm[2]}", f"{load:.1f}"]
                    print("  ".join(row), flush=True)
                    rows.append(row)
                    shutil.rmtree(tmp, ignore_errors=True)
    write_table("first_call", "First call (empty Numba cache) and later calls of the command line",
                ["command", "source", "first: wall s", "first: CPU s", "again: wall s", "again: CPU s",
                 "exit codes", "load avg (1 min) at start"], rows,
                notes="Each call is a new process, `python -m frictionrules ...`, timed as a whole "
                      "(wall; CPU = user + system of the process and its children), from a copy of the "
                      "source with its bytecode compiled (as installed). 'first': "
                      "NUMBA_CACHE_DIR and FRICTIONRULES_CACHE_DIR in a new empty folder; 'again': the "
                      "same call with the same folders. Exit code -1: stopped after --timeout seconds. "
                      f"{os.cpu_count()} logical processors; the load average is that of the whole "
                      "machine, other jobs included.")


if __name__ == "__main__":
    main()
