r"""The small-problem path of :func:`~frictionrules.solve`: up to :data:`SMALL_MAX` contacts,
the whole solve in one compiled call.

A physics step, a calibration or a sweep over thousands of small problems pays a solver's
set-up at every call; here the set-up (diagonal blocks, norms), the iterations and the final
error run inside one Numba function on W's CSR arrays, so that a call costs the Python
argument checks, one compiled call and the :class:`Solution` record (``benchmarks/fclib.py``
measures it). ``nsgs`` runs the same sweeps as the general path; ``polish`` and ``auto`` take
dense Newton steps on the natural map (:func:`._kernels.natural_map`) with NumPy's least-squares
solve (the minimum-norm step where J is singular). ``auto`` runs at most ``AUTO_PROBE`` sweeps,
the polish, then sweeps to the end of its budget and the polish again.
"""

from __future__ import annotations

import numpy as np

from .._optional import require
from . import _kernels as K
from ._frame import UNBOUNDED
from ._options import PolishOptions

njit = require("numba", extra="kernels").njit

#: Largest number of contacts solved by the small path.
SMALL_MAX = 16
#: Sweeps before the first polish of ``auto`` (the general path's probe).
AUTO_PROBE = 50
#: Modes of :func:`small_solve`, and the stages ``auto`` may run.
MODES = {"nsgs": 0, "polish": 1, "auto": 2}
STAGES = ("nsgs", "polish")
#: The polish schedule of ``auto`` and ``nsgs`` on this path.
POLISH_DEFAULTS = PolishOptions()


def r_bound(problem) -> float:
    """The reactions' bound of :data:`._frame.UNBOUNDED` for this problem."""
    diag = np.abs(problem.W.diagonal())
    mean_diag = float(np.mean(diag[diag > 0])) if np.any(diag > 0) else 1.0
    return UNBOUNDED * max(float(np.linalg.norm(problem.q)), np.finfo(float).tiny) / mean_diag


@njit(cache=True)
def _error(indptr, indices, data, q, mu, dil, r, norm_q):
    err, u = K.fc3d_error_kernel(indptr, indices, data, q, mu, dil, r, norm_q)
    return err, u


@njit(cache=True)
def _polish(indptr, indices, data, q, mu, dil, r, tol, max_iter, norm_q, hist_err, hist_it, nh, offset,
            contraction, patience, max_halvings):
    """Dense Newton steps on the natural map (see :mod:`._polish`); returns ``(steps, error, nh)``."""
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
    err, u = _error(indptr, indices, data, q, mu, dil, r, norm_q)
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
        dx = np.linalg.lstsq(J, -phi, -1.0)[0]
        alpha = 1.0
        accepted = False
        for _ in range(max_halvings + 1):
            rn = r + alpha * dx
            en, un = _error(indptr, indices, data, q, mu, dil, rn, norm_q)
            if en < err:
                accepted = True
                break
            alpha *= 0.5
        if not accepted:
            break
        it += 1
        slow = slow + 1 if en > contraction * err else 0
        r[:] = rn
        u, err = un, en
        hist_err[nh] = err
        hist_it[nh] = offset + it
        nh += 1
        if slow >= patience:
            break
    return it, err, nh


@njit(cache=True)
def small_solve(indptr, indices, data, q, mu, dil, r, tol, max_iter, mode, contraction, patience, max_halvings):
    """Solve in place from ``r``: mode 0 nsgs, 1 polish, 2 auto (see the module docstring).

    Returns ``(iterations, error, history errors, history iterations, stages)``; ``stages`` is
    the sequence of stages run (0 nsgs, 1 polish), -1 after the last.
    """
    nc = mu.size
    norm_q = np.sqrt(np.sum(q * q))
    hist_err = np.empty(max_iter + 4)
    hist_it = np.empty(max_iter + 4, dtype=np.int64)
    stages = np.full(4, -1, dtype=np.int64)
    D = K.diagonal_blocks(indptr, indices, data, nc)
    nh, done, err = 0, 0, np.inf
    if mode == 0:
        done, err, nh = K.nsgs(indptr, indices, data, D, q, mu, dil, r, tol, max_iter, hist_err, hist_it, norm_q, 16)
        stages[0] = 0
        return done, err, hist_err[:nh], hist_it[:nh], stages
    if mode == 1:
        done, err, nh = _polish(indptr, indices, data, q, mu, dil, r, tol, max_iter, norm_q, hist_err, hist_it, 0, 0,
                                contraction, patience, max_halvings)
        if nh == 0:
            hist_err[0], hist_it[0], nh = err, 0, 1
        stages[0] = 1
        return done, err, hist_err[:nh], hist_it[:nh], stages
    ns = 0
    budget = min(AUTO_PROBE, max_iter)
    for stage in range(4):
        if stage % 2 == 0:
            it, err, k = K.nsgs(indptr, indices, data, D, q, mu, dil, r, tol, budget, hist_err[nh:], hist_it[nh:],
                                norm_q, 16)
            for j in range(nh, nh + k):
                hist_it[j] += done
        else:
            it, err, k = _polish(indptr, indices, data, q, mu, dil, r, tol, budget, norm_q, hist_err, hist_it, nh,
                                 done, contraction, patience, max_halvings)
            k -= nh
        stages[ns] = stage % 2
        ns += 1
        nh += k
        done += it
        budget = max_iter - done
        if err <= tol or budget <= 0:
            break
    return done, err, hist_err[:nh], hist_it[:nh], stages
