"""The dynamic (DEM) engine: the closed forms of regular arrays, the energy balance, any law at
every contact, records, run files and bad input (docs/assembly.md, "Dynamic runs")."""

import numpy as np
import pytest

from frictionrules import (Assembly, ContactModel, Coulomb, EllipticOrthotropic,
                           FrictionRulesError, UserLaw, load_cell, triaxial)

STIFF = 1e6  # kn/(p d) = 5e5 with p = 1, d = 2: the lattices' closed forms are rigid-grain ones
QUASI_STATIC = dict(method="dem", inertial_number=1e-4, record_every=5e-6, peak_window=0.0)


def model(law, kn=STIFF):
    return ContactModel(law, kn=kn, kt=kn)


# ---- lattices: the implicit path's closed forms, by damped dynamics ------------------------------
@pytest.mark.parametrize("mu", [0.1, 0.3, 0.5])
def test_thornton_fcc_axisymmetric(mu):
    """σzz/σxx = 2(1 + μ)/(1 - μ) (Thornton 1979), within 0.5 %; the cell stays rectangular."""
    r = triaxial(Assembly.lattice("fcc", model(Coulomb(mu))), "axisymmetric", pressure=1.0,
                 axial_strain=2e-4, **QUASI_STATIC)
    assert r.method == "dem" and r.failed
    assert r.peak_ratio == pytest.approx(2 * (1 + mu) / (1 - mu), rel=5e-3)
    assert np.abs(r.strain[:, [1, 0, 0], [2, 2, 1]]).max() < 1e-12


@pytest.mark.parametrize("cell", ["rectangular", "flexible"])
@pytest.mark.parametrize("imperfection", [0.0, 1e-6])
def test_fcc_limit_in_either_cell(cell, imperfection):
    """μ = 0.5: the horizontal contacts open near σ1/σ3 = 3 and leave the array a mode of zero
    stiffness; with one grain moved by ``imperfection`` radii, or none, and in either cell,
    the array slides symmetrically to Thornton's 6 without shear stresses."""
    lattice = Assembly.lattice("fcc", model(Coulomb(0.5)))
    x = lattice.positions.copy()
    x[0] += imperfection * lattice.radii[0] * np.array([1.0, 0.5, 0.0])
    sample = Assembly(x, lattice.radii, lattice.cell, lattice.model)
    r = triaxial(sample, "axisymmetric", pressure=1.0, axial_strain=2e-5, cell=cell,
                 **QUASI_STATIC)
    assert r.peak_ratio == pytest.approx(6.0, rel=5e-3)
    assert np.abs(r.stress[-1][[1, 0, 0], [2, 2, 1]]).max() < 1e-3


def test_hex2d_rowe():
    """Hexagonal disks, σ1 normal to the rows: R = tan(θ + φμ) tan θ, θ = 60° (Rowe 1962)."""
    mu = 0.3
    r = triaxial(Assembly.lattice("hex2d", model(Coulomb(mu))), "biaxial", pressure=1.0,
                 axial_strain=2e-4, **QUASI_STATIC)
    assert r.peak_ratio == pytest.approx(np.tan(np.pi / 3 + np.arctan(mu)) * np.tan(np.pi / 3),
                                         rel=5e-3)


# ---- random packings ----------------------------------------------------------------------------
@pytest.fixture(scope="module")
def sample():
    return Assembly.random(100, 3, model(Coulomb(0.5), kn=1e4), polydispersity=0.2, seed=3)


def _run(sample, law, strain=0.01, **kw):
    s = Assembly(sample.positions, sample.radii, sample.cell, model(law, kn=1e4))
    return triaxial(s, "axisymmetric", pressure=1.0, axial_strain=strain, method="dem", **kw)


def test_random_packing_is_jammed_and_seeded(sample):
    """Frictionless random close packing (φ ≈ 0.64 for spheres); the same seed, the same sample."""
    assert 0.6 < sample.solid_fraction < 0.66
    again = Assembly.random(100, 3, model(Coulomb(0.5), kn=1e4), polydispersity=0.2, seed=3)
    assert np.array_equal(again.positions, sample.positions)


def test_frictionless_consolidation_by_fire_ends_in_equilibrium(sample):
    """The frictionless consolidation moves its grains by FIRE (only its end state matters):
    it ends where every normal stress is within 1e-3 of the pressure with an unbalanced-force
    ratio below 1e-4 (the rectangular cell leaves the shear stresses to the packing), and its
    step never left FIRE's bounds."""
    from frictionrules.assembly._dem import _engine
    r = _run(sample, Coulomb(0.5), strain=0.001, record_every=0.001)
    first = r.stress[0]
    np.testing.assert_allclose(np.diag(first), 1.0, atol=1e-3 + 1e-12)
    assert r.unbalanced_force[0] < 1e-4
    meters = r.engine.meters[0]
    dt = 0.25 * np.sqrt(1.0 * 4 / 3 * np.pi * sample.radii.min() ** 3 / 1e4)
    assert _engine.FIRE_DT_MIN * dt <= meters["fire_dt"] <= _engine.FIRE_DT_MAX * dt * (1 + 1e-12)


class _Phases:
    """A progress callback that keeps the texts of the preparation's phases."""

    def __init__(self):
        self.texts = []

    def __call__(self, done, total):
        pass

    def phase(self, text):
        self.texts.append(text)


def test_frictionless_consolidation_settles_at_its_preload_first(sample):
    """A frictionless consolidation approaches the pressure from above by default: it settles
    at PRELOAD times the pressure (its stress reported against that target), then at the
    pressure (``tests/test_assembly_preload.py``: other preloads)."""
    from frictionrules.assembly._dem._protocol import PRELOAD
    progress = _Phases()
    r = _run(sample, Coulomb(0.5), strain=0.001, record_every=0.001, progress=progress)
    texts = progress.texts
    pre = [k for k, t in enumerate(texts)
           if t.startswith(f"consolidation (frictionless, preload {PRELOAD:g} p)")]
    final = [k for k, t in enumerate(texts) if t.startswith("consolidation (frictionless):")]
    assert PRELOAD > 1 and pre and final and pre[-1] < final[0]
    ratio = float(texts[pre[-1]].split("p/p* = ")[1].split(",")[0])
    assert abs(ratio - 1.0) <= 1e-3 + 1e-4  # settled at the preload (printed to 4 digits)
    assert r.engine.meters[0]["preloaded"] == 1
    np.testing.assert_allclose(np.diag(r.stress[0]), 1.0, atol=1e-3 + 1e-12)


def test_records_take_their_frames_from_the_normals(sample):
    """A frictionless stage computes no contact frames (its contacts carry no tangential
    force); the records' frames, the first one after it included, are the contact rule's
    (:func:`frictionrules.assembly._contacts.frames`): orthonormal, t1 along the reference
    axis projected on the contact plane."""
    from frictionrules.assembly._contacts import frames
    r = _run(sample, Coulomb(0.5), strain=0.001, record_every=0.001)
    for snap in (r.contacts[0], r.contacts[-1]):
        F = snap.frame
        assert len(F) > 100
        np.testing.assert_allclose(np.einsum("kij,klj->kil", F, F),
                                   np.broadcast_to(np.eye(3), F.shape), atol=1e-12)
        np.testing.assert_allclose(F, frames(F[:, 2], sample.reference_axis), atol=1e-12)


def test_records_and_energy_balance(sample):
    """Boundary work = the laws' dissipation + elastic + kinetic energy + damping loss, to 1 %
    of the boundary work; a record every 0.1 % of Hencky strain (at the first step past it:
    a step is 7e-7 of strain here), compression positive."""
    r = _run(sample, Coulomb(0.5))
    assert len(r.axial_strain) == 11
    np.testing.assert_allclose(r.axial_strain, np.linspace(0, 0.01, 11), atol=2e-6)
    assert r.energy.relative_error < 0.01
    assert r.energy.dissipation[-1] > 0 and np.all(np.diff(r.energy.dissipation) >= 0)
    assert np.all(r.coordination > 3) and np.all(r.coordination_without_rattlers >= r.coordination)
    assert np.all((r.sliding_fraction >= 0) & (r.sliding_fraction <= 1))
    # σ1/σ3 rises from 1: the lateral stress held by the servo
    lateral = r.stress[:, 0, 0]
    np.testing.assert_allclose(lateral, 1.0, rtol=0.05)
    assert r.stress_ratio[-1] > 1.5
    assert len(r.contacts) == len(r.axial_strain) == len(r.positions)


def test_user_law_for_coulomb_is_coulomb(sample):
    """A UserLaw written for Coulomb runs the same test: its generated kernel gives the same
    forces, so the records agree until round-off grows (a granular sample is chaotic)."""
    a = _run(sample, Coulomb(0.5), strain=0.003)
    b = _run(sample, UserLaw("sqrt(T1**2 + T2**2) - 0.5*N", potential="sqrt(T1**2 + T2**2)"),
             strain=0.003)
    np.testing.assert_allclose(b.stress_ratio, a.stress_ratio, rtol=1e-6)


@pytest.mark.parametrize("law", [
    EllipticOrthotropic(0.5, 0.25),
    UserLaw("sqrt(T1**2 + T2**2) - 0.5*N", potential="sqrt(T1**2 + T2**2) - 0.15*N")],
    ids=["orthotropic", "dilatant-non-associated"])
def test_other_laws_hold_the_energy_balance(sample, law):
    r = _run(sample, law, strain=0.005)
    assert r.energy.relative_error < 0.01
    assert r.energy.dissipation[-1] > 0


def test_biaxial_disks_and_load_cell(sample):
    disks = Assembly.random(60, 2, model(Coulomb(0.3), kn=1e4), polydispersity=0.2, seed=2)
    r = triaxial(disks, "biaxial", pressure=1.0, axial_strain=0.004, method="dem")
    assert r.energy.relative_error < 0.01 and r.stress_ratio[-1] > 1.2
    m = load_cell(disks, {"yy": ("strain", 0.004), "xx": ("stress", 1.0)}, pressure=1.0,
                  method="dem")
    assert m.kind == "mixed" and m.axial_strain[-1] == pytest.approx(0.004, abs=2e-6)


def test_max_time_then_resume_gives_the_same_records(sample, tmp_path):
    """An interrupted run keeps its records; called again it resumes from the engine's state
    bit for bit (fixed chunks: the same numbers whatever the number of threads)."""
    whole = _run(sample, Coulomb(0.5), strain=0.004)
    path = tmp_path / "run.h5"
    first = _run(sample, Coulomb(0.5), strain=0.004, run_file=path, max_time=1e-9)
    assert "max_time" in first.message
    rest = _run(sample, Coulomb(0.5), strain=0.004, run_file=path)
    np.testing.assert_array_equal(rest.stress, whole.stress)
    # the records' contacts are read from the file when indexed, the last one held
    assert len(rest.contacts) == len(whole.contacts) > 2
    for k in (0, 1, -1):
        for key in ("grains", "frame", "force", "slip", "status", "group"):
            np.testing.assert_array_equal(getattr(rest.contacts[k], key),
                                          getattr(whole.contacts[k], key))
        np.testing.assert_array_equal(rest.contacts[k].states[0].elastic,
                                      whole.contacts[k].states[0].elastic)
    assert [s.size for s in rest.contacts[:2]] == [s.size for s in whole.contacts[:2]]
    with pytest.raises(IndexError):
        rest.contacts[len(whole.contacts)]
    path.rename(tmp_path / "moved.h5")
    assert rest.contacts[-1] is rest.contacts[len(rest.contacts) - 1]  # held in memory
    with pytest.raises(FrictionRulesError, match="run_file = .*run.h5.* record 0"):
        rest.contacts[0]


@pytest.mark.parametrize("kw, match", [
    (dict(inertial_number=0.0), "inertial_number"),
    (dict(damping=1.0), "damping"),
    (dict(density=-1.0), "density"),
    (dict(record_every=0.5), "record_every"),
    (dict(method="explicit"), "method"),
    (dict(cell="skewed"), "cell = 'skewed' violates: one of rectangular, flexible"),
])
def test_bad_options(sample, kw, match):
    opts = dict(method="dem") | kw
    with pytest.raises(FrictionRulesError, match=match):
        triaxial(sample, "axisymmetric", pressure=1.0, axial_strain=0.01, **opts)


def test_unstable_motion_is_an_error(sample):
    """Contacts far too soft for the pressure (overlaps beyond half a radius): an error, never
    a result."""
    soft = Assembly(sample.positions, sample.radii, sample.cell, model(Coulomb(0.5), kn=1.0))
    with pytest.raises(FrictionRulesError, match="unstable"):
        triaxial(soft, "axisymmetric", pressure=1.0, axial_strain=0.01, method="dem")
