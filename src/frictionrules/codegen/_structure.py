r"""Structures of a law whose backward-Euler return needs no Newton system, recognised from its
symbolic form (for built-in and user laws alike).

The return (4.2), (4.3), (4.5) solves :math:`\sigma = \sigma^{tr} - \Delta\lambda D\nabla g`,
:math:`q = q_n + \Delta\lambda h`, :math:`f = 0` with :math:`D = \mathrm{diag}(k_t, k_t, k_n)`.

**Radial.** Where the flow direction ``v = (-D∇g, h)`` does not turn along itself,
:math:`\partial_v \nabla g = 0` and :math:`\partial_v h = 0` (a cone whose potential's
gradient keeps its direction: Coulomb with either rule, Drucker–Prager-like cones, the Huber
ellipse with g = |T|), the return path is the straight line :math:`x^{tr} + \Delta\lambda v^{tr}`
and one scalar equation :math:`\phi(\Delta\lambda) = f(x^{tr} + \Delta\lambda v^{tr}) = 0`
remains; where ∇f and ∂f/∂q do not change along it either (:math:`\partial_v\nabla f = 0`) φ is
linear and :math:`\Delta\lambda = f^{tr}/(\nabla f\cdot D\nabla g - \partial_q f\cdot h)`
(the radial return in closed form).

**Elliptic.** Where g depends on T only, :math:`g = \sqrt{T^\top A T}` with a constant
positive definite A, and :math:`\nabla_T f = c\,\nabla_T g` for a constant :math:`c > 0` (no
internal variables), backward Euler gives, in the principal frame of A (eigenvalues
:math:`\alpha_i`), :math:`T'_i = a_i/(1 + x\alpha_i)` with :math:`x = k_t\Delta\lambda/g`, N
unchanged, and the one scalar equation
:math:`\sum_i \alpha_i a_i^2/(1 + x\alpha_i)^2 = R^2`, :math:`R = g^{tr} - f^{tr}/c`, convex and
decreasing in x: Newton's iteration from x = 0 converges monotonically.

**Affine flow.** Where ∇g is affine in the forces with a diagonal Hessian that does not
depend on them, :math:`\nabla g = H(q)\sigma + c(q)`, :math:`H = \mathrm{diag}(H_{11}, H_{22},
H_{33})` (the ellipsoidal cap (4.9)), the forces follow from Δλ and q in closed form,
:math:`\sigma_a = (\sigma^{tr}_a - \Delta\lambda D_a c_a)/(1 + \Delta\lambda D_a H_{aa})`, and
Newton's method solves the reduced system :math:`f(\sigma, q) = 0`,
:math:`q - q_n - \Delta\lambda h(\sigma, q) = 0` in :math:`(\Delta\lambda, q)`: 1 + nq
unknowns instead of 4 + nq.

Each identity is checked first numerically at random points (a quick no) and then proved with
SymPy (a law whose identity SymPy cannot prove keeps the general return).

**Two coaxial elliptic cones** (:func:`elliptic_cones`, for the many-contact solvers' oblique
projection, not for the return of this module's step): :math:`f = \sqrt{T^\top P T} - mN`
and :math:`g = \sqrt{T^\top A T}` with constant positive definite P, A that share their
principal axes, m > 0, no internal variables — the transformed-variable rule (1.17)–(1.18),
the associated elliptic law (1.9)–(1.10), Coulomb, a coaxial ``UserLaw``. The return keeps N
and, in the common principal frame (eigenvalues :math:`\alpha_i` of A, :math:`\pi_i` of P),
gives :math:`T'_i = a_i/(1 + x\alpha_i)` with the one scalar equation
:math:`\sum_i \pi_i a_i^2/(1 + x\alpha_i)^2 = (mN)^2`, convex and decreasing in x.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from .._returnspec import (RETURN_AFFINE, RETURN_ELLIPTIC, RETURN_GENERIC, RETURN_RADIAL,
                          RETURN_SIZE)

__all__ = ["ReturnStructure", "return_structure", "return_constants", "elliptic_cones",
           "ELLIPTIC_CONES_SIZE"]


@dataclass(frozen=True)
class ReturnStructure:
    """How a law structure's return is solved (:mod:`frictionrules._returnspec` kinds).

    Attributes
    ----------
    kind : int
        ``RETURN_GENERIC``, ``RETURN_RADIAL``, ``RETURN_ELLIPTIC`` or ``RETURN_AFFINE``.
    linear : bool
        Radial: f is linear along the return path (the return in closed form).
    A, c : sympy expressions or None
        Elliptic: the matrix of :math:`g^2 = T^\\top A T` (2 × 2) and the ratio
        :math:`c = \\nabla_T f / \\nabla_T g`, in the law's parameters.
    """

    kind: int
    linear: bool = False
    A: tuple | None = None
    c: object = None


def _vanishes_at(expr, points) -> bool:
    """``expr`` is zero (to 1e-9) at every substitution of ``points``: the quick no of
    :func:`_zero` and :func:`_zero_expanded`."""
    for sub in points:
        try:
            value = complex(expr.xreplace(sub).evalf())
        except (TypeError, ValueError, ZeroDivisionError):
            return False
        if not abs(value) <= 1e-9:
            return False
    return True


def _zero(expr, points) -> bool:
    """True when ``expr`` vanishes identically: numerically at ``points`` first (a quick
    no), then proved by SymPy."""
    import sympy
    return _vanishes_at(expr, points) and sympy.simplify(expr) == 0


def _points(symbols, count=3):
    """Random points away from kinks: forces in [0.3, 1.2], everything else in [0.2, 0.9]."""
    import sympy
    rng = np.random.default_rng(7)
    out = []
    for _ in range(count):
        out.append({s: sympy.Float(rng.uniform(0.3, 1.2) if str(s) in ("T1", "T2", "N")
                                   else rng.uniform(0.2, 0.9)) for s in symbols})
    return out


def _radial(form, points):
    import sympy
    kt, kn = sympy.symbols("k_t k_n", positive=True)
    x, q = list(form.variables), list(form.state)
    dg = [sympy.diff(form.g, s) for s in x]
    v = [-kt * dg[0], -kt * dg[1], -kn * dg[2]] + list(form.rates)

    def along(e):
        return sum(sympy.diff(e, s) * vs for s, vs in zip(x + q, v))

    pts = [p | {kt: sympy.Float(1.3), kn: sympy.Float(0.7)} for p in points]
    if not all(_zero(along(e), pts) for e in dg + list(form.rates)):
        return None
    df = [sympy.diff(form.f, s) for s in x + q]
    return ReturnStructure(RETURN_RADIAL, linear=all(_zero(along(e), pts) for e in df))


def _elliptic(form, points):
    import sympy
    if form.state:
        return None
    T1, T2, N = form.variables
    g2 = sympy.expand(form.g ** 2)
    if not _zero(sympy.diff(form.g, N), points):
        return None
    A = [[sympy.diff(g2, a, b) / 2 for b in (T1, T2)] for a in (T1, T2)]
    if not all(_zero(sympy.diff(e, s), points) for row in A for e in row for s in (T1, T2, N)):
        return None
    A = [[sympy.simplify(e) for e in row] for row in A]
    quad = A[0][0] * T1**2 + 2 * A[0][1] * T1 * T2 + A[1][1] * T2**2
    if not _zero(g2 - quad, points) or not _zero(A[0][1] - A[1][0], points):
        return None
    c = sympy.simplify(sympy.diff(form.f, T1) / sympy.diff(form.g, T1))
    if c.free_symbols & {T1, T2, N} or not _zero(sympy.diff(form.f, T2) - c * sympy.diff(form.g, T2),
                                                 points):
        return None
    return ReturnStructure(RETURN_ELLIPTIC, A=(A[0][0], A[0][1], A[1][1]), c=c)


def _affine(form, points):
    import sympy
    x = list(form.variables)
    hess = [[sympy.diff(form.g, a, b) for b in x] for a in x]
    if not all(_zero(hess[a][b], points) for a in range(3) for b in range(3) if a != b):
        return None
    if not all(_zero(sympy.diff(hess[a][a], s), points) for a in range(3) for s in x):
        return None
    return ReturnStructure(RETURN_AFFINE)


@functools.lru_cache(maxsize=256)
def _structure(key, form) -> ReturnStructure:
    points = _points(list(form.variables) + list(form.state) + list(form.params))
    return (_radial(form, points) or _elliptic(form, points) or _affine(form, points)
            or ReturnStructure(RETURN_GENERIC))


def return_structure(form) -> ReturnStructure:
    """The structure of a symbolic form's return (cached per structure)."""
    return _structure(form.structure, form)


def return_constants(form) -> np.ndarray:
    """The return's block of a law's row (``RETURN_SIZE`` numbers, parameter values in):
    ``kind, linear`` and, elliptic, ``cos, sin`` of the principal frame of A, its eigenvalues
    ``α1, α2`` and c. A structure whose numbers do not fit (A not positive definite, c <= 0)
    falls back to the general return."""
    s = return_structure(form)
    out = np.zeros(RETURN_SIZE)
    out[0] = s.kind
    out[1] = float(s.linear)
    if s.kind == RETURN_ELLIPTIC:
        import sympy
        values = dict(zip(form.params, (sympy.Float(v) for v in form.values)))
        a11, a12, a22 = (float(e.xreplace(values)) for e in s.A)
        c = float(s.c.xreplace(values))
        alpha, vec = np.linalg.eigh(np.array([[a11, a12], [a12, a22]]))
        if not (alpha[0] > 0 and np.isfinite(alpha).all() and c > 0 and np.isfinite(c)):
            out[:] = 0.0
            return out
        out[2:7] = vec[0, 0], vec[1, 0], alpha[0], alpha[1], c
    return out


#: Length of :func:`elliptic_cones`' numbers: ``flag, cos, sin, α1, α2, π1, π2, m``.
ELLIPTIC_CONES_SIZE = 8


def _zero_expanded(expr, points) -> bool:
    """:func:`_zero`, trying the expansion first (a polynomial identity is proved by it at once;
    SymPy's simplify, with its trigonometric rewriting of a turned law's axes, took seconds)."""
    import sympy
    return _vanishes_at(expr, points) and (sympy.expand(expr) == 0
                                           or sympy.simplify(expr) == 0)


def _quadratic_form(expr, variables, points):
    """The constant symmetric matrix ``(M11, M12, M22)`` of ``expr = sqrt(Tᵀ M T)`` (proved),
    else None (the entries as derived: they are evaluated at the parameter values)."""
    import sympy
    T1, T2, _ = variables
    sq = sympy.expand(expr ** 2)
    M = [[sympy.diff(sq, a, b) / 2 for b in (T1, T2)] for a in (T1, T2)]
    if not all(_zero_expanded(sympy.diff(e, s), points) for row in M for e in row for s in variables):
        return None
    quad = M[0][0] * T1**2 + 2 * M[0][1] * T1 * T2 + M[1][1] * T2**2
    if not _zero_expanded(sq - quad, points):
        return None
    return M[0][0], M[0][1], M[1][1]


_CONES: dict = {}


def _cones(form):
    """The symbolic ``(P, A, m)`` of two coaxial elliptic cones, or None, in the law's parameter
    symbols: kept per structure (a law with other parameter values reuses it; the principal
    axes are compared at the values)."""
    if form.structure not in _CONES:
        _CONES[form.structure] = _derive_cones(form)
    return _CONES[form.structure]


def _derive_cones(form):
    import sympy
    if form.state:
        return None
    T1, T2, N = form.variables
    points = _points(list(form.variables) + list(form.params))
    if not _zero_expanded(sympy.diff(form.g, N), points):
        return None
    h = form.f.xreplace({T1: sympy.Integer(0), T2: sympy.Integer(0)})
    m = -sympy.diff(h, N)
    if m.free_symbols & {T1, T2, N} or not _zero_expanded(h + m * N, points):
        return None
    k = form.f - h
    if not _zero_expanded(sympy.diff(k, N), points):
        return None
    P = _quadratic_form(k, form.variables, points)
    A = _quadratic_form(form.g, form.variables, points)
    if P is None or A is None:
        return None
    return P, A, m


def elliptic_cones(form) -> np.ndarray:
    r"""The numbers of the oblique projection of two coaxial elliptic cones (module docstring):
    ``flag, cos, sin, α1, α2, π1, π2, m`` (:data:`ELLIPTIC_CONES_SIZE`), ``(cos, sin)`` the
    first principal axis shared by :math:`g^2 = T^\top A T` (eigenvalues α) and
    :math:`(f + mN)^2 = T^\top P T` (eigenvalues π); all zeros (flag 0) where the symbolic
    form is not of that structure (proved with SymPy, as :func:`return_structure`), where A or
    P is not positive definite, m <= 0, or the two do not share their axes (to 1e-12)."""
    out = np.zeros(ELLIPTIC_CONES_SIZE)
    sym = _cones(form)
    if sym is None:
        return out
    import sympy
    values = dict(zip(form.params, (sympy.Float(v) for v in form.values)))
    P, A = (np.array([[float(e.xreplace(values)) for e in (M[0], M[1])],
                      [float(e.xreplace(values)) for e in (M[1], M[2])]]) for M in sym[:2])
    m = float(sym[2].xreplace(values))
    if not (np.isfinite(P).all() and np.isfinite(A).all() and np.isfinite(m) and m > 0):
        return out
    alpha, vec = np.linalg.eigh(A)
    if alpha[1] - alpha[0] <= 1e-14 * abs(alpha[1]):
        _, vec = np.linalg.eigh(P)      # A a multiple of I: P's axes are the common ones
    Ad, Pd = vec.T @ A @ vec, vec.T @ P @ vec
    if not (min(Ad[0, 0], Ad[1, 1], Pd[0, 0], Pd[1, 1]) > 0 and abs(Ad[0, 1]) <= 1e-12 * np.abs(Ad).max()
            and abs(Pd[0, 1]) <= 1e-12 * np.abs(Pd).max()):
        return out
    out[:] = 1.0, vec[0, 0], vec[1, 0], Ad[0, 0], Ad[1, 1], Pd[0, 0], Pd[1, 1], m
    return out
