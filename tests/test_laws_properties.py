"""Invariants of every built-in law, checked with hypothesis: the sliding rule is the normalized
derived gradient of g, the inverse relation inverts it, dissipation is non-negative, frames
commute with rotations; hand-written gradients against the SymPy-derived ones and Hessians
against finite differences."""

import types

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from frictionrules import Coulomb, EllipticOrthotropic, Huber, TransformedCoulomb, WedgeAsperity
from frictionrules.laws._inverse import inverse_relation
from frictionrules.laws._symbolic import derived, form_of


def compiled(law):
    """The functions derived from the law's symbolic form, at its parameter values."""
    d, p = derived(law), form_of(law).values
    q = np.zeros(0)
    return types.SimpleNamespace(**{k: (lambda fun: lambda t1, t2, n: fun(t1, t2, n, q, p))(getattr(d, k))
                                    for k in ("f", "g", "grad_f", "grad_g")})

mus = st.floats(0.05, 1.5)
angles = st.floats(-np.pi, np.pi)
thetas = st.floats(-np.pi, np.pi)
normals = st.floats(0.1, 10.0)


@st.composite
def laws(draw, wedge=True):
    kind = draw(st.sampled_from(["coulomb", "elliptic", "huber", "transformed"] + (["wedge"] if wedge else [])))
    if kind == "coulomb":
        return Coulomb(draw(mus), draw(st.booleans()))
    if kind == "elliptic":
        return EllipticOrthotropic(draw(mus), draw(mus), draw(angles))
    if kind == "huber":
        return Huber(draw(mus), draw(mus), draw(angles))
    if kind == "transformed":
        return TransformedCoulomb(draw(mus), draw(mus), draw(angles))
    # an elliptic wedge (alpha' + rho < pi/2) so that every direction slides
    mu = draw(st.floats(0.05, 1.0))
    a = draw(st.floats(0.05, 0.95)) * (np.pi / 2 - np.arctan(mu))
    alpha = draw(st.sampled_from([a, np.pi - a]))
    return WedgeAsperity(alpha, mu, draw(st.sampled_from(["non-associated", "associated"])))


def _limit_point(law, theta, N):
    return law.force_for_slip([np.cos(theta), np.sin(theta)], N)


settings.register_profile("laws", max_examples=60, deadline=None)
settings.load_profile("laws")


@given(laws(), thetas, normals)
def test_slip_direction_is_normalized_derived_gradient_of_g(law, theta, N):
    T = _limit_point(law, theta, N)
    grad = compiled(law).grad_g(T[0], T[1], N)
    v = np.array([grad[0], grad[1], -grad[2]])
    np.testing.assert_allclose(law.slip_direction(T, N), v / np.linalg.norm(v), rtol=1e-9, atol=1e-12)


@given(laws(), thetas, normals)
def test_hand_written_gradients_match_derived(law, theta, N):
    T = 1.3 * _limit_point(law, theta, N) + 0.01  # off the limit surface, away from the apex
    c = compiled(law)
    np.testing.assert_allclose(law.limit_gradient(T, N), c.grad_f(T[0], T[1], N), rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(law.potential_gradient(T, N), c.grad_g(T[0], T[1], N), rtol=1e-9, atol=1e-12)
    assert float(law.limit(T, N)) == pytest.approx(float(c.f(T[0], T[1], N)), rel=1e-12, abs=1e-12)


@given(laws(), thetas, normals)
def test_hessians_match_finite_differences(law, theta, N):
    T = _limit_point(law, theta, N)
    x = np.array([T[0], T[1], N])
    h = 1e-6 * max(1.0, np.abs(x).max())
    for hess, grad in ((law.limit_hessian, law.limit_gradient), (law.potential_hessian, law.potential_gradient)):
        H = hess(T, N)
        fd = np.empty((3, 3))
        for j in range(3):
            e = np.zeros(3)
            e[j] = h
            fd[:, j] = (grad((x + e)[:2], (x + e)[2]) - grad((x - e)[:2], (x - e)[2])) / (2 * h)
        np.testing.assert_allclose(H, fd, rtol=1e-5, atol=1e-6 * np.abs(H).max() + 1e-9)


@given(laws(), thetas, normals)
def test_force_for_slip_inverts_slip_direction(law, theta, N):
    T = _limit_point(law, theta, N)
    assert abs(float(law.limit(T, N))) <= 1e-10 * max(N, np.hypot(*T))
    v = law.slip_direction(T, N)
    assert np.arctan2(v[1], v[0]) == pytest.approx(theta, abs=1e-9) or abs(abs(theta) - np.pi) < 1e-9
    np.testing.assert_allclose(law.force_for_slip(v, N), T, rtol=1e-9, atol=1e-12 * N)


@given(laws(), thetas, normals)
def test_closed_form_inverse_matches_generic_numeric_inverse(law, theta, N):
    closed = law.inverse_relation(np.array(theta), np.array(N)).force
    generic = inverse_relation(law, np.array(theta), np.array(N)).force
    np.testing.assert_allclose(closed, generic, rtol=1e-9, atol=1e-12 * N)


@given(laws(), st.lists(st.floats(-5, 5), min_size=2, max_size=2), normals)
def test_dissipation_is_non_negative(law, v, N):
    if np.hypot(*v) < 1e-6:
        v = [1.0, 0.0]
    D = float(law.dissipation(v, N))
    assert D >= -1e-12 * N * np.hypot(*v)
    s = law.slip_direction(law.force_for_slip(v, N), N)
    assert float(law.dissipation(s, N)) >= -1e-12 * N


@given(st.sampled_from([EllipticOrthotropic, Huber, TransformedCoulomb]), mus, mus, angles, angles, thetas, normals)
def test_rotating_the_frame_commutes_with_rotating_forces_and_slips(cls, m1, m2, a, b, theta, N):
    law, turned = cls(m1, m2, a), cls(m1, m2, ((a + b + np.pi) % (2 * np.pi)) - np.pi)
    R = np.array([[np.cos(b), -np.sin(b)], [np.sin(b), np.cos(b)]])
    T = _limit_point(law, theta, N)
    np.testing.assert_allclose(_limit_point(turned, theta + b, N), R @ T, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(turned.slip_direction(R @ T, N)[:2], R @ law.slip_direction(T, N)[:2],
                               rtol=1e-9, atol=1e-12)
    assert float(turned.limit(R @ T, N)) == pytest.approx(float(law.limit(T, N)), abs=1e-12)
    assert float(turned.friction_coefficient(theta + b)) == pytest.approx(float(law.friction_coefficient(theta)))


@given(st.floats(0.0, 2.0), st.booleans(), angles, thetas, normals)
def test_coulomb_is_isotropic(mu, dilatant, b, theta, N):
    law = Coulomb(mu, dilatant)
    R = np.array([[np.cos(b), -np.sin(b)], [np.sin(b), np.cos(b)]])
    T = 0.7 * np.array([np.cos(theta), np.sin(theta)])
    v, vr = law.slip_direction(T, N), law.slip_direction(R @ T, N)
    np.testing.assert_allclose(vr[:2], R @ v[:2], atol=1e-14)
    assert vr[2] == pytest.approx(v[2])


def test_cone_apex_and_kinks_are_finite():
    for law in (Coulomb(0.3), EllipticOrthotropic(0.6, 0.3), Huber(0.6, 0.3), TransformedCoulomb(0.6, 0.3)):
        v = law.slip_direction([0.0, 0.0], 1.0)
        np.testing.assert_array_equal(v, 0.0)  # no preferred direction inside, at T = 0
        assert float(law.limit([0.0, 0.0], 1.0)) < 0
        assert float(law.limit([0.0, 0.0], 0.0)) == 0.0  # the apex itself is on the surface
    # the dilatant cone's apex: pure opening
    np.testing.assert_allclose(Coulomb(0.3, True).slip_direction([0.0, 0.0], 0.0), [0.0, 0.0, 1.0])
    # zero normal force: the inverse is the zero force
    np.testing.assert_array_equal(Coulomb(0.3).force_for_slip([1.0, 2.0], 0.0), 0.0)
    np.testing.assert_array_equal(EllipticOrthotropic(0.6, 0.3).force_for_slip([1.0, 2.0], 0.0), 0.0)


def test_vectorized_over_leading_dimensions():
    law = EllipticOrthotropic(0.6, 0.3, 0.2)
    rng = np.random.default_rng(3)
    T = rng.normal(size=(4, 5, 2))
    N = rng.uniform(0.5, 1.0, (4, 5))
    assert law.limit(T, N).shape == (4, 5)
    assert law.slip_direction(T, N).shape == (4, 5, 3)
    assert law.limit_hessian(T, N).shape == (4, 5, 3, 3)
    np.testing.assert_allclose(law.slip_direction(T, N)[2, 3], law.slip_direction(T[2, 3], N[2, 3]))
    assert law.limit(T, 1.0).shape == (4, 5)  # broadcasting N
    V = rng.normal(size=(3, 2))
    assert law.force_for_slip(V, 1.0).shape == (3, 2)
    assert law.friction_coefficient(np.zeros((2, 3))).shape == (2, 3)
