"""The law protocol with state: internal variables, capabilities, parameters, user laws with
named parameters, the cone capability, and the defects it removed."""

import numpy as np
import pytest
import sympy
from hypothesis import given, settings
from hypothesis import strategies as st

from frictionrules import (Cone, ContactModel, ContactState, Coulomb, EllipsoidCap, EllipticOrthotropic,
                           FacetSet, FrictionContactProblem, FrictionRulesError, Huber,
                           LawState, SlipHardening, TransformedCoulomb, UserLaw, WedgeAsperity, solve)

NORM = "sqrt(T1**2 + T2**2)"


# ---- a state variable a law does not use does not change its result -------------------------
@pytest.mark.parametrize("law", [Coulomb(0.4), Coulomb(0.4, dilatant=True), Huber(0.4, 0.6, 0.3)])
@pytest.mark.parametrize("compiled", [True, False])
def test_unused_kappa_does_not_change_the_update(law, compiled):
    """The example of the defect: Coulomb(0.4), kn = 100, kt = 80, a contact open by a gap
    closed by the increment; κ = 0, 1, 100 must give the same update (plastic,
    T = (0.002735, 0.002663) for Coulomb)."""
    m = ContactModel(law, kn=100.0, kt=80.0)
    inc = [9.670875075074053e-05, 9.41523674949819e-05, -5.312483418616695e-4]
    results = [m.update(ContactState([0.0, 0.0, 4.3581763709382823e-4], [0.0, 0.0, 0.0], kappa, 0.5),
                        inc, compiled=compiled) for kappa in (0.0, 1.0, 100.0)]
    for r in results[1:]:
        np.testing.assert_array_equal(r.force, results[0].force)
        assert r.status == results[0].status
        assert r.state.kappa - r.state.kappa.round(0) == pytest.approx(results[0].state.kappa)
    if law == Coulomb(0.4):
        assert results[0].status == 1
        np.testing.assert_allclose(results[0].force[:2], [0.002735, 0.002663], atol=5e-7)


# ---- capabilities are checked where a law enters ---------------------------------------------
def test_contact_model_refuses_a_law_without_symbolic_form():
    facets = FacetSet([[-0.5, 0.0, 0.866], [0.5, 0.0, 0.866]], 0.3)
    with pytest.raises(FrictionRulesError, match="lacks the capability 'symbolic'"):
        ContactModel(facets, 100.0, 100.0)


def test_problem_takes_a_conical_law_without_cone_on_the_law_path():
    """Huber's rule (1.16) has no capability 'cone' (its potential is not associated in the
    sliding plane) but f and g are cones in (T, N): the many-contact problem takes it on the
    law path; a law whose limit condition is not a cone is refused naming that property."""
    assert FrictionContactProblem(np.eye(3), np.zeros(3), [Huber(0.3, 0.5)]).path == "law"
    with pytest.raises(FrictionRulesError, match="not a cone in \\(T, N\\)"):
        FrictionContactProblem(np.eye(3), np.zeros(3), [UserLaw("T1**2 + T2**2 - N**2")])


def test_declared_capabilities_of_the_built_in_laws():
    assert Coulomb(0.3).capabilities == {"symbolic", "cone", "closed_form_return"}
    assert EllipticOrthotropic(0.3, 0.5).capabilities == {"symbolic", "cone"}
    assert Huber(0.3, 0.5).capabilities == {"symbolic"}
    assert TransformedCoulomb(0.3, 0.5).capabilities == {"symbolic"}
    assert WedgeAsperity(0.3, 0.5).capabilities == {"symbolic"}
    assert EllipsoidCap(0.6).capabilities == {"symbolic"}
    assert SlipHardening(0.2, 0.1).apply(Coulomb(0.3)).capabilities == {"symbolic", "cone"}
    assert "symbolic" not in FacetSet([[0.0, 0.0, 1.0]], 0.3).capabilities


# ---- internal variables -------------------------------------------------------------------
def test_law_state_record():
    q = EllipsoidCap(0.6).initial_state((2, 3), beta=0.3)
    assert isinstance(q, LawState) and q.names == ("kappa", "beta") and q.shape == (2, 3)
    np.testing.assert_array_equal(q.beta, 0.3)
    with pytest.raises(AttributeError):
        q.gamma
    with pytest.raises(FrictionRulesError, match="beta"):
        EllipsoidCap(0.6).initial_state(beta=1.5)
    with pytest.raises(FrictionRulesError, match="internal variables"):
        Coulomb(0.3).initial_state(kappa=1.0)
    assert Coulomb(0.3).initial_state(4).values.shape == (4, 0)


def test_cap_state_argument_forms_agree():
    cap = EllipsoidCap(0.6)
    T, N = np.array([0.3, 0.2]), 0.7
    q = LawState(("kappa", "beta"), np.array([0.02, 0.45]))
    assert cap.limit(T, N, q) == cap.limit(T, N, 0.02, 0.45) == cap.limit(T, N, [0.02, 0.45])
    np.testing.assert_array_equal(cap.limit_gradient(T, N, q), cap.limit_gradient(T, N, 0.02, 0.45))


def test_state_rates_of_the_cap_eq_4_5():
    """(4.5): κ̇/λ̇ = |∂g/∂T| = 2|T|/m², β̇/λ̇ = B(β) ∂g/∂N = b β(1-β) 2ω(N - A)."""
    cap = EllipsoidCap(0.6, normal_ratio=0.5)
    T, N, kappa, beta = np.array([0.3, 0.2]), 0.7, 0.02, 0.45
    A = float(cap.A(kappa, beta))
    h = cap.state_rates(T, N, [kappa, beta])
    assert h[0] == pytest.approx(2 * np.hypot(*T) / 0.36, rel=1e-12)
    assert h[1] == pytest.approx(cap.B.b * beta * (1 - beta) * 2 * 0.5 * (N - A), rel=1e-12)


@settings(max_examples=30, deadline=None)
@given(st.floats(0.05, 1.0), st.floats(-0.5, 2.0), st.floats(0.001, 0.5), st.floats(0.0, 2.0),
       st.floats(-np.pi, np.pi), st.floats(0.1, 3.0))
def test_hardened_law_closed_forms_match_its_symbolic_form(mu, h, kh, kappa, angle, N):
    law = SlipHardening(h, kh).apply(Huber(mu, 1.5 * mu, 0.2))
    T = np.array([np.cos(angle), np.sin(angle)]) * 1.1 * mu * N
    q = law.initial_state(kappa=kappa)
    loc = law.local_derivatives(T, N, q)
    assert float(law.limit(T, N, q)) == pytest.approx(float(loc.f), rel=1e-10, abs=1e-12)
    np.testing.assert_allclose(law.limit_gradient(T, N, q), loc.df, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(law.potential_gradient(T, N, q), loc.dg, rtol=1e-9, atol=1e-12)
    # (4.5) κ̇ = |ġ_T| λ̇ and (4.7) H = -f_κ h
    assert loc.h[0] == pytest.approx(np.hypot(*loc.dg[:2]), rel=1e-12)
    s1 = float(SlipHardening(h, kh).scale_derivative(kappa))
    assert float(law.hardening_modulus(T, N, q)) == pytest.approx(
        -(law.law.limit_gradient(T, float(SlipHardening(h, kh).scale(kappa)) * N)[2] * N * s1) * loc.h[0],
        rel=1e-9, abs=1e-12)


def test_hardened_cone_at_each_contact_state():
    law = SlipHardening(0.5, 0.1).apply(Coulomb(0.4))
    kappa = np.array([0.0, 10.0])
    p = FrictionContactProblem(np.eye(6), np.array([-1.0, 2.0, 0.0, -1.0, 2.0, 0.0]), law,
                               state=law.initial_state(2, kappa=kappa))
    np.testing.assert_allclose(p.mu_bar, [0.4, 0.4 * 1.5], rtol=1e-12)
    s = solve(p, tol=1e-12)
    np.testing.assert_allclose(-s.r[[1, 4]], [0.4, 0.6], rtol=1e-9)


# ---- user laws with named parameters ---------------------------------------------------------
def test_user_law_parameters_are_symbols_equality_hash_replace():
    a = UserLaw(f"{NORM} - mu*N", potential=NORM, params={"mu": 0.3})
    b = UserLaw(f"{NORM} - mu*N", potential=NORM, params={"mu": 0.3})
    assert a == b and hash(a) == hash(b) and a != a.replace(mu=0.4)
    assert a.parameters == {"mu": 0.3} and a.replace(mu=0.4).parameters == {"mu": 0.4}
    form = a.symbolic_form()
    assert [str(p) for p in form.params] == ["mu"] and form.values == (0.3,)
    assert form.structure == a.replace(mu=0.4).symbolic_form().structure
    with pytest.raises(FrictionRulesError, match="parameters"):
        a.replace(nu=1.0)


def test_user_law_from_sympy_symbols_matched_by_name():
    from frictionrules import N, T1, T2
    mu = sympy.Symbol("mu")
    law = UserLaw(sympy.sqrt(T1**2 + T2**2) - mu * N, params={"mu": 0.25})
    assert float(law.limit([0.25, 0.0], 1.0)) == 0.0


def test_user_law_mapping_round_trip():
    table = {"limit": f"{NORM} - mu*N", "potential": f"{NORM} - psi*N", "params": {"mu": 0.5, "psi": 0.1},
             "state": {"kappa": 0.0}, "rates": {"kappa": "slip"}}
    law = UserLaw.from_mapping(table)
    again = UserLaw.from_mapping(law.to_mapping())
    assert again == law
    with pytest.raises(FrictionRulesError, match="unknown keys"):
        UserLaw.from_mapping({**table, "extra": 1})
    with pytest.raises(FrictionRulesError, match="limit"):
        UserLaw.from_mapping({"potential": NORM})
    with pytest.raises(FrictionRulesError, match="one rate per internal variable"):
        UserLaw(f"{NORM} - mu*N", params={"mu": 0.5}, state={"kappa": 0.0})


def test_user_law_with_slip_hardening_written_out_matches_hardened_law():
    user = UserLaw(f"{NORM} - mu*(1 + h*(1 - exp(-kappa/kh)))*N", potential=NORM,
                   params={"mu": 0.4, "h": 0.5, "kh": 0.05}, state={"kappa": 0.0}, rates={"kappa": "slip"})
    ref = SlipHardening(0.5, 0.05).apply(Coulomb(0.4))
    mu_, mr = ContactModel(user, 100.0, 80.0), ContactModel(ref, 100.0, 80.0)
    su, sr = mu_.initial_state(), mr.initial_state()
    for du in ([0.0, 0.0, -0.01], [0.01, 0.002, 0.0], [0.005, -0.01, 0.001], [0.02, 0.0, 0.0]):
        ru, rr = mu_.update(su, du), mr.update(sr, du)
        np.testing.assert_allclose(ru.force, rr.force, rtol=1e-10, atol=1e-14)
        np.testing.assert_allclose(ru.state.kappa, rr.state.kappa, rtol=1e-10, atol=1e-14)
        su, sr = ru.state, rr.state


@pytest.mark.parametrize("limit, potential, cone", [
    (f"{NORM} - 0.4*N", None, Cone(0.4, 0.4, 0.0, 1.0)),
    (f"{NORM} - 0.4*N", NORM, Cone(0.4, 0.4, 0.0, 0.0)),
    (f"{NORM} - 0.4*N", f"{NORM} - 0.1*N", Cone(0.4, 0.4, 0.0, 0.25)),
    ("sqrt((T1/0.6)**2 + (T2/0.3)**2) - N", "sqrt((T1/0.6)**2 + (T2/0.3)**2)", Cone(0.6, 0.3, 0.0, 0.0)),
])
def test_user_law_cone_from_its_symbolic_form(limit, potential, cone):
    c = UserLaw(limit, potential).cone()
    assert c.mu_x == pytest.approx(cone.mu_x) and c.mu_y == pytest.approx(cone.mu_y)
    assert c.dilatancy == pytest.approx(cone.dilatancy, abs=1e-15)


def test_user_law_rotated_ellipse_is_the_elliptic_cone():
    ref = EllipticOrthotropic(0.6, 0.3, 0.4)
    user = UserLaw(str(ref.symbolic()[0]), str(ref.symbolic()[1]))
    c = user.cone()
    assert (c.mu_x, c.mu_y, c.angle) == pytest.approx((0.6, 0.3, 0.4), rel=1e-9)
    T, N = np.array([0.2, -0.1]), 1.0
    np.testing.assert_allclose(user.slip_direction(T, N), ref.slip_direction(T, N), rtol=1e-12)


def test_user_law_not_a_cone():
    for law in (UserLaw("T1**2 + T2**2 - N"), UserLaw(f"{NORM} - 0.3*N", "T1**2 + T2**2"),
                UserLaw(f"{NORM} - mu*(1 + kappa)*N", params={"mu": 0.3}, state={"kappa": 0.0},
                        rates={"kappa": "slip"})):
        assert "cone" not in law.capabilities


# ---- inverse relations: locked directions are flagged ---------------------------------------
def test_inverse_relation_flags_locked_directions():
    wedge = WedgeAsperity(np.deg2rad(60), 1.0)
    inv = wedge.inverse_relation(np.array([0.0, np.pi]))
    assert inv.locked.tolist() == [True, False]
    assert np.all(np.isinf(inv.force[0])) and np.all(np.isfinite(inv.force[1]))
    assert np.isinf(wedge.friction_coefficient(0.0))
    with pytest.raises(FrictionRulesError, match="locks"):
        wedge.force_for_slip([1.0, 0.0], 1.0)
