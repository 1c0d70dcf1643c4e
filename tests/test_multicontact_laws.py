"""Many-contact problems with the paper's non-associated rules (the law path): small problems
against an independent solve by regime enumeration, the natural-map error at solutions,
dissipation >= 0, the associated limit, refusals.

The independent solve writes f and g of each law again here (SymPy, in FCLIB's variables
``r = (r_N, r_T)``, ``T = -r_T``, ``N = r_N``), enumerates every contact's regime —
separated (``r = 0``, ``u_N >= 0``), stick (``u = 0``, ``F(r) <= 0``), sliding (``F(r) = 0``,
``u = -λ ∇G(r)``, ``λ >= 0``) — solves each combination's equations with
``scipy.optimize.root`` from several starts and keeps the solutions satisfying every
inequality. No kernel of the library is used for it.
"""

from __future__ import annotations

import functools
import itertools

import numpy as np
import pytest
import sympy
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import root

from frictionrules import (Coulomb, EllipticOrthotropic, FrictionContactProblem, FrictionRulesError, Huber,
                           SlipHardening, TransformedCoulomb, UserLaw, solve)
from frictionrules.multicontact import contact_dissipation, law_error

rN, r1, r2 = sympy.symbols("rN r1 r2", real=True)


def _frame(angle):
    """The force in the law's principal frame, T = -r_T."""
    c, s = sympy.cos(angle), sympy.sin(angle)
    T1, T2 = -r1, -r2
    return c * T1 + s * T2, -s * T1 + c * T2


def transformed_coulomb(mx, my, angle):
    """(1.17)-(1.18): the ellipse of (1.9) as limit, g = sqrt(T1'^2/mx + T2'^2/my)."""
    a, b = _frame(angle)
    return sympy.sqrt((a / mx) ** 2 + (b / my) ** 2) - rN, sympy.sqrt(a**2 / mx + b**2 / my)


def huber(m1, m2, angle):
    """(1.16): |T| = N (m1 cos^2 + m2 sin^2) of the force's angle, g = |T|."""
    a, b = _frame(angle)
    rho2 = r1**2 + r2**2
    return sympy.sqrt(rho2) - rN * (m1 * a**2 + m2 * b**2) / rho2, sympy.sqrt(rho2)


def elliptic_user():
    """A UserLaw's f and g (g != f in the plane), as written below in USER_LAWS."""
    return (sympy.sqrt(r1**2 + 4 * r2**2) - sympy.Rational(1, 2) * rN, sympy.sqrt(r1**2 + r2**2))


def dilatant_user():
    """A dilatant, tangentially non-associated UserLaw: g = sqrt(T1^2 + 2 T2^2) - 0.2 N."""
    return (sympy.sqrt(r1**2 + r2**2) - sympy.Rational(1, 2) * rN,
            sympy.sqrt(r1**2 + 2 * r2**2) - sympy.Rational(1, 5) * rN)


def coulomb(mu):
    return sympy.sqrt(r1**2 + r2**2) - mu * rN, sympy.sqrt(r1**2 + r2**2)


#: (library law, its f and g written independently in FCLIB's variables)
LAWS = {
    "transformed": (TransformedCoulomb(0.6, 0.3, angle=0.4), transformed_coulomb(0.6, 0.3, 0.4)),
    "huber": (Huber(0.6, 0.45, angle=-0.3), huber(0.6, 0.45, -0.3)),
    "user": (UserLaw("sqrt(T1**2 + 4*T2**2) - 0.5*N", "sqrt(T1**2 + T2**2)"), elliptic_user()),
    "dilatant": (UserLaw("sqrt(T1**2 + T2**2) - 0.5*N", "sqrt(T1**2 + 2*T2**2) - 0.2*N"),
                 dilatant_user()),
}


@functools.lru_cache(maxsize=None)
def _numeric(name):
    f, g = LAWS[name][1]
    x = (rN, r1, r2)
    grad = [sympy.diff(g, v) for v in x]
    return (sympy.lambdify(x, f, "numpy"), sympy.lambdify(x, grad, "numpy"))


def random_problem(seed, nc):
    """SPD W (a Delassus-like product plus a diagonal), closing normal and pushing tangential
    free velocities."""
    rng = np.random.default_rng(seed)
    B = rng.standard_normal((3 * nc, 3 * nc))
    W = B @ B.T / (3 * nc) + 0.3 * np.eye(3 * nc)
    q = rng.standard_normal(3 * nc)
    q[0::3] = -np.abs(q[0::3]) - 0.2 * rng.random(nc) + 0.3 * (rng.random(nc) < 0.2)
    return W, q


def independent_solutions(W, q, names):
    """Every solution found by regime enumeration (see the module docstring)."""
    nc = len(names)
    fun = [_numeric(n) for n in names]
    found = []
    rng = np.random.default_rng(0)
    r_stick = np.linalg.solve(W, -q)
    for regimes in itertools.product("ski", repeat=nc):     # separated, stick, sliding
        slide = [a for a in range(nc) if regimes[a] == "i"]

        def eqs(x):
            r, lam = x[:3 * nc], x[3 * nc:]
            u = W @ r + q
            out = []
            for a in range(nc):
                ra, ua = r[3 * a:3 * a + 3], u[3 * a:3 * a + 3]
                if regimes[a] == "s":
                    out.extend(ra)
                elif regimes[a] == "k":
                    out.extend(ua)
                else:
                    k = slide.index(a)
                    out.extend(ua + lam[k] * np.asarray(fun[a][1](*ra), dtype=float))
                    out.append(fun[a][0](*ra))
            return np.array(out)

        starts = []
        for scale in (1.0, 0.5, 2.0):
            x0 = np.concatenate((r_stick * scale, np.ones(len(slide))))
            for a in slide:         # radially onto a cone of the size of the stick force
                n = max(abs(r_stick[3 * a]), 0.1)
                x0[3 * a:3 * a + 3] = [n, *(0.5 * n * np.sign(r_stick[3 * a + 1:3 * a + 3] + 1e-3))]
            starts.append(x0)
        starts += [np.concatenate((rng.standard_normal(3 * nc), rng.random(len(slide))))
                   for _ in range(4)]
        for x0 in starts:
            with np.errstate(all="ignore"):
                sol = root(eqs, x0, method="hybr", tol=1e-14)
                if not np.all(np.isfinite(sol.x)) or np.max(np.abs(eqs(sol.x))) > 1e-11:
                    sol = root(eqs, sol.x if np.all(np.isfinite(sol.x)) else x0, method="lm",
                               tol=1e-15)
                res = eqs(sol.x)
            if not np.all(np.isfinite(res)) or np.max(np.abs(res)) > 1e-11:
                continue
            r, lam = sol.x[:3 * nc], sol.x[3 * nc:]
            if _admissible(W, q, r, lam, regimes, fun):
                if not any(np.max(np.abs(r - s)) < 1e-9 for s in found):
                    found.append(r)
                break
    return found


def _admissible(W, q, r, lam, regimes, fun, tol=1e-10):
    u = W @ r + q
    k = 0
    for a, regime in enumerate(regimes):
        ra, ua = r[3 * a:3 * a + 3], u[3 * a:3 * a + 3]
        if regime == "s" and ua[0] < -tol:
            return False
        if regime == "k" and (ra[0] <= 0 or fun[a][0](*ra) > tol):
            return False
        if regime == "i":
            if lam[k] < -tol or ra[0] <= tol or np.hypot(ra[1], ra[2]) <= tol:
                return False
            k += 1
    return True


CASES = [(name, nc, seed) for name in LAWS for nc, seed in ((1, 3), (2, 5), (3, 11), (4, 2))]


@pytest.mark.parametrize("name,nc,seed", CASES)
def test_small_problems_equal_independent_regime_solve(name, nc, seed):
    """The law path's NSGS solution equals the regime enumeration's to 1e-8, and its
    natural-map error is at most 1e-10."""
    W, q = random_problem(seed, nc)
    law = LAWS[name][0]
    sol = solve(FrictionContactProblem(W, q, [law] * nc), tol=1e-13)
    assert sol.converged and sol.error_measure == "law"
    assert law_error(FrictionContactProblem(W, q, [law] * nc), sol.r) <= 1e-10
    found = independent_solutions(W, q, [name] * nc)
    assert found, "the enumeration found no solution"
    best = min(np.max(np.abs(sol.r - s)) for s in found)
    assert best <= 1e-8


def test_a_different_law_at_each_contact():
    """Four contacts, four laws (the paper's three non-associated rules and a dilatant one)."""
    W, q = random_problem(7, 4)
    names = list(LAWS)
    p = FrictionContactProblem(W, q, [LAWS[n][0] for n in names])
    sol = solve(p, tol=1e-13)
    assert sol.converged and law_error(p, sol.r) <= 1e-10
    found = independent_solutions(W, q, names)
    assert found and min(np.max(np.abs(sol.r - s)) for s in found) <= 1e-8


def test_slide_regimes_are_exercised():
    """The cases above are not all stick or separation: every law slides somewhere."""
    for name in LAWS:
        sliding = 0
        for n, nc, seed in CASES:
            if n != name:
                continue
            W, q = random_problem(seed, nc)
            p = FrictionContactProblem(W, q, [LAWS[name][0]] * nc)
            s = solve(p, tol=1e-13)
            sliding += int(np.sum(np.abs(s.u.reshape(-1, 3)[:, 1:]).sum(1)
                                  * s.r.reshape(-1, 3)[:, 0] > 1e-9))
        assert sliding >= 1, name


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), nc=st.integers(1, 4),
       name=st.sampled_from(sorted(LAWS)))
def test_dissipation_nonnegative_at_every_contact(seed, nc, name):
    """D_a = -r_a . u_a = λ g(T, N) >= 0 at a solution (g >= 0 on the limit surface of each of
    these laws)."""
    W, q = random_problem(seed, nc)
    p = FrictionContactProblem(W, q, [LAWS[name][0]] * nc)
    sol = solve(p, tol=1e-12)
    assert sol.converged
    D = contact_dissipation(p, sol.r, sol.u)
    # the round-off of r.u where u = W r + q vanishes (stick): |r| eps (|W||r| + |q|)
    scale = np.linalg.norm(sol.r) * (np.linalg.norm(W, 2) * np.linalg.norm(sol.r) + np.linalg.norm(q))
    assert D.shape == (nc,) and np.all(D >= -1e-12 * scale)


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_associated_limit_equals_cone_path(seed):
    """TransformedCoulomb(μ, μ) is Coulomb(μ) without normal slip: the law path's solution is
    the cone path's (De Saxcé's complementarity) to round-off."""
    nc = 4
    W, q = random_problem(100 + seed, nc)
    mu = [0.3, 0.5, 0.7, 0.4]
    law_path = FrictionContactProblem(W, q, [TransformedCoulomb(m, m) for m in mu])
    cone_path = FrictionContactProblem(W, q, mu)
    assert law_path.path == "law" and cone_path.path == "cone"
    a = solve(law_path, tol=1e-14, method="nsgs")
    b = solve(cone_path, tol=1e-14, method="nsgs")
    np.testing.assert_allclose(a.r, b.r, rtol=0, atol=1e-11 * np.linalg.norm(b.r))
    assert law_error(law_path, b.r) <= 1e-12


def test_refuses_a_limit_condition_that_is_not_a_cone():
    W, q = random_problem(0, 1)
    with pytest.raises(FrictionRulesError, match=r"violates: its limit condition is not a cone "
                                                 r"in \(T, N\) \(f not homogeneous of degree one\)"):
        FrictionContactProblem(W, q, [UserLaw("T1**2 + T2**2 - N**2")])


def test_refuses_a_potential_that_is_not_a_cone():
    W, q = random_problem(0, 1)
    with pytest.raises(FrictionRulesError, match=r"its sliding potential is not a cone"):
        FrictionContactProblem(W, q, [UserLaw("sqrt(T1**2 + T2**2) - 0.3*N", "T1**2 + T2**2")])


def test_refuses_internal_variables_off_the_cone_path():
    W, q = random_problem(0, 2)
    hardened = SlipHardening(0.2, 1.0).apply(Coulomb(0.4))
    with pytest.raises(FrictionRulesError, match="no internal variables"):
        FrictionContactProblem(W, q, [hardened, TransformedCoulomb(0.5, 0.3)])


@pytest.mark.parametrize("method", ["newton", "prox", "admm"])
def test_refuses_a_method_that_cannot_take_the_law(method):
    W, q = random_problem(0, 2)
    p = FrictionContactProblem(W, q, [0.3, Huber(0.6, 0.45)])
    with pytest.raises(FrictionRulesError, match=rf"method = '{method}' violates: one of "
                                                 r"\['auto', 'nsgs', 'polish'\] for contact 1's "
                                                 r"law Huber"):
        solve(p, method=method)


@pytest.mark.parametrize("name", sorted(LAWS))
def test_polish_from_a_rough_answer_reaches_round_off(name):
    """Newton on the law path's natural map (J from the returns' consistent tangents) from a
    few sweeps' answer: the law error falls to 1e-12 in a few steps."""
    W, q = random_problem(21, 4)
    p = FrictionContactProblem(W, q, [LAWS[name][0]] * 4)
    rough = solve(p, method="nsgs", max_iter=3, tol=0.0)
    sol = solve(p, method="polish", r0=rough.r, tol=1e-12)
    assert sol.converged and sol.iterations <= 10 and law_error(p, sol.r) <= 1e-12


def test_cone_only_measures_refuse_the_law_path():
    W, q = random_problem(0, 1)
    p = FrictionContactProblem(W, q, [TransformedCoulomb(0.6, 0.3)])
    from frictionrules.multicontact import fc3d_error
    with pytest.raises(FrictionRulesError, match="use law_error"):
        fc3d_error(p, np.zeros(3))
    with pytest.raises(FrictionRulesError, match="associated"):
        p.associated()


def test_law_error_is_zero_only_at_solutions():
    """The natural map vanishes at the solution and not at a perturbed one."""
    W, q = random_problem(5, 2)
    p = FrictionContactProblem(W, q, [TransformedCoulomb(0.6, 0.3, angle=0.4)] * 2)
    sol = solve(p, tol=1e-14)
    assert law_error(p, sol.r) <= 1e-13
    assert law_error(p, sol.r + 1e-4) > 1e-6


def test_warm_start_callback_and_options_on_the_law_path():
    """r0 (a previous step's answer) converges at once; the callback sees each evaluation; a
    budget of one sweep stops as max_iter; the small path's records keep Siconos' measure."""
    from frictionrules import NSGSOptions
    W, q = random_problem(9, 4)
    p = FrictionContactProblem(W, q, [Huber(0.6, 0.45), TransformedCoulomb(0.5, 0.3), 0.4,
                                      LAWS["dilatant"][0]])
    first = solve(p, tol=1e-12)
    seen = []
    again = solve(p, tol=1e-12, r0=first.r, callback=seen.append,
                  options=NSGSOptions(max_check_interval=2), method="nsgs")
    assert again.converged and again.iterations == 1 and seen and seen[-1].error <= 1e-12
    assert solve(p, tol=0.0, max_iter=1).reason == "max_iter"
    assert solve(FrictionContactProblem(W, q, 0.4)).error_measure == "fc3d"


@pytest.mark.parametrize("law", [EllipticOrthotropic(0.6, 0.2, angle=0.5), Coulomb(0.4, dilatant=True)],
                         ids=["elliptic", "dilatant-coulomb"])
def test_cone_laws_on_the_law_path_equal_the_cone_path(law):
    """A cone law beside a Huber contact that W decouples from it: on the law path its answer
    is the cone path's answer of the contact alone (the elliptic cone's frame transformation;
    the dilatant rule (1.6) at a sliding, compressed contact, where the two separation rules
    agree)."""
    W1, q1 = random_problem(4, 1)
    q1 = np.array([-1.0, 0.9, -0.6])
    W = np.zeros((6, 6))
    W[:3, :3], W[3:, 3:] = W1, np.eye(3)
    q = np.concatenate((q1, [-1.0, 0.2, 0.1]))
    both = solve(FrictionContactProblem(W, q, [law, Huber(0.6, 0.45)]), tol=1e-13)
    alone = solve(FrictionContactProblem(W1, q1, [law]), tol=1e-13, method="nsgs")
    assert both.converged and alone.converged
    assert np.linalg.norm(alone.u[1:]) > 1e-3 and alone.r[0] > 0      # sliding, compressed
    np.testing.assert_allclose(both.r[:3], alone.r, rtol=0, atol=1e-10)


@pytest.mark.parametrize("laws", ["law path", "cone path"])
def test_renewed_problem_is_the_fresh_problem_of_its_W_and_q(laws):
    """``renewed(W, q)`` keeps the laws' reduction and replaces W and q: its solve is the
    solve of a problem built anew from the same laws (the same bits), on the law path (a
    different law at each contact) and on the cone path (an ellipse turned, Coulomb); a W or
    q of another size is refused."""
    W, q = random_problem(7, 4)
    W2, q2 = random_problem(8, 4)
    if laws == "law path":
        mu = [LAWS[n][0] for n in LAWS]
    else:
        mu = [EllipticOrthotropic(0.3, 0.6, angle=0.4), Coulomb(0.5), 0.4, Coulomb(0.5)]
    first = FrictionContactProblem(W, q, mu)
    solve(first, tol=1e-12)                         # the law path's compiled set, built
    again = first.renewed(W2, q2)
    fresh = FrictionContactProblem(W2, q2, mu)
    assert again.path == fresh.path and again.laws == fresh.laws
    np.testing.assert_array_equal(again.mu_bar, fresh.mu_bar)
    a, b = solve(again, tol=1e-12), solve(fresh, tol=1e-12)
    assert a.converged and np.array_equal(a.r, b.r) and a.error == b.error
    assert np.array_equal(first.q, q)               # the first problem is left as it was
    with pytest.raises(FrictionRulesError, match="q has 9 entries"):
        first.renewed(W2, q2[:9])
    with pytest.raises(FrictionRulesError, match="W has shape"):
        first.renewed(W2[:9, :9], q2[:9])
