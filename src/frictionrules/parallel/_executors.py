"""Many independent tasks on any executor: serial, a ``concurrent.futures`` pool, or Dask.

``executor`` arguments across the package accept

* ``None`` — run in this process, in order;
* any :class:`concurrent.futures.Executor` (``ProcessPoolExecutor``, ``ThreadPoolExecutor``,
  MPI's ``MPIPoolExecutor``, ...);
* a ``distributed.Client`` (Dask; its ``get_executor()`` is used), e.g. on a local cluster
  (:func:`local_cluster`) or pointed at a cluster's scheduler (:func:`dask_client`), which
  dask-jobqueue starts on SLURM or PBS.

Results are identical to the serial run: each task runs the same function on the same input
with one BLAS thread. :func:`sweep` maps a function over a parameter grid.
"""

from __future__ import annotations

import contextlib
import itertools
from dataclasses import dataclass
from typing import Any, Callable, Iterable, Iterator, Mapping

from ..errors import FrictionRulesError

__all__ = ["sweep", "SweepPoint", "local_cluster", "dask_client"]

def _distributed():
    from .._optional import require
    return require("distributed", extra="dask", purpose="a Dask cluster")


@contextlib.contextmanager
def local_cluster(workers: int):
    """A Dask ``Client`` on a local cluster of ``workers`` processes, one thread each.

    Starting it takes 1–4 s; a task costs 7–9 ms of overhead (measured on 2 cores), which
    :func:`~frictionrules.solve_many` amortizes by batching small problems.
    """
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise FrictionRulesError(f"workers = {workers!r} violates: an integer >= 1")
    distributed = _distributed()
    cluster = distributed.LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                       dashboard_address=None, silence_logs=40)
    try:
        with distributed.Client(cluster) as client:
            yield client
    finally:
        cluster.close()


@contextlib.contextmanager
def dask_client(address: str):
    """A Dask ``Client`` connected to the scheduler at ``address`` (``tcp://host:8786``)."""
    distributed = _distributed()
    try:
        client = distributed.Client(address, timeout=10)
    except (OSError, TimeoutError, ValueError) as exc:
        raise FrictionRulesError(f"scheduler = {address!r}: cannot connect ({exc})") from exc
    try:
        yield client
    finally:
        client.close()


def _as_executor(executor):
    """A ``concurrent.futures.Executor`` (or None) from the accepted ``executor`` values."""
    import concurrent.futures as cf
    if executor is None or isinstance(executor, cf.Executor):
        return executor
    if hasattr(executor, "get_executor") and hasattr(executor, "submit"):  # distributed.Client
        return executor.get_executor()
    raise FrictionRulesError(f"executor = {executor!r}; constraint: None, a concurrent.futures."
                             "Executor or a distributed.Client")


def run_tasks(function: Callable, tasks: list, executor) -> Iterator[tuple[int, Any]]:
    """``(index, function(task))`` for every task: in order when ``executor`` is None,
    otherwise as they complete."""
    import concurrent.futures as cf
    ex = _as_executor(executor)
    if ex is None:
        for i, task in enumerate(tasks):
            yield i, function(task)
        return
    futures = {ex.submit(function, task): i for i, task in enumerate(tasks)}
    try:
        for future in cf.as_completed(futures):
            yield futures[future], future.result()
    finally:
        for future in futures:
            future.cancel()


@dataclass(frozen=True)
class SweepPoint:
    """One point of a :func:`sweep`: the parameters (by name) and the function's value."""

    parameters: Mapping[str, Any]
    value: Any


def _call(job):
    function, parameters = job
    return function(**parameters)


def sweep(function: Callable, parameter_grid, *, executor=None) -> list[SweepPoint]:
    """Evaluate ``function(**parameters)`` over a parameter grid, on any executor.

    Parameters
    ----------
    function : callable
        Called with the parameters as keyword arguments; it (and its value) must pickle to run
        on a process pool or a cluster (a module-level function, not a lambda).
    parameter_grid : mapping of name -> sequence, or iterable of mappings
        A mapping is expanded to its Cartesian product (the last name varies fastest); an
        iterable of mappings is taken point by point.
    executor : None, concurrent.futures.Executor or distributed.Client
        Where to run (see the module docstring); None runs in this process.

    Returns
    -------
    list of SweepPoint
        In the order of the grid, whatever the order of completion.
    """
    if not callable(function):
        raise FrictionRulesError(f"function = {function!r} is not callable")
    if isinstance(parameter_grid, Mapping):
        names = list(parameter_grid)
        for name in names:
            if not isinstance(name, str):
                raise FrictionRulesError(f"parameter_grid key {name!r} is not a parameter name")
        try:
            values = [list(parameter_grid[name]) for name in names]
        except TypeError as exc:
            raise FrictionRulesError(f"parameter_grid: constraint: each value a sequence ({exc})") from exc
        points = [dict(zip(names, combo)) for combo in itertools.product(*values)]
    elif isinstance(parameter_grid, Iterable) and not isinstance(parameter_grid, (str, bytes)):
        points = [dict(p) if isinstance(p, Mapping) else None for p in parameter_grid]
        if any(p is None for p in points):
            raise FrictionRulesError("parameter_grid: constraint: a mapping of sequences or an "
                                     "iterable of mappings")
    else:
        raise FrictionRulesError(f"parameter_grid = {parameter_grid!r}; constraint: a mapping of "
                                 "sequences or an iterable of mappings")
    results = [None] * len(points)
    for i, value in run_tasks(_call, [(function, p) for p in points], executor):
        results[i] = value
    return [SweepPoint(p, v) for p, v in zip(points, results)]
