"""Many independent tasks on any executor: in this process, a ``concurrent.futures`` pool, or
Dask (a local cluster or a cluster's scheduler). :func:`~frictionrules.solve_many` and
:func:`sweep` take the same ``executor`` argument."""

from ._executors import SweepPoint, dask_client, local_cluster, run_tasks, sweep

__all__ = ["sweep", "SweepPoint", "local_cluster", "dask_client", "run_tasks"]
