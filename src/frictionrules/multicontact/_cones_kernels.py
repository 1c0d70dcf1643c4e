r"""Numba kernels of the law path for laws of two coaxial elliptic cones: the projection along
the potential in closed form up to one scalar equation, and the local problem of a sweep, on
scalars only.

A law whose limit and potential are :math:`f = \sqrt{T^\top P T} - mN`,
:math:`g = \sqrt{T^\top A T}` with P and A sharing their principal axes (recognised from its
symbolic form: :func:`frictionrules.codegen.elliptic_cones` — the transformed-variable rule
(1.17)–(1.18), the associated elliptic law (1.9)–(1.10), Coulomb, a coaxial ``UserLaw``) has
the projection :math:`P_K` of :mod:`._law_kernels` in a form that needs no Newton system
(:func:`cones_project`). The general local problem (:func:`._law_kernels._local`) passes the
contact's rows, scratch arrays and workspace to the law's compiled update at every call; here
everything is a scalar or a tuple of scalars, so a sweep's contact costs what the cone path's
does (the general path spends most of a sweep on the reference counts of those arrays).
:func:`cones_local` is the same algorithm as :func:`._law_kernels._local` (separation, the stick
solution, semismooth Newton with step halvings and the fixed-point step), so the two agree to
rounding (``tests/test_multicontact_cones.py``).
"""

from __future__ import annotations

import numpy as np

from .._optional import require
from .._returnspec import TOL as RETURN_TOL
from ..contact import ellipse_root

njit = require("numba", extra="kernels").njit

#: Halvings of a local Newton step before the fixed-point step is taken instead.
MAX_HALVINGS = 8


@njit(cache=True)
def cones_of(ell, a):
    """Contact ``a``'s numbers ``(cos, sin, α1, α2, π1, π2, m)`` from the rows ``ell`` (nc, 8)
    of :func:`frictionrules.codegen.elliptic_cones`, as a tuple."""
    return (ell[a, 1], ell[a, 2], ell[a, 3], ell[a, 4], ell[a, 5], ell[a, 6], ell[a, 7])


@njit(cache=True)
def block_of(D, a):
    """Contact ``a``'s diagonal block ``D[a]`` (3 x 3) as 9 numbers, row-major."""
    return (D[a, 0, 0], D[a, 0, 1], D[a, 0, 2], D[a, 1, 0], D[a, 1, 1], D[a, 1, 2],
            D[a, 2, 0], D[a, 2, 1], D[a, 2, 2])


@njit(cache=True)
def cones_project(e, x0, x1, x2):
    r""":math:`P_K(x)` of two coaxial elliptic cones ``e = (cos, sin, α1, α2, π1, π2, m)`` at
    ``x = (x_N, x_T1, x_T2)`` and its derivative :math:`\partial P_K/\partial x` (FCLIB's
    ordering, row-major, 9 numbers): returns ``(r_N, r_T1, r_T2, kind, ok, DP)``, ``kind`` 0
    inside, 1 returned, 2 zero (``x_N <= 0``: the contact opens).

    The return along g keeps :math:`r_N = x_N` and, in the common principal frame (``a =
    Q^T x_T``, eigenvalues :math:`\alpha_i` of A, :math:`\pi_i` of P), gives
    :math:`b_i = a_i/d_i`, :math:`d_i = 1 + y\alpha_i`, with y the root of

    .. math:: \phi(y) = \sum_i \pi_i a_i^2/d_i^2 - R^2 = 0, \qquad R = m x_N,

    convex and decreasing: Newton's iteration from a point left of the root (the root of the
    same equation with the larger α in both terms) rises to it monotonically. The projection
    does not depend on the metric K (N is kept; the tangential stiffness scales only y, the
    multiplier). Its derivative, from :math:`d\phi = 0`:

    .. math:: \frac{\partial b_i}{\partial a_j} = \frac{\delta_{ij}}{d_i}
              - \frac{\alpha_i b_i}{d_i}\,\frac{\pi_j b_j}{d_j S}, \qquad
              \frac{\partial b_i}{\partial x_N} = \frac{\alpha_i b_i}{d_i}\,\frac{R m}{S},
              \qquad S = \sum_i \frac{\pi_i\alpha_i b_i^2}{d_i}.

    Inside (:math:`\sum_i \pi_i a_i^2 \le R^2`): ``x`` and the identity. ``ok`` False where
    the scalar iteration does not converge in ``SCALAR_MAX_ITER`` steps."""
    c, sn, al1, al2, pi1, pi2, m = e
    if not x0 > 0.0:
        return 0.0, 0.0, 0.0, 2, True, (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    a1 = c * x1 + sn * x2
    a2 = -sn * x1 + c * x2
    R = m * x0
    r2 = R * R
    k2 = pi1 * a1 * a1 + pi2 * a2 * a2
    if k2 <= r2:
        return x0, x1, x2, 0, True, (1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0)
    ok, y = ellipse_root(a1, a2, al1, al2, pi1, pi2, np.sqrt(k2), R)
    d1 = 1.0 + y * al1
    d2 = 1.0 + y * al2
    b1 = a1 / d1
    b2 = a2 / d2
    S = pi1 * al1 * b1 * b1 / d1 + pi2 * al2 * b2 * b2 / d2
    e1, e2 = al1 * b1 / d1, al2 * b2 / d2
    w1, w2 = pi1 * b1 / (d1 * S), pi2 * b2 / (d2 * S)
    # in the principal frame G = db/da, h = db/dx_N; turned back with Q = [[c, -sn], [sn, c]]:
    # dr_T/dx_T = Q G Q^T, dr_T/dx_N = Q h
    g11, g12 = 1.0 / d1 - e1 * w1, -e1 * w2
    g21, g22 = -e2 * w1, 1.0 / d2 - e2 * w2
    h1, h2 = e1 * R * m / S, e2 * R * m / S
    t11, t12 = g11 * c - g12 * sn, g11 * sn + g12 * c
    t21, t22 = g21 * c - g22 * sn, g21 * sn + g22 * c
    DP = (1.0, 0.0, 0.0,
          c * h1 - sn * h2, c * t11 - sn * t21, c * t12 - sn * t22,
          sn * h1 + c * h2, sn * t11 + c * t21, sn * t12 + c * t22)
    return x0, c * b1 - sn * b2, sn * b1 + c * b2, 1, ok, DP


@njit(cache=True)
def _residual(A, b0, b1, b2, e, kn, kt, r0, r1, r2):
    r""":math:`R(r) = r - P_K(r - K(Ar + b))` (``A`` row-major, 9 numbers) and ``DP`` at the
    trial; ``bad`` where the projection did not converge."""
    u0 = A[0] * r0 + A[1] * r1 + A[2] * r2 + b0
    u1 = A[3] * r0 + A[4] * r1 + A[5] * r2 + b1
    u2 = A[6] * r0 + A[7] * r1 + A[8] * r2 + b2
    p0, p1, p2, _kind, ok, DP = cones_project(e, r0 - kn * u0, r1 - kt * u1, r2 - kt * u2)
    return r0 - p0, r1 - p1, r2 - p2, not ok, DP


@njit(cache=True)
def _solve3(J, c0, c1, c2):
    """``J^{-1} c`` (``J`` row-major, 9 numbers) by Cramer's rule and the determinant."""
    det = (J[0] * (J[4] * J[8] - J[5] * J[7])
           - J[1] * (J[3] * J[8] - J[5] * J[6])
           + J[2] * (J[3] * J[7] - J[4] * J[6]))
    if det == 0.0 or not np.isfinite(det):
        return 0.0, 0.0, 0.0, det
    d0 = (c0 * (J[4] * J[8] - J[5] * J[7])
          - J[1] * (c1 * J[8] - J[5] * c2)
          + J[2] * (c1 * J[7] - J[4] * c2)) / det
    d1 = (J[0] * (c1 * J[8] - J[5] * c2)
          - c0 * (J[3] * J[8] - J[5] * J[6])
          + J[2] * (J[3] * c2 - c1 * J[6])) / det
    d2 = (J[0] * (J[4] * c2 - c1 * J[7])
          - J[1] * (J[3] * c2 - c1 * J[6])
          + c0 * (J[3] * J[7] - J[4] * J[6])) / det
    return d0, d1, d2, det


@njit(cache=True)
def cones_local(A, b0, b1, b2, e, kn, kt, r0, r1, r2, local_iter, local_tol):
    r"""One contact's problem :math:`A r + b \in N_g(r)` with the others frozen, for two coaxial
    elliptic cones ``e`` (:func:`cones_of`), ``A`` the contact's diagonal block of W
    (row-major, 9 numbers), ``kn, kt`` the metric: the algorithm of
    :func:`._law_kernels._local` — separation (``b_N >= 0``), the stick solution
    :math:`-A^{-1}b` where it is inside the limit surface, otherwise semismooth Newton on
    :math:`R(r) = r - P_K(r - K(Ar + b))` from the contact's last reactions, the generalized
    Jacobian :math:`I - \partial P_K(I - KA)`, a step halved while it does not lower |R|, the
    fixed-point step where none does, and a stop, converged, where nothing lowers a map
    already within the return's tolerance. Returns the reactions."""
    if b0 >= 0.0:
        return 0.0, 0.0, 0.0
    s0, s1, s2, det = _solve3(A, -b0, -b1, -b2)
    if det != 0.0 and np.isfinite(det) and s0 > 0.0:
        _p0, _p1, _p2, kind, ok, _DP = cones_project(e, s0, s1, s2)
        if ok and kind == 0:
            return s0, s1, s2
    kd = (kn, kt, kt)
    R0, R1, R2, failed, DP = _residual(A, b0, b1, b2, e, kn, kt, r0, r1, r2)
    nR = np.sqrt(R0 * R0 + R1 * R1 + R2 * R2)
    for _ in range(local_iter):
        nr = np.sqrt(r0 * r0 + r1 * r1 + r2 * r2)
        if nR <= local_tol * nr or nR == 0.0:
            return r0, r1, r2
        # J = I - DP (I - K A)
        J = _jacobian(DP, A, kd)
        d0, d1, d2, det = _solve3(J, -R0, -R1, -R2)
        ok = det != 0.0 and np.isfinite(det) and not failed
        ok = ok and np.isfinite(d0) and np.isfinite(d1) and np.isfinite(d2)
        step = 1.0
        accepted = False
        t0, t1, t2 = r0, r1, r2
        S0, S1, S2, bad, DPt = R0, R1, R2, failed, DP
        nS = nR
        if ok:
            for _h in range(MAX_HALVINGS):
                t0, t1, t2 = r0 + step * d0, r1 + step * d1, r2 + step * d2
                S0, S1, S2, bad, DPt = _residual(A, b0, b1, b2, e, kn, kt, t0, t1, t2)
                nS = np.sqrt(S0 * S0 + S1 * S1 + S2 * S2)
                if not bad and nS < nR:
                    accepted = True
                    break
                step *= 0.5
        if not accepted:            # the fixed point: r <- P_K(r - K u)
            t0, t1, t2 = r0 - R0, r1 - R1, r2 - R2
            S0, S1, S2, bad, DPt = _residual(A, b0, b1, b2, e, kn, kt, t0, t1, t2)
            nS = np.sqrt(S0 * S0 + S1 * S1 + S2 * S2)
            if not bad and nS >= nR and nR <= RETURN_TOL * nr:
                # nothing lowers a map already within the return's own tolerance
                return r0, r1, r2
        r0, r1, r2 = t0, t1, t2
        R0, R1, R2, nR, failed, DP = S0, S1, S2, nS, bad, DPt
    return r0, r1, r2


@njit(cache=True)
def _jacobian(DP, A, kd):
    r""":math:`I - \partial P_K (I - KA)` (row-major, 9 numbers)."""
    J00 = 1.0 - _row_times(DP, 0, A, kd, 0)
    J01 = -_row_times(DP, 0, A, kd, 1)
    J02 = -_row_times(DP, 0, A, kd, 2)
    J10 = -_row_times(DP, 1, A, kd, 0)
    J11 = 1.0 - _row_times(DP, 1, A, kd, 1)
    J12 = -_row_times(DP, 1, A, kd, 2)
    J20 = -_row_times(DP, 2, A, kd, 0)
    J21 = -_row_times(DP, 2, A, kd, 1)
    J22 = 1.0 - _row_times(DP, 2, A, kd, 2)
    return (J00, J01, J02, J10, J11, J12, J20, J21, J22)


@njit(cache=True)
def _row_times(DP, i, A, kd, k):
    r""":math:`\sum_m DP_{im} (\delta_{mk} - K_m A_{mk})`."""
    acc = 0.0
    for m in range(3):
        acc += DP[3 * i + m] * ((1.0 if m == k else 0.0) - kd[m] * A[3 * m + k])
    return acc
