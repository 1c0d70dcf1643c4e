r"""Semismooth Newton on the Alart–Curnier function (``method="newton"``; the inner solver of
``"prox"``).

:func:`._kernels.alart_curnier` gives :math:`\Phi` and the blocks of the generalized Jacobian
:math:`J = B_1 + B_2 W` (the normal part uses De Saxcé's modified normal velocity
:math:`u_N - \mu d|u_T|`, so a non-associated law is one equation). J is assembled sparse and
solved by LU (LAPACK dense or SuperLU sparse) with iterative refinement; non-monotone Armijo
backtracking on :math:`\tfrac12|\Phi|^2`; Levenberg–Marquardt directions while the iteration
stalls (singular J); a projection step when the line search fails.
"""

from __future__ import annotations

import warnings

import numpy as np

from ._frame import _Frame, _Monitor
from ._options import NewtonOptions


def _refined(solve, J, b, steps: int, rtol: float):
    """``solve(b)`` improved by up to ``steps`` steps of iterative refinement; None if the
    residual stays above ``rtol |b|`` or the result is not finite."""
    norm_b = np.linalg.norm(b)
    x = solve(b)
    for _ in range(steps + 1):
        if not np.all(np.isfinite(x)):
            return None
        res = b - J @ x
        if np.linalg.norm(res) <= rtol * norm_b:
            return x
        x = x + solve(res)
    return None


def newton_direction(JT, b, eye, opts: NewtonOptions, lm: bool = False, perm=None):
    r"""The direction ``x`` of a Newton step ``J x = b``, given ``J^T`` in CSC (J in CSR).

    ``lm=False``: by LU with iterative refinement. Up to ``opts.dense_max`` unknowns, or when
    J is denser than ``opts.dense_fill``, LAPACK's dense LU (SuperLU's set-up costs more
    there); otherwise SuperLU on diagonal pivots in symmetric mode (J has the symmetric
    sparsity of W plus its diagonal, nonzero in every contact state) after the contacts'
    minimum-degree ordering ``perm`` (:func:`._ordering.frame_ordering`; without it, after
    SuperLU's symmetric minimum degree of the unknowns), then with partial pivoting, tried only
    when the first fails. (Measured over 40 iterations on the 1,812-contact sphere pile: the
    contacts' ordering 16.5 ms a factorization, SuperLU's symmetric one 18.1, partial pivoting
    43.2; on the 3,970 pile the first succeeded in 8 iterations, the second in none, so it is
    not tried after the first.) A solve counts
    when its refined residual is within ``opts.direction_rtol |b|`` (refinement recovers the
    digits an ill-conditioned J loses: without it, the pile's directions failed at 2.5e-10 and
    fell back to the slow Levenberg–Marquardt system). When none does (J singular), or with
    ``lm=True``, the Levenberg–Marquardt direction (:func:`lm_direction`).

    J is singular or nearly so where W is rank-deficient (more contacts than the bodies'
    degrees of freedom: the periodic box, stacks, towers) and contacts stick. With LU
    directions only, the iteration stagnates on LMGC_100_PR_PerioBox (error 4e-2 after 300
    iterations); switching to Levenberg–Marquardt while it stalls gives 6e-9 in 122.
    """
    norm_b = np.linalg.norm(b)
    if norm_b == 0.0:
        return np.zeros_like(b)
    lam = opts.lm_weight * norm_b
    n = b.shape[0]
    if n <= opts.dense_max or JT.nnz > opts.dense_fill * n * n:
        import scipy.linalg as sla
        J = JT.toarray().T
        if not lm:
            try:
                with warnings.catch_warnings():  # a singular J is handled below
                    warnings.simplefilter("ignore", sla.LinAlgWarning)
                    lu = sla.lu_factor(J, check_finite=False)
                x = _refined(lambda v: sla.lu_solve(lu, v, check_finite=False), J, b,
                             opts.refinement_steps, opts.direction_rtol)
                if x is not None:
                    return x
            except (np.linalg.LinAlgError, ValueError):
                pass
        try:
            return np.linalg.solve(J.T @ J + lam * np.eye(n), J.T @ b)
        except np.linalg.LinAlgError:       # lam below J^T J's rounding: least squares
            return np.linalg.lstsq(J, b, rcond=None)[0]
    J = JT.T
    for solve in () if lm else _sparse_lus(JT, perm):
        x = _refined(solve, J, b, opts.refinement_steps, opts.direction_rtol)
        if x is not None:
            return x
    return lm_direction(JT, b, lam, eye, opts, perm)


def _sparse_lus(JT, perm):
    """Solvers of ``J x = b`` (``J^T`` in CSC), each factorized only when asked for: on
    diagonal pivots in symmetric mode after the contacts' ordering ``perm`` (or, without it,
    SuperLU's symmetric minimum degree), then with partial pivoting (an exactly zero pivot
    skips one)."""
    import scipy.sparse.linalg as spla

    from ._ordering import ordered_lu
    if perm is not None:
        try:                                # J's CSR arrays are those of J^T in CSC
            yield ordered_lu(JT.indptr, JT.indices, JT.data, perm)
        except RuntimeError:
            pass
    symmetric = {"permc_spec": "MMD_AT_PLUS_A", "diag_pivot_thresh": 0.0, "options": {"SymmetricMode": True}}
    for options in ({},) if perm is not None else (symmetric, {}):
        try:
            lu = spla.splu(JT, **options)
        except RuntimeError:
            continue
        yield lambda v, lu=lu: lu.solve(v, trans="T")


def lm_direction(JT, b, lam: float, eye, opts: NewtonOptions, perm=None):
    r"""The Levenberg–Marquardt direction :math:`x = \arg\min |J x - b|^2 + \lambda |x|^2`
    (``J^T`` in CSC, sparse).

    With the contacts' ordering ``perm``: from the quasi-definite augmented system

    .. math:: \begin{pmatrix} I & J \\ J^T & -\lambda I \end{pmatrix}
              \begin{pmatrix} y \\ x \end{pmatrix} = \begin{pmatrix} b \\ 0 \end{pmatrix}

    (:math:`y = b - J x`, so :math:`(J^T J + \lambda I) x = J^T b`), which has J's pattern
    where the normal equations have that of :math:`J^T J`. A quasi-definite matrix has an
    :math:`LDL^T` factorization in every symmetric ordering (Vanderbei, SIAM J. Optim. 5,
    1995), so diagonal pivots serve; each contact's six unknowns :math:`(y_a, x_a)` are
    ordered together by ``perm``. Measured on the 3,970-contact pile: 264 ms and 5.6 million
    entries in the factors, against 1,053 ms and 7.5 million for the normal equations (503 ms
    in symmetric mode); both satisfy the normal equations to 1e-12 relative. Refined as the
    LU directions are; where it fails, or without ``perm``, the normal equations
    :math:`(J^T J + \lambda I)` by SuperLU in symmetric mode.
    """
    import scipy.sparse as sp
    import scipy.sparse.linalg as spla

    from ._ordering import augmented_csr, ordered_lu
    n = b.size
    if perm is not None:
        Jc = JT.tocsr()                     # J's columns, each sorted
        K = augmented_csr(JT.indptr, JT.indices, JT.data, Jc.indptr, Jc.indices, Jc.data, lam)
        unknowns = perm.reshape(-1, 3)      # each contact's three, in order
        perm6 = np.concatenate((unknowns, unknowns + n), axis=1).ravel()
        rhs = np.concatenate((b, np.zeros(n)))
        try:
            solve = ordered_lu(*K, perm6, 0.0, dense_blocks=False)
            z = _refined(solve, sp.csr_matrix(K[::-1], shape=(2 * n, 2 * n)), rhs, opts.refinement_steps,
                         opts.direction_rtol)
            if z is not None:
                return z[n:]
        except RuntimeError:
            pass
    try:
        A = (JT @ JT.T + lam * eye).tocsc()
        return spla.splu(A, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                         options={"SymmetricMode": True}).solve(JT @ b)
    except RuntimeError:
        return b


def newton_steps(fr: _Frame, W, q, r, rho, stop, max_iter: int, on_iter, opts: NewtonOptions):
    r"""Semismooth Newton iterations on ``(W, q)`` from ``r`` until ``stop(r, u)`` or ``max_iter``.

    Non-monotone Armijo backtracking on :math:`\tfrac12|\Phi|^2`; a projection step when it
    fails. While the merit has not halved over the last ``opts.stall_iterations`` iterations
    (a singular or ill-conditioned J), the direction is the Levenberg–Marquardt one (see
    :func:`newton_direction`); once it falls again, Newton's. (Kept for the whole run instead,
    it slows spheres-in-a-box from 41 to 120 iterations.) ``on_iter(k, r, u)`` is called after
    iteration k; a true return stops. Returns ``(r, iterations)``.
    """
    import scipy.sparse as sp

    from . import _kernels as K
    from ._ordering import frame_ordering
    n = 3 * fr.nc
    eye = sp.identity(n, format="csc")
    perm = frame_ordering(fr) if n > opts.dense_max else None
    Wp, Wi = W.indptr.astype(np.int32), W.indices.astype(np.int32)
    u = W @ r + q
    phi, B1, B2 = K.alart_curnier(r, u, fr.mu, fr.d, rho)
    merit = 0.5 * float(phi @ phi)
    merits = [merit]  # the last few give the non-monotone (Grippo-Lampariello-Lucidi) reference
    lm = False
    it = 0
    while it < max_iter and not stop(r, u):
        it += 1
        jptr, jind, jdat = K.jacobian_csr(Wp, Wi, W.data, B1, B2)
        # the CSR arrays of J are the CSC arrays of J^T: factorize J^T, solve with trans="T"
        JT = sp.csc_matrix((jdat, jind, jptr), shape=(n, n))
        JT.has_sorted_indices = True
        dx = newton_direction(JT, -phi, eye, opts, lm, perm)
        reference = max(merits[-opts.nonmonotone_memory:])
        alpha, accepted = 1.0, False
        while alpha > opts.min_step:
            rn = r + alpha * dx
            un = W @ rn + q
            phin, B1n, B2n = K.alart_curnier(rn, un, fr.mu, fr.d, rho)
            mn = 0.5 * float(phin @ phin)
            if mn <= reference - opts.armijo * alpha * merit:
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
        k = opts.stall_iterations
        lm = len(merits) > k and merit > 0.5 * merits[-1 - k]
        if on_iter(it, r, u):
            break
    return r, it


def run_newton(fr: _Frame, r, max_iter: int, mon: _Monitor, opts: NewtonOptions):
    r"""Newton iterations from ``r`` until converged, stopped or ``max_iter``; returns ``(r, it)``.

    When Siconos' error has not halved over ``opts.restart_stall`` iterations,
    ``opts.restart_sweeps`` Gauss–Seidel sweeps (:func:`._nsgs.run_nsgs`, each counted as an
    iteration and recorded as ``"nsgs"``), then Newton again. The merit
    :math:`\tfrac12|\Phi|^2` can be small where the error is not: a contact sliding the wrong
    way (its friction along its slip) leaves :math:`\Phi_T = \rho u_T`, which
    :math:`\rho = 3/\mathrm{tr}\,W_{aa}` makes tiny, and Newton's steps stall there; a sweep
    solves each contact exactly, on its right piece. Measured with W and q perturbed by 1e-15
    (relative, sixteen draws each), the draws that did not reach 1e-8 in 200 iterations:
    Capsules 11 without the sweeps and 1 with them, local_problem_test 2 and 1,
    spheres-in-a-box 1 and 1, Box_Stacks 1 and 0; PerioBox's slowest draw took 165
    iterations instead of 195. (A change of :math:`\rho` instead, up or down, at the same
    stalls did not do it.)
    """
    from ._nsgs import run_nsgs
    from ._options import NSGSOptions
    rho = fr.rho()
    base, it = mon.offset, 0
    while True:
        best, since, stalled = np.inf, 0, False

        def on_iter(k, rr, uu, start=it):
            nonlocal best, since, stalled
            err = fr.error(rr, uu)
            if mon.record("newton", start + k, rr, err):
                return True
            best, since = (err, 0) if err < 0.5 * best else (best, since + 1)
            stalled = opts.restart_sweeps > 0 and since >= opts.restart_stall
            return stalled

        r, k = newton_steps(fr, fr.W, fr.q, r, rho, lambda r, u: False, max_iter - it, on_iter, opts)
        it += k
        if not stalled or mon.reason or it >= max_iter:
            return r, it
        mon.offset = base + it
        it += run_nsgs(fr, r, min(opts.restart_sweeps, max_iter - it), mon, NSGSOptions())
        mon.offset = base
        if mon.reason or it >= max_iter:
            return r, it
