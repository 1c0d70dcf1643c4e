r"""Semismooth Newton on the law path's natural map (``method="polish"`` on the law path, and
the second stage of its ``"auto"``).

With each contact's metric ``K_a`` (:func:`._law_path.metric_rows`) and trial weight
:math:`\omega_a` (held for the step), the map :math:`R(r) = r - P(r - \Omega K(Wr + q))` has the
generalized Jacobian

.. math:: J = I - \partial P\,(I - \Omega K W),

:math:`\partial P` block-diagonal from each law's consistent tangent of its return
(:func:`._law_kernels.law_linearization`): each contact's regime (open, stick, slide) read
from the iterate and held for one step, Newton's method on a smooth system once the regimes
have settled. ``J`` is assembled sparse and solved by SuperLU; a step is kept when it lowers
the law error (:func:`._law_path.law_error`), halved up to ``HALVINGS`` times; where no step
of a direction does, the direction of :math:`J + \sigma I` with the next shift of ``SHIFTS``
is tried, and the stage stops when none does.
"""

from __future__ import annotations

import numpy as np

#: Step halvings of a direction, and the relative diagonal shifts of J tried in turn until a
#: direction lowers the error (a singular or nearly singular J: sticking contacts of a
#: rank-deficient W, whose null-space components a small shift leaves huge).
HALVINGS, SHIFTS = 6, (0.0, 1e-10, 1e-7, 1e-4)


def polish(problem, ls, rows_k, r, tol, steps, error, record, ws):
    """Up to ``steps`` Newton steps from ``r`` (not modified); ``error(r)`` the law error,
    ``record(r, err)`` called after each kept step (true: stop). Returns ``(r, err, steps
    taken, stopped by record)``."""
    import scipy.sparse as sp
    import scipy.sparse.linalg as spla

    from ..contact.layout import LAW_KN, LAW_KT
    from . import _law_kernels as K
    nc, n = problem.nc, 3 * problem.nc
    W, q = problem.W, problem.q
    kd = np.empty(n)
    kd[0::3] = rows_k[:, LAW_KN]
    kd[1::3] = rows_k[:, LAW_KT]
    kd[2::3] = rows_k[:, LAW_KT]
    R, DP, om = np.empty(n), np.empty((nc, 3, 3)), np.empty(nc)
    I = sp.identity(n, format="csr")
    err = error(r)
    taken = 0
    for _ in range(steps):
        if err <= tol:
            break
        K.law_linearization(ls.fn, rows_k, ls.ell, r, W @ r + q, ws, R, DP, om)
        B = sp.bsr_matrix((DP, np.arange(nc), np.arange(nc + 1)), shape=(n, n)).tocsr()
        J = (I - B + B @ sp.diags(np.repeat(om, 3) * kd) @ W).tocsc()
        kept = False
        for shift in SHIFTS:
            d = _solve(J, -R, shift, spla, sp)
            if d is None:
                continue
            t = 1.0
            for _h in range(HALVINGS + 1):
                trial = r + t * d
                e = error(trial)
                if e < err:
                    kept = True
                    break
                t *= 0.5
            if kept:
                break
        if not kept:
            break
        r, err = trial, e
        taken += 1
        if record(r, err):
            return r, err, taken, True
    return r, err, taken, False


def _solve(J, b, shift, spla, sp):
    r""":math:`(J + \sigma I)^{-1} b`, :math:`\sigma` = ``shift`` times the largest diagonal
    entry of J (at least 1); None where singular or not finite."""
    import warnings
    scale = shift * max(abs(J.diagonal()).max(), 1.0)
    A = J if shift == 0.0 else (J + scale * sp.identity(J.shape[0])).tocsc()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            x = spla.spsolve(A, b)
        except RuntimeError:
            return None
    return x if np.all(np.isfinite(x)) else None
