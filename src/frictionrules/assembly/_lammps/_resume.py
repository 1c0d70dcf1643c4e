r"""A LAMMPS triaxial test resumed from its own restart files (``docs/assembly.md``, "LAMMPS",
"Restarts").

``write_lammps_triaxial(..., restart_every=e)`` runs the shear in segments, each followed by
``write_restart shear.<step>.restart``, and writes ``in.resume`` beside ``in.triaxial``.
:func:`resume_lammps_triaxial` goes on from one of those files. :func:`lammps_triaxial`
is ``triaxial(..., engine="lammps")``; with ``lammps_dir=DIR``, the same call
again (the same sample, law and options, recorded in ``run.json``) reads a finished run back
without running anything, resumes an interrupted one from its last complete restart file, and
starts any other afresh, as our engine's run file does.

A restart file is complete when it ends with LAMMPS's magic string (``write_restart`` writes it
last and ``read_restart`` checks it): a run stopped while writing one (``max_time``, a batch
system's time limit) leaves an incomplete file, which is passed over.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import numpy as np

from ...errors import FrictionRulesError, check_scalar
from .._results import TriaxialResult
from ._runner import (DATA, OPTIONS, RESUME, LammpsFiles, _records, _shear_done,
                      check_lammps_options, read_lammps_triaxial, run_lammps,
                      write_lammps_triaxial)
from ._script import POSITIONS, RECORD_COLUMNS, RECORDS, RESTART_PREFIX, SHEAR_DONE, STAGES

__all__ = ["resume_lammps_triaxial", "lammps_triaxial", "restart_files", "run_key"]

#: The last bytes of a complete restart file (LAMMPS's ``MAGIC_STRING`` and its terminating
#: zero, ``lmprestart.h``; ``write_restart`` writes it at the end, ``read_restart`` checks it).
MAGIC = b"LammpS RestartT\x00"


def _step(path: Path) -> int:
    return int(path.name[len(RESTART_PREFIX):-len(".restart")])


def restart_files(folder) -> list[Path]:
    """The complete restart files of the shear in ``folder``, by step (an incomplete one, left
    by a run stopped while writing it, is left out)."""
    out = []
    for path in Path(folder).glob(f"{RESTART_PREFIX}*.restart"):
        try:
            _step(path)
        except ValueError:
            continue
        with open(path, "rb") as f:
            f.seek(0, 2)
            size = f.tell()
            if size < len(MAGIC):
                continue
            f.seek(size - len(MAGIC))
            if f.read() == MAGIC:
                out.append(path)
    return sorted(out, key=_step)


def resume_lammps_triaxial(assembly, folder, *, restart=None, ranks: int = 1, progress=None,
                           max_time: float | None = None) -> TriaxialResult:
    """Go on with the shear of a LAMMPS run written with ``restart_every`` from one of its
    restart files (the last complete one by default): the records and centres after its step
    are dropped, ``in.resume`` runs on ``ranks`` ranks, and the result is read as
    :func:`read_lammps_triaxial` reads it. On one rank the result equals, bit for bit, that of
    the run that wrote the file had it gone on (``docs/assembly.md``, "LAMMPS")."""
    folder = Path(folder)
    if not (folder / RESUME).exists():
        raise FrictionRulesError(f"folder = {str(folder)!r} violates: a run written with "
                                 "restart_every (no in.resume)")
    check_lammps_options(assembly, "axisymmetric", "rectangular", ranks)
    complete = restart_files(folder)
    chosen = Path(restart) if restart is not None else (complete[-1] if complete else None)
    if chosen is None or (folder / chosen.name) not in complete:
        raise FrictionRulesError(f"restart = {restart!r} violates: a complete restart file of "
                                 f"the shear in {folder}")
    step = _step(chosen)
    opts = json.loads((folder / OPTIONS).read_text())
    _truncate(folder, step)
    if step >= opts["steps"]:    # stopped after the last segment's file: nothing left to run
        with open(folder / STAGES, "a") as f:
            f.write(f"stage {SHEAR_DONE} at step {step}\n")
        return read_lammps_triaxial(assembly, folder, ranks=ranks)
    files = LammpsFiles(folder, folder / RESUME, folder / DATA, opts["steps"],
                        opts["record_steps"], opts["pair_style"])
    ended = run_lammps(files, ranks=ranks, progress=progress, max_time=max_time,
                       arguments=["-var", "restart", chosen.name])
    return read_lammps_triaxial(assembly, folder, ended=f"{ended} (resumed from {chosen.name})",
                                ranks=ranks)


def _truncate(folder: Path, step: int) -> None:
    """Records and dumps after ``step`` dropped (what a resumed run writes again), and what a
    stopped process left half written."""
    path = folder / RECORDS
    kept = []
    for line in path.read_text().splitlines():
        values = line.split()
        if line.startswith("#") or (len(values) == len(RECORD_COLUMNS) and values[0].isdigit()
                                    and int(values[0]) <= step):
            kept.append(line)
    path.write_text("\n".join(kept) + "\n")
    dump = folder / POSITIONS
    if dump.exists():
        lines = dump.read_text().splitlines(keepends=True)
        cut, last = len(lines), -1
        for k, line in enumerate(lines):
            if line.startswith("ITEM: TIMESTEP"):
                text = lines[k + 1].strip() if k + 1 < len(lines) else ""
                at = int(text) if text.isdigit() else -1
                # the dumps' steps never decrease: a smaller one is a number cut short
                if at < last or at > step:
                    cut = k
                    break
                last = at
        dump.write_text("".join(lines[:cut]))
    stages = folder / STAGES
    if stages.exists():
        stages.write_text("".join(line for line in stages.read_text().splitlines(keepends=True)
                                  if SHEAR_DONE not in line))


def run_key(assembly, kind: str, options: dict) -> str:
    """A digest of the sample (centres, radii, cell), the contact model (its ``repr``: law,
    parameters, stiffnesses) and the test's options: the same run gives the same key."""
    h = hashlib.sha256()
    for a in (assembly.positions, assembly.radii, assembly.cell):
        h.update(np.ascontiguousarray(a, dtype=float).tobytes())
    h.update(json.dumps([repr(assembly.model), kind, options], sort_keys=True,
                        default=repr).encode())
    return h.hexdigest()


def _recorded_key(folder: Path) -> str | None:
    try:
        return json.loads((folder / OPTIONS).read_text()).get("run")
    except (OSError, ValueError):
        return None


def lammps_triaxial(assembly, kind: str, *, pressure: float, axial_strain: float, ranks: int,
                    lammps_dir=None, progress=None, max_time=None, **options) -> TriaxialResult:
    """``triaxial(..., method="dem", engine="lammps")``: write the files (into ``lammps_dir``,
    a temporary folder otherwise), run them on ``ranks`` ranks, read the result back. In a
    ``lammps_dir`` that holds the same run (the same :func:`run_key`, recorded in
    ``run.json``), a finished run is read back without running anything and an interrupted
    one resumed from its last complete restart file (``restart_every``); anything else starts
    afresh."""
    import tempfile
    check_lammps_options(assembly, kind, options.get("cell", "rectangular"), ranks)
    if max_time is not None:
        check_scalar("max_time", max_time, lo=0.0, lo_open=True)
    if lammps_dir is None:
        with tempfile.TemporaryDirectory(prefix="frictionrules-lammps-") as tmp:
            return _write_run_read(assembly, kind, tmp, pressure, axial_strain, ranks, progress,
                                   max_time, options, None)
    folder = Path(lammps_dir)
    key = run_key(assembly, kind, dict(options, pressure=pressure, axial_strain=axial_strain))
    if _recorded_key(folder) == key:
        if _shear_done(folder):
            return read_lammps_triaxial(assembly, folder, ended="completed (read back: this "
                                        "run had finished in this folder)")
        if (folder / RESUME).exists() and restart_files(folder):
            return resume_lammps_triaxial(assembly, folder, ranks=ranks, progress=progress,
                                          max_time=max_time)
    return _write_run_read(assembly, kind, folder, pressure, axial_strain, ranks, progress,
                           max_time, options, key)


def _write_run_read(assembly, kind, folder, pressure, axial_strain, ranks, progress, max_time,
                    options, key):
    files = write_lammps_triaxial(assembly, kind, folder, pressure=pressure,
                                  axial_strain=axial_strain, **options)
    if key is not None:    # the run's identity, for the same call again
        opts = json.loads((files.folder / OPTIONS).read_text())
        opts["run"] = key
        (files.folder / OPTIONS).write_text(json.dumps(opts, indent=1))
    ended = run_lammps(files, ranks=ranks, progress=progress, max_time=max_time)
    if ended != "completed" and len(_records(files.folder)) == 0:
        raise FrictionRulesError(f"max_time = {max_time!r} violates: long enough for the "
                                 "consolidation (LAMMPS was stopped before its first record)")
    return read_lammps_triaxial(assembly, files.folder, ended=ended, ranks=ranks)
