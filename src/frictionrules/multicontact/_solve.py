r"""``solve(problem, method=...)``: the solvers of :class:`~frictionrules.FrictionContactProblem`.

* ``"nsgs"`` — non-smooth Gauss–Seidel over the contacts with an exact local solver
  (:mod:`._nsgs`); a sweep costs O(nnz(W)).
* ``"newton"`` — semismooth Newton on the Alart–Curnier function (:mod:`._newton`).
* ``"prox"`` — proximal point with an inner semismooth Newton (:mod:`._prox`).
* ``"admm"`` — ADMM with De Saxcé's correction, adaptive penalty and Anderson acceleration
  (:mod:`._admm`); the factorization of :math:`W + \rho I` is kept while :math:`\rho` is.
* ``"auto"`` — a choice from the problem's size and structure (:func:`auto_plan`).

Every method stops when Siconos' error (:func:`.error.fc3d_error`) is at most ``tol``, at
``max_iter``, at ``time_limit``, when the callback asks, or when the reactions grow without
bound; :attr:`Solution.reason` says which. BLAS runs on ``blas_threads`` threads inside the
solver (threadpoolctl): with other jobs on the machine, threaded BLAS made the dense-LU path
10–30 times slower on small problems.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from ..errors import FrictionRulesError, check_finite, check_scalar
from ._admm import run_admm
from ._frame import _Frame, _Monitor
from ._newton import run_newton
from ._nsgs import run_nsgs
from ._options import options_for
from ._prox import run_prox
from .problem import FrictionContactProblem, Solution

__all__ = ["solve", "METHODS"]

#: Method names accepted by :func:`solve`, with their default ``max_iter`` (for ``"auto"``,
#: the iterations of all its stages together).
METHODS = {"auto": 100000, "nsgs": 100000, "newton": 200, "prox": 200, "admm": 5000}

_RUN = {"nsgs": run_nsgs, "newton": run_newton, "prox": run_prox, "admm": run_admm}


@dataclass(frozen=True)
class _Stage:
    """One stage of ``"auto"``: ``method`` until ``tol`` (the caller's when None) or
    ``max_iter``, from the last stage's answer or, with ``restart``, from the initial one."""

    method: str
    tol: float | None
    max_iter: int
    restart: bool = False


#: ``"auto"`` (docs/multicontact.md, "Choosing a method", has the measurements): first at most
#: ``_AUTO_PROBE`` NSGS sweeps (they cost O(nnz(W)) each and solve the easy problems: CubeH8,
#: the LMGC cube, PerioBox and Box_Stacks in 1-34 sweeps); then, up to ``_AUTO_PROX_MAX``
#: contacts, prox from the initial reactions (the one method that reached 1e-8 on every shared
#: file of up to 570 contacts, fastest or within 2.5 times the fastest on each; started from
#: the probe's answer instead it did not reach 1e-4 in 30 s on Capsules and spheres-in-a-box,
#: its proximal schedule being tuned for a start from zero); beyond, NSGS goes on (on
#: the piles of 1,264-1,812 contacts prox and newton did not reach 1e-4 within 60 s, ADMM
#: reached 7e-4, NSGS 1e-4 in 3,000 sweeps).
_AUTO_PROBE, _AUTO_PROX_MAX = 50, 1000


def auto_plan(fr: _Frame, tol: float) -> tuple[_Stage, ...]:
    """The stages ``"auto"`` runs on a problem (see the module constants)."""
    probe = _Stage("nsgs", None, _AUTO_PROBE)
    if fr.nc <= _AUTO_PROX_MAX:
        return (probe, _Stage("prox", None, METHODS["prox"], restart=True))
    return (probe, _Stage("nsgs", None, METHODS["nsgs"]))


def _initial(problem, fr: _Frame, r0):
    n = 3 * problem.nc
    if r0 is None:
        return np.zeros(n)
    r = check_finite("r0", r0).ravel().astype(float)
    if r.size != n:
        raise FrictionRulesError(f"r0 has {r.size} entries; constraint: 3 nc = {n}")
    if fr.P is not None:
        import scipy.sparse.linalg as spla
        r = spla.spsolve(fr.P.tocsc(), r)
    return np.ascontiguousarray(r)


@functools.lru_cache(maxsize=1)
def _blas_controller():
    """threadpoolctl's view of the loaded BLAS libraries, found once per process (a fresh
    ``threadpool_limits`` scans every loaded library: 14 ms a call, measured on 2 busy cores)."""
    from .._optional import require
    return require("threadpoolctl", extra="solvers").ThreadpoolController().select(user_api="blas")


def _blas_limits(threads):
    """A context limiting BLAS to ``threads`` threads (None, or BLAS already within: nothing)."""
    import contextlib
    if threads is None:
        return contextlib.nullcontext()
    blas = _blas_controller()
    if all(lib["num_threads"] <= threads for lib in blas.info()):
        return contextlib.nullcontext()
    return blas.limit(limits=threads)


def solve(problem: FrictionContactProblem, method: str = "auto", tol: float = 1e-8,
          max_iter: int | None = None, r0=None, *, options=None, callback=None,
          time_limit: float | None = None, blas_threads: int | None = 1) -> Solution:
    r"""Solve a frictional contact problem; the error is Siconos' (see :mod:`.error`).

    Parameters
    ----------
    problem : FrictionContactProblem
    method : {"auto", "nsgs", "newton", "prox", "admm"}
        See the module docstring; ``"auto"`` chooses from the problem's size and structure.
    tol : float
        Stop when :func:`~frictionrules.multicontact.fc3d_error` ``<= tol``.
    max_iter : int, optional
        Sweeps (nsgs), Newton iterations (newton), outer proximal iterations (prox), ADMM
        iterations (admm), all stages together (auto); defaults ``METHODS[method]``.
    r0 : (3 nc,) array, optional
        Initial reactions (zero by default), e.g. a previous solution or an FCLIB file's guess.
    options : NSGSOptions, NewtonOptions, ProxOptions or ADMMOptions, optional
        The schedule of ``method`` (its defaults when omitted; not with ``"auto"``).
    callback : callable, optional
        ``callback(info)`` with an :class:`~frictionrules.IterationInfo` after every iteration
        (nsgs: after every sweep where it evaluates the error, at least every
        ``NSGSOptions.chunk_seconds``); a true return stops the run (reason ``"callback"``).
    time_limit : float, optional
        Wall-clock seconds; the run stops after the iteration that passes it (reason
        ``"time_limit"``).
    blas_threads : int or None
        BLAS threads inside the solver (threadpoolctl); None leaves BLAS as it is.

    Returns
    -------
    Solution
        ``converged`` is ``error <= tol`` with bounded reactions; ``reason`` says why the run
        stopped; ``history[k]`` the error after iteration ``history_iterations[k]``.
    """
    import time
    if not isinstance(problem, FrictionContactProblem):
        raise FrictionRulesError(f"problem = {problem!r} is not a FrictionContactProblem")
    if method not in METHODS:
        raise FrictionRulesError(f"method = {method!r}; constraint: one of {sorted(METHODS)}")
    tol = check_scalar("tol", tol, lo=0.0)
    max_iter = METHODS[method] if max_iter is None else int(check_scalar("max_iter", max_iter, lo=1))
    if time_limit is not None:
        time_limit = check_scalar("time_limit", time_limit, lo=0.0, lo_open=True)
    if blas_threads is not None:
        blas_threads = int(check_scalar("blas_threads", blas_threads, lo=1))
    if callback is not None and not callable(callback):
        raise FrictionRulesError(f"callback = {callback!r} is not callable")
    if method == "auto" and options is not None:
        raise FrictionRulesError("options: constraint: none with method = 'auto' (name a method)")
    opts = None if method == "auto" else options_for(method, options)
    fr = _Frame(problem)
    r = _initial(problem, fr, r0)
    t0 = time.perf_counter()
    with _blas_limits(blas_threads):
        mon = _Monitor(fr, tol, time_limit, callback)
        if method == "auto":
            r, it, ran = _run_auto(fr, r, tol, max_iter, mon)
        else:
            r, it = _run(method, fr, r, max_iter, mon, opts)
            ran = method
    seconds = time.perf_counter() - t0
    r = r if fr.P is None else fr.P @ r
    u = problem.velocity(r)
    from .error import fc3d_error
    err = fc3d_error(problem, r, u)
    bounded = bool(np.linalg.norm(r) <= fr.r_bound)
    reason = mon.reason or "max_iter"
    if err <= tol and bounded:
        reason = "converged"
    elif reason == "converged":  # the monitor saw tol in the solver frame but not here
        reason = "max_iter" if bounded else "unbounded"
    return Solution(r=r, u=u, error=err, iterations=int(it), converged=reason == "converged",
                    history=np.array(mon.errors), history_iterations=np.array(mon.iterations, dtype=int),
                    method=ran, seconds=seconds, reason=reason)


def _run(method, fr, r, max_iter, mon, opts):
    if method == "nsgs":
        r = np.array(r, dtype=float)
        return r, run_nsgs(fr, r, max_iter, mon, opts)
    if fr.error(r) <= mon.tol:
        mon.record(method, 0, r, fr.error(r))
        return r, 0
    return _RUN[method](fr, r, max_iter, mon, opts)


def _run_auto(fr, r, tol, max_iter, mon):
    """The stages of :func:`auto_plan`, each warm-started from the last; returns
    ``(r, iterations, "stage+stage")``."""
    total, ran, start = 0, [], r.copy()
    for stage in auto_plan(fr, tol):
        budget = min(stage.max_iter, max_iter - total)
        if budget <= 0:
            break
        mon.tol = tol if stage.tol is None else stage.tol
        mon.reason, mon.offset = "", total
        r, it = _run(stage.method, fr, start.copy() if stage.restart else r, budget, mon,
                     options_for(stage.method, None))
        total += it
        ran.append(stage.method)
        if mon.reason in ("time_limit", "callback", "unbounded") or (mon.reason == "converged" and mon.tol <= tol):
            break
    mon.tol = tol
    if mon.reason == "converged" and mon.errors and mon.errors[-1] > tol:
        mon.reason = "max_iter"
    return r, total, "+".join(ran)
