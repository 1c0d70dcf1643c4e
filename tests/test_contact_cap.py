"""The ellipsoidal cap (4.9), its hardening modulus (4.7)/(4.11), rate form (4.10) and the
behaviour of Fig. 10c."""

import numpy as np
import pytest
import sympy

from frictionrules import ContactModel, EllipsoidCap, FrictionRulesError, drive
from frictionrules.contact import AreaGrowth, AreaHardening
from frictionrules.laws.cap import state_symbols
from frictionrules.contact.state import PLASTIC

M = 0.6


def test_hardening_modulus_eq_4_11_from_eq_4_7():
    """(4.7) H = -[f_κ |g_t| + f_β B g_n] with g = f (4.8) equals the printed (4.11)."""
    T1, T2, N, kappa, beta, m = sympy.symbols("T1 T2 N kappa beta m", positive=True)
    A = sympy.Function("A")(kappa, beta)
    B = sympy.Function("B")(beta)
    f = (N - A) ** 2 + T1**2 / m**2 + T2**2 / m**2 - A**2
    g_t = sympy.sqrt(sympy.diff(f, T1) ** 2 + sympy.diff(f, T2) ** 2)
    H_47 = -(sympy.diff(f, kappa) * g_t + sympy.diff(f, beta) * B * sympy.diff(f, N))
    H_411 = 2 * (sympy.diff(f, beta) * (A - N) * B - sympy.diff(f, kappa) * sympy.sqrt((T1**2 + T2**2) / m**4))
    assert sympy.simplify(H_47 - H_411) == 0
    # Explicitly (f_A = -2N): H = 4N [A_β B (N - A) + A_κ |T|/m²]; its β part changes sign on the
    # critical-state line N = A: hardening on the compactive side, softening on the dilatant one.
    H_explicit = 4 * N * (sympy.diff(A, beta) * B * (N - A)
                          + sympy.diff(A, kappa) * sympy.sqrt(T1**2 + T2**2) / m**2)
    assert sympy.simplify(H_47 - H_explicit) == 0
    # (4.10): the plastic rates λ̇ (g_n, g_t1, g_t2) with g = f are 2(N-A), 2T_i/m^2 times ḟ_T/H.
    assert sympy.simplify(sympy.diff(f, N) - 2 * (N - A)) == 0
    assert sympy.simplify(sympy.diff(f, T1) - 2 * T1 / m**2) == 0


def test_hardening_modulus_method_matches_symbolic():
    cap = EllipsoidCap(M)
    T, N, kap, bet = np.array([0.3, 0.2]), 0.7, 0.02, 0.45
    f, _ = cap.symbolic()
    from frictionrules.laws.symbols import N as sN, T1 as sT1, T2 as sT2
    k, b = state_symbols()
    subs = {sT1: T[0], sT2: T[1], sN: N, k: kap, b: bet}
    gt = sympy.sqrt(sympy.diff(f, sT1) ** 2 + sympy.diff(f, sT2) ** 2)
    Bsym = cap.B.symbolic(b)
    H = -(sympy.diff(f, k) * gt + sympy.diff(f, b) * Bsym * sympy.diff(f, sN))
    assert cap.hardening_modulus(T, N, kap, bet) == pytest.approx(float(H.subs(subs)), rel=1e-12)


def test_cap_geometry_eq_4_9():
    """(4.9) passes through the origin and N = 2A; its top N = A, |T| = mA lies on |T| = mN."""
    cap = EllipsoidCap(M)
    A = float(cap.A(0.0, 0.5))
    assert A == pytest.approx(1.0)
    for T, N in [([0, 0], 0.0), ([0, 0], 2 * A), ([M * A, 0], A), ([0, M * A], A)]:
        assert cap.limit(T, N, 0.0, 0.5) == pytest.approx(0.0, abs=1e-14)
    grad = cap.limit_gradient([M * A, 0], A, 0.0, 0.5)
    assert grad[2] == pytest.approx(0.0)          # no normal slip on the critical-state line


def test_default_hardening_functions():
    A, B = AreaHardening(), AreaGrowth()
    assert A(0.0, 0.5) == pytest.approx(1.0)
    assert A(1e3, 0.5) == pytest.approx(1.0 * (1 + A.h))
    assert B(0.5) > 0 and B(1e-9) == pytest.approx(0.0, abs=1e-6)
    with pytest.raises(FrictionRulesError, match="p"):
        AreaHardening(p=-1.0)
    with pytest.raises(FrictionRulesError, match="A"):
        EllipsoidCap(M, A=1.0)
    with pytest.raises(FrictionRulesError, match="normal_ratio"):
        EllipsoidCap(M, normal_ratio=0.0)


def _shear_at(N, model, steps=300, slip=0.8):
    return drive(model, [{"N": N, "dt1": 0.0, "T2": 0.0, "steps": 10}, {"dt1": slip, "steps": steps}])


@pytest.fixture(scope="module")
def fig10c():
    model = ContactModel(EllipsoidCap(M), kn=100.0, kt=100.0)
    return {N: _shear_at(N, model) for N in (0.4, 1.6)}


def test_fig_10c_low_normal_force_peak_then_softening(fig10c):
    """Below A0 the contact dilates (δnᵖ > 0), loses area (β falls) and T falls after a peak."""
    r = fig10c[0.4]
    T = r.force[:, 0]
    k = int(np.argmax(T))
    assert 10 < k < len(T) - 50
    assert T[k] > 1.5 * T[-1]
    assert np.all(np.diff(T[k:]) <= 1e-12)
    assert r.plastic[-1, 2] > 0 and r.beta[-1] < r.beta[0]
    assert T[-1] / 0.4 == pytest.approx(M, rel=0.02)


def test_fig_10c_high_normal_force_hardening(fig10c):
    """Above A0 the contact compacts (δnᵖ < 0), gains area and T rises to its asymptote."""
    r = fig10c[1.6]
    T = r.force[:, 0]
    first_yield = int(np.argmax(r.status == PLASTIC))
    yield_T = T[first_yield] if first_yield > 10 else T[11]
    assert T[-1] > 1.3 * yield_T
    assert r.plastic[-1, 2] < 0 and r.beta[-1] > r.beta[0]
    assert T[-1] / 1.6 == pytest.approx(M, rel=0.02)
    # The rise is monotonic up to a small overshoot of slip hardening (the paper's B', B_c).
    assert T.max() <= 1.01 * M * 1.6


def test_fig_10c_common_asymptote(fig10c):
    """Both asymptotes lie on one line through the origin, T/N -> m."""
    ratios = [fig10c[N].force[-1, 0] / N for N in (0.4, 1.6)]
    assert ratios[0] == pytest.approx(ratios[1], rel=0.03)


@pytest.mark.parametrize("omega", [1.0, 0.3])
def test_cap_kernel_matches_generic(omega):
    m = ContactModel(EllipsoidCap(M, normal_ratio=omega), 100.0, 50.0)
    rng = np.random.default_rng(3)
    n = 400
    s = m.initial_state((n,))
    for _ in range(3):
        du = np.column_stack((rng.normal(0, 0.01, (n, 2)), rng.normal(-0.004, 0.006, n)))
        a = m.update(s, du, tangent=True)
        b = m.update(s, du, tangent=True, compiled=False)
        np.testing.assert_array_equal(a.status, b.status)
        for x, y in [(a.force, b.force), (a.state.plastic, b.state.plastic), (a.state.kappa, b.state.kappa),
                     (a.state.beta, b.state.beta), (a.tangent, b.tangent)]:
            np.testing.assert_allclose(x, y, rtol=1e-8, atol=1e-11)
        s = a.state


def test_plastic_rates_eq_4_10_under_force_control():
    """(4.10) with ḟ_T = ∇f·σ̇: δ̇tᵖ = (ḟ_T/H) 2T/m², and δ̇nᵖ = -(ḟ_T/H) 2(N - A) in our
    opening-positive convention (the paper's sign is for closure positive)."""
    cap = EllipsoidCap(M)
    model = ContactModel(cap, 100.0, 100.0)
    start = drive(model, [{"N": 1.5, "dt1": 0.0, "T2": 0.0, "steps": 5}, {"dt1": 0.008, "T2": 0.0, "steps": 4}])
    s = start.final
    F = start.force[-1]
    assert start.status[-1] == PLASTIC
    eps = 1e-6
    target = F + eps * np.array([1.0, 0.3, -0.2])
    r = drive(model, [{"T1": target[0], "T2": target[1], "N": target[2]}], state=s)
    dp = r.plastic[-1] - s.plastic
    grad = cap.limit_gradient(F[:2], F[2], s.kappa, s.beta)
    fT = grad[:3] @ (target - F)
    H = cap.hardening_modulus(F[:2], F[2], s.kappa, s.beta)
    A = float(cap.A(s.kappa, s.beta))
    expected = fT / H * np.array([2 * F[0] / M**2, 2 * F[1] / M**2, -2 * (F[2] - A)])
    np.testing.assert_allclose(dp, expected, rtol=1e-4, atol=1e-5 * np.abs(expected).max())
