"""FacetSet with local laws other than Coulomb: against an independent mechanism search written
here (slip-angle parametrization + law.inverse_relation + brentq, a 3x3 solve for pairs), the
Coulomb limit, dilatant and user laws, the facet frame convention, vectorized limit loads."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import brentq, linprog

from frictionrules import (Coulomb, EllipticOrthotropic, FacetSet, FrictionRulesError,
                           HardenedLaw, Huber, SlipHardening, TransformedCoulomb, TwoFlankAsperity,
                           UserLaw, WedgeAsperity)

FIG5_NORMALS = TwoFlankAsperity(np.pi / 3, 5 * np.pi / 6, 1.0).normals()
Z = np.array([0.0, 0.0, 1.0])


def directions(m, offset=0.37):
    phi = -np.pi + 2 * np.pi * (np.arange(m) + offset) / m
    return phi, np.stack((np.cos(phi), np.sin(phi)), axis=-1)


def unit(v):
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def frames(n):
    """t1 = unit projection of x onto the facet, t2 = n x t1 (docs/conventions.md)."""
    x = np.array([1.0, 0.0, 0.0])
    t1 = unit(x - np.outer(n @ x, np.ones(3)) * n)
    return t1, np.cross(n, t1)


def wrap(a):
    return np.angle(np.exp(1j * a))


# ---- the independent search -------------------------------------------------------------------
def independent_limit_loads(normals, laws, phi, samples=3000):
    """Smallest load factor along each direction ``phi`` (Q = 1) over

    * one facet j sliding at the in-plane slip angle theta (V = cos t1 + sin t2, admissible when
      V.n_m >= 0 for the others): the local force per unit N from ``law.inverse_relation``, the
      block's load ``F = N (T1 t1 + T2 t2 - n)`` with ``F_z = -1``; the load direction of F is
      matched to phi by brentq on theta;
    * two facets sliding along +-(n_j x n_k): forces from the two inverse relations and the 3x3
      system ``t D + N_j r_j + N_k r_k = z``, ``r = n - T1 t1 - T2 t2``, with t, N >= 0.

    Only laws without normal slip (the velocity lies in the sliding facets' planes).
    """
    n = unit(np.asarray(normals, float))
    t1, t2 = frames(n)
    K = len(n)

    def load_on(j, theta):
        T = laws[j].inverse_relation(np.asarray(theta, float), 1.0).force
        p = T[..., :1] * t1[j] + T[..., 1:] * t2[j] - n[j]          # block's force per unit N
        N = -1.0 / p[..., 2]
        return np.where((N > 0)[..., None], N[..., None] * p[..., :2], np.nan)

    best = np.full(len(phi), np.inf)
    theta = np.linspace(-np.pi, np.pi, samples + 1)
    for j in range(K):
        V = np.cos(theta)[:, None] * t1[j] + np.sin(theta)[:, None] * t2[j]
        others = [m for m in range(K) if m != j]
        ok = np.all(V @ n[others].T >= -1e-12, axis=1) if others else np.ones(len(theta), bool)
        T = load_on(j, theta)
        ok &= np.all(np.isfinite(T), axis=1)
        ang = np.arctan2(T[:, 1], T[:, 0])
        for m, ph in enumerate(phi):
            g = wrap(ang - ph)
            cand = np.flatnonzero(ok[:-1] & ok[1:] & (g[:-1] * g[1:] <= 0)
                                  & (np.abs(g[:-1] - g[1:]) < 1.0))
            for i in cand:
                def h(th):
                    Tt = load_on(j, th)
                    return wrap(np.arctan2(Tt[1], Tt[0]) - ph)
                th = brentq(h, theta[i], theta[i + 1], xtol=1e-15, rtol=1e-15)
                Tt = load_on(j, th)
                if np.all(np.isfinite(Tt)) and np.hypot(*Tt) > 0 and abs(h(th)) < 1e-9:
                    best[m] = min(best[m], np.hypot(*Tt))
    D = np.stack((np.cos(phi), np.sin(phi), 0 * phi), axis=-1)
    for j in range(K):
        for k in range(j + 1, K):
            e = np.cross(n[j], n[k])
            if np.linalg.norm(e) < 1e-12:
                continue
            for V in (unit(e), -unit(e)):
                others = [m for m in range(K) if m not in (j, k)]
                if others and np.any(V @ n[others].T < -1e-12):
                    continue
                r = []
                for f in (j, k):
                    th = np.arctan2(V @ t2[f], V @ t1[f])
                    T = laws[f].inverse_relation(th, 1.0).force
                    r.append(n[f] - T[0] * t1[f] - T[1] * t2[f])
                for m in range(len(phi)):
                    A = np.stack((D[m], r[0], r[1]), axis=1)
                    if abs(np.linalg.det(A)) < 1e-12:
                        continue
                    t, Nj, Nk = np.linalg.solve(A, Z)
                    if t >= 0 and Nj >= -1e-12 and Nk >= -1e-12:
                        best[m] = min(best[m], t)
    return best


def random_normals(seed, k, slope=0.7):
    p = np.random.default_rng(seed).uniform(-slope, slope, size=(k, 2))
    return np.concatenate((-p, np.ones((k, 1))), axis=1)


CASES = {
    "fig5-elliptic": (FIG5_NORMALS, [EllipticOrthotropic(0.9, 0.5, 0.4)] * 2),
    "random-elliptic-per-facet": (random_normals(1, 4), [
        EllipticOrthotropic(0.6, 0.3, 0.2), EllipticOrthotropic(0.35, 0.7, -1.0),
        EllipticOrthotropic(0.5, 0.4, 2.0), Coulomb(0.45)]),
    "random-mixed": (random_normals(4, 3), [Huber(0.5, 0.4, 0.3), TransformedCoulomb(0.6, 0.4),
                                             EllipticOrthotropic(0.4, 0.7, 1.2)]),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_local_laws_match_an_independent_mechanism_search(case):
    normals, laws = CASES[case]
    law = laws[0] if len(set(laws)) == 1 else laws
    fs = FacetSet(normals, law)
    phi, d = directions(40)
    got = fs.limit_load(d)
    want = independent_limit_loads(normals, laws, phi)
    assert got.quasi_static.all()
    assert np.array_equal(np.isfinite(got.load), np.isfinite(want))
    fin = np.isfinite(want)
    assert fin.sum() >= 20
    np.testing.assert_allclose(got.load[fin], want[fin], rtol=1e-9)


@pytest.mark.parametrize("normals", [FIG5_NORMALS, random_normals(2, 5)])
def test_equal_coefficients_reduce_to_coulomb(normals):
    mu = 0.45
    phi, d = directions(36)
    ref = FacetSet(normals, mu).limit_load(d)
    fin = np.isfinite(ref.load)
    # mu_x = mu_y: Coulomb exactly (the fast path), whatever the axes' angle
    same = FacetSet(normals, EllipticOrthotropic(mu, mu, 0.7)).limit_load(d)
    np.testing.assert_array_equal(same.load, ref.load)
    # the general paths: a cone a hair off isotropy, and laws that are Coulomb at mu_1 = mu_2
    # without declaring a cone (solved numerically)
    for law, tol in ((EllipticOrthotropic(mu, mu * (1 + 1e-12), 0.7), 1e-9),
                     (Huber(mu, mu, 0.3), 1e-12), (TransformedCoulomb(mu, mu, -0.2), 1e-12)):
        got = FacetSet(normals, law).limit_load(d)
        assert np.array_equal(np.isfinite(got.load), fin)
        np.testing.assert_allclose(got.load[fin], ref.load[fin], rtol=tol)
        np.testing.assert_array_equal(got.facets * got.active, ref.facets * ref.active)
        np.testing.assert_allclose(got.velocity, ref.velocity, atol=1e-9)
    theta = np.linspace(-3.0, 3.0, 13)
    np.testing.assert_allclose(FacetSet(normals, Huber(mu, mu)).friction_coefficient(theta),
                               FacetSet(normals, mu).friction_coefficient(theta), rtol=1e-9)


def test_one_facet_closed_forms_and_the_frame_rule():
    """A facet inclined at alpha about y: t1 = (cos a, 0, sin a) is its up-slope direction, so
    an elliptic law with axis 1 along t1 (angle 0) climbs with mu_x: T_x = Q tan(a + atan mu_x);
    pushed along the ridge (y = t2) T1 = -Q sin a and N = Q cos a stay, and T2 reaches
    mu_y sqrt(N^2 - T1^2/mu_x^2). A quarter turn of the law's axes swaps the coefficients."""
    a, mx, my = 0.3, 0.6, 0.35
    n = np.array([[-np.sin(a), 0.0, np.cos(a)]])
    fs = FacetSet(n, EllipticOrthotropic(mx, my, 0.0))
    np.testing.assert_allclose(fs.frames()[0], [[np.cos(a), 0, np.sin(a)], [0, 1, 0], n[0]],
                               atol=1e-15)
    for law, m1, m2 in ((fs.law, mx, my), (EllipticOrthotropic(mx, my, np.pi / 2), my, mx)):
        f = FacetSet(n, law)
        assert f.limit_load([1.0, 0.0], 2.0).load == pytest.approx(2.0 * np.tan(a + np.arctan(m1)),
                                                                  rel=1e-13)
        Ty = m2 * np.sqrt(np.cos(a) ** 2 - np.sin(a) ** 2 / m1**2)
        assert f.limit_load([0.0, 1.0]).load == pytest.approx(Ty, rel=1e-13)


def test_frames_follow_the_convention():
    n = unit(random_normals(7, 6, 1.5))
    F = FacetSet(n, 3.0).frames()
    t1, t2 = frames(n)
    np.testing.assert_allclose(F[:, 0], t1, atol=1e-15)
    np.testing.assert_allclose(F[:, 1], t2, atol=1e-15)
    np.testing.assert_allclose(F[:, 2], n, atol=1e-15)
    np.testing.assert_allclose(np.einsum("kij,klj->kil", F, F), np.broadcast_to(np.eye(3), F.shape),
                               atol=1e-14)
    np.testing.assert_allclose(np.linalg.det(F), 1.0)


@settings(max_examples=8, deadline=None)
@given(seed=st.integers(0, 1000), rot=st.floats(-np.pi, np.pi))
def test_rotating_the_facets_rotates_the_limit_curve(seed, rot):
    """Turn the facets about z by rot and each law's axes by the angle delta from the new
    frame's t1 to the turned old t1 (the frame rule): the limit load in the turned direction,
    the mechanism and the turned velocity are unchanged."""
    normals = unit(random_normals(seed, 3, 0.6))
    laws = [EllipticOrthotropic(0.6, 0.3, 0.5), EllipticOrthotropic(0.3, 0.5, -1.0),
            EllipticOrthotropic(0.45, 0.8, 2.5)]
    c, s = np.cos(rot), np.sin(rot)
    R = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    turned_n = normals @ R.T
    t1, _ = frames(normals)
    u1, u2 = frames(turned_n)
    Rt1 = t1 @ R.T
    delta = np.arctan2(np.sum(Rt1 * u2, -1), np.sum(Rt1 * u1, -1))
    turned_laws = [EllipticOrthotropic(x.mu_x, x.mu_y, float(wrap(x.angle + dl)))
                   for x, dl in zip(laws, delta)]
    try:
        a = FacetSet(normals, laws)
    except FrictionRulesError:
        return                                               # the block slides under Q alone
    b = FacetSet(turned_n, turned_laws)
    phi, d = directions(24)
    ra, rb = a.limit_load(d), b.limit_load(d @ R[:2, :2].T)
    assert np.array_equal(np.isfinite(ra.load), np.isfinite(rb.load))
    fin = np.isfinite(ra.load)
    np.testing.assert_allclose(rb.load[fin], ra.load[fin], rtol=1e-9)
    np.testing.assert_array_equal((ra.facets * ra.active)[fin], (rb.facets * rb.active)[fin])
    np.testing.assert_allclose(rb.velocity[fin], ra.velocity[fin] @ R.T, atol=1e-8)


# ---- dilatant laws ----------------------------------------------------------------------------
def elliptic_cone(a, b, d):
    """An elliptic cone in (T1, T2) with dilatancy ratio d, as a user law (capability cone)."""
    return UserLaw("sqrt((T1/a)**2 + (T2/b)**2) - N", potential="sqrt((T1/a)**2 + (T2/b)**2) - d*N",
                   params={"a": a, "b": b, "d": d})


def test_dilatant_coulomb_is_the_associated_rule():
    phi, d = directions(48)
    for normals in (FIG5_NORMALS, random_normals(3, 5)):
        a = FacetSet(normals, Coulomb(0.5, dilatant=True)).limit_load(d)
        b = FacetSet(normals, 0.5, "associated").limit_load(d)
        np.testing.assert_array_equal(a.load, b.load)
        c = FacetSet(normals, Coulomb(0.5), "associated").limit_load(d)   # the twin of (1.5)
        np.testing.assert_array_equal(c.load, b.load)


def lp_static_max_elliptic(normals, cones, d, G=180):
    """max t: t D + sum lambda_g r_g = z, lambda >= 0, with r_g the block's reactions on the
    generators of each facet's elliptic friction cone (an inner polygon: a lower bound)."""
    n = unit(np.asarray(normals, float))
    t1, t2 = frames(n)
    b = 2 * np.pi * np.arange(G) / G
    gens = []
    for j, (mx, my, ang) in enumerate(cones):
        T1 = mx * np.cos(b) * np.cos(ang) - my * np.sin(b) * np.sin(ang)
        T2 = mx * np.cos(b) * np.sin(ang) + my * np.sin(b) * np.cos(ang)
        gens.append(n[j] - T1[:, None] * t1[j] - T2[:, None] * t2[j])
    R = np.concatenate(gens).T
    out = []
    for di in d:
        A = np.concatenate(([[di[0]], [di[1]], [0.0]], R), axis=1)
        c = np.zeros(A.shape[1])
        c[0] = -1.0
        res = linprog(c, A_eq=A, b_eq=Z, bounds=[(0, None)] * A.shape[1], method="highs")
        out.append(np.inf if res.status == 3 else res.x[0])
    return np.array(out)


@pytest.mark.parametrize("normals", [FIG5_NORMALS, random_normals(5, 4, 0.5)])
def test_associated_elliptic_cones_give_the_static_maximum(normals):
    """g = f (dilatancy ratio 1): the limit load is the static maximum (limit analysis), checked
    against a linear programme on polygonal cones; the non-associated law (ratio 0) and an
    intermediate one never exceed it."""
    phi, d = directions(24)
    laws = [elliptic_cone(0.5, 0.3, 1.0), elliptic_cone(0.3, 0.45, 1.0)]
    assert all("cone" in x.capabilities for x in laws)
    lp = lp_static_max_elliptic(normals, ([(0.5, 0.3, 0.0), (0.3, 0.45, 0.0)] * 2)[:len(normals)],
                                d)
    law = laws * (len(normals) // 2) + laws[: len(normals) % 2]
    assoc = FacetSet(normals, law).limit_load(d)
    assert FacetSet(normals, law).associated and assoc.quasi_static.all()
    assert np.array_equal(np.isfinite(lp), np.isfinite(assoc.load))
    fin = np.isfinite(lp)
    np.testing.assert_allclose(assoc.load[fin], lp[fin], rtol=2e-3)
    assert np.all(lp[fin] <= assoc.load[fin] * (1 + 1e-9))
    for ratio in (0.0, 0.5):
        other = [elliptic_cone(x.parameters["a"], x.parameters["b"], ratio) for x in law]
        r = FacetSet(normals, other).limit_load(d)
        assert np.all(r.load <= assoc.load * (1 + 1e-9))
        np.testing.assert_array_equal(FacetSet(normals, other, "associated").limit_load(d).load,
                                      assoc.load)


def check_mechanism(fs, r, laws, d, Q=1.0):
    """Equilibrium, N >= 0, the sliding facets' rules (the local force slides with the block's
    velocity, normal slip included) and admissibility of the others."""
    n = fs.normal_array
    F = fs.frames()
    V = r.velocity
    P = np.zeros(3)
    for j in r.mechanism:
        t1, t2 = F[j, 0], F[j, 1]
        vt = np.array([V @ t1, V @ t2])
        T = laws[j].inverse_relation(np.arctan2(vt[1], vt[0]), r.normal_forces[j]).force
        s = laws[j].slip_direction(T, r.normal_forces[j])
        np.testing.assert_allclose(s, np.array([*vt, V @ n[j]]) / np.linalg.norm(V), atol=1e-8)
        assert float(laws[j].limit(T, r.normal_forces[j])) == pytest.approx(0.0, abs=1e-9)
        P = P + T[0] * t1 + T[1] * t2 - r.normal_forces[j] * n[j]
    np.testing.assert_allclose(P, [*r.T, -Q], atol=1e-8)
    assert np.all(r.normal_forces >= 0)
    for m in set(range(len(n))) - set(r.mechanism):
        vt = np.array([V @ F[m, 0], V @ F[m, 1]])
        psi = laws[m].slip_direction(laws[m].inverse_relation(np.arctan2(vt[1], vt[0]), 1.0).force,
                                     1.0)
        assert V @ n[m] >= np.hypot(*vt) * psi[2] / np.hypot(*psi[:2]) - 1e-8


@settings(max_examples=6, deadline=None)
@given(seed=st.integers(0, 1000), ratio=st.sampled_from([0.3, 0.7]), phi=st.floats(-np.pi, np.pi))
def test_dilatant_elliptic_mechanisms_hypothesis(seed, ratio, phi):
    laws = [elliptic_cone(0.5, 0.35, ratio), elliptic_cone(0.4, 0.6, ratio),
            elliptic_cone(0.45, 0.45, ratio)]
    try:
        fs = FacetSet(random_normals(seed, 3, 0.5), laws)
    except FrictionRulesError:
        return
    d = np.array([np.cos(phi), np.sin(phi)])
    r = fs.limit_load(d)
    if r.mechanism is not None and r.quasi_static:
        check_mechanism(fs, r, laws, d)


def test_dilatant_user_law_without_a_cone():
    """A non-cone dilatant user law (elliptic limit, isotropic potential with dilatancy):
    the mechanisms meet their local rules, and the protocol holds on the limit curve."""
    law = UserLaw("sqrt((T1/a)**2 + (T2/b)**2) - N", potential="sqrt(T1**2 + T2**2) - psi*N",
                  params={"a": 0.5, "b": 0.3, "psi": 0.2})
    assert "cone" not in law.capabilities
    fs = FacetSet(FIG5_NORMALS, law)
    laws = [law, law]
    phi, d = directions(8)
    rs = fs.limit_load(d)
    for i in range(len(d)):
        if not rs.locked[i] and rs.quasi_static[i]:
            check_mechanism(fs, rs[i], laws, d[i])
    assert {len(rs[i].mechanism) for i in range(len(d)) if not rs.locked[i]} == {1, 2}
    fin = ~rs.locked
    np.testing.assert_allclose(fs.limit(rs.T[fin], 1.0), 0.0, atol=1e-12)
    np.testing.assert_allclose(fs.slip_direction(rs.T[fin], 1.0), rs.velocity[fin], atol=1e-10)


# ---- user laws --------------------------------------------------------------------------------
def test_user_laws_equal_the_built_in_laws_they_write():
    phi, d = directions(24)
    normals = random_normals(2, 4)
    cone = UserLaw("sqrt((T1/a)**2 + (T2/b)**2) - N", potential="sqrt((T1/a)**2 + (T2/b)**2)",
                   params={"a": 0.55, "b": 0.35})
    a = FacetSet(normals, cone).limit_load(d)
    b = FacetSet(normals, EllipticOrthotropic(0.55, 0.35)).limit_load(d)
    np.testing.assert_allclose(a.load, b.load, rtol=1e-12)
    transformed = UserLaw("sqrt((T1/a)**2 + (T2/b)**2) - N", potential="sqrt(T1**2/a + T2**2/b)",
                          params={"a": 0.55, "b": 0.35})
    a = FacetSet(normals, transformed).limit_load(d)
    b = FacetSet(normals, TransformedCoulomb(0.55, 0.35)).limit_load(d)
    np.testing.assert_allclose(a.load, b.load, rtol=1e-10)
    np.testing.assert_array_equal(a.quasi_static, b.quasi_static)


# ---- the protocol with local laws -------------------------------------------------------------
def test_protocol_on_the_limit_curve_with_orthotropic_facets():
    fs = FacetSet(FIG5_NORMALS, EllipticOrthotropic(0.7, 0.4, 0.3))
    curve = fs.limit_curve(1.0, n=120)
    fin = np.isfinite(curve.load)
    T = curve.T[fin]
    np.testing.assert_allclose(fs.limit(T, 1.0), 0.0, atol=1e-12)
    assert np.all(fs.limit(0.5 * T, 1.0) < 0) and np.all(fs.limit(1.5 * T, 1.0) > 0)
    np.testing.assert_allclose(fs.slip_direction(T, 1.0), curve.velocity[fin], atol=1e-12)
    np.testing.assert_allclose(fs.normal_direction(T, 1.0), curve.normal[fin], atol=1e-12)
    assert len(curve.corners) >= 2
    theta = np.linspace(-np.pi, np.pi, 25)
    inv = fs.inverse_relation(theta, 1.0)
    ok = ~inv.locked
    assert ok.sum() >= 10
    np.testing.assert_allclose(fs.limit(inv.force[ok], 1.0), 0.0, atol=1e-10)
    v = fs.slip_direction(inv.force[ok], 1.0)
    np.testing.assert_allclose(wrap(np.arctan2(v[:, 1], v[:, 0]) - theta[ok]), 0.0, atol=1e-9)
    assert np.all(fs.dissipation(np.stack((np.cos(theta[ok]), np.sin(theta[ok])), -1), 1.0) > 0)


def test_two_flank_asperity_takes_a_law():
    law = EllipticOrthotropic(0.6, 0.3, 0.2)
    groove = TwoFlankAsperity(np.pi / 3, 5 * np.pi / 6, law)
    assert TwoFlankAsperity(np.pi / 3, 5 * np.pi / 6, law=law) == groove
    phi, d = directions(36)
    np.testing.assert_array_equal(groove.limit_load(d).load,
                                  FacetSet(groove.normals(), law).limit_load(d).load)
    with pytest.raises(FrictionRulesError, match="closed forms"):
        groove.closed_form_load(d)
    assert groove.parameters == {"alpha1": np.pi / 3, "alpha2": 5 * np.pi / 6, **law.parameters}
    assert groove.replace(mu_y=0.4, alpha1=1.0).law == law.replace(mu_y=0.4)
    assert TwoFlankAsperity(1.0, 2.0, 0.3).replace(mu=0.4).mu == 0.4


def test_limit_load_vectorized_over_directions():
    fs = FacetSet(random_normals(3, 5), EllipticOrthotropic(0.5, 0.3, 0.4))
    phi, d = directions(30)
    many = fs.limit_load(d, Q=2.0)
    np.testing.assert_allclose(fs.limit_load(3.0 * d, Q=2.0).load, many.load, rtol=1e-14)
    assert len(many) == 30 and many.normal_forces.shape == (30, 5)
    for i in range(30):
        one = fs.limit_load(d[i], Q=2.0)
        row = many[i]
        assert row.mechanism == one.mechanism and row.quasi_static == one.quasi_static
        np.testing.assert_allclose(row.T, one.T, rtol=1e-13)
        np.testing.assert_allclose(row.normal_forces, one.normal_forces, rtol=1e-13)
        assert bool(many.locked[i]) == (one.mechanism is None)
    assert many.locked.any() or np.isfinite(many.load).all()
    with pytest.raises(FrictionRulesError, match="nonzero"):
        fs.limit_load([[1.0, 0.0], [0.0, 0.0]])


def test_parameters_and_replace():
    n = FIG5_NORMALS
    assert FacetSet(n, 0.3).parameters == {"mu": 0.3}
    assert FacetSet(n, mu=0.3) == FacetSet(n, 0.3) and FacetSet(n, 0.3).mu == 0.3
    assert FacetSet(n, 0.3).replace(mu=0.4) == FacetSet(n, 0.4)
    law = Huber(0.5, 0.4)
    fs = FacetSet(n, law)
    assert fs.parameters == law.parameters
    assert fs.replace(mu_2=0.45).law == Huber(0.5, 0.45)
    assert fs.local_laws == (law, law)
    with pytest.raises(FrictionRulesError, match="not Coulomb"):
        fs.mu
    assert FacetSet(n, [0.3, Coulomb(0.3)]).mu == 0.3                  # Coulomb on both
    with pytest.raises(FrictionRulesError, match="parameters"):
        fs.replace(mu=0.3)


def test_laws_the_search_cannot_use_are_refused():
    n = FIG5_NORMALS
    cases = [(HardenedLaw(Coulomb(0.4), SlipHardening(0.2, 0.1)), "internal variables"),
             (WedgeAsperity(0.3, 0.4), "external loads"),
             (FacetSet([[0.0, 0.0, 1.0]], 0.3), "external loads"),
             (UserLaw("sqrt(T1**2 + T2**2) - mu*N - c", params={"mu": 0.4, "c": 0.1}),
              "homogeneous"),
             (Huber(0.3, 0.5), "not convex"),
             ("0.3", "a number"), ([0.3, 0.4, 0.5], "one per facet"), (-0.3, "mu > 0")]
    for law, match in cases:
        with pytest.raises(FrictionRulesError, match=match):
            FacetSet(n, law)
    with pytest.raises(FrictionRulesError, match="once"):
        FacetSet(n, 0.3, mu=0.3)
    with pytest.raises(FrictionRulesError, match="internal variables"):
        TwoFlankAsperity(1.0, 2.0, HardenedLaw(Coulomb(0.4), SlipHardening(0.2, 0.1)))


def test_orthotropic_facet_must_carry_the_vertical_load():
    """A 30° facet holds the block only if the coefficient along its slope (its t1 axis)
    exceeds tan 30° = 0.577."""
    n = [[-np.sin(np.pi / 6), 0.0, np.cos(np.pi / 6)]]
    with pytest.raises(FrictionRulesError, match="cannot carry"):
        FacetSet(n, EllipticOrthotropic(0.5, 0.9))
    FacetSet(n, EllipticOrthotropic(0.5, 0.9, np.pi / 2))
    with pytest.raises(FrictionRulesError, match="cannot carry"):
        FacetSet(n, Huber(0.5, 0.7))
    FacetSet(n, Huber(0.6, 0.5))


# ---- a machined surface with local laws, end to end ------------------------------------------
def test_machined_surface_with_orthotropic_and_dilatant_facets():
    """Grooves along y (rising at 0.35, falling at 0.2 across): every facet's t1 lies across
    the lay and t2 along it, so machined facets EllipticOrthotropic(mu_x, mu_y) slide across
    the lay as Coulomb mu_x — tan(atan s + atan mu_x), s the slope climbed — and along it as
    Coulomb mu_y. A dilatant (associated) machined law never gives smaller limit loads."""
    from frictionrules import from_heightmap
    from frictionrules.asperities.surfaces import machined_surface

    h = machined_surface(48, period=16.0, roughness=0.0)
    law = EllipticOrthotropic(0.25, 0.12)
    ortho = from_heightmap(h, 1.0, 1.0, law)
    across = ortho.friction_coefficient(np.array([0.0, np.pi]))
    np.testing.assert_allclose(across, np.tan(np.arctan([0.35, 0.2]) + np.arctan(0.25)),
                               rtol=1e-9)
    along = from_heightmap(h, 1.0, 1.0, 0.12).friction_coefficient(np.pi / 2)
    assert float(ortho.friction_coefficient(np.pi / 2)) == pytest.approx(float(along), rel=1e-9)

    rough = machined_surface(48, period=16.0, roughness=0.1, correlation=3.0)
    phi, d = directions(24)
    plain = from_heightmap(rough, 1.0, 1.0, law).limit_load(d)
    dilatant = from_heightmap(rough, 1.0, 1.0, elliptic_cone(0.25, 0.12, 1.0)).limit_load(d)
    assert np.all(dilatant.load >= plain.load * (1 - 1e-9))
    np.testing.assert_array_equal(dilatant.load, from_heightmap(rough, 1.0, 1.0, law,
                                                                "associated").limit_load(d).load)
