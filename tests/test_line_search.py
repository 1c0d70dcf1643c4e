"""One line search: Armijo's rule (sufficient decrease of the residual's norm, Dennis &
Schnabel's c = 1e-4) and step halving, defined once in the return-map specification and read
by the NumPy and compiled returns, the force-controlled driver and the assembly's solver."""

from pathlib import Path

import numpy as np
import pytest

from frictionrules import _returnspec as spec

SRC = Path(__file__).resolve().parents[1] / "src" / "frictionrules"


def test_sufficient_decrease_is_armijos_rule():
    """||R(x + a d)|| <= (1 - c a) ||R(x)||, finite; the same for scalars and arrays."""
    c = spec.SUFFICIENT_DECREASE
    merit, alpha = 2.0, 0.25
    bound = (1 - c * alpha) * merit
    assert spec.sufficient_decrease(bound, merit, alpha)
    assert not spec.sufficient_decrease(np.nextafter(bound, 3.0), merit, alpha)
    assert not spec.sufficient_decrease(np.inf, np.inf, alpha)
    assert not spec.sufficient_decrease(np.nan, merit, alpha)
    trial = np.array([0.0, bound, 1.99999, np.nan, np.inf])
    np.testing.assert_array_equal(spec.sufficient_decrease(trial, merit, alpha),
                                  [True, True, False, False, False])


def test_compiled_rule_is_the_specifications():
    """The compiled returns' rule is the specification's function compiled: the same answers
    on random merits around the bound."""
    pytest.importorskip("numba")
    from frictionrules.contact._kernel_newton import sufficient_decrease
    rng = np.random.default_rng(0)
    for _ in range(200):
        merit, alpha = rng.uniform(0, 2), 0.5 ** rng.integers(0, 13)
        trial = (1 - spec.SUFFICIENT_DECREASE * alpha) * merit * rng.uniform(0.999, 1.001)
        assert sufficient_decrease(trial, merit, alpha) == spec.sufficient_decrease(trial, merit,
                                                                                    alpha)


def test_backtrack_halves_until_accepted():
    """Steps alpha, alpha/2, ...: the first accepted one, else the last tried, not accepted."""
    tried = []

    def evaluate(a):
        tried.append(a)
        return abs(1.0 - 8.0 * a)          # the merit along the step; 1 at a = 0

    accept = lambda value, a: spec.sufficient_decrease(value, 1.0, a)  # noqa: E731
    assert spec.backtrack(evaluate, accept, 1.0, 10) == (0.125, 0.0, True)
    assert tried == [1.0, 0.5, 0.25, 0.125]
    tried.clear()
    a, value, ok = spec.backtrack(evaluate, accept, 0.5, 2)
    assert (a, value, ok) == (0.25, 1.0, False) and tried == [0.5, 0.25]


@pytest.mark.parametrize("path", ["contact/integrate.py", "contact/_kernel_newton.py",
                                  "contact/driver.py", "assembly/_newton.py"])
def test_every_line_search_reads_the_one_rule(path):
    """The returns, the driver and the assembly's solver take the rule from the
    specification; no Armijo constant of their own."""
    text = (SRC / path).read_text()
    assert "sufficient_decrease" in text and "_returnspec import" in text
    assert "1e-4" not in text
