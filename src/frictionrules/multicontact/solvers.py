r"""Solvers for :class:`~frictionrules.FrictionContactProblem`: ``solve(problem, method=...)``.

* ``"nsgs"`` — non-smooth Gauss–Seidel: sweep the contacts, each solved exactly
  (:func:`._kernels.local_solve`: separation, stick or slip found by enumeration) with the
  others frozen; compiled with Numba.
* ``"newton"`` — semismooth Newton on the Alart–Curnier function
  (:func:`._kernels.alart_curnier`; the normal part uses De Saxcé's modified normal velocity
  :math:`u_N - \mu d|u_T|`, so a non-associated law is one equation), generalized Jacobian
  :math:`J = B_1 + B_2 W` solved by LU (LAPACK dense or SuperLU sparse), non-monotone Armijo
  backtracking on :math:`\tfrac12|\Phi|^2`, Levenberg–Marquardt directions while the
  iteration stalls (singular J), a projection step when the line search fails.
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

    def error(self, r, u=None) -> float:
        """Siconos' error of ``r`` (``u = W r + q`` when not given): see :mod:`.error`."""
        from . import _kernels as K
        u = self.W @ r + self.q if u is None else u
        e = np.sqrt(K.error_sum(r, u, self.mu, self.d))
        scale = max(self.norm_q, np.linalg.norm(r), np.linalg.norm(u))
        return e / scale if scale > np.finfo(float).eps else e


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
#: Levenberg–Marquardt weight relative to |Phi|, and the iterations without halving the merit
#: after which the Newton iteration switches to Levenberg–Marquardt directions.
_LM, _STALL = 1e-6, 4


def _newton_direction(JT, b, eye, lm: bool = False):
    r"""The direction ``x`` of a Newton step ``J x = b``, given ``J^T`` in CSC (J in CSR).

    ``lm=False``: by LU. Up to ``_DENSE_MAX`` unknowns, or when J is denser than
    ``_DENSE_FILL``, LAPACK's dense LU (SuperLU's set-up costs more there); otherwise SuperLU,
    first with the symmetric minimum-degree ordering on diagonal pivots (J has the symmetric
    sparsity of W plus its diagonal, nonzero in every contact state; half the fill of COLAMD
    on the towers), then with partial pivoting. A solve counts when its residual is within
    ``1e-10 |b|``; when none does (J singular), or with ``lm=True``, the Levenberg–Marquardt
    direction :math:`x = \arg\min |J x - b|^2 + \lambda |x|^2`,
    :math:`\lambda = 10^{-6}|b|`, from :math:`(J^T J + \lambda I) x = J^T b`.

    J is singular or nearly so where W is rank-deficient (more contacts than the bodies'
    degrees of freedom: the periodic box, stacks, towers) and contacts stick. With LU
    directions only, the iteration stagnates on LMGC_100_PR_PerioBox (error 4e-2 after 300
    iterations); switching to Levenberg–Marquardt while it stalls gives 6e-9 in 122, and every
    FCLIB file converges.
    """
    import scipy.sparse.linalg as spla
    norm_b = np.linalg.norm(b)
    if norm_b == 0.0:
        return np.zeros_like(b)
    lam = _LM * norm_b
    n = b.shape[0]
    if n <= _DENSE_MAX or JT.nnz > _DENSE_FILL * n * n:
        J = JT.toarray().T
        if not lm:
            try:
                x = np.linalg.solve(J, b)
                if np.all(np.isfinite(x)) and np.linalg.norm(J @ x - b) <= 1e-10 * norm_b:
                    return x
            except np.linalg.LinAlgError:
                pass
        return np.linalg.solve(J.T @ J + lam * np.eye(n), J.T @ b)
    J = JT.T
    for options in () if lm else ({"permc_spec": "MMD_AT_PLUS_A", "diag_pivot_thresh": 0.0}, {}):
        try:
            x = spla.splu(JT, **options).solve(b, trans="T")
        except RuntimeError:
            continue
        if np.all(np.isfinite(x)) and np.linalg.norm(J @ x - b) <= 1e-10 * norm_b:
            return x
    try:
        A = (JT @ J + lam * eye).tocsc()
        return spla.splu(A, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0).solve(JT @ b)
    except RuntimeError:
        return b


def _newton_steps(fr: _Frame, W, q, r, rho, stop, max_iter, on_iter):
    r"""Semismooth Newton iterations on ``(W, q)`` from ``r`` until ``stop(r, u)`` or ``max_iter``.

    Non-monotone Armijo backtracking on :math:`\tfrac12|\Phi|^2`; a projection step when it
    fails. While the merit has not halved over the last ``_STALL`` iterations (a singular or
    ill-conditioned J), the direction is the Levenberg–Marquardt one (see
    :func:`_newton_direction`); once it falls again, Newton's. (Kept for the whole run instead,
    it slows spheres-in-a-box from 41 to 120 iterations.) ``on_iter(r, u)`` is called after
    every iteration; returns ``(r, iterations)``.
    """
    import scipy.sparse as sp

    from . import _kernels as K
    n = 3 * fr.nc
    eye = sp.identity(n, format="csc")
    Wp, Wi = W.indptr.astype(np.int32), W.indices.astype(np.int32)
    u = W @ r + q
    phi, B1, B2 = K.alart_curnier(r, u, fr.mu, fr.d, rho)
    merit = 0.5 * float(phi @ phi)
    merits = [merit]  # the last 10 give the non-monotone (Grippo-Lampariello-Lucidi) reference
    lm = False
    it = 0
    while it < max_iter and not stop(r, u):
        it += 1
        jptr, jind, jdat = K.jacobian_csr(Wp, Wi, W.data, B1, B2)
        # the CSR arrays of J are the CSC arrays of J^T: factorize J^T, solve with trans="T"
        JT = sp.csc_matrix((jdat, jind, jptr), shape=(n, n))
        JT.has_sorted_indices = True
        dx = _newton_direction(JT, -phi, eye, lm)
        reference = max(merits[-10:])
        alpha, accepted = 1.0, False
        while alpha > 1e-8:
            rn = r + alpha * dx
            un = W @ rn + q
            phin, B1n, B2n = K.alart_curnier(rn, un, fr.mu, fr.d, rho)
            mn = 0.5 * float(phin @ phin)
            if mn <= reference - 2e-4 * alpha * merit:
                accepted = True
                break
            alpha *= 0.5
        if not accepted:  # projection (fixed-point) step r <- psi(r) = r - Phi(r)
            rn = r - phi
            un = W @ rn + q
            phin, B1n, B2n = K.alart_curnier(rn, un, fr.mu, fr.d, rho)
            mn = 0.5 * float(phin @ phin)
        r, u, phi, B1, B2, merit = rn, un, phin, B1n, B2n, mn
        merits.append(merit)
        lm = len(merits) > _STALL and merit > 0.5 * merits[-1 - _STALL]
        on_iter(r, u)
    return r, it


def _newton(fr: _Frame, r, tol, max_iter, history):
    rho = _rho(fr, fr.W)
    state = {"err": fr.error(r), "k": 0}

    def on_iter(r, u):
        state["err"] = fr.error(r, u)
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

    err = fr.error(r)
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
            return fr.error(rr, uu - sigma * (rr - rk)) <= tol

        r_new, _ = _newton_steps(fr, Ws, qs, r.copy(), rho, stop, _PROX_INNER_MAX, lambda rr, uu: None)
        err_new = fr.error(r_new)
        if err_new < err:
            sigma *= _PROX_SHRINK
        else:
            sigma *= 4.0
        r, err = r_new, err_new
        history[it - 1] = err
    return r, it, err, np.arange(1, it + 1)


#: Proximal point: initial sigma / mean diag(W), its factor after a successful outer step, the
#: inner tolerance relative to the outer error, and the inner Newton steps at most. Chosen on
#: the FCLIB files (outer iterations / factorizations, 0.3-0.03-0.03 against 0.1-0.1-0.1):
#: local_problem_test 6/19 vs 9/34, Capsules 4/16 vs 5/21, KaplasTower 5/8 vs 6/10, PerioBox
#: 4/15 vs 5/11, spheres-in-a-box 7/50 vs 27/241. The schedule is sensitive: sigma0 = 0.5
#: fails on Capsules, an inner tolerance of 0.05 takes 81 outer iterations on spheres-in-a-box.
_PROX_SIGMA0, _PROX_SHRINK, _PROX_INNER, _PROX_INNER_MAX = 0.3, 0.03, 0.03, 10

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
