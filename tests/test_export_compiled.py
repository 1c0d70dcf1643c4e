"""The exported code compiled and called as its host calls it, against the library.

Each generated file is compiled (``gcc -std=c99 -Wall -Wextra -Werror``; ``gfortran`` fixed
form, 72 columns, ``-Wall -Werror -fcheck=all -ffpe-trap=invalid,zero,overflow``) and run with
floating-point traps on. The reference is :class:`frictionrules.ContactModel` (backward Euler
on (4.2), (4.3), (4.5), its consistent tangent), driven over 8 random paths of 60 increments:
forces to 1e-10 relative, tangents to 1e-8; every tangent also against central differences
(1e-5). FRIC is compared at the pressure Abaqus passes (the model's 3 × 3 tangent condensed at
fixed N), VFRIC with the law's inverse relation (1.8).
"""

import numpy as np
import pytest

import frictionrules as fr
from _export_harness import CKernel, Fric, compile_c, compile_fortran, fpe_traps

KT, KN = 100.0, 200.0
NONASSOC = fr.UserLaw("sqrt((T1/mu_x)**2 + (T2/mu_y)**2) - N", potential="sqrt(T1**2 + T2**2)",
                      params={"mu_x": 0.5, "mu_y": 0.3})
#: name -> (law, slip hardening)
LAWS = {
    "coulomb": (fr.Coulomb(0.3), None),
    "elliptic": (fr.EllipticOrthotropic(0.6, 0.3, angle=0.4), None),
    "nonassoc": (NONASSOC, None),
    "hardening": (fr.Coulomb(0.3), fr.SlipHardening(0.2, 0.05)),
    "wedge": (fr.WedgeAsperity(0.3, 0.2), None),
    "cap": (fr.EllipsoidCap(m=0.6), None),
    "dilatant": (fr.Coulomb(0.3, dilatant=True), None),
}
PATHS, STEPS = 8, 60


def _built(tmp_path_factory, key, target):
    law, hard = LAWS[key]
    folder = tmp_path_factory.mktemp(f"{key}-{target}")
    res = fr.export(law, target, folder, kt=KT, kn=KN, hardening=hard, name=key)
    return folder, res


def _model(key):
    law, hard = LAWS[key]
    return fr.ContactModel(law, kn=KN, kt=KT, hardening=hard)


def _close(a, b, tol, scale):
    d = np.abs(np.asarray(a, dtype=float) - np.asarray(b, dtype=float))
    return d.size == 0 or d.max() <= tol * scale


# ---- target c ----------------------------------------------------------------------------
@pytest.fixture(scope="module")
def c_kernels(tmp_path_factory):
    cache = {}

    def get(key):
        if key not in cache:
            folder, res = _built(tmp_path_factory, key, "c")
            cache[key] = (CKernel(compile_c(folder, f"{key}.c"), key, res.nstatv), res)
        return cache[key]
    return get


def _path(rng, i, nd=3):
    du = np.array([rng.normal(0, 0.004), rng.normal(0, 0.004), rng.normal(0, 0.002)])
    if i == 0:
        du[2] = -0.01
    if nd == 2:
        du[1] = 0.0
    return du


@pytest.mark.parametrize("key", ["coulomb", "elliptic", "nonassoc", "hardening", "wedge", "cap",
                                 "dilatant"])
def test_c_update_matches_contact_model(key, c_kernels):
    """``<name>_update`` against ``ContactModel.update(..., tangent=True)``: forces, tangents
    and the state (δᵉ, δᵖ, q) along 8 random paths of 60 increments."""
    kernel, res = c_kernels(key)
    model = _model(key)
    params = np.array(res.props)
    statuses = set()
    for path in range(PATHS):
        rng = np.random.default_rng(path)
        st, s = model.initial_state(), kernel.initial_state()
        for i in range(STEPS):
            du = _path(rng, i)
            r = model.update(st, du, tangent=True)
            with fpe_traps():
                rc, s, force, tan = kernel.update(params, s, du)
            assert rc == int(r.status), (path, i)
            statuses.add(rc)
            scale = max(np.abs(r.force).max(), 1e-2)
            assert _close(force, r.force, 1e-10, scale), (path, i, force, r.force)
            assert _close(tan, r.tangent, 1e-8, KT), (path, i, tan, r.tangent)
            st = r.state
            q = model.law_state(st).values
            assert _close(s[:3], st.elastic, 1e-10, 1e-2) and _close(s[3:6], st.plastic, 1e-10, 1e-2)
            assert _close(s[6:], np.ravel(q), 1e-10, 1.0)
    assert {0, 1} <= statuses  # stick and slip both exercised


@pytest.mark.parametrize("key", ["coulomb", "nonassoc", "hardening", "wedge", "cap"])
def test_c_tangent_is_the_derivative_of_the_force(key, c_kernels):
    """The consistent tangent against central differences of the force in the increment."""
    kernel, res = c_kernels(key)
    params = np.array(res.props)
    rng = np.random.default_rng(11)
    s, checked = kernel.initial_state(), 0
    for i in range(40):
        du = _path(rng, i)
        rc, s1, force, tan = kernel.update(params, s, du)
        if rc == 1:
            h = 1e-7
            fd = np.empty((3, 3))
            for j in range(3):
                e = np.zeros(3)
                e[j] = h
                rp, _, fp, _ = kernel.update(params, s, du + e)
                rm, _, fm, _ = kernel.update(params, s, du - e)
                fd[:, j] = (fp - fm) / (2 * h)
            if rp == rm == 1:
                assert _close(tan, fd, 1e-5, KT), (i, tan, fd)
                checked += 1
        s = s1
    assert checked >= 5


def test_c_example_compiles(tmp_path):
    """The usage example beside the C files builds with the kernel."""
    import subprocess

    from _export_harness import C_FLAGS, compiler
    res = fr.export(fr.Coulomb(0.3), "c", tmp_path, kt=KT, kn=KN)
    exe = tmp_path / "example"
    flags = [f for f in C_FLAGS if f not in ("-shared", "-fPIC")]
    out = subprocess.run([compiler("c"), *flags, "-o", str(exe), str(tmp_path / "coulomb_example.c"),
                          str(tmp_path / "coulomb.c"), "-lm"], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    run = subprocess.run([str(exe)], capture_output=True, text=True)
    assert run.returncode == 0 and "status 0" in run.stdout and len(res.files) == 4


# ---- abaqus-fric -------------------------------------------------------------------------
@pytest.fixture(scope="module")
def frics(tmp_path_factory):
    cache = {}

    def get(key):
        if key not in cache:
            folder, res = _built(tmp_path_factory, key, "abaqus-fric")
            cache[key] = (Fric(compile_fortran(folder, f"{key}_fric.f")), res)
        return cache[key]
    return get


def _fric_increment(fric, lm, tau, statev, dgam, p0, p1, props, nfdir, calls):
    """One increment as Abaqus runs it: ``calls`` calls with growing DGAM (and pressure), TAU,
    STATEV and LM reset to their start-of-increment values each time; the last one counts."""
    for k in range(1, calls + 1):
        a = k / calls
        pk = p0 + a * (p1 - p0)
        with fpe_traps():
            out = fric.call(lm, tau, statev, a * dgam, pk, pk - p0, props, nfdir)
    return out


def _condensed(C):
    """DDTDDG, DDTDDP of a 3 × 3 tangent d(T, N)/d(δt, δn): T at fixed N, and dT/dN."""
    return C[:2, :2] - np.outer(C[:2, 2], C[2, :2]) / C[2, 2], C[:2, 2] / C[2, 2]


def _fric_path(fric, res, model, path, nfdir, calls):
    """Drive FRIC and the model along one random path; yields per increment
    ``(fric outputs, model result, LM on entry, pressure)``."""
    rng = np.random.default_rng(path)
    st = model.initial_state()
    statev, tau, lm, p0 = np.zeros(res.nstatv), np.zeros(nfdir), 0, 0.0
    for i in range(STEPS):
        p1 = rng.uniform(-0.2, 1.0) if i else 0.5
        dg = rng.normal(0, 0.004, 2)
        if nfdir == 1:
            dg[1] = 0.0
        out = _fric_increment(fric, lm, tau, statev, dg[:nfdir], p0, p1, res.props, nfdir, calls)
        if lm == 2:  # entered open: no friction this increment (slip free, then closing)
            r = model.update(st, [dg[0], dg[1], 0.0])
            r = model.update(r.state, [0.0, 0.0, -(p1 - p0) / KN], tangent=True)
        else:
            r = model.update(st, [dg[0], dg[1], -(p1 - p0) / KN], tangent=True)
        yield out, r, lm, p1
        st, statev = r.state, out[8]
        tau = out[1] if lm != 2 else np.zeros(nfdir)
        lm = 2 if p1 <= 0 else (0 if lm == 2 else out[0])
        p0 = p1


@pytest.mark.parametrize("key, nfdir", [("coulomb", 2), ("elliptic", 2), ("nonassoc", 2),
                                        ("hardening", 2), ("coulomb", 1), ("elliptic", 1),
                                        ("nonassoc", 1), ("hardening", 1)])
def test_fric_matches_contact_model_at_the_pressure(key, nfdir, frics):
    """FRIC called like Abaqus (3 calls per increment, LM carried, random pressures with
    openings) against the model driven to the same pressure: TAU, the condensed tangent
    DDTDDG, DDTDDP and the internal variables. In 2-D (NFDIR = 1) the model moves with
    δt2 ≡ 0: no relative motion out of the plane."""
    fric, res = frics(key)
    model = _model(key)
    n = nfdir
    plastic = 0
    for path in range(PATHS):
        prev = model.initial_state()
        for out, r, lm, p in _fric_path(fric, res, model, path, nfdir, calls=3):
            lm_out, tau, ddg, ddp, dslip, sed, sfd, pnewdt, statev = out
            before, prev = prev, r.state
            assert pnewdt == 1.0 and np.isfinite(tau).all()
            if lm == 2:
                assert lm_out == 2
                continue
            assert lm_out == 0
            scale = max(abs(p), 1e-2)
            assert _close(tau, r.force[:n], 1e-10, scale), (path, tau, r.force)
            if p <= 0:
                assert not tau.any() and not ddg.any()
                continue
            g, dp = _condensed(r.tangent)
            assert _close(ddg, g[:n, :n], 1e-8, KT) and _close(ddp, dp[:n], 1e-8, 1.0)
            # the frictional dissipation and the plastic slip of the increment
            assert _close(sfd, r.dissipation, 1e-10, max(abs(float(r.dissipation)), 1e-6))
            assert _close(dslip, (r.state.plastic - before.plastic)[:n], 1e-10, 1e-2)
            q = np.ravel(model.law_state(r.state).values)
            virgin = model.effective_law.initial_values()
            q0 = np.array([virgin[k] for k in model.effective_law.state_names])
            assert _close(statev[:len(q)] + q0, q, 1e-10, 1.0)
            plastic += int(r.status) == 1
    assert plastic > 20


@pytest.mark.parametrize("key", ["coulomb", "nonassoc", "hardening"])
def test_fric_one_call_and_three_calls_commit_the_same(key, frics):
    """Nothing is kept between calls: the committed TAU and STATEV do not depend on how many
    times Abaqus called FRIC in the increment."""
    fric, res = frics(key)
    model = _model(key)
    one = list(_fric_path(fric, res, model, 3, 2, calls=1))
    three = list(_fric_path(fric, res, model, 3, 2, calls=3))
    for (a, _, _, _), (b, _, _, _) in zip(one, three):
        assert np.array_equal(a[1], b[1]) and np.array_equal(a[8], b[8])
        assert np.array_equal(a[2], b[2]) and np.array_equal(a[3], b[3])


@pytest.mark.parametrize("key, nfdir", [("coulomb", 2), ("elliptic", 2), ("elliptic", 1),
                                        ("nonassoc", 2), ("hardening", 2)])
def test_fric_tangent_is_the_derivative_of_tau(key, nfdir, frics):
    """DDTDDG against central differences in DGAM, DDTDDP in PRESS (1e-5)."""
    fric, res = frics(key)
    rng = np.random.default_rng(5)
    statev, tau, checked = np.zeros(res.nstatv), np.zeros(nfdir), 0
    for i in range(30):
        p = rng.uniform(0.3, 1.0)
        dg = rng.normal(0, 0.004, nfdir)
        base = fric.call(0, tau, statev, dg, p, 0.0, res.props, nfdir)
        h = 1e-7
        fd = np.empty((nfdir, nfdir))
        for j in range(nfdir):
            e = np.zeros(nfdir)
            e[j] = h
            fd[:, j] = (fric.call(0, tau, statev, dg + e, p, 0.0, res.props, nfdir)[1]
                        - fric.call(0, tau, statev, dg - e, p, 0.0, res.props, nfdir)[1]) / (2 * h)
        fdp = (fric.call(0, tau, statev, dg, p + h, h, res.props, nfdir)[1]
               - fric.call(0, tau, statev, dg, p - h, -h, res.props, nfdir)[1]) / (2 * h)
        if np.abs(base[2] - KT * np.eye(nfdir)).max() > 1e-6 * KT:  # slipping
            assert _close(base[2], fd, 1e-5, KT) and _close(base[3], fdp, 1e-5, 1.0)
            checked += 1
        statev, tau = base[8], base[1]
    assert checked >= 5


@pytest.mark.parametrize("key, unsymmetric", [("coulomb", False), ("elliptic", False),
                                             ("hardening", False), ("nonassoc", True)])
def test_fric_tangent_is_symmetric_only_for_an_associated_isotropic_law(key, unsymmetric, frics):
    """An associated law (isotropic, elliptic, with slip hardening) gives a symmetric DDTDDG,
    a non-associated one an unsymmetric one, and its snippet asks for UNSYMM=YES."""
    fric, res = frics(key)
    assert res.unsymmetric == unsymmetric
    snippet = next(p for p in res.files if p.suffix == ".inp").read_text()
    assert ("UNSYMM=YES" in snippet) == unsymmetric
    rng = np.random.default_rng(2)
    worst = 0.0
    for _ in range(20):
        dg = rng.normal(0, 0.02, 2)
        out = fric.call(0, np.zeros(2), np.zeros(res.nstatv), dg, 0.5, 0.0, res.props, 2)
        worst = max(worst, abs(out[2][0, 1] - out[2][1, 0]))
    assert (worst > 1e-3 * KT) if unsymmetric else (worst <= 1e-12 * KT)


def test_fric_open_and_nonpositive_pressure(frics):
    """LM = 2 on entry returns at once (nothing touched); PRESS <= 0 gives TAU = 0, no NaN."""
    fric, res = frics("coulomb")
    tau = np.array([0.1, 0.2])
    out = fric.call(2, tau, np.zeros(res.nstatv), np.array([0.1, 0.0]), 1.0, 0.0, res.props, 2)
    assert out[0] == 2 and np.array_equal(out[1], tau)
    for p in (0.0, -1.0):
        with fpe_traps():
            out = fric.call(0, tau, np.zeros(res.nstatv), np.array([0.1, 0.0]), p, 0.0,
                            res.props, 2)
        assert out[0] == 0 and not out[1].any() and np.isfinite(out[2]).all()
