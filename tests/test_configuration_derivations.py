"""SymPy derivations of the §3 rate relations (3.6)–(3.13), checked against the paper and the code.

The code composes the local law's derivatives (from its symbolic form) with the derivatives of
the contact's frame; the tests here derive the wedge of §2 in the rotated frame (3.11)
independently and compare."""

import numpy as np
import pytest
import sympy as sp
from hypothesis import example, given, settings
from hypothesis import strategies as st

from frictionrules import Coulomb, EllipticOrthotropic, GrainContact, UserLaw, WedgeAsperity
from frictionrules.configuration._contact import contact_terms, slide
from frictionrules.configuration._frame import angle_rates, frames, offset_of_angles
from frictionrules._rotation import rotate

t = sp.symbols("t", real=True)
R, Q, mu, c = sp.symbols("R Q mu c", positive=True)
Tx, Ty = sp.symbols("T_x T_y", real=True)


def test_cylinder_kinematics_eq_3_6_R_is_the_diameter():
    """Centre on the circle of radius r1 + r2 = d about the layer axis: u = c - d sin(alpha),
    z = d cos(alpha); so alpha_dot = -V_x/(d cos alpha) (3.6) with R = d, and V_z = V_x tan(alpha)."""
    d = sp.symbols("d", positive=True)
    al = sp.Function("alpha")(t)
    radius = d / 2 + d / 2                      # two cylinders of diameter d touching
    ux, uz = c - radius * sp.sin(al), radius * sp.cos(al)
    Vx, Vz = sp.diff(ux, t), sp.diff(uz, t)
    adot = sp.diff(al, t)
    assert sp.simplify(adot - (-Vx / (d * sp.cos(al)))) == 0
    assert sp.simplify(Vz - Vx * sp.tan(al)) == 0


def test_consistency_eq_3_7_and_3_9():
    """(3.5) with psi_dot = 0 and (3.6): lambda_dot = R cos(a) f_T_dot / (f_a g_Tx) (3.7) and
    alpha_dot = -f_T_dot / f_a (3.9)."""
    fa, gx, fT, lam, a = sp.symbols("f_alpha g_Tx fdot_T lambda_dot alpha")
    adot = -lam * gx / (R * sp.cos(a))          # (3.6) with V_x = lambda_dot g_Tx (3.3)
    sol = sp.solve(sp.Eq(fT + fa * adot, 0), lam)[0]
    assert sp.simplify(sol - R * sp.cos(a) * fT / (fa * gx)) == 0
    assert sp.simplify(adot.subs(lam, sol) + fT / fa) == 0


def test_explicit_alpha_rate_eq_3_10():
    """(3.9) with the quadratic limit condition (2.2) gives exactly (3.10)."""
    a = sp.symbols("alpha", real=True)
    dTx, dTy = sp.symbols("Tdot_x Tdot_y")
    f = (Tx**2 * (sp.cos(a)**2 - mu**2 * sp.sin(a)**2) - Tx * Q * sp.sin(2 * a) * (1 + mu**2)
         + Ty**2 + Q**2 * (sp.sin(a)**2 - mu**2 * sp.cos(a)**2))
    ours = -(sp.diff(f, Tx) * dTx + sp.diff(f, Ty) * dTy) / sp.diff(f, a)
    paper = -(((2 * Tx * (sp.cos(a)**2 - mu**2 * sp.sin(a)**2) - Q * sp.sin(2 * a) * (1 + mu**2)) * dTx
               + 2 * Ty * dTy)
              / ((1 + mu**2) * (sp.sin(2 * a) * (Q**2 - Tx**2) - 2 * Tx * Q * sp.cos(2 * a))))
    assert sp.simplify(sp.expand_trig(ours - paper)) == 0


def test_sphere_kinematics_eq_3_12_rederived():
    """u = c - d sin(alpha) e_psi: alpha_dot = -V.e_psi/(d cos a), psi_dot = -V.e_perp/(d sin a).

    The paper's (3.12) puts R cos(alpha) under psi_dot as well; the horizontal radius of the
    circle of latitude is d sin(alpha), so psi_dot differs (erratum)."""
    d = sp.symbols("d", positive=True)
    al, ps = sp.Function("alpha")(t), sp.Function("psi")(t)
    u = sp.Matrix([-d * sp.sin(al) * sp.cos(ps), -d * sp.sin(al) * sp.sin(ps)])
    V = sp.diff(u, t)
    e = sp.Matrix([sp.cos(ps), sp.sin(ps)])
    ep = sp.Matrix([-sp.sin(ps), sp.cos(ps)])
    assert sp.simplify(sp.diff(al, t) + V.dot(e) / (d * sp.cos(al))) == 0
    assert sp.simplify(sp.diff(ps, t) + V.dot(ep) / (d * sp.sin(al))) == 0
    # the paper's form |V'| cos(psi + delta)/(R cos a) cannot hold for every motion: at a pure
    # azimuthal motion (alpha_dot = 0) |V'| = d sin(a) |psi_dot|, not d cos(a) |psi_dot|
    v2 = V.dot(V).subs(sp.diff(al, t), 0).subs(sp.diff(ps, t), 1)
    assert sp.simplify(v2 - (d * sp.sin(al))**2) == 0


def wedge_in_rotated_frame():
    """The §2 wedge (2.1), (2.2), (2.6) in the frame rotated by psi ((3.11), counter-clockwise),
    with a signed alpha: ``(symbols, f, g, N)``, an independent derivation."""
    Tx_, Ty_, a, p = sp.symbols("T_x T_y alpha psi", real=True)
    Q_, m = sp.symbols("Q mu", positive=True)
    tpx = Tx_ * sp.cos(p) + Ty_ * sp.sin(p)
    tpy = -Tx_ * sp.sin(p) + Ty_ * sp.cos(p)
    t1 = tpx * sp.cos(a) - Q_ * sp.sin(a)
    n = tpx * sp.sin(a) + Q_ * sp.cos(a)
    g = sp.sqrt(t1**2 + tpy**2)
    return (Tx_, Ty_, a, p, Q_, m), g - m * n, g, n


def terms(law, a, p, T, Q, d, cylindrical=False):
    fr = frames(offset_of_angles(a, p, d), d, rates=True)
    return contact_terms(law, fr.axes, fr.rates, T, Q, cylindrical)


def on_limit(law, a, p, th, Q, d=1.0):
    """The force on the limit curve of the contact (alpha, psi) sliding along th."""
    fr = frames(offset_of_angles(a, p, d), d)
    return slide(law, fr.axes, np.array([np.cos(th), np.sin(th)]), Q).force


def test_code_kinematics_match_the_derivation():
    """(3.12) re-derived: the angle rates move the centre with the given horizontal velocity."""
    d, a, p = 1.3, 0.4, 0.7
    V = np.array([0.3, -0.8])
    da, dp = angle_rates(a, p, d, V, cylindrical=False)
    h = 1e-6
    u = lambda a, p: -d * np.sin(a) * np.array([np.cos(p), np.sin(p)])  # noqa: E731
    assert np.allclose((u(a + h * da, p + h * dp) - u(a, p)) / h, V, atol=1e-5)
    assert angle_rates(a, 0.0, d, V, cylindrical=True)[0] == pytest.approx(-V[0] / (d * np.cos(a)))


@settings(max_examples=40, deadline=None)
@given(a=st.floats(0.05, 1.0), p=st.floats(-3.0, 3.0), th=st.floats(-3.0, 3.0),
       m=st.floats(0.05, 0.5))
def test_softening_modulus_eq_3_13_rederived(a, p, th, m):
    """On the limit curve h = -(f_a a_lam + f_psi psi_lam) = -(1 + mu^2) N / d for a sphere:
    lambda_dot = -d f_T_dot / ((1 + mu^2) N), the corrected (3.13); always softening."""
    law = Coulomb(m)
    T = on_limit(law, a, p, th, 2.0, 1.7)
    F = terms(law, a, p, T, 2.0, 1.7)
    assert abs(F.f) < 1e-10
    assert F.modulus == pytest.approx(-(1 + m**2) * F.N / 1.7, rel=1e-9)


@settings(max_examples=40, deadline=None)
@given(a=st.floats(0.05, 1.0), th=st.floats(-3.0, 3.0), m=st.floats(0.05, 0.5))
def test_cylinder_modulus_matches_eq_3_7(a, th, m):
    """Cylinder: lambda_dot = R cos(a) f_T_dot/(f_a g_Tx) (3.7), i.e. h = f_a g_Tx/(R cos a),
    with f_a of the wedge derived here."""
    law = Coulomb(m)
    T = on_limit(law, a, 0.0, th, 2.0, 1.7)
    F = terms(law, a, 0.0, T, 2.0, 1.7, cylindrical=True)
    (tx, ty, al, ps, q, mm), f, _, _ = wedge_in_rotated_frame()
    f_a = float(sp.diff(f, al).subs({tx: T[0], ty: T[1], al: a, ps: 0, q: 2.0, mm: m}))
    assert F.modulus == pytest.approx(f_a * F.g_T[0] / (1.7 * np.cos(a)), rel=1e-9, abs=1e-12)
    assert F.modulus <= 1e-12


@settings(max_examples=30, deadline=None)
@given(a=st.floats(-1.2, 1.2), p=st.floats(-3.0, 3.0), tx=st.floats(-3, 3), ty=st.floats(-3, 3),
       m=st.floats(0.0, 1.0))
@example(a=1e-10, p=0.0, tx=0.0, ty=0.0, m=0.0)
@example(a=-1e-17, p=0.0, tx=0.0, ty=0.0, m=0.0)
def test_contact_is_the_core_wedge_in_the_rotated_frame_eq_3_11(a, p, tx, ty, m):
    """f, g and the slip direction of Coulomb in the contact's frame are WedgeAsperity(alpha,
    mu) applied to rotate(T, -psi) (``pi + alpha`` for a signed alpha < 0)."""
    # the top (alpha = 0, or pi + alpha rounding to pi): the wedge degenerates to Coulomb;
    # any other alpha, however small, is a wedge (at alpha = 1e-10 its limit differs from
    # Coulomb's by about N alpha = 1.5e-10)
    level = a == 0.0 or (a < 0.0 and np.pi + a >= np.pi)
    law = Coulomb(m) if level else WedgeAsperity(a if a > 0 else np.pi + a, m)
    contact = GrainContact(Coulomb(m), a, p)
    Tp = rotate(np.array([tx, ty]), -p)
    assert contact.limit([tx, ty], 1.5) == pytest.approx(law.limit(Tp, 1.5), abs=1e-10)
    if not level:
        grad = law.potential_gradient(Tp, 1.5)
        mine = contact.potential_gradient([tx, ty], 1.5)
        assert mine[2] == pytest.approx(grad[2], abs=1e-10)
        assert np.allclose(mine[:2], rotate(grad[:2], p), atol=1e-10)


def test_inverse_relation_is_the_core_force_for_slip():
    law = WedgeAsperity(0.5, 0.3)
    contact = GrainContact(Coulomb(0.3), 0.5, 0.9)
    for th in np.linspace(-3, 3, 13):
        v = np.array([np.cos(th), np.sin(th)])
        core = rotate(law.force_for_slip(rotate(v, -0.9), 1.0), 0.9)
        assert np.allclose(contact.force_for_slip(v, 1.0), core, atol=1e-12)
        assert np.allclose(on_limit(Coulomb(0.3), 0.5, 0.9, th, 1.0), core, atol=1e-12)


def test_contact_terms_against_the_wedge_derivation():
    """f_u of the code (frame derivatives x local gradient) equals f_alpha alpha_u + f_psi psi_u of
    the wedge written in the rotated frame (derived here), and g_T, g_Q its gradient (3.3)."""
    (tx, ty, al, ps, q, mm), f, g, n = wedge_in_rotated_frame()
    d, a, p, T, Q, m = 1.4, 0.5, 0.8, np.array([0.9, 0.4]), 1.3, 0.35
    F = terms(Coulomb(m), a, p, T, Q, d)
    at = {tx: T[0], ty: T[1], al: a, ps: p, q: Q, mm: m}
    grad = [float(sp.diff(f, s_).subs(at)) for s_ in (tx, ty, al, ps)]
    K = np.array([[-np.cos(p) / (d * np.cos(a)), -np.sin(p) / (d * np.cos(a))],
                  [np.sin(p) / (d * np.sin(a)), -np.cos(p) / (d * np.sin(a))]])  # d(a, psi)/du
    assert np.allclose(F.f_T, grad[:2], atol=1e-12)
    assert np.allclose(F.f_u, np.array(grad[2:]) @ K, atol=1e-12)
    assert np.allclose(F.g_T, [float(sp.diff(g, tx).subs(at)), float(sp.diff(g, ty).subs(at))])
    assert F.g_Q == pytest.approx(float(sp.diff(g, q).subs(at)))
    assert F.N == pytest.approx(float(n.subs(at)))


@pytest.mark.parametrize("law, cylindrical", [
    (Coulomb(0.4), False), (Coulomb(0.4), True), (EllipticOrthotropic(0.25, 0.45, 0.6), False),
    (UserLaw("sqrt(T1**2 + T2**2) - mu*N", "sqrt(T1**2 + T2**2)", params={"mu": 0.4}), False),
])
def test_contact_terms_against_finite_differences(law, cylindrical):
    """Every derivative the rate relations use, against central differences of f and g_T."""
    d, Q = 1.2, 1.1
    r0 = np.array([-0.45, 0.0 if cylindrical else 0.3])
    T0 = np.array([0.7, -0.2])

    def at(T, r):
        fr = frames(r, d, rates=True)
        return contact_terms(law, fr.axes, fr.rates, T, Q, cylindrical)

    base = at(T0, r0)
    h = 1e-6
    for k in range(2):
        e = np.eye(2)[k]
        fp, fm = at(T0 + h * e, r0), at(T0 - h * e, r0)
        assert base.f_T[k] == pytest.approx((fp.f - fm.f) / (2 * h), abs=1e-8)
        assert np.allclose(base.g_TT[:, k], (fp.g_T - fm.g_T) / (2 * h), atol=1e-7)
        if cylindrical and k == 1:
            assert base.f_u[1] == 0.0 and np.all(base.g_Tu[:, 1] == 0.0)
            continue
        up, um = at(T0, r0 + h * e), at(T0, r0 - h * e)
        assert base.f_u[k] == pytest.approx((up.f - um.f) / (2 * h), abs=1e-8)
        assert np.allclose(base.g_Tu[:, k], (up.g_T - um.g_T) / (2 * h), atol=1e-7)


def test_contact_limit_is_the_quadric_eq_2_2():
    """(g - mu N)(g + mu N) = g^2 - mu^2 N^2 is the quadric (2.2) at psi = 0."""
    rng = np.random.default_rng(1)
    for a in (0.3, 0.7, -0.4):
        contact = GrainContact(Coulomb(0.3), a, 0.0)
        for Tx_, Ty_ in rng.normal(size=(5, 2)):
            T1, T2, N = contact.plane_forces([Tx_, Ty_], 1.0)
            quad = (Tx_**2 * (np.cos(a)**2 - 0.09 * np.sin(a)**2) - Tx_ * np.sin(2 * a) * 1.09
                    + Ty_**2 + (np.sin(a)**2 - 0.09 * np.cos(a)**2))
            assert T1**2 + T2**2 - 0.09 * N**2 == pytest.approx(quad, abs=1e-12)
