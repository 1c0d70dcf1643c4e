"""``solve_many``: many frictional contact problems (FCLIB files or problem objects) on any
executor, written as they arrive, resumable.

It sits above the file layer (:mod:`frictionrules.io`) and the solvers
(:mod:`frictionrules.multicontact`). Each problem is solved by :func:`~frictionrules.solve`
with the same arguments, wherever it runs (one BLAS thread), so the answers are those of the
serial loop. Small problems are batched: a task holds problems until their FCLIB files (or W's
nonzeros, 12 bytes each) reach ``batch_bytes``, so that a Dask task's overhead (7–9 ms
measured on 2 cores) stays small against its work. With ``out=`` a CSV table is rewritten
atomically after every finished task, and a rerun with the same parameters skips the problems
it already lists.

Times: each record carries the solve's wall and CPU time (:class:`~frictionrules.Solution`);
the start-up of a task's process (loading the compiled kernels, the first time a process
solves) is done before the first problem is timed and reported apart, as the record's
``startup_seconds``.
"""

from __future__ import annotations

import csv
import dataclasses
import functools
import io
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .errors import FrictionRulesError, check_scalar
from .io import read_fclib, read_guess, read_solution, write_solution
from .multicontact import METHODS, SMALL_MAX, SMALL_MODES, FrictionContactProblem, Solution, solve, solve_batch

__all__ = ["solve_many", "SolveRecord", "CSV_HEADER", "read_table"]

#: Columns of the table ``solve_many(..., out=)`` and ``frictionrules solve --csv`` write:
#: ``method`` is the method that ran (``nsgs+prox``), ``requested`` the one asked for; ``tol``,
#: ``max_iter``, ``time_limit`` and ``warm_start`` are the parameters that decided the row.
CSV_HEADER = ("file", "contacts", "method", "iterations", "error", "converged", "reason", "seconds",
              "cpu_seconds", "requested", "tol", "max_iter", "time_limit", "warm_start")

#: Units of the table's columns (``docs/conventions.md``).
CSV_UNITS = {"file": "-", "contacts": "1", "method": "-", "iterations": "1", "error": "1",
             "converged": "1", "reason": "-", "seconds": "s", "cpu_seconds": "s", "requested": "-",
             "tol": "1", "max_iter": "1", "time_limit": "s", "warm_start": "-"}

#: Problems are batched into one task until their size reaches this many bytes (FCLIB file size,
#: or 12 bytes per nonzero of W): CubeH8 (66 kB) solves in 5 ms, KaplasTower (1.4 MB) in 0.1 s.
BATCH_BYTES = 1_000_000


@dataclass(frozen=True)
class SolveRecord:
    """The outcome of one problem of :func:`solve_many`.

    Attributes
    ----------
    name : str
        The file's name, or ``problem[i]`` (its title when it has one) for a problem object.
    contacts : int
        Number of contacts (0 when the file could not be read).
    method : str
        The method that ran (``Solution.method``: ``"nsgs+prox"`` for ``"auto"``); the
        requested one when nothing ran.
    solution : Solution or None
        None when the file could not be read (see ``message``) or the record was read back
        from an earlier run's table (``resumed``).
    message : str
        Why the file could not be read, else empty.
    resumed : bool
        Taken from the table of an earlier run instead of solved again.
    iterations, error, converged, reason, seconds, cpu_seconds
        As in :class:`Solution` (from the table when resumed); ``error`` is None for a file
        that could not be read, ``reason`` is then ``"bad input"``.
    requested : str
        The ``method`` argument.
    startup_seconds : float
        Wall time the task's process spent starting up (loading the compiled kernels, or
        compiling them where Numba's cache does not hold them yet) before this problem; not
        part of ``seconds`` nor of the time limit. Non-zero only for the first problem of a
        task that needed kernels its process had not loaded yet (only the solver paths the
        task's problems take are loaded).
    """

    name: str
    contacts: int
    method: str
    iterations: int
    error: float | None
    converged: bool
    reason: str
    seconds: float
    solution: Solution | None = None
    message: str = ""
    resumed: bool = False
    requested: str = ""
    cpu_seconds: float = 0.0
    startup_seconds: float = 0.0

    def csv_row(self, parameters) -> tuple:
        err = "" if self.error is None else f"{self.error:.6e}"
        return (self.name, str(self.contacts), self.method, str(self.iterations), err,
                str(int(self.converged)), self.reason, f"{self.seconds:.6f}", f"{self.cpu_seconds:.6f}",
                *parameters)


def _name(item, index: int) -> str:
    if isinstance(item, FrictionContactProblem):
        return item.title or f"problem[{index}]"
    return Path(item).name


def _weight(item) -> int:
    if isinstance(item, FrictionContactProblem):
        return 12 * item.W.nnz
    try:
        return Path(item).stat().st_size
    except OSError:
        return 0


def _warm_start(item, name, source, n):
    """``r0`` for one problem: the file's guess (``source == "guess"``), a saved solution
    (a file, or a folder holding ``<name>``), or None."""
    if source is None:
        return None
    if source == "guess":
        return None if isinstance(item, FrictionContactProblem) else read_guess(item)
    path = Path(source)
    if path.is_dir():
        path = path / name
        if not path.is_file():
            return None
    return read_solution(path, size=n)


#: The paths :func:`_start_up` loads: the compiled batch of small problems
#: (:func:`~frictionrules.solve_batch`), one small problem (:func:`~frictionrules.solve`
#: without time limit or callback) and the general path (a larger problem, or any problem with
#: a time limit or a callback).
PATHS = ("small batch", "small", "general")


def _start_up(method: str, path: str) -> float:
    """Load (on a first run: compile) what ``method`` needs on ``path`` (:data:`PATHS`); its
    wall time. Called once per process and pair (:data:`_started`), for the paths a task's
    problems take: a one-contact file compiles the small path alone, not the solvers of large
    problems."""
    t0 = time.perf_counter()
    nc = 1 if path != "general" else SMALL_MAX + 1
    W = np.eye(3 * nc) + 0.1
    problem = FrictionContactProblem(W, np.tile([-1.0, 0.5, 0.1], nc), [0.5] * nc)
    if path == "small batch":
        solve_batch([problem], method=method, max_iter=3)
    else:
        solve(problem, method=method, max_iter=3)
    return time.perf_counter() - t0


def _paths(problems, method: str, plain: bool, direct) -> list[str]:
    """The :data:`PATHS` that ``problems`` take: the small ones (:func:`~frictionrules.solve`'s
    rule) the compiled batch when ``plain``, else the small path where ``direct[k]`` (no time
    limit, no callback); the others the general path. (A problem that ``auto`` leaves
    unconverged on the small path goes on with the general path, loaded when it does.)"""
    small = [p.nc <= SMALL_MAX and p.frames is None and method in SMALL_MODES and (plain or d)
             for p, d in zip(problems, direct)]
    paths = [PATHS[0] if plain else PATHS[1]] if any(small) else []
    return paths + ([PATHS[2]] if not all(small) else [])


def _read(job):
    """``(problem, r0)`` of one job, or the record of a file that cannot be read."""
    item, name, kwargs, warm, _callback = job
    method = kwargs["method"]
    try:
        problem = item if isinstance(item, FrictionContactProblem) else read_fclib(item)
        return problem, _warm_start(item, name, warm, 3 * problem.nc)
    except (FrictionRulesError, OSError) as exc:
        return SolveRecord(name, 0, method, 0, None, False, "bad input", 0.0, requested=method,
                           message=str(exc).splitlines()[0] if str(exc) else type(exc).__name__), None


def _record(name, problem, s, method, startup) -> SolveRecord:
    return SolveRecord(name, problem.nc, s.method, s.iterations, s.error, s.converged, s.reason, s.seconds,
                       solution=s, requested=method, cpu_seconds=s.cpu_seconds, startup_seconds=startup)


#: ``(method, path)`` pairs this process has started.
_started: set = set()


def _solve_batch(jobs) -> list[SolveRecord]:
    """The problems of one task, after the process's start-up (timed apart). Without warm
    starts, callbacks and time limits they go through :func:`~frictionrules.solve_batch` (the
    small ones in one compiled call), else one :func:`~frictionrules.solve` each."""
    kwargs = jobs[0][2]
    read = [_read(job) for job in jobs]
    out: list = [p if isinstance(p, SolveRecord) else None for p, _r0 in read]
    todo = [k for k, rec in enumerate(out) if rec is None]
    plain = kwargs["time_limit"] is None and all(read[k][1] is None and jobs[k][4] is None for k in todo)
    direct = [kwargs["time_limit"] is None and jobs[k][4] is None for k in todo]
    paths = _paths([read[k][0] for k in todo], kwargs["method"], plain, direct)
    new = [path for path in paths if (kwargs["method"], path) not in _started]
    startup = sum(_start_up(kwargs["method"], path) for path in new)
    _started.update((kwargs["method"], path) for path in new)
    fresh = bool(new)
    if plain:
        solutions = solve_batch([read[k][0] for k in todo], kwargs["method"], kwargs["tol"], kwargs["max_iter"])
    else:
        solutions = [solve(read[k][0], r0=read[k][1], **kwargs,
                           callback=None if jobs[k][4] is None else functools.partial(_named, jobs[k][4], jobs[k][1]))
                     for k in todo]
    for k, s in zip(todo, solutions):
        out[k] = _record(jobs[k][1], read[k][0], s, kwargs["method"], 0.0)
    if fresh and out:
        out[0] = dataclasses.replace(out[0], startup_seconds=startup)
    return out


def _named(callback, name, info):
    return callback(name, info)


def _parameters(kwargs, warm_start) -> tuple:
    """The per-row parameter columns of the table (strings as written)."""
    def text(v):
        return "" if v is None else (f"{v:.6g}" if isinstance(v, float) else str(v))
    return (kwargs["method"], text(float(kwargs["tol"])), text(kwargs["max_iter"]), text(kwargs["time_limit"]),
            text(warm_start))


def read_table(path, parameters: tuple) -> dict[str, SolveRecord]:
    """Records of an earlier run's CSV table with the same ``parameters`` (the columns from
    ``requested`` on), by name (empty when absent)."""
    path = Path(path)
    if not path.is_file():
        return {}
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise FrictionRulesError(f"cannot read the earlier table {path}: {exc}") from exc
    rows = list(csv.reader(line for line in io.StringIO(text) if not line.startswith("#")))
    if not rows or tuple(rows[0]) != CSV_HEADER:
        raise FrictionRulesError(f"{path} is not a table of this command (header {rows[:1]}); "
                                 "constraint: remove it or name another file")
    done = {}
    first = CSV_HEADER.index("requested")
    for row in rows[1:]:
        if len(row) != len(CSV_HEADER) or tuple(row[first:]) != parameters or row[6] == "bad input":
            continue                        # other parameters, or a file to try again
        try:
            err = float(row[4]) if row[4] else None
            done[row[0]] = SolveRecord(row[0], int(row[1]), row[2], int(row[3]), err, row[5] == "1",
                                       row[6], float(row[7]), resumed=True, requested=row[first],
                                       cpu_seconds=float(row[8]))
        except ValueError:
            continue
    return done


def _executor_text(executor) -> str:
    if executor is None:
        return "serial (this process)"
    workers = getattr(executor, "_max_workers", None)
    if workers is None and hasattr(executor, "scheduler_info"):
        try:
            workers = len(executor.scheduler_info().get("workers", {}))
        except Exception:                   # a closed client: the table still gets written
            workers = None
    return type(executor).__name__ + (f" ({workers} workers)" if workers else "")


def _write_table(path, records, parameters, metadata) -> None:
    from ._output import write_table
    rows = [rec.csv_row(parameters) for rec in records]
    columns = {name: [row[k] for row in rows] for k, name in enumerate(CSV_HEADER)}
    write_table(path, columns, units=CSV_UNITS, metadata=metadata)


def _batches(jobs, weights, batch_bytes):
    batches, current, size = [], [], 0
    for job, w in zip(jobs, weights):
        if current and size + w > batch_bytes:
            batches.append(current)
            current, size = [], 0
        current.append(job)
        size += w
    if current:
        batches.append(current)
    return batches


def _items(paths_or_problems) -> list:
    if isinstance(paths_or_problems, (str, Path)) and Path(paths_or_problems).is_dir():
        items = sorted(Path(paths_or_problems).glob("*.hdf5"))
        if not items:
            raise FrictionRulesError(f"folder {paths_or_problems} holds no *.hdf5 file")
    elif isinstance(paths_or_problems, (str, Path, FrictionContactProblem)):
        items = [paths_or_problems]
    else:
        items = list(paths_or_problems)
    for i, item in enumerate(items):
        if not isinstance(item, (str, Path, FrictionContactProblem)):
            raise FrictionRulesError(f"paths_or_problems[{i}] = {item!r}; constraint: a path or a "
                                     "FrictionContactProblem")
    return items


def solve_many(paths_or_problems, method: str = "auto", tol: float = 1e-8, max_iter: int | None = None,
               *, executor=None, time_limit: float | None = None, warm_start=None, out=None,
               save_solutions=None, batch_bytes: int = BATCH_BYTES, on_result=None,
               callback=None, metadata=None) -> list[SolveRecord]:
    """Solve many problems (FCLIB files or :class:`FrictionContactProblem` objects).

    Parameters
    ----------
    paths_or_problems : path, or sequence of paths and problems
        A folder stands for its ``*.hdf5`` files (sorted by name).
    method, tol, max_iter, time_limit
        As in :func:`~frictionrules.solve`, for every problem (``time_limit`` per problem).
    executor : None, concurrent.futures.Executor or distributed.Client
        Where the tasks run (None: in this process, in order). See
        :mod:`frictionrules.parallel` for a local Dask cluster or a cluster's scheduler.
    warm_start : None, "guess", or a path
        Initial reactions: an FCLIB file's ``/guesses/1/r``, or a saved solution (a file, or
        a folder of files named like the problems, as ``save_solutions`` writes them).
    out : path, optional
        CSV table (columns :data:`CSV_HEADER`) rewritten atomically after every task; when it
        exists, the problems it lists with the same parameters (method asked, tol, max_iter,
        time_limit, warm_start) are not solved again.
    save_solutions : path, optional
        Folder receiving each solution as ``<name>`` (HDF5, :func:`frictionrules.io.write_solution`)
        as it arrives.
    batch_bytes : int
        Problems are grouped into one task up to this size (see :data:`BATCH_BYTES`).
    on_result : callable, optional
        ``on_result(record)`` in this process as each record arrives (progress).
    callback : callable, optional
        ``callback(name, info)`` after every iteration of every problem (``info`` as in
        :func:`~frictionrules.solve`; a true return stops that problem); only without an
        executor, where the problems run in this process.
    metadata : mapping, optional
        More provenance for the table's comment lines (the CLI's command line).

    Returns
    -------
    list of SolveRecord
        In the order of the input, whatever the order of completion.
    """
    from ._output import provenance
    from .parallel import run_tasks
    items = _items(paths_or_problems)
    if not isinstance(method, str) or method not in METHODS:
        raise FrictionRulesError(f"method = {method!r}; constraint: one of {sorted(METHODS)}")
    batch_bytes = check_scalar("batch_bytes", batch_bytes, lo=0.0)
    if callback is not None and executor is not None:
        raise FrictionRulesError("callback: constraint: only without an executor (it runs here)")
    if warm_start is not None and warm_start != "guess" and not Path(warm_start).exists():
        raise FrictionRulesError(f"warm_start = {str(warm_start)!r}: no such file or folder; "
                                 "constraint: 'guess' or a saved solution")
    names = [_name(item, i) for i, item in enumerate(items)]
    if len(set(names)) != len(names):
        names = [f"{n}#{i}" for i, n in enumerate(names)]
    kwargs = {"method": method, "tol": tol, "max_iter": max_iter, "time_limit": time_limit}
    parameters = _parameters(kwargs, warm_start)
    done = read_table(out, parameters) if out is not None else {}
    meta = provenance(model="frictionrules.solve_many",
                      parameters={"method": method, "tol": tol, "max_iter": max_iter, "time_limit": time_limit,
                                  "warm_start": warm_start, "executor": _executor_text(executor),
                                  "batch_bytes": batch_bytes},
                      times="seconds: wall, cpu_seconds: CPU of the solving thread; process start-up excluded",
                      **dict(metadata or {}))
    if save_solutions is not None:
        Path(save_solutions).mkdir(parents=True, exist_ok=True)
    records: list[SolveRecord | None] = [done.get(n) for n in names]
    todo = [i for i, rec in enumerate(records) if rec is None]
    jobs = [(items[i], names[i], kwargs, warm_start, callback) for i in todo]
    batches = _batches(list(zip(todo, jobs)), [_weight(items[i]) for i in todo], batch_bytes)
    if not batches:
        return records
    tasks = [[job for _, job in batch] for batch in batches]
    for b, result in run_tasks(_solve_batch, tasks, executor):
        for (i, _job), rec in zip(batches[b], result):
            records[i] = rec
            if save_solutions is not None and rec.solution is not None:
                write_solution(Path(save_solutions) / rec.name, rec.solution, source=rec.name, tol=tol)
            if on_result is not None:
                on_result(rec)
        if out is not None:
            _write_table(out, [rec for rec in records if rec is not None], parameters, meta)
    return records
