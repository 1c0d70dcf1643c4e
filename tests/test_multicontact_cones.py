"""The law path's fast path for two coaxial elliptic cones (multicontact._cones_kernels) against
the general one (the law's generated return map through the contact layer).

A law whose f and g are :math:`\\sqrt{T^\\top P T} - mN` and :math:`\\sqrt{T^\\top A T}` with P
and A sharing their axes (the transformed-variable rule (1.17)-(1.18), the associated elliptic
law (1.9)-(1.10), Coulomb, a coaxial ``UserLaw``) is recognised from its symbolic form
(``codegen.elliptic_cones``); its projection along g has one scalar equation and its local
problem is solved on scalars. Checked here: what is recognised and what is not; the projection
and its derivative equal the general return's (the contact layer's update, its consistent
tangent) and finite differences; the local solve equals the general local solve to 1e-10,
ends on the limit surface or inside it (f <= tol) and dissipates (-r.u >= 0); whole solves
equal the general path's.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

import frictionrules as fr
from frictionrules.codegen import elliptic_cones
from frictionrules.laws import form_of

pytest.importorskip("numba")

from frictionrules.contact import workspace  # noqa: E402
from frictionrules.contact.layout import LAW_KN, LAW_KT  # noqa: E402
from frictionrules.multicontact import _cones_kernels as CK  # noqa: E402
from frictionrules.multicontact import _law_kernels as LK  # noqa: E402
from frictionrules.multicontact._law_path import law_set  # noqa: E402
from frictionrules.multicontact.factored import ContactLaws  # noqa: E402

RECOGNISED = {
    "transformed": fr.TransformedCoulomb(0.5, 0.25),
    "transformed turned": fr.TransformedCoulomb(0.6, 0.3, angle=0.4),
    "elliptic": fr.EllipticOrthotropic(0.2, 0.8, angle=-1.1),
    "coulomb": fr.Coulomb(0.5),
    "coaxial user": fr.UserLaw("sqrt(T1**2 + 4*T2**2) - 0.5*N", "sqrt(T1**2 + T2**2)"),
    "user, both ellipses": fr.UserLaw("sqrt(4*T1**2 + T2**2) - 0.7*N", "sqrt(2*T1**2 + T2**2)"),
}
NOT_RECOGNISED = {
    "huber": fr.Huber(0.6, 0.45, angle=-0.3),
    "dilatant": fr.UserLaw("sqrt(T1**2 + T2**2) - 0.5*N", "sqrt(T1**2 + 2*T2**2) - 0.2*N"),
    # the limit's axes turned against the potential's: not coaxial
    "turned axes": fr.UserLaw("sqrt((T1 + T2)**2 + 4*(T1 - T2)**2) - 0.5*N", "sqrt(T1**2 + 3*T2**2)"),
}


@pytest.mark.parametrize("name", list(RECOGNISED))
def test_elliptic_cones_recognised_with_their_numbers(name):
    """The numbers reproduce f + mN = sqrt(T'P'T') and g = sqrt(T'A'T') in the common frame."""
    law = RECOGNISED[name]
    e = elliptic_cones(form_of(law))
    assert e[0] == 1.0
    c, s, a1, a2, p1, p2, m = e[1:]
    rng = np.random.default_rng(3)
    T, N = rng.normal(size=(20, 2)), rng.uniform(0.5, 2.0, 20)
    t1, t2 = c * T[:, 0] + s * T[:, 1], -s * T[:, 0] + c * T[:, 1]
    assert law.limit(T, N) == pytest.approx(np.sqrt(p1 * t1**2 + p2 * t2**2) - m * N, rel=1e-12, abs=1e-12)
    assert law.potential(T, N) == pytest.approx(np.sqrt(a1 * t1**2 + a2 * t2**2), rel=1e-12, abs=1e-12)


@pytest.mark.parametrize("name", list(NOT_RECOGNISED))
def test_other_laws_keep_the_general_update(name):
    assert elliptic_cones(form_of(NOT_RECOGNISED[name]))[0] == 0.0


def _law_rows(law):
    """The law's kernel rows: (fn, row, ell) and ell zeroed (the general path)."""
    ls = law_set(ContactLaws([law]))
    return ls.fn[0], ls.rows[0].copy(), ls.ell[0].copy(), np.zeros_like(ls.ell[0])


def _project(fn, row, ell, x, want=True):
    s, du, s1, res, tan = LK.scratch(0)
    p0, p1, p2, kind, failed = LK.project_law(fn, row, ell, x[0], x[1], x[2], s, du, s1, res,
                                              workspace(0), tan, want)
    DP = np.empty((3, 3))
    LK.tangent_of(row, tan, DP)
    return np.array([p0, p1, p2]), kind, failed, DP


points = st.tuples(st.floats(0.05, 3.0), st.floats(-3.0, 3.0), st.floats(-3.0, 3.0))


@settings(max_examples=60, deadline=None)
@given(x=points, kt=st.floats(0.3, 3.0), kn=st.floats(0.3, 3.0), name=st.sampled_from(sorted(RECOGNISED)))
def test_projection_and_tangent_equal_the_general_return(x, kt, kn, name):
    """P_K(x) and dP_K/dx of the scalar equation against the law's generated return map and
    its consistent tangent, for any metric K (the projection does not depend on it)."""
    fn, row, ell, none = _law_rows(RECOGNISED[name])
    row[LAW_KT], row[LAW_KN] = kt, kn
    x = np.array(x)
    p, kind, failed, DP = _project(fn, row, ell, x)
    q, kind_g, failed_g, DQ = _project(fn, row, none, x)
    assert not failed and not failed_g
    scale = np.abs(x).max()
    assert np.abs(p - q).max() <= 1e-12 * scale
    if kind == kind_g:       # a trial within round-off of the surface may fall either side
        assert np.abs(DP - DQ).max() <= 1e-8 * max(1.0, np.abs(DQ).max())


@settings(max_examples=40, deadline=None)
@given(x=points, name=st.sampled_from(sorted(RECOGNISED)))
def test_projection_tangent_against_finite_differences(x, name):
    """dP_K/dx against central differences, away from the edge of the limit surface (where P_K
    has a kink: |f(x)| > 1e-3 |x|)."""
    law = RECOGNISED[name]
    x = np.array(x)
    assume(abs(law.limit(-x[1:], x[0])) > 1e-3 * np.abs(x).max())
    fn, row, ell, _ = _law_rows(law)
    _, _, _, DP = _project(fn, row, ell, x)
    h = 1e-6 * max(1.0, np.abs(x).max())
    fd = np.empty((3, 3))
    for k in range(3):
        e = np.zeros(3)
        e[k] = h
        fd[:, k] = (_project(fn, row, ell, x + e, False)[0] - _project(fn, row, ell, x - e, False)[0]) / (2 * h)
    assert np.abs(DP - fd).max() <= 1e-5 * max(1.0, np.abs(fd).max())


def _local_general(A, b, fn, row, none, r):
    s, du, s1, res, tan = LK.scratch(0)
    return np.array(LK._local(A, b, fn, row, none, False, r[0], r[1], r[2], 30, 1e-14, s, du, s1, res,
                              workspace(0), tan))


def _local_cones(A, b, row, ell, r):
    e = tuple(ell[1:])
    return np.array(CK.cones_local(tuple(A.ravel()), b[0], b[1], b[2], e, row[LAW_KN],
                                   row[LAW_KT], r[0], r[1], r[2], 30, 1e-14))


@settings(max_examples=80, deadline=None)
@given(seed=st.integers(0, 10**6), name=st.sampled_from(sorted(RECOGNISED)))
def test_local_solve_equals_the_general_one_and_is_admissible(seed, name):
    """One contact's problem A r + b in N_g(r), A a Delassus-like SPD block: the scalar local
    solve equals the general one to 1e-10; f(r) <= 1e-12 |r| and the dissipation -r.u >= 0
    (u = A r + b: zero sticking, lambda g(T, N) >= 0 sliding)."""
    law = RECOGNISED[name]
    fn, row, ell, none = _law_rows(law)
    rng = np.random.default_rng(seed)
    G = rng.normal(size=(3, 3))
    A = G @ G.T + 0.3 * np.eye(3)
    row[LAW_KN] = 1.0 / A[0, 0]
    row[LAW_KT] = 2.0 / (A[1, 1] + A[2, 2])
    b = rng.normal(size=3)
    b[0] = -abs(b[0]) - 0.05
    r_start = rng.normal(size=3) * rng.choice([0.0, 1.0])
    r_start[0] = abs(r_start[0])
    got = _local_cones(A, b, row, ell, r_start)
    want = _local_general(A, b, fn, row, none, r_start)
    assert np.abs(got - want).max() <= 1e-10 * max(1.0, np.abs(want).max())
    u = A @ got + b
    assert law.limit(-got[1:], got[0]) <= 1e-12 * max(1.0, np.abs(got).max())
    assert -got @ u >= -1e-12 * max(1.0, np.abs(got).max() * np.abs(u).max())


def test_local_solve_at_separation_and_stick():
    """b_N >= 0 separates (r = 0); a push inside the cone sticks at r = -A^-1 b."""
    law = RECOGNISED["transformed"]
    _, row, ell, _ = _law_rows(law)
    A = np.diag([1.0, 2.0, 2.0])
    assert np.all(_local_cones(A, np.array([0.3, 1.0, 0.0]), row, ell, np.ones(3)) == 0.0)
    stick = _local_cones(A, np.array([-1.0, 0.1, -0.05]), row, ell, np.zeros(3))
    assert stick == pytest.approx(np.linalg.solve(A, [1.0, -0.1, 0.05]), rel=1e-14)


@pytest.mark.parametrize("name", ["transformed turned", "coaxial user", "user, both ellipses"])
def test_whole_solves_equal_the_general_path(name):
    """NSGS on W and the factored sweeps with the scalar path equal the general path's (the same
    sweeps, reactions to 1e-10)."""
    from test_multicontact_factored import random_system
    law = RECOGNISED[name]
    blocks, J, Minv, q = random_system(4)
    W = J @ Minv @ J.T
    laws = [law] * blocks.nc
    fast = fr.solve(fr.FrictionContactProblem(W, q, laws), "nsgs", tol=1e-12, max_iter=3000)
    problem = fr.FrictionContactProblem(W, q, laws)
    law_set(problem).ell[:] = 0.0
    slow = fr.solve(problem, "nsgs", tol=1e-12, max_iter=3000)
    assert fast.converged and slow.converged and fast.iterations == slow.iterations
    assert np.abs(fast.r - slow.r).max() <= 1e-10 * np.abs(slow.r).max()
    from frictionrules.multicontact.factored import solve_factored
    claws = ContactLaws(laws)
    f1 = solve_factored(claws, blocks, q, tol=1e-12, max_iter=3000)
    claws0 = ContactLaws(laws)
    law_set(claws0).ell[:] = 0.0
    f0 = solve_factored(claws0, blocks, q, tol=1e-12, max_iter=3000)
    assert f1.iterations == f0.iterations
    assert np.abs(f1.r - f0.r).max() <= 1e-10 * np.abs(f0.r).max()


@pytest.mark.parametrize("law", [fr.TransformedCoulomb(0.6, 0.3, angle=0.4), fr.Huber(0.6, 0.45, angle=-0.3),
                                 fr.Coulomb(0.5)], ids=["transformed", "huber", "coulomb"])
def test_limit_value_is_the_laws_limit_condition(law):
    """contact.limit_value (the update's limit check alone) against the law's own f, and finite
    at the apex T = 0 (the kink rule: Huber's f is 0/0 there)."""
    from frictionrules.contact import limit_value
    fn, row, _, _ = _law_rows(law)
    ws = workspace(0)
    rng = np.random.default_rng(5)
    for T1, T2, N in rng.normal(size=(20, 3)) * [1.0, 1.0, 0.0] + [0.0, 0.0, 1.0] * rng.uniform(0.1, 2.0, (20, 1)):
        want = float(law.limit(np.array([T1, T2]), N))
        assert limit_value(fn, row, ws.qn, T1, T2, N, ws) == pytest.approx(want, rel=1e-12, abs=1e-12)
    apex = limit_value(fn, row, ws.qn, 0.0, 0.0, 1.0, ws)
    assert np.isfinite(apex) and apex < 0.0
