"""ADMM's compiled pieces: the contacts' minimum-degree ordering and the permuted, shifted
matrix handed to SuperLU (checked against SciPy's own slicing and against a dense solve), the
products with W and the power iteration (against SciPy's product, within its rounding), and
the iteration's arithmetic against its NumPy expressions."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
from hypothesis import given
from hypothesis import strategies as st

from frictionrules import FrictionContactProblem
from frictionrules.multicontact import _admm_steps as S
from frictionrules.multicontact import _kernels as K
from frictionrules.multicontact import _ordering as O
from frictionrules.multicontact import _triangular as T
from frictionrules.multicontact._admm import (
    _Anderson,
    _compiled_w,
    _Factor,
    _product,
)
from frictionrules.multicontact._frame import _Frame
from test_io import FCLIB, needs_fclib


def block_matrix(nc: int, seed: int, density: float = 0.05, drop_diagonal=(), nonsymmetric=0.0):
    """A 3 nc x 3 nc CSR matrix of random 3 x 3 blocks (symmetric pattern, SPD plus an
    optional nonsymmetric part), with the diagonal entries ``drop_diagonal`` not stored."""
    rng = np.random.default_rng(seed)
    B = sp.random(nc, nc, density=density, random_state=rng, format="csr")
    B = ((B + B.T) != 0).astype(float) + sp.identity(nc)
    A = sp.kron(B, np.ones((3, 3)), format="csr")
    A.data = rng.normal(size=A.nnz)
    A = A @ A.T + nonsymmetric * A + 3 * nc * sp.identity(3 * nc)
    A = sp.csr_matrix(A)
    if len(drop_diagonal):
        A = A.tolil()
        for i in drop_diagonal:
            A[i, i] = 0.0
        A = A.tocsr()
        A.eliminate_zeros()
    A.sort_indices()
    return A


@pytest.mark.parametrize("seed, drop, contacts", [(0, (), False), (1, (0, 5, 17), False), (2, (3,), True),
                                                 (3, (), True)])
def test_shifted_permuted_csc_is_scipy_slicing(seed, drop, contacts):
    """Both paths: whole 3 x 3 blocks moved by a permutation of contacts (seed 3), entries one
    by one otherwise (a permutation of unknowns, or diagonal entries missing)."""
    nc = 40
    A = block_matrix(nc, seed, drop_diagonal=drop)
    rng = np.random.default_rng(seed)
    perm = ((3 * rng.permutation(nc))[:, None] + np.arange(3)).ravel() if contacts else rng.permutation(3 * nc)
    c = 0.25
    indptr, indices = A.indptr.astype(np.int32), A.indices.astype(np.int32)
    assert O._dense_blocks(indptr, indices, nc) == (not drop)
    ptr, rows, vals = O.shifted_permuted_csc(indptr, indices, A.data, perm, c)
    B = sp.csc_matrix((vals, rows, ptr), shape=A.shape)
    assert B.has_canonical_format
    ref = (A + c * sp.identity(3 * nc)).tocsc()[perm][:, perm]
    assert B.nnz == ref.nnz
    assert abs(B - ref).max() == 0.0


def test_contact_graph_is_the_block_pattern_of_a_plus_transpose():
    nc = 70                                   # two words of bits per contact
    A = block_matrix(nc, 3, density=0.08)
    A = sp.csr_matrix(sp.triu(A))             # a nonsymmetric pattern
    G = O.contact_graph(A.indptr, A.indices, nc)
    Gu = O.contact_graph(A.indptr.astype(np.int32).view(np.uint32), A.indices.astype(np.int32).view(np.uint32), nc)
    np.testing.assert_array_equal(G, Gu)
    bits = np.unpackbits(G.view(np.uint8), axis=1, bitorder="little")[:, :nc].astype(bool)
    block = (abs(A) + abs(A.T)).tocsr()
    ref = np.zeros((nc, nc), bool)
    rows, cols = block.nonzero()
    ref[rows // 3, cols // 3] = True
    np.fill_diagonal(ref, False)
    np.testing.assert_array_equal(bits, ref)


def elimination_fill(G_dense: np.ndarray, order) -> int:
    """Edges of the filled graph of eliminating ``order`` (dense reference)."""
    G = G_dense.copy()
    alive = np.ones(len(G), bool)
    fill = 0
    for v in order:
        alive[v] = False
        nb = np.flatnonzero(G[v] & alive)
        fill += nb.size
        G[np.ix_(nb, nb)] = True
    return fill


def to_bits(G_dense: np.ndarray) -> np.ndarray:
    n = len(G_dense)
    padded = np.zeros((n, 64 * ((n + 63) // 64)), np.uint8)
    padded[:, :n] = G_dense
    return np.packbits(padded, axis=1, bitorder="little").view(np.uint64).copy()


def test_minimum_degree_on_a_star_a_path_and_a_grid():
    n = 9                                      # star: the leaves first, no fill
    star = np.zeros((n, n), bool)
    star[0, 1:] = star[1:, 0] = True
    order, parent = O.minimum_degree(to_bits(star))
    assert sorted(order) == list(range(n)) and set(order[:n - 2]) <= set(range(1, n))
    assert elimination_fill(star, order) == n - 1
    path = np.zeros((n, n), bool)              # path: no fill, a chain as the tree
    path[np.arange(n - 1), np.arange(1, n)] = path[np.arange(1, n), np.arange(n - 1)] = True
    order, parent = O.minimum_degree(to_bits(path))
    assert elimination_fill(path, order) == n - 1
    m = 8                                      # 8 x 8 grid: much less fill than the natural order
    grid = np.zeros((m * m, m * m), bool)
    for i in range(m):
        for j in range(m):
            if i + 1 < m:
                grid[i * m + j, (i + 1) * m + j] = grid[(i + 1) * m + j, i * m + j] = True
            if j + 1 < m:
                grid[i * m + j, i * m + j + 1] = grid[i * m + j + 1, i * m + j] = True
    order, parent = O.minimum_degree(to_bits(grid))
    assert sorted(order) == list(range(m * m))
    assert elimination_fill(grid, order) < 0.8 * elimination_fill(grid, np.arange(m * m))
    post = O.postorder(order, parent)          # a postorder: every node after its descendants
    pos = np.empty(m * m, int)
    pos[post] = np.arange(m * m)
    assert all(parent[v] == -1 or pos[parent[v]] > pos[v] for v in range(m * m))
    assert elimination_fill(grid, post) == elimination_fill(grid, order)


def test_indistinguishable_contacts_are_eliminated_together():
    # contacts 0-3 have the same closed neighbourhood {0,1,2,3,4}; 4 joins them to 5-7
    n = 8
    G = np.zeros((n, n), bool)
    clique = [0, 1, 2, 3, 4]
    G[np.ix_(clique, clique)] = True
    G[4, 5:] = G[5:, 4] = True
    np.fill_diagonal(G, False)
    order, _ = O.minimum_degree(to_bits(G))
    pos = {v: k for k, v in enumerate(order)}
    first = [pos[v] for v in range(4)]
    assert max(first) - min(first) == 3            # one supervariable
    assert elimination_fill(G, order) <= elimination_fill(G, range(n))


@pytest.mark.parametrize("nonsymmetric", [0.0, 0.3])
def test_factor_with_the_contact_ordering_solves(nonsymmetric):
    nc = 200                                       # 600 unknowns: the sparse path
    W = block_matrix(nc, 4, density=0.02, nonsymmetric=nonsymmetric)
    problem = FrictionContactProblem(W, np.ones(3 * nc), np.full(nc, 0.5))
    fr = _Frame(problem)
    c = 0.1
    f = _Factor(fr, c)
    b = np.random.default_rng(5).normal(size=3 * nc)
    x = f.solve(b)
    ref = np.linalg.solve(fr.W.toarray() + c * np.eye(3 * nc), b)
    np.testing.assert_allclose(x, ref, rtol=1e-10, atol=1e-12 * np.abs(ref).max())
    again = f.solve(b)                             # the kept last solve, as a fresh array
    np.testing.assert_array_equal(again, x)
    assert again is not x
    perm = fr.cache["ordering"]
    assert np.array_equal(np.sort(perm), np.arange(3 * nc))
    assert np.all(perm[1::3] == perm[0::3] + 1) and np.all(perm[0::3] % 3 == 0)


@pytest.mark.parametrize("nonsymmetric", [0.0, 0.3])
def test_refactorization_on_the_pattern_is_a_dense_solve(monkeypatch, nonsymmetric):
    """After a first SuperLU factorization of W + c I the frame keeps its pattern; W + c' I is
    then factorized on it (compiled, no pivoting): the solves are those of a dense solve with
    W + c' I, and the refilled factors at c are SuperLU's (the pattern's own check)."""
    from frictionrules.multicontact import _admm as A
    monkeypatch.setattr(A, "SYMMETRIC_MIN_ENTRIES", 0)
    monkeypatch.setattr(T, "block_factors", lambda arrays, patterns=None: (arrays, patterns))         # the rows' form
    nc = 200
    W = block_matrix(nc, 4, density=0.005, nonsymmetric=nonsymmetric)      # factors: 34 per unknown
    fr = _Frame(FrictionContactProblem(W, np.ones(3 * nc), np.full(nc, 0.5)))
    first = _Factor(fr, 0.1)
    pattern = fr.cache["admm_pattern"]
    assert pattern is not None
    lp, li, up, ui, rows, cols, triples, bp, bi, bx, refactor = pattern
    assert refactor is (T.symmetric_refactor if nonsymmetric == 0.0 else T.lu_refactor)
    lx, ux, ud, ok = T.lu_refactor(bp, bi, bx, 0.1, lp, li, up, ui)
    assert ok
    if nonsymmetric == 0.0:                         # the lower triangle alone: the same factors
        sx, sux, sud, ok = T.symmetric_refactor(bp, bi, bx, 0.1, lp, li, up, ui)
        assert ok
        assert T.symmetric_form(lp, li, sx, up, ui, sux, sud)   # U = D L^T as built: no check owed
        for a, b in ((sx, lx), (sux, ux), (sud, ud)):
            np.testing.assert_allclose(a, b, rtol=1e-9, atol=1e-13 * np.abs(b).max())
    else:                                           # B's pattern is symmetric, its values not
        assert not np.allclose(T.symmetric_refactor(bp, bi, bx, 0.1, lp, li, up, ui)[1], ux)
    np.testing.assert_allclose(lx, first.arrays[2], rtol=1e-9, atol=1e-12 * np.abs(first.arrays[2]).max())
    np.testing.assert_allclose(ud, first.arrays[6], rtol=1e-9)
    again = _Factor(fr, 7.5)
    assert again.arrays[0] is lp                                    # the pattern itself
    assert again.arrays[3].size == (0 if nonsymmetric == 0.0 else up.size)     # U = D L^T dropped
    b = np.random.default_rng(8).normal(size=3 * nc)
    ref = np.linalg.solve(fr.W.toarray() + 7.5 * np.eye(3 * nc), b)
    np.testing.assert_allclose(again.solve(b), ref, rtol=1e-10, atol=1e-12 * np.abs(ref).max())


def symmetric_refactor_by_rows(bp, bi, bx, c, lp, li, up, ui):
    """The refill from the lower triangle one row at a time (NumPy), for the compiled one."""
    n = lp.size - 1
    lx, ux, ud = np.empty(li.size), np.empty(ui.size), np.empty(n)
    w, nxt = np.zeros(n), up[:n].astype(np.int64)
    for i in range(n):
        lower = bi[bp[i]:bp[i + 1]] <= i
        w[bi[bp[i]:bp[i + 1]][lower]] = bx[bp[i]:bp[i + 1]][lower]
        w[i] += c
        for p in range(lp[i], lp[i + 1]):
            k = li[p]
            r = nxt[k]
            assert ui[r] == i
            x = w[k]
            w[k], ux[r], nxt[k] = 0.0, x, r + 1
            lx[p] = x / ud[k]
            for s in range(up[k], r + 1):
                w[ui[s]] -= lx[p] * ux[s]
        ud[i], w[i] = w[i], 0.0
    return lx, ux, ud


def test_symmetric_refactorization_by_contacts_is_the_rows_one_bit_for_bit(monkeypatch):
    """A contact's three rows refilled together (:func:`_triangular.symmetric_refactor`) give
    the bits of the rows one at a time, contacts whose L rows share their columns and the
    others alike."""
    from frictionrules.multicontact import _admm as A
    monkeypatch.setattr(A, "SYMMETRIC_MIN_ENTRIES", 0)
    nc = 120
    fr = _Frame(FrictionContactProblem(block_matrix(nc, 4, density=0.01), np.ones(3 * nc), np.full(nc, 0.5)))
    _Factor(fr, 0.1)
    lp, li, up, ui, rows, cols, triples, bp, bi, bx, refactor = fr.cache["admm_pattern"]
    assert refactor is T.symmetric_refactor
    shared = T.contact_triples(lp, li, up, ui) & 1
    assert shared.all()                         # every contact's rows go together here
    for c in (0.1, 3.0):
        lx, ux, ud, ok = T.symmetric_refactor(bp, bi, bx, c, lp, li, up, ui)
        assert ok
        for a, b in zip((lx, ux, ud), symmetric_refactor_by_rows(bp, bi, bx, c, lp, li, up, ui)):
            np.testing.assert_array_equal(a, b)
    # a contact's rows that do not share their columns: each row alone (the rows of contact 0
    # get an entry of L in the first row that the others lack)
    dense = np.eye(6) * 4.0
    dense[3, 0] = dense[0, 3] = 1.0
    dense[4, 1] = dense[1, 4] = 0.5
    B = sp.csr_matrix(dense)
    L = sp.csr_matrix(np.tril(np.where(dense != 0.0, 1.0, 0.0), -1))
    U = L.T.tocsr()
    args = (B.indptr.astype(np.int64), B.indices.astype(np.int64), B.data, 0.2,
            L.indptr.astype(np.int64), L.indices.astype(np.int64), U.indptr.astype(np.int64),
            U.indices.astype(np.int64))
    assert not (T.contact_triples(*args[4:]) & 1).any()
    lx, ux, ud, ok = T.symmetric_refactor(*args)
    assert ok
    for a, b in zip((lx, ux, ud), symmetric_refactor_by_rows(*args)):
        np.testing.assert_array_equal(a, b)
    Lf = np.eye(6) + sp.csr_matrix((lx, args[5], args[4]), shape=(6, 6)).toarray()
    np.testing.assert_allclose(Lf @ np.diag(ud) @ Lf.T, dense + 0.2 * np.eye(6), rtol=1e-14)


def test_refactorization_reports_a_zero_pivot():
    """A zero pivot (here B = 0 at c = 0) is reported, not divided by."""
    lp, li = np.zeros(3, np.int64), np.zeros(0, np.int64)
    up, ui = np.zeros(3, np.int64), np.zeros(0, np.int64)
    bp, bi, bx = np.zeros(3, np.int64), np.zeros(0, np.int64), np.zeros(0)
    assert not T.lu_refactor(bp, bi, bx, 0.0, lp, li, up, ui)[3]
    assert T.lu_refactor(bp, bi, bx, 2.0, lp, li, up, ui)[3]
    assert not T.symmetric_refactor(bp, bi, bx, 0.0, lp, li, up, ui)[3]
    assert T.symmetric_refactor(bp, bi, bx, 2.0, lp, li, up, ui)[3]


def test_symmetric_refactorization_needs_u_as_l_transposed():
    """:func:`symmetric_refactor` writes U's row k from L's column k: a U that holds an entry
    whose transpose L lacks (or the other way) is refused, and the LU refactorization serves."""
    def csr(rows):
        return (np.cumsum([0] + [len(r) for r in rows]).astype(np.int64),
                np.array([c for r in rows for c in r], np.int64))
    B = np.array([[4.0, 1.0, 0.0], [1.0, 4.0, 1.0], [0.0, 1.0, 4.0]])
    bp, bi = csr([[0, 1], [0, 1, 2], [1, 2]])
    bx = B[B != 0]
    lp, li = csr([[], [0], [1]])
    up, ui = csr([[1], [2], []])
    lx, ux, ud, ok = T.symmetric_refactor(bp, bi, bx, 0.5, lp, li, up, ui)
    assert ok
    L = np.eye(3) + sp.csr_matrix((lx, li, lp), shape=(3, 3)).toarray()
    np.testing.assert_allclose(L @ np.diag(ud) @ L.T, B + 0.5 * np.eye(3), rtol=1e-14)
    np.testing.assert_allclose(ux, [ud[0] * lx[0], ud[1] * lx[1]], rtol=1e-15)
    up2, ui2 = csr([[1, 2], [2], []])               # U's row 0 holds column 2, L's row 2 not 0
    assert T.lu_refactor(bp, bi, bx, 0.5, lp, li, up2, ui2)[3]
    assert not T.symmetric_refactor(bp, bi, bx, 0.5, lp, li, up2, ui2)[3]
    lp3, li3 = csr([[], [0], [0, 1]])               # L's row 2 holds column 0, U's row 0 not 2
    assert not T.symmetric_refactor(bp, bi, bx, 0.5, lp3, li3, up, ui)[3]


def test_refinement_only_where_it_pays():
    """A step of iterative refinement is taken where the test solve misses 1e-12 relative
    residual and the step at least halves it: not on an exact solve, yes on a solve off by
    1e-6, not where the correction does not lower the residual (a solver returning zeros: the
    round-off of an ill-conditioned A behaves so)."""
    nc = 200
    W = block_matrix(nc, 4, density=0.02)
    fr = _Frame(FrictionContactProblem(W, np.ones(3 * nc), np.full(nc, 0.5)))
    f = _Factor(fr, 0.1)
    b = np.random.default_rng(6).normal(size=3 * nc)
    x = np.linalg.solve(fr.W.toarray() + 0.1 * np.eye(3 * nc), b)
    assert not f._refines(x, b)
    off = x * (1 + 1e-6 * np.random.default_rng(7).normal(size=x.size))
    assert f._refines(off, b)
    f._solve = np.zeros_like
    assert not f._refines(off, b)


@pytest.mark.parametrize("drop", [(), (4,)])
def test_products_and_power_iteration_have_scipys_bits(drop):
    nc = 150
    W = block_matrix(nc, 6, density=0.03, nonsymmetric=0.2, drop_diagonal=drop)
    fr = _Frame(FrictionContactProblem(W, np.ones(3 * nc), np.full(nc, 0.5)))
    assert _compiled_w(fr)[3] == (not drop)           # by blocks, or by entries
    x, q = np.random.default_rng(7).normal(size=(2, 3 * nc))
    product = _product(fr)
    # a row's sum in any order (or with fused multiply-adds, as a SciPy built by clang on
    # arm64 has) is within (row length) eps sum |W_ij x_j| of the exact one
    bound = 2 * np.diff(fr.W.indptr).max() * np.finfo(float).eps * (abs(fr.W) @ abs(x))
    assert np.all(np.abs(product(x, np.zeros(3 * nc)) - fr.W @ x) <= bound)
    assert np.all(np.abs(product(x, q) - (fr.W @ x + q)) <= bound + 2 * np.finfo(float).eps * np.abs(q))
    indptr, indices, data, blocks = _compiled_w(fr)
    v = np.random.default_rng(0).uniform(0.5, 1.5, 3 * nc)
    lam = S.power_iteration(indptr, indices, data, v, 10, blocks)
    assert lam == pytest.approx(power_iteration_reference(fr.W, v, 10), rel=1e-12)


def power_iteration_reference(W, v, iterations: int) -> float:
    """The power iteration in NumPy: |W v_k| with v_{k+1} = W v_k / |W v_k|, v_0 = v/|v|."""
    v = v / np.linalg.norm(v)
    lam = 0.0
    for _ in range(iterations):
        w = W @ v
        lam = float(np.linalg.norm(w))
        v = w / lam
    return lam


def test_iteration_arithmetic_is_the_numpy_expressions():
    nc = 30
    n = 3 * nc
    rng = np.random.default_rng(8)
    q, x, x_new = rng.normal(size=(3, n))
    v = rng.normal(size=2 * n)
    mu, dil = rng.uniform(0.2, 0.9, nc), rng.uniform(0.0, 0.5, nc)
    rho, eta = 0.7, 1e-3
    y, z = v[:n], v[n:]
    s_ref = np.empty(n)
    K.desaxce_shift(z, mu, dil, s_ref)
    s = np.empty(n)
    b = S.x_step_rhs(q, y, x, z, mu, dil, rho, eta, s, np.empty(n))
    np.testing.assert_array_equal(s, s_ref)
    np.testing.assert_array_equal(b, -(q + s_ref) + rho * y + eta * x + z)
    tv = np.empty(2 * n)
    res, primal, dual = S.y_z_steps(x_new, x, v, mu, rho, eta, tv)
    y_new = np.empty(n)
    K.project_all(x_new - z / rho, mu, y_new)
    np.testing.assert_array_equal(tv, np.concatenate((y_new, z - rho * (x_new - y_new))))
    assert res == pytest.approx(np.linalg.norm(tv - v), rel=1e-14)
    assert primal == np.max(np.abs(x_new - y_new))
    assert dual == np.max(np.abs(rho * (y_new - y) + eta * (x_new - x)))
    x_new[5] = np.nan
    assert np.isnan(S.y_z_steps(x_new, x, v, mu, rho, eta, tv)[1])


def anderson_reference(m, pairs):
    """The NumPy Anderson step (normal equations), for the compiled one."""
    dG, dF, out = [], [], None
    prev = None
    for v, tv in pairs:
        f = tv - v
        if prev is not None:
            dG.append(tv - prev[1])
            dF.append(f - (prev[1] - prev[0]))
            dG, dF = dG[-m:], dF[-m:]
        prev = (v, tv)
        if not dF:
            out = tv
            continue
        F, G = np.array(dF), np.array(dG)
        A = F @ F.T
        gamma = np.linalg.solve(A + 1e-14 * np.trace(A) * np.eye(len(F)), F @ f)
        out = tv - gamma @ G
    return out


def test_anderson_step_is_the_normal_equations():
    rng = np.random.default_rng(9)
    pairs = [(rng.normal(size=40), rng.normal(size=40)) for _ in range(8)]
    a = _Anderson(3)
    for k, (v, tv) in enumerate(pairs):
        out, extrapolated = a.step(v, tv)
        np.testing.assert_allclose(out, anderson_reference(3, pairs[:k + 1]), rtol=1e-9, atol=1e-12)
        assert extrapolated == (k > 0)
    a.clear()                                        # the memory restarts, its arrays kept
    out, extrapolated = a.step(*pairs[0])
    assert out is pairs[0][1] and not extrapolated
    same = np.ones(40)                               # a zero difference: the plain step
    a = _Anderson(3)
    a.step(same, same)
    out, extrapolated = a.step(same, same)
    assert out is same and not extrapolated


def test_anderson_step_falls_back_to_the_plain_step_where_not_finite():
    """An extrapolation whose system or result is not finite gives T(v) itself, not
    extrapolated: an infinite entry of T(v), and a result that overflows (the update's check,
    :func:`_admm_steps._minus_rows`, which also sees a NaN)."""
    rng = np.random.default_rng(4)
    pairs = [(rng.normal(size=30), rng.normal(size=30)) for _ in range(3)]
    a = _Anderson(3)
    for v, tv in pairs:
        a.step(v, tv)
    bad = rng.normal(size=30)
    bad[7] = np.inf
    out, extrapolated = a.step(rng.normal(size=30), bad)
    assert out is bad and not extrapolated
    gamma = np.array([-10.0, 1.0])
    rows = np.zeros((2, 4))
    rows[0, 1] = 1e308                               # 1e309 overflows
    out = np.ones(4)
    assert not S._minus_rows(out, rows, gamma, 0, 1) and np.isinf(out[1])
    out = np.ones(4)
    rows[0, 1], rows[1, 2] = 1.0, np.nan
    assert S._minus_rows(out, rows, gamma, 0, 1)    # the first row alone: finite
    np.testing.assert_array_equal(out, [1.0, 11.0, 1.0, 1.0])
    assert not S._minus_rows(out, rows, gamma, 0, 2) and np.isnan(out[2])


def test_factor_beyond_the_bitset_limit_lets_superlu_order(monkeypatch):
    nc = 200
    W = block_matrix(nc, 10, density=0.02)
    fr = _Frame(FrictionContactProblem(W, np.ones(3 * nc), np.full(nc, 0.5)))
    monkeypatch.setattr(O, "BITSET_MAX", nc - 1)
    f = _Factor(fr, 0.1)
    assert fr.cache["ordering"] is None
    b = np.random.default_rng(11).normal(size=3 * nc)
    ref = np.linalg.solve(fr.W.toarray() + 0.1 * np.eye(3 * nc), b)
    np.testing.assert_allclose(f.solve(b), ref, rtol=1e-10, atol=1e-12 * np.abs(ref).max())


def test_unsorted_rows_let_superlu_order():
    nc = 150
    W = block_matrix(nc, 12, density=0.03)
    fr = _Frame(FrictionContactProblem(W, np.ones(3 * nc), np.full(nc, 0.5)))
    fr.W.has_sorted_indices = False                  # the contacts' graph reads sorted rows
    f = _Factor(fr, 0.1)
    assert fr.cache["ordering"] is None
    b = np.random.default_rng(13).normal(size=3 * nc)
    ref = np.linalg.solve(fr.W.toarray() + 0.1 * np.eye(3 * nc), b)
    np.testing.assert_allclose(f.solve(b), ref, rtol=1e-10, atol=1e-12 * np.abs(ref).max())


@pytest.mark.parametrize("nc, nonsymmetric", [(60, 0.0), (60, 0.3), (200, 0.0), (200, 0.3)])
def test_compiled_triangular_solves_are_a_dense_solve(monkeypatch, nc, nonsymmetric):
    """The factors as CSR arrays, solved in compiled code (:func:`lu_solve`): SuperLU's
    factors of the contacts' ordering (180 and 600 unknowns), against NumPy's dense solve of W + cI (with the step of
    refinement where the factor's test asks for it). Every fill is let through."""
    from frictionrules.multicontact import _admm as A
    monkeypatch.setattr(A, "COMPILED_FILL_MAX", 3 * nc)
    monkeypatch.setattr(A, "SYMMETRIC_MIN_ENTRIES", 0)
    monkeypatch.setattr(T, "block_factors", lambda arrays, patterns=None: (arrays, patterns))         # the rows' form
    W = block_matrix(nc, 6, density=0.02, nonsymmetric=nonsymmetric)
    fr = _Frame(FrictionContactProblem(W, np.ones(3 * nc), np.full(nc, 0.5)))
    c = 0.1
    f = _Factor(fr, c)
    assert f.arrays is not None
    b = np.random.default_rng(7).normal(size=3 * nc)
    ref = np.linalg.solve(fr.W.toarray() + c * np.eye(3 * nc), b)
    x = f.solve(b)
    np.testing.assert_allclose(x, ref, rtol=1e-10, atol=1e-12 * np.abs(ref).max())
    wp, wi, wx, blocks = _compiled_w(fr)
    again = S.factor_solve(*f.arrays, f.refine, c, wp, wi, wx, blocks, b, np.empty(b.size), np.empty(b.size))
    np.testing.assert_array_equal(again, x)
    triples = f.arrays[-1]
    assert np.all(triples == 3)                    # W of whole 3 x 3 blocks: every contact's rows
    by_rows = T.lu_solve(*f.arrays[:-1], np.zeros_like(triples), b)
    np.testing.assert_allclose(T.lu_solve(*f.arrays, b), by_rows, rtol=1e-12, atol=1e-14 * np.abs(by_rows).max())
    # SuperLU's factors of a symmetric W + cI keep L alone (U = D L^T), those of a
    # nonsymmetric W keep U
    assert (f.arrays[3].size == 0) == (nonsymmetric == 0.0)


@pytest.mark.parametrize("nc", [60, 200])
def test_symmetric_form_is_the_lu_solve_with_u(monkeypatch, nc):
    """U = D L^T (:func:`symmetric_form`) for SuperLU's factors of a symmetric W + cI; the
    solve from L alone (read again column by column, by triples or entry by entry) is the
    solve with U to round-off, and a dense solve's. A U that is not D L^T (one entry moved by
    1e-9 of the largest, or one entry missing) is kept."""
    from frictionrules.multicontact import _admm as A
    keep = A._symmetric
    monkeypatch.setattr(A, "_symmetric", lambda arrays: arrays)
    monkeypatch.setattr(A, "COMPILED_FILL_MAX", 3 * nc)
    monkeypatch.setattr(T, "block_factors", lambda arrays, patterns=None: (arrays, patterns))         # the rows' form
    W = block_matrix(nc, 6, density=0.02)
    fr = _Frame(FrictionContactProblem(W, np.ones(3 * nc), np.full(nc, 0.5)))
    full = _Factor(fr, 0.1).arrays
    lp, li, lx, up, ui, ux, ud, rows, cols, triples = full
    assert up.size == 3 * nc + 1 and np.array_equal(rows, cols) and np.all(triples == 3)
    assert T.symmetric_form(lp, li, lx, up, ui, ux, ud)
    monkeypatch.setattr(A, "SYMMETRIC_MIN_ENTRIES", lx.size + 1)
    assert keep(full) is full                       # below SYMMETRIC_MIN_ENTRIES: U kept
    monkeypatch.setattr(A, "SYMMETRIC_MIN_ENTRIES", lx.size)
    half = keep(full)
    assert half[3].size == half[4].size == half[5].size == 0 and half[2] is lx
    b = np.random.default_rng(5).normal(size=3 * nc)
    with_u = T.lu_solve(*full, b)
    scale = np.abs(with_u).max()
    np.testing.assert_allclose(T.lu_solve(*half, b), with_u, rtol=1e-12, atol=1e-14 * scale)
    by_entries = T.lu_solve(*half[:-1], np.zeros_like(triples), b)
    np.testing.assert_allclose(by_entries, with_u, rtol=1e-12, atol=1e-14 * scale)
    ref = np.linalg.solve(fr.W.toarray() + 0.1 * np.eye(3 * nc), b)
    np.testing.assert_allclose(with_u, ref, rtol=1e-9, atol=1e-12 * scale)
    moved = ux.copy()
    moved[ux.size // 2] += 1e-9 * np.abs(ux).max()
    assert not T.symmetric_form(lp, li, lx, up, ui, moved, ud)
    assert keep((lp, li, lx, up, ui, moved, ud, rows, cols, triples))[3] is up
    short = up.copy()
    short[-2:] -= 1                                 # U's last stored entry left out
    assert not T.symmetric_form(lp, li, lx, short, ui[:-1], ux[:-1], ud)


@pytest.mark.parametrize("nonsymmetric, symmetric_min", [(0.0, 0), (0.0, 10**9), (0.3, 0)])
def test_block_factors_solve_as_the_rows(monkeypatch, nonsymmetric, symmetric_min):
    """The factors in 3 x 3 blocks by contacts (:func:`block_factors`) give the solve of the
    rows' form to round-off (each block's terms summed first: within 64 eps cond(A) |x|): L
    alone (U = D L^T), L and U of a symmetric W, L and U of a nonsymmetric one; and the blocks
    hold every entry of the rows, each in its place."""
    from frictionrules.multicontact import _admm as A
    monkeypatch.setattr(A, "COMPILED_FILL_MAX", 600)
    monkeypatch.setattr(A, "SYMMETRIC_MIN_ENTRIES", symmetric_min)
    keep = T.block_factors
    monkeypatch.setattr(T, "block_factors", lambda arrays, patterns=None: (arrays, patterns))
    nc = 200
    W = block_matrix(nc, 6, density=0.02, nonsymmetric=nonsymmetric)
    fr = _Frame(FrictionContactProblem(W, np.ones(3 * nc), np.full(nc, 0.5)))
    rows = _Factor(fr, 0.1).arrays
    blocks, _ = keep(rows)
    assert blocks is not rows and blocks[0].size == nc + 1
    assert (blocks[3].size == 0) == (rows[3].size == 0) == (nonsymmetric == 0.0 and symmetric_min == 0)
    cond = np.linalg.cond(fr.W.toarray() + 0.1 * np.eye(3 * nc))
    for b in np.random.default_rng(9).normal(size=(3, 3 * nc)):
        x = T.lu_solve(*rows, b)
        assert np.linalg.norm(T.lu_solve(*blocks, b) - x) <= 64 * np.finfo(float).eps * cond * np.linalg.norm(x)
    def dense(ptr, idx, vals, by_blocks):
        if not by_blocks:
            return sp.csr_matrix((vals, idx, ptr), shape=(3 * nc, 3 * nc)).toarray()
        out = np.zeros((3 * nc, 3 * nc))
        for t in range(nc):
            for k in range(ptr[t], ptr[t + 1]):
                out[3 * t:3 * t + 3, 3 * idx[k]:3 * idx[k] + 3] += vals[9 * k:9 * k + 9].reshape(3, 3)
        return out
    for part in ((0, 3), (3, 6)) if rows[3].size else ((0, 3),):       # L, and U where kept
        np.testing.assert_array_equal(dense(*blocks[slice(*part)], True), dense(*rows[slice(*part)], False))


def test_block_factors_fill_partial_blocks_with_zeros(monkeypatch):
    """Rows that are not a contact's triple, or blocks they fill in part, are stored in blocks
    with zeros where no entry is (the solve of the rows' form to round-off, and a dense
    solve's); a pattern whose blocks would be mostly zeros stays in the rows' form."""
    monkeypatch.setattr(T, "BLOCK_FILL_MAX", 10.0)      # two contacts: blocks mostly the diagonal's
    def csr(rows):
        return (np.cumsum([0] + [len(r) for r in rows]).astype(np.int32),
                np.array([c for r in rows for c in r], np.int32))
    rng = np.random.default_rng(4)
    lp, li = csr([[], [0], [0, 1], [1], [1, 3], [0, 1, 3, 4]])      # contact 1: partial blocks
    up, ui = csr([[1, 2, 4], [2, 3], [3, 4, 5], [4, 5], [5], []])
    lx, ux, ud = rng.normal(size=li.size), rng.normal(size=ui.size), rng.uniform(2, 3, 6)
    rows = np.arange(6)
    arrays = (lp, li, lx, up, ui, ux, ud, rows, rows, T.contact_triples(lp, li, up, ui))
    blocks, _ = T.block_factors(arrays)
    assert blocks[0].size == 3 and blocks[2].size == 9 * 3 and blocks[5].size == 9 * 3
    L = np.eye(6) + sp.csr_matrix((lx, li, lp), shape=(6, 6)).toarray()
    U = np.diag(ud) + sp.csr_matrix((ux, ui, up), shape=(6, 6)).toarray()
    b = rng.normal(size=6)
    np.testing.assert_allclose(T.lu_solve(*blocks, b), T.lu_solve(*arrays, b), rtol=1e-14)
    np.testing.assert_allclose(T.lu_solve(*blocks, b), np.linalg.solve(L @ U, b), rtol=1e-12)
    monkeypatch.setattr(T, "BLOCK_FILL_MAX", 1.5)
    nc = 30                                                            # one entry per row, each
    lp, li = csr([[] for _ in range(3)] + [[3 * (k // 3) - 3 + k % 3] for k in range(3, 3 * nc)])
    up, ui = csr([[] for _ in range(3 * nc)])                          # in a block of its own row
    scattered = (lp, li, np.ones(li.size), up, ui, np.ones(0), np.ones(3 * nc), np.arange(3 * nc),
                 np.arange(3 * nc), T.contact_triples(lp, li, up, ui))
    assert T.block_factors(scattered)[0] is scattered


@given(nc=st.integers(1, 12), density=st.floats(0.0, 1.0), seed=st.integers(0, 2**32 - 1),
       symmetric=st.booleans())
def test_block_solve_is_a_dense_solve(nc, density, seed, symmetric):
    """Any unit lower L and upper U (or U = D L^T: L alone), of any pattern, solved in blocks
    (:func:`block_factors`, every fill let through), and in rows: each a solution of the dense
    ``(L U) x = b`` with rows and columns permuted, its residual at round-off of the
    triangular solves (whatever the conditioning of the draw)."""
    rng = np.random.default_rng(seed)
    n = 3 * nc
    keep = rng.random((n, n)) < density
    Ld = np.tril(np.where(keep, rng.uniform(-0.5, 0.5, (n, n)), 0.0), -1)
    d = rng.uniform(1.0, 2.0, n) * rng.choice([-1.0, 1.0], n)
    Ud = np.diag(d) @ Ld.T if symmetric else np.triu(np.where(keep.T, rng.uniform(-0.5, 0.5, (n, n)), 0.0), 1)
    L, U = sp.csr_matrix(Ld), sp.csr_matrix(Ud)
    rows, cols = rng.permutation(n), rng.permutation(n)
    arrays = (L.indptr.astype(np.int32), L.indices.astype(np.int32), L.data, U.indptr.astype(np.int32),
              U.indices.astype(np.int32), U.data, d, rows, cols,
              T.contact_triples(L.indptr, L.indices, U.indptr, U.indices))
    if symmetric:
        arrays = arrays[:3] + (arrays[3][:0], arrays[4][:0], arrays[5][:0]) + arrays[6:]
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(T, "BLOCK_FILL_MAX", 1e9)
        blocks, _ = T.block_factors(arrays)
    assert blocks[0].size == nc + 1
    b = rng.normal(size=n)
    A = (np.eye(n) + Ld) @ (Ud + np.diag(d) if not symmetric else np.diag(d) + np.diag(d) @ Ld.T)
    B = np.empty((n, n))                            # L U = B, B_ij = A'_{rows_i cols_j}
    B[np.ix_(rows, cols)] = A
    Ua = np.abs(Ud) + np.diag(np.abs(d)) if not symmetric else np.diag(np.abs(d)) @ (np.eye(n) + np.abs(Ld.T))
    bound = 10 * n * np.finfo(float).eps * ((np.eye(n) + np.abs(Ld)) @ Ua).sum(axis=1).max()
    for x in (T.lu_solve(*blocks, b), T.lu_solve(*arrays, b)):   # backward stable: |r| <~ n eps |L||U||x|
        assert np.abs(B @ x - b).max() <= bound * np.abs(x).max() + 1e-15 * np.abs(b).max()


def test_contact_triples_need_the_shared_columns():
    """A triple of rows is summed together only where its rows share their other columns: L's
    rows P, P + [3t], P + [3t, 3t + 1], U's [3t + 1, 3t + 2] + Q, [3t + 2] + Q, Q."""
    def csr(rows):
        ptr = np.cumsum([0] + [len(r) for r in rows]).astype(np.int32)
        return ptr, np.array([c for r in rows for c in r], np.int32)
    lp, li = csr([[], [0], [0, 1], [0, 1], [0, 1, 3], [0, 1, 3, 4]])
    up, ui = csr([[1, 2, 4], [2, 4], [4], [4, 5], [5], []])
    np.testing.assert_array_equal(T.contact_triples(lp, li, up, ui), [3, 3])
    lp, li = csr([[], [0], [0, 1], [0], [1, 3], [0, 1, 3, 4]])      # L's row 4 lost column 0
    np.testing.assert_array_equal(T.contact_triples(lp, li, up, ui), [3, 2])
    up, ui = csr([[1, 2, 4], [2], [4], [4, 5], [5], []])              # U's row 1 lost column 4
    np.testing.assert_array_equal(T.contact_triples(lp, li, up, ui), [1, 2])


def test_dense_factors_rebuild_lapacks_lu():
    """P A = L U from :func:`dense_factors`: the rows' order from LAPACK's interchanges, the
    unit lower and the upper triangle, zeros left out."""
    import scipy.linalg as sla
    rng = np.random.default_rng(3)
    A = rng.normal(size=(30, 30))
    A[rng.random((30, 30)) < 0.5] = 0.0
    A += 4 * np.eye(30)
    lu, piv = sla.lu_factor(A)
    lp, li, lx, up, ui, ux, ud, rows = T.dense_factors(lu, piv)
    L = sp.csr_matrix((lx, li, lp), shape=A.shape).toarray() + np.eye(30)
    U = sp.csr_matrix((ux, ui, up), shape=A.shape).toarray() + np.diag(ud)
    np.testing.assert_allclose(L @ U, A[rows], atol=1e-12)
    assert lx.size + ux.size == np.count_nonzero(np.tril(lu, -1)) + np.count_nonzero(np.triu(lu, 1))


@needs_fclib
@pytest.mark.parametrize("name, anderson, doublings", [("Capsules-i125-1213.hdf5", 5, 0),
                                                       ("Capsules-i125-1213.hdf5", 5, 2),
                                                       ("Spheres-i099-356-679.hdf5", 5, 0),
                                                       ("local_problem_test.hdf5", 0, 0),
                                                       ("spheres-in-a-box-98-i10000-256-10.hdf5", 5, 0)])
def test_compiled_loop_is_the_python_loop(name, anderson, doublings):
    """ADMM's iterations in one compiled loop (no callback) and one by one in Python (a
    callback that never stops the run): with the error measured at every iteration
    (``max_check_interval=1``), the same errors at every iteration (the compiled error sums as
    the frame's), the same answer; also with Anderson's pause doubled after repeated drops and
    on spheres-in-a-box, whose rho jumps by several levels (120 iterations there)."""
    from frictionrules import ADMMOptions, read_fclib, solve
    p = read_fclib(FCLIB / name)
    opts = ADMMOptions(anderson=anderson, max_check_interval=1, anderson_pause_doublings=doublings)
    if name.startswith("spheres-in"):
        a = solve(p, method="admm", tol=0.0, max_iter=120, options=opts)
        seen = []
        b = solve(p, method="admm", tol=0.0, max_iter=120, options=opts, callback=lambda info: seen.append(info.error))
        np.testing.assert_allclose(a.history, seen, rtol=1e-9)
        np.testing.assert_allclose(a.r, b.r, rtol=1e-9, atol=1e-12 * np.abs(b.r).max())
        return
    seen = []
    a = solve(p, method="admm", tol=1e-8, options=opts)
    b = solve(p, method="admm", tol=1e-8, options=opts, callback=lambda info: seen.append(info.error))
    assert a.converged and b.converged
    assert a.iterations == b.iterations
    np.testing.assert_allclose(a.history, seen, rtol=1e-9)
    np.testing.assert_array_equal(a.history_iterations, b.history_iterations)
    np.testing.assert_allclose(a.r, b.r, rtol=1e-9, atol=1e-12 * np.abs(b.r).max())


@needs_fclib
@pytest.mark.parametrize("name", ["Capsules-i125-1213.hdf5", "Spheres-i099-356-679.hdf5", "local_problem_test.hdf5",
                                  "Box_Stacks-i0122-82-5.hdf5"])
def test_error_measured_at_intervals_is_the_same_run(name):
    """With the error measured only at some iterations (the default ``max_check_interval``)
    the iterates are the same as with it measured at every one (the measure does not feed the
    iteration): the errors recorded are those of the every-iteration run at the same
    iterations, at most ``max_check_interval`` (+ 1) apart, and the run stops at the first measured
    iteration at or after the every-iteration run's stop (here within 8)."""
    from frictionrules import ADMMOptions, read_fclib, solve
    p = read_fclib(FCLIB / name)
    every = solve(p, method="admm", tol=1e-8, options=ADMMOptions(max_check_interval=1))
    some = solve(p, method="admm", tol=1e-8)
    assert every.converged and some.converged
    k = some.history_iterations
    # one more where the iteration due was an extrapolation dropped (then the plain step runs alone)
    assert k[0] == 1 and np.all(np.diff(k) >= 1) and np.all(np.diff(k) <= ADMMOptions().max_check_interval + 1)
    assert len(k) < len(every.history_iterations)
    by_iteration = dict(zip(every.history_iterations.tolist(), every.history))
    measured = [(e, by_iteration[i]) for i, e in zip(k.tolist(), some.history) if i <= every.iterations]
    assert len(measured) == np.count_nonzero(k <= every.iterations)     # no dropped step measured
    np.testing.assert_allclose(*np.array(measured).T, rtol=1e-12)
    assert every.iterations <= some.iterations <= every.iterations + ADMMOptions().max_check_interval


@needs_fclib
def test_error_measured_at_the_last_iteration_at_tolerance_zero():
    """At tolerance zero the error is measured at most ``max_check_interval`` iterations apart
    and at the last iteration, whose error the result reports."""
    from frictionrules import ADMMOptions, read_fclib, solve
    p = read_fclib(FCLIB / "Spheres-i099-356-679.hdf5")
    s = solve(p, method="admm", tol=0.0, max_iter=120, options=ADMMOptions(max_check_interval=6))
    k = s.history_iterations
    assert k[-1] == 120 and s.iterations == 120
    assert np.all(np.diff(k) <= 6 + 1) and len(k) < 120


def test_rho_change_stays_in_its_band():
    """The residuals' balance (ratio 10) asks +1 or -1; a step leaving [lo, hi] is refused,
    a step from outside towards the band is kept."""
    limits = np.zeros(11)
    limits[2], limits[7], limits[8], limits[9], limits[10] = 10.0, 1.0, 8.0, 2.0, 8.0
    assert S.rho_change(100.0, 1.0, 2.0, 0, limits) == 1
    assert S.rho_change(1.0, 100.0, 2.0, 0, limits) == -1
    assert S.rho_change(5.0, 1.0, 2.0, 0, limits) == 0
    assert S.rho_change(100.0, 1.0, 8.0, 0, limits) == 0         # 16 > hi
    assert S.rho_change(1.0, 100.0, 1.0, 0, limits) == 0         # 0.5 < lo
    assert S.rho_change(1.0, 100.0, 64.0, 0, limits) == -1       # above the band, towards it
    assert S.rho_change(100.0, 1.0, 0.25, 0, limits) == 1        # below the band, towards it


def test_anderson_pause_doubles_after_repeated_drops():
    """The pause after the k-th drop in a row (k = 0, 1, ...) is pause 2^k, k at most the
    doublings allowed; with none allowed it is the plain pause."""
    assert [S.pause_length(10, k, 2.0) for k in range(5)] == [10, 20, 40, 40, 40]
    assert [S.pause_length(10, k, 0.0) for k in range(3)] == [10, 10, 10]


def test_rho_streak_doubles_its_levels():
    """A run of changes the same way, each as soon as allowed: 1, 1, 2, 4, 8, 8 levels
    (``rho_levels_max`` 8), so 2^k levels in about k + 2 changes; a change the other way, or
    one after a pause, starts again at one level; within the band only the levels that fit."""
    limits = np.zeros(11)
    limits[2], limits[7], limits[8], limits[9], limits[10] = 10.0, 2.0 ** -40, 1.0, 2.0, 8.0
    rho, streak, levels = 1.0, 0, []
    for _ in range(6):
        change = S.rho_change(1.0, 100.0, rho, streak, limits)
        streak = S.rho_streak(streak, change, True)
        rho *= 2.0 ** change
        levels.append(change)
    assert levels == [-1, -1, -2, -4, -8, -8] and streak == -6
    assert S.rho_change(100.0, 1.0, rho, streak, limits) == 1          # the other way
    assert S.rho_streak(streak, 1, True) == 1
    assert S.rho_streak(streak, -1, False) == -1                       # after a pause
    assert S.rho_change(1.0, 100.0, 2.0 ** -37, -5, limits) == -3      # 2^-40 is the band's end
    limits[10] = 1.0
    assert S.rho_change(1.0, 100.0, 1.0, -5, limits) == -1             # rho_levels_max = 1


@needs_fclib
def test_rho_streak_factorizes_less_on_spheres_in_a_box():
    """spheres-in-a-box: rho drifts down from its spectral start by eleven levels; with jumps
    of up to 8 levels its first 120 iterations factorize fewer times than level by level, and
    its iterates at the iterations before the first jump are the same."""
    from frictionrules import ADMMOptions, read_fclib, solve
    from frictionrules.multicontact import _admm
    p = read_fclib(FCLIB / "spheres-in-a-box-98-i10000-256-10.hdf5")
    counts = []
    for levels in (1, 8):
        made = []
        original = _admm._Factor.__init__

        def counting(self, fr, c, original=original, made=made):
            made.append(c)
            original(self, fr, c)
        _admm._Factor.__init__ = counting
        try:
            s = solve(p, method="admm", tol=0.0, max_iter=120, options=ADMMOptions(rho_levels_max=levels,
                                                                                    max_check_interval=1))
        finally:
            _admm._Factor.__init__ = original
        counts.append((len(made), s.history[:14]))
    assert counts[1][0] < counts[0][0] - 3
    np.testing.assert_array_equal(counts[0][1], counts[1][1])


@pytest.mark.parametrize("kw, name", [({"max_check_interval": 0}, "max_check_interval"),
                                      ({"rho_min": -1.0}, "rho_min"),
                                      ({"rho_levels_max": 0}, "rho_levels_max"),
                                      ({"anderson_pause_doublings": -1}, "anderson_pause_doublings"),
                                      ({"rho_min": 1.0, "rho_max": 0.5}, "rho_max")])
def test_admm_options_name_the_bad_argument(kw, name):
    from frictionrules import ADMMOptions, FrictionRulesError
    with pytest.raises(FrictionRulesError, match=name):
        ADMMOptions(**kw)
