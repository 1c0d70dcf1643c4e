"""Grain assemblies: lattices, contact frames, input checks and the closed forms of regular
arrays (derivations in docs/assembly.md)."""

from dataclasses import dataclass

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from frictionrules import (Assembly, ContactModel, Coulomb, EllipticOrthotropic, FrictionLaw,
                           FrictionRulesError, UserLaw, triaxial)
from frictionrules.assembly._contacts import frames

KN = 1e6  # kn/(p d) = 5e5 with p = 1, d = 2


def model(law, kn=KN):
    return ContactModel(law, kn=kn, kt=kn)


def plateau_rate(result, n=3):
    """d(volumetric strain)/d(axial strain) over the first increments after the peak."""
    k = int(np.argmax(result.stress_ratio)) + 1
    ev, ax = result.volumetric_strain, result.axial_strain
    return (ev[k + n] - ev[k]) / (ax[k + n] - ax[k])


# ---- lattices and frames ------------------------------------------------------------------------
@pytest.mark.parametrize("name, frame, per_grain", [("fcc", "cube", 12), ("fcc", "layer", 12),
                                                    ("sc", "cube", 6), ("hex2d", "cube", 6),
                                                    ("square2d", "cube", 4)])
def test_lattice_coordination(name, frame, per_grain):
    a = Assembly.lattice(name, model(Coulomb(0.3)), frame=frame, cells=2)
    from frictionrules.assembly._loading import initial_state
    c = initial_state(a).contacts
    assert c.size == a.size * per_grain // 2
    counts = np.bincount(np.concatenate((c.i, c.j)), minlength=a.size)
    assert np.all(counts == per_grain)
    assert a.solid_fraction == pytest.approx({"fcc": np.pi / np.sqrt(18), "sc": np.pi / 6,
                                              "hex2d": np.pi / np.sqrt(12), "square2d": np.pi / 4}[name])


def test_fcc_layer_frame_axes():
    """Layer frame: x = [110], y = [1-10], z = [001]: 4 neighbours in the (001) plane along x
    and y, 8 at 45 degrees from z."""
    from frictionrules.assembly._loading import initial_state
    c = initial_state(Assembly.lattice("fcc", model(Coulomb(0.3)), frame="layer")).contacts
    n = np.abs(c.frames[:, 2, :])
    assert np.sum(np.isclose(n[:, 2], 0)) == 4  # two x and two y neighbours per grain, 2 grains
    assert np.allclose(n[n[:, 2] > 0.1], [0.5, 0.5, np.sqrt(0.5)])


@settings(max_examples=60, deadline=None)
@given(st.floats(-1, 1), st.floats(-1, 1), st.floats(-1, 1))
def test_frames_right_handed_t1_from_reference_axis(x, y, z):
    v = np.array([x, y, z])
    if np.linalg.norm(v) < 1e-3:
        v = np.array([0.0, 0.0, 1.0])
    n = v / np.linalg.norm(v)
    f = frames(n[None], np.array([1.0, 0.0, 0.0]))[0]
    assert np.allclose(f @ f.T, np.eye(3), atol=1e-12)
    assert np.linalg.det(f) == pytest.approx(1.0)
    p = np.array([1.0, 0, 0]) - n[0] * n
    if np.linalg.norm(p) > 1e-5:
        assert np.allclose(f[0], p / np.linalg.norm(p))


def test_frame_where_reference_axis_is_normal():
    f = frames(np.array([[1.0, 0, 0], [0, 1.0, 0]]), np.array([0.0, 1.0, 0.0]))
    assert np.allclose(f[0, 0], [0, 1, 0])   # projection of y
    assert np.allclose(f[1, 0], [0, 0, 1])   # y normal: the next axis, z
    assert np.allclose(f[1, 1], np.cross([0, 1, 0], [0, 0, 1]))


# ---- input checks -------------------------------------------------------------------------------
def test_overlap_beyond_tolerance():
    a = Assembly(np.array([[0.0, 0, 0], [1.9, 0, 0]]), 1.0, 10 * np.eye(3), model(Coulomb(0.3)))
    with pytest.raises(FrictionRulesError, match="overlap by 0.1.*tolerance"):
        triaxial(a, "axisymmetric", pressure=1.0)


def test_cell_that_does_not_tile():
    with pytest.raises(FrictionRulesError, match="cell widths.*largest diameter"):
        Assembly(np.zeros((1, 3)), 1.0, np.eye(3), model(Coulomb(0.3)))
    with pytest.raises(FrictionRulesError, match="det"):
        Assembly(np.zeros((1, 2)), 1.0, np.array([[2.0, 0], [0, -2.0]]), model(Coulomb(0.3)))


@dataclass(frozen=True)
class _Bare(FrictionLaw):
    mu: float = 0.3


def test_law_without_capability():
    with pytest.raises(FrictionRulesError, match="lacks the capability 'symbolic'"):
        Assembly.lattice("sc", lambda i, j: ContactModel(_Bare(), kn=1.0, kt=1.0))
        triaxial(Assembly.lattice("sc", lambda i, j: ContactModel(_Bare(), 1.0, 1.0)),
                 "axisymmetric", pressure=1.0)


def test_kind_and_dimension():
    with pytest.raises(FrictionRulesError, match="kind = 'biaxial'"):
        triaxial(Assembly.lattice("sc", model(Coulomb(0.3))), "biaxial", pressure=1.0)
    with pytest.raises(FrictionRulesError, match="pressure"):
        triaxial(Assembly.lattice("sc", model(Coulomb(0.3))), "axisymmetric", pressure=-1.0)


# ---- Thornton's fcc array -----------------------------------------------------------------------
@pytest.mark.parametrize("mu", [0.0, 0.1, 0.3, 0.5])
def test_thornton_fcc_axisymmetric(mu):
    """σzz/σxx = 2(1 + μ)/(1 - μ) (Thornton 1979): the 45-degree contacts slide, the contacts
    in the xy planes open."""
    r = triaxial(Assembly.lattice("fcc", model(Coulomb(mu))), "axisymmetric", pressure=1.0,
                 axial_strain=2e-4, increments=40)
    assert r.failed
    assert r.peak_ratio == pytest.approx(2 * (1 + mu) / (1 - mu), rel=1e-3)
    phi = np.degrees(np.arcsin((r.peak_ratio - 1) / (r.peak_ratio + 1)))
    assert r.peak_friction_angle == pytest.approx(phi)


def test_thornton_fcc_no_failure_above_locking_friction():
    """μ >= 1 locks the 45-degree contacts: the ratio grows without a limit."""
    r = triaxial(Assembly.lattice("fcc", model(Coulomb(1.2))), "axisymmetric", pressure=1.0,
                 axial_strain=2e-4, increments=20)
    assert not r.failed and r.peak_ratio == np.inf and r.peak_friction_angle == 90.0
    assert r.stress_ratio[-1] > 2 * (1 + 0.99) / (1 - 0.99) / 10 and r.converged.all()


def plane_strain_ratio(mu, psi_ratio):
    """The layer-frame plane-strain limit (docs/assembly.md): slip direction of the inclined
    contact n = (1/2, 1/2, 1/√2) from the kinematics Δd = (e/2, 0, -1/√2) with the normal part
    vn = tanψ |vt|; the force n - μ t̂ gives σzz/σxx = (f_z n_z)/(f_x n_x)."""
    n = np.array([0.5, 0.5, np.sqrt(0.5)])
    sin_psi = psi_ratio / np.hypot(1.0, psi_ratio)

    def residual(e):
        a = np.array([e / 2, 0.0, -np.sqrt(0.5)])
        return a @ n - sin_psi * np.linalg.norm(a)
    lo, hi = 0.0, 100.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if residual(mid) < 0 else (lo, mid)
    a = np.array([lo / 2, 0.0, -np.sqrt(0.5)])
    vt = a - (a @ n) * n
    f = n - mu * vt / np.linalg.norm(vt)
    return f[2] * n[2] / (f[0] * n[0]), lo


def test_plane_strain_layer_frame_closed_form():
    mu = 0.3
    assert plane_strain_ratio(mu, 0.0)[0] == pytest.approx(2 * (np.sqrt(6) + 2 * mu) / (np.sqrt(6) - 4 * mu))
    r = triaxial(Assembly.lattice("fcc", model(Coulomb(mu), kn=1e7), frame="layer"), "plane_strain",
                 pressure=1.0, axial_strain=2e-5, increments=40)
    assert r.peak_ratio == pytest.approx(plane_strain_ratio(mu, 0.0)[0], rel=1e-3)


def test_plane_strain_associated_rule_is_stronger():
    """With the dilatant rule (1.6) the inclined contacts slide partly along y: the strength
    rises (4.969 against 4.881 at μ = 0.3)."""
    mu = 0.3
    r = triaxial(Assembly.lattice("fcc", model(Coulomb(mu, dilatant=True)), frame="layer"),
                 "plane_strain", pressure=1.0, axial_strain=2e-4, increments=40)
    good = r.converged
    assert good[:5].all()
    peak = r.stress_ratio[good].max()
    assert peak == pytest.approx(plane_strain_ratio(mu, mu)[0], rel=1e-3)
    assert peak > 1.01 * plane_strain_ratio(mu, 0.0)[0]


@pytest.mark.parametrize("dilatant", [False, True])
def test_axisymmetric_associated_same_strength_more_dilation(dilatant):
    """Same forces at the limit, so the same strength; dilatancy dεv/dεz = -1 (ψ = 0) or
    -(1 + 3μ)/(1 - μ) (ψ = φ)."""
    mu = 0.3
    r = triaxial(Assembly.lattice("fcc", model(Coulomb(mu, dilatant=dilatant))), "axisymmetric",
                 pressure=1.0, axial_strain=2e-4, increments=40)
    assert r.peak_ratio == pytest.approx(2 * (1 + mu) / (1 - mu), rel=1e-3)
    want = -(1 + 3 * mu) / (1 - mu) if dilatant else -1.0
    assert plateau_rate(r) == pytest.approx(want, rel=2e-3)


def test_dilatant_non_associated_rule():
    """0 < ψ < φ: the strength of Coulomb, the dilatancy -(1 + 3 tanψ)/(1 - tanψ)."""
    mu, m = 0.3, 0.15
    law = UserLaw("sqrt(T1**2 + T2**2) - mu*N", potential="sqrt(T1**2 + T2**2) - m*N",
                  params={"mu": mu, "m": m})
    r = triaxial(Assembly.lattice("fcc", model(law)), "axisymmetric", pressure=1.0,
                 axial_strain=2e-4, increments=30)
    assert r.peak_ratio == pytest.approx(2 * (1 + mu) / (1 - mu), rel=1e-3)
    assert plateau_rate(r) == pytest.approx(-(1 + 3 * m) / (1 - m), rel=2e-3)


def test_orthotropic_contacts():
    """Elliptic law with axis 1 on t1 (the projection of x): the xz contacts slide along t1
    with μx, the yz contacts along t2 with μy: σzz/σ3 = (1+μx)/(1-μx) + (1+μy)/(1-μy)."""
    mx, my = 0.2, 0.4
    r = triaxial(Assembly.lattice("fcc", model(EllipticOrthotropic(mx, my))), "axisymmetric",
                 pressure=1.0, axial_strain=2e-4, increments=40)
    assert r.peak_ratio == pytest.approx((1 + mx) / (1 - mx) + (1 + my) / (1 - my), rel=1e-3)


def test_hex2d_rowe_stress_dilatancy():
    """Hexagonal disks, σ1 normal to the rows: R = tan(θ + φμ) tan θ with θ = 60°, and
    D = -dεx/dεy = tan²θ = 3 (Rowe's R = D tan(θ + φμ)/tan θ)."""
    mu = 0.3
    r = triaxial(Assembly.lattice("hex2d", model(Coulomb(mu))), "biaxial", pressure=1.0,
                 axial_strain=2e-4, increments=40)
    theta, phi = np.pi / 3, np.arctan(mu)
    assert r.peak_ratio == pytest.approx(np.tan(theta + phi) * np.tan(theta), rel=1e-3)
    k = int(np.argmax(r.stress_ratio)) + 1
    ex, ey = r.strain[:, 0, 0], r.strain[:, 1, 1]
    D = -(ex[k + 3] - ex[k]) / (ey[k + 3] - ey[k])
    assert D == pytest.approx(np.tan(theta) ** 2, rel=2e-3)


def test_simple_cubic_carries_any_ratio_without_tangential_force():
    r = triaxial(Assembly.lattice("sc", model(Coulomb(0.3)), cells=2), "axisymmetric",
                 pressure=1.0, axial_strain=1e-4, increments=10)
    assert r.stress_ratio[-1] > 10 and not r.failed
    for snap in r.contacts:
        f = snap.force
        assert np.max(np.hypot(f[:, 0], f[:, 1])) <= 1e-8 * f[:, 2].max()


def test_power_balance_every_increment():
    """V σ:ε̇ = Σ f·v: the boundary work equals the contacts' work at equilibrium."""
    r = triaxial(Assembly.lattice("fcc", model(Coulomb(0.3)), cells=(2, 1, 1)), "axisymmetric",
                 pressure=1.0, axial_strain=2e-4, increments=20)
    ok = r.converged[1:]
    cw, bw = r.contact_work[1:][ok], r.boundary_work[1:][ok]
    assert np.all(np.abs(cw - bw) <= 1e-8 * np.abs(bw))


def test_result_record_fields():
    r = triaxial(Assembly.lattice("square2d", model(Coulomb(0.3))), "biaxial", pressure=2.0,
                 axial_strain=1e-5, increments=3)
    assert r.stress.shape == (4, 2, 2) and r.strain.shape == (4, 2, 2)
    assert np.allclose(r.stress[:, 0, 0], 2.0)
    assert r.volumetric_strain.shape == (4,) and r.coordination[0] == pytest.approx(4.0)
    assert len(r.contacts) == 4 and r.converged.all()


def test_load_cell_mixed_control_equals_triaxial():
    """Axisymmetric compression written as a general mixed control gives the same history."""
    from frictionrules import load_cell
    a = Assembly.lattice("fcc", model(Coulomb(0.3)))
    r1 = triaxial(a, "axisymmetric", pressure=1.0, axial_strain=1e-4, increments=10)
    r2 = load_cell(a, {"zz": ("strain", 1e-4)}, pressure=1.0, increments=10)
    np.testing.assert_allclose(r2.stress, r1.stress, rtol=1e-9, atol=1e-12)
    assert r2.kind == "mixed"


def test_load_cell_stress_path_and_bad_loading():
    from frictionrules import load_cell
    a = Assembly.lattice("sc", model(Coulomb(0.3)))
    r = load_cell(a, {"zz": ("stress", 3.0)}, pressure=1.0, increments=4)
    assert r.stress[-1, 2, 2] == pytest.approx(3.0) and r.stress[-1, 0, 0] == pytest.approx(1.0)
    with pytest.raises(FrictionRulesError, match="at least one driven component"):
        load_cell(a, {"zz": ("stress", 1.0)}, pressure=1.0)
    with pytest.raises(FrictionRulesError, match="control key 'zx'"):
        load_cell(a, {"zx": ("strain", 1e-3)}, pressure=1.0)
