"""Abaqus UINTER and VFRIC compiled and called as Abaqus calls them, against the library.

UINTER carries the whole interface law (normal penalty kn, dilatancy, the wedge (2.2) and the
cap (4.9)): its STRESS = (pressure, shear 1, shear 2) and DDSDDR = d STRESS / d(overclosure,
slip 1, slip 2) against ``ContactModel.update(..., tangent=True)`` over 8 random paths of 60
increments (1e-10, 1e-8) and against central differences (1e-5). VFRIC returns the force of
the law's inverse relation (1.8) times the normal force, bounded by the stick force.
"""

import numpy as np
import pytest

import frictionrules as fr
from _export_harness import Fric, Uinter, Vfric, compile_fortran, fpe_traps
from test_export_compiled import KN, KT, PATHS, STEPS, _built, _close, _model, _path

#: STRESS index -> (T1, T2, N) index; RDISP index -> (δt1, δt2, δn) index and sign.
_S = (2, 0, 1)
_R = ((2, -1.0), (0, 1.0), (1, 1.0))


def _abaqus_tangent(C, n):
    """The model's d(T1, T2, N)/d(δt1, δt2, δn) as DDSDDR (pressure first, overclosure first)."""
    return np.array([[C[_S[i], _R[j][0]] * _R[j][1] for j in range(n)] for i in range(n)])


@pytest.fixture(scope="module")
def uinters(tmp_path_factory):
    cache = {}

    def get(key):
        if key not in cache:
            folder, res = _built(tmp_path_factory, key, "abaqus-uinter")
            cache[key] = (Uinter(compile_fortran(folder, f"{key}_uinter.f")), res)
        return cache[key]
    return get


@pytest.mark.parametrize("key, ndir", [("dilatant", 3), ("wedge", 3), ("cap", 3), ("coulomb", 3),
                                       ("dilatant", 2), ("wedge", 2), ("cap", 2), ("elliptic", 2)])
def test_uinter_matches_contact_model(key, ndir, uinters):
    u, res = uinters(key)
    model = _model(key)
    statuses = set()
    for path in range(PATHS):
        rng = np.random.default_rng(path)
        st, statev, rdisp = model.initial_state(), np.zeros(res.nstatv), np.zeros(ndir)
        for i in range(STEPS):
            du = _path(rng, i, nd=ndir)
            dr = np.array([-du[2], du[0], du[1]])[:ndir]
            rdisp = rdisp + dr
            with fpe_traps():
                stress, ddsddr, statev, *_, pnewdt, lstate, _ = u.call(statev, rdisp, dr,
                                                                        res.props, ndir)
            r = model.update(st, du, tangent=True)
            statuses.add(int(r.status))
            ours = np.array([r.force[k] for k in _S])[:ndir]
            assert pnewdt == 1.0 and lstate == (0 if int(r.status) == 2 else 1)
            assert _close(stress, ours, 1e-10, max(np.abs(ours).max(), 1e-2)), (path, i)
            assert _close(ddsddr, _abaqus_tangent(r.tangent, ndir), 1e-8, KT), (path, i)
            st = r.state
    assert statuses == {0, 1, 2}


@pytest.mark.parametrize("key", ["dilatant", "wedge", "cap"])
def test_uinter_tangent_is_the_derivative_of_the_stress(key, uinters):
    u, res = uinters(key)
    rng = np.random.default_rng(4)
    statev, rdisp, checked = np.zeros(res.nstatv), np.zeros(3), 0
    for i in range(40):
        du = _path(rng, i)
        dr = np.array([-du[2], du[0], du[1]])
        base = u.call(statev, rdisp + dr, dr, res.props, 3)
        fd = np.empty((3, 3))
        h = 1e-7
        for j in range(3):
            e = np.zeros(3)
            e[j] = h
            fd[:, j] = (u.call(statev, rdisp + dr + e, dr + e, res.props, 3)[0]
                        - u.call(statev, rdisp + dr - e, dr - e, res.props, 3)[0]) / (2 * h)
        if base[-2] == 1 and np.abs(base[1] - np.diag([KN, KT, KT])).max() > 1e-6 * KT:
            assert _close(base[1], fd, 1e-5, KT), (i, base[1], fd)
            checked += 1
        statev, rdisp = base[2], rdisp + dr
    assert checked >= 5


# ---- abaqus-vfric ------------------------------------------------------------------------
def _frame(n, phi):
    """The material frame VFRIC rebuilds: global 1 (2 where the normal is closer to 1)
    projected on the tangent plane, turned by ``phi`` about the normal."""
    ref = np.array([1.0, 0, 0]) if abs(n[0]) <= np.sqrt(0.5) else np.array([0, 1.0, 0])
    b1 = ref - ref @ n * n
    b1 /= np.linalg.norm(b1)
    b2 = np.cross(n, b1)
    return np.cos(phi) * b1 + np.sin(phi) * b2, -np.sin(phi) * b1 + np.cos(phi) * b2


@pytest.mark.parametrize("key", ["coulomb", "elliptic", "nonassoc", "hardening"])
def test_vfric_force_is_the_inverse_relation_times_the_normal_force(key, tmp_path_factory):
    folder, res = _built(tmp_path_factory, key, "abaqus-vfric")
    v = Vfric(compile_fortran(folder, f"{key}_vfric.f"))
    law = _model(key).effective_law
    rng = np.random.default_rng(0)
    n = 64
    normal = rng.normal(size=(3, n))
    normal /= np.linalg.norm(normal, axis=0)
    slip = rng.normal(size=(3, n))
    slip -= (slip * normal).sum(0) * normal
    slip /= np.linalg.norm(slip, axis=0)
    fnormal = rng.uniform(0.1, 2.0, n)
    fstick = np.where(rng.uniform(size=n) < 0.25, 0.05, 1e3)
    dslip = slip * rng.uniform(0.0, 0.01, n)
    props = np.array(res.props)
    props[-1] = phi = 0.3
    state = np.full((max(res.nstatv, 1), n), 0.02 if res.nstatv else 0.0)
    with fpe_traps():
        f, state1 = v.call(state, props, dslip, fstick, fnormal, normal, slip, 2)
    for k in range(n):
        m1, m2 = _frame(normal[:, k], phi)
        theta = np.arctan2(slip[:, k] @ m2, slip[:, k] @ m1)
        q = state[:res.nstatv, k] if res.nstatv else None
        T = law.inverse_relation(theta, fnormal[k], q).force
        G = T[0] * m1 + T[1] * m2
        F = np.array([G @ slip[:, k], G @ np.cross(normal[:, k], slip[:, k])])
        stuck = np.linalg.norm(F) > fstick[k]
        if stuck:
            F *= fstick[k] / np.linalg.norm(F)
        assert _close(f[:, k], -F, 1e-10, np.abs(F).max()), (k, f[:, k], -F)
        if res.nstatv:  # the accumulated slip grows by the slip, where the node slides
            grow = 0.0 if stuck else np.linalg.norm(dslip[:, k])
            assert state1[0, k] == pytest.approx(state[0, k] + grow, abs=1e-14)


def test_vfric_2d_and_zero_normal_force(tmp_path_factory):
    folder, res = _built(tmp_path_factory, "coulomb", "abaqus-vfric")
    v = Vfric(compile_fortran(folder, "coulomb_vfric.f"))
    normal = np.array([[0.0, 0.6, 0.0], [1.0, 0.8, 1.0]])
    slip = np.array([[1.0, 0.8, -1.0], [0.0, -0.6, 0.0]])
    with fpe_traps():
        f, _ = v.call(np.zeros((1, 3)), res.props, slip * 0.01, np.full(3, 1e3),
                      np.array([2.0, 1.0, 0.0]), normal, slip, 1)
    assert np.allclose(f[0], [-0.6, -0.3, 0.0], rtol=1e-12, atol=0)


#: Steady sliding along local direction 1 in 2-D at pressure 1 of the turned orthotropic law
#: (1.16): the force along the slip is the dissipation per unit slip and pressure,
#: D(t1)/N = √(μx² cos² a + μy² sin² a) (the support function of the ellipse), not the
#: section of the ellipse by T2 = 0.
TURNED = fr.EllipticOrthotropic(0.6, 0.3, angle=0.4)
TAU_2D = np.sqrt(0.6**2 * np.cos(0.4) ** 2 + 0.3**2 * np.sin(0.4) ** 2)


@pytest.mark.parametrize("target", ["abaqus-fric", "abaqus-uinter", "abaqus-vfric"])
def test_2d_steady_sliding_has_no_motion_out_of_the_plane(target, tmp_path):
    """FRIC (NFDIR = 1), UINTER (NDIR = 2) and VFRIC (nDir = 2) of EllipticOrthotropic(0.6,
    0.3, angle=0.4), kt = 100: steady sliding at pressure 1 gives TAU = 0.5648."""
    res = fr.export(TURNED, target, tmp_path, kt=100.0, kn=1000.0, name="turned")
    lib = compile_fortran(tmp_path, f"turned_{target.split('-')[1]}.f")
    with fpe_traps():
        if target == "abaqus-fric":
            fric, statev, tau = Fric(lib), np.zeros(res.nstatv), np.zeros(1)
            for _ in range(200):
                _, tau, *_, statev = fric.call(0, tau, statev, [0.01], 1.0, 0.0, res.props, 1)
            force = abs(tau[0])
        elif target == "abaqus-uinter":
            u, statev = Uinter(lib), np.zeros(res.nstatv)
            rdisp = np.array([1e-3, 0.0])
            stress, _, statev, *_ = u.call(statev, rdisp, rdisp, res.props, 2)
            assert stress[0] == pytest.approx(1.0, rel=1e-12)
            for _ in range(200):
                rdisp = rdisp + [0.0, 0.01]
                stress, _, statev, *_ = u.call(statev, rdisp, [0.0, 0.01], res.props, 2)
            force = abs(stress[1])
        else:
            f, _ = Vfric(lib).call(np.zeros((max(res.nstatv, 1), 1)), res.props,
                                   [[0.01], [0.0]], [1e3], [1.0], [[0.0], [1.0]],
                                   [[1.0], [0.0]], 1)
            force = abs(f[0, 0])
    assert round(TAU_2D, 4) == 0.5648
    assert force == pytest.approx(TAU_2D, rel=1e-10)
