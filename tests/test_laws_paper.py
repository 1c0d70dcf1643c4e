"""Each equation of §1 and the first example of §2, (1.4)–(1.18) and (2.1)–(2.8), checked against
an independent derivation (SymPy or elementary geometry) with numbers."""

import numpy as np
import pytest
import sympy as sp

from frictionrules import (
    Coulomb,
    EllipticOrthotropic,
    Huber,
    TransformedCoulomb,
    UserLaw,
    WedgeAsperity,
    compare_rules,
)

Tx, Ty, Q, Nn = sp.symbols("T_x T_y Q N", real=True)
Vx, Vy = sp.symbols("V_x V_y", real=True)
al, mu_s = sp.symbols("alpha mu", positive=True)


# ---------------------------------------------------------------- (1.4)-(1.8) Coulomb
def test_limit_condition_eq_1_4():
    law = Coulomb(0.3)
    T = np.array([[0.3, 0.4], [0.0, 0.0], [0.18, 0.24]])
    np.testing.assert_allclose(law.limit(T, [2.0, 1.0, 1.0]), [0.5 - 0.6, -0.3, 0.0], atol=1e-15)


def test_sliding_rule_eq_1_5_no_normal_slip():
    f = sp.sqrt(Tx**2 + Ty**2) - sp.Rational(3, 10) * Nn
    grad = [sp.diff(f, s) for s in (Tx, Ty)]
    point = {Tx: 0.3, Ty: -0.2, Nn: 1.0}
    expected = np.array([float(g.subs(point)) for g in grad])
    v = Coulomb(0.3).slip_direction([0.3, -0.2], 1.0)
    np.testing.assert_allclose(v[:2], expected / np.linalg.norm(expected), rtol=1e-14)
    assert v[2] == 0.0
    # lambda-dot = |V| (1.5): the slip is a unit vector in the sliding plane
    assert np.hypot(v[0], v[1]) == pytest.approx(1.0)


def test_associated_rule_eq_1_6_opens_by_mu():
    mu = 0.4
    v = Coulomb(mu, dilatant=True).slip_direction([0.1, 0.3], 1.0)
    # (1.6): V = lambda (T/|T|, mu) with opening positive (the paper writes -lambda mu with z
    # pointing into the support; see docs/errata.md)
    lam = 1.0 / np.sqrt(1.0 + mu**2)
    np.testing.assert_allclose(v, lam * np.array([0.1, 0.3, mu * np.hypot(0.1, 0.3)]) / np.hypot(0.1, 0.3),
                               rtol=1e-14)


def test_dissipation_eq_1_7_and_inverse_eq_1_8():
    mu, N = 0.3, 2.0
    D = mu * Nn * sp.sqrt(Vx**2 + Vy**2)
    point = {Vx: 0.7, Vy: -1.1, Nn: N}
    law = Coulomb(mu)
    assert float(law.dissipation([0.7, -1.1], N)) == pytest.approx(float(D.subs(point)), rel=1e-14)
    T_expected = [float(sp.diff(D, s).subs(point)) for s in (Vx, Vy)]
    np.testing.assert_allclose(law.force_for_slip([0.7, -1.1], N), T_expected, rtol=1e-14)
    # the force is on the limit surface and D = T . V (1.7)
    T = law.force_for_slip([0.7, -1.1], N)
    assert float(law.limit(T, N)) == pytest.approx(0.0, abs=1e-15)
    assert float(T @ [0.7, -1.1]) == pytest.approx(float(D.subs(point)), rel=1e-14)


def test_dilatant_coulomb_dissipates_nothing():
    """With (1.6) the opening slip absorbs the frictional power: T.v_t - N v_n = 0."""
    law = Coulomb(0.3, dilatant=True)
    assert float(law.dissipation([0.7, -1.1], 2.0)) == pytest.approx(0.0, abs=1e-15)
    v = law.slip_direction(law.force_for_slip([0.7, -1.1], 2.0), 2.0)
    assert float(law.dissipation(v, 2.0)) == pytest.approx(0.0, abs=1e-15)


# ---------------------------------------------------------------- (1.9)-(1.15) elliptic
def test_limit_condition_eq_1_9_same_zero_set():
    mx, my = sp.Rational(3, 5), sp.Rational(3, 10)
    f19 = Tx**2 / mx**2 + Ty**2 / my**2 - Nn**2
    law = EllipticOrthotropic(0.6, 0.3)
    f_ours = sp.sqrt((Tx / mx) ** 2 + (Ty / my) ** 2) - Nn
    assert sp.simplify((f_ours + Nn) ** 2 - Nn**2 - f19) == 0
    rng = np.random.default_rng(0)
    T = rng.normal(size=(50, 2))
    N = rng.uniform(0.1, 2.0, 50)
    f_num = sp.lambdify((Tx, Ty, Nn), f19)(T[:, 0], T[:, 1], N)
    np.testing.assert_array_equal(np.sign(law.limit(T, N)), np.sign(f_num))


def test_sliding_rule_eq_1_10_and_multiplier_eq_1_11():
    mx, my, N = 0.6, 0.3, 1.5
    law = EllipticOrthotropic(mx, my)
    T = law.force_for_slip([0.4, 0.9], N)
    # (1.10): V = lambda (2Tx/mx^2, 2Ty/my^2, 0), with lambda from (1.11) for the given V
    lam = 0.5 / N * np.sqrt((mx * 0.4) ** 2 + (my * 0.9) ** 2)
    np.testing.assert_allclose(lam * np.array([2 * T[0] / mx**2, 2 * T[1] / my**2]), [0.4, 0.9], rtol=1e-13)
    v = law.slip_direction(T, N)
    assert v[2] == 0.0
    np.testing.assert_allclose(v[:2], np.array([0.4, 0.9]) / np.hypot(0.4, 0.9), rtol=1e-13)


def test_dissipation_eq_1_12_and_inverse_eq_1_13():
    mx, my = sp.Rational(3, 5), sp.Rational(3, 10)
    D = Nn * sp.sqrt((mx * Vx) ** 2 + (my * Vy) ** 2)
    point = {Vx: -0.3, Vy: 0.8, Nn: 1.7}
    law = EllipticOrthotropic(0.6, 0.3)
    assert float(law.dissipation([-0.3, 0.8], 1.7)) == pytest.approx(float(D.subs(point)), rel=1e-14)
    T_expected = [float(sp.diff(D, s).subs(point)) for s in (Vx, Vy)]
    np.testing.assert_allclose(law.force_for_slip([-0.3, 0.8], 1.7), T_expected, rtol=1e-14)
    # D = 2 lambda N^2 (1.12) with lambda of (1.11)
    lam = 0.5 / 1.7 * np.hypot(0.6 * -0.3, 0.3 * 0.8)
    assert 2 * lam * 1.7**2 == pytest.approx(float(D.subs(point)), rel=1e-14)


def test_force_angle_eq_1_14():
    mx, my = 0.6, 0.3
    law = EllipticOrthotropic(mx, my)
    theta = np.array([0.2, 0.7, 1.2, 2.0, -2.5])
    beta = law.force_angle(theta)
    np.testing.assert_allclose(np.tan(theta) / np.tan(beta), mx**2 / my**2, rtol=1e-12)


def test_directional_coefficient_eq_1_15():
    a = sp.symbols("a", real=True)
    mx, my = sp.Rational(3, 5), sp.Rational(3, 10)
    D = sp.sqrt((mx * Vx) ** 2 + (my * Vy) ** 2)  # (1.12) at N = 1
    unit = {Vx: sp.cos(a), Vy: sp.sin(a)}
    Tx_, Ty_ = (sp.diff(D, s).subs(unit) for s in (Vx, Vy))  # (1.13)
    mu15 = sp.sqrt((mx**4 * sp.cos(a) ** 2 + my**4 * sp.sin(a) ** 2) / (mx**2 * sp.cos(a) ** 2 + my**2 * sp.sin(a) ** 2))
    assert sp.simplify(Tx_**2 + Ty_**2 - mu15**2) == 0
    theta = np.linspace(0, 2 * np.pi, 13)
    np.testing.assert_allclose(EllipticOrthotropic(0.6, 0.3).friction_coefficient(theta),
                               sp.lambdify(a, mu15)(theta), rtol=1e-14)


# ---------------------------------------------------------------- (1.16)-(1.18) alternatives
def test_huber_coefficient_eq_1_16():
    theta = np.linspace(-np.pi, np.pi, 17)
    law = Huber(0.6, 0.3)
    np.testing.assert_allclose(law.friction_coefficient(theta), 0.6 * np.cos(theta) ** 2 + 0.3 * np.sin(theta) ** 2,
                               rtol=1e-14)
    # Huber's force is along the slip
    np.testing.assert_allclose(law.force_angle(theta[1:-1]), theta[1:-1], atol=1e-14)


def test_transformed_coefficient_eq_1_17_and_rule_eq_1_18():
    theta = np.linspace(-np.pi, np.pi, 17)
    law = TransformedCoulomb(0.6, 0.3)
    np.testing.assert_allclose(law.friction_coefficient(theta),
                               np.sqrt(0.36 * np.cos(theta) ** 2 + 0.09 * np.sin(theta) ** 2), rtol=1e-14)
    # (1.18): T'/mu = N V/|V|
    V = np.array([0.3, -0.5])
    T = law.force_for_slip(V, 2.0)
    np.testing.assert_allclose(T / [0.6, 0.3], 2.0 * V / np.linalg.norm(V), rtol=1e-14)
    # the transformed force lies on the limit ellipse of (1.9)
    assert float(law.limit(T, 2.0)) == pytest.approx(0.0, abs=1e-14)


def test_only_elliptic_law_obeys_normality_in_sliding_plane():
    """The paper's claim after (1.18): (1.16)-(1.18) do not satisfy normality in the sliding
    plane; the elliptic rule (1.10) does."""
    theta = np.linspace(0.1, 6.2, 40)
    for law, normal in ((EllipticOrthotropic(0.6, 0.3, 0.4), True), (Huber(0.6, 0.3, 0.4), False),
                        (TransformedCoulomb(0.6, 0.3, 0.4), False), (Coulomb(0.3), True)):
        T = law.force_for_slip(np.stack((np.cos(theta), np.sin(theta)), -1), 1.0)
        angle = compare_rules(law, T, np.ones(theta.shape)).tangential_angle
        assert law.tangentially_associated is normal
        if normal:
            assert np.max(np.abs(angle)) < 1e-12
        else:
            assert np.max(np.abs(angle)) > 0.05


# ---------------------------------------------------------------- (2.1)-(2.8) wedge
def _plane(alpha):
    """Independent geometry: up-slope tangent and upward normal of the plane, z up."""
    t1 = np.array([np.cos(alpha), 0.0, np.sin(alpha)])
    n = np.array([-np.sin(alpha), 0.0, np.cos(alpha)])
    return t1, n * np.sign(n[2]) if n[2] != 0 else n


@pytest.mark.parametrize("alpha", [0.3, 1.0, 2.2])
def test_equilibrium_eq_2_1(alpha):
    law = WedgeAsperity(alpha, 0.4)
    t1, n = _plane(alpha)
    F = np.array([0.7, -0.2, -1.3])  # load (Tx, Ty, -Q)
    expected = (F @ t1, F[1], -(F @ n))  # in-plane components and compressive normal force
    np.testing.assert_allclose(law.plane_forces(F[:2], 1.3), expected, rtol=1e-14)
    if alpha < np.pi / 2:  # (2.1) verbatim
        np.testing.assert_allclose(expected[::2], (0.7 * np.cos(alpha) - 1.3 * np.sin(alpha),
                                                   0.7 * np.sin(alpha) + 1.3 * np.cos(alpha)), rtol=1e-14)


def test_limit_condition_eq_2_2():
    T1 = Tx * sp.cos(al) - Q * sp.sin(al)
    N = Tx * sp.sin(al) + Q * sp.cos(al)
    f22 = (Tx**2 * (sp.cos(al) ** 2 - mu_s**2 * sp.sin(al) ** 2) - Tx * Q * sp.sin(2 * al) * (1 + mu_s**2)
           + Ty**2 + Q**2 * (sp.sin(al) ** 2 - mu_s**2 * sp.cos(al) ** 2))
    assert sp.simplify(sp.expand(T1**2 + Ty**2 - mu_s**2 * N**2 - f22)) == 0
    law = WedgeAsperity(0.5, 0.6)
    rng = np.random.default_rng(1)
    T = rng.normal(size=(200, 2))
    q = rng.uniform(0.1, 2, 200)
    quad = sp.lambdify((Tx, Ty, Q), f22.subs({al: 0.5, mu_s: 0.6}))(T[:, 0], T[:, 1], q)
    physical = law.normal_force(T, q) > 0  # (2.2) holds on the nappe N > 0
    np.testing.assert_array_equal(np.sign(law.limit(T, q))[physical], np.sign(quad)[physical])
    assert np.all(law.limit(T, q)[~physical] > 0)
    # points of the limit curve satisfy (2.2)
    P = law.limit_curve(1.0)
    np.testing.assert_allclose(sp.lambdify((Tx, Ty, Q), f22.subs({al: 0.5, mu_s: 0.6}))(P[:, 0], P[:, 1], 1.0),
                               0.0, atol=1e-12)


@pytest.mark.parametrize("alpha,mu,shape", [(np.pi / 6, 0.5, "ellipse"),
                                            (np.pi / 2 - np.arctan(0.5), 0.5, "parabola"),
                                            (np.pi / 3, 1.0, "hyperbola"),
                                            (5 * np.pi / 6, 2.0, "hyperbola"),
                                            (5 * np.pi / 6, 1.0, "ellipse")])
def test_conic_classification_after_eq_2_2(alpha, mu, shape):
    law = WedgeAsperity(alpha, mu)
    assert law.conic() == shape
    # independent: discriminant of the quadratic form of (2.2) in (Tx, Ty)
    a = np.cos(alpha) ** 2 - mu**2 * np.sin(alpha) ** 2
    assert {"ellipse": a > 1e-12, "parabola": abs(a) <= 1e-12, "hyperbola": a < -1e-12}[shape]


def test_slip_eq_2_3_and_ratio_eq_2_4():
    alpha, mu = 0.4, 0.5
    law = WedgeAsperity(alpha, mu)
    T = law.limit_point(1.1, 1.0)
    t1, t2, _ = law.plane_forces(T, 1.0)
    V = law.slip_direction(T, 1.0)
    # (2.3): in-plane velocity along the in-plane force; lift to 3-D along t1 and y
    v_plane = np.array([t1, t2]) / np.hypot(t1, t2)
    t1_vec, _ = _plane(alpha)
    np.testing.assert_allclose(V, v_plane[0] * t1_vec + v_plane[1] * np.array([0, 1, 0]), rtol=1e-14)
    assert V[0] / V[1] == pytest.approx((T[0] * np.cos(alpha) - np.sin(alpha)) * np.cos(alpha) / T[1], rel=1e-13)


def test_associated_ratio_eq_2_5():
    alpha, mu = 0.4, 0.5
    law = WedgeAsperity(alpha, mu)
    f22 = (Tx**2 * (sp.cos(al) ** 2 - mu_s**2 * sp.sin(al) ** 2) - Tx * Q * sp.sin(2 * al) * (1 + mu_s**2)
           + Ty**2 + Q**2 * (sp.sin(al) ** 2 - mu_s**2 * sp.cos(al) ** 2))
    ratio = sp.diff(f22, Tx) / sp.diff(f22, Ty)
    T = law.limit_point(1.1, 1.0)
    val = float(ratio.subs({Tx: T[0], Ty: T[1], Q: 1.0, al: alpha, mu_s: mu}))
    paper = (T[0] * (np.cos(alpha) ** 2 - mu**2 * np.sin(alpha) ** 2)
             - np.sin(alpha) * np.cos(alpha) * (1 + mu**2)) / T[1]
    assert val == pytest.approx(paper, rel=1e-13)
    n = compare_rules(law, T, 1.0).associated
    assert n[0] / n[1] == pytest.approx(paper, rel=1e-13)
    # and it differs from the actual ratio (2.4)
    assert compare_rules(law, T, 1.0).tangential_angle > 0.05


def test_potential_eq_2_6_and_rule_eq_2_7():
    alpha = 0.4
    g = sp.sqrt((Tx * sp.cos(al) - Q * sp.sin(al)) ** 2 + Ty**2)
    point = {Tx: 0.9, Ty: 0.3, Q: 1.2, al: alpha}
    grad = np.array([float(sp.diff(g, s).subs(point)) for s in (Tx, Ty, Q)])
    V = np.array([grad[0], grad[1], -grad[2]])  # (2.7): Vz = -lambda dg/dQ
    law = WedgeAsperity(alpha, 0.5)
    np.testing.assert_allclose(law.slip_direction([0.9, 0.3], 1.2), V / np.linalg.norm(V), rtol=1e-14)
    assert float(law.potential([0.9, 0.3], 1.2)) == pytest.approx(float(g.subs(point)), rel=1e-14)
    # the potential at fixed Q is an ellipse centred at Q tan(alpha) with semi-axes C/cos, C
    C = float(g.subs(point))
    centre = law.centre(1.2)
    assert centre[0] == pytest.approx(1.2 * np.tan(alpha))
    assert float(law.potential(centre + [C / np.cos(alpha), 0.0], 1.2)) == pytest.approx(C)
    assert float(law.potential(centre + [0.0, C], 1.2)) == pytest.approx(C)


def test_dilatancy_angle_eq_2_8():
    alpha, mu = 0.4, 0.5
    law = WedgeAsperity(alpha, mu)
    T = np.array([[0.9, 0.3], [1.0, -0.1], [0.2, 0.05]])
    t1 = T[:, 0] * np.cos(alpha) - np.sin(alpha)
    expected = np.arcsin(t1 * np.sin(alpha) / np.hypot(t1, T[:, 1]))
    np.testing.assert_allclose(law.dilatancy_angle(T, 1.0), expected, rtol=1e-14)


def test_wedge_pushing_along_x_gives_tan_alpha_plus_rho():
    """Classical result: up-slope Tx = Q tan(alpha + rho), down-slope Q tan(alpha - rho)."""
    alpha, mu = 0.4, 0.5
    rho = np.arctan(mu)
    law = WedgeAsperity(alpha, mu)
    np.testing.assert_allclose(law.force_for_slip([[1.0, 0.0], [-1.0, 0.0]], 1.0)[:, 0],
                               [np.tan(alpha + rho), np.tan(alpha - rho)], rtol=1e-14)


def test_wedge_associated_local_rule_is_globally_associated():
    law = WedgeAsperity(0.4, 0.5, local="associated")
    T = law.limit_point(np.linspace(0, 6, 7), 1.0)
    cmp = compare_rules(law, T, np.ones(7))
    assert np.max(cmp.angle) < 1e-12
    # the separation: velocity = e1 t1 + e2 y + mu n (unit-normalized)
    v = law.slip_direction(T, np.ones(7))
    t1, t2, _ = np.moveaxis(law.plane_forces(T, 1.0), -1, 0)
    e = np.stack((t1, t2)) / np.hypot(t1, t2)
    tv, n = _plane(0.4)
    expected = e[0][:, None] * tv + e[1][:, None] * [0, 1, 0] + 0.5 * n
    np.testing.assert_allclose(v, expected / np.linalg.norm(expected, axis=-1, keepdims=True), rtol=1e-13)


def test_wedge_locks_beyond_hyperbola_asymptotes():
    law = WedgeAsperity(np.pi / 3, 1.0)  # alpha + rho > pi/2
    mu_theta = law.friction_coefficient(np.array([0.0, np.pi]))
    assert np.isinf(mu_theta[0]) and np.isfinite(mu_theta[1])
    with pytest.raises(ValueError, match="locks"):
        law.force_for_slip([1.0, 0.0], 1.0)


def test_user_law_reproduces_coulomb_to_round_off():
    from frictionrules import N, T1, T2
    norm = sp.sqrt(T1**2 + T2**2)
    for dilatant, user in ((False, UserLaw(norm - 0.3 * N, potential=norm)), (True, UserLaw(norm - 0.3 * N))):
        law = Coulomb(0.3, dilatant)
        rng = np.random.default_rng(2)
        T = rng.normal(size=(20, 2))
        N_ = rng.uniform(0.5, 2.0, 20)
        for name in ("limit", "potential", "limit_gradient", "potential_gradient", "slip_direction"):
            np.testing.assert_allclose(getattr(user, name)(T, N_), getattr(law, name)(T, N_), rtol=1e-14,
                                       atol=1e-15, err_msg=name)
        V = rng.normal(size=(4, 2))
        np.testing.assert_allclose(user.force_for_slip(V, N_[:4]), law.force_for_slip(V, N_[:4]), rtol=1e-12,
                                   atol=1e-14)
        np.testing.assert_allclose(user.dissipation(V, N_[:4]), law.dissipation(V, N_[:4]), rtol=1e-12, atol=1e-14)
        assert user.associated is law.associated
        assert user.tangentially_associated
