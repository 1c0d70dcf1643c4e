"""The factored operator W = J M^-1 J^T (multicontact.factored) against the same problem on W.

A random multibody problem: kinematic trees of 1-6 dofs with SPD mass blocks, contacts on one
or two trees with random Jacobian blocks. The blocks' W equals the dense J M^-1 J^T; the
factored sweeps are the W sweeps of ``solve(..., "nsgs")`` to rounding (same local solver,
same checks of the error), on the cone path (Coulomb, dilatant Coulomb) and on the law path
(the transformed-variable rule (1.18)).
"""

from __future__ import annotations

import numpy as np
import pytest

import frictionrules as fr
from frictionrules.errors import FrictionRulesError
from frictionrules.multicontact.factored import ContactLaws, TreeBlocks, solve_factored

pytest.importorskip("numba")


def random_system(seed: int, ntree: int = 6, nc: int = 9):
    """``(blocks, J (3 nc, nv) dense, Minv (nv, nv), q)``: contacts pushed together (q_N < 0)."""
    rng = np.random.default_rng(seed)
    dofnum = rng.integers(1, 7, ntree)
    dofadr = np.concatenate(([0], np.cumsum(dofnum)[:-1]))
    nv = int(dofnum.sum())
    Minv = np.zeros((nv, nv))
    for a, n in zip(dofadr, dofnum):
        G = rng.normal(size=(n, n))
        Minv[a:a + n, a:a + n] = np.linalg.inv(G @ G.T + n * np.eye(n))
    tree = np.full((nc, 2), -1, dtype=np.int64)
    offset = np.zeros((nc, 2), dtype=np.int64)
    Jd = np.zeros((3 * nc, nv))
    Jp, Bp, size = [], [], 0
    for c in range(nc):
        ts = rng.choice(ntree, size=1 + (c % 2), replace=False)
        for s, t in enumerate(ts):
            a, n = dofadr[t], dofnum[t]
            block = rng.normal(size=(3, n))
            Jd[3 * c:3 * c + 3, a:a + n] = block
            tree[c, s], offset[c, s] = t, size
            Jp.append(block.ravel())
            Bp.append((block @ Minv[a:a + n, a:a + n]).ravel())
            size += 3 * n
    W = Jd @ Minv @ Jd.T
    D = np.array([W[3 * c:3 * c + 3, 3 * c:3 * c + 3] for c in range(nc)])
    blocks = TreeBlocks(tree, offset, np.concatenate(Jp), np.concatenate(Bp), dofadr.astype(np.int64),
                        dofnum.astype(np.int64), D, nv)
    q = rng.normal(size=3 * nc)
    q[0::3] = -np.abs(q[0::3]) - 0.1
    return blocks, Jd, Minv, q


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_blocks_give_W_equal_to_J_Minv_JT_and_its_products(seed):
    """W_ac = sum_t J_a,t M_t^-1 J_c,t^T, M^-1 J^T r and J v + q against the dense products."""
    blocks, J, Minv, q = random_system(seed)
    W = J @ Minv @ J.T
    assert np.abs(blocks.delassus().toarray() - W).max() <= 1e-13 * np.abs(W).max()
    rng = np.random.default_rng(seed + 10)
    r, v = rng.normal(size=q.size), rng.normal(size=blocks.nv)
    assert blocks.impulse_velocity(r) == pytest.approx(Minv @ J.T @ r, rel=1e-12, abs=1e-12)
    assert blocks.velocity(v, q) == pytest.approx(J @ v + q, rel=1e-12, abs=1e-12)


@pytest.mark.parametrize("law", [0.5, fr.Coulomb(0.4, dilatant=True), fr.TransformedCoulomb(0.5, 0.25)],
                         ids=["coulomb", "dilatant", "transformed"])
@pytest.mark.parametrize("sweeps", [1, 3, 40])
def test_factored_sweeps_are_the_nsgs_sweeps_on_W(law, sweeps):
    """The same sweeps (Gauss-Seidel in the contacts' order, the same local solver) from the
    same start: the impulses and the error equal ``solve(problem, "nsgs")``'s to rounding."""
    blocks, J, Minv, q = random_system(3)
    laws = [law] * blocks.nc
    problem = fr.FrictionContactProblem(blocks.delassus(), q, laws)
    r0 = np.tile([0.1, 0.0, 0.0], blocks.nc)
    ref = fr.solve(problem, "nsgs", 1e-300, sweeps, r0=r0)
    got = solve_factored(ContactLaws(laws), blocks, q, r0, tol=1e-300, max_iter=sweeps)
    scale = np.abs(ref.r).max()
    assert np.abs(got.r - ref.r).max() <= 1e-10 * scale
    assert got.iterations == ref.iterations == sweeps
    assert got.error == pytest.approx(ref.error, rel=1e-6, abs=1e-14)
    assert got.error_measure == ref.error_measure
    assert got.u == pytest.approx(problem.velocity(got.r), rel=1e-10, abs=1e-12 * np.abs(q).max())


@pytest.mark.parametrize("law", [0.5, fr.TransformedCoulomb(0.5, 0.25)], ids=["coulomb", "transformed"])
def test_factored_solve_converges_to_a_solution_of_the_problem_on_W(law):
    """Converged sweeps give a solution: the problem's own error measure on W is within tol."""
    blocks, J, Minv, q = random_system(4)
    laws = [law] * blocks.nc
    problem = fr.FrictionContactProblem(blocks.delassus(), q, laws)
    sol = solve_factored(ContactLaws(laws), blocks, q, tol=1e-10, max_iter=5000)
    assert sol.converged and sol.reason == "converged"
    from frictionrules.multicontact import fc3d_error, law_error
    measure = fc3d_error if problem.path == "cone" else law_error
    assert measure(problem, sol.r) <= 1e-10


@pytest.mark.parametrize("seed", [0, 3, 7])
def test_one_sliding_contact_is_solved_by_its_local_solve_in_one_sweep(seed):
    """One contact sliding under the transformed-variable rule (1.18): the problem is the
    contact's local problem, so one sweep's local Newton (to the return's tolerance) solves it:
    the law path's natural map on W is at round-off, not at the local tolerance's scale."""
    law = fr.TransformedCoulomb(0.5, 0.25)
    blocks, J, Minv, _q = random_system(seed, ntree=1, nc=1)
    q = np.array([-0.3, 1.0 + seed, -0.5 * seed])
    sol = solve_factored(ContactLaws([law]), blocks, q, tol=1e-12, max_iter=50)
    assert sol.converged and sol.iterations == 1
    from frictionrules.multicontact import law_error
    problem = fr.FrictionContactProblem(blocks.delassus(), q, [law])
    assert law_error(problem, sol.r) <= 1e-12
    assert sol.r[0] > 0.0 and np.hypot(sol.u[1], sol.u[2]) > 0.1      # pressed, sliding


def test_factored_refuses_turned_elliptic_cones_and_bad_sizes():
    blocks, J, Minv, q = random_system(5)
    laws = ContactLaws([fr.EllipticOrthotropic(0.5, 0.25)] * blocks.nc)
    with pytest.raises(FrictionRulesError, match="elliptic cones with turned frames"):
        solve_factored(laws, blocks, q)
    with pytest.raises(FrictionRulesError, match="q has 3 entries"):
        solve_factored(ContactLaws([0.5] * blocks.nc), blocks, q[:3])
    with pytest.raises(FrictionRulesError, match="blocks has"):
        solve_factored(ContactLaws([0.5]), blocks, q)
