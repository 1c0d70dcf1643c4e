r"""The small-problem path of :func:`~frictionrules.solve`: up to :data:`SMALL_MAX` contacts,
the whole solve in one or two compiled calls.

A physics step, a calibration or a sweep over thousands of small problems pays a solver's
set-up at every call; here the set-up (diagonal blocks, norms), the iterations and the final
error run inside one Numba function on W's CSR arrays, so that a call costs the Python
argument checks, one compiled call and the :class:`Solution` record (``benchmarks/fclib.py``
measures it). ``nsgs`` runs the same sweeps as the general path; ``polish`` and ``auto`` take
dense Newton steps on the natural map (:func:`._kernels.natural_map`) with LAPACK's least-squares
solve (:func:`._lapack.min_norm_solve`, NumPy's ``lstsq``: the minimum-norm step where J is
singular). ``auto`` runs at most ``AUTO_PROBE`` sweeps,
the polish, then sweeps to the end of its budget and the polish again.

The sweeps (all of ``nsgs``, the probe of ``auto``) are one compiled call of their own
(:func:`sweeps_into`, :func:`sweeps_many`), and the polish with what follows it a second one
that goes on from their state (:func:`solve_into`, :func:`small_solve_many`), called only for a
problem that needs it: a first run on a problem the sweeps solve (CubeH8, one contact) compiles
no polish, 5 of its 13 s of CPU before (under load). The answer is that of one run from the
start, to the bit.
"""

from __future__ import annotations

import sys
import time

import numpy as np

from .._optional import require
from . import _kernels as K
from ._lapack import min_norm_solve
from ._frame import UNBOUNDED, initial_reactions
from ._options import PolishOptions
from .problem import Solution

numba = require("numba", extra="kernels")
njit = numba.njit
intrinsic = numba.core.extending.intrinsic

#: Largest number of contacts solved by the small path.
SMALL_MAX = 16
#: Sweeps before the first polish of ``auto`` (the general path's probe).
AUTO_PROBE = 50
#: Modes of :func:`small_solve`, and the stages ``auto`` may run.
MODES = {"nsgs": 0, "polish": 1, "auto": 2}
STAGES = ("nsgs", "polish")
#: The polish schedule of ``auto`` on this path.
POLISH_DEFAULTS = PolishOptions()


#: Integer constants of the compiled calls below, typed ``int64`` (``np.int64(1)``), not as
#: literals: Numba compiles a callee once for each literal value passed to it (``_grow(.., 1)``
#: and ``_grow(.., n)`` would be two compilations of ``_grow``, and ``nh = 0`` before a loop
#: one more of every function it reaches) -- seconds of a first call each.
_ZERO, _ONE = numba.int64(0), numba.int64(1)
#: Most sweeps between two evaluations of the error in :func:`_sweeps` (``K.nsgs``).
_INTERVAL = numba.int64(16)


@njit(inline="always")
def _copy(src, dst):
    """``dst[:] = src`` for arrays of the same size. An array assigned to a slice compiles
    Numba's check of the shapes with its formatted error message (its string functions: 3 s
    of a first call on 2 cores); this loop compiles to the same copy without it."""
    for k in range(src.size):
        dst[k] = src[k]


@njit(inline="always")
def _polish(indptr, indices, data, q, mu, dil, r, tol, max_iter, norm_q, hist_err, hist_it, nh, offset,
            contraction, patience, max_halvings):
    """Dense Newton steps on the natural map (see :mod:`._polish`); returns ``(steps, error, nh,
    hist_err, hist_it)``, the history buffers grown (doubled) when a step finds them full."""
    nc = mu.size
    n = 3 * nc
    Wd = np.zeros((n, n))
    for i in range(n):
        for k in range(indptr[i], indptr[i + 1]):
            Wd[i, indices[k]] += data[k]
    D = K.diagonal_blocks(indptr, indices, data, nc)
    rho = np.empty(nc)
    for a in range(nc):
        tr = abs(D[a, 0, 0] + D[a, 1, 1] + D[a, 2, 2]) / 3.0
        rho[a] = 1.0 / tr if tr > 0.0 else 1.0
    err, u = K.fc3d_error_kernel(indptr, indices, data, q, mu, dil, r, norm_q)
    if max_iter <= 0 or err <= tol:
        return 0, err, nh, hist_err, hist_it
    J = np.empty((n, n))
    slow = 0
    it = 0
    while it < max_iter and err > tol:
        phi, B1, B2, pieces = K.natural_map(r, u, mu, dil, rho)
        for a in range(nc):
            for l in range(3):
                row = 3 * a + l
                for j in range(n):
                    J[row, j] = (B2[a, l, 0] * Wd[3 * a, j] + B2[a, l, 1] * Wd[3 * a + 1, j]
                                 + B2[a, l, 2] * Wd[3 * a + 2, j])
                for c in range(3):
                    J[row, 3 * a + c] += B1[a, l, c]
        dx = min_norm_solve(J, -phi)         # np.linalg.lstsq(J, -phi, -1.0)[0], compiled faster
        alpha = 1.0
        accepted = False
        for _ in range(max_halvings + 1):
            rn = r + alpha * dx
            en, un = K.fc3d_error_kernel(indptr, indices, data, q, mu, dil, rn, norm_q)
            if en < err:
                accepted = True
                break
            alpha *= 0.5
        if not accepted:
            break
        it += 1
        slow = slow + 1 if en > contraction * err else 0
        _copy(rn, r)
        u, err = un, en
        hist_err, hist_it = _grow(hist_err, hist_it, nh, _ONE)
        hist_err[nh] = err
        hist_it[nh] = offset + it
        nh += 1
        if slow >= patience:
            break
    return it, err, nh, hist_err, hist_it


#: Sweeps per compiled chunk of the small path (its history buffer).
CHUNK = 256


@njit(cache=True)
def _grow(h_err, h_it, nh, extra):
    """History buffers with room for ``extra`` more entries after the first ``nh``."""
    if nh + extra <= h_err.size:
        return h_err, h_it
    size = max(2 * h_err.size, nh + extra)
    e, i = np.empty(size), np.empty(size, dtype=np.int64)
    for k in range(nh):                 # a loop, not slices: see _copy
        e[k], i[k] = h_err[k], h_it[k]
    return e, i


@njit(inline="always")
def _sweeps(indptr, indices, data, D, q, mu, dil, r, tol, budget, norm_q, h_err, h_it, nh, offset):
    """NSGS in chunks of :data:`CHUNK` sweeps; returns ``(sweeps, error, h_err, h_it, nh)``."""
    done, err = _ZERO, np.inf
    while done < budget:
        n = min(CHUNK, budget - done)
        h_err, h_it = _grow(h_err, h_it, nh, n)
        it, err, k = K.nsgs(indptr, indices, data, D, q, mu, dil, r, tol, n, h_err[nh:], h_it[nh:], norm_q, _INTERVAL)
        for j in range(nh, nh + k):
            h_it[j] += offset + done
        nh += k
        done += it
        if err <= tol:
            break
    return done, err, h_err, h_it, nh


@njit(inline="always")
def _finish(indptr, indices, data, q, mu, dil, r, u, D, norm_q, err, r_bound_factor):
    """``u = W r + q``; the error of ``r`` where the last stage left none (``inf``); whether
    the reactions are within ``r_bound_factor`` times |q| over the mean |W_ii|. Returns
    ``(error, bounded)``."""
    nc = mu.size
    for i in range(3 * nc):
        acc = q[i]
        for k in range(indptr[i], indptr[i + 1]):
            acc += data[k] * r[indices[k]]
        u[i] = acc
    if not np.isfinite(err):
        err, _u = K.fc3d_error_kernel(indptr, indices, data, q, mu, dil, r, norm_q)
    mean_diag, count = 0.0, 0
    for a in range(nc):
        for l in range(3):
            if D[a, l, l] != 0.0:
                mean_diag += abs(D[a, l, l])
                count += 1
    mean_diag = mean_diag / count if count else 1.0
    return err, K.norm2(r) <= r_bound_factor * max(norm_q, 1e-300) / mean_diag


@njit(inline="always")
def small_sweeps(indptr, indices, data, q, mu, dil, r, u, h_err, h_it, tol, budget, r_bound_factor):
    """The first stage alone, up to ``budget`` NSGS sweeps from ``r``: the whole of mode 0
    (nsgs) and the probe of mode 2 (auto). Its callers compile no polish: a problem the sweeps
    solve (CubeH8 and most small problems) never compiles it (:func:`small_solve` goes on where
    they stop). Returns ``(sweeps, error, bounded, stage error, history length, h_err, h_it)``;
    the stage error is the sweeps' own (``inf`` where none was evaluated), the state
    :func:`small_solve` resumes from."""
    norm_q = K.norm2(q)
    D = K.diagonal_blocks(indptr, indices, data, mu.size)
    it, stage_err, h_err, h_it, nh = _sweeps(indptr, indices, data, D, q, mu, dil, r, tol, budget, norm_q,
                                             h_err, h_it, _ZERO, _ZERO)
    err, bounded = _finish(indptr, indices, data, q, mu, dil, r, u, D, norm_q, stage_err, r_bound_factor)
    return it, err, bounded, stage_err, nh, h_err, h_it


@njit(inline="always")
def small_solve(indptr, indices, data, q, mu, dil, r, u, h_err, h_it, tol, max_iter, mode, contraction, patience,
                max_halvings, r_bound_factor, ns, done, nh, err):
    """Solve in place from ``r``: mode 0 nsgs, 1 polish, 2 auto (see the module docstring);
    ``u`` receives :math:`W r + q`, ``h_err``, ``h_it`` the history (buffers of any size,
    replaced by larger ones when the history outgrows them). ``ns, done, nh, err``: the
    stages run so far, their iterations, history length and last stage's error; ``0, 0, 0,
    inf`` for a fresh start, ``1, sweeps, length, stage error`` of :func:`small_sweeps`' probe
    to go on after it (the same run as from the start).

    Returns ``(iterations, error, bounded, stages, history length, h_err, h_it)``; ``stages``
    is the number of stages run (they alternate from nsgs, or are one polish in mode 1: see
    :data:`STAGE_NAMES`); ``bounded`` whether the reactions are within ``r_bound_factor``
    times |q| over the mean |W_ii|. The error is the last stage's, of ``r`` as returned.
    """
    nc = mu.size
    norm_q = K.norm2(q)
    D = K.diagonal_blocks(indptr, indices, data, nc)
    if ns == 0:
        budget = max_iter if mode != 2 else min(AUTO_PROBE, max_iter)
    else:
        budget = max_iter - done
    stage = 1 if mode == 1 else ns % 2
    while ns < 4:
        if stage == 0:
            it, err, h_err, h_it, nh = _sweeps(indptr, indices, data, D, q, mu, dil, r, tol, budget, norm_q,
                                               h_err, h_it, nh, done)
        else:
            it, err, k, h_err, h_it = _polish(indptr, indices, data, q, mu, dil, r, tol, budget, norm_q, h_err,
                                              h_it, nh, done, contraction, patience, max_halvings)
            if k == nh:                     # no step taken: the error of r as it is
                h_err, h_it = _grow(h_err, h_it, nh, _ONE)
                h_err[nh], h_it[nh], k = err, done, nh + 1
            nh = k
        ns += 1
        done += it
        budget = max_iter - done
        if mode != 2 or err <= tol or budget <= 0:
            break
        stage = 1 - stage
    # every stage ends with the error of r as it is (NSGS evaluates after its last sweep)
    err, bounded = _finish(indptr, indices, data, q, mu, dil, r, u, D, norm_q, err, r_bound_factor)
    return done, err, bounded, ns, nh, h_err, h_it


@njit(inline="always")
def _keep_into(h_err, h_it, nh, he, hi):
    """The history written to grown buffers ``he``, ``hi`` copied back to the caller's where it
    fits (a longer one is run again with room for it: see :func:`solve_into`). A chunk of
    sweeps grows the buffers when the history *might* outgrow them, so a run may end in grown
    buffers with a history that fits."""
    if he.size != h_err.size and nh <= h_err.size:
        _copy(he[:nh], h_err[:nh])
        _copy(hi[:nh], h_it[:nh])


def goes_on(mode: int, stage_err: float, tol: float, sweeps: int, max_iter: int) -> bool:
    """Whether mode 2 (auto) goes on after :func:`small_sweeps`' probe (``small_solve``'s rule
    after its first stage)."""
    return mode == 2 and not stage_err <= tol and sweeps < max_iter


@njit(cache=True)
def sweeps_into(indptr, indices, data, q, mu, dil, r0, out, h_it, tol, budget, r_bound_factor):
    """:func:`small_sweeps` from ``r0`` (zero where it is empty) into one buffer laid out as
    :func:`solve_into`'s; returns ``(sweeps, error, bounded, stage error, history length)``."""
    n = q.size
    if r0.size:
        _copy(r0, out[:n])
    else:
        out[:n] = 0.0
    it, err, bounded, stage_err, nh, he, hi = small_sweeps(indptr, indices, data, q, mu, dil, out[:n],
                                                           out[n:2 * n], out[2 * n:], h_it, tol, budget,
                                                           r_bound_factor)
    _keep_into(out[2 * n:], h_it, nh, he, hi)
    return it, err, bounded, stage_err, nh


@njit(cache=True)
def solve_into(indptr, indices, data, q, mu, dil, r0, out, h_it, tol, max_iter, mode, contraction, patience,
               max_halvings, r_bound_factor, ns, done, nh, err):
    """:func:`small_solve` from ``r0`` (zero where it is empty; ignored where ``ns > 0``: ``out``
    holds the state :func:`sweeps_into` left) into one buffer, returning
    numbers only: ``(iterations, error, bounded, stages, history length)``. ``out`` receives
    ``r``, then ``u``, then the errors of the history, whose iterations go to ``h_it``. A
    Python call of a compiled function pays for each argument (about 40 ns for an array) and
    for each array it returns (0.27 µs to box), and NumPy about 0.15 µs for each array it
    allocates, a tenth of a tiny solve each: hence one buffer, and numbers out. A history
    longer than ``h_it`` is lost; the same call with room for at least ``length +``
    :data:`CHUNK` entries gives the same answer with the whole history."""
    n = q.size
    if ns == 0:
        if r0.size:
            _copy(r0, out[:n])
        else:
            out[:n] = 0.0
    it, err, bounded, ns, nh, he, hi = small_solve(indptr, indices, data, q, mu, dil, out[:n], out[n:2 * n],
                                                   out[2 * n:], h_it, tol, max_iter, mode, contraction, patience,
                                                   max_halvings, r_bound_factor, ns, done, nh, err)
    _keep_into(out[2 * n:], h_it, nh, he, hi)
    return it, err, bounded, ns, nh


#: History entries allocated per call: one chunk of sweeps fits without a new buffer.
HISTORY = CHUNK + 4


@intrinsic
def _clock_ns(typingctx, clock):
    """``clock_gettime(clock)`` in nanoseconds, from compiled code (the C library's function,
    resolved when the code is loaded; ``struct timespec`` of two 64-bit integers)."""
    from llvmlite import ir
    from numba.core import cgutils

    def codegen(context, builder, signature, args):
        i32, i64 = ir.IntType(32), ir.IntType(64)
        timespec = ir.LiteralStructType([i64, i64])
        fn = cgutils.get_or_insert_function(builder.module, ir.FunctionType(i32, [i32, timespec.as_pointer()]),
                                            "clock_gettime")
        ts = cgutils.alloca_once(builder, timespec)
        builder.call(fn, [builder.trunc(args[0], i32), ts])
        seconds = builder.load(cgutils.gep_inbounds(builder, ts, 0, 0))
        nanoseconds = builder.load(cgutils.gep_inbounds(builder, ts, 0, 1))
        return builder.add(builder.mul(seconds, ir.Constant(i64, 1_000_000_000)), nanoseconds)

    return numba.types.int64(numba.types.int64), codegen


#: The clock of the compiled batch's per-problem times (the monotonic clock, that of
#: ``time.perf_counter``), or None where the platform's ``clock_gettime`` is not known to have
#: it (the batch then solves problem by problem). As on :func:`solve_small`, the time is the
#: wall time, also given as the CPU time: the thread's CPU clock is a system call (0.6 µs),
#: and two a problem made the batch slower than a loop of ``solve``.
CLOCK = time.CLOCK_MONOTONIC if sys.platform.startswith("linux") else None


@njit(inline="always")
def _problem(indptr, indices, data, ptr_start, nnz_start, con_start, k):
    """Problem k's CSR arrays in the batch layout of :func:`sweeps_many`, and its first contact."""
    a, b = con_start[k], con_start[k + 1]
    n = 3 * (b - a)
    ip = indptr[ptr_start[k]:ptr_start[k] + n + 1]
    nz = nnz_start[k]
    return ip, indices[nz:nz + ip[n]], data[nz:nz + ip[n]], a, b


@njit(inline="always")
def _keep(h_err, h_it, k, nh, he, hi):
    """The history length of row k (-1: it outgrew the row), copied there from a grown buffer."""
    if he.size != h_err.shape[1] and nh <= h_err.shape[1]:     # written to a grown buffer
        _copy(he[:nh], h_err[k, :nh])
        _copy(hi[:nh], h_it[k, :nh])
    return nh if nh <= h_err.shape[1] else -1


@njit(cache=True)
def sweeps_many(indptr, indices, data, ptr_start, nnz_start, q, mu, dil, con_start, r, u, h_err, h_it, tol,
                budget, r_bound_factor, clock, out_int, out_float):
    """:func:`small_sweeps` on each of P problems stored one after the other: problem k has
    ``n = 3 (con_start[k+1] - con_start[k])`` unknowns, its CSR row pointers
    ``indptr[ptr_start[k]:ptr_start[k] + n + 1]`` (from 0), its column indices and values
    from ``nnz_start[k]``, its q, r, u from ``3 con_start[k]``, its history in row k of
    ``h_err``, ``h_it``; ``r`` holds the initial reactions. Writes ``out_int[k] = (iterations,
    bounded, stages, history length)`` (length -1: the history outgrew its row) and
    ``out_float[k] = (error, seconds on clock, stage error)``."""
    for k in range(con_start.size - 1):
        t0 = _clock_ns(clock)
        ip, ix, dt, a, b = _problem(indptr, indices, data, ptr_start, nnz_start, con_start, k)
        it, err, bounded, stage_err, nh, he, hi = small_sweeps(
            ip, ix, dt, q[3 * a:3 * b], mu[a:b], dil[a:b], r[3 * a:3 * b], u[3 * a:3 * b], h_err[k], h_it[k], tol,
            budget, r_bound_factor)
        out_int[k, 0], out_int[k, 1], out_int[k, 2] = it, bounded, 1
        out_int[k, 3] = _keep(h_err, h_it, k, nh, he, hi)
        out_float[k, 0], out_float[k, 2] = err, stage_err
        out_float[k, 1] = 1e-9 * (_clock_ns(clock) - t0)


@njit(cache=True)
def small_solve_many(indptr, indices, data, ptr_start, nnz_start, q, mu, dil, con_start, r, u, h_err, h_it,
                     tol, max_iter, mode, contraction, patience, max_halvings, r_bound_factor, clock, out_int,
                     out_float):
    """:func:`small_solve` on the problems of :func:`sweeps_many`'s layout and outputs, each
    from the state those outputs hold: a fresh start where ``out_int[k, 2]`` (the stages) is 0,
    else the state :func:`sweeps_many`' probe left, for the problems that go on after it
    (:func:`goes_on`; the others are left as they are). The seconds are added to those in
    ``out_float[k, 1]``."""
    for k in range(con_start.size - 1):
        ns, done, nh = out_int[k, 2], out_int[k, 0], out_int[k, 3]
        if ns > 0 and (nh < 0 or mode != 2 or out_float[k, 2] <= tol or done >= max_iter):
            continue
        t0 = _clock_ns(clock)
        ip, ix, dt, a, b = _problem(indptr, indices, data, ptr_start, nnz_start, con_start, k)
        it, err, bounded, ns, nh, he, hi = small_solve(
            ip, ix, dt, q[3 * a:3 * b], mu[a:b], dil[a:b], r[3 * a:3 * b], u[3 * a:3 * b], h_err[k], h_it[k], tol,
            max_iter, mode, contraction, patience, max_halvings, r_bound_factor, ns, done, nh, out_float[k, 2])
        out_int[k, 0], out_int[k, 1], out_int[k, 2] = it, bounded, ns
        out_int[k, 3] = _keep(h_err, h_it, k, nh, he, hi)
        out_float[k, 0], out_float[k, 2] = err, err
        out_float[k, 1] += 1e-9 * (_clock_ns(clock) - t0)


#: ``Solution.method`` of a small-path run, ``STAGE_NAMES[mode][count]`` after ``count`` stages
#: (at most four; they alternate from nsgs, or are one polish in mode 1).
STAGE_NAMES = tuple(tuple("polish" if mode == MODES["polish"] else "+".join(STAGES[k % 2] for k in range(count))
                          for count in range(5)) for mode in range(len(MODES)))


def reason(method: str, bounded: bool, err: float, tol: float, it: int, max_iter: int) -> str:
    """:attr:`Solution.reason` of a small-path run."""
    if not bounded:
        return "unbounded"
    if err <= tol:
        return "converged"
    return "stalled" if method == "polish" and it < max_iter else "max_iter"


_empty, _int64, _clock, _NO_R0, _INF = np.empty, np.int64, time.perf_counter, np.empty(0), float("inf")


def solve_small(problem, method: str, tol: float, max_iter: int, r0, polish, t0: float) -> Solution:
    """:func:`~frictionrules.solve` on the small path (arguments checked; ``polish``: the
    :class:`PolishOptions` of ``method="polish"`` or None; ``t0``: the call's start on
    ``time.perf_counter``). Its ``cpu_seconds`` is the wall time of the call: the thread's CPU
    clock is a system call of 0.6 µs, and two of them were a sixth of a 1-contact solve; a call
    of microseconds runs on one processor, so its wall time is its CPU time, or more when the
    thread was preempted. (Every module-level name here is a global of this module: bound
    through another module's attribute, each was 20 ns of a 4 µs call.)"""
    W = problem.W
    n = 3 * problem.nc
    if polish is None or method != "polish":
        polish = POLISH_DEFAULTS
    r0 = _NO_R0 if r0 is None else initial_reactions(r0, n)
    mode = MODES[method]
    size = HISTORY
    while True:
        out, h_it = _empty(2 * n + size), _empty(size, _int64)
        if mode == 1:
            go_on, ns, it, nh, stage_err = True, 0, 0, 0, _INF         # a fresh start
        else:                       # the sweeps (all of nsgs, the probe of auto): no polish compiled
            it, err, bounded, stage_err, nh = sweeps_into(W.indptr, W.indices, W.data, problem.q, problem.mu_bar,
                                                          problem.dilatancy, r0, out, h_it, tol,
                                                          max_iter if mode == 0 else min(AUTO_PROBE, max_iter),
                                                          UNBOUNDED)
            go_on, ns, stages = nh <= size and goes_on(mode, stage_err, tol, it, max_iter), 1, 1
        if go_on:
            it, err, bounded, stages, nh = solve_into(W.indptr, W.indices, W.data, problem.q, problem.mu_bar,
                                                      problem.dilatancy, r0, out, h_it, tol, max_iter, mode,
                                                      polish.contraction, polish.patience, polish.max_halvings,
                                                      UNBOUNDED, ns, it, nh, stage_err)
        if nh <= size:
            break
        size = nh + CHUNK           # a history longer than the buffers: the same run with room for it
    why = reason(method, bounded, err, tol, it, max_iter)
    seconds = _clock() - t0
    return Solution._record(out[:n], out[n:2 * n], err, it, why == "converged", out[2 * n:2 * n + nh], h_it[:nh],
                            STAGE_NAMES[mode][stages], seconds, why, seconds)
