r"""The O(nc) arithmetic of one ADMM iteration (:mod:`._admm`), compiled.

Each function does in one call what the iteration did in NumPy expressions, the same
operations in the same order on every entry (the same bits; only the residual's sum of
squares is summed in order where NumPy's dot blocked it). The NumPy version cost about
0.2 ms of Python per iteration on KaplasTower (570 contacts; 5 iterations and 12.6 ms per
solve), beside the 0.2 ms of the triangular solves and 0.08 ms of the error.
"""

from __future__ import annotations

import numpy as np

from .._optional import require
from . import _kernels as K

njit = require("numba", extra="kernels").njit


@njit(cache=True)
def x_step_rhs(q, y, x, z, mu, dil, rho, eta, s):
    r"""De Saxcé's correction ``s`` of the dual variable z (into ``s``) and the right-hand
    side :math:`-(q + s) + \rho y + \eta x + z` of the x-step."""
    K.desaxce_shift(z, mu, dil, s)
    b = np.empty(q.size)
    for i in range(q.size):
        b[i] = -(q[i] + s[i]) + rho * y[i] + eta * x[i] + z[i]
    return b


@njit(cache=True)
def y_z_steps(x_new, x, v, mu, rho, eta):
    r"""From the x-step's ``x_new`` (``x`` the previous one, ``v = (y, z)``): the next
    :math:`(y, z)` as one array, :math:`y = P_K(x_{new} - z/\rho)`,
    :math:`z - \rho (x_{new} - y)`; the fixed-point residual :math:`|T(v) - v|`, the primal
    residual :math:`|x_{new} - y|_\infty` and the dual one
    :math:`|\rho\,\Delta y + \eta\,\Delta x|_\infty` (NaN when an entry is)."""
    n = x_new.size
    tv = np.empty(2 * n)
    w = np.empty(n)
    for i in range(n):
        w[i] = x_new[i] - v[n + i] / rho
    K.project_all(w, mu, tv[:n])
    res, primal, dual, nan = 0.0, 0.0, 0.0, False
    for i in range(n):
        y_new = tv[i]
        tv[n + i] = v[n + i] - rho * (x_new[i] - y_new)
        p = abs(x_new[i] - y_new)
        d = abs(rho * (y_new - v[i]) + eta * (x_new[i] - x[i]))
        nan = nan or np.isnan(p) or np.isnan(d)
        primal, dual = max(primal, p), max(dual, d)
        res += (y_new - v[i]) ** 2 + (tv[n + i] - v[n + i]) ** 2
    if nan:
        primal = dual = np.nan
    return tv, np.sqrt(res), primal, dual


@njit(cache=True)
def anderson_push(v, tv, prev_v, prev_tv, dG, dF):
    r"""The new differences of Anderson's memory: :math:`\Delta G = T(v) - T(v')`,
    :math:`\Delta F = (T(v) - v) - (T(v') - v')` (into ``dG``, ``dF``)."""
    for i in range(v.size):
        dG[i] = tv[i] - prev_tv[i]
        dF[i] = (tv[i] - v[i]) - (prev_tv[i] - prev_v[i])


@njit(cache=True)
def anderson_mix(F, G, v, tv):
    r"""Type-II Anderson's extrapolation :math:`T(v) - \gamma G` with
    :math:`(F F^T + 10^{-14} \mathrm{tr}(F F^T) I)\,\gamma = F (T(v) - v)`, and whether it is
    finite (``tv`` itself when the system is not)."""
    f = tv - v
    A = F @ F.T
    b = F @ f
    tr = np.trace(A)
    if not (np.isfinite(tr) and tr > 0.0 and np.all(np.isfinite(b))):
        return tv, False                    # NumPy's solve raised or returned NaN here
    gamma = np.linalg.solve(A + 1e-14 * tr * np.eye(A.shape[0]), b)
    out = tv - gamma @ G
    if not np.all(np.isfinite(out)):
        return tv, False
    return out, True


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
        w = block_matvec(indptr, indices, data, v, zero) if blocks else K.csr_matvec(indptr, indices, data, v,
                                                                                       zero)
        lam = np.sqrt(np.dot(w, w))
        if lam == 0.0:
            return 0.0
        v = w / lam
    return lam
