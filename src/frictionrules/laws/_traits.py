r"""What the layers above ask of a law beyond f and g: its traits, derived once from the
symbolic form and cached per law.

A built-in law declares its traits in closed form (:meth:`FrictionLaw.declared_traits`); the
tests check every declaration against :func:`derive_traits`. A law without a declaration (a
:class:`~frictionrules.UserLaw`, a law with slip hardening) gets the derived ones.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

__all__ = ["LawTraits", "derive_traits", "traits_of"]


@dataclass(frozen=True)
class LawTraits:
    r"""The traits of a law, each a property of its symbolic form at fixed internal variables.

    Attributes
    ----------
    degree : float or None
        Degree k of positive homogeneity of f in the forces,
        :math:`f(sT, sN, q) = s^k f(T, N, q)` for every ``s > 0``; ``None`` when f is not
        homogeneous.
    slip_degree : float or None
        The common degree of the non-zero components of :math:`\nabla g`; ``None`` when they
        are not homogeneous of one degree. With one, the slip direction is the same at every
        point of a ray ``s(T, N)``.
    normal_slip : bool
        :math:`\partial g/\partial N \not\equiv 0`: the sliding rule opens or closes the contact
        (dilatancy, compaction).
    tangentially_associated : bool
        Normality in the sliding plane: :math:`\nabla_T g \parallel \nabla_T f`, i.e.
        :math:`f_{,T_1}g_{,T_2} - f_{,T_2}g_{,T_1} \equiv 0` (the tangential slip is normal to
        the limit curve at fixed N).
    tangent_coupling : bool
        The internal variables couple the tangential directions:
        :math:`\partial^2 g/\partial T\partial q \not\equiv 0` or
        :math:`\partial h/\partial T \not\equiv 0` ((4.5)).
    convex : bool
        The limit curve at ``N = 1`` (the virgin state) bounds a convex set of forces T
        (checked on 720 points along rays from :meth:`FrictionLaw.centre`; for a conical law
        this holds at every N).
    """

    degree: float | None
    slip_degree: float | None
    normal_slip: bool
    tangentially_associated: bool
    tangent_coupling: bool
    convex: bool

    @property
    def conical(self) -> bool:
        """The limit surface is a cone in (T, N) with its apex at 0 and the same slip direction
        along each of its rays: the limit force for a slip direction is N times the one at
        ``N = 1`` (VFRIC, grain contacts, facets)."""
        return self.degree is not None and self.degree > 0 and self.slip_degree is not None

    @property
    def symmetric_tangent(self) -> bool:
        """The consistent tangent of the return mapping is symmetric in the tangential
        directions: normality in the sliding plane and no coupling through the internal
        variables."""
        return self.tangentially_associated and not self.tangent_coupling


def _zero(expr) -> bool:
    import sympy
    return expr == 0 or sympy.simplify(expr) == 0


def _degree(expr):
    """k with ``expr(s x) = s^k expr(x)`` for ``s > 0`` (``x = (T1, T2, N)``), else None."""
    import sympy

    from .symbols import N, T1, T2
    s = sympy.Symbol("s", positive=True)
    ratio = sympy.simplify(expr.xreplace({T1: s * T1, T2: s * T2, N: s * N}) / expr)
    if not ratio.free_symbols <= {s}:
        return None
    k = sympy.simplify(s * sympy.diff(ratio, s) / ratio)
    return float(k) if k.is_number else None


def derive_traits(law) -> LawTraits:
    """The traits of ``law`` from its symbolic form (SymPy; parameter values put in exactly,
    as rationals, so that a trait holding for these values is an exact zero)."""
    import sympy

    from ._symbolic import form_of
    from .symbols import N, T1, T2
    form = form_of(law)
    exact = {p: sympy.Rational(v) for p, v in zip(form.params, form.values)}
    f, g = form.f.xreplace(exact), form.g.xreplace(exact)
    rates = [h.xreplace(exact) for h in form.rates]
    grad_g = [sympy.diff(g, x) for x in (T1, T2, N)]
    degrees = {_degree(e) for e in grad_g if e != 0}
    cross = sympy.diff(f, T1) * grad_g[1] - sympy.diff(f, T2) * grad_g[0]
    coupled = ([sympy.diff(gx, q) for gx in grad_g[:2] for q in form.state]
               + [sympy.diff(h, x) for h in rates for x in (T1, T2)])
    return LawTraits(
        degree=None if f == 0 else _degree(f),
        slip_degree=degrees.pop() if len(degrees) == 1 and None not in degrees else None,
        normal_slip=not _zero(grad_g[2]),
        tangentially_associated=_zero(cross),
        tangent_coupling=not all(_zero(e) for e in coupled),
        convex=limit_curve_is_convex(law))


def limit_curve_is_convex(law) -> bool:
    """The limit curve at ``N = 1`` in the virgin state, sampled on 720 rays from the law's
    centre, turns one way only (unbounded parts aside); False where f cannot be evaluated
    along the rays (convexity not shown)."""
    from ..errors import FrictionRulesError
    from ._inverse import GRID, radius
    centre = np.asarray(law.centre(1.0), dtype=float).reshape(2)
    phi = -np.pi + 2.0 * np.pi * np.arange(GRID) / GRID
    try:
        r = radius(law, centre, 1.0, phi, max(1.0, float(np.hypot(*centre))), None)
    except FrictionRulesError:
        return False
    fin = np.isfinite(r)
    T = centre + np.where(fin, r, 0.0)[:, None] * np.stack((np.cos(phi), np.sin(phi)), axis=-1)
    e = np.roll(T, -1, axis=0) - T
    e2 = np.roll(e, -1, axis=0)
    turn = e[:, 0] * e2[:, 1] - e[:, 1] * e2[:, 0]
    scale = np.linalg.norm(e, axis=-1) * np.linalg.norm(e2, axis=-1)
    ok = fin & np.roll(fin, -1) & np.roll(fin, -2)
    return bool(np.all(turn[ok] >= -1e-9 * scale[ok]))


@functools.lru_cache(maxsize=1024)
def _cached(law) -> LawTraits:
    return law.declared_traits() or derive_traits(law)


def traits_of(law) -> LawTraits:
    """The traits of ``law``: declared in closed form, else derived (cached per law)."""
    try:
        hash(law)
    except TypeError:  # an unhashable law is not cached
        return law.declared_traits() or derive_traits(law)
    return _cached(law)
