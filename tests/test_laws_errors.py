"""Bad parameters and inputs raise FrictionRulesError (a ValueError) naming the argument, the
value and the constraint."""

import numpy as np
import pytest
import sympy as sp

from frictionrules import (Coulomb, EllipticOrthotropic, FrictionRulesError, Huber, TransformedCoulomb,
                           UserLaw, WedgeAsperity)


@pytest.mark.parametrize("make,pattern", [
    (lambda: Coulomb(-0.3), r"mu = -0.3 violates mu >= 0"),
    (lambda: Coulomb(float("nan")), r"mu = nan violates: must be finite"),
    (lambda: EllipticOrthotropic(0.0, 0.3), r"mu_x = 0.0 violates mu_x > 0"),
    (lambda: EllipticOrthotropic(0.6, 0.3, angle=4.0), r"angle = 4.0 violates angle <= 3.14"),
    (lambda: Huber(0.6, -1.0), r"mu_2 = -1.0 violates mu_2 > 0"),
    (lambda: TransformedCoulomb(0.6, np.inf), r"mu_y = inf violates: must be finite"),
    (lambda: WedgeAsperity(0.0, 0.3), r"alpha = 0.0 violates alpha > 0"),
    (lambda: WedgeAsperity(np.pi, 0.3), r"alpha = 3.14\d* violates alpha < 3.14"),
    (lambda: WedgeAsperity(0.3, 0.3, local="dilatant"), r"local = 'dilatant' violates local in"),
    (lambda: UserLaw("sqrt(T1**2 + T2**2) - mu*N"), r"unknown name 'mu'"),
    (lambda: UserLaw("sqrt(T1**2 +"), r"ends too early"),
])
def test_bad_parameters(make, pattern):
    with pytest.raises(FrictionRulesError, match=pattern):
        make()


def test_errors_are_value_errors():
    assert issubclass(FrictionRulesError, ValueError)


def test_tension_where_the_limit_needs_compression():
    with pytest.raises(FrictionRulesError, match=r"N\[1\] = -1.0 .*violates N >= 0"):
        Coulomb(0.3).limit([[0.0, 0.0], [0.1, 0.0]], [1.0, -1.0])
    with pytest.raises(FrictionRulesError, match=r"Q = -2.0 violates Q >= 0"):
        WedgeAsperity(0.3, 0.3).limit([0.0, 0.0], -2.0)


def test_nan_inputs_are_refused():
    with pytest.raises(FrictionRulesError, match=r"T\[1\] = nan"):
        EllipticOrthotropic(0.6, 0.3).slip_direction([0.1, np.nan], 1.0)
    with pytest.raises(FrictionRulesError, match=r"theta = nan"):
        Coulomb(0.3).friction_coefficient(np.nan)


def test_bad_shapes_and_zero_slip():
    with pytest.raises(FrictionRulesError, match=r"T must have shape \(\.\.\., 2\)"):
        Coulomb(0.3).limit([1.0, 2.0, 3.0], 1.0)
    with pytest.raises(FrictionRulesError, match="zero tangential part"):
        Coulomb(0.3).force_for_slip([0.0, 0.0, 1.0], 1.0)


def test_wedge_load_that_leaves_the_plane():
    law = WedgeAsperity(0.3, 0.5)
    assert float(law.limit([-10.0, 0.0], 1.0)) > 0  # masked: cannot be carried
    with pytest.raises(FrictionRulesError, match="leaves the plane"):
        law.slip_direction([-10.0, 0.0], 1.0)


def test_user_law_apex_gives_the_minimal_norm_subgradient_like_coulomb():
    from frictionrules import N, T1, T2
    law = UserLaw(sp.sqrt(T1**2 + T2**2) - 0.3 * N)
    np.testing.assert_array_equal(law.limit_gradient([0.0, 0.0], 1.0),
                                  Coulomb(0.3).limit_gradient([0.0, 0.0], 1.0))
    np.testing.assert_array_equal(law.slip_direction([0.0, 0.0], 1.0),
                                  Coulomb(0.3, dilatant=True).slip_direction([0.0, 0.0], 1.0))


def test_user_law_value_undefined_at_a_point():
    from frictionrules import N, T1, T2
    law = UserLaw(sp.sqrt(T1**2 + T2**2) - N * T1**2 / (T1**2 + T2**2))
    with pytest.raises(FrictionRulesError, match="not finite"):
        law.limit([0.0, 0.0], 1.0)
