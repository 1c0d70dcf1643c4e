"""SymPy derivations of the §3 rate relations (3.6)–(3.13), checked against the paper and the code."""

import numpy as np
import pytest
import sympy as sp
from hypothesis import given, settings
from hypothesis import strategies as st

from frictionrules import WedgeAsperity
from frictionrules.configuration import CylinderOnLayer, SphereOnLayer
from frictionrules.configuration._symbolic import contact_functions, expressions
from frictionrules.configuration.path import _kinematics, hardening_modulus, inverse_force
from frictionrules.laws.base import rotate

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


def test_code_kinematics_match_the_derivation():
    d, a, p = 1.3, 0.4, 0.7
    V = np.array([0.3, -0.8])
    da, dp = _kinematics(a, p, V, d, cylindrical=False)
    h = 1e-6
    u = lambda a, p: -d * np.sin(a) * np.array([np.cos(p), np.sin(p)])  # noqa: E731
    assert np.allclose((u(a + h * da, p + h * dp) - u(a, p)) / h, V, atol=1e-5)


@settings(max_examples=50, deadline=None)
@given(a=st.floats(0.05, 1.0), p=st.floats(-3.0, 3.0), th=st.floats(-3.0, 3.0),
       m=st.floats(0.05, 0.5))
def test_softening_modulus_eq_3_13_rederived(a, p, th, m):
    """On the limit curve h = -(f_a a_lam + f_psi psi_lam) = -(1 + mu^2) N / d for a sphere:
    lambda_dot = -d f_T_dot / ((1 + mu^2) N), the corrected (3.13); always softening."""
    model = SphereOnLayer(1.7, m, Q=2.0)
    T = inverse_force(a, p, np.array([np.cos(th), np.sin(th)]), m, 2.0)
    F = contact_functions()(T[0], T[1], a, p, 2.0, m)
    assert abs(F["f"]) < 1e-10
    h = hardening_modulus(F, a, p, model)
    assert h == pytest.approx(-(1 + m**2) * F["N"] / 1.7, rel=1e-9)


@settings(max_examples=50, deadline=None)
@given(a=st.floats(0.05, 1.0), th=st.floats(-3.0, 3.0), m=st.floats(0.05, 0.5))
def test_cylinder_modulus_matches_eq_3_7(a, th, m):
    """Cylinder: lambda_dot = R cos(a) f_T_dot/(f_a g_Tx) (3.7), i.e. h = f_a g_Tx/(R cos a)."""
    model = CylinderOnLayer(1.7, m, Q=2.0)
    T = inverse_force(a, 0.0, np.array([np.cos(th), np.sin(th)]), m, 2.0)
    F = contact_functions()(T[0], T[1], a, 0.0, 2.0, m)
    h = hardening_modulus(F, a, 0.0, model)
    assert h == pytest.approx(F["f_alpha"] * F["g_Tx"] / (1.7 * np.cos(a)), rel=1e-9, abs=1e-12)
    assert h <= 1e-12


@settings(max_examples=50, deadline=None)
@given(a=st.floats(0.05, 1.5), p=st.floats(-3.0, 3.0), tx=st.floats(-3, 3), ty=st.floats(-3, 3),
       m=st.floats(0.0, 1.0))
def test_contact_functions_are_the_core_wedge_in_the_rotated_frame_eq_3_11(a, p, tx, ty, m):
    """f, g and the slip direction are WedgeAsperity(alpha, mu) applied to rotate(T, -psi)."""
    law = WedgeAsperity(a, m)
    F = contact_functions()(tx, ty, a, p, 1.5, m)
    Tp = rotate(np.array([tx, ty]), -p)
    assert F["f"] == pytest.approx(law.limit(Tp, 1.5), abs=1e-10)
    assert F["g_Q"] == pytest.approx(law.potential_gradient(Tp, 1.5)[2], abs=1e-10)
    gT = rotate(law.potential_gradient(Tp, 1.5)[:2], p)
    assert np.allclose([F["g_Tx"], F["g_Ty"]], gT, atol=1e-10)


def test_inverse_force_is_the_core_force_for_slip():
    law = WedgeAsperity(0.5, 0.3)
    for th in np.linspace(-3, 3, 13):
        v = np.array([np.cos(th), np.sin(th)])
        ours = inverse_force(0.5, 0.9, v, 0.3, 1.0)
        core = rotate(law.force_for_slip(rotate(v, -0.9), 1.0), 0.9)
        assert np.allclose(ours, core, atol=1e-9)


def test_symbolic_derivatives_against_finite_differences():
    F = contact_functions()
    x = np.array([0.7, -0.2, 0.5, 0.3])
    base = F(*x, 1.0, 0.4)
    h = 1e-6
    for k, name in enumerate(("f_Tx", "f_Ty", "f_alpha", "f_psi")):
        xp, xm = x.copy(), x.copy()
        xp[k] += h
        xm[k] -= h
        fd = (F(*xp, 1.0, 0.4)["f"] - F(*xm, 1.0, 0.4)["f"]) / (2 * h)
        assert base[name] == pytest.approx(fd, abs=1e-7)


def test_expressions_reduce_to_eq_2_2_at_psi_zero():
    (tx, ty, a, p, q, m), f, g, n = expressions()
    quad = (tx**2 * (sp.cos(a)**2 - m**2 * sp.sin(a)**2) - tx * q * sp.sin(2 * a) * (1 + m**2)
            + ty**2 + q**2 * (sp.sin(a)**2 - m**2 * sp.cos(a)**2))
    # (g - mu N)(g + mu N) = g^2 - mu^2 N^2 is the quadric (2.2)
    assert sp.simplify(sp.expand_trig((g**2 - m**2 * n**2).subs(p, 0) - quad)) == 0
