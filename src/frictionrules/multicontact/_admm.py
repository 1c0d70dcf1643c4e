r"""ADMM with De Saxcé's correction, adaptive penalty and Anderson acceleration
(``method="admm"``).

The exact Coulomb problem :math:`K \ni r \perp \hat u = W r + q + s(u) \in K^*` is solved as in
Carpentier, Le Lidec & Montaut (RSS 2024, Pinocchio's ADMM): split :math:`r = x = y`, the
quadratic part in x and the cone in y, with the correction :math:`s = \mu(1 - d)|z_T| e_N`
taken from the current dual variable z (the velocity estimate); see :class:`ADMMOptions` for
the iteration. :math:`W + (\rho + \eta) I` is factorized once per value of :math:`\rho` (sparse
LU after a minimum-degree ordering of the contacts, :mod:`._ordering`, refilled on its pattern
for a new :math:`\rho`, as :math:`L D L^T` from the lower triangle where W is symmetric, kept
in 3 x 3 blocks by contacts, :mod:`._triangular`; dense LU on small problems; kept on the
frame, so that a value of :math:`\rho` met again, or another ADMM stage of ``"auto"``, costs
no new factorization), so an iteration costs two triangular solves, one
product with W where Siconos' error is measured (at intervals, :attr:`ADMMOptions.max_check_interval`)
and O(nc), the latter compiled (:mod:`._admm_steps`).

:math:`\rho` starts from the spectral rule, or small where the problem is in the all-stick
regime: when the minimizer of the regularized quadratic, :math:`-(W + \rho_s I)^{-1} q`, lies
inside every cone, the constraints are inactive near the solution and each x-step is nearly an
exact solve (KaplasTower: 5 iterations to 1e-8 with :math:`\rho = 10^{-4} L`, 43 with the
spectral :math:`\rho`, whose residual balancing then lowers it through four
refactorizations); the dual variable (the velocity) then starts at zero, the all-stick
velocity (from the projected :math:`q`, random all-stick problems took 70 iterations with
the small :math:`\rho` instead of 3: a small penalty moves the dual variable slowly). It is raised or lowered when the primal and dual residuals are out of
balance, by more levels at once along a streak of changes the same way
(:func:`._admm_steps.rho_change`: a drift of :math:`2^k` levels costs about k + 2
factorizations). Anderson acceleration (type II, memory ``ADMMOptions.anderson``) extrapolates the
fixed-point map on :math:`(y, z)`; an extrapolated step is dropped, and the memory cleared,
when the next residual is larger than the last plain one; plain steps then run alone for
``ADMMOptions.anderson_pause`` iterations (doubled after repeated drops up to
``ADMMOptions.anderson_pause_doublings`` times).
"""

from __future__ import annotations

import numpy as np

from ._frame import _Frame, _Monitor, norm
from ._options import ADMMOptions


def _compiled_w(fr: _Frame):
    """``(indptr, indices, data, blocks)``: the frame's CSR arrays, the indices viewed as
    unsigned (the compiled code then skips the wrapping of negative indices: a product with W
    by entries took 0.064 ms on KaplasTower instead of 0.126), and whether W is made of whole
    3 x 3 blocks (:func:`._ordering._dense_blocks`)."""
    if "admm_w" not in fr.cache:
        from ._ordering import _dense_blocks
        indptr, indices, data = fr.csr
        fr.cache["admm_w"] = (indptr.view(np.uint32), indices.view(np.uint32), data,
                              bool(_dense_blocks(indptr, indices, fr.nc)))
    return fr.cache["admm_w"]


def _product(fr: _Frame):
    r"""The frame's compiled :math:`(x, q) \mapsto q + W x`, each row summed in the order of
    SciPy's product: by 3 x 3 blocks when W is made of them
    (:func:`._admm_steps.block_matvec`), by entries otherwise."""
    if "admm_product" not in fr.cache:
        from . import _admm_steps as S
        from . import _kernels as K
        indptr, indices, data, blocks = _compiled_w(fr)
        kernel = S.block_matvec if blocks else K.csr_matvec

        def product(x, q):
            return kernel(indptr, indices, data, x, q)
        fr.cache["admm_product"] = product
    return fr.cache["admm_product"]


#: The compiled triangular solves (:func:`._triangular.lu_solve`, entry by entry, a contact's
#: three rows together) serve while the factors hold at most this many nonzeros per unknown;
#: beyond, SuperLU's supernodal solve (dense blocks) is faster. Measured under load, one solve,
#: compiled against SuperLU: Spheres (6.8 per unknown) 17 against 58 µs, Capsules (13.9) 20
#: against 62, the 1,264 boxes (22.9) 89 against 219, spheres-in-a-box (45) 30 against 87, the
#: 1,812 spheres (91) 535 against 590; the 3,970 spheres (135) 2,850 against 2,630 (1,170
#: from L alone, :data:`SYMMETRIC_MIN_ENTRIES`; 473 in blocks, :func:`._triangular.block_factors`),
#: KaplasTower (167) 310 against 226. The compiled loop also measures the error at intervals
#: (one product with W, not one per iteration) and runs no Python per iteration: ADMM's
#: marginal cost on the 3,970 spheres 3,070 µs an iteration with the compiled solves against
#: 3,440 with SuperLU's (two interleaved pairs, under load); KaplasTower's 520-595 against
#: 450-560, left to SuperLU.
COMPILED_FILL_MAX = 150

#: Where L holds at least this many entries and W is symmetric, U is dropped for
#: :math:`D L^T` (:func:`_symmetric`): the factors' memory halves (12 bytes an entry with its
#: index), and the solve's pass over them stays in the processor's cache. One solve, L and U
#: against L alone (idle machine, 2 MB of cache per core): the 3,970-sphere pile (796,062
#: entries) 2.04-2.68 ms against 1.16-1.19; the 1,812 spheres 359-575 µs against 345-349;
#: below, 3-8 % (Spheres, 3,106 entries: 10.1 against 9.8 µs). Below the bound U is kept: its
#: solve is a little more accurate on ill-conditioned matrices, which the choice of iterative
#: refinement (:meth:`_Factor._refines`) reads (spheres-in-a-box at ρ + η = 3.4: relative
#: residual 2.8e-11 from L alone, refined, each ADMM iteration then twice as long).
SYMMETRIC_MIN_ENTRIES = 100_000

#: W + cI is factorized dense (LAPACK) up to this many unknowns where W stores at least
#: :data:`DENSE_MIN_FILL` of its entries, by SuperLU otherwise. Measured under load, one
#: factorization, dense against SuperLU: Box_Stacks (246 unknowns, W 3.3 % full) 0.56 against
#: 0.18 ms; local_problem_test (144, 24 %) 0.19 against 0.35; PerioBox (180, 30 %) 0.30
#: against 0.59; but SuperLU's pattern serves again when ρ changes (:func:`_pattern`):
#: local_problem_test's ADMM marginal cost 10.3 µs an iteration with it, 19-30 dense (two
#: interleaved pairs, under load; two factorizations in iterations 20-120).
DENSE_MAX = 400
DENSE_MIN_FILL = 0.5


def _test_rhs(fr: _Frame):
    """The random right-hand side of the factors' test solves (:meth:`_Factor._refines`), one
    per frame (a new generator and draw cost 20-30 µs a factorization)."""
    if "admm_test_rhs" not in fr.cache:
        fr.cache["admm_test_rhs"] = np.random.default_rng(1).normal(size=fr.W.shape[0])
    return fr.cache["admm_test_rhs"]


class _Factor:
    r"""Solves with :math:`A = W + c I`: dense LU up to 400 unknowns where W is at least half
    full (:data:`DENSE_MAX`, :data:`DENSE_MIN_FILL`), SuperLU otherwise, or, after a first
    SuperLU factorization on the frame, a compiled one on its pattern (:func:`_pattern`).

    SuperLU runs on diagonal pivots in symmetric mode (the fastest, and W is symmetric or
    nearly so), which can cost digits on a nonsymmetric W: when a test solve (beside the first
    one, as a second right-hand side) misses :math:`10^{-12}` relative residual and one step
    of iterative refinement at least halves it (:meth:`_refines`), every solve takes one.
    (Without it ADMM stalled at 2e-8 on the 1,264-box pile, whose W is nonsymmetric by 2e-3;
    the test's right-hand side is random: the residual of a solve with ``-q`` met the bound
    there.) The unknowns are ordered by :func:`._ordering.contact_ordering` (computed once per
    frame) and the permuted matrix is built in one pass from W's CSR arrays; above
    :data:`._ordering.BITSET_MAX` contacts SuperLU orders them itself.

    Where the factors hold at most :data:`COMPILED_FILL_MAX` nonzeros per unknown they are
    kept as CSR arrays (``arrays``, the arguments of :func:`._triangular.lu_solve`; in 3 x 3
    blocks by contacts where they are made of them, :func:`._triangular.block_factors`), solved
    in compiled code, and ADMM's iteration runs in one compiled call
    (:func:`._admm_steps.admm_iteration`); ``arrays`` is None otherwise.

    The first solve is kept for the next call: ADMM's first iteration in the all-stick regime
    solves with ``-q`` again, as :func:`all_stick` did (0.2 ms on KaplasTower). With SuperLU's
    factors in ``arrays`` the test solve is made at once (compiled) and nothing is kept.
    """

    def __init__(self, fr: _Frame, c: float):
        from . import _triangular as T
        W = fr.W
        n = W.shape[0]
        self.first, self.kept = True, None
        self.c, self.fr = c, fr
        self.arrays = None
        if n <= DENSE_MAX and W.nnz >= DENSE_MIN_FILL * n * n:
            import scipy.linalg as sla
            if "dense_w" not in fr.cache:
                fr.cache["dense_w"] = W.toarray()
            A = fr.cache["dense_w"].copy()
            A[np.diag_indices(n)] += c
            lu, piv = sla.lu_factor(A, overwrite_a=True, check_finite=False)
            factors = T.dense_factors(lu, piv)
            if factors[1].size + factors[4].size + n <= COMPILED_FILL_MAX * n:
                self.arrays = factors + (np.arange(n), T.contact_triples(factors[0], factors[1], factors[3],
                                                                       factors[4]))
            else:
                self._solve = lambda b: sla.lu_solve((lu, piv), b, check_finite=False)
            self.refine = False
            return
        pattern = fr.cache.get("admm_pattern")
        if pattern is not None:         # the pattern of an earlier factorization, refilled
            lp, li, up, ui, rows, cols, triples, bp, bi, bx, refactor = pattern
            lx, ux, ud, ok = refactor(bp, bi, bx, c, lp, li, up, ui)
            if ok:
                factors = _symmetric((lp, li, lx, up, ui, ux, ud, rows, cols, triples),
                                     built=refactor is T.symmetric_refactor)
                self.arrays, fr.cache["admm_blocks"] = T.block_factors(factors, fr.cache.get("admm_blocks"))
                self._test_solve()
                return
        import scipy.sparse as sp
        import scipy.sparse.linalg as spla

        from ._ordering import frame_ordering, ordered_superlu
        perm = frame_ordering(fr)
        if perm is None:
            A = (W + c * sp.identity(n, format="csr")).tocsc()
            lu = spla.splu(A, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                           options={"SymmetricMode": True})
            perm = np.arange(n)
        else:
            lu = ordered_superlu(*fr.csr, perm, c, _compiled_w(fr)[3])
        if lu.nnz <= COMPILED_FILL_MAX * n:
            # L U = B, B_kj = M_{r'_k c'_j} (r', c' the inverses of SuperLU's perm_r, perm_c),
            # M_ij = A_{perm_i perm_j}
            rinv, cinv = np.empty(n, np.int64), np.empty(n, np.int64)
            rinv[lu.perm_r], cinv[lu.perm_c] = np.arange(n), np.arange(n)
            factors = T.csr_factors(lu.L, lu.U)
            self.arrays = factors + (perm[rinv], perm[cinv], T.contact_triples(factors[0], factors[1], factors[3],
                                                                              factors[4]))
            fresh = "admm_pattern" not in fr.cache
            if fresh:
                fr.cache["admm_pattern"] = _pattern(W, self.arrays, c)
            self.arrays, blocks = T.block_factors(_symmetric(self.arrays))
            if fresh and fr.cache["admm_pattern"] is not None:     # the blocks of the kept pattern
                fr.cache["admm_blocks"] = blocks
            self._test_solve()
            return
        else:
            def solve(b):
                x = np.empty_like(b)
                x[perm] = lu.solve(b[perm])
                return x
            self._solve = solve
        self.refine = None              # decided by the first solve

    def _solve(self, b):
        from . import _triangular as T
        if b.ndim == 2:
            return np.column_stack([self._solve(np.ascontiguousarray(col)) for col in b.T])
        return T.lu_solve(*self.arrays, b)

    def _test_solve(self):
        """The test solve of :meth:`_refines`, compiled (:func:`._admm_steps.refines`, one
        call: 10-30 µs of Python at each change of ρ on local_problem_test before), at the
        factorization: ADMM's next iteration then runs in the compiled loop (two iterations ran
        in Python after each new factorization otherwise, 0.1-0.3 ms); nothing is kept."""
        from . import _admm_steps as S
        self.refine = bool(S.refines(*self.arrays, self.c, *_compiled_w(self.fr), _test_rhs(self.fr)))
        self.first = False

    def _refines(self, x, b) -> bool:
        """Whether solves take a step of refinement: the test solve ``x`` of ``A x = b`` misses
        :math:`10^{-12}` relative residual and one step at least halves it
        (:data:`._admm_steps.REFINE_RESIDUAL`, :data:`._admm_steps.REFINE_GAIN`). (Where the residual
        is round-off of an ill-conditioned A, the step does not pay: spheres-in-a-box at small
        :math:`\rho`, 4.4e-12 before and 4.0e-12 after, each iteration then twice as long.)"""
        from . import _admm_steps as S
        r = norm(self._residual(x, b))
        if not r > S.REFINE_RESIDUAL * norm(b):
            return False
        return bool(S.REFINE_GAIN * norm(self._residual(x - self._solve(self._residual(x, b)), b)) <= r)

    def _residual(self, x, b):
        return _product(self.fr)(x, self.c * x - b)

    def solve(self, b):
        """The solution of :math:`A x = b` (a new array)."""
        if self.kept is not None:
            kept_b, kept_x = self.kept
            self.kept = None
            if np.array_equal(b, kept_b):
                return kept_x
        if self.refine is None:         # with the random test's right-hand side: one pass over
            t = _test_rhs(self.fr)                               # the factors (0.25 ms, not 0.32)
            X = self._solve(np.column_stack((t, b)))
            x_t, x = np.ascontiguousarray(X[:, 0]), np.ascontiguousarray(X[:, 1])
            self.refine = self._refines(x_t, t)
        else:
            x = self._solve(b)
        if self.refine:
            x = x - self._solve(self._residual(x, b))
        if self.first:
            self.first, self.kept = False, (b.copy(), x.copy())
        return x


class _Anderson:
    """Type-II Anderson extrapolation of a fixed-point map v -> T(v), memory m.

    The differences are kept as the rows of two arrays (no stacking per step) and the
    least-squares coefficients come from the m x m normal equations, their matrix
    :math:`F F^T` kept and updated by one row per step (O(n m); NumPy's lstsq of the n x m
    system cost a sixth of an iteration on the 3,970-contact pile, and recomputing
    :math:`F F^T` with NumPy's solve 16 µs a step on Spheres, under load).
    """

    def __init__(self, m: int):
        self.m = m
        self.dG = self.dF = None        # kept by clear(): 2 x 137 kB for KaplasTower
        self.state = np.zeros(2, np.int64)      # (steps in memory, whether v' and T(v') are kept)

    def clear(self):
        self.state[:] = 0

    def buffers(self, size: int):
        """``(prev_f, prev_tv, dG, dF, gram, small, state)``: the memory, as the compiled loop
        (:func:`._admm_steps.admm_loop`) takes it (``small``: the scratch of the m x m
        system)."""
        if self.dG is None:
            self.dG, self.dF = np.empty((self.m, size)), np.empty((self.m, size))
            self.gram, self.small = np.empty((self.m, self.m)), np.empty((self.m + 2, self.m))
            self.prev_f, self.prev_tv = np.empty(size), np.empty(size)
        return self.prev_f, self.prev_tv, self.dG, self.dF, self.gram, self.small, self.state

    def step(self, v, tv):
        """``(next, extrapolated)``: the extrapolated next iterate from ``v`` and ``T(v)``, or
        ``T(v)`` itself (``extrapolated`` false) at first and where the extrapolation is not
        finite."""
        from . import _admm_steps as S
        out = np.array(v, dtype=float)
        extrapolated = S.anderson_update(out, tv, *self.buffers(v.size))
        return (out if extrapolated else tv), extrapolated


def _symmetric(arrays, built=False):
    r"""The factors' arrays with U dropped where L holds at least :data:`SYMMETRIC_MIN_ENTRIES`
    entries and U is :math:`D L^T` (the same rows and columns,
    :func:`._triangular.symmetric_form`; not checked again where ``built`` says the factors
    come from :func:`._triangular.symmetric_refactor`, which writes U as :math:`D L^T`: the
    check was 7 ms of a 106 ms change of ρ on the 3,970-sphere pile):
    :func:`._triangular.lu_solve` then reads L twice."""
    from . import _triangular as T
    lp, li, lx, up, ui, ux, ud, rows, cols, triples = arrays
    if lx.size < SYMMETRIC_MIN_ENTRIES or not (np.array_equal(rows, cols) and (
            built or T.symmetric_form(lp, li, lx, up, ui, ux, ud))):
        return arrays
    return lp, li, lx, up[:0], ui[:0], ux[:0], ud, rows, cols, triples


def _pattern(W, arrays, c: float):
    r"""The pattern of SuperLU's factors (``arrays`` of :func:`._triangular.lu_solve`, of
    :math:`W + cI`) and W's rows and columns in their order (:math:`B = W_{rows, cols}` as CSR
    arrays), and the function that factorizes :math:`W + c'I` again on it (ρ changed: 20-60 µs
    on the shared files' patterns instead of SuperLU's 0.2-1.5 ms, under load):
    :func:`._triangular.symmetric_refactor` where B is symmetric (to
    :data:`._triangular.SYMMETRIC_TOL` of its largest entry) and the pattern is (half the work:
    spheres-in-a-box 394 µs against 799, local_problem_test 41 against 72),
    :func:`._triangular.lu_refactor` otherwise. None where SuperLU permuted rows and columns
    differently (a pivot off the diagonal) or the refilled factors at c are not SuperLU's (a
    pattern missing fill)."""
    from . import _triangular as T
    lp, li, lx, up, ui, ux, ud, rows, cols, triples = arrays
    if not np.array_equal(rows, cols):
        return None
    B = W[rows][:, cols].tocsr()
    B.sort_indices()
    bp, bi = B.indptr.astype(np.int64), B.indices.astype(np.int64)
    bx = np.ascontiguousarray(B.data, dtype=float)
    scale = max(np.abs(ud).max(), 1e-300)

    def same(refactor):
        lx2, ux2, ud2, ok = refactor(bp, bi, bx, c, lp, li, up, ui)
        return ok and not any(a.size and np.abs(a - b).max() > 1e-8 * max(np.abs(b).max(), scale)
                              for a, b in ((lx2, lx), (ux2, ux), (ud2, ud)))
    if not same(T.lu_refactor):
        return None
    refactor = T.lu_refactor
    if B.nnz and abs(B - B.T).max() <= T.SYMMETRIC_TOL * np.abs(bx).max() and same(T.symmetric_refactor):
        refactor = T.symmetric_refactor
    return lp, li, up, ui, rows, cols, triples, bp, bi, bx, refactor


#: Iterations of one call of the compiled loop (:func:`._admm_steps.admm_loop`) at most: a
#: time limit is noticed after as many.
COMPILED_BATCH = 64

#: Factorizations of ``W + cI`` kept on a frame (the oldest dropped first).
FACTORS_KEPT = 4


def _factor(fr: _Frame, shift: float) -> _Factor:
    r"""The solver of :math:`(W + \text{shift}\,I) x = b`, from the frame's cache."""
    factors = fr.cache.setdefault("admm_factors", {})
    if shift not in factors:
        if len(factors) >= FACTORS_KEPT:
            del factors[next(iter(factors))]
        factors[shift] = _Factor(fr, shift)
    return factors[shift]


def _largest(fr: _Frame, iterations: int) -> float:
    key = ("largest_eigenvalue", iterations)
    if key not in fr.cache:
        from . import _admm_steps as S
        v = np.random.default_rng(0).uniform(0.5, 1.5, fr.W.shape[0])
        indptr, indices, data, blocks = _compiled_w(fr)
        fr.cache[key] = S.power_iteration(indptr, indices, data, v, iterations, blocks) or fr.mean_diag
    return fr.cache[key]


def all_stick(fr: _Frame, opts: ADMMOptions) -> bool:
    r"""Whether the problem is in the all-stick regime: :math:`x = -(W + (\rho_s + \eta) I)^{-1} q`,
    :math:`\rho_s =` ``opts.rho_stick`` L, lies in every cone (then ADMM runs with
    :math:`\rho_s`). False when ``rho_stick`` is 0."""
    if opts.rho_stick == 0.0:
        return False
    key = ("all_stick", opts.rho_stick, opts.eta, opts.power_iterations)
    if key not in fr.cache:
        L = _largest(fr, opts.power_iterations)
        x = _factor(fr, opts.rho_stick * L + opts.eta * L).solve(-fr.q)
        xn, xt = x[0::3], np.hypot(x[1::3], x[2::3])
        fr.cache[key] = bool(np.all(xt <= fr.mu * xn) and np.all(np.isfinite(x)))
    return fr.cache[key]


def run_admm(fr: _Frame, r, max_iter: int, mon: _Monitor, opts: ADMMOptions):
    """ADMM iterations from ``r``; returns ``(r, iterations)`` with r in the cones."""
    from . import _admm_steps as S
    from . import _kernels as K
    W, q, mu, d = fr.W, fr.q, fr.mu, fr.d
    product = _product(fr)
    n = q.size
    L = _largest(fr, opts.power_iterations)
    eta = opts.eta * L
    cond = 1.0 / opts.eta
    stick = all_stick(fr, opts)
    rho0 = opts.rho_stick * L if stick else np.sqrt(L * eta) * cond ** opts.rho_power
    step = cond ** opts.rho_power_step
    level = 0                       # rho = rho0 step**level: a value met again finds its factors
    rho = rho0
    factor = _factor(fr, rho + eta)
    x = np.array(r, dtype=float)
    y = np.empty(n)
    K.project_all(x, mu, y)
    s = np.empty(n)
    if stick:
        z = np.zeros(n)
    else:
        z = W @ y + q
        K.desaxce_shift(z, mu, d, s)
        z += s - (rho + eta) * y
        K.project_dual_all(z.copy(), mu, z)
    anderson = _Anderson(opts.anderson) if opts.anderson > 0 else None
    v = np.concatenate((y, z))
    safe_v, safe_res, extrapolated = v, np.inf, False
    last_update, it, paused_until, streak, dropped = 0, 0, 0, 0, 0
    best_r, best_err = y.copy(), np.inf
    compiled = mon.callback is None and mon.handover is None
    memory = anderson.buffers(2 * n) if anderson is not None else (
        np.empty(0), np.empty(0), np.empty((0, 2 * n)), np.empty((0, 2 * n)), np.empty((0, 0)),
        np.empty((0, 0)), np.zeros(2, np.int64))
    limits = np.array([mon.tol, fr.r_bound, opts.ratio_primal_dual, max_iter, opts.rho_update_every,
                       opts.anderson_pause, opts.max_check_interval, opts.rho_min * L, opts.rho_max * L, step,
                       opts.rho_levels_max,
                       opts.anderson_pause_doublings],
                      dtype=float)
    next_check, last_measured, last_err = 1, 0, np.inf
    errs, its = np.empty(COMPILED_BATCH), np.empty(COMPILED_BATCH, np.int64)
    while it < max_iter:
        if compiled and factor.arrays is not None and factor.kept is None and factor.refine is not None:
            x, v, safe_v, best_r, y_last = x.copy(), v.copy(), safe_v.copy(), best_r.copy(), np.empty(n)
            ints = np.array([it, last_update, paused_until, extrapolated, next_check, last_measured, streak, dropped],
                            dtype=np.int64)
            floats = np.array([safe_res, best_err, last_err])
            count, change = S.admm_loop(*factor.arrays, factor.refine, *_compiled_w(fr), q, mu, d, fr.norm_q,
                                        rho, eta, x, v, s, safe_v, y_last, best_r, *memory, ints, floats, limits,
                                        errs, its)
            it, last_update, paused_until, extrapolated = int(ints[0]), int(ints[1]), int(ints[2]), bool(ints[3])
            safe_res, best_err = float(floats[0]), float(floats[1])
            next_check, last_measured, last_err = int(ints[4]), int(ints[5]), float(floats[2])
            streak, dropped = int(ints[6]), int(ints[7])
            if count and mon.record_many("admm", its[:count], y_last, errs[:count]):
                return y_last, int(its[count - 1])
            if change:
                level += change
                rho = rho0 * step ** level
                factor = _factor(fr, rho + eta)
            continue
        it += 1
        x_new = factor.solve(S.x_step_rhs(q, v[:n], x, v[n:], mu, d, rho, eta, s, np.empty(n)))
        tv = np.empty(2 * n)
        res, primal, dual = S.y_z_steps(x_new, x, v, mu, rho, eta, tv)
        if extrapolated and res > safe_res:   # the extrapolation did not pay: back to the plain step
            anderson.clear()
            v, extrapolated = safe_v, False
            paused_until = it + S.pause_length(opts.anderson_pause, dropped, limits[11])
            dropped += 1
            continue
        if extrapolated:
            dropped = 0
        y_new = tv[:n]
        x = x_new
        err = fr.error(y_new, product(y_new, q))
        if err < best_err:
            best_r, best_err = y_new, err
        if mon.record("admm", it, y_new, err):
            return y_new.copy(), it
        if it - last_update >= opts.rho_update_every and max(primal, dual) > 0:
            consecutive = it - last_update <= opts.rho_update_every
            change = S.rho_change(primal, dual, rho, streak if consecutive else 0, limits)
            if change != 0:
                streak = S.rho_streak(streak, change, consecutive)
                level += change
                rho = rho0 * step ** level
                factor = _factor(fr, rho + eta)
                last_update = it
                if anderson is not None:
                    anderson.clear()
        safe_v, safe_res = tv, res
        if anderson is not None and it >= paused_until:
            v, extrapolated = anderson.step(v, tv)
        else:
            v = tv
    return best_r.copy(), it
