"""FacetSet and TwoFlankAsperity: general solver against the closed forms (2.9)-(2.17) and
against independent brute-force checks (a dense velocity scan and a linear programme)."""

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from scipy.optimize import linprog

from frictionrules import (FacetSet, FrictionRulesError, TwoFlankAsperity, WedgeAsperity,
                           compare_rules)

FIG5 = dict(alpha1=np.pi / 3, alpha2=5 * np.pi / 6, mu=1.0)


def directions(m):
    phi = -np.pi + 2 * np.pi * (np.arange(m) + 0.37) / m   # avoid exact symmetry lines
    return phi, np.stack((np.cos(phi), np.sin(phi)), axis=-1)


def solver_loads(law, d, Q=1.0):
    return np.array([law.limit_load(di, Q).load for di in d])


# ---- independent brute force 1: dense scan over velocity directions (non-associated) --------
def _plane_basis(n):
    a = np.cross(n, [0.0, 1.0, 0.0] if abs(n[1]) < 0.9 else [1.0, 0.0, 0.0])
    a /= np.linalg.norm(a)
    return a, np.cross(n, a)


def velocity_scan_pieces(normals, mu, samples=20000):
    """Polylines of loads (Q = 1) of every mechanism, parametrized by the velocity.

    One facet j: for every in-plane unit velocity V admissible for the others (V.n_m >= 0),
    equilibrium F = -N (n_j - mu V), F_z = -1 gives the load. Two facets: the velocity along
    their intersection line; the loads fill the segment between the two one-facet loads.
    """
    n = np.asarray(normals, float)
    n = n / np.linalg.norm(n, axis=1, keepdims=True)
    pieces = []
    psi = np.linspace(0, 2 * np.pi, samples)
    for j, nj in enumerate(n):
        a, b = _plane_basis(nj)
        V = np.cos(psi)[:, None] * a + np.sin(psi)[:, None] * b
        ok = np.all(V @ n.T >= -1e-12, axis=1) & (nj[2] - mu * V[:, 2] > 0)
        N = 1.0 / (nj[2] - mu * V[:, 2])
        T = -N[:, None] * (nj[:2] - mu * V[:, :2])
        # contiguous admissible runs
        idx = np.flatnonzero(ok)
        if len(idx):
            runs = np.split(idx, np.flatnonzero(np.diff(idx) > 1) + 1)
            pieces += [T[r] for r in runs if len(r) > 1]
    for j in range(len(n)):
        for k in range(j + 1, len(n)):
            e = np.cross(n[j], n[k])
            if np.linalg.norm(e) < 1e-12:
                continue
            for V in (e / np.linalg.norm(e), -e / np.linalg.norm(e)):
                if np.all(V @ n.T >= -1e-12):
                    ends = [-(m[:2] - mu * V[:2]) / (m[2] - mu * V[2]) for m in (n[j], n[k])]
                    if all(m[2] - mu * V[2] > 0 for m in (n[j], n[k])):
                        s = np.linspace(0, 1, 50)[:, None]
                        pieces.append(ends[0] + s * (ends[1] - ends[0]))
    return pieces


def ray_hits(pieces, d):
    """Smallest t > 0 with t d on one of the polylines (inf if none)."""
    best = np.full(len(d), np.inf)
    for P in pieces:
        A, B = P[:-1], P[1:]
        E = B - A
        den = d[:, None, 0] * E[None, :, 1] - d[:, None, 1] * E[None, :, 0]
        with np.errstate(divide="ignore", invalid="ignore"):
            t = (A[None, :, 0] * E[None, :, 1] - A[None, :, 1] * E[None, :, 0]) / den
            s = (A[None, :, 0] * d[:, None, 1] - A[None, :, 1] * d[:, None, 0]) / den
        ok = (np.abs(den) > 1e-15) & (s >= -1e-9) & (s <= 1 + 1e-9) & (t > 0)
        best = np.minimum(best, np.min(np.where(ok, t, np.inf), axis=1))
    return best


# ---- independent brute force 2: static linear programme (friction cones as pyramids) --------
def lp_static_max(normals, mu, d, Q=1.0, G=256):
    """max t s.t. t D + sum lambda_g r_g = Q z, lambda >= 0, r_g the generators of the
    friction cones (reaction per unit N: n + mu w_g). Inner pyramids: a slight under-estimate."""
    n = np.asarray(normals, float)
    n = n / np.linalg.norm(n, axis=1, keepdims=True)
    g = 2 * np.pi * np.arange(G) / G
    gens = []
    for nj in n:
        a, b = _plane_basis(nj)
        gens.append(nj + mu * (np.cos(g)[:, None] * a + np.sin(g)[:, None] * b))
    R = np.concatenate(gens).T                                   # (3, K*G)
    out = []
    for di in d:
        A = np.concatenate(([[di[0]], [di[1]], [0.0]], R), axis=1)
        c = np.zeros(A.shape[1])
        c[0] = -1.0
        res = linprog(c, A_eq=A, b_eq=[0.0, 0.0, Q], bounds=[(0, None)] * A.shape[1],
                      method="highs")
        out.append(np.inf if res.status == 3 else (res.x[0] if res.status == 0 else np.nan))
    return np.array(out)


# ---- closed forms -----------------------------------------------------------------------------
@pytest.mark.parametrize("mu", [1.0, 0.5, 0.3])
def test_two_flank_closed_forms_eq_2_9_to_2_13_all_directions(mu):
    law = TwoFlankAsperity(np.pi / 3, 5 * np.pi / 6, mu)
    phi, d = directions(720)
    closed, mech = law.closed_form_load(d)
    general = law.limit_curve(n=720)       # a second, vectorized call of the solver
    sol = solver_loads(law, d)
    assert np.array_equal(np.isfinite(closed), np.isfinite(sol))
    fin = np.isfinite(closed)
    np.testing.assert_allclose(sol[fin], closed[fin], rtol=1e-10)
    # mechanism labels: 1 -> facet 0, 2 -> facet 1, 3 -> both
    labels = {1: (0,), 2: (1,), 3: (0, 1)}
    for i in np.flatnonzero(fin):
        assert law.limit_load(d[i]).mechanism == labels[int(mech[i])]
    assert np.all(general.load[np.isfinite(general.load)] > 0)


@pytest.mark.parametrize("mu", [0.5, 0.3])
def test_two_flank_associated_closed_form_corrected_2_16_2_17(mu):
    law = TwoFlankAsperity(np.pi / 3, 5 * np.pi / 6, mu, local="associated")
    phi, d = directions(720)
    closed, mech = law.closed_form_load(d)
    sol = solver_loads(law, d)
    assert np.array_equal(np.isfinite(closed), np.isfinite(sol))
    fin = np.isfinite(closed)
    np.testing.assert_allclose(sol[fin], closed[fin], rtol=1e-10)
    assert set(np.unique(mech)) == {1, 2, 3}


def test_pair_range_eq_2_13():
    law = TwoFlankAsperity(**FIG5)
    lo, hi = law.pair_range()
    assert lo == pytest.approx(-np.sin(5 * np.pi / 6)) and hi == pytest.approx(np.sin(np.pi / 3))
    # just inside / outside the range at Ty > 0 and Ty < 0
    for sy in (1.0, -1.0):
        for ratio, want in ((hi - 1e-6, (0, 1)), (hi + 1e-6, (0,)), (lo + 1e-6, (0, 1)),
                            (lo - 1e-6, (1,))):
            assert law.limit_load([ratio, sy]).mechanism == want


def test_associated_degenerate_at_delta_plus_rho_half_pi():
    law = TwoFlankAsperity(**FIG5, local="associated")   # delta = rho = pi/4
    with pytest.raises(FrictionRulesError, match="delta \\+ rho < pi/2"):
        law.pair_range()
    # the friction cones add up to a half-space: the only limit is the line Tx = Q tan(105°)
    r = law.limit_load([-1.0, 0.0])
    assert r.load == pytest.approx(-np.tan(np.deg2rad(105.0)))
    assert np.isinf(law.limit_load([1.0, 0.0]).load)


# ---- brute force ------------------------------------------------------------------------------
@pytest.mark.parametrize("params", [FIG5, dict(alpha1=0.3, alpha2=2.6, mu=0.4),
                                    dict(alpha1=1.2, alpha2=1.9, mu=0.2)])
def test_two_flank_against_velocity_scan(params):
    law = TwoFlankAsperity(**params)
    phi, d = directions(360)
    brute = ray_hits(velocity_scan_pieces(law.normals(), law.mu), d)
    sol = solver_loads(law, d)
    closed = law.closed_form_load(d)[0]
    fin = np.isfinite(sol)
    assert np.array_equal(fin, np.isfinite(brute))
    np.testing.assert_allclose(brute[fin], sol[fin], rtol=1e-5)
    np.testing.assert_allclose(closed[fin], sol[fin], rtol=1e-10)


def random_normals(rng, k, max_slope=1.0):
    p = rng.uniform(-max_slope, max_slope, size=(k, 2))
    return np.concatenate((-p, np.ones((k, 1))), axis=1)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_random_facets_against_velocity_scan(seed):
    rng = np.random.default_rng(seed)
    normals = random_normals(rng, 5)
    law = FacetSet(normals, 0.4)
    phi, d = directions(180)
    brute = ray_hits(velocity_scan_pieces(normals, 0.4), d)
    sol = solver_loads(law, d)
    fin = np.isfinite(sol)
    assert np.array_equal(fin, np.isfinite(brute))
    np.testing.assert_allclose(brute[fin], sol[fin], rtol=1e-5)


@pytest.mark.parametrize("normals,mu", [
    (TwoFlankAsperity(np.pi / 3, 5 * np.pi / 6, 0.5).normals(), 0.5),
    (TwoFlankAsperity(0.3, 2.6, 0.4).normals(), 0.4),
    (random_normals(np.random.default_rng(3), 5, 0.6), 0.5),
])
def test_associated_equals_static_lp(normals, mu):
    """Associated local rule: the mechanism load is the static maximum (limit analysis), and the
    non-associated one never exceeds it (Radenkovic)."""
    phi, d = directions(48)
    lp = lp_static_max(normals, mu, d)
    assoc = solver_loads(FacetSet(normals, mu, "associated"), d)
    nonassoc = solver_loads(FacetSet(normals, mu), d)
    assert np.array_equal(np.isfinite(lp), np.isfinite(assoc))
    fin = np.isfinite(lp)
    np.testing.assert_allclose(lp[fin], assoc[fin], rtol=2e-3)
    assert np.all(lp[fin] <= assoc[fin] * (1 + 1e-9))        # inner pyramids: a lower bound
    assert np.all(nonassoc <= assoc * (1 + 1e-9))


# ---- concavity (Fig. 5) and convexity (Fig. 7) ------------------------------------------------
def test_fig5_concave_corners():
    law = TwoFlankAsperity(**FIG5)
    curve = law.limit_curve(n=1440)
    corners = curve.concave_corners
    assert len(corners) == len(curve.corners) == 4
    pos = np.array([c.T for c in corners])
    s3 = np.sqrt(3.0)
    # ends of the line (2.12): N_1 = 0 (Tx = -Q tan(pi - alpha2), |Ty| = mu Q/|cos alpha2|)
    # and N_2 = 0 (Tx = Q tan(alpha1), |Ty| = mu Q/cos(alpha1))
    for e in [(-1 / s3, -2 / s3), (-1 / s3, 2 / s3), (s3, -2.0), (s3, 2.0)]:
        assert np.min(np.hypot(*(pos - e).T)) < 1e-7
    a1, a2, mu = FIG5["alpha1"], FIG5["alpha2"], FIG5["mu"]
    for c in corners:
        # independent: the angle between the outward normals of the wedge cone (2.2) of the
        # flank and of the line (2.12); concave, so interior = pi + that angle
        flank = WedgeAsperity(a2 if c.T[0] < 0 else a1, mu)
        g = flank.limit_gradient(c.T, 1.0)[:2]
        line = np.array([mu * (np.cos(a1) + np.cos(a2)), np.sign(c.T[1]) * np.sin(a2 - a1)])
        want = np.pi + np.arccos(g @ line / np.linalg.norm(g) / np.linalg.norm(line))
        assert c.interior == pytest.approx(want, abs=1e-6)
    assert sorted(np.round(np.rad2deg([c.interior for c in corners]), 2)) == [
        200.79, 200.79, 226.67, 226.67]


@pytest.mark.parametrize("mu", [0.5, 0.3])
def test_associated_curve_is_convex(mu):
    law = TwoFlankAsperity(np.pi / 3, 5 * np.pi / 6, mu, local="associated")
    curve = law.limit_curve(n=2000)
    # the pair plane is tangent to both cones: smooth (C1) joins, no corner at all
    assert all(abs(c.turning) < 1e-6 for c in curve.corners)
    P = curve.T[np.isfinite(curve.load)]
    e1, e2 = np.roll(P, -1, 0) - P, P - np.roll(P, 1, 0)
    cross = e2[:, 0] * e1[:, 1] - e2[:, 1] * e1[:, 0]
    assert np.all(cross[1:-1] >= -1e-12)
    nonassoc = TwoFlankAsperity(np.pi / 3, 5 * np.pi / 6, mu).limit_curve(n=2000)
    assert nonassoc.concave_corners
    fin = np.isfinite(nonassoc.load)
    assert np.all(nonassoc.load[fin] <= curve.load[fin] * (1 + 1e-12))


def test_global_rule_is_non_associated_fig5():
    curve = TwoFlankAsperity(**FIG5).limit_curve(n=720)
    fin = np.isfinite(curve.load)
    pair = fin & (curve.facets[:, 1] >= 0)
    # along the line (2.12) the slip is +-y while the normal of the line is not (2.15)
    np.testing.assert_allclose(np.abs(curve.velocity[pair][:, 1]), 1.0)
    assert np.all(curve.tangential_rule_angle[pair] > 0.1)
    assoc = TwoFlankAsperity(np.pi / 3, 5 * np.pi / 6, 0.5, "associated").limit_curve(n=720)
    np.testing.assert_allclose(assoc.rule_angle[np.isfinite(assoc.load)], 0.0, atol=1e-7)


# ---- one facet is the wedge -------------------------------------------------------------------
@pytest.mark.parametrize("alpha,mu", [(0.3, 0.5), (np.pi - 0.4, 0.8), (0.5, 2.0)])
@pytest.mark.parametrize("local", ["non-associated", "associated"])
def test_one_facet_is_wedge_eq_2_2(alpha, mu, local):
    wedge = WedgeAsperity(alpha, mu, local)
    c = np.cos(alpha)
    facet = FacetSet([np.sign(c) * np.array([-np.sin(alpha), 0.0, c])], mu, local)
    phi, d = directions(90)
    for di in d:
        r = facet.limit_load(di, 2.0)
        if np.isfinite(r.load):
            assert float(wedge.limit(r.T, 2.0)) == pytest.approx(0.0, abs=1e-9)
            np.testing.assert_allclose(facet.slip_direction(r.T, 2.0), wedge.slip_direction(r.T, 2.0),
                                       atol=1e-9)
            np.testing.assert_allclose(r.velocity, wedge.slip_direction(r.T, 2.0), atol=1e-9)
            assert r.normal_forces[0] == pytest.approx(float(wedge.normal_force(r.T, 2.0)))
    theta = np.linspace(-3.0, 3.0, 25)
    np.testing.assert_allclose(facet.friction_coefficient(theta), wedge.friction_coefficient(theta),
                               rtol=1e-6 if local == "associated" else 1e-12)
    T = np.array([[0.1, 0.2], [0.5, -0.1], [-0.3, 0.4]])
    assert np.array_equal(np.sign(facet.limit(T, 1.0)), np.sign(wedge.limit(T, 1.0)))


# ---- protocol ---------------------------------------------------------------------------------
def test_protocol_on_the_limit_curve():
    law = TwoFlankAsperity(np.pi / 3, 5 * np.pi / 6, 0.5)
    curve = law.limit_curve(n=90)
    fin = np.isfinite(curve.load)
    T = curve.T[fin]
    np.testing.assert_allclose(law.limit(T, 1.0), 0.0, atol=1e-12)
    assert np.all(law.limit(0.5 * T, 1.0) < 0) and np.all(law.limit(1.5 * T, 1.0) > 0)
    np.testing.assert_allclose(law.limit(2 * T, 2.0), 0.0, atol=1e-12)  # degree one
    np.testing.assert_allclose(law.slip_direction(T, 1.0), curve.velocity[fin], atol=1e-12)
    np.testing.assert_allclose(law.normal_direction(T, 1.0), curve.normal[fin], atol=1e-12)
    cmp = compare_rules(law, T, 1.0)
    np.testing.assert_allclose(cmp.angle, curve.rule_angle[fin], atol=1e-9)
    # inverse: the force for a slip slides that way and lies on the limit curve
    theta = np.linspace(-np.pi, np.pi, 37)
    mu = law.friction_coefficient(theta)
    ok = np.isfinite(mu)
    F = law.force_for_slip(np.stack((np.cos(theta[ok]), np.sin(theta[ok])), -1), 1.0)
    np.testing.assert_allclose(law.limit(F, 1.0), 0.0, atol=1e-9)
    v = law.slip_direction(F, 1.0)
    np.testing.assert_allclose(np.arctan2(v[:, 1], v[:, 0]) % (2 * np.pi), theta[ok] % (2 * np.pi),
                               atol=1e-9)
    D = law.dissipation(np.stack((np.cos(theta[ok]), np.sin(theta[ok])), -1), 1.0)
    assert np.all(D > 0)
    assert "symbolic" not in law.capabilities
    with pytest.raises(FrictionRulesError, match="lacks the capability 'symbolic'"):
        law.symbolic()


def test_potential_eq_2_14_2_15():
    law = TwoFlankAsperity(**FIG5)
    a1 = np.pi / 3
    # flank 1 (2.14)
    r = law.limit_load([1.0, 0.8])
    assert r.mechanism == (0,)
    Tx, Ty = r.T
    assert float(law.potential(r.T, 1.0)) == pytest.approx(np.hypot(Tx * np.cos(a1) - np.sin(a1), Ty))
    # both flanks (2.15): g = Ty, slip +y
    r = law.limit_load([0.1, 1.0])
    assert r.mechanism == (0, 1)
    assert float(law.potential(r.T, 1.0)) == pytest.approx(r.T[1])
    np.testing.assert_allclose(law.potential_gradient(r.T, 1.0), [0.0, 1.0, 0.0], atol=1e-12)


def test_limit_load_result_fields_and_locked():
    law = TwoFlankAsperity(**FIG5)
    r = law.limit_load([0.2, 1.0], Q=2.0)
    assert r.mechanism == (0, 1) and np.all(r.normal_forces > 0)
    F = np.array([*r.T, -2.0])
    R = sum(N * (n - law.mu * r.velocity) for N, n in zip(r.normal_forces, law.normals()))
    np.testing.assert_allclose(F + R, 0.0, atol=1e-12)
    locked = law.limit_load([1.0, 0.0])
    assert locked.mechanism is None and np.isinf(locked.load) and np.all(locked.velocity == 0)
    assert np.all(np.isinf(law.limit(np.array([[1.0, 0.0]]), 1.0)))


def test_bad_input():
    with pytest.raises(FrictionRulesError, match="nz > 0"):
        FacetSet([[1.0, 0.0, 0.0]], 0.5)
    with pytest.raises(FrictionRulesError, match="mu"):
        FacetSet([[0.0, 0.0, 1.0]], 0.0)
    with pytest.raises(FrictionRulesError, match="local"):
        FacetSet([[0.0, 0.0, 1.0]], 0.5, "dilatant")
    with pytest.raises(FrictionRulesError, match="alpha2"):
        TwoFlankAsperity(0.5, 1.0, 0.5)
    with pytest.raises(FrictionRulesError, match="direction"):
        FacetSet([[0.0, 0.0, 1.0]], 0.5).limit_load([0.0, 0.0])


# ---- invariants -------------------------------------------------------------------------------
@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 10**6), k=st.integers(1, 6), mu=st.floats(0.1, 1.0),
       local=st.sampled_from(["non-associated", "associated"]), phi=st.floats(-np.pi, np.pi),
       rot=st.floats(-np.pi, np.pi))
def test_mechanism_invariants(seed, k, mu, local, phi, rot):
    """Equilibrium, N >= 0, admissibility, Radenkovic's bound, and frame rotation."""
    normals = random_normals(np.random.default_rng(seed), k, 0.8)
    try:
        law = FacetSet(normals, mu, local)
    except FrictionRulesError:
        assume(False)                                  # the block slides under Q alone
    d = np.array([np.cos(phi), np.sin(phi)])
    r = law.limit_load(d, 1.0)
    if r.mechanism is None:
        assert np.isinf(r.load)
    else:
        n = law.normal_array
        V = r.velocity
        # the static limit (no quasi-static sliding) carries the associated mechanism
        thr = np.sin(np.arctan(mu)) if local == "associated" or not r.quasi_static else 0.0
        assert np.all(V @ n.T >= thr - 1e-8)
        np.testing.assert_allclose(V @ n[list(r.mechanism)].T, thr, atol=1e-8)
        assert np.all(r.normal_forces >= 0)
        R = 0.0
        for j in r.mechanism:
            w = V - (V @ n[j]) * n[j]
            R = R + r.normal_forces[j] * (n[j] - mu * w / np.linalg.norm(w))
        np.testing.assert_allclose(np.array([*r.T, -1.0]) + R, 0.0, atol=1e-8)
    if local == "non-associated":
        assoc = FacetSet(normals, mu, "associated").limit_load(d, 1.0).load
        assert r.load <= assoc * (1 + 1e-9)
    c, s = np.cos(rot), np.sin(rot)
    Rz = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])
    turned = FacetSet(law.normal_array @ Rz.T, mu, local).limit_load(Rz[:2, :2] @ d, 1.0)
    if np.isfinite(r.load):
        assert turned.load == pytest.approx(r.load, rel=1e-8)
    else:
        assert np.isinf(turned.load) or turned.load > 1e6


def test_interior_facets_never_slide_and_indices_are_the_users():
    """A facet whose gradient lies inside the hull of the others separates in every mechanism:
    adding it changes nothing, and mechanisms keep the user's facet numbering."""
    rng = np.random.default_rng(5)
    outer = random_normals(rng, 5, 0.7)
    p_mean = -(outer[:, :2] / outer[:, 2:]).mean(axis=0)
    inner = np.array([[p_mean[0], p_mean[1], 1.0]])
    base = FacetSet(outer, 0.4)
    more = FacetSet(np.concatenate((inner, outer)), 0.4)        # facet 0 is the interior one
    phi, d = directions(72)
    for di in d:
        a, b = base.limit_load(di), more.limit_load(di)
        assert b.load == pytest.approx(a.load, rel=1e-12) or (np.isinf(a.load) and np.isinf(b.load))
        if a.mechanism is not None:
            assert b.mechanism == tuple(i + 1 for i in a.mechanism)
            assert b.normal_forces[0] == 0.0
    np.testing.assert_allclose(more.friction_coefficient(phi), base.friction_coefficient(phi))


@settings(max_examples=30, deadline=None)
@given(a1=st.floats(0.05, 1.5), a2=st.floats(1.65, 3.1), mu=st.floats(0.05, 2.0),
       local=st.sampled_from(["non-associated", "associated"]))
def test_two_flank_closed_forms_hypothesis(a1, a2, mu, local):
    """Closed forms (2.9)-(2.13) / corrected (2.16)-(2.17) = general solver, any groove."""
    law = TwoFlankAsperity(a1, a2, mu, local)
    if local == "associated" and law._assoc_pair[3] < 1e-3:
        return                                           # no associated two-flank mechanism
    phi, d = directions(64)
    closed = law.closed_form_load(d)[0]
    sol = law.limit_curve(n=64)                          # directions differ: use limit_load
    general = solver_loads(law, d)
    fin = np.isfinite(closed)
    assert np.array_equal(fin, np.isfinite(general))
    np.testing.assert_allclose(general[fin], closed[fin], rtol=1e-8)
    assert len(sol.load) == 64


def test_facets_must_carry_the_vertical_load():
    """A single facet steeper than the friction angle, or a tilted set, is rejected; the
    two-flank groove always carries Q (its bisector points up)."""
    with pytest.raises(FrictionRulesError, match="cannot carry the vertical load"):
        FacetSet([[-np.sin(0.6), 0.0, np.cos(0.6)]], 0.5)        # 34° > rho = 26.6°
    FacetSet([[-np.sin(0.4), 0.0, np.cos(0.4)]], 0.5)              # 23° < rho
    with pytest.raises(FrictionRulesError, match="cannot carry"):
        FacetSet([[-0.3, 0.4, 1.0], [0.7, 0.3, 1.0]], 0.25)        # both rise towards +y
    TwoFlankAsperity(1.5, 1.65, 0.05)                              # deep narrow groove


def test_static_maximum_bounds_the_non_associated_load():
    """A marginal groove descending towards +y: pushed along +x, no non-associated sliding
    equilibrium exists at any load, but beyond the static maximum (LP) no equilibrium exists
    at all; the limit is that maximum, flagged as not quasi-static."""
    normals = random_normals(np.random.default_rng(2), 2, 0.8)
    mu = 0.40625
    d = np.array([[1.0, 0.0]])
    assert np.isinf(ray_hits(velocity_scan_pieces(normals, mu), d)[0])   # no mechanism
    lp = lp_static_max(normals, mu, d)[0]
    r = FacetSet(normals, mu).limit_load(d[0])
    assert not r.quasi_static and r.load == pytest.approx(lp, abs=1e-4)   # inner pyramids
    assert r.load == pytest.approx(FacetSet(normals, mu, "associated").limit_load(d[0]).load)
    np.testing.assert_allclose(FacetSet(normals, mu).slip_direction(r.T, 1.0), r.velocity,
                               atol=1e-9)
    assert TwoFlankAsperity(**FIG5).limit_curve(n=360).quasi_static.all()
