r"""The polish stage (``method="polish"``, and the last stage of ``"auto"``): semismooth Newton
on De Saxcé's natural map from a first-order iterate whose active set has settled.

Each contact's piece of the cone projection (open, stick, slip; :func:`._kernels.natural_map`)
is read from the current iterate and held while one Newton step on
:math:`\Phi(r) = r - P_K(r - \rho\hat u)` is taken: on a settled active set this is Newton's
method on a smooth system, quadratically convergent, and the pieces are read again after every
step (which makes it the semismooth Newton method). The step is kept when it lowers Siconos'
error (halved otherwise, :class:`PolishOptions`); the stage stops as ``"stalled"`` when no
step lowers it or when the error has not contracted by ``PolishOptions.contraction`` for
``PolishOptions.patience`` steps: the active set has not settled (the first-order method must
go on) or the problem with that active set has no solution to that precision.

An iteration costs one sparse LU of :math:`J = B_1 + B_2 W` (the sparsity of W with its
diagonal blocks: the contacts' minimum-degree ordering, :func:`._ordering.frame_ordering`,
diagonal pivots in symmetric mode) and O(nnz(W)) besides. J is singular where W is (more
contact unknowns than the bodies' degrees of freedom) and contacts stick; there the direction
solves the consistent singular system by iterated Lavrentiev regularization, :math:`(J + \sigma I)
\delta_{k+1} = b - J\delta_k + \sigma\delta_k`, which leaves the null-space components of the
step at zero.
"""

from __future__ import annotations

import numpy as np

from ._frame import _Frame, _Monitor
from ._options import PolishOptions


def _lu(J, sigma: float, dense: bool, perm=None):
    """A solver of ``(J + sigma I) x = b`` (J in CSR) from one LU (LAPACK dense, or SuperLU on
    diagonal pivots in symmetric mode, after the contacts' ordering ``perm`` when given), or
    None when the matrix is singular to working precision."""
    import scipy.sparse as sp
    if perm is not None and not dense:
        from ._ordering import ordered_lu
        try:
            return ordered_lu(J.indptr, J.indices, J.data, perm, sigma)
        except RuntimeError:    # an exactly zero pivot
            return None
    if dense:
        # LAPACK's getrf and getrs themselves (SciPy's lu_factor and lu_solve call them, with
        # 60 and 7 us of checks a call on 144 unknowns); the shift added to the dense copy
        from scipy.linalg import lapack
        A = J.toarray()
        A[np.diag_indices_from(A)] += sigma
        lu, piv, _info = lapack.dgetrf(A, overwrite_a=True)
        if not np.all(np.isfinite(lu)) or np.min(np.abs(np.diag(lu))) == 0.0:
            return None
        return lambda b: lapack.dgetrs(lu, piv, b)[0]
    A = J + sigma * sp.identity(J.shape[0], format="csr") if sigma else J
    import scipy.sparse.linalg as spla
    try:
        lu = spla.splu(A.tocsc(), permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                       options={"SymmetricMode": True})
    except RuntimeError:        # an exactly zero pivot
        return None
    return lu.solve


def polish_direction(J, b, opts: PolishOptions, rtol: float | None = None, perm=None):
    r"""A Newton direction ``x`` with :math:`|J x - b| \le` ``rtol`` :math:`|b|` (J in CSR;
    ``rtol`` defaults to ``opts.direction_rtol``; ``perm``: the contacts' ordering,
    :func:`._ordering.frame_ordering`, for the sparse LU).

    Iterated Lavrentiev regularization: one LU of :math:`J + \sigma I`, :math:`\sigma = `
    ``opts.regularization`` :math:`\max|J_{ii}|`, and up to ``opts.refinement_steps`` steps
    :math:`x \leftarrow x + (J + \sigma I)^{-1}(b - J x)` (stopped when a step does not halve
    the residual: the best step so far is returned); only if that LU fails, or its step is
    not finite, the same with a thousand times :math:`\sigma`. A refinement that stalls above
    ``rtol``, or spends its steps, keeps its best step: a second shift there costs another LU,
    and changed no polish run on the shared files or the piles beyond round-off. Where J is
    nearly singular (sticking contacts of a rank-deficient W) the components of the step
    along its smallest eigenvalues stay small, where a plain LU solve puts huge ones (steps of
    2e6 against reactions of 1.6e5 on PerioBox; the plain-LU polish stalled on
    local_problem_test from 5e-5, this one reaches 1e-14 in three steps). Returns
    ``(x, relative residual)``.
    """
    n = b.size
    norm_b = float(np.linalg.norm(b))
    rtol = opts.direction_rtol if rtol is None else rtol
    if norm_b == 0.0:
        return np.zeros(n), 0.0
    dense = n <= opts.dense_max
    best, best_res = np.zeros(n), 1.0
    sigma0 = opts.regularization * float(np.max(np.abs(J.diagonal())) or 1.0)
    for sigma in (sigma0, 1e3 * sigma0):
        solve = _lu(J, sigma, dense, perm)
        if solve is None:
            continue                        # singular: the larger shift
        x, last, resid = np.zeros(n), np.inf, b
        for _ in range(opts.refinement_steps + 1):
            x = x + solve(resid)
            if not np.all(np.isfinite(x)):
                break                       # a step not finite: the larger shift
            resid = b - J @ x
            res = float(np.linalg.norm(resid)) / norm_b
            if res < best_res:
                best, best_res = x.copy(), res
            if res <= rtol or res > 0.5 * last:
                return best, best_res
            last = res
        else:
            return best, best_res           # the refinement's steps spent
    return best, best_res


def run_polish(fr: _Frame, r, max_iter: int, mon: _Monitor, opts: PolishOptions):
    """Polish iterations from ``r``; returns ``(r, iterations)`` (``mon.reason`` is
    ``"stalled"`` when the stage gave up)."""
    import scipy.sparse as sp

    from . import _kernels as K
    from ._ordering import frame_ordering
    W, q = fr.W, fr.q
    n = q.size
    perm = frame_ordering(fr) if n > opts.dense_max else None
    rho = fr.rho()
    Wp, Wi = fr.csr[0], fr.csr[1]
    r = np.array(r, dtype=float)
    u = W @ r + q
    err = fr.error(r, u)
    if err <= mon.tol:
        mon.record("polish", 0, r, err)
        return r, 0
    slow = 0
    for it in range(1, max_iter + 1):
        phi, B1, B2, _pieces = K.natural_map(r, u, fr.mu, fr.d, rho)
        jptr, jind, jdat = K.jacobian_csr(Wp, Wi, W.data, B1, B2)
        J = sp.csr_matrix((jdat, jind, jptr), shape=(n, n))
        # an inexact Newton direction: a residual of the order of the error squared keeps the rate
        dx, _res = polish_direction(J, -phi, opts, max(opts.direction_rtol, min(1e-6, err * err)), perm)
        alpha = 1.0
        for _ in range(opts.max_halvings + 1):
            rn = r + alpha * dx
            un = W @ rn + q
            en = fr.error(rn, un)
            if en < err:
                break
            alpha *= 0.5
        else:
            mon.reason = "stalled"
            return r, it - 1
        slow = slow + 1 if en > opts.contraction * err else 0
        r, u, err = rn, un, en
        if mon.record("polish", it, r, err):
            return r, it
        if slow >= opts.patience:
            mon.reason = "stalled"
            return r, it
    return r, max_iter
