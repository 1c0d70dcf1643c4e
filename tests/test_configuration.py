"""Configuration softening (§3): cylinders and spheres sliding over layers, Figs. 8–9."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from frictionrules import CylinderOnLayer, FrictionRulesError, GrainState, SphereOnLayer

MU = 0.3
RHO = np.arctan(MU)


def slope(hs, errs):
    return np.polyfit(np.log(hs), np.log(errs), 1)[0]


# ---- cylinder: Fig. 8, (3.6)–(3.10) -------------------------------------------------------------
def test_cylinder_rest_and_top_exact():
    """At rest in the groove alpha = pi/6 and T = Q tan(pi/6 + rho); on the top alpha = 0 and
    T = mu Q (the flat Coulomb contact); past the top T = Q tan(rho + alpha), alpha < 0."""
    cyl = CylinderOnLayer(2.0, MU)
    res = cyl.displacement_path(cyl.straight_path(0.0, 2.0, 9), Q=3.0)
    assert res.alpha[0] == pytest.approx(np.pi / 6)
    assert res.force[0] == pytest.approx([3.0 * np.tan(np.pi / 6 + RHO), 0.0])
    assert res.alpha[4] == pytest.approx(0.0, abs=1e-12)          # u = d/2: on the top
    assert res.force[4] == pytest.approx([MU * 3.0, 0.0])
    assert res.normal[4, 0] == pytest.approx(3.0)
    assert res.alpha[5] < 0
    assert res.force[5, 0] == pytest.approx(3.0 * np.tan(RHO + res.alpha[5]))
    assert res.height[4] == pytest.approx(2.0)
    assert res.height[0] == pytest.approx(np.sqrt(3.0))


def test_cylinder_softening_is_monotone_up_to_the_next_groove():
    cyl = CylinderOnLayer(1.0, MU)
    res = cyl.displacement_path(cyl.straight_path(0.0, 0.999, 200))
    assert np.all(np.diff(res.force[:, 0]) < 0)
    assert res.force[-1, 0] == pytest.approx(np.tan(RHO - np.pi / 6), abs=2e-3)


def test_cylinder_contact_switches_at_the_next_groove():
    cyl = CylinderOnLayer(1.0, MU)
    res = cyl.displacement_path(cyl.straight_path(0.0, 2.0, 401))
    assert res.events() == [(200, "open", (0, 0)), (200, "close", (1, 0)),
                            (400, "open", (1, 0)), (400, "close", (2, 0))]
    assert res.force[200, 0] == pytest.approx(res.force[0, 0])        # periodic: back in a groove


@pytest.mark.parametrize("scheme, order", [("euler", 1.0), ("heun", 2.0)])
def test_cylinder_incremental_converges_to_exact(scheme, order):
    """T(u) from the rate form (3.6)–(3.10) with consistency (3.5) -> exact geometry; observed
    order 1 (explicit Euler, the paper's incremental scheme) and 2 (Heun)."""
    cyl = CylinderOnLayer(1.0, MU)
    hs, errs = [], []
    for n in (21, 41, 81, 161):
        path = cyl.straight_path(0.0, 0.5, n)                          # rest -> top
        inc = cyl.displacement_path(path, "incremental", scheme)
        ex = cyl.displacement_path(path)
        hs.append(0.5 / (n - 1))
        errs.append(np.abs(inc.force - ex.force).max())
        assert inc.force[0] == pytest.approx(ex.force[0], abs=1e-12)   # rest: exact
    assert slope(hs, errs) == pytest.approx(order, abs=0.15)
    assert inc.force[-1, 0] == pytest.approx(MU, abs=0.01 if scheme == "euler" else 1e-4)  # top


def test_cylinder_oblique_path_limit_curve_eq_2_2():
    """Sliding obliquely to the axes: the exact force lies on the limit curve (2.2) of the current
    alpha and its slip (2.4) is along the path."""
    cyl = CylinderOnLayer(1.0, MU)
    th = 0.6
    res = cyl.displacement_path(cyl.straight_path(th, 0.5, 11), Q=2.0)
    for i in range(10):
        st_ = cyl.state_at(res.position[i], th)
        assert abs(cyl.limit(res.force[i], st_, Q=2.0)) < 1e-9
        Tx, Ty = res.force[i]
        a = res.alpha[i]
        assert (Tx * np.cos(a) - 2.0 * np.sin(a)) * np.cos(a) / Ty == pytest.approx(1 / np.tan(th))


def test_cylinder_groove_along_axis_two_contacts():
    """Pushed along its axis in the groove it slides on both neighbours: T = mu Q / cos(pi/6)."""
    cyl = CylinderOnLayer(1.0, MU)
    res = cyl.displacement_path(cyl.straight_path(np.pi / 2, 1.0, 5))
    assert all(len(c) == 2 for c in res.contacts)
    assert res.force[0] == pytest.approx([0.0, MU / np.cos(np.pi / 6)], abs=1e-12)
    assert res.normal[0, 0] == pytest.approx(res.normal[0, 1])
    with pytest.raises(FrictionRulesError, match="two contacts"):
        cyl.displacement_path(cyl.straight_path(np.pi / 2, 1.0, 5), "incremental")


# ---- sphere: Fig. 9, (3.11)–(3.13) --------------------------------------------------------------
@pytest.mark.parametrize("direction", [0.0, 0.4, -0.9, 1.3, 2.0])
def test_sphere_incremental_matches_exact_equilibrium(direction):
    """Straight trajectories in several directions: the rate form ((3.3), re-derived (3.12),
    (3.5)) matches the equilibrium along the exact trajectory (centre on the contact sphere)."""
    sph = SphereOnLayer(1.0, MU)
    errs = []
    for n in (51, 101, 201):
        path = sph.straight_path(direction, 0.5, n)
        ex = sph.displacement_path(path)
        inc = sph.displacement_path(path, "incremental")
        heun = sph.displacement_path(path, "incremental", "heun")
        errs.append(np.abs(inc.force - ex.force).max())
        assert np.abs(heun.force - ex.force).max() < 1e-4
        assert np.abs(heun.normal - ex.normal).max() < 1e-4
        assert np.abs(heun.height - ex.height).max() < 1e-4
        assert np.abs(np.cos(heun.psi - ex.psi) - 1).max() < 1e-6
    assert errs[-1] < 0.01
    assert slope([1, 0.5, 0.25], errs) == pytest.approx(1.0, abs=0.1)


def test_sphere_limit_curve_translates_shrinks_and_rotates():
    """Fig. 9: off the top the limit curve rotates with psi and shrinks/grows with alpha."""
    sph = SphereOnLayer(1.0, MU)
    res = sph.displacement_path(sph.straight_path(np.pi / 6, 1.0, 101))
    assert res.psi[-1] == pytest.approx(-2 * np.pi / 3, abs=1e-6)
    assert res.alpha.min() < 0.6 * res.alpha[0]
    for i in (0, 50, 100):
        st_ = GrainState(res.position[i], res.height[i], res.contacts[i], (res.alpha[i],), (res.psi[i],))
        assert abs(sph.limit(res.force[i], st_)) < 1e-9
        curve = sph.limit_curve(st_)
        assert np.abs(sph.limit(curve, st_)).max() < 1e-9


@settings(max_examples=40, deadline=None)
@given(th=st.floats(-np.pi, np.pi), packing=st.sampled_from(["square", "hexagonal", "single"]),
       m=st.floats(0.05, 0.5))
def test_power_balance_and_compression(th, packing, m):
    """Exact path: every N_k >= 0 and the power of the loads equals the friction dissipation,
    T.V_h - Q V_z = mu sum N_k |V| >= 0 ((1.7) at each contact)."""
    sph = SphereOnLayer(1.0, m, packing=packing)
    res = sph.displacement_path(sph.straight_path(th, 0.3, 61))
    assert np.all(res.normal >= 0)
    du = np.diff(res.position, axis=0)
    dz = np.diff(res.height)
    mid = lambda a: 0.5 * (a[1:] + a[:-1])  # noqa: E731  (trapezoidal rule on each step)
    work = np.einsum("ni,ni->n", mid(res.force), du) - 1.0 * dz
    dist = np.sqrt((du**2).sum(1) + dz**2)
    assert np.allclose(work, m * mid(res.normal).sum(1) * dist, rtol=1e-2, atol=1e-6)


# ---- force control: (3.7), (3.13) ---------------------------------------------------------------
def test_force_control_finds_the_limit_point_cylinder():
    cyl = CylinderOnLayer(1.0, MU)
    F = np.stack((np.linspace(0.0, 4.0, 41), np.zeros(41)), axis=-1)
    res = cyl.force_path(F, Q=2.0)
    lp = res.limit_point
    assert not res.completed
    assert lp.force[0] == pytest.approx(2.0 * np.tan(np.pi / 6 + RHO), rel=1e-10)
    assert lp.index == 21 and 0 < lp.fraction < 1
    assert not res.sliding.any()
    assert np.all(res.position == 0.0)


def test_force_control_limit_point_sphere_any_direction():
    """The limit point lies on the climbing branch (T1 > 0) of the limit curve (2.2) of the
    contact that slides."""
    sph = SphereOnLayer(1.0, MU, packing="hexagonal")
    for beta in (0.0, 0.2, -0.25):
        F = np.outer(np.linspace(0, 3, 31), [np.cos(beta), np.sin(beta)])
        res = sph.force_path(F)
        st_ = res.limit_point.state
        assert len(st_.contacts) == 1
        assert abs(sph.limit(res.limit_point.force, st_)) < 1e-9
        assert not res.completed
    # pushed at 29 deg the grain rides the ridge between two layer spheres: the limit point is
    # the pocket's break-out force there, reached with both contacts on their limit curves
    res = sph.force_path(np.outer(np.linspace(0, 3, 31), [np.cos(0.5), np.sin(0.5)]))
    st_ = res.limit_point.state
    assert len(st_.contacts) == 2
    assert np.hypot(*res.limit_point.force) == pytest.approx(sph.breakout_force([0.5]).peak[0],
                                                             rel=1e-10)


def test_force_control_softening_branch_follows_the_exact_path():
    """Prescribing the decreasing forces of the exact displacement path, (3.7)/(3.13) give back
    the displacements (first order in the force step)."""
    for model, th in ((CylinderOnLayer(1.0, MU), 0.0), (SphereOnLayer(1.0, MU), 0.5)):
        errs = []
        for n in (101, 201, 401):
            ex = model.displacement_path(model.straight_path(th, 0.45, n))
            res = model.force_path(ex.force[:-1], model.rest_state(th))
            assert res.completed and res.sliding.all() and res.limit_point.index == 0
            errs.append(np.abs(res.position - ex.position[:-1]).max())
        assert slope([4, 2, 1], errs) == pytest.approx(1.0, abs=0.15)


def test_force_control_cannot_increase_after_the_limit_point():
    cyl = CylinderOnLayer(1.0, MU)
    T0 = np.tan(np.pi / 6 + RHO)
    res = cyl.force_path([[T0, 0.0], [T0 - 0.1, 0.0], [T0 - 0.05, 0.0]], cyl.rest_state())
    assert not res.completed and len(res.force) == 2 and res.sliding.all()


# ---- pockets: beyond the paper ------------------------------------------------------------------
def test_square_pocket_peak_forces():
    sph = SphereOnLayer(1.0, MU, packing="square")
    pk = sph.peak_force([0.0, np.pi / 4, np.pi / 2, 3 * np.pi / 4])
    assert list(pk.count) == [2, 1, 2, 1]                     # ridge between two / over one
    assert pk.peak[1] == pytest.approx(np.tan(np.pi / 4 + RHO))
    assert pk.peak[0] == pytest.approx(pk.peak[2])
    assert pk.peak[0] < pk.peak[1]
    assert pk.start[0, 1] == pytest.approx(0.0, abs=1e-12)


def test_hexagonal_pocket_peak_forces_and_symmetry():
    sph = SphereOnLayer(1.0, MU, packing="hexagonal")
    th = np.deg2rad([0.0, 120.0, 180.0, 60.0, 20.0, 140.0])
    pk = sph.peak_force(th)
    assert list(pk.count[:4]) == [1, 1, 2, 2]
    assert pk.peak[0] == pytest.approx(np.tan(np.arcsin(1 / np.sqrt(3)) + RHO))
    assert pk.peak[0] == pytest.approx(pk.peak[1])
    assert pk.peak[2] == pytest.approx(pk.peak[3])
    assert pk.peak[4] == pytest.approx(pk.peak[5])              # 120-degree symmetry


def test_ridge_two_contacts_equilibrium():
    """Square pocket pushed along x: it rides the ridge between two spheres with equal N."""
    sph = SphereOnLayer(1.0, MU, packing="square")
    res = sph.displacement_path(sph.straight_path(0.0, 0.5, 11))
    assert all(len(c) == 2 for c in res.contacts)
    assert np.allclose(res.normal[:, 0], res.normal[:, 1])
    assert np.allclose(res.force[:, 1], 0.0, atol=1e-12)


# ---- input checks -------------------------------------------------------------------------------
@pytest.mark.parametrize("make, match", [
    (lambda: SphereOnLayer(1.0, 0.3, packing="cubic"), "packing"),
    (lambda: CylinderOnLayer(-1.0, 0.3), "diameter"),
    (lambda: CylinderOnLayer(1.0, -0.3), "mu"),
    (lambda: SphereOnLayer(1.0, 0.3).breakout_force([0.0], Q=0.0), "Q"),
    (lambda: CylinderOnLayer(1.0, 0.3).displacement_path([[0, 0], [0.1, 0]], Q=-1.0), "Q"),
])
def test_bad_parameters(make, match):
    with pytest.raises(FrictionRulesError, match=match):
        make()


def test_bad_paths():
    sph = SphereOnLayer(1.0, MU)
    with pytest.raises(FrictionRulesError, match="zero-length"):
        sph.displacement_path([[0, 0], [0, 0], [0.1, 0]])
    with pytest.raises(FrictionRulesError, match="shape"):
        sph.displacement_path([[0, 0]])
    with pytest.raises(FrictionRulesError, match="off the layer"):
        sph.displacement_path([[0, 0], [3.0, 0]])
    with pytest.raises(FrictionRulesError, match="method"):
        sph.displacement_path([[0, 0], [0.1, 0]], method="rk4")
    with pytest.raises(FrictionRulesError, match="locks"):
        SphereOnLayer(1.0, 1.5, packing="square").displacement_path([[0, 0], [0.1, 0.1]])
    with pytest.raises(FrictionRulesError, match="mu > 0"):
        SphereOnLayer(1.0, 0.0).displacement_path([[0, 0], [0.1, 0]], "incremental")
    with pytest.raises(FrictionRulesError, match="outside the limit"):
        CylinderOnLayer(1.0, MU).force_path([[5.0, 0.0], [6.0, 0.0]])


def test_contact_law_is_the_core_wedge():
    """A contact is the local law in the contact's frame: for local Coulomb friction the core
    WedgeAsperity (2.2) of the same inclination (``pi + alpha`` past the top, where the plane
    falls towards +x), and Coulomb on the top."""
    from frictionrules import Coulomb, GrainContact, WedgeAsperity
    cyl = CylinderOnLayer(1.0, MU)
    T = np.array([[0.2, 0.1], [1.0, -0.3], [-0.4, 0.2]])
    rest = cyl.contact_law(cyl.rest_state())
    assert isinstance(rest, GrainContact) and rest.alpha == pytest.approx(np.pi / 6)
    assert np.allclose(rest.limit(T, 1.0), WedgeAsperity(np.pi / 6, MU).limit(T, 1.0), atol=1e-14)
    top = cyl.contact_law(cyl.state_at((0.5, 0.0)))
    assert np.allclose(top.limit(T, 1.0), Coulomb(MU).limit(T, 1.0), atol=1e-14)
    past = cyl.state_at((0.75, 0.0))
    wedge = WedgeAsperity(np.pi - np.arcsin(0.25), MU)
    assert np.allclose(cyl.contact_law(past).limit(T, 1.0), wedge.limit(T, 1.0), atol=1e-14)
    assert cyl.limit(T[0], past) == pytest.approx(
        np.hypot(T[0, 0] * np.cos(past.alpha[0]) - np.sin(past.alpha[0]), T[0, 1])
        - MU * (T[0, 0] * np.sin(past.alpha[0]) + np.cos(past.alpha[0])))


# ---- break-out from a pocket under a force in any direction -------------------------------------
def test_breakout_cylinder_groove():
    """Pushed across the groove it climbs one neighbour at Q tan(pi/6 + rho); along the axis it
    slides on both at mu Q / cos(pi/6); between, the two-contact mechanism is a straight line."""
    cyl = CylinderOnLayer(1.0, MU)
    bo = cyl.breakout_force(np.radians([0.0, 90.0, 60.0, 120.0, 180.0]))
    assert bo.peak[0] == pytest.approx(np.tan(np.pi / 6 + RHO), rel=1e-6)
    assert bo.peak[1] == pytest.approx(MU / np.cos(np.pi / 6))
    assert list(bo.count) == [1, 2, 2, 2, 1]
    assert bo.peak[2] * np.sin(np.radians(60)) == pytest.approx(bo.peak[1])   # straight line
    assert bo.peak[4] == pytest.approx(bo.peak[0], rel=1e-6)


def test_breakout_pockets():
    sq = SphereOnLayer(1.0, MU, packing="square").breakout_force(np.radians([0.0, 45.0, 90.0]))
    assert list(sq.count) == [2, 1, 2]
    assert sq.peak[1] == pytest.approx(np.tan(np.pi / 4 + RHO), rel=1e-6)
    # over two at once along x: equals the displacement-controlled ridge force
    sph = SphereOnLayer(1.0, MU, packing="square")
    assert sq.peak[0] == pytest.approx(sph.peak_force([0.0]).peak[0], rel=1e-9)
    hx = SphereOnLayer(1.0, MU, packing="hexagonal").breakout_force(np.radians([0.0, 60.0, 180.0]))
    assert list(hx.count) == [1, 2, 2]
    assert hx.peak[1] == pytest.approx(hx.peak[2])
    assert hx.peak[0] == pytest.approx(np.tan(np.arcsin(1 / np.sqrt(3)) + RHO), rel=1e-6)


def test_breakout_over_one_lies_on_that_contacts_limit_curve():
    """Where the grain climbs over one grain, the break-out force is on the limit curve (2.2) of
    that contact (in its frame (3.11)); elsewhere it may lie beyond a single contact's limit curve,
    whose slip the neighbours block (the ridge mechanism starts later)."""
    from frictionrules.configuration.geometry import angles, touching
    sph = SphereOnLayer(1.0, MU, packing="hexagonal")
    th = np.linspace(0, 2 * np.pi, 37)
    bo = sph.breakout_force(th)
    pocket = touching(sph.layer, np.zeros(2))
    normals, ids = pocket.normals, pocket.ids
    states = [GrainState(np.zeros(2), 0.0, (i,), (a,), (p,))
              for i, (a, p) in zip(ids, zip(*angles(normals, False)))]
    for t, T, c in zip(bo.peak, bo.start, bo.count):
        fs = [float(sph.limit(T, st_)) for st_ in states]
        if c == 1:
            assert min(abs(f) for f in fs) < 1e-10


@pytest.mark.parametrize("packing", ["square", "hexagonal"])
def test_incremental_follows_contact_changes_in_a_layer(packing):
    """Across a layer the grain climbs one sphere, drops into the next pocket and climbs the
    next: the incremental run switches contact where the exact one does and stays close."""
    sph = SphereOnLayer(1.0, MU, packing=packing)
    path = sph.straight_path(0.2, 1.6, 401)
    ex = sph.displacement_path(path)
    inc = sph.displacement_path(path, "incremental", "heun")
    assert len(ex.events()) >= 2 and inc.events() == ex.events()
    assert np.abs(inc.force - ex.force).max() < 1e-4


def test_force_control_on_the_left_neighbour():
    """Pushed towards -x the cylinder climbs its left neighbour (signed alpha < 0)."""
    cyl = CylinderOnLayer(1.0, MU)
    res = cyl.force_path(np.stack((-np.linspace(0, 2, 101), np.zeros(101)), axis=-1))
    assert res.limit_point.force[0] == pytest.approx(-np.tan(np.pi / 6 + RHO))
    ex = cyl.displacement_path(cyl.straight_path(np.pi, 0.45, 201))
    back = cyl.force_path(ex.force[:-1], cyl.rest_state(np.pi))
    assert back.completed and np.abs(back.position - ex.position[:-1]).max() < 2e-3
