"""Multi-contact problems: hand-made cases with known solutions, the error measure, the cone
conditions of solutions checked independently of the solvers, per-contact laws."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
from hypothesis import given, settings
from hypothesis import strategies as st

from frictionrules import (Coulomb, EllipticOrthotropic, FrictionContactProblem, FrictionRulesError,
                           Solution, UserLaw, WedgeAsperity, solve)
from frictionrules.io import GlobalProblem
from frictionrules.multicontact import fc3d_error, project_cone

METHODS = ("nsgs", "newton", "prox", "admm")


def cone_violation(mu, r, u, dilatancy=None, scale_r=1.0, scale_u=1.0):
    r"""Largest violation of Coulomb's law (r in K, u^ in K*, r.u^ = 0, slip opposite r_T).

    Checked directly on r and u, independently of any solver or of the error measure. With a
    dilatancy ratio d the normal velocity while sliding is ``mu d |u_T|``. Force violations are
    divided by ``scale_r``, velocity ones by ``scale_u``; the slip direction is checked as
    :math:`|u_T| r_T + \mu r_N u_T = 0`.
    """
    r, u = r.reshape(-1, 3), u.reshape(-1, 3)
    d = np.zeros(len(mu)) if dilatancy is None else np.asarray(dilatancy)
    rt, ut = np.linalg.norm(r[:, 1:], axis=1), np.linalg.norm(u[:, 1:], axis=1)
    uhat_n = u[:, 0] + mu * (1 - d) * ut
    v = [np.max(-r[:, 0]) / scale_r,                       # r_N >= 0
         np.max(rt - mu * r[:, 0]) / scale_r,              # |r_T| <= mu r_N
         np.max(mu * ut - uhat_n) / scale_u,               # u^ in K*: u^_N >= mu |u_T|
         np.max(np.abs(np.sum(r[:, 1:] * u[:, 1:], 1) + r[:, 0] * uhat_n)) / (scale_r * scale_u),
         np.max(np.abs(ut[:, None] * r[:, 1:] + mu[:, None] * r[:, :1] * u[:, 1:])) / (scale_r * scale_u)]
    return max(0.0, max(v))


def single(W, q, mu):
    return FrictionContactProblem(np.asarray(W, float), np.asarray(q, float), [mu])


# ---- one contact: separation, stick, slip (closed forms) ---------------------------------
@pytest.mark.parametrize("method", METHODS)
def test_single_contact_separation(method):
    s = solve(single(np.eye(3), [0.5, 0.3, -0.2], 0.4), method=method)
    assert s.converged
    np.testing.assert_allclose(s.r, 0.0, atol=1e-12)
    np.testing.assert_allclose(s.u, [0.5, 0.3, -0.2], atol=1e-12)


@pytest.mark.parametrize("method", METHODS)
def test_single_contact_stick(method):
    # W = I, q = (-1, 0.1, 0): r = -q lies inside the cone |r_T| = 0.1 <= 0.5 * 1
    s = solve(single(np.eye(3), [-1.0, 0.1, 0.0], 0.5), method=method, tol=1e-12)
    np.testing.assert_allclose(s.r, [1.0, -0.1, 0.0], atol=1e-9)
    np.testing.assert_allclose(s.u, 0.0, atol=1e-9)


@pytest.mark.parametrize("method", METHODS)
def test_single_contact_slip(method):
    # W = I, q = (-1, 2, 0), mu = 0.5: r = (1, -0.5, 0), u = (0, 1.5, 0)
    s = solve(single(np.eye(3), [-1.0, 2.0, 0.0], 0.5), method=method, tol=1e-12)
    np.testing.assert_allclose(s.r, [1.0, -0.5, 0.0], atol=1e-9)
    np.testing.assert_allclose(s.u, [0.0, 1.5, 0.0], atol=1e-9)


@pytest.mark.parametrize("method", METHODS)
def test_single_contact_frictionless_slip(method):
    # mu = 0: r = (1, 0, 0), u = (0, 2, -1)
    s = solve(single(np.eye(3), [-1.0, 2.0, -1.0], 0.0), method=method, tol=1e-12)
    np.testing.assert_allclose(s.r, [1.0, 0.0, 0.0], atol=1e-9)
    np.testing.assert_allclose(s.u, [0.0, 2.0, -1.0], atol=1e-9)


def test_single_contact_slip_coupled_block():
    """A non-diagonal SPD block: the exact local solver must give a zero-error slip."""
    A = np.array([[2.0, 0.3, -0.2], [0.3, 1.5, 0.4], [-0.2, 0.4, 1.2]])
    p = single(A, [-1.0, 1.5, -0.7], 0.3)
    for method in METHODS:
        s = solve(p, method=method, tol=1e-13)
        assert s.error <= 1e-12
        assert cone_violation(np.array([0.3]), s.r, s.u) < 1e-10
        assert np.linalg.norm(s.u[1:]) > 0.1  # it slides


# ---- two stacked blocks (global problem, condensed) --------------------------------------
def stacked_blocks(F, m1=1.0, m2=0.5, mu1=0.4, mu2=0.3, h=0.01, g=9.81):
    """Block 2 on block 1 on the ground, from rest; horizontal push F (along x) on block 2.

    Unknowns v = (v1, v2) (translations), contact 1 ground/block 1, contact 2 block 1/block 2,
    frames (z, x, y). One Moreau step: M v = h f_ext + H r, u = H^T v.
    """
    M = sp.diags([m1] * 3 + [m2] * 3)
    perm = [2, 0, 1]  # (N, T1, T2) = (z, x, y)
    H = np.zeros((6, 6))
    for k, axis in enumerate(perm):
        H[axis, k] = 1.0            # contact 1 acts on block 1
        H[axis, 3 + k] = -1.0       # contact 2: reaction on block 2, opposite on block 1
        H[3 + axis, 3 + k] = 1.0
    f = h * np.array([0.0, 0.0, -m1 * g, F, 0.0, -m2 * g])
    return GlobalProblem(M, sp.csr_matrix(H), f, np.zeros(6), np.array([mu1, mu2]))


@pytest.mark.parametrize("method", METHODS)
def test_two_stacked_blocks_closed_forms(method):
    m1, m2, mu2, h, g = 1.0, 0.5, 0.3, 0.01, 9.81   # as in stacked_blocks (μ1 = 0.4 there)
    # (a) F below both thresholds: everything sticks, the push goes to the ground
    F = 0.5 * mu2 * m2 * g
    s = solve(stacked_blocks(F).condense(), method=method, tol=1e-12)
    np.testing.assert_allclose(s.r, h * np.array([(m1 + m2) * g, -F, 0, m2 * g, -F, 0]), atol=1e-10)
    np.testing.assert_allclose(s.u, 0.0, atol=1e-10)
    # (b) F above mu2 m2 g: the top block slides, the bottom one sticks
    F = 3.0 * mu2 * m2 * g
    s = solve(stacked_blocks(F).condense(), method=method, tol=1e-12)
    T2 = mu2 * m2 * g
    np.testing.assert_allclose(s.r, h * np.array([(m1 + m2) * g, -T2, 0, m2 * g, -T2, 0]), atol=1e-10)
    np.testing.assert_allclose(s.u, [0, 0, 0, 0, h * (F - T2) / m2, 0], atol=1e-10)
    # (c) grippy top, slippery ground: both slide together
    F = 3.0
    p = stacked_blocks(F, mu1=0.1, mu2=0.9).condense()
    s = solve(p, method=method, tol=1e-12)
    a = (F - 0.1 * (m1 + m2) * g) / (m1 + m2)
    np.testing.assert_allclose(s.u, [0, h * a, 0, 0, 0, 0], atol=1e-10)
    np.testing.assert_allclose(s.r[4], h * (m2 * a - F), atol=1e-10)


# ---- the error measure (Siconos fc3d_compute_error), hand-made cases ---------------------
def test_error_zero_at_solutions_and_one_for_r0_under_pressure():
    p = single(np.eye(3), [-1.0, 0.0, 0.0], 0.5)
    # r = 0: u = u^ = (-1, 0, 0), r - u^ = (1, 0, 0) inside K -> residual 1, scale max(1, 0, 1)
    assert fc3d_error(p, np.zeros(3)) == pytest.approx(1.0)
    assert fc3d_error(p, [1.0, 0.0, 0.0]) == 0.0
    p = single(np.eye(3), [-1.0, 2.0, 0.0], 0.5)
    assert fc3d_error(p, [1.0, -0.5, 0.0]) == pytest.approx(0.0, abs=1e-16)


def test_error_hand_value_with_modified_velocity():
    # r = (1, 0, 0), W = I, q = (-1, 0.6, 0.8), mu = 0.5: u = (0, 0.6, 0.8), |u_T| = 1,
    # u^ = (0.5, 0.6, 0.8); z = r - u^ = (0.5, -0.6, -0.8): t = 1 > mu z_N, mu t = 0.5 > -z_N
    # s = (0.5 + 0.5)/1.25 = 0.8, P = (0.8, 0.4 * (-0.6, -0.8)) = (0.8, -0.24, -0.32)
    # residual = |(0.2, 0.24, 0.32)| = sqrt(0.04 + 0.0576 + 0.1024) = sqrt(0.2)
    # scale = max(|q| = sqrt(2), |r| = 1, |u| = 1)
    p = single(np.eye(3), [-1.0, 0.6, 0.8], 0.5)
    assert fc3d_error(p, [1.0, 0.0, 0.0]) == pytest.approx(np.sqrt(0.2) / np.sqrt(2.0), rel=1e-14)


def test_error_unnormalized_below_machine_epsilon():
    p = single(np.eye(3), [0.0, 0.0, 0.0], 0.5)
    assert fc3d_error(p, [1e-17, 0.0, 0.0]) == pytest.approx(1e-17, rel=1e-12)


def test_project_cone_cases():
    mu = 0.5
    np.testing.assert_allclose(project_cone([-1.0, 0.1, 0.0], mu), 0.0)        # polar cone
    np.testing.assert_allclose(project_cone([1.0, 0.3, 0.0], mu), [1.0, 0.3, 0.0])  # inside
    # boundary: s = (1 + 0.5 * 2)/1.25 = 1.6, P = (1.6, 0.8, 0)
    np.testing.assert_allclose(project_cone([1.0, 2.0, 0.0], mu), [1.6, 0.8, 0.0])


@settings(max_examples=50, deadline=None)
@given(st.integers(0, 10_000))
def test_error_kernel_matches_numpy_and_projection_is_a_projection(seed):
    from frictionrules.multicontact import _kernels as K
    rng = np.random.default_rng(seed)
    nc = 4
    A = rng.normal(size=(3 * nc, 3 * nc))
    p = FrictionContactProblem(A @ A.T + np.eye(3 * nc), rng.normal(size=3 * nc), rng.uniform(0, 1, nc))
    r = rng.normal(size=3 * nc)
    W = p.W
    err, _u = K.fc3d_error_kernel(W.indptr.astype(np.int64), W.indices.astype(np.int64), W.data,
                                  p.q, p.mu_bar, p.dilatancy, r, np.linalg.norm(p.q))
    assert err == pytest.approx(fc3d_error(p, r), rel=1e-12)
    z = rng.normal(size=(nc, 3))
    P = project_cone(z, p.mu_bar[:, None][..., 0])
    assert np.all(np.linalg.norm(P[:, 1:], axis=1) <= p.mu_bar * P[:, 0] * (1 + 1e-12) + 1e-15)
    # Moreau: z - P(z) is orthogonal to P(z) and P(P(z)) = P(z)
    np.testing.assert_allclose(np.sum((z - P) * P, axis=1), 0.0, atol=1e-12)
    np.testing.assert_allclose(project_cone(P, p.mu_bar[:, None][..., 0]), P, atol=1e-12)


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 10_000))
def test_random_spd_problems_solved_with_cone_conditions(seed):
    rng = np.random.default_rng(seed)
    nc = 5
    A = rng.normal(size=(3 * nc, 3 * nc))
    mu = rng.uniform(0.1, 1.0, nc)
    p = FrictionContactProblem(A @ A.T + 0.5 * np.eye(3 * nc), rng.normal(size=3 * nc), mu)
    s = solve(p, method="nsgs", tol=1e-11, max_iter=20000)
    if not s.converged:
        s = solve(p, method="prox", tol=1e-11)
    assert s.converged
    assert cone_violation(mu, s.r, s.u) < 1e-8
    np.testing.assert_allclose(s.u, p.W @ s.r + p.q, atol=1e-12)


# ---- the Solution and input checks --------------------------------------------------------
def test_solution_fields_and_history():
    s = solve(single(np.eye(3), [-1.0, 2.0, 0.0], 0.5), method="nsgs")
    assert isinstance(s, Solution)
    assert s.history.shape == s.history_iterations.shape and s.history_iterations[-1] == s.iterations
    assert s.history[-1] == pytest.approx(s.error, abs=1e-15)
    assert s.method == "nsgs" and s.seconds >= 0
    for method in ("newton", "prox"):
        s = solve(single(np.eye(3) + 0.1, [-1.0, 2.0, 0.5], 0.5), method=method)
        np.testing.assert_array_equal(s.history_iterations, np.arange(1, s.iterations + 1))


@pytest.mark.parametrize("kwargs, match", [
    ({"method": "cg"}, "method"), ({"tol": -1.0}, "tol"), ({"max_iter": 0}, "max_iter"),
    ({"r0": np.zeros(4)}, "r0")])
def test_solve_rejects_bad_arguments(kwargs, match):
    with pytest.raises(FrictionRulesError, match=match):
        solve(single(np.eye(3), [-1.0, 0.0, 0.0], 0.5), **kwargs)


@pytest.mark.parametrize("args, match", [
    ((np.eye(4), np.zeros(4), [0.3]), "W"), ((np.eye(3), np.zeros(4), [0.3]), "q"),
    ((np.eye(3), np.zeros(3), [-0.3]), "mu"), ((np.eye(3), np.zeros(3), [0.3, 0.2]), "mu"),
    ((np.eye(3), np.zeros(3), ["x"]), "mu"), ((np.eye(3) * np.nan, np.zeros(3), [0.3]), "W")])
def test_problem_rejects_bad_input(args, match):
    with pytest.raises(FrictionRulesError, match=match):
        FrictionContactProblem(*args)


# ---- beyond Siconos: per-contact laws ---------------------------------------------------
@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("push_angle", [0.0, 0.7, 2.0, -1.2])
def test_block_on_orthotropic_support_pushed_obliquely_eq_1_13(method, push_angle):
    """Block of mass m on an elliptic orthotropic support (axes at 0.4 rad), one Moreau step.

    With W = I/m and T = -r_T the friction force, sliding means T + m u_T = m q_T and, by the
    law's inverse relation (1.13), T = law.force_for_slip(u_T, N): checked with the core law.
    Below the limit (1.9) the block sticks with T = m q_T.
    """
    m, h, g = 2.0, 0.01, 9.81
    law = EllipticOrthotropic(mu_x=0.6, mu_y=0.2, angle=0.4)
    N = m * g * h
    for F in (0.5 * 0.2 * m * g, 3.0 * 0.6 * m * g):  # below the weakest / above the strongest
        q = np.array([-g * h, h * F / m * np.cos(push_angle), h * F / m * np.sin(push_angle)])
        p = FrictionContactProblem(np.eye(3) / m, q, [law])
        s = solve(p, method=method, tol=1e-12)
        assert s.converged
        T = -s.r[1:]
        assert s.r[0] == pytest.approx(N, rel=1e-10)
        if law.limit(m * q[1:], N) <= 0:
            np.testing.assert_allclose(s.u, 0.0, atol=1e-10)
        else:
            assert float(law.limit(T, N)) == pytest.approx(0.0, abs=1e-9)
            np.testing.assert_allclose(T + m * s.u[1:], m * q[1:], atol=1e-10)
            np.testing.assert_allclose(T, law.force_for_slip(s.u[1:], N), atol=1e-8)


def test_orthotropic_push_along_principal_axis_closed_form():
    m, h, g = 1.0, 0.01, 9.81
    law = EllipticOrthotropic(mu_x=0.6, mu_y=0.2, angle=0.4)
    F = 1.0 * m * g
    e = np.array([np.cos(0.4 + np.pi / 2), np.sin(0.4 + np.pi / 2)])  # axis 2, mu_y = 0.2
    p = FrictionContactProblem(np.eye(3) / m, np.r_[-g * h, h * F / m * e], [law])
    s = solve(p, method="nsgs", tol=1e-13)
    np.testing.assert_allclose(-s.r[1:], 0.2 * m * g * h * e, atol=1e-12)
    np.testing.assert_allclose(s.u[1:], h * (F - 0.2 * m * g) / m * e, atol=1e-12)


@pytest.mark.parametrize("method", METHODS)
def test_dilatant_coulomb_eq_1_6_closed_form(method):
    # W = I, q = (-1, 2, 0), mu = 0.5, u_N = mu |u_T|: r_N = 1.6, u = (0.6, 1.2, 0)
    s = solve(single(np.eye(3), [-1.0, 2.0, 0.0], Coulomb(0.5, dilatant=True)), method=method,
              tol=1e-12)
    np.testing.assert_allclose(s.r, [1.6, -0.8, 0.0], atol=1e-9)
    np.testing.assert_allclose(s.u, [0.6, 1.2, 0.0], atol=1e-9)


def test_user_law_dilatancy_angle_probed():
    """g = |T| - tan(psi) N with f = |T| - mu N: ratio d = tan(psi)/mu, u_N = tan(psi)|u_T|."""
    law = UserLaw("sqrt(T1**2 + T2**2) - 0.5*N", potential="sqrt(T1**2 + T2**2) - 0.2*N")
    p = single(np.eye(3), [-1.0, 2.0, 0.0], law)
    assert p.dilatancy[0] == pytest.approx(0.4, rel=1e-6) and p.mu_bar[0] == pytest.approx(0.5, rel=1e-6)
    s = solve(p, method="nsgs", tol=1e-12)
    # r_N - 1 = 0.2 (2 - 0.5 r_N) -> r_N = 1.4 / 1.1
    rn = 1.4 / 1.1
    np.testing.assert_allclose(s.r, [rn, -0.5 * rn, 0.0], atol=1e-8)
    assert s.u[0] == pytest.approx(0.2 * s.u[1], rel=1e-8)


def test_user_law_not_a_cone_rejected():
    with pytest.raises(FrictionRulesError, match="cone"):
        FrictionContactProblem(np.eye(3), np.zeros(3), [UserLaw("T1**2 + T2**2 - N")])


@pytest.mark.parametrize("local", ["non-associated", "associated"])
@pytest.mark.parametrize("Tx", [0.2, 0.9, 2.5, -0.4])
def test_block_on_wedge_asperity_matches_core_law_eq_2_2_eq_2_7(local, Tx):
    """A block on a plane inclined at alpha (one contact), horizontal load Tx, vertical load Q.

    The block moves iff the wedge law's limit (2.2) is exceeded, and then in the direction of
    the wedge law's sliding rule (2.7) (or the associated one): both from the core law.
    """
    alpha, mu, m, h, Q = 0.3, 0.4, 1.0, 0.01, 1.0
    law = WedgeAsperity(alpha, mu, local=local)
    n = np.array([-np.sin(alpha), 0.0, np.cos(alpha)])
    t1 = np.array([np.cos(alpha), 0.0, np.sin(alpha)])
    H = np.stack((n, t1, [0.0, 1.0, 0.0]), axis=1)
    F = np.array([Tx, 0.0, -Q])
    gp = GlobalProblem(sp.identity(3) * m, sp.csr_matrix(H), h * F, np.zeros(3), np.array([mu]))
    local_law = Coulomb(mu, dilatant=(local == "associated"))
    cond = gp.condense()
    p = FrictionContactProblem(cond.W, cond.q, [local_law])
    s = solve(p, method="nsgs", tol=1e-13)
    v = (h * F + H @ s.r) / m
    if law.limit([Tx, 0.0], Q) < 0:
        np.testing.assert_allclose(v, 0.0, atol=1e-12)
    else:
        np.testing.assert_allclose(v / np.linalg.norm(v), law.slip_direction([Tx, 0.0], Q), atol=1e-9)


@pytest.mark.parametrize("method", METHODS)
def test_mixed_laws_stack_on_orthotropic_ground(method):
    """The two stacked blocks with an orthotropic ground and a dilatant upper contact:
    the cone conditions hold in each contact's circular frame and u = W r + q."""
    gp = stacked_blocks(2.0)
    cond = gp.condense()
    laws = [EllipticOrthotropic(0.5, 0.2, 0.3), Coulomb(0.3, dilatant=True)]
    p = FrictionContactProblem(cond.W, cond.q, laws)
    s = solve(p, method=method, tol=1e-12)
    assert s.converged
    rr, uu = s.r.reshape(2, 3).copy(), s.u.reshape(2, 3).copy()
    rr[:, 1:] = np.linalg.solve(p.frames, rr[:, 1:, None])[..., 0]
    uu[:, 1:] = np.einsum("aji,aj->ai", p.frames, uu[:, 1:])
    assert cone_violation(p.mu_bar, rr.ravel(), uu.ravel(), p.dilatancy) < 1e-9
    # the ground contact obeys the elliptic law directly
    assert float(laws[0].limit(-s.r[1:3], s.r[0])) <= 1e-10


# ---- CLI ------------------------------------------------------------------------------------
def test_cli_solve_file_and_folder(tmp_path, capsys):
    from frictionrules.cli import main
    from frictionrules.io import write_fclib
    for k in range(2):
        rng = np.random.default_rng(k)
        A = rng.normal(size=(9, 9))
        write_fclib(tmp_path / f"p{k}.hdf5",
                    FrictionContactProblem(A @ A.T + np.eye(9), rng.normal(size=9), [0.3, 0.5, 0.7]))
    assert main(["solve", str(tmp_path / "p0.hdf5"), "--method", "nsgs", "--tol", "1e-10"]) == 0
    out = capsys.readouterr().out
    assert "p0.hdf5" in out and "contacts" in out
    csv = tmp_path / "out" / "table.csv"
    assert main(["solve", str(tmp_path), "--method", "prox", "--csv", str(csv)]) == 0
    lines = [line for line in csv.read_text().splitlines() if not line.startswith("#")]
    assert lines[0].startswith("file,contacts,method") and len(lines) == 3
    assert all(line.split(",")[5] == "1" for line in lines[1:])


def test_cli_solve_bad_input_exit_code_2(tmp_path, capsys):
    from frictionrules.cli import main
    assert main(["solve", str(tmp_path / "missing.hdf5")]) == 2
    (tmp_path / "bad.hdf5").write_bytes(b"not hdf5")
    assert main(["solve", str(tmp_path / "bad.hdf5")]) == 2
    assert "error" in capsys.readouterr().err


def test_cli_solve_folder_reports_a_bad_file_and_goes_on(tmp_path, capsys):
    """In a folder, a malformed file is reported on its row; the others are still solved and
    the CSV (rewritten after every file) holds them all; the exit code says something failed."""
    from frictionrules.cli import main
    from frictionrules.io import write_fclib
    write_fclib(tmp_path / "b_good.hdf5",
                FrictionContactProblem(np.eye(3), [-1.0, 0.2, 0.0], [0.5]))
    (tmp_path / "a_bad.hdf5").write_bytes(b"not hdf5")
    csv = tmp_path / "table.csv"
    assert main(["solve", str(tmp_path), "--csv", str(csv)]) == 1
    out = capsys.readouterr().out
    assert "a_bad.hdf5" in out and "error" in out and "b_good.hdf5" in out
    rows = [line.split(",") for line in csv.read_text().splitlines()[1:] if not line.startswith("#")]
    assert [r[0] for r in rows] == ["a_bad.hdf5", "b_good.hdf5"]
    assert rows[0][5] == "0" and rows[1][5] == "1" and rows[0][6] == "bad input"


# ---- options records, callback, time limit, reasons -------------------------------------------
def test_options_records_are_validated_and_must_match_the_method():
    from frictionrules import ADMMOptions, NewtonOptions, NSGSOptions, ProxOptions
    for bad, match in [(lambda: ADMMOptions(eta=-1.0), "eta"), (lambda: ADMMOptions(anderson=-2), "anderson"),
                       (lambda: ADMMOptions(anderson_pause=-1), "anderson_pause"),
                       (lambda: NewtonOptions(armijo=2.0), "armijo"), (lambda: ProxOptions(grow=0.5), "grow"),
                       (lambda: NSGSOptions(max_check_interval=0), "max_check_interval"),
                       (lambda: ProxOptions(newton=3), "newton")]:
        with pytest.raises(FrictionRulesError, match=match):
            bad()
    p = single(np.eye(3), [-1.0, 2.0, 0.0], 0.5)
    with pytest.raises(FrictionRulesError, match="NSGSOptions"):
        solve(p, method="nsgs", options=ADMMOptions())
    with pytest.raises(FrictionRulesError, match="auto"):
        solve(p, method="auto", options=ADMMOptions())
    s = solve(p, method="admm", options=ADMMOptions(anderson=0), tol=1e-12)
    np.testing.assert_allclose(s.r, [1.0, -0.5, 0.0], atol=1e-9)


def block_stack(seed=0, nc=6):
    rng = np.random.default_rng(seed)
    A = rng.normal(size=(3 * nc, 3 * nc))
    return FrictionContactProblem(A @ A.T + 0.1 * np.eye(3 * nc), rng.normal(size=3 * nc),
                                  rng.uniform(0.1, 1.0, nc))


@pytest.mark.parametrize("method", ("auto",) + METHODS)
def test_callback_sees_every_iteration_and_can_stop(method):
    from frictionrules import IterationInfo
    seen = []
    s = solve(block_stack(), method=method, tol=1e-12, callback=seen.append)
    assert s.converged and s.reason == "converged" and seen
    assert all(isinstance(i, IterationInfo) for i in seen)
    assert seen[-1].error == pytest.approx(s.history[-1]) and seen[-1].seconds >= 0
    stopped = solve(block_stack(1, nc=20), method=method, tol=1e-14, callback=lambda info: True)
    assert stopped.reason == "callback" and not stopped.converged and len(stopped.history) == 1


def test_time_limit_reported_as_not_converged():
    p = block_stack(2, nc=30)
    s = solve(p, method="nsgs", tol=0.0, time_limit=0.05)
    assert not s.converged and s.reason == "time_limit" and s.seconds < 5.0
    s = solve(p, method="newton", tol=0.0, max_iter=3)
    assert not s.converged and s.reason == "max_iter"


@pytest.mark.parametrize("method", ("auto",) + METHODS)
def test_infeasible_problem_is_never_converged(method):
    """mu = 0 and W_NN = 0 with q_N < 0: u_N = -1 whatever r, so no r satisfies the law; the
    relative error can be pushed down by letting r_N grow, which must not count."""
    p = FrictionContactProblem(np.diag([0.0, 1.0, 1.0]), [-1.0, 0.0, 0.0], [0.0])
    s = solve(p, method=method, tol=1e-8, max_iter=2000)
    assert not s.converged and s.reason in ("unbounded", "max_iter")


def test_auto_is_a_named_choice_and_blas_threads_checked():
    s = solve(block_stack(), method="auto", tol=1e-10)
    assert s.converged and set(s.method.split("+")) <= {"nsgs", "newton", "prox", "admm"}
    with pytest.raises(FrictionRulesError, match="blas_threads"):
        solve(block_stack(), blas_threads=0)
    with pytest.raises(FrictionRulesError, match="time_limit"):
        solve(block_stack(), time_limit=-1.0)
    assert solve(block_stack(), blas_threads=None, tol=1e-10).converged


def test_cli_solve_outputs_checked_before_the_work(tmp_path, capsys):
    from frictionrules.cli import main
    from frictionrules.io import write_fclib
    write_fclib(tmp_path / "p.hdf5", block_stack())
    assert main(["solve", str(tmp_path / "p.hdf5"), "--csv", "/proc/x.csv"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "/proc/x.csv" in err and ".x.csv" not in err
    assert main(["solve", str(tmp_path / "p.hdf5"), "--csv", str(tmp_path / "t.txt")]) == 2
    assert main(["solve", str(tmp_path / "p.hdf5"), "--save-solution", str(tmp_path / "s.png")]) == 2
    assert main(["solve", str(tmp_path / "p.hdf5"), "--warm-start", str(tmp_path / "none.hdf5")]) == 2
    assert "--warm-start" in capsys.readouterr().err


def test_cli_solve_save_warm_start_time_limit_and_resume(tmp_path, capsys):
    from frictionrules.cli import main
    from frictionrules.io import read_solution, write_fclib
    write_fclib(tmp_path / "a.hdf5", block_stack(3))
    write_fclib(tmp_path / "b.hdf5", block_stack(4, nc=40))
    sol = tmp_path / "out" / "a_sol.hdf5"
    assert main(["solve", str(tmp_path / "a.hdf5"), "--method", "nsgs", "--save-solution", str(sol)]) == 0
    assert read_solution(sol, size=18).shape == (18,)
    capsys.readouterr()
    assert main(["solve", str(tmp_path / "a.hdf5"), "--method", "nsgs", "--warm-start", str(sol)]) == 0
    row = capsys.readouterr().out.splitlines()[1].split()
    assert row[0] == "a.hdf5" and int(row[3]) <= 1
    # a problem stopped by the time limit is not converged, with the reason
    assert main(["solve", str(tmp_path / "b.hdf5"), "--method", "nsgs", "--tol", "0",
                 "--time-limit", "0.05"]) == 1
    captured = capsys.readouterr()
    assert "not converged: time_limit" in captured.out
    assert len(captured.err.strip().splitlines()) == 1    # stderr not a terminal: one summary line
    # a folder run writes its table as it goes; a second run does not redo finished files
    csv = tmp_path / "t.csv"
    assert main(["solve", str(tmp_path), "--method", "nsgs", "--max-iter", "50", "--csv", str(csv)]) == 0
    capsys.readouterr()
    assert main(["solve", str(tmp_path), "--method", "nsgs", "--max-iter", "50", "--csv", str(csv)]) == 0
    out = capsys.readouterr().out
    assert out.count("(from --csv)") == 2
    assert main(["solve", str(tmp_path), "--method", "nsgs", "--max-iter", "50", "--csv", str(csv),
                 "--restart"]) == 0
    assert "(from --csv)" not in capsys.readouterr().out


# ---- the associated (dilatant, convex) relaxation ----------------------------------------------
def test_associated_relaxation_single_contact_eq_1_5_vs_eq_1_6():
    """W = I, q = (-1, 2, 0), mu = 0.5. Coulomb (1.5): r = (1, -0.5, 0), u = (0, 1.5, 0),
    dissipation (1.7) D = mu r_N |u_T| = 0.75. Associated (1.6): u_N = mu |u_T|, r_N = 1.6,
    u = (0.6, 1.2, 0): the friction work 0.8 * 1.2 = 0.96 lifts the normal force, 1.6 * 0.6,
    and D = 0."""
    from frictionrules import compare_relaxation
    p = single(np.eye(3), [-1.0, 2.0, 0.0], 0.5)
    assert np.all(p.associated().dilatancy == 1.0) and np.all(p.dilatancy == 0.0)
    c = compare_relaxation(p, method="nsgs", tol=1e-13)
    np.testing.assert_allclose(c.associated.r, [1.6, -0.8, 0.0], atol=1e-10)
    assert c.dissipation_coulomb == pytest.approx(0.75, rel=1e-10)
    assert c.dissipation_associated == pytest.approx(0.0, abs=1e-10)
    assert c.friction_work_associated == pytest.approx(0.96, rel=1e-10)
    assert c.normal_velocity_coulomb == pytest.approx(0.0, abs=1e-12)
    assert c.normal_velocity_associated == pytest.approx(0.6, rel=1e-10)
    assert c.sliding_coulomb == c.sliding_associated == 1
    assert c.coulomb_error_of_associated == pytest.approx(fc3d_error(p, c.associated.r))
    assert c.coulomb_error_of_associated > 0.01
    assert c.warm_started.converged
