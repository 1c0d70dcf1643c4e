r"""One ADMM iteration (:mod:`._admm`), compiled.

Each function does in one call what the iteration did in NumPy expressions, the same
operations in the same order on every entry (the same bits; only the residual's sum of
squares is summed in order where NumPy's dot blocked it). The NumPy version cost about
0.2 ms of Python per iteration on KaplasTower (570 contacts; 5 iterations and 12.6 ms per
solve), beside the 0.2 ms of the triangular solves and 0.08 ms of the error.

Where the factors of :math:`W + cI` are kept as CSR arrays (:func:`._triangular.lu_solve`),
:func:`admm_iteration` is the whole iteration in one call: the x-step's right-hand side, its
two triangular solves, the y- and z-steps, the residuals and the error of the new iterate.
SuperLU's ``solve`` spent most of its time in Python and SciPy on small problems (Spheres,
356 contacts: 46 µs a solve against 16 µs compiled, under load).
"""

from __future__ import annotations

import numpy as np

from .._optional import require
from . import _kernels as K
from ._triangular import lu_solve, lu_solve_into

njit = require("numba", extra="kernels").njit


@njit(cache=True)
def x_step_rhs(q, y, x, z, mu, dil, rho, eta, s, b):
    r"""De Saxcé's correction ``s`` of the dual variable z (into ``s``) and the right-hand
    side :math:`-(q + s) + \rho y + \eta x + z` of the x-step (into ``b``, returned)."""
    K.desaxce_shift(z, mu, dil, s)
    for i in range(q.size):
        b[i] = -(q[i] + s[i]) + rho * y[i] + eta * x[i] + z[i]
    return b


@njit(cache=True, inline="always")
def w_product(wp, wi, wx, blocks, x, q):
    """:math:`q + W x` from W's CSR arrays: by 3 x 3 blocks (:func:`block_matvec`) when W is
    made of them (``blocks``), by entries (:func:`._kernels.csr_matvec`) otherwise."""
    return block_matvec(wp, wi, wx, x, q) if blocks else K.csr_matvec(wp, wi, wx, x, q)


@njit(cache=True, inline="always")
def shifted_residual(wp, wi, wx, blocks, shift, x, b):
    r""":math:`(W + \text{shift}\,I)\,x - b` (:func:`w_product` of ``shift x - b``)."""
    return w_product(wp, wi, wx, blocks, x, shift * x - b)


@njit(cache=True)
def factor_solve(lp, li, lx, up, ui, ux, ud, rows, cols, triples, refine, shift, wp, wi, wx, blocks, b, scratch,
                 x):
    r""":func:`._triangular.lu_solve_into` (into ``x``, returned; ``scratch`` of b's size),
    then, when ``refine``, one step of iterative refinement with
    :math:`A = W + \text{shift}\,I` (W's CSR arrays, by 3 x 3 blocks when ``blocks``):
    :math:`x \leftarrow x - A^{-1}(A x - b)`."""
    lu_solve_into(lp, li, lx, up, ui, ux, ud, rows, cols, triples, b, scratch, x)
    if refine:
        r = shifted_residual(wp, wi, wx, blocks, shift, x, b)
        x -= lu_solve(lp, li, lx, up, ui, ux, ud, rows, cols, triples, r)
    return x


#: Iterative refinement is taken where a test solve misses this relative residual and one
#: step of it divides the residual by at least REFINE_GAIN (:func:`refines`,
#: :meth:`._admm._Factor._refines`).
REFINE_RESIDUAL, REFINE_GAIN = 1e-12, 2.0


@njit(cache=True)
def refines(lp, li, lx, up, ui, ux, ud, rows, cols, triples, shift, wp, wi, wx, blocks, t):
    r"""Whether solves with these factors of :math:`A = W + \text{shift}\,I` take a step of
    iterative refinement (:meth:`._admm._Factor._refines`, in one compiled call): the solve of
    :math:`A x = t` misses :data:`REFINE_RESIDUAL` relative residual and one step divides
    it by at least :data:`REFINE_GAIN`."""
    x = lu_solve(lp, li, lx, up, ui, ux, ud, rows, cols, triples, t)
    r = shifted_residual(wp, wi, wx, blocks, shift, x, t)
    res = np.sqrt(np.dot(r, r))
    if not res > REFINE_RESIDUAL * np.sqrt(np.dot(t, t)):
        return False
    x = x - lu_solve(lp, li, lx, up, ui, ux, ud, rows, cols, triples, r)
    r = shifted_residual(wp, wi, wx, blocks, shift, x, t)
    return REFINE_GAIN * np.sqrt(np.dot(r, r)) <= res


@njit(cache=True, inline="always")
def work_views(work, n):
    """The parts of an iteration's workspace ``work`` (5 n, :func:`admm_iteration`): the
    right-hand side, the solve's scratch, ``x_new`` and ``tv = (y, z)``."""
    return work[:n], work[n:2 * n], work[2 * n:3 * n], work[3 * n:]


@njit(cache=True)
def admm_iteration(lp, li, lx, up, ui, ux, ud, rows, cols, triples, refine, shift, wp, wi, wx, blocks,
                   q, mu, dil, rho, eta, x, v, s, norm_q, measure, work):
    r"""One whole iteration from ``v = (y, z)`` and the last x-step's ``x``: the x-step
    :math:`x_{new} = (W + (\rho + \eta) I)^{-1}(-(q + s) + \rho y + \eta x + z)`
    (:func:`x_step_rhs`, :func:`factor_solve`; ``shift`` :math:`= \rho + \eta`), then
    :func:`y_z_steps` and, when ``measure``, the error of the new y (:func:`residual_error`;
    NaN otherwise). ``work`` (5 n, its parts :func:`work_views`): the new ``x_new`` and
    ``tv`` are written there, so that no array is allocated. Returns ``(res, primal, dual,
    err)``."""
    n = q.size
    rhs, scratch, x_new, tv = work_views(work, n)
    b = x_step_rhs(q, v[:n], x, v[n:], mu, dil, rho, eta, s, rhs)
    factor_solve(lp, li, lx, up, ui, ux, ud, rows, cols, triples, refine, shift, wp, wi, wx, blocks, b, scratch,
                 x_new)
    res, primal, dual = y_z_steps(x_new, x, v, mu, rho, eta, tv)
    err = residual_error(wp, wi, wx, blocks, q, mu, dil, tv[:n], norm_q) if measure else np.nan
    return res, primal, dual, err


@njit(cache=True)
def residual_error(wp, wi, wx, blocks, q, mu, dil, r, norm_q):
    r"""Siconos' error of ``r`` (:meth:`._frame._Frame.error`):
    :math:`\sqrt{\sum_a |r_a - P_K(r_a - \hat u_a)|^2} / \max(|q|, |r|, |u|)`,
    :math:`u = W r + q`, unscaled when that maximum is at most the machine epsilon."""
    u = w_product(wp, wi, wx, blocks, r, q)
    e = np.sqrt(K.error_sum(r, u, mu, dil))
    scale = max(norm_q, np.sqrt(np.dot(r, r)), np.sqrt(np.dot(u, u)))
    return e / scale if scale > np.finfo(np.float64).eps else e


@njit(cache=True, inline="always")
def _z_entry(i, x_new, x, v, tv, rho, eta, n):
    """Entry i of the z-step (into ``tv[n + i]``, from the new y in ``tv[i]``): the primal and
    dual residuals' entries and the entry's two squares of :math:`|T(v) - v|^2`, summed."""
    y_new = tv[i]
    tv[n + i] = v[n + i] - rho * (x_new[i] - y_new)
    dz = tv[n + i] - v[n + i]
    dy = y_new - v[i]
    return abs(x_new[i] - y_new), abs(rho * dy + eta * (x_new[i] - x[i])), dy * dy + dz * dz


@njit(cache=True)
def y_z_steps(x_new, x, v, mu, rho, eta, tv):
    r"""From the x-step's ``x_new`` (``x`` the previous one, ``v = (y, z)``): the next
    :math:`(y, z)` into ``tv``, :math:`y = P_K(x_{new} - z/\rho)`,
    :math:`z - \rho (x_{new} - y)`; the fixed-point residual :math:`|T(v) - v|`, the primal
    residual :math:`|x_{new} - y|_\infty` and the dual one
    :math:`|\rho\,\Delta y + \eta\,\Delta x|_\infty` (NaN when an entry is). The cone's
    argument is formed in ``tv[n:]`` (a pass of divisions the processor vectorizes), then the
    z-step and the residuals by contacts, a contact's three squares summed together."""
    n = x_new.size
    w = tv[n:]                              # the cone's argument, then z
    for i in range(n):
        w[i] = x_new[i] - v[n + i] / rho
    K.project_all(w, mu, tv[:n])
    res, primal, dual, nan = 0.0, 0.0, 0.0, False
    for a in range(mu.size):
        i = 3 * a
        p0, d0, r0 = _z_entry(i, x_new, x, v, tv, rho, eta, n)
        p1, d1, r1 = _z_entry(i + 1, x_new, x, v, tv, rho, eta, n)
        p2, d2, r2 = _z_entry(i + 2, x_new, x, v, tv, rho, eta, n)
        p, d = max(p0, p1, p2), max(d0, d1, d2)
        nan = nan or np.isnan(p0 + p1 + p2) or np.isnan(d0 + d1 + d2)
        primal, dual = max(primal, p), max(dual, d)
        res += (r0 + r1) + r2
    if nan:
        primal = dual = np.nan
    return np.sqrt(res), primal, dual


@njit(cache=True, fastmath={"reassoc", "contract"})
def _dots(a, b, row):
    r""":math:`(a \cdot r, b \cdot r)` in one pass over ``row``, each summed in any order
    (vectorized: the sums of Anderson's normal equations, which NumPy's dot also sums in
    BLAS's order)."""
    sa = sb = 0.0
    for i in range(row.size):
        sa += a[i] * row[i]
        sb += b[i] * row[i]
    return sa, sb


@njit(cache=True, fastmath={"reassoc", "contract"})
def _minus_rows(out, dG, gamma, j, count):
    """``out -= gamma_j dG_j (+ gamma_{j+1} dG_{j+1})`` (``count`` rows, 1 or 2, in one pass);
    whether every entry of ``out`` is finite after (``x - x`` is 0 for a finite x and NaN
    otherwise, summed in any order: no overflow)."""
    acc = 0.0
    g0, r0 = gamma[j], dG[j]
    if count == 2:
        g1, r1 = gamma[j + 1], dG[j + 1]
        for i in range(out.size):
            out[i] -= g0 * r0[i] + g1 * r1[i]
            acc += out[i] - out[i]
    else:
        for i in range(out.size):
            out[i] -= g0 * r0[i]
            acc += out[i] - out[i]
    return acc == 0.0


@njit(cache=True)
def anderson_step(v, tv, prev_f, prev_tv, dG, dF, gram, small, slot, used):
    r"""Type-II Anderson's extrapolation :math:`T(v) - \gamma G` with
    :math:`(F F^T + 10^{-14} \mathrm{tr}(F F^T) I)\,\gamma = F (T(v) - v)`, F and G the first
    ``used`` rows of ``dF`` and ``dG``, after writing the newest differences into their row
    ``slot``: :math:`\Delta G = T(v) - T(v')`, :math:`\Delta F = (T(v) - v) - (T(v') - v')`,
    and keeping :math:`T(v) - v` and :math:`T(v)` in ``prev_f`` and ``prev_tv`` for the next
    step. The result is written into ``v``: the extrapolation, or ``tv`` itself where the
    system or the result is not finite (then False is returned).

    No array is allocated (``small``: m + 2 rows of scratch for the m x m system).
    :math:`F F^T` is kept in ``gram`` (only its row and column ``slot`` are new) and the
    system is solved by Gaussian elimination with partial pivoting (m is small)."""
    n = v.size
    fs = dF[slot]
    for i in range(n):
        f = tv[i] - v[i]
        dG[slot, i] = tv[i] - prev_tv[i]
        fs[i] = f - prev_f[i]
        prev_f[i] = f
        prev_tv[i] = tv[i]
    A, b, gamma = small[:used], small[used], small[used + 1]
    for j in range(used):
        gram[slot, j], b[j] = _dots(fs, prev_f, dF[j])
        gram[j, slot] = gram[slot, j]
    tr = 0.0
    for j in range(used):
        tr += gram[j, j]
    ok = np.isfinite(tr) and tr > 0.0
    for j in range(used):
        ok = ok and np.isfinite(b[j])
    if ok:
        for j in range(used):
            for k in range(used):
                A[j, k] = gram[j, k]
            A[j, j] += 1e-14 * tr
        for k in range(used):               # elimination with partial pivoting
            p = k
            for j in range(k + 1, used):
                if abs(A[j, k]) > abs(A[p, k]):
                    p = j
            if p != k:
                for c in range(used):
                    A[k, c], A[p, c] = A[p, c], A[k, c]
                b[k], b[p] = b[p], b[k]
            for j in range(k + 1, used):
                m = A[j, k] / A[k, k]
                for c in range(k, used):
                    A[j, c] -= m * A[k, c]
                b[j] -= m * b[k]
        for k in range(used - 1, -1, -1):
            acc = b[k]
            for c in range(k + 1, used):
                acc -= A[k, c] * gamma[c]
            gamma[k] = acc / A[k, k]
        v[:] = tv
        for j in range(0, used, 2):             # two rows a pass: half the passes over v
            ok = _minus_rows(v, dG, gamma, j, min(used - j, 2))
        if ok:
            return True
    v[:] = tv                               # NumPy's solve raised or returned NaN here
    return False


@njit(cache=True)
def anderson_update(v, tv, prev_f, prev_tv, dG, dF, gram, small, state):
    """Anderson's step of :class:`._admm._Anderson` in place (its memory as arrays; ``state``
    = (steps in memory, whether ``prev_f``, ``prev_tv`` hold the last step)): ``v`` becomes
    ``tv`` at first, the result of :func:`anderson_step` after. Returns whether ``v`` is
    extrapolated."""
    m = dG.shape[0]
    if state[1]:
        slot = state[0] % m
        state[0] += 1
        return anderson_step(v, tv, prev_f, prev_tv, dG, dF, gram, small, slot, min(state[0], m))
    for i in range(v.size):
        prev_f[i] = tv[i] - v[i]
        prev_tv[i] = tv[i]
        v[i] = tv[i]
    state[1] = 1
    return False


@njit(cache=True)
def block_matvec(indptr, indices, data, x, q):
    """:math:`q + W x` for W's CSR arrays made of whole 3 x 3 blocks
    (:func:`._ordering._dense_blocks`): each row summed in the order of its columns, as
    :func:`._kernels.csr_matvec` (the same bits), the three rows of a contact at once (one
    column index and three entries of x per block: 0.039 ms on KaplasTower instead of 0.064,
    SciPy's product 0.070, with unsigned index arrays)."""
    nc = (indptr.size - 1) // 3
    y = np.empty(3 * nc)
    for a in range(nc):
        s = np.int64(indptr[3 * a])
        m = np.int64(indptr[3 * a + 1]) - s
        acc0, acc1, acc2 = q[3 * a], q[3 * a + 1], q[3 * a + 2]
        for t in range(s, s + m, 3):
            j = indices[t]
            x0, x1, x2 = x[j], x[j + 1], x[j + 2]
            acc0 = acc0 + data[t] * x0
            acc0 = acc0 + data[t + 1] * x1
            acc0 = acc0 + data[t + 2] * x2
            acc1 = acc1 + data[t + m] * x0
            acc1 = acc1 + data[t + m + 1] * x1
            acc1 = acc1 + data[t + m + 2] * x2
            acc2 = acc2 + data[t + 2 * m] * x0
            acc2 = acc2 + data[t + 2 * m + 1] * x1
            acc2 = acc2 + data[t + 2 * m + 2] * x2
        y[3 * a], y[3 * a + 1], y[3 * a + 2] = acc0, acc1, acc2
    return y


@njit(cache=True)
def power_iteration(indptr, indices, data, v, iterations, blocks):
    """The largest eigenvalue modulus of W by ``iterations`` power iterations from ``v``
    (normalized here), the products by :func:`block_matvec` when ``blocks`` (W made of whole
    3 x 3 blocks), by entries otherwise, in one call."""
    zero = np.zeros(v.size)
    v = v / np.sqrt(np.dot(v, v))
    lam = 0.0
    for _ in range(iterations):
        w = w_product(indptr, indices, data, blocks, v, zero)
        lam = np.sqrt(np.dot(w, w))
        if lam == 0.0:
            return 0.0
        v = w / lam
    return lam


@njit(cache=True)
def rho_change(primal, dual, rho, streak, limits):
    r"""The change of :math:`\rho`'s level asked by the residuals' balance: up (:math:`\rho`
    times ``limits[9]`` per level) when the primal residual exceeds ``limits[2]`` times the
    dual one, down in the opposite case, 0 otherwise. ``streak``: the changes just before,
    signed, each made as soon as allowed and the same way (:func:`rho_streak`); after k >= 2
    of them this one the same way is of :math:`2^{k-1}` levels (at most ``limits[10]``), one
    otherwise: a drift of :math:`\rho` by :math:`2^k` levels costs about k + 2
    factorizations, not :math:`2^k`. Levels that would take :math:`\rho` out of
    ``[limits[7], limits[8]]`` are left out (a change from outside towards it is kept)."""
    lo, hi, step = limits[7], limits[8], limits[9]
    sign = 1 if primal > limits[2] * dual else (-1 if dual > limits[2] * primal else 0)
    if sign == 0:
        return 0
    levels = 1
    if streak * sign >= 2:
        levels = min(np.int64(1) << min(abs(streak) - 1, 30), max(np.int64(limits[10]), 1))
    change = sign * levels
    while change > 1 and rho * step ** change > hi:
        change -= 1
    while change < -1 and rho * step ** change < lo:
        change += 1
    if change > 0 and rho * step > hi and rho >= lo:
        return 0
    if change < 0 and rho / step < lo and rho <= hi:
        return 0
    return change


@njit(cache=True)
def pause_length(pause, dropped, doublings):
    """Anderson's pause after a dropped extrapolation: ``pause`` iterations, doubled for each
    of the ``dropped`` extrapolations dropped before it with none kept between, at most
    ``doublings`` times."""
    return pause << min(dropped, np.int64(doublings))


@njit(cache=True)
def rho_streak(streak, change, consecutive):
    """The streak of :func:`rho_change` after a change ``change`` (nonzero), ``consecutive``
    when it came as soon as allowed after the last one."""
    sign = 1 if change > 0 else -1
    return streak + sign if consecutive and streak * sign > 0 else sign


@njit(cache=True)
def admm_loop(lp, li, lx, up, ui, ux, ud, rows, cols, triples, refine, wp, wi, wx, blocks, q, mu, dil, norm_q,
              rho, eta, x, v, s, safe_v, y, best_r, prev_f, prev_tv, dG, dF, gram, small, astate, ints,
              floats, limits, errs, its):
    r"""ADMM's iterations (:func:`._admm.run_admm`) at one value of :math:`\rho`, compiled,
    each by :func:`admm_iteration`, until one of: ``limits[3]`` (max_iter) iterations in all,
    ``errs.size`` iterations in this call, an error at most ``limits[0]`` (tol), not finite,
    or a new y beyond ``limits[1]`` in norm (the run stops), or a change of :math:`\rho` asked
    by the residuals' balance (:func:`rho_change`; ``limits[4]``: at most every this many
    iterations; the caller refactorizes).

    Siconos' error is measured only at some iterations: where the fixed-point residual
    :math:`|T(v) - v|` is at most tol times :math:`\max(|q|, |y|)` (convergence is possible),
    at the iteration ``ints[4]`` chosen after the last measure by
    :func:`._kernels.check_interval` from the last two measures (at most ``limits[6]``
    iterations later), at the last iteration of the call or of the run, and where y leaves
    the bound. The best y is the best of those measured.

    The run's state is read and written in place: ``x``, ``v = (y, z)``, ``s``, the last
    plain ``safe_v``, the last y and the best one (``y``, ``best_r``), Anderson's memory
    (:func:`anderson_update`; none when ``dG`` has no row; ``limits[5]``: its pause after a
    dropped extrapolation, doubled at most ``limits[11]`` times, :func:`pause_length`),
    ``ints`` = (iteration, iteration of the last change of :math:`\rho`, end of the pause,
    whether v is extrapolated, next measure, iteration of the last measure, the streak of
    :math:`\rho`'s changes (:func:`rho_streak`; ``limits[10]``: the most levels of one), the
    extrapolations dropped with none kept since), ``floats`` = (residual of ``safe_v``, best error, last error measured).
    The errors measured and their iteration numbers go to ``errs`` and ``its``. Returns
    ``(recorded, change)``: change +1 (raise :math:`\rho`), -1 (lower it), 0 (none); the last
    iteration of the call is recorded unless it was a dropped extrapolation or the call ends
    on a change of :math:`\rho`."""
    n = q.size
    it, last_update, paused_until, extrapolated = ints[0], ints[1], ints[2], ints[3] != 0
    next_check, last_it, streak, dropped = ints[4], ints[5], ints[6], ints[7]
    safe_res, best_err, last_err = floats[0], floats[1], floats[2]
    tol, r_bound = limits[0], limits[1]
    max_iter, every, pause = np.int64(limits[3]), np.int64(limits[4]), np.int64(limits[5])
    max_interval = np.int64(limits[6])
    first = it
    hist_err, hist_it = np.empty(2), np.empty(2, np.int64)
    count, change = 0, 0
    work = np.empty(5 * n)
    _, _, x_new, tv = work_views(work, n)
    while it < max_iter and it - first < errs.size:
        it += 1
        measure = it >= next_check or it >= max_iter or it - first >= errs.size
        res, primal, dual, err = admm_iteration(lp, li, lx, up, ui, ux, ud, rows, cols, triples, refine, rho + eta,
                                                wp, wi, wx, blocks, q, mu, dil, rho, eta, x, v, s, norm_q, measure,
                                                work)
        if extrapolated and res > safe_res:     # the extrapolation did not pay: the plain step
            astate[:] = 0
            v[:] = safe_v
            extrapolated = False
            paused_until = it + pause_length(pause, dropped, limits[11])
            dropped += 1
            continue
        if extrapolated:
            dropped = 0
        x[:] = x_new
        y[:] = tv[:n]
        y_norm = np.sqrt(np.dot(y, y))
        if not measure and (res <= tol * max(norm_q, y_norm) or y_norm > r_bound or not np.isfinite(res)):
            measure = True
            err = residual_error(wp, wi, wx, blocks, q, mu, dil, y, norm_q)
        if measure:
            if err < best_err:
                best_r[:] = y
                best_err = err
            errs[count], its[count] = err, it
            count += 1
            if err <= tol or not np.isfinite(err) or y_norm > r_bound:
                break
            hist_err[0], hist_it[0], hist_err[1], hist_it[1] = last_err, last_it, err, it
            next_check = it + K.check_interval(hist_err, hist_it, 2 if last_it > 0 else 1, err, tol, max_interval)
            last_err, last_it = err, it
        if it - last_update >= every and max(primal, dual) > 0:
            consecutive = it - last_update <= every
            change = rho_change(primal, dual, rho, streak if consecutive else 0, limits)
            if change != 0:
                streak = rho_streak(streak, change, consecutive)
                last_update = it
                astate[:] = 0
        safe_v[:] = tv
        safe_res = res
        if dG.shape[0] > 0 and it >= paused_until:
            extrapolated = anderson_update(v, tv, prev_f, prev_tv, dG, dF, gram, small, astate)
        else:
            v[:] = tv
        if change != 0:
            break
    ints[0], ints[1], ints[2], ints[3] = it, last_update, paused_until, np.int64(extrapolated)
    ints[4], ints[5], ints[6], ints[7] = next_check, last_it, streak, dropped
    floats[0], floats[1], floats[2] = safe_res, best_err, last_err
    return count, change
