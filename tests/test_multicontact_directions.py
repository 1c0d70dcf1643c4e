"""The sparse directions of Newton and the polish after the contacts' ordering: the LU of J,
the Levenberg–Marquardt direction from the quasi-definite augmented system (against the
regularized least-squares problem solved densely), and the augmented matrix's arrays
(against SciPy's block assembly)."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from frictionrules import FrictionContactProblem, NewtonOptions
from frictionrules.multicontact import _ordering as O
from frictionrules.multicontact._frame import _Frame
from frictionrules.multicontact._newton import lm_direction, newton_direction
from frictionrules.multicontact._polish import _lu


def jacobian_like(nc: int, seed: int, singular_contacts=()):
    """A nonsymmetric 3 nc x 3 nc CSR matrix of whole 3 x 3 blocks on a symmetric pattern of
    contacts with every diagonal block (as ``B1 + B2 W``), its rows sorted; the rows of the
    contacts ``singular_contacts`` are zero (stored), which makes it singular."""
    rng = np.random.default_rng(seed)
    G = sp.random(nc, nc, density=0.04, random_state=rng, format="csr")
    G = ((G + G.T) != 0).astype(float) + sp.identity(nc)
    J = sp.kron(G, np.ones((3, 3)), format="csr")
    J.data = rng.normal(size=J.nnz)
    J = sp.csr_matrix(J + 4.0 * np.sqrt(nc * 0.04 * 9) * sp.identity(3 * nc))
    for a in singular_contacts:
        J.data[J.indptr[3 * a]:J.indptr[3 * a + 3]] = 0.0
    J.sort_indices()
    return J


def ordering_of(J):
    nc = J.shape[0] // 3
    return O.contact_ordering(J.indptr.astype(np.int32), J.indices.astype(np.int32), nc)


def test_augmented_csr_is_scipys_block_matrix():
    J = jacobian_like(60, 1)
    n = J.shape[0]
    Jc = J.tocsc()
    lam = 0.37
    ptr, ind, val = O.augmented_csr(J.indptr, J.indices, J.data, Jc.indptr, Jc.indices, Jc.data, lam)
    K = sp.csr_matrix((val, ind, ptr), shape=(2 * n, 2 * n))
    assert K.has_canonical_format
    ref = sp.bmat([[sp.identity(n), J], [J.T, -lam * sp.identity(n)]], format="csr")
    assert (K != ref).nnz == 0


def test_newton_direction_after_the_contacts_ordering_solves_j():
    J = jacobian_like(200, 2)                         # 600 unknowns: the sparse path
    perm = ordering_of(J)
    b = np.random.default_rng(3).normal(size=J.shape[0])
    opts = NewtonOptions()
    x = newton_direction(sp.csc_matrix(J.T), b, sp.identity(J.shape[0], format="csc"), opts, perm=perm)
    ref = np.linalg.solve(J.toarray(), b)
    np.testing.assert_allclose(x, ref, rtol=1e-9, atol=1e-12 * np.abs(ref).max())


@pytest.mark.parametrize("with_ordering", [True, False])
def test_lm_direction_is_the_regularized_least_squares_solution(with_ordering):
    """x = argmin |J x - b|^2 + lam |x|^2, solved densely as the least-squares problem of
    [J; sqrt(lam) I] x = [b; 0] (no normal equations), on a singular J."""
    J = jacobian_like(200, 4, singular_contacts=(0, 7, 31))
    n = J.shape[0]
    b = np.random.default_rng(5).normal(size=n)
    lam = 1e-3 * np.linalg.norm(b)
    perm = ordering_of(J) if with_ordering else None
    x = lm_direction(sp.csc_matrix(J.T), b, lam, sp.identity(n, format="csc"), NewtonOptions(), perm)
    stacked = np.vstack((J.toarray(), np.sqrt(lam) * np.eye(n)))
    ref = np.linalg.lstsq(stacked, np.concatenate((b, np.zeros(n))), rcond=None)[0]
    np.testing.assert_allclose(x, ref, rtol=1e-8, atol=1e-10 * np.abs(ref).max())


def test_newton_direction_on_a_singular_j_is_levenberg_marquardts():
    J = jacobian_like(200, 6, singular_contacts=(3,))
    n = J.shape[0]
    b = np.random.default_rng(7).normal(size=n)
    opts = NewtonOptions()
    lam = opts.lm_weight * np.linalg.norm(b)
    JT, eye = sp.csc_matrix(J.T), sp.identity(n, format="csc")
    x = newton_direction(JT, b, eye, opts, perm=ordering_of(J))
    np.testing.assert_allclose(x, lm_direction(JT, b, lam, eye, opts, None), rtol=1e-6,
                               atol=1e-9 * np.abs(x).max())


def test_polish_lu_after_the_contacts_ordering_solves_the_shifted_j():
    J = jacobian_like(150, 8)
    n = J.shape[0]
    solve = _lu(J, 0.25, dense=False, perm=ordering_of(J))
    b = np.random.default_rng(9).normal(size=n)
    ref = np.linalg.solve(J.toarray() + 0.25 * np.eye(n), b)
    np.testing.assert_allclose(solve(b), ref, rtol=1e-9, atol=1e-12 * np.abs(ref).max())
    assert _lu(jacobian_like(150, 8, singular_contacts=(2,)), 0.0, dense=False,
               perm=ordering_of(J)) is None


def test_frame_ordering_is_kept_and_serves_jacobians():
    W = jacobian_like(150, 10)
    W = sp.csr_matrix(W @ W.T)
    W.sort_indices()
    fr = _Frame(FrictionContactProblem(W, np.ones(W.shape[0]), np.full(150, 0.5)))
    perm = O.frame_ordering(fr)
    assert perm is O.frame_ordering(fr) is fr.cache["ordering"]
    assert np.array_equal(np.sort(perm), np.arange(W.shape[0]))
