"""The implicit increment at mechanisms: the Newton step without its part on the mechanisms,
rattlers left out of the unknowns, plateaus that do not depend on round-off, limit points."""

import numpy as np
import pytest

from frictionrules import Assembly, ContactModel, Coulomb, load_cell, triaxial
from frictionrules.assembly._newton import FREE_SHIFT, MECHANISM, newton_direction, rattlers


def _blocks(J):
    """A (6, 6) matrix made of two 3x3 diagonal blocks as the contact blocks (2, 3, 3)."""
    return np.stack((J[:3, :3], J[3:, 3:]))


@pytest.mark.parametrize("dense", [True, False])
def test_newton_direction_is_newton_without_the_mechanisms(dense):
    """With the elastic Jacobian E = I (so M = m I, m = 1 + η) and J = V diag(λ) Vᵀ, mode by
    mode (``q = εm/(λ + εm)``): the step is ``-(1 - q)²(1 + 2q)/λ VᵀR`` (Newton's ``-1/λ`` to
    within ``3q²`` on the stiff modes, nothing on the mechanisms), its part on the mechanisms
    the rest of ``y = -A⁻¹R``, and the load left ``R + J dx = (3q² - 2q³) VᵀR``: all of R's
    component on the modes with ``λ ≪ ε``, none of the stiff ones."""
    rng = np.random.default_rng(3)
    lam = np.array([[1.0, 0.3, 1e-3], [2.0, 1e-12, 0.0]])
    J = np.zeros((6, 6))
    for b in range(2):
        q, _ = np.linalg.qr(rng.standard_normal((3, 3)))
        J[3 * b:3 * b + 3, 3 * b:3 * b + 3] = q @ np.diag(lam[b]) @ q.T
    R = rng.standard_normal(6)
    B = np.eye(6)
    if not dense:
        import scipy.sparse as sp
        B = sp.csr_matrix(B)
    step, z, load = newton_direction(B, _blocks(J), _blocks(np.eye(6)), R, dense)
    w, V = np.linalg.eigh(J)
    em = MECHANISM * (1 + FREE_SHIFT)
    q = em / (w + em)
    r = V.T @ R
    y = -r / (w + em)
    # y and the corrections are ~|R|/ε on the mechanisms: exact to the rounding of that size
    # (times the largest stiffness, 2, for the load R + J dx)
    big = np.abs(r).max() / em
    np.testing.assert_allclose(V.T @ step, -(1 - q) * (1 + 2 * q) / (w + em) * r, rtol=1e-9,
                               atol=1e-11 * big)
    np.testing.assert_allclose(V.T @ z, y - V.T @ step, rtol=1e-9, atol=1e-11 * big)
    np.testing.assert_allclose(V.T @ load, (3 * q**2 - 2 * q**3) * r, rtol=1e-9,
                               atol=1e-15 * 2 * big)
    stiff = w > 1e-4
    np.testing.assert_allclose((V.T @ step)[stiff], -r[stiff] / w[stiff], rtol=1e-5)  # Newton
    np.testing.assert_allclose((V.T @ load)[~stiff], r[~stiff], rtol=1e-5)   # the whole load
    assert np.all(np.abs(V.T @ load)[stiff] <= 1e-5 * np.abs(r[stiff]))       # none of it


def test_rattlers_are_the_grains_outside_the_two_core():
    """Grains 0-1-2 hold each other (a triangle); 3 hangs on 0 by one contact; 4 touches
    nothing; 5 touches its own image (two points of contact); 6-7 hold only each other; the
    chain 8-9-10 unravels from its ends; 11 and 12 rest on the triangle by two contacts each
    (their contact 11-12, open beyond the tolerance, does not count)."""
    i = np.array([0, 1, 2, 0, 5, 6, 8, 9, 11, 11, 11, 12, 12])
    j = np.array([1, 2, 0, 3, 5, 7, 9, 10, 12, 0, 1, 1, 2])
    holding = np.array([True] * 8 + [False] + [True] * 4)
    out = rattlers(13, i, j, holding)
    np.testing.assert_array_equal(np.flatnonzero(out), [3, 4, 6, 7, 8, 9, 10])


def _fcc_with(extra_position, extra_radius, mu=0.3):
    model = ContactModel(Coulomb(mu), kn=1e6, kt=1e6)
    a = Assembly.lattice("fcc", model)
    return Assembly(np.vstack((a.positions, extra_position)), np.append(a.radii, extra_radius),
                    a.cell, model, a.reference_axis, a.tolerance)


def test_rattler_in_a_hole_moves_with_the_cell():
    """A small sphere in the octahedral hole of Thornton's array touches nothing: it is left
    out of the unknowns, moves affinely with the cell, and the strength stays 2(1+μ)/(1-μ)."""
    mu = 0.3
    a = _fcc_with(np.full(3, np.sqrt(2.0)), 0.3, mu)   # the hole's centre, hole radius √2 - 1
    r = triaxial(a, "axisymmetric", pressure=1.0, axial_strain=2e-4, increments=20,
                 consolidation="stress")
    assert r.converged.all() and r.failed
    assert r.peak_ratio == pytest.approx(2 * (1 + mu) / (1 - mu), rel=1e-9)
    F = r.final.cell @ np.linalg.inv(a.cell)
    np.testing.assert_allclose(r.final.positions[-1], F @ a.positions[-1], rtol=0, atol=1e-14)


def test_grain_on_one_contact_carries_no_force():
    """A sphere touching one neighbour cannot balance a force: it is a rattler at the start,
    takes part as soon as its neighbour pushes it, and rides along with a zero force."""
    mu = 0.3
    # touching the face centre (√2, √2, 0) at distance 1 + 0.4, inside the hole
    a = _fcc_with(np.array([np.sqrt(2.0), np.sqrt(2.0), 1.4]), 0.4, mu)
    r = triaxial(a, "axisymmetric", pressure=1.0, axial_strain=2e-4, increments=10,
                 consolidation="stress")
    assert r.converged.all()
    assert r.peak_ratio == pytest.approx(2 * (1 + mu) / (1 - mu), rel=1e-9)
    for snap in r.contacts:
        own = np.any(snap.grains == a.size - 1, axis=1)
        assert np.abs(snap.force[own]).max() <= 1e-9


def _plane_strain(positions_scale=None):
    a = Assembly.lattice("fcc", ContactModel(Coulomb(0.3, dilatant=True), kn=1e6, kt=1e6),
                         frame="layer")
    if positions_scale is not None:
        a = a.with_geometry(a.positions * positions_scale, a.cell)
    return triaxial(a, "plane_strain", pressure=1.0, axial_strain=6e-5, increments=12)


def test_plane_strain_plateau_does_not_depend_on_round_off():
    """At the plateau of the associated rule in plane strain the sliding contacts form a
    mechanism (the grains rotate about y with a shear xz: half of the inclined contacts slide
    forward, half back, all without plastic work). Positions perturbed by 1e-14 give the same
    history: every increment converges, the stress ratios agree to 1e-9."""
    ref = _plane_strain()
    rng = np.random.default_rng(7)
    other = _plane_strain(1 + 1e-14 * rng.uniform(-1, 1, (2, 3)))
    assert ref.converged.all() and other.converged.all()
    np.testing.assert_allclose(other.stress_ratio, ref.stress_ratio, rtol=1e-9)
    assert ref.failed and ref.peak_ratio == pytest.approx(4.969, abs=1e-3)


def test_limit_point_under_stress_control_is_reported():
    """σzz driven past the strength 2(1+μ)/(1-μ) = 3.714 of Thornton's array: no equilibrium
    exists beyond it, and the run says so."""
    a = Assembly.lattice("fcc", ContactModel(Coulomb(0.3), kn=1e6, kt=1e6))
    r = load_cell(a, {"zz": ("stress", 5.0)}, pressure=1.0, increments=10)
    assert r.limit_point and r.message.startswith("limit point")
    assert not r.converged[-1] and r.converged[:-1].all()
    assert r.stress_ratio[r.converged].max() <= 2 * 1.3 / 0.7
