"""A grain at rest in a pocket is a block on facets: its break-out force is the facet set's limit
load, force control reaches it in every direction, and displacement control continues past it.
The grain contacts carry any local law of the library; the vertical load Q is a loading input."""

import warnings

import numpy as np
import pytest

from frictionrules import (Coulomb, CylinderOnLayer, EllipticOrthotropic, FacetSet,
                           FrictionRulesError, HardenedLaw, Huber, SlipHardening, SphereOnLayer,
                           TransformedCoulomb, UserLaw, WedgeAsperity)
from frictionrules.configuration.geometry import touching

MU = 0.3
POCKETS = pytest.mark.parametrize("model", [SphereOnLayer(1.0, MU, packing="square"),
                                            SphereOnLayer(1.0, MU, packing="hexagonal"),
                                            CylinderOnLayer(1.0, MU)],
                                  ids=["square", "hexagonal", "groove"])


def pocket_normals(model):
    return touching(model.layer, np.zeros(2)).normals


def exact_breakout(normals, mu, beta, Q=1.0):
    """The break-out force by an independent mechanism search with local Coulomb friction (no
    normal slip), the smallest load factor t over the admissible mechanisms: over one grain k, a
    positive root t of the quadratic |F_t|^2 = mu^2 N^2, F = (t e, -Q), N = -F.n_k >= 0, whose
    slip (along F_t) climbs and separates the grain from the others; over two j, k, V = +-n_j x n_k
    separating it from the others and the 3x3 equilibrium (t e, -Q) = N_j (mu V - n_j) +
    N_k (mu V - n_k) with t, N_j, N_k >= 0."""
    e = np.array([np.cos(beta), np.sin(beta), 0.0])
    B = np.array([0.0, 0.0, -Q])
    best, count = np.inf, 0
    K = len(normals)
    for k, n in enumerate(normals):
        a, b = e - (e @ n) * n, B - (B @ n) * n
        c, c0 = -(e @ n), -(B @ n)
        A2, A1, A0 = a @ a - mu**2 * c * c, 2 * (a @ b - mu**2 * c * c0), b @ b - mu**2 * c0 * c0
        roots = np.roots([A2, A1, A0]) if abs(A2) > 1e-300 else np.array([-A0 / A1])
        for t in np.sort(roots[np.abs(roots.imag) < 1e-12].real):
            F = t * e + B
            if t <= 0 or -(F @ n) < 0:
                continue
            V = F - (F @ n) * n                # climbs, away from the other grains
            if V[2] > 0 and all(V @ normals[m] > 1e-12 for m in range(K) if m != k) and (
                    t < best - 1e-12):
                best, count = t, 1
    for j in range(K):
        for k in range(j + 1, K):
            V = np.cross(normals[j], normals[k])
            if np.linalg.norm(V) < 1e-12:
                continue
            for V in (V / np.linalg.norm(V), -V / np.linalg.norm(V)):
                if not all(V @ normals[m] > 1e-12 for m in range(K) if m not in (j, k)):
                    continue
                aj, ak = mu * V - normals[j], mu * V - normals[k]
                M = np.array([[e[0], -aj[0], -ak[0]], [e[1], -aj[1], -ak[1]], [0.0, -aj[2], -ak[2]]])
                t, Nj, Nk = np.linalg.solve(M, [0.0, 0.0, Q])
                if min(t, Nj, Nk) >= 0 and t < best - 1e-12:
                    best, count = t, 2
    return best, count


@POCKETS
def test_breakout_is_the_exact_root(model):
    """Break-out forces agree with the exact roots (a quadratic, a 3x3 system) to 1e-10."""
    beta = np.linspace(0.0, 2 * np.pi, 48, endpoint=False) + 0.01
    bo = model.breakout_force(beta, Q=1.7)
    normals = pocket_normals(model)
    for b, t, c in zip(beta, bo.peak, bo.count):
        ref, count = exact_breakout(normals, MU, b, 1.7)
        assert t == pytest.approx(ref, rel=1e-10)
        assert c == count


def test_breakout_over_the_single_sphere_is_the_quadratic_root():
    """The one-contact model: the grain leans on one layer sphere, held down the slope by the
    pocket it comes from; along a ray the break-out is the root of the wedge's quadratic (2.2)
    on its climbing part, and no mechanism starts where the ray leaves sideways (jammed)."""
    sph = SphereOnLayer(1.0, MU)
    beta = np.radians([-25.0, -10.0, 0.0, 15.0, 25.0])
    bo = sph.breakout_force(beta, Q=1.3)
    for b, t in zip(beta, bo.peak):
        assert t == pytest.approx(exact_breakout(pocket_normals(sph), MU, b, 1.3)[0], rel=1e-12)
    with pytest.raises(FrictionRulesError, match="jams"):
        sph.breakout_force([np.radians(120.0)])
    with pytest.raises(FrictionRulesError, match="down the slope"):
        sph.force_path(ramp(np.radians(57.0)))


def test_breakout_is_the_facet_set_limit_load():
    model = SphereOnLayer(1.0, MU, packing="hexagonal")
    fs = FacetSet(pocket_normals(model), MU)
    for b in (0.0, 0.4, 1.9):
        load = fs.limit_load(np.array([np.cos(b), np.sin(b)]), 2.0)
        assert model.breakout_force([b], Q=2.0).peak[0] == pytest.approx(load.load, rel=1e-14)


# ---- the defects of force control from a pocket, with their numbers -----------------------------
def ramp(beta, top=3.0, n=31):
    return np.outer(np.linspace(0.0, top, n), [np.cos(beta), np.sin(beta)])


@pytest.mark.parametrize("packing, degrees, expected, over", [
    ("square", 30.0, 1.61114, 2), ("square", 60.0, 1.61114, 2), ("hexagonal", 20.0, 1.04127, 2),
])
def test_force_control_reaches_the_true_limit_point(packing, degrees, expected, over):
    """Square at 30 and 60 deg: no limit point at |T| = 1.54161 (a one-contact limit curve the
    neighbours block) — the grain breaks out over two grains at 1.61114; hexagonal at 20 deg:
    1.04127, not 1.03183."""
    with pytest.warns(DeprecationWarning):
        sph = SphereOnLayer(1.0, MU, 1.0, packing=packing)
    res = sph.force_path(ramp(np.radians(degrees)))
    lp = res.limit_point
    assert np.hypot(*lp.force) == pytest.approx(expected, abs=5e-6)
    assert len(lp.state.contacts) == over
    assert not res.completed and not res.sliding.any()


@pytest.mark.parametrize("degrees", [0.0, 10.0, 20.0])
def test_force_control_square_along_the_ridges_does_not_raise(degrees):
    sph = SphereOnLayer(1.0, MU, packing="square")
    res = sph.force_path(ramp(np.radians(degrees)))
    assert np.hypot(*res.limit_point.force) == pytest.approx(
        sph.breakout_force([np.radians(degrees)]).peak[0], rel=1e-10)


@POCKETS
def test_force_control_reaches_the_breakout_force_in_every_direction(model):
    beta = np.linspace(0.0, 2 * np.pi, 24, endpoint=False) + 0.003
    bo = model.breakout_force(beta, Q=2.0)
    for b, peak, mech in zip(beta, bo.peak, bo.mechanism):
        res = model.force_path(ramp(b, top=2.0 * 3.0), Q=2.0)
        assert np.hypot(*res.limit_point.force) == pytest.approx(peak, rel=1e-10)
        assert res.limit_point.state.contacts == mech


@pytest.mark.parametrize("packing, degrees", [("square", 45.0), ("hexagonal", 0.0),
                                              ("hexagonal", 125.0)])
def test_displacement_control_continues_past_the_limit_point(packing, degrees):
    """Where the grain breaks out over one grain, displacement control along the mechanism's
    slip starts at the break-out force and the force then falls (softening)."""
    sph = SphereOnLayer(1.0, MU, packing=packing)
    b = np.radians(degrees)
    res = sph.force_path(ramp(b))
    V = sph.contact_law(res.limit_point.state).slip_direction(res.limit_point.force, 1.0)
    path = sph.displacement_path(sph.straight_path(np.arctan2(V[1], V[0]), 0.3, 31))
    assert np.allclose(path.force[0], res.limit_point.force, rtol=1e-9, atol=1e-12)
    assert path.contacts[0] == res.limit_point.state.contacts
    assert np.all(np.diff(path.force_magnitude) < 0)


def test_force_control_follows_the_softening_branch_out_of_a_pocket():
    """From the break-out over one grain (square, 45 deg), the decreasing forces of the exact
    displacement path give back its positions by (3.7), (3.13) (first order in the step); an
    increment that does not change the force leaves the grain where it is."""
    sph = SphereOnLayer(1.0, MU, packing="square")
    errs = []
    for n in (41, 81, 161):
        ex = sph.displacement_path(sph.straight_path(np.pi / 4, 0.3, n))
        res = sph.force_path(np.concatenate((ex.force[:1], ex.force[:-1])))
        assert res.completed and res.sliding.all() and res.limit_point.state.contacts == ((0, 0),)
        assert np.all(res.position[1] == 0.0)
        errs.append(np.abs(res.position[1:] - ex.position[:-1]).max())
    assert np.polyfit(np.log([4, 2, 1]), np.log(errs), 1)[0] == pytest.approx(1.0, abs=0.15)


def test_displacement_control_continues_past_a_ridge_limit_point():
    """Over two grains the break-out force lies on the ridge mechanism's limit line
    det(F, mu V - n_j, mu V - n_k) = 0 (V along the ridge), on which the displacement path along
    the ridge starts; the force then falls (softening)."""
    sph = SphereOnLayer(1.0, MU, packing="square")
    res = sph.force_path(ramp(np.radians(25.0)))
    lp = res.limit_point
    assert lp.state.contacts == ((0, -1), (0, 0))
    path = sph.displacement_path(sph.straight_path(0.0, 0.4, 21))
    assert path.contacts[0] == lp.state.contacts
    assert np.all(np.diff(path.force_magnitude) < 0)
    t = touching(sph.layer, np.zeros(2))
    nj, nk = (t.normals[t.ids.index(c)] for c in lp.state.contacts)
    V = np.cross(nj, nk)
    V *= np.sign(V[0]) / np.linalg.norm(V)
    for T in (lp.force, path.force[0]):
        F = np.array([T[0], T[1], -1.0])
        assert np.linalg.det(np.array([F, MU * V - nj, MU * V - nk])) == pytest.approx(0.0, abs=1e-12)


# ---- Q is a loading input -----------------------------------------------------------------------
def test_constructor_load_is_deprecated_and_still_used():
    with pytest.warns(DeprecationWarning, match="Q"):
        old = SphereOnLayer(1.0, MU, 2.0, packing="square")
    with pytest.warns(DeprecationWarning):
        old_kw = CylinderOnLayer(1.0, MU, Q=2.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        new = SphereOnLayer(1.0, MU, packing="square")
        cyl = CylinderOnLayer(1.0, MU)
        assert new.Q == 1.0 and repr(new) == ("SphereOnLayer(diameter=1.0, law=Coulomb(mu=0.3, "
                                              "dilatant=False), packing='square')")
    b = np.radians([0.0, 45.0])
    assert np.allclose(old.breakout_force(b).peak, new.breakout_force(b, Q=2.0).peak, rtol=1e-14)
    assert np.allclose(old.breakout_force(b).peak, 2.0 * new.breakout_force(b).peak, rtol=1e-12)
    path = cyl.straight_path(0.3, 0.4, 11)
    assert np.allclose(old_kw.displacement_path(path).force,
                       cyl.displacement_path(path, Q=2.0).force, rtol=1e-14)
    assert old.Q == 2.0 and "Q=2.0" in repr(old)
    with pytest.warns(DeprecationWarning):
        legacy = SphereOnLayer(1.0, MU, 1.0, "hexagonal")
    assert legacy.packing == "hexagonal" and legacy.Q == 1.0


def test_forces_scale_with_the_load():
    """Everything is homogeneous of degree one in (T, Q)."""
    sph = SphereOnLayer(1.0, MU, packing="hexagonal")
    path = sph.straight_path(0.2, 0.5, 21)
    for method in ("exact", "incremental"):
        one = sph.displacement_path(path, method, Q=1.0)
        three = sph.displacement_path(path, method, Q=3.0)
        assert np.allclose(three.force, 3.0 * one.force, rtol=1e-12)
        assert np.allclose(three.height, one.height, rtol=1e-12)


# ---- the local law is pluggable -----------------------------------------------------------------
def test_law_argument():
    assert SphereOnLayer(1.0, law=Coulomb(MU)) == SphereOnLayer(1.0, MU)
    assert CylinderOnLayer(1.0, MU).law == Coulomb(MU)
    with pytest.raises(FrictionRulesError, match="once"):
        SphereOnLayer(1.0, MU, law=Coulomb(MU))
    with pytest.raises(FrictionRulesError, match="missing"):
        CylinderOnLayer(1.0)
    with pytest.raises(FrictionRulesError, match="internal variables"):
        SphereOnLayer(1.0, law=HardenedLaw(Coulomb(MU), SlipHardening(0.1, 1.0)))
    with pytest.raises(FrictionRulesError, match="external loads"):
        SphereOnLayer(1.0, law=WedgeAsperity(0.3, MU))
    with pytest.raises(FrictionRulesError, match="mu"):
        SphereOnLayer(1.0, law=EllipticOrthotropic(0.2, 0.3)).mu


def test_dilatant_contacts_cannot_slide_along_the_contact_surface():
    sph = SphereOnLayer(1.0, law=Coulomb(MU, dilatant=True), packing="square")
    with pytest.raises(FrictionRulesError, match="normal slip"):
        sph.displacement_path(sph.straight_path(0.5, 0.2, 5))
    with pytest.raises(FrictionRulesError, match="normal slip"):
        sph.force_path(ramp(0.5))
    # at rest the pocket is a facet set with the dilatant local rule (1.6): the associated limit
    # load, above the non-associated one (Radenkovic)
    dil = sph.breakout_force([0.5]).peak[0]
    assert dil >= SphereOnLayer(1.0, MU, packing="square").breakout_force([0.5]).peak[0] - 1e-12


def test_user_law_written_for_coulomb_gives_the_coulomb_results():
    user = UserLaw("sqrt(T1**2 + T2**2) - mu*N", "sqrt(T1**2 + T2**2)", params={"mu": MU})
    a, b = SphereOnLayer(1.0, law=user), SphereOnLayer(1.0, MU)
    path = a.straight_path(0.4, 0.4, 21)
    for method in ("exact", "incremental"):
        assert np.allclose(a.displacement_path(path, method).force,
                           b.displacement_path(path, method).force, atol=1e-10)
    F = ramp(0.4, top=2.0, n=21)
    assert np.allclose(a.force_path(F).limit_point.force, b.force_path(F).limit_point.force,
                       atol=1e-10)


@pytest.mark.parametrize("law", [
    EllipticOrthotropic(0.2, 0.4, 0.5), Huber(0.25, 0.35, 0.2), TransformedCoulomb(0.2, 0.4, -0.3),
    UserLaw("sqrt((T1/mx)**2 + (T2/my)**2) - N", "sqrt((T1/mx)**2 + (T2/my)**2)",
            params={"mx": 0.25, "my": 0.35}),
], ids=["elliptic", "huber", "transformed", "user"])
def test_rate_form_converges_for_every_local_law(law):
    """The rate relations (the law's derivatives from its symbolic form composed with the
    frame's) against the exact path (the law's inverse relation and equilibrium): Heun is of
    order 2 whatever the local law."""
    sph = SphereOnLayer(1.0, law=law)
    errs = []
    for n in (41, 81):
        path = sph.straight_path(0.4, 0.4, n)
        errs.append(np.abs(sph.displacement_path(path, "incremental", "heun").force
                           - sph.displacement_path(path).force).max())
    assert errs[0] < 1e-4 and np.log2(errs[0] / errs[1]) == pytest.approx(2.0, abs=0.15)


def test_isotropic_elliptic_contacts_are_coulomb():
    """EllipticOrthotropic with mu_x = mu_y = mu is Coulomb(mu) in every frame."""
    a = SphereOnLayer(1.0, law=EllipticOrthotropic(MU, MU, 0.7), packing="hexagonal")
    b = SphereOnLayer(1.0, MU, packing="hexagonal")
    path = a.straight_path(-0.3, 0.6, 31)
    for method in ("exact", "incremental"):
        assert np.allclose(a.displacement_path(path, method).force,
                           b.displacement_path(path, method).force, atol=1e-10)
    st_ = a.state_at((0.1, 0.05), 0.3)
    assert np.allclose(a.limit_curve(st_), b.limit_curve(st_), atol=1e-10)


# ---- orthotropic grain contacts, end to end -------------------------------------------------------
ORTHO = EllipticOrthotropic(0.2, 0.4, 0.3)


def test_orthotropic_pocket_end_to_end():
    """Each contact carries EllipticOrthotropic in its own frame (t1 the projection of x): the
    pocket is the facet set with that local law (the same frames), force control reaches its
    limit load in every direction, and where one contact slides the break-out force is on that
    contact's limit curve (its own frame and law) with a slip that separates the grain from the
    other layer grains."""
    from frictionrules import GrainContact
    from frictionrules.configuration._frame import axes_of
    sph = SphereOnLayer(1.0, law=ORTHO, packing="square")
    pocket = touching(sph.layer, np.zeros(2))
    assert np.allclose(FacetSet(pocket.normals, ORTHO).frames(), axes_of(pocket.normals[:, :2], 1.0),
                       atol=1e-14)
    beta = np.linspace(0.0, 2 * np.pi, 16, endpoint=False) + 0.02
    bo = sph.breakout_force(beta, Q=1.5)
    assert np.all(np.isfinite(bo.peak)) and set(bo.count) == {1, 2}
    for b, T, mech in zip(beta, bo.start, bo.mechanism):
        res = sph.force_path(ramp(b, top=6.0, n=21), Q=1.5)
        assert np.allclose(res.limit_point.force, T, rtol=1e-10, atol=1e-12)
        assert res.limit_point.state.contacts == mech
        if len(mech) == 1:
            k = pocket.ids.index(mech[0])
            n = pocket.normals[k]
            a, p = np.arccos(n[2]), np.arctan2(-n[1], -n[0])
            contact = GrainContact(ORTHO, a, p)
            assert abs(contact.limit(T, 1.5)) < 1e-10
            V = contact.slip_direction(T, 1.5)
            assert np.allclose(V, res.limit_point.velocity, atol=1e-8)
            assert all(V @ pocket.normals[m] > 0 for m in range(4) if m != k)
