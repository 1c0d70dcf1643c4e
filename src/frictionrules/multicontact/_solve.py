r"""``solve(problem, method=...)``: the solvers of :class:`~frictionrules.FrictionContactProblem`.

The methods and their defaults are one table (:data:`._methods.METHODS`):

* ``"nsgs"`` — non-smooth Gauss–Seidel over the contacts with an exact local solver
  (:mod:`._nsgs`); a sweep costs O(nnz(W)).
* ``"newton"`` — semismooth Newton on the Alart–Curnier function (:mod:`._newton`).
* ``"prox"`` — proximal point with an inner semismooth Newton (:mod:`._prox`).
* ``"admm"`` — ADMM with De Saxcé's correction, adaptive penalty and Anderson acceleration
  (:mod:`._admm`); the factorization of :math:`W + \rho I` is kept while :math:`\rho` is.
* ``"polish"`` — semismooth Newton on the natural map from a settled active set (:mod:`._polish`).
* ``"auto"`` — first-order stages chosen from the problem's size, then the polish
  (:func:`_run_auto`).

Every method stops when Siconos' error (:func:`.error.fc3d_error`) is at most ``tol``, at
``max_iter``, at ``time_limit``, when the callback asks, or when the reactions grow without
bound; :attr:`Solution.reason` says which. The whole call, from the problem's frame to the
final error, runs with BLAS and OpenMP limited to ``blas_threads`` threads (threadpoolctl):
with other jobs on the machine, threaded BLAS made the dense-LU path 10–30 times slower on
small problems and its times meaningless. Problems of at most :data:`._small.SMALL_MAX`
contacts solved by ``nsgs``, ``polish`` or ``auto`` take the compiled small-problem path
(:mod:`._small`).

A problem on the law path (``problem.path == "law"``: a law that is not an elliptic cone, e.g.
:class:`~frictionrules.TransformedCoulomb`) is dispatched once, before any of this, to
:mod:`._law_path` (``"nsgs"``, ``"polish"``; ``"auto"`` alternates them; the other methods are
refused), whose error is the laws' natural map (:func:`.law_error`).
"""

from __future__ import annotations

import functools
import time

import numpy as np

from ..errors import FrictionRulesError, check_scalar
from ._frame import _Frame, _Monitor, initial_reactions
from ._admm import all_stick
from ._methods import METHODS, check_method, options_for
from .problem import FrictionContactProblem, Solution

__all__ = ["solve", "solve_batch", "METHODS"]

#: ``"auto"`` (docs/multicontact.md, "Choosing a method", has the measurements): first
#: ``_AUTO_PROBE_FIRST`` NSGS sweeps, and more (up to ``_AUTO_PROBE`` in all) when their linear
#: rate predicts the tolerance within them (sweeps cost O(nnz(W)) each and solve the easy
#: problems: CubeH8, the LMGC cube, PerioBox and Box_Stacks in 1-34 sweeps). Then, up to ``_AUTO_PROX_MAX``
#: contacts, ADMM from the probe's answer to each error of ``_AUTO_ADMM_LEVELS`` (at most ``_AUTO_ADMM_BUDGET``
#: iterations in all), the polish after each: from an ADMM iterate at 1e-4-1e-6 one to three
#: Newton steps reach 1e-15 on KaplasTower, Spheres, Box_Stacks and local_problem_test. Where
#: the polish stalls (PerioBox, Capsules, spheres-in-a-box: the active set has not settled),
#: prox from the initial reactions (the one method that reached 1e-8 on every shared file of
#: up to 570 contacts; started from another answer its proximal schedule, tuned for a start
#: from zero, did not reach 1e-4 in 30 s on Capsules and spheres-in-a-box), and the polish.
#: Beyond ``_AUTO_PROX_MAX`` contacts NSGS goes on (on the piles of 1,264-3,970 contacts
#: prox and newton did not reach 1e-4 within 60 s, ADMM needed more iterations than NSGS
#: sweeps, each 5-10 times dearer), the polish trying whenever the sweeps' error has fallen
#: by ``_AUTO_POLISH_STEP`` since its last try (first at ``_AUTO_POLISH_FROM``).
_AUTO_PROBE, _AUTO_PROBE_FIRST, _AUTO_PROX_MAX = 50, 10, 1000
_AUTO_ADMM_LEVELS, _AUTO_ADMM_BUDGET, _AUTO_ADMM_MORE = (1e-4, 1e-6), 400, 30
_AUTO_POLISH_FROM, _AUTO_POLISH_STEP = 1e-6, 1e-2
#: ADMM starts from the probe's answer. Measured (CPU to 1e-8 with the polish): from the
#: probe's answer Spheres 0.007 s and KaplasTower 0.087 s, from zero 0.011 s and 0.062 s, from
#: zero with ``ADMMOptions(rho_power=0.1, rho_update_every=10)`` 0.017 s and 0.036 s; no start
#: and schedule is best on every file.


#: The compiled small-problem path (:mod:`._small`, imported with Numba on first use): problems
#: of at most SMALL_MAX contacts, with these methods, no callback and no time limit.
SMALL_MAX, SMALL_MODES = 16, ("nsgs", "polish", "auto")


@functools.cache
def _small_path():
    from . import _small
    assert _small.SMALL_MAX == SMALL_MAX and tuple(_small.MODES) == SMALL_MODES
    return _small


def _initial(problem, fr: _Frame, r0):
    n = 3 * problem.nc
    if r0 is None:
        return np.zeros(n)
    r = initial_reactions(r0, n)
    if fr.P is not None:
        import scipy.sparse.linalg as spla
        r = spla.spsolve(fr.P.tocsc(), r)
    return np.ascontiguousarray(r)


#: Modules whose import loads a BLAS or OpenMP library: the set of those imported keys the
#: controller, so that a library loaded after the last scan is found. Numba's thread pools
#: are among them: its OpenMP layer loads the GNU OpenMP runtime at the first parallel call
#: (possibly after a solve), and that runtime must be limited too.
THREADED_MODULES = ("numpy", "scipy.linalg", "sklearn", "torch", "mkl", "numba.np.ufunc.omppool",
                    "numba.np.ufunc.tbbpool", "numba.np.ufunc.workqueue")


@functools.lru_cache(maxsize=None)
def _thread_controller(_loaded: frozenset):
    """threadpoolctl's controller of the BLAS and OpenMP libraries loaded now, found once per
    set of imported :data:`THREADED_MODULES` (a scan costs 14 ms on 2 busy cores). SciPy's own BLAS (loaded by
    ``scipy.linalg``, another library than NumPy's) is loaded first, so that it is limited too."""
    from .._optional import require
    return require("threadpoolctl", extra="solvers").ThreadpoolController()


def thread_limits(threads):
    """A context limiting every BLAS and OpenMP library in the process to ``threads`` threads
    (None: nothing), for the whole of a solve (SciPy's factorizations included)."""
    import contextlib
    import sys
    if threads is None:
        return contextlib.nullcontext()
    import scipy.linalg  # noqa: F401  (SciPy's BLAS, so that it is in the controller)
    loaded = frozenset(name for name in THREADED_MODULES if name in sys.modules)
    ctl = _thread_controller(loaded)
    if all(lib["num_threads"] <= threads for lib in ctl.info()):
        return contextlib.nullcontext()
    return ctl.limit(limits=threads)


def _check(problem, method, tol, max_iter, time_limit, blas_threads, callback, options):
    if not isinstance(problem, FrictionContactProblem):
        raise FrictionRulesError(f"problem = {problem!r} is not a FrictionContactProblem")
    entry = check_method(method)
    if not (type(tol) is float and tol >= 0.0 and tol != np.inf):    # the common case costs nothing
        tol = check_scalar("tol", tol, lo=0.0)
    max_iter = entry.max_iter if max_iter is None else int(check_scalar("max_iter", max_iter, lo=1))
    if time_limit is not None:
        time_limit = check_scalar("time_limit", time_limit, lo=0.0, lo_open=True)
    if blas_threads is not None and not (type(blas_threads) is int and blas_threads >= 1):
        blas_threads = int(check_scalar("blas_threads", blas_threads, lo=1))
    if callback is not None and not callable(callback):
        raise FrictionRulesError(f"callback = {callback!r} is not callable")
    return tol, max_iter, time_limit, blas_threads, options_for(method, options)


def solve(problem: FrictionContactProblem, method: str = "auto", tol: float = 1e-8,
          max_iter: int | None = None, r0=None, *, options=None, callback=None,
          time_limit: float | None = None, blas_threads: int | None = 1) -> Solution:
    r"""Solve a frictional contact problem; the error is Siconos' (see :mod:`.error`).

    Parameters
    ----------
    problem : FrictionContactProblem
    method : {"auto", "nsgs", "newton", "prox", "admm", "polish"}
        See the module docstring; ``"auto"`` chooses from the problem's size and structure.
        On the law path only ``"auto"``, ``"nsgs"`` and ``"polish"`` (the others are refused,
        naming the contact's law).
    tol : float
        Stop when :func:`~frictionrules.multicontact.fc3d_error` ``<= tol``
        (:func:`~frictionrules.multicontact.law_error` on the law path).
    max_iter : int, optional
        Sweeps (nsgs), Newton iterations (newton, polish), outer proximal iterations (prox),
        ADMM iterations (admm), all stages together (auto); defaults ``METHODS[method].max_iter``.
    r0 : (3 nc,) array, optional
        Initial reactions (zero by default), e.g. a previous solution or an FCLIB file's guess.
    options : NSGSOptions, NewtonOptions, ProxOptions, ADMMOptions or PolishOptions, optional
        The schedule of ``method`` (its defaults when omitted; not with ``"auto"``).
    callback : callable, optional
        ``callback(info)`` with an :class:`~frictionrules.IterationInfo` after every iteration
        (nsgs: after every sweep where it evaluates the error, at least every
        ``NSGSOptions.chunk_seconds``); a true return stops the run (reason ``"callback"``).
    time_limit : float, optional
        Wall-clock seconds; the run stops after the iteration that passes it (reason
        ``"time_limit"``). Seconds spent compiling kernels (a first call in a fresh
        environment) are not counted: the limit bounds the solver's work, whatever the state
        of Numba's cache.
    blas_threads : int or None
        BLAS and OpenMP threads during the whole call (threadpoolctl); None leaves them.

    Returns
    -------
    Solution
        ``converged`` is ``error <= tol`` with bounded reactions; ``reason`` says why the run
        stopped; ``history[k]`` the error after iteration ``history_iterations[k]``;
        ``seconds`` and ``cpu_seconds`` the wall and CPU time of the call.
    """
    t0 = time.perf_counter()
    if getattr(problem, "path", "cone") == "law":
        tol, max_iter, time_limit, blas_threads, opts = _check(problem, method, tol, max_iter, time_limit,
                                                               blas_threads, callback, options)
        from ._law_path import solve_law
        with thread_limits(blas_threads):
            return solve_law(problem, method, tol, max_iter, r0, opts, callback, time_limit, t0,
                             time.thread_time())
    if (type(problem) is FrictionContactProblem and method in SMALL_MODES and problem.nc <= SMALL_MAX
            and problem.frames is None and callback is None and time_limit is None and options is None
            and max_iter is None and r0 is None and type(tol) is float and 0.0 <= tol < np.inf
            and (blas_threads is None or type(blas_threads) is int and blas_threads >= 1)):
        # the small path with every argument at its default: nothing else to check
        sol = _small_path().solve_small(problem, method, tol, METHODS[method].max_iter, None, None, t0)
        if sol.converged or method != "auto":
            return sol
        opts, max_iter = None, METHODS[method].max_iter
        c0 = time.thread_time() - sol.seconds       # the small attempt's CPU time: its wall time
    else:
        tol, max_iter, time_limit, blas_threads, opts = _check(problem, method, tol, max_iter, time_limit,
                                                               blas_threads, callback, options)
        if (problem.nc <= SMALL_MAX and method in SMALL_MODES and problem.frames is None
                and callback is None and time_limit is None):
            sol = _small_path().solve_small(problem, method, tol, max_iter, r0, opts, t0)
            if sol.converged or method != "auto":
                return sol
            opts = options_for(method, options)
            c0 = time.thread_time() - sol.seconds
        else:
            c0 = time.thread_time()
    with thread_limits(blas_threads):
        fr = _Frame(problem)
        r = _initial(problem, fr, r0)
        mon = _Monitor(fr, tol, time_limit, callback)
        if method == "auto":
            r, it, ran = _run_auto(fr, r, tol, max_iter, mon)
        else:
            r, it = _run(method, fr, r, max_iter, mon, opts)
            ran = method
        r = r if fr.P is None else fr.P @ r
        u = problem.velocity(r)
        if fr.P is None:    # the frame is the problem's: the compiled error (0.1 ms less on 270 contacts)
            err = fr.error(r, u)
        else:
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
                    method=ran, seconds=time.perf_counter() - t0, reason=reason,
                    cpu_seconds=time.thread_time() - c0)


#: Problems per compiled call of :func:`solve_batch` (its history buffers: 4 kB a problem).
_BATCH_BLOCK = 1024


def solve_batch(problems, method: str = "auto", tol: float = 1e-8, max_iter: int | None = None, *,
                blas_threads: int | None = 1) -> list[Solution]:
    """Solve each problem with the same arguments: ``[solve(p, method, tol, max_iter) for p in
    problems]``, the same answers, with the problems of at most :data:`SMALL_MAX` contacts
    (``nsgs``, ``polish`` or ``auto``) solved in one compiled call.

    A physics step, a calibration or a parameter sweep solves thousands of small problems;
    one at a time each pays a Python call (about 4 µs of argument handling, dispatch, buffers
    and its record); here they share one, and each problem costs its compiled work, two
    readings of the monotonic clock (its ``seconds``, also its ``cpu_seconds`` as on the small
    path of :func:`solve`) and its :class:`Solution`. An ``auto`` run that does not converge
    there goes on with the general path, as in :func:`solve`; so does every problem on a
    platform without that clock (:data:`._small.CLOCK`).

    Parameters
    ----------
    problems : iterable of FrictionContactProblem
    method, tol, max_iter, blas_threads
        As in :func:`solve`, for every problem.

    Returns
    -------
    list of Solution
        In the order of ``problems``.
    """
    problems = list(problems)
    if not problems:
        check_method(method)
        return []
    for p in problems[:1]:
        _check(p, method, tol, max_iter, None, blas_threads, None, None)
    out: list = [None] * len(problems)
    small = _small_path()
    batch = [k for k, p in enumerate(problems) if type(p) is FrictionContactProblem and p.nc <= SMALL_MAX
             and p.frames is None and p.path == "cone"]
    if method in SMALL_MODES and small.CLOCK is not None and batch:
        tol = float(tol)
        limit = METHODS[method].max_iter if max_iter is None else int(max_iter)
        for start in range(0, len(batch), _BATCH_BLOCK):
            block = batch[start:start + _BATCH_BLOCK]
            for k, sol in zip(block, _solve_small_many([problems[k] for k in block], method, tol, limit, small)):
                out[k] = sol
    return [s if s is not None else solve(p, method, tol, max_iter, blas_threads=blas_threads)
            for p, s in zip(problems, out)]


def _solve_small_many(problems, method, tol, max_iter, small) -> list:
    """The problems in one compiled call (:func:`._small.sweeps_many`, then
    :func:`._small.small_solve_many` for the polish and what follows it, where a problem needs
    them); None for those left to :func:`solve` (``auto`` not converged, a history longer than
    its buffer)."""
    P = len(problems)
    con_start = np.zeros(P + 1, dtype=np.int64)
    np.cumsum([p.nc for p in problems], out=con_start[1:])
    Ws = [p.W for p in problems]
    ptr_start = np.zeros(P, dtype=np.int64)
    np.cumsum([W.shape[0] + 1 for W in Ws[:-1]], out=ptr_start[1:])
    nnz_start = np.zeros(P, dtype=np.int64)
    np.cumsum([W.nnz for W in Ws[:-1]], out=nnz_start[1:])
    cat = np.concatenate
    n = 3 * int(con_start[-1])
    r, u = np.zeros(n), np.empty(n)
    h_err, h_it = np.empty((P, small.HISTORY)), np.empty((P, small.HISTORY), dtype=np.int64)
    out_int, out_float = np.zeros((P, 4), dtype=np.int64), np.zeros((P, 3))
    polish = small.POLISH_DEFAULTS
    mode = small.MODES[method]
    arrays = (cat([W.indptr for W in Ws]), cat([W.indices for W in Ws]), cat([W.data for W in Ws]), ptr_start,
              nnz_start, cat([p.q for p in problems]), cat([p.mu_bar for p in problems]),
              cat([p.dilatancy for p in problems]), con_start, r, u, h_err, h_it, tol)
    if mode != small.MODES["polish"]:       # the sweeps first: the polish is compiled only if a problem needs it
        small.sweeps_many(*arrays, max_iter if method == "nsgs" else min(small.AUTO_PROBE, max_iter),
                          small.UNBOUNDED, small.CLOCK, out_int, out_float)
    if mode == small.MODES["polish"] or any(
            nh >= 0 and small.goes_on(mode, stage_err, tol, it, max_iter)
            for (it, _b, _s, nh), (_e, _t, stage_err) in zip(out_int.tolist(), out_float.tolist())):
        small.small_solve_many(*arrays, max_iter, mode, polish.contraction, polish.patience, polish.max_halvings,
                               small.UNBOUNDED, small.CLOCK, out_int, out_float)
    sols = []
    starts = (3 * con_start).tolist()       # Python numbers: a tenth of NumPy scalars' cost
    for k, ((it, bounded, stages, nh), (err, seconds, _stage_err)) in enumerate(zip(out_int.tolist(),
                                                                                   out_float.tolist())):
        reason = small.reason(method, bounded, err, tol, it, max_iter)
        if nh < 0 or (method == "auto" and reason != "converged"):
            sols.append(None)
            continue
        a, b = starts[k], starts[k + 1]
        sols.append(Solution._record(r[a:b], u[a:b], err, it, reason == "converged", h_err[k, :nh], h_it[k, :nh],
                                     small.STAGE_NAMES[mode][stages], seconds, reason, seconds))
    return sols


def _run(method, fr, r, max_iter, mon, opts):
    if method == "nsgs":
        r = np.array(r, dtype=float)
        return r, METHODS["nsgs"].run(fr, r, max_iter, mon, opts)
    if fr.error(r) <= mon.tol:
        mon.record(method, 0, r, fr.error(r))
        return r, 0
    return METHODS[method].run(fr, r, max_iter, mon, opts)


def _stage(method, fr, r, tol, budget, mon, total):
    """One stage of ``auto`` to ``tol`` within ``budget`` iterations; returns ``(r, iterations)``."""
    mon.tol, mon.reason, mon.offset = tol, "", total
    return _run(method, fr, r, budget, mon, options_for(method, None))


def _predicted_sweeps(mon, tol) -> float:
    """Sweeps still needed to ``tol`` at the linear rate of the last two evaluated errors."""
    e, k = mon.errors[-2:], mon.iterations[-2:]
    if len(e) < 2 or not 0.0 < e[1] < e[0] or k[1] <= k[0]:
        return np.inf
    return np.log(tol / e[1]) / (np.log(e[1] / e[0]) / (k[1] - k[0]))


def _run_auto(fr, r, tol, max_iter, mon):
    """The stages of ``"auto"`` (see the module constants), each from the last one's answer;
    returns ``(r, iterations, "stage+stage...")``."""
    start, total, ran = r.copy(), 0, []

    def run(method, r, stage_tol, budget):
        nonlocal total
        budget = min(budget, max_iter - total)
        if budget <= 0:
            return r, True
        r, it = _stage(method, fr, r, stage_tol, budget, mon, total)
        total += it
        if not ran or ran[-1] != method:    # the probe's extensions are one NSGS stage
            ran.append(method)
        stop = mon.reason in ("time_limit", "callback", "unbounded") or (mon.reason == "converged" and stage_tol <= tol)
        return r, stop

    def polish(r):
        r_new, stop = run("polish", r.copy(), tol, METHODS["polish"].max_iter)
        better = fr.error(r_new) < fr.error(r)
        return (r_new if better else r), stop

    r, stop = run("nsgs", r, tol, _AUTO_PROBE_FIRST)
    while not stop and mon.reason != "converged":
        more = _predicted_sweeps(mon, tol)
        if more > _AUTO_PROBE - total:
            break
        r, stop = run("nsgs", r, tol, min(int(1.5 * more) + 2, _AUTO_PROBE - total))
    if not stop and fr.nc <= _AUTO_PROX_MAX:
        spent = total
        if all_stick(fr, options_for("admm", None)):
            r = start.copy()
        for level in _AUTO_ADMM_LEVELS:
            mon.handover = (max(tol, level), _AUTO_ADMM_MORE)
            r, stop = run("admm", r, tol, _AUTO_ADMM_BUDGET - (total - spent))
            mon.handover = None
            if stop or not mon.errors or mon.errors[-1] > max(tol, level):
                break
            r, stop = polish(r)
            if stop:
                break
        if not stop:
            r, stop = run("prox", start.copy(), tol, METHODS["prox"].max_iter)
        if not stop:
            r, stop = polish(r)
    level = max(tol, _AUTO_POLISH_FROM)
    while not stop and fr.nc > _AUTO_PROX_MAX:
        r, stop = run("nsgs", r, level, max_iter)
        if stop:
            break
        reached = mon.reason == "converged"
        r, stop = polish(r)
        if not reached:                     # the sweeps' budget is spent
            break
        level = max(tol, level * _AUTO_POLISH_STEP)
    mon.tol = tol
    if mon.reason in ("converged", "stalled", "handover") and (not mon.errors or mon.errors[-1] > tol):
        mon.reason = "max_iter"
    return r, total, "+".join(ran)
