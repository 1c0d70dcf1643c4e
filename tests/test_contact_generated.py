"""The compiled return mapping generated from a law's symbolic form (§4, (4.1)–(4.7)).

It must give what the NumPy return mapping derived from the same form gives, for every
built-in law and for a user law written for it, on random paths; the invariants f <= tol after
every plastic step and dissipation >= 0 must hold over 10^3-step paths for every law,
hardening included.
"""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from test_contact import LAWS as BUILT_IN

from frictionrules import (ContactModel, Coulomb, EllipticOrthotropic, Huber, SlipHardening,
                           TransformedCoulomb, UserLaw)
from frictionrules.contact._generated import generated_kernel, module_source
from frictionrules.contact.state import PLASTIC
from frictionrules.laws import HardenedLaw
from frictionrules.laws._symbolic import form_of

KN, KT = 100.0, 80.0

#: The built-in laws of tests/test_contact.py and two with slip hardening.
LAWS = {
    **BUILT_IN,
    "coulomb_hardening": HardenedLaw(Coulomb(0.4), SlipHardening(0.5, 0.02)),
    "elliptic_softening": HardenedLaw(EllipticOrthotropic(0.3, 0.6, angle=0.4),
                                      SlipHardening(-0.3, 0.05)),
}


def user_law_for(law) -> UserLaw:
    """A UserLaw with the same f, g, parameters, internal variables and evolution as ``law``."""
    form = form_of(law)
    state = law.initial_values() if form.state else None
    return UserLaw(form.f, potential=form.g, params=dict(zip(form.param_names, form.values)),
                   state=state, rates=dict(zip(form.state_names, form.rates)) or None)


def _path(seed, n, steps):
    rng = np.random.default_rng(seed)
    closing = np.tile([0.0, 0.0, -0.01], (n, 1))
    return [closing] + [rng.normal(0.0, [0.01, 0.01, 0.003], (n, 3)) + [0.004, 0.0, 0.0]
                        for _ in range(steps)]


def _compare(a, b, tol, du):
    """Two update results agree: same statuses, forces, state and tangents to ``tol``
    relative to the force (stiffness) scale of the batch; the dissipation to ``tol`` relative
    to the work scale |σ| |Δδ| (an associated dilatant law dissipates nothing: roundoff)."""
    np.testing.assert_array_equal(a.status, b.status)
    F = max(np.abs(b.force).max(), 1e-300)
    np.testing.assert_allclose(a.force, b.force, rtol=0, atol=tol * F)
    for x, y in [(a.state.plastic, b.state.plastic), (a.state.elastic, b.state.elastic),
                 (a.state.kappa, b.state.kappa), (a.state.beta, b.state.beta)]:
        np.testing.assert_allclose(x, y, rtol=0, atol=tol * max(np.abs(y).max(), 1e-3))
    np.testing.assert_allclose(a.dissipation, b.dissipation, rtol=0,
                               atol=tol * F * np.abs(du).max())
    if b.tangent is not None:
        np.testing.assert_allclose(a.tangent, b.tangent, rtol=0, atol=1e3 * tol * max(KN, KT))


@pytest.mark.parametrize("name", sorted(LAWS))
@settings(max_examples=3, deadline=None)
@given(seed=st.integers(0, 2**31))
def test_generated_return_matches_numpy_return_mapping(name, seed):
    """Compiled (generated) and NumPy return maps of the same law agree to 1e-12 along a path,
    each path continued from the generic result (the tangent with ``tangent=True``, which
    always runs the generated kernel)."""
    m = ContactModel(LAWS[name], KN, KT)
    s = m.initial_state(48)
    for du in _path(seed, 48, 6):
        a = m.update(s, du, tangent=True, compiled=True)
        b = m.update(s, du, tangent=True, compiled=False)
        _compare(a, b, 1e-12, du)
        s = b.state


@pytest.mark.parametrize("name", sorted(LAWS))
def test_user_law_written_for_a_law_matches_it(name):
    """A UserLaw with the same f, g and evolution runs the same generated return and agrees
    with the built-in law's NumPy return map to 1e-12 (the cap is defined for N >= 0 only, a
    user law everywhere: their returns agree on paths that stay closed)."""
    law = LAWS[name]
    user = user_law_for(law)
    mu, mb = ContactModel(user, KN, KT), ContactModel(law, KN, KT)
    su, sb = mu.initial_state(48), mb.initial_state(48)
    for du in _path(3, 48, 6):
        if law.defined_in_tension:
            du = du.copy()
            du[:, 2] = -np.abs(du[:, 2])
        a = mu.update(su, du, tangent=True)
        b = mb.update(sb, du, tangent=True, compiled=False)
        _compare(a, b, 1e-12, du)
        su, sb = a.state, b.state


@pytest.mark.parametrize("name", sorted(LAWS))
def test_thousand_step_paths_keep_consistency_and_dissipation(name):
    """Over 10^3 random steps of 16 contacts: f <= 1e-10 (relative) after every step, |f| at
    plastic steps, and the plastic work of every step >= 0 (up to roundoff)."""
    m = ContactModel(LAWS[name], KN, KT)
    s = m.initial_state(16)
    for du in _path(11, 16, 1000):
        r = m.update(s, du * [0.2, 0.2, 0.1])
        s = r.state
        res = m.yield_residual(s)
        assert res.max() <= 1e-10
        assert np.abs(res[r.status == PLASTIC]).max(initial=0.0) <= 1e-10
        scale = np.linalg.norm(r.force, axis=-1) * (np.linalg.norm(du, axis=-1)
                                                    + np.linalg.norm(s.elastic, axis=-1))
        assert np.all(r.dissipation >= -1e-12 * scale)


@pytest.mark.parametrize("law", [Huber(0.5, 0.3), TransformedCoulomb(0.5, 0.3)],
                         ids=["huber", "transformed"])
def test_long_random_paths_converge(law):
    """64 contacts, kn = 100, kt = 80, increments N(0, (2e-3, 2e-3, 5e-4)) + (1e-3, 0, 0) per
    step after closing by 0.01: the return mapping converges over 1200 steps (κ grows past 1.5
    contact-widths, where it used to fail) with f <= 1e-10 at every step."""
    m = ContactModel(law, kn=100, kt=80)
    rng = np.random.default_rng(0)
    s = m.update(m.initial_state(64), [0.0, 0.0, -0.01]).state
    for _ in range(1200):
        du = rng.normal(0.0, [2e-3, 2e-3, 5e-4], size=(64, 3)) + [1e-3, 0.0, 0.0]
        s = m.update(s, du).state
        assert m.yield_residual(s).max() <= 1e-10
    assert s.kappa.mean() > 1.2


def test_generated_module_is_reproducible_and_shared_per_structure():
    """The module text depends on the law's structure only (same bytes for other parameter
    values) and names the package version; laws of one structure share one kernel."""
    import frictionrules
    a, b = UserLaw("sqrt(T1**2 + T2**2) - mu*N", params={"mu": 0.3}), \
        UserLaw("sqrt(T1**2 + T2**2) - mu*N", params={"mu": 0.5})
    text = module_source(form_of(a), "UserLaw")
    assert text == module_source(form_of(b), "UserLaw")
    assert f"frictionrules {frictionrules.__version__}" in text.splitlines()[0]
    assert generated_kernel(a) is generated_kernel(b)


def test_user_law_at_the_apex_is_finite():
    """A cone's gradient is 0/0 at T = 0: the generated return uses the minimal-norm
    subgradient there (a pure normal step stays elastic, a return through the apex opens)."""
    m = ContactModel(UserLaw("sqrt(T1**2 + T2**2) - mu*N", params={"mu": 0.3}), KN, KT)
    r = m.update(m.initial_state(2), [[0.0, 0.0, -0.01], [0.0, 0.0, 0.01]], tangent=True)
    assert np.all(np.isfinite(r.force)) and np.all(np.isfinite(r.tangent))
    np.testing.assert_allclose(r.force[0], [0.0, 0.0, 1.0])
    np.testing.assert_array_equal(r.force[1], 0.0)


@pytest.mark.parametrize("nq", [0, 1, 2, 3])
def test_kernel_layout_is_the_codegen_layout(nq):
    """The compiled kernel's offsets are those of the one layout the code generator writes."""
    from frictionrules.codegen import local_layout
    from frictionrules.contact._kernel_law import _layout
    layout = local_layout(nq)
    names = ("df", "dfq", "dg", "hgg", "hgq", "h", "dhs", "dhq")
    size = sum(int(np.prod(shape)) for _, shape in layout.values())
    assert _layout.py_func(nq) == tuple(layout[k][0] for k in names) + (size,)


def _entry_loop():
    """A compiled loop of the kind the grain assemblies' dynamic engine runs: one call of the
    compiled entry ``contact_update`` per contact, the law given by its ``CompiledLaw``."""
    from numba import njit

    from frictionrules.contact import contact_update, workspace

    @njit
    def loop(fn, row, S, DU, max_depth):
        n = S.shape[0]
        S1, RES = np.empty_like(S), np.empty((n, 6))
        status, failed = np.empty(n, np.int64), np.zeros(n, np.bool_)
        ws = workspace(int(row[3]))
        tan = np.empty((3, 3))
        for i in range(n):
            status[i], failed[i] = contact_update(fn, row, S[i], DU[i], S1[i], RES[i], ws,
                                                  max_depth, False, tan)
        return S1, RES, status, failed

    return loop


@pytest.mark.parametrize("name, scales", [("wedge", (0.01, 0.3, 3.0)), ("coulomb_hardening", (0.01, 0.3, 3.0)),
                                          ("cap", (0.01, 0.1)), ("elliptic_softening", (0.01, 0.1))])
def test_compiled_entry_with_substeps_is_the_numpy_return(name, scales):
    """The one compiled entry, called per contact from a user's compiled loop with substeps
    (halving where Newton fails, as ``generic_step`` does), gives the NumPy return mapping's
    forces and state, large increments included (the wedge's whole step fails at a few
    contacts of 0.3 and 3.0)."""
    from frictionrules.contact.layout import RES_DISSIPATION, RES_FORCE, STATE_E, STATE_P, STATE_Q
    law = LAWS[name]
    model = ContactModel(law, kn=KN, kt=KT)
    compiled = model.compiled()
    loop = _entry_loop()
    rng = np.random.default_rng(7)
    n = 256
    state = model.initial_state(n)
    for scale in scales:
        du = rng.normal(0.0, [scale, scale, 0.3 * scale], (n, 3)) + [0.0, 0.0, -0.5 * scale]
        q = model._q(state)
        S = np.concatenate((state.elastic, state.plastic, q), axis=1)
        S1, res, status, failed = loop(compiled.fn, compiled.row, S, du, 10)
        ref = model.update(state, du, compiled=False)
        assert not failed.any()
        F = max(np.abs(ref.force).max(), 1e-300)
        np.testing.assert_allclose(res[:, RES_FORCE:RES_FORCE + 3], ref.force, rtol=0, atol=1e-9 * F)
        np.testing.assert_allclose(S1[:, STATE_E:STATE_E + 3], ref.state.elastic, rtol=0, atol=1e-9 * scale)
        np.testing.assert_allclose(S1[:, STATE_P:STATE_P + 3], ref.state.plastic, rtol=0, atol=1e-9 * scale)
        np.testing.assert_allclose(S1[:, STATE_Q:], model._q(ref.state), rtol=0, atol=1e-9)
        np.testing.assert_allclose(res[:, RES_DISSIPATION], ref.dissipation, rtol=0,
                                   atol=1e-9 * F * scale)
        state = ref.state


@pytest.mark.parametrize("compiled", [False, True])
def test_kink_rule_is_one_on_every_path(compiled):
    """The Huber ellipse f = |T| - N μ(θ) (1.16) written as a user law is 0/0 at T = 0. By
    the one kink rule (frictionrules._returnspec: the largest f on a circle of radius
    1e-9 (|T| + |N|) around T, here r - 0.3 N < 0) a pure compression is elastic, with and
    without the compiled return, as for the built-in Huber law: force (0, 0, kn δ), tangent E."""
    user = UserLaw("sqrt(T1**2+T2**2) - N*(0.3*T1**2+0.5*T2**2)/(T1**2+T2**2)",
                   "sqrt(T1**2+T2**2)")
    for law in (user, Huber(0.3, 0.5)):
        model = ContactModel(law, kn=1, kt=1)
        r = model.update(model.initial_state(), [0, 0, -0.1], tangent=True, compiled=compiled)
        assert int(r.status) == 0
        assert np.array_equal(r.force, [0.0, 0.0, 0.1])
        assert np.array_equal(r.tangent, np.diag([1.0, 1.0, -1.0]))


#: A Drucker–Prager-like user cone with a non-associated dilatant rule: its flow direction
#: (-D∇g) does not turn along the return, as for Coulomb.
DP_CONE = UserLaw("sqrt(T1**2 + T2**2) - 0.5*N", potential="sqrt(T1**2 + T2**2) - 0.2*N")


@pytest.mark.parametrize("law, kind, linear", [
    (Coulomb(0.4), "radial", True), (Coulomb(0.4, dilatant=True), "radial", True),
    (UserLaw("sqrt(T1**2 + T2**2) - 0.4*N", potential="sqrt(T1**2 + T2**2)"), "radial", True),
    (DP_CONE, "radial", True), (LAWS["coulomb_hardening"], "radial", False),
    (EllipticOrthotropic(0.3, 0.6, angle=0.4), "elliptic", False),
    (LAWS["cap"], "affine", False), (LAWS["wedge"], "generic", False)])
def test_return_structure_recognised_from_the_symbolic_form(law, kind, linear):
    """Radial: ∂_v ∇g = 0 and ∂_v h = 0 along v = (-D∇g, h) (closed form where ∂_v ∇f = 0 too);
    elliptic: g = √(TᵀAT), ∇_T f = c ∇_T g; affine: ∇g affine in the forces (the cap)."""
    from frictionrules._returnspec import (RETURN_AFFINE, RETURN_ELLIPTIC, RETURN_GENERIC,
                                           RETURN_RADIAL)
    from frictionrules.codegen import return_structure
    s = return_structure(form_of(law))
    assert s.kind == {"radial": RETURN_RADIAL, "elliptic": RETURN_ELLIPTIC,
                      "affine": RETURN_AFFINE, "generic": RETURN_GENERIC}[kind]
    assert s.linear == linear


@pytest.mark.parametrize("law", [Coulomb(0.4), Coulomb(0.4, dilatant=True), DP_CONE,
                                 LAWS["coulomb_hardening"],
                                 EllipticOrthotropic(0.3, 0.6, angle=0.4), LAWS["cap"]])
def test_special_returns_equal_the_newton_return(law):
    """The radial, elliptic and affine-flow returns against the general Newton return of the same compiled
    kernel (the law's row with the return kind set to the general one), to 1e-12, on random
    increments from a loaded state — elastic, plastic, open and through the apex included."""
    from frictionrules.contact._generated import generated_kernel, law_row
    from frictionrules.contact._kernel_batch import Batch
    from frictionrules.contact.layout import RET_KIND
    model = ContactModel(law, kn=KN, kt=KT)
    rng = np.random.default_rng(5)
    n = 4000
    q = model._q(model.initial_state(n))
    e = np.column_stack((rng.normal(0, 0.003, (n, 2)), -np.abs(rng.normal(0, 0.01, n))))
    batch = Batch(e, np.zeros((n, 3)), np.ascontiguousarray(q), rng.normal(0, 0.01, (n, 3)))
    kernel = generated_kernel(law)
    row = law_row(law, KT, KN)
    general = row.copy()
    general[RET_KIND] = 0
    for tangent in (False, True):
        a, b = kernel.run(row, batch, tangent), kernel.run(general, batch, tangent)
        assert (a.status == PLASTIC).sum() > n // 4
        np.testing.assert_array_equal(a.status, b.status)
        # Each field to 1e-12 of its scale; the dissipation of the work scale |σ| |Δδ| (an
        # associated dilatant law dissipates nothing: round-off).
        work = np.abs(b.force).max() * np.abs(batch.du).max()
        for field in ("e", "p", "q", "force", "dlam", "dissipation", "slip") + ("tangent",) * tangent:
            x, y = getattr(a, field), getattr(b, field)
            scale = work if field == "dissipation" else np.abs(y).max(initial=0.0)
            np.testing.assert_allclose(x, y, rtol=1e-12, atol=1e-12 * scale, err_msg=field)


@pytest.mark.parametrize("dilatant", [False, True])
def test_hand_written_coulomb_kernel_is_the_derived_return(dilatant):
    """The hand-written Coulomb kernel (radial return (1.4)–(1.6) in closed form, run where no
    tangent is asked for) gives the NumPy return mapping derived from the symbolic form and
    the generated step to 1e-12, on random paths (open, elastic and plastic contacts)."""
    from frictionrules.contact._generated import generated_step
    from frictionrules.contact._kernel_batch import batch_of, step_of
    from frictionrules.contact._kernels import run_kernel
    law = Coulomb(0.4, dilatant=dilatant)
    m = ContactModel(law, KN, KT)
    assert m.kernel() == "coulomb"
    s = m.initial_state(200)
    for du in _path(5, 200, 6):
        a = m.update(s, du)
        b = m.update(s, du, compiled=False)
        _compare(a, b, 1e-12, du)
        e, p, q = s.elastic, s.plastic, m._q(s)
        hand = step_of(run_kernel(law.closed_form_return(), KT, KN, batch_of(e, p, q, du)))
        gen, failed, _ = generated_step(law, KT, KN, e, p, q, du, False)
        assert not failed.any()
        for field in ("e", "p", "force", "dlam", "status", "dissipation", "slip"):
            x, y = getattr(hand, field), getattr(gen, field)
            np.testing.assert_allclose(x, y, rtol=0, atol=1e-12 * max(np.abs(y).max(), 1.0),
                                       err_msg=field)
        s = b.state
