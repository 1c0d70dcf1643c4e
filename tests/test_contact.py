"""ContactModel (§4): elastic law (4.2), sliding rule (4.3), return mapping, tangent,
separation, apex, invariants over random paths, convergence order, rate form (4.10)."""

import numpy as np
import pytest
import sympy
from hypothesis import given, settings
from hypothesis import strategies as st

from frictionrules import (ContactModel, ContactState, Coulomb, EllipsoidCap, EllipticOrthotropic,
                           FrictionRulesError, Huber, TransformedCoulomb, WedgeAsperity)
from frictionrules.contact import SlipHardening
from frictionrules.contact.state import ELASTIC, OPEN, PLASTIC

KN, KT = 100.0, 50.0

LAWS = {
    "coulomb": Coulomb(0.4),
    "coulomb_dilatant": Coulomb(0.4, dilatant=True),
    "elliptic": EllipticOrthotropic(0.3, 0.6, angle=0.4),
    "huber": Huber(0.3, 0.6, angle=-0.3),
    "transformed": TransformedCoulomb(0.3, 0.6, angle=0.2),
    "cap": EllipsoidCap(0.6),
    "cap_nonassociated": EllipsoidCap(0.6, normal_ratio=0.3),
    "wedge": WedgeAsperity(0.3, 0.5),
}


def model_for(name, hardening=None):
    return ContactModel(LAWS[name], KN, KT, hardening)


def test_elastic_law_eq_4_2_sign_convention():
    """(4.2) in our convention: closing (δn < 0) compresses, N = -kn (δn - δnᵖ) > 0."""
    m = model_for("coulomb")
    r = m.update(m.initial_state(), [0.001, -0.002, -0.01])
    assert r.status == ELASTIC
    np.testing.assert_allclose(r.force, [KT * 0.001, -KT * 0.002, KN * 0.01])
    np.testing.assert_allclose(r.tangent if r.tangent is not None else m.elastic_tangent,
                               np.diag([KT, KT, -KN]))


def test_state_is_returned_not_mutated():
    m = model_for("coulomb")
    s0 = m.initial_state((3,))
    r = m.update(s0, [0.05, 0.0, -0.01])
    assert np.all(s0.plastic == 0) and np.all(s0.displacement == 0)
    assert not r.state.plastic.flags.writeable
    with pytest.raises(ValueError):
        r.state.plastic[0, 0] = 1.0


def test_bad_input_names_argument():
    with pytest.raises(FrictionRulesError, match="kn"):
        ContactModel(Coulomb(0.3), -1.0, 1.0)
    m = model_for("coulomb")
    with pytest.raises(FrictionRulesError, match="increments"):
        m.update(m.initial_state((2,)), np.zeros((3, 2)))
    with pytest.raises(FrictionRulesError, match="beta"):
        m.initial_state(beta=1.5)
    with pytest.raises(FrictionRulesError, match="hardening"):
        ContactModel(EllipsoidCap(0.5), 1.0, 1.0, SlipHardening(0.1, 0.1))


@pytest.mark.parametrize("name", sorted(LAWS))
@pytest.mark.parametrize("compiled", [True, False])
def test_separation_keeps_history(name, compiled):
    """N <= 0: open contact, zero force; κ, β and δnᵖ kept; on closing the contact sticks."""
    m = model_for(name)
    s = m.update(m.initial_state(), [0.0, 0.0, -0.01]).state
    s = m.update(s, [0.05, 0.02, 0.0], compiled=compiled).state
    r = m.update(s, [0.3, -0.1, 0.05], tangent=True, compiled=compiled)
    assert r.status == OPEN
    np.testing.assert_array_equal(r.force, 0.0)
    np.testing.assert_array_equal(r.tangent, 0.0)
    assert r.dissipation == 0.0
    assert r.state.kappa == s.kappa and r.state.beta == s.beta
    assert r.state.plastic[2] == s.plastic[2]
    back = m.update(r.state, [0.0, 0.0, -0.05])
    assert back.status == ELASTIC
    np.testing.assert_allclose(back.force[:2], 0.0, atol=1e-12)
    np.testing.assert_allclose(back.force[2], m.force(s)[2])


@pytest.mark.parametrize("name", ["coulomb", "coulomb_dilatant", "huber", "elliptic"])
def test_cone_apex(name):
    """At the apex T = 0 the return is finite; a tiny N with a large T returns onto f = 0."""
    m = model_for(name)
    r = m.update(m.initial_state(), [0.0, 0.0, -1e-3], tangent=True)
    assert r.status == ELASTIC and np.all(np.isfinite(r.tangent))
    r = m.update(m.initial_state(), [0.5, 0.1, -1e-12], tangent=True, compiled=False)
    assert r.status == PLASTIC
    assert np.all(np.isfinite(r.force)) and np.all(np.isfinite(r.tangent))
    assert abs(m.yield_residual(r.state)) <= 1e-10


def test_cap_corner_at_origin_and_beyond_far_end():
    """The cap meets the separation plane N = 0 at the origin: a trial with tiny N and large T
    returns onto the cap with 0 <= N; a trial beyond N = 2A compacts and hardens."""
    m = model_for("cap")
    r = m.update(m.initial_state(), [0.5, 0.0, -1e-9], tangent=True)
    assert r.status == PLASTIC and r.force[2] >= 0 and np.all(np.isfinite(r.tangent))
    assert abs(m.yield_residual(r.state)) <= 1e-10
    r = m.update(m.initial_state(), [0.0, 0.0, -0.05])
    assert r.status == PLASTIC and r.state.beta > 0.5 and r.state.plastic[2] < 0
    assert abs(m.yield_residual(r.state)) <= 1e-10


def _paths(n_steps=6):
    inc = st.tuples(st.floats(-0.04, 0.04), st.floats(-0.04, 0.04), st.floats(-0.012, 0.006))
    return st.lists(inc, min_size=n_steps, max_size=n_steps)


@pytest.mark.parametrize("name", sorted(LAWS))
@settings(max_examples=15, deadline=None)
@given(path=_paths())
def test_random_paths_consistency_and_dissipation(name, path):
    """After every plastic step f <= 1e-10 (relative); the plastic work of every step >= 0."""
    m = model_for(name)
    s = m.update(m.initial_state(), [0.0, 0.0, -0.01]).state
    for du in path:
        r = m.update(s, du)
        s = r.state
        # Roundoff bound of the plastic work T·Δδᵖ - N Δδnᵖ of a step: |σ| (|Δδ| + |δᵉ|) ε.
        scale = np.linalg.norm(r.force) * (np.linalg.norm(du) + np.linalg.norm(r.state.elastic))
        assert r.dissipation >= -1e-12 * scale
        if r.status == PLASTIC:
            assert abs(m.yield_residual(s)) <= 1e-10
        else:
            assert m.yield_residual(s) <= 1e-10


@pytest.mark.parametrize("name", ["coulomb", "elliptic", "huber"])
@settings(max_examples=10, deadline=None)
@given(path=_paths(4))
def test_random_paths_with_slip_hardening(name, path):
    m = model_for(name, SlipHardening(0.5, 0.02))
    s = m.update(m.initial_state(), [0.0, 0.0, -0.01]).state
    for du in path:
        r = m.update(s, du)
        s = r.state
        scale = np.linalg.norm(r.force) * (np.linalg.norm(du) + np.linalg.norm(r.state.elastic))
        assert r.dissipation >= -1e-12 * scale
        assert m.yield_residual(s) <= 1e-10
        if r.status == PLASTIC:
            assert abs(m.yield_residual(s)) <= 1e-10


CASES = [(n, None) for n in sorted(LAWS)] + [("coulomb", SlipHardening(0.5, 0.02)),
                                              ("coulomb_dilatant", SlipHardening(-0.3, 0.02)),
                                              ("transformed", SlipHardening(0.4, 0.05))]


@pytest.mark.parametrize("name,hardening", CASES)
def test_consistent_tangent_matches_finite_differences(name, hardening):
    m = model_for(name, hardening)
    s = m.update(m.initial_state(), [0.0, 0.0, -0.01]).state
    s = m.update(s, [0.03, 0.006, -0.001]).state
    du = np.array([0.006, -0.003, 0.0005])
    r = m.update(s, du, tangent=True)
    assert r.status == PLASTIC
    h = 1e-7
    fd = np.empty((3, 3))
    for j in range(3):
        e = np.zeros(3)
        e[j] = h
        fd[:, j] = (m.update(s, du + e).force - m.update(s, du - e).force) / (2 * h)
    assert np.abs(fd - r.tangent).max() <= 1e-6 * np.abs(r.tangent).max()


@pytest.mark.parametrize("name", ["coulomb", "coulomb_dilatant", "elliptic"])
def test_compiled_kernel_matches_generic_return_mapping(name):
    m = model_for(name)
    rng = np.random.default_rng(1)
    n = 300
    s = m.initial_state((n,))
    for _ in range(3):
        du = np.column_stack((rng.normal(0, 0.02, (n, 2)), rng.normal(-0.003, 0.006, n)))
        a = m.update(s, du, tangent=True)
        b = m.update(s, du, tangent=True, compiled=False)
        np.testing.assert_array_equal(a.status, b.status)
        for x, y in [(a.force, b.force), (a.state.plastic, b.state.plastic), (a.state.kappa, b.state.kappa),
                     (a.dissipation, b.dissipation), (a.tangent, b.tangent)]:
            np.testing.assert_allclose(x, y, rtol=1e-9, atol=1e-12)
        s = a.state
    assert {ELASTIC, PLASTIC, OPEN} <= set(np.unique(a.status).tolist())


def _circle_exact(a, t, mu_n):
    """Exact Coulomb force for the circular path δ = R(cos t, sin t) after sliding to (R, 0).

    The force angle φ lags behind by ψ = t - φ with ψ' = 1 - a cos ψ, a = kt R/(μN), ψ(0) = 0;
    with u = tan(ψ/2), c² = (a-1)/(a+1), s = sqrt(a²-1): u = -c tanh(s t / 2).
    """
    c = np.sqrt((a - 1) / (a + 1))
    s = np.sqrt(a * a - 1)
    psi = 2 * np.arctan(-c * np.tanh(s * t / 2))
    phi = t - psi
    return mu_n * np.array([np.cos(phi), np.sin(phi)])


def _circle_error(model, steps, explicit=False):
    R, N, t_end = 0.02, 1.0, 1.0
    s = model.update(model.initial_state(), [0.0, 0.0, -N / KN]).state
    s = model.update(s, [R, 0.0, 0.0]).state
    ts = np.linspace(0.0, t_end, steps + 1)
    pts = R * np.column_stack((np.cos(ts), np.sin(ts)))
    for k in range(steps):
        du = np.array([*(pts[k + 1] - pts[k]), 0.0])
        s = (model.rate_update(s, du) if explicit else model.update(s, du)).state
    exact = _circle_exact(KT * R / (0.4 * N), t_end, 0.4 * N)
    return np.linalg.norm(model.force(s)[:2] - exact)


@pytest.mark.parametrize("explicit", [False, True])
def test_first_order_convergence_circular_path(explicit):
    """Backward Euler (and the explicit rate form (4.10)) converge at order 1 to the exact
    solution of a Coulomb contact dragged round a circle at fixed N."""
    m = model_for("coulomb")
    steps = np.array([20, 40, 80, 160])
    err = np.array([_circle_error(m, k, explicit) for k in steps])
    slope = np.polyfit(np.log(1.0 / steps), np.log(err), 1)[0]
    assert 0.85 < slope < 1.2, (slope, err)


def test_rate_form_and_implicit_agree_on_cap_path():
    """The explicit rate form (4.10)–(4.11) and backward Euler converge to one solution."""
    m = model_for("cap")
    s0 = m.update(m.initial_state(), [0.0, 0.0, -0.006]).state

    def run(steps, explicit):
        s = s0
        for _ in range(steps):
            du = np.array([0.03, 0.01, -0.002]) / steps
            s = (m.rate_update(s, du) if explicit else m.update(s, du)).state
        return m.force(s)

    fine = run(1600, False)
    errs = [np.linalg.norm(run(k, True) - fine) for k in (50, 100, 200)]
    assert errs[2] < errs[1] < errs[0]
    assert errs[2] < 0.01 * np.linalg.norm(fine)


def test_batched_shapes_and_broadcasting():
    m = model_for("cap")
    s = m.initial_state((2, 3))
    r = m.update(s, [0.0, 0.0, -0.004], tangent=True)
    assert r.force.shape == (2, 3, 3) and r.tangent.shape == (2, 3, 3, 3) and r.status.shape == (2, 3)
    assert isinstance(r.state, ContactState) and r.state.shape == (2, 3)


def test_user_law_goes_through_the_generic_path():
    """A UserLaw (SymPy f, g) integrates like the built-in law it spells out."""
    from frictionrules import N, T1, T2, UserLaw
    user = ContactModel(UserLaw(sympy.sqrt(T1**2 + T2**2) - 0.4 * N, sympy.sqrt(T1**2 + T2**2)), KN, KT)
    ref = model_for("coulomb")
    assert user.kernel() is None and ref.kernel() == "coulomb"
    su, sr = user.initial_state(), ref.initial_state()
    for du in ([0.0, 0.0, -0.01], [0.03, 0.01, 0.0], [0.0, 0.02, -0.002]):
        a, b = user.update(su, du, tangent=True), ref.update(sr, du, tangent=True)
        np.testing.assert_allclose(a.force, b.force, rtol=1e-10, atol=1e-14)
        np.testing.assert_allclose(a.tangent, b.tangent, rtol=1e-8, atol=1e-10)
        su, sr = a.state, b.state


def test_return_past_the_apex_of_the_wedge_cone():
    """Sliding down the wedge at fixed δn closes the contact plastically until N reaches 0:
    the return ends at the apex — zero force, the elastic displacement turned plastic."""
    m = model_for("wedge")
    s = m.update(m.initial_state(), [0.0, 0.0, -0.01]).state
    r = m.update(s, [-0.0390625, 0.03125, 0.0], tangent=True)
    assert r.status == OPEN
    np.testing.assert_array_equal(r.force, 0.0)
    np.testing.assert_array_equal(r.tangent, 0.0)
    np.testing.assert_array_equal(m.force(r.state), 0.0)
    np.testing.assert_allclose(r.state.elastic, 0.0, atol=1e-15)
    assert r.state.kappa > s.kappa and r.dissipation == 0.0
    again = m.update(r.state, [0.0, 0.0, -0.001])
    assert again.status == ELASTIC and again.force[2] == pytest.approx(0.1)
