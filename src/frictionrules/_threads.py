"""Numba's threading layer for the processes that run the dynamic engine on their own."""

from __future__ import annotations

import os

__all__ = ["prefer_openmp"]

#: Numba's layers, the spinning one first.
_PRIORITY = ["omp", "tbb", "workqueue"]


def prefer_openmp() -> None:
    """Put Numba's OpenMP threading layer first, unless the process has already chosen one.

    A step of the dynamic engine has two parallel passes (contacts, then grains), so its
    threads meet twice a step. OpenMP's threads spin between the passes; TBB's and the
    workqueue's go to sleep, and waking a virtual CPU costs about 0.1 ms each time. Measured on
    a 2-vCPU virtual machine (10,800 spheres in shear, 2 threads, 2,000 steps, three runs per
    layer): OpenMP 1.58–1.74 ms per step, TBB 1.85–2.19 ms, the workqueue 2.14 ms; 10,000
    spheres to 25 % axial strain: 12.6 min against 12.8 min under TBB (13.9 against 14.6
    while frictionless stages still computed their tangential kinematics). Numba's
    default order puts TBB first wherever ``libtbb`` is installed. The numbers of a run do not
    depend on the layer (the engine's chunks are fixed by the sizes alone).

    GNU OpenMP does not survive ``fork()``: a child of a process that has run OpenMP threads
    is terminated. So only entry points that own their process and do not fork call this:
    the ``assembly`` command and the benchmarks. A library call never changes the layer.

    Nothing happens where ``NUMBA_THREADING_LAYER`` or ``NUMBA_THREADING_LAYER_PRIORITY`` is
    set, or where parallel code has already run (the layer is fixed at the first launch).
    Where OpenMP cannot be loaded, Numba goes on to the next layer.
    """
    if os.environ.get("NUMBA_THREADING_LAYER") or os.environ.get("NUMBA_THREADING_LAYER_PRIORITY"):
        return
    import numba

    try:
        numba.threading_layer()
    except ValueError:  # not launched yet: the choice is still open
        numba.config.THREADING_LAYER_PRIORITY = list(_PRIORITY)
