"""SymPy derivations behind the two-flank closed forms (2.9)-(2.17) and their errata."""

import numpy as np
import sympy as sp

a1, a2, mu, Q, T, phi = sp.symbols("alpha1 alpha2 mu Q T phi", real=True)
Tx, Ty = sp.symbols("T_x T_y", real=True)
N1, N2 = sp.symbols("N1 N2", real=True)
n1 = sp.Matrix([-sp.sin(a1), 0, sp.cos(a1)])
n2 = sp.Matrix([sp.sin(a2), 0, -sp.cos(a2)])


def test_eq_2_10_is_equilibrium_with_the_wedge_normals():
    """(2.10): F + N1 (n1 - mu y) + N2 (n2 - mu y) = 0 for sliding along +y, F = (Tx, Ty, -Q)."""
    y = sp.Matrix([0, 1, 0])
    F = sp.Matrix([Tx, Ty, -Q])
    eqs = F + N1 * (n1 - mu * y) + N2 * (n2 - mu * y)
    paper = [Tx - (N1 * sp.sin(a1) - N2 * sp.sin(a2)), Ty - mu * (N1 + N2),
             Q - (N1 * sp.cos(a1) - N2 * sp.cos(a2))]
    assert [sp.simplify(e + s * p) for e, p, s in zip(eqs, paper, (-1, -1, 1))] == [0, 0, 0]


def test_eq_2_11_corrected_sign_of_N2():
    sol = sp.solve([T * sp.sin(phi) - (N1 * sp.sin(a1) - N2 * sp.sin(a2)),
                    T * sp.cos(phi) - mu * (N1 + N2)], [N1, N2], dict=True)[0]
    s1, s2 = sp.sin(a1), sp.sin(a2)
    N1_paper = T * (sp.cos(phi) / mu + sp.sin(phi) / s2) * s2 / (s1 + s2)
    N2_paper = T * (sp.cos(phi) / mu + sp.sin(phi) / s1) * s1 / (s1 + s2)
    N2_fixed = T * (sp.cos(phi) / mu - sp.sin(phi) / s1) * s1 / (s1 + s2)
    assert sp.simplify(sol[N1] - N1_paper) == 0
    assert sp.simplify(sol[N2] - N2_fixed) == 0
    assert sp.simplify(sol[N2] - N2_paper) != 0


def test_eq_2_12_plane_of_the_two_flank_mechanism():
    sol = sp.solve([Tx - (N1 * sp.sin(a1) - N2 * sp.sin(a2)), Ty - mu * (N1 + N2)], [N1, N2])
    f3 = sp.expand((sol[N1] * sp.cos(a1) - sol[N2] * sp.cos(a2) - Q) * mu * (sp.sin(a1) + sp.sin(a2)))
    paper = Tx * (sp.cos(a1) + sp.cos(a2)) * mu + Ty * sp.sin(a2 - a1) - Q * (sp.sin(a1) + sp.sin(a2)) * mu
    assert sp.simplify(f3 - sp.expand_trig(paper)) == 0


def test_eq_2_9_is_the_squared_wedge_limit():
    """(2.9) = |F_t|^2 - mu^2 N^2 on the flank (sign of N free: the quadric has both nappes)."""
    F = sp.Matrix([Tx, Ty, -Q])
    for n in (n1, n2):
        a = a1 if n is n1 else a2
        Fn = (F.T * n)[0]
        f = (F.T * F)[0] - Fn**2 - mu**2 * Fn**2
        paper = (Tx**2 * (sp.cos(a)**2 - mu**2 * sp.sin(a)**2) - Tx * Q * sp.sin(2 * a) * (1 + mu**2)
                 + Ty**2 + Q**2 * (sp.sin(a)**2 - mu**2 * sp.cos(a)**2))
        assert sp.simplify(sp.expand_trig(f - paper)) == 0


def test_climbing_condition_of_one_flank_mechanism():
    """Sliding on flank 1 alone along its in-plane load: V.n2 = T1 sin(alpha2 - alpha1) / |F_t|,
    so the mechanism is admissible only when the block climbs (T1 >= 0)."""
    t1 = sp.Matrix([sp.cos(a1), 0, sp.sin(a1)])     # up-slope of flank 1
    T1, T2 = sp.symbols("T1 T2", real=True)
    V = T1 * t1 + T2 * sp.Matrix([0, 1, 0])          # times 1/|F_t|
    assert sp.simplify((V.T * n2)[0] - T1 * sp.sin(a2 - a1)) == 0


def test_corrected_eq_2_16_associated_two_flank_mechanism():
    """V = (sin rho / cos delta) b + c y with c^2 = 1 - sin^2 rho / cos^2 delta makes the angle
    rho with both flanks, and the limit plane V.F = 0 is |Ty| = kappa (Q sin m - Tx cos m)."""
    rho = sp.Symbol("rho", positive=True)
    d = (sp.pi + a1 - a2) / 2
    m = (a1 + a2) / 2
    c = sp.sqrt(1 - sp.sin(rho)**2 / sp.cos(d)**2)
    b = sp.Matrix([sp.cos(m), 0, sp.sin(m)])
    V = sp.sin(rho) / sp.cos(d) * b + c * sp.Matrix([0, 1, 0])
    for n in (n1, n2):
        assert sp.simplify(sp.expand_trig((V.T * n)[0] - sp.sin(rho))) == 0
    assert sp.simplify((V.T * V)[0] - 1) == 0
    F = sp.Matrix([Tx, Ty, -Q])
    kappa = sp.sin(rho) / sp.sqrt(sp.cos(d)**2 - sp.sin(rho)**2)
    plane = sp.solve((V.T * F)[0], Ty)[0]
    diff = plane - kappa * (Q * sp.sin(m) - Tx * sp.cos(m))
    # sympy cannot fix the branch of the square roots: check at points of the domain
    # 0 < alpha1 < pi/2 < alpha2 < pi, delta + rho < pi/2
    for vals in ({a1: 1.0, a2: 2.6, rho: 0.3, Q: 1.0, Tx: 0.4},
                 {a1: 0.3, a2: 2.0, rho: 0.2, Q: 2.0, Tx: -1.0},
                 {a1: np.pi / 3, a2: 5 * np.pi / 6, rho: 0.46, Q: 1.0, Tx: 0.1}):
        assert abs(float(diff.subs(vals))) < 1e-12
    # the non-associated line (2.12) in the same variables: kappa -> mu / cos(delta)
    sol = sp.solve([Tx - (N1 * sp.sin(a1) - N2 * sp.sin(a2)), Ty - mu * (N1 + N2),
                    Q - (N1 * sp.cos(a1) - N2 * sp.cos(a2))], [N1, N2, Ty], dict=True)[0]
    assert sp.simplify(sp.expand_trig(sol[Ty] - mu / sp.cos(d) * (Q * sp.sin(m) - Tx * sp.cos(m)))) == 0
