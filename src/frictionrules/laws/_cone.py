r"""The elliptic-cone form of a law, found from its symbolic form.

A law is an elliptic cone (capability ``"cone"``) when, with the parameter values put in,

.. math:: f = \sqrt{Q(T)} - c\,N, \qquad g = a_1\sqrt{Q(T)} + a_2 N,

``Q`` a positive-definite quadratic form in ``T``, ``c > 0``, ``a_1 > 0`` (the tangential slip is
then normal to the ellipse at any N) and no internal variables. The ellipse
:math:`\sqrt{Q(T)} \le cN` has semi-axes :math:`\mu_x, \mu_y` along the eigenvectors of ``Q``,
and the normal slip :math:`v_n = -\dot\lambda a_2` gives the constant dilatancy ratio
:math:`d = -a_2/(a_1 c)` of :class:`Cone` (``g = f``: ``d = 1``).
"""

from __future__ import annotations

import functools

import numpy as np

from ._records import Cone


@functools.lru_cache(maxsize=256)
def cone_of(law) -> Cone | None:
    """The :class:`Cone` of ``law``'s symbolic form, or ``None`` when it is not one."""
    import sympy

    from ._symbolic import form_of
    from .symbols import N, T1, T2
    form = form_of(law)
    if form.state:
        return None
    f, g, _ = form.substituted()
    try:
        c = -sympy.diff(f, N)
        r = sympy.simplify(f + c * N)
        if not c.is_number or float(c) <= 0 or r.has(N):
            return None
        quad = sympy.Poly(sympy.expand(r**2), T1, T2)
        if quad.total_degree() != 2 or not all(sum(m) == 2 for m in quad.monoms()):
            return None
        if sympy.simplify(r - sympy.sqrt(quad.as_expr())) != 0:
            return None
        coef = {m: float(v) for m, v in zip(quad.monoms(), quad.coeffs())}
        Q = np.array([[coef.get((2, 0), 0.0), 0.5 * coef.get((1, 1), 0.0)],
                      [0.5 * coef.get((1, 1), 0.0), coef.get((0, 2), 0.0)]])
        lam, V = np.linalg.eigh(Q)
        if lam.min() <= 0:
            return None
        a2 = sympy.diff(g, N)
        a1 = sympy.simplify((g - a2 * N) / r)
        if not (a2.is_number and a1.is_number) or float(a1) <= 0:
            return None
    except (sympy.PolynomialError, TypeError, ValueError):
        return None
    c, a1, a2 = float(c), float(a1), float(a2)
    mu_x, mu_y = c / np.sqrt(lam)
    angle = float(np.arctan2(V[1, 0], V[0, 0]))
    angle = (angle + np.pi / 2) % np.pi - np.pi / 2
    return Cone(float(mu_x), float(mu_y), angle, -a2 / (a1 * c))
