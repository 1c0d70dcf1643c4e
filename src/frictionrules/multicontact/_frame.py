r"""What every solver shares: the problem as kernel arrays, and the monitor of a run.

:class:`_Frame` holds the problem in its circular frame (see :mod:`.problem`) as the arrays
the Numba kernels take. :class:`_Monitor` records the error after each iteration, calls the
user's callback, and decides when a run stops and why (:data:`REASONS`).
"""

from __future__ import annotations

import math
import threading
import time

import numpy as np

from ..errors import FrictionRulesError, check_finite
from .problem import FrictionContactProblem

#: Why a run stopped (``Solution.reason``); only ``"converged"`` means converged.
REASONS = ("converged", "max_iter", "time_limit", "callback", "unbounded", "stalled")

#: A run whose reactions grow past ``UNBOUNDED`` times the scale |q| / mean|diag W| stops as
#: ``"unbounded"``: no bounded solution is being approached (an infeasible problem, where
#: Siconos' relative error can be pushed below any tolerance by letting |r| grow). On the
#: shared FCLIB files the solutions have |r| mean|diag W| / |q| between 0.03 and 45.
UNBOUNDED = 1e6

#: Errors over which :meth:`_Monitor.predicted` measures a stage's linear rate.
RATE_POINTS = 4

_CLOCK_LOCK = threading.Lock()
_COMPILING: dict[int, list] = {}    # thread id -> [nesting depth, start, seconds of finished compilations]


def compiling_seconds() -> float:
    """Seconds the calling thread has spent in finished Numba compilations (kind
    ``"numba:compile"`` of ``numba.core.event``: a compilation, not a load from the cache),
    counted from the first call of this function in the process. A time limit subtracts them,
    so that a first call's compiling (seconds to a minute on a busy machine) does not use up a
    run's budget."""
    if not _COMPILING:
        with _CLOCK_LOCK:
            if not _COMPILING:
                from numba.core import event

                class _Clock(event.Listener):
                    def on_start(self, ev):
                        c = _COMPILING.setdefault(threading.get_ident(), [0, 0.0, 0.0])
                        if c[0] == 0:
                            c[1] = time.perf_counter()
                        c[0] += 1

                    def on_end(self, ev):
                        c = _COMPILING.get(threading.get_ident())
                        if c is not None and c[0] > 0:
                            c[0] -= 1
                            if c[0] == 0:
                                c[2] += time.perf_counter() - c[1]

                event.register("numba:compile", _Clock())
                _COMPILING[-1] = [0, 0.0, 0.0]    # marks the clock as installed
    c = _COMPILING.get(threading.get_ident())
    return c[2] if c is not None else 0.0


def initial_reactions(r0, n: int) -> np.ndarray:
    """The argument ``r0`` of a solve with ``n`` unknowns, checked (finite, ``n`` entries), as
    an array of its own: a solver may write it, and a compiled call sees one type whether the
    caller's array is read-only or unaligned (each is another type to Numba)."""
    r = check_finite("r0", r0).ravel().astype(float)
    if r.size != n:
        raise FrictionRulesError(f"r0 has {r.size} entries; constraint: 3 nc = {n}")
    return r


def norm(x) -> float:
    """``np.linalg.norm`` of a 1-D float array, the same bits (NumPy takes ``sqrt(x.dot(x))``)
    without its checks (about 10 us a call, 0.3 ms of a 13 ms ADMM solve of KaplasTower)."""
    return math.sqrt(x.dot(x))


class _Frame:
    """The problem in its circular frame, as arrays the kernels take.

    ``cache`` holds what a solver derives from the problem alone and another stage of the
    same call may use again (ADMM's largest eigenvalue and factorizations of
    :math:`W + cI`); it lives as long as the frame, one call of :func:`solve`.
    """

    def __init__(self, problem: FrictionContactProblem):
        Wt, qt, P = problem._solver_frame()
        self.W, self.q, self.P = Wt, np.ascontiguousarray(qt, dtype=float), P
        self.mu = np.ascontiguousarray(problem.mu_bar, dtype=float)
        self.d = np.ascontiguousarray(problem.dilatancy, dtype=float)
        self.nc = problem.nc
        self.norm_q = float(np.linalg.norm(self.q))
        # W's own index arrays when they are int32 already (SciPy's usual): a copy of the
        # indices of KaplasTower was 0.47 MB of fresh memory a solve, 114 page faults of
        # about 2.3 us each on the benchmark machine
        self.csr = (self.W.indptr.astype(np.int32, copy=False), self.W.indices.astype(np.int32, copy=False),
                    self.W.data)
        diag = np.abs(self.W.diagonal())
        self.mean_diag = float(np.mean(diag[diag > 0])) if np.any(diag > 0) else 1.0
        self.r_bound = UNBOUNDED * max(self.norm_q, np.finfo(float).tiny) / self.mean_diag
        self.cache: dict = {}

    def error(self, r, u=None) -> float:
        """Siconos' error of ``r`` (``u = W r + q`` when not given): see :mod:`.error`."""
        from . import _kernels as K
        u = self.W @ r + self.q if u is None else u
        e = np.sqrt(K.error_sum(r, u, self.mu, self.d))
        scale = max(self.norm_q, norm(r), norm(u))
        return e / scale if scale > np.finfo(float).eps else e

    def rho(self, W=None):
        r"""Per-contact Alart–Curnier weights :math:`\rho_a = 3/\mathrm{tr}\,W_{aa}`."""
        from . import _kernels as K
        W = self.W if W is None else W
        D = K.diagonal_blocks(W.indptr.astype(np.int32), W.indices.astype(np.int32), W.data, self.nc)
        tr = np.abs(np.trace(D, axis1=1, axis2=2)) / 3.0
        return np.where(tr > 0, 1.0 / np.where(tr > 0, tr, 1.0), 1.0)


class _Monitor:
    """Error history, callback, time limit and the stop decision of one run.

    ``record(method, iteration, r, err)`` is called by a solver after each iteration (NSGS:
    after each sweep where it evaluated the error); it returns True when the run must stop,
    with ``reason`` set. The caller checks ``err <= tol`` and ``max_iter`` itself.

    ``handover = (level, more)`` (set by ``"auto"`` for one stage) also stops the run, with
    the internal reason ``"handover"``, once the error is below ``level`` and the linear rate
    of the stage's last :data:`RATE_POINTS` errors predicts more than ``more`` iterations to
    ``tol``: the next stage is expected to finish sooner.
    """

    def __init__(self, fr: _Frame, tol: float, time_limit, callback):
        self.fr, self.tol, self.time_limit, self.callback = fr, tol, time_limit, callback
        self.t0 = time.perf_counter()
        self.c0 = compiling_seconds() if time_limit is not None else 0.0
        self.errors: list[float] = []
        self.iterations: list[int] = []
        self.offset = 0          # iterations of the earlier stages of a chained run
        self.reason = ""
        self.handover = None

    def elapsed(self) -> float:
        return time.perf_counter() - self.t0

    def out_of_time(self) -> bool:
        """Past ``time_limit``: wall seconds since the start, less those spent compiling kernels."""
        return (self.time_limit is not None
                and self.elapsed() - (compiling_seconds() - self.c0) >= self.time_limit)

    def record(self, method: str, iteration: int, r, err: float) -> bool:
        self.errors.append(float(err))
        self.iterations.append(self.offset + int(iteration))
        stop = False
        if self.callback is not None:
            from ._options import IterationInfo
            stop = bool(self.callback(IterationInfo(method, self.offset + int(iteration), float(err),
                                                    self.elapsed())))
        if err <= self.tol:
            self.reason = "converged"
        elif not np.isfinite(err) or norm(r) > self.fr.r_bound:
            self.reason = "unbounded"
        elif stop:
            self.reason = "callback"
        elif self.out_of_time():
            self.reason = "time_limit"
        elif self.handover is not None and err <= self.handover[0] and self.predicted() > self.handover[1]:
            self.reason = "handover"
        return bool(self.reason)

    def record_many(self, method: str, iterations, r, errors) -> bool:
        """:meth:`record` for iterations run in compiled code (``r``: the last one's
        reactions), where no callback nor handover is set: the stop is decided at the last
        (the compiled loop stops itself at convergence and unboundedness; a time limit is
        noticed at the end of the batch)."""
        self.errors.extend(float(e) for e in errors[:-1])
        self.iterations.extend(self.offset + int(k) for k in iterations[:-1])
        return self.record(method, int(iterations[-1]), r, float(errors[-1]))

    def predicted(self) -> float:
        """Iterations still needed to ``tol`` at the linear rate of the current stage's last
        :data:`RATE_POINTS` errors (inf when they do not fall; 0 with fewer points)."""
        e, k = self.errors[-RATE_POINTS:], self.iterations[-RATE_POINTS:]
        if len(e) < RATE_POINTS or k[0] <= self.offset:
            return 0.0
        if not 0.0 < e[-1] < e[0]:
            return np.inf
        return float(np.log(self.tol / e[-1]) / (np.log(e[-1] / e[0]) / (k[-1] - k[0])))
