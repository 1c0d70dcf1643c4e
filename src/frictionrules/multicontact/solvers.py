r"""Solvers for :class:`~frictionrules.FrictionContactProblem`: ``solve(problem, method=...)``.

* ``"nsgs"`` — non-smooth Gauss–Seidel: sweep the contacts, each solved exactly
  (:func:`._kernels.local_solve`: separation, stick or slip found by enumeration) with the
  others frozen; compiled with Numba.
* ``"newton"`` — semismooth Newton on the natural map
  :math:`\Phi(r) = r - P_K(r - \rho\hat u(r))` (De Saxcé's modified velocity, so the
  non-associated law is one equation), generalized Jacobian
  :math:`J = (I - G) + \rho G (I + E) W` factorized with SuperLU, Armijo backtracking on
  :math:`\tfrac12|\Phi|^2`, a projection step when the Newton step fails.
* ``"prox"`` — proximal point: :math:`r_{k+1}` solves the problem with
  :math:`W + \sigma I`, :math:`q - \sigma r_k` (better conditioned, unique solution), each by a
  few semismooth Newton steps; :math:`\sigma` shrinks while the outer error falls.
  It is the fastest on the badly conditioned problems (stacks, towers), as Siconos' PROX is.

Every method stops when Siconos' error (:func:`.error.fc3d_error`) is at most ``tol``.
"""

from __future__ import annotations

import time

import numpy as np

from ..errors import FrictionRulesError, check_finite, check_scalar
from .problem import FrictionContactProblem, Solution

__all__ = ["solve", "METHODS"]

#: Method names accepted by :func:`solve`, with their default ``max_iter``.
METHODS = {"nsgs": 10000, "newton": 200, "prox": 200}


class _Frame:
    """The problem in its circular frame, as arrays the kernels take."""

    def __init__(self, problem: FrictionContactProblem):
        Wt, qt, P = problem._solver_frame()
        self.W, self.q, self.P = Wt, np.ascontiguousarray(qt, dtype=float), P
        self.mu = np.ascontiguousarray(problem.mu_bar, dtype=float)
        self.d = np.ascontiguousarray(problem.dilatancy, dtype=float)
        self.nc = problem.nc
        self.norm_q = float(np.linalg.norm(self.q))
        self.csr = (self.W.indptr.astype(np.int32), self.W.indices.astype(np.int32), self.W.data)


def _nsgs(fr: _Frame, r, tol, max_iter, history):
    from . import _kernels as K
    D = K.diagonal_blocks(*fr.csr, fr.nc)
    hist_it = np.zeros(max_iter, dtype=np.int64)
    it, err, nh = K.nsgs(*fr.csr, D, fr.q, fr.mu, fr.d, r, tol, max_iter, history, hist_it, fr.norm_q)
    return r, it, err, hist_it[:nh]


def _rho(fr: _Frame, W):
    from . import _kernels as K
    D = K.diagonal_blocks(W.indptr.astype(np.int32), W.indices.astype(np.int32), W.data, fr.nc)
    tr = np.abs(np.trace(D, axis1=1, axis2=2)) / 3.0
    return np.where(tr > 0, 1.0 / np.where(tr > 0, tr, 1.0), 1.0)


#: J is solved dense (LAPACK) up to this many unknowns, or above this fraction of nonzeros.
_DENSE_MAX, _DENSE_FILL = 400, 0.2


def _lu_solve(JT, b, eye):
    """Solve ``J x = b`` (LAPACK or SuperLU), given ``J^T`` in CSC (that is, J in CSR).

    Up to ``_DENSE_MAX`` unknowns, or when J is denser than ``_DENSE_FILL``, LAPACK's dense
    LU is used (SuperLU's set-up costs more there). Otherwise: J has the (symmetric) sparsity
    of W plus its diagonal, which is nonzero for every contact state, so the symmetric
    minimum-degree ordering on diagonal pivots is tried first (half the
    fill of COLAMD with partial pivoting on the towers); if its residual is poor, partial
    pivoting; if J is singular, a tiny diagonal shift; failing all, the steepest step ``b``.
    """
    import scipy.sparse.linalg as spla
    norm_b = np.linalg.norm(b)
    n = b.shape[0]
    if n <= _DENSE_MAX or JT.nnz > _DENSE_FILL * n * n:
        # small or dense J: LAPACK's LU beats SuperLU's set-up (prox on local_problem_test:
        # 0.020 s -> 0.014 s); a (nearly) singular J falls through to the sparse path
        J = JT.toarray().T
        try:
            x = np.linalg.solve(J, b)
        except np.linalg.LinAlgError:
            x = None
        if x is not None and np.all(np.isfinite(x)) and np.linalg.norm(J @ x - b) <= 1e-10 * norm_b:
            return x
    try:
        x = spla.splu(JT, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0).solve(b, trans="T")
        if np.all(np.isfinite(x)) and np.linalg.norm(JT.T @ x - b) <= 1e-10 * norm_b:
            return x
    except RuntimeError:
        pass
    for A in (JT, (JT + 1e-10 * max(1.0, abs(JT).max()) * eye).tocsc()):
        try:
            x = spla.splu(A).solve(b, trans="T")
        except RuntimeError:
            continue
        if np.all(np.isfinite(x)):
            return x
    return b


def _newton_steps(fr: _Frame, W, q, r, rho, stop, max_iter, on_iter):
    """Semismooth Newton iterations on ``(W, q)`` from ``r`` until ``stop(r, u)`` or ``max_iter``.

    ``on_iter(r, u)`` returns the error to record; returns ``(r, iterations)``.
    """
    import scipy.sparse as sp

    from . import _kernels as K
    n = 3 * fr.nc
    eye = sp.identity(n, format="csc")
    Wp, Wi = W.indptr.astype(np.int32), W.indices.astype(np.int32)
    u = W @ r + q
    phi, B1, B2 = K.alart_curnier(r, u, fr.mu, fr.d, rho)
    merit = 0.5 * float(phi @ phi)
    recent = [merit]  # non-monotone Armijo (Grippo-Lampariello-Lucidi) over the last 10 merits
    it = 0
    while it < max_iter and not stop(r, u):
        it += 1
        jptr, jind, jdat = K.jacobian_csr(Wp, Wi, W.data, B1, B2)
        # the CSR arrays of J are the CSC arrays of J^T: factorize J^T, solve with trans="T"
        JT = sp.csc_matrix((jdat, jind, jptr), shape=(n, n))
        JT.has_sorted_indices = True
        dx = _lu_solve(JT, -phi, eye)
        alpha, accepted = 1.0, False
        while alpha > 1e-8:
            rn = r + alpha * dx
            un = W @ rn + q
            phin, B1n, B2n = K.alart_curnier(rn, un, fr.mu, fr.d, rho)
            mn = 0.5 * float(phin @ phin)
            if mn <= max(recent) - 2e-4 * alpha * merit:
                accepted = True
                break
            alpha *= 0.5
        if not accepted:  # projection (fixed-point) step r <- psi(r) = r - Phi(r)
            rn = r - phi
            un = W @ rn + q
            phin, B1n, B2n = K.alart_curnier(rn, un, fr.mu, fr.d, rho)
            mn = 0.5 * float(phin @ phin)
        r, u, phi, B1, B2, merit = rn, un, phin, B1n, B2n, mn
        recent = recent[-9:] + [merit]
        on_iter(r, u)
    return r, it


def _newton(fr: _Frame, r, tol, max_iter, history):
    from . import _kernels as K
    rho = _rho(fr, fr.W)
    state = {"err": np.inf, "k": 0}

    def error(r, u):
        err = np.sqrt(K.error_sum(r, u, fr.mu, fr.d))
        scale = max(fr.norm_q, np.linalg.norm(r), np.linalg.norm(u))
        return err / scale if scale > np.finfo(float).eps else err

    state["err"] = error(r, fr.W @ r + fr.q)

    def on_iter(r, u):
        state["err"] = error(r, u)
        history[state["k"]] = state["err"]
        state["k"] += 1

    r, it = _newton_steps(fr, fr.W, fr.q, r, rho, lambda r, u: state["err"] <= tol, max_iter, on_iter)
    return r, it, state["err"], np.arange(1, it + 1)


def _prox(fr: _Frame, r, tol, max_iter, history):
    import scipy.sparse as sp

    from . import _kernels as K
    n = 3 * fr.nc
    diag = np.abs(fr.W.diagonal())
    sigma = _PROX_SIGMA0 * (float(np.mean(diag[diag > 0])) if np.any(diag > 0) else 1.0)
    eye = sp.identity(n, format="csr")

    def error(r, u=None):
        u = fr.W @ r + fr.q if u is None else u
        e = np.sqrt(K.error_sum(r, u, fr.mu, fr.d))
        scale = max(fr.norm_q, np.linalg.norm(r), np.linalg.norm(u))
        return e / scale if scale > np.finfo(float).eps else e

    err = error(r)
    it = 0
    while it < max_iter and err > tol:
        it += 1
        Ws = (fr.W + sigma * eye).tocsr()
        qs = fr.q - sigma * r
        rho = _rho(fr, Ws)
        inner_tol = max(0.1 * tol, _PROX_INNER * err)

        def stop(rr, uu, qs=qs, rk=r, sigma=sigma):
            e = np.sqrt(K.error_sum(rr, uu, fr.mu, fr.d))
            if e <= inner_tol * max(np.linalg.norm(qs), np.linalg.norm(rr), np.linalg.norm(uu), 1e-300):
                return True
            # the outer problem's own error: u = W r + q = (Ws r + qs) - sigma (r - r_k); once it
            # is within tol, further inner steps are wasted
            return error(rr, uu - sigma * (rr - rk)) <= tol

        r_new, _ = _newton_steps(fr, Ws, qs, r.copy(), rho, stop, _PROX_INNER_MAX, lambda rr, uu: None)
        err_new = error(r_new)
        if err_new < err:
            sigma *= _PROX_SHRINK
        else:
            sigma *= 4.0
        r, err = r_new, err_new
        history[it - 1] = err
    return r, it, err, np.arange(1, it + 1)


#: Proximal point: initial sigma / mean diag(W), its factor after a successful outer step, and
#: the inner tolerance relative to the outer error.
_PROX_SIGMA0, _PROX_SHRINK, _PROX_INNER, _PROX_INNER_MAX = 0.1, 0.1, 0.1, 10

_SOLVERS = {"nsgs": _nsgs, "newton": _newton, "prox": _prox}


def solve(problem: FrictionContactProblem, method: str = "nsgs", tol: float = 1e-8,
          max_iter: int | None = None, r0=None) -> Solution:
    r"""Solve a frictional contact problem; the error is Siconos' (see :mod:`.error`).

    Parameters
    ----------
    problem : FrictionContactProblem
    method : {"nsgs", "newton", "prox"}
        See the module docstring.
    tol : float
        Stop when :func:`~frictionrules.multicontact.fc3d_error` ``<= tol``.
    max_iter : int, optional
        Sweeps (nsgs), Newton iterations (newton) or outer proximal iterations (prox);
        defaults ``METHODS[method]``.
    r0 : (3 nc,) array, optional
        Initial reactions (zero by default).

    Returns
    -------
    Solution
        ``converged`` is ``error <= tol``; ``history[k]`` the error after iteration
        ``history_iterations[k]`` (every iteration for newton and prox; NSGS evaluates the full
        error only after the sweeps where it may have converged, see ``_kernels.nsgs``).
    """
    if not isinstance(problem, FrictionContactProblem):
        raise FrictionRulesError(f"problem = {problem!r} is not a FrictionContactProblem")
    if method not in _SOLVERS:
        raise FrictionRulesError(f"method = {method!r}; constraint: one of {sorted(_SOLVERS)}")
    tol = check_scalar("tol", tol, lo=0.0)
    max_iter = METHODS[method] if max_iter is None else int(check_scalar("max_iter", max_iter, lo=1))
    n = 3 * problem.nc
    fr = _Frame(problem)
    if r0 is None:
        r = np.zeros(n)
    else:
        r = check_finite("r0", r0).ravel().astype(float)
        if r.size != n:
            raise FrictionRulesError(f"r0 has {r.size} entries; constraint: 3 nc = {n}")
        if fr.P is not None:
            import scipy.sparse.linalg as spla
            r = spla.spsolve(fr.P.tocsc(), r)
    history = np.full(max_iter, np.nan)
    t0 = time.perf_counter()
    r, it, _err, hist_it = _SOLVERS[method](fr, np.ascontiguousarray(r), tol, max_iter, history)
    seconds = time.perf_counter() - t0
    r = r if fr.P is None else fr.P @ r
    u = problem.velocity(r)
    from .error import fc3d_error
    err = fc3d_error(problem, r, u)
    return Solution(r=r, u=u, error=err, iterations=int(it), converged=bool(err <= tol),
                    history=history[:hist_it.size].copy(), history_iterations=hist_it,
                    method=method, seconds=seconds)
