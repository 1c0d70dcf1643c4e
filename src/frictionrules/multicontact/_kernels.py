r"""Numba kernels looping over contacts (imported when a solver runs; compiled once, cached).

All kernels work in the circular frame of :mod:`.problem`: per contact an isotropic cone
:math:`|r_T| \le \mu r_N` and a dilatancy ratio ``d``; the modified velocity is
:math:`\hat u = u + \mu(1 - d)|u_T| e_N`. ``W`` comes as CSR arrays ``(indptr, indices, data)``.
"""

from __future__ import annotations

import numpy as np
from .._optional import require

njit = require("numba", extra="kernels").njit

_EPS = np.finfo(float).eps


@njit(cache=True)
def project_cone(zn, z1, z2, mu):
    """Projection of ``z`` onto :math:`K_\\mu = \\{|z_T| \\le \\mu z_N\\}`."""
    t = np.sqrt(z1 * z1 + z2 * z2)
    if mu * t <= -zn:
        return 0.0, 0.0, 0.0
    if t <= mu * zn:
        return zn, z1, z2
    s = (zn + mu * t) / (1.0 + mu * mu)
    return s, mu * s * z1 / t, mu * s * z2 / t


@njit(cache=True)
def csr_matvec(indptr, indices, data, x, q):
    n = q.size
    y = np.empty(n)
    for i in range(n):
        acc = q[i]
        for k in range(indptr[i], indptr[i + 1]):
            acc += data[k] * x[indices[k]]
        y[i] = acc
    return y


@njit(cache=True)
def error_sum(r, u, mu, dil):
    """:math:`\\sum_a |r_a - P_K(r_a - \\hat u_a)|^2` (unnormalized, squared)."""
    acc = 0.0
    for a in range(mu.size):
        i = 3 * a
        ut = np.sqrt(u[i + 1] ** 2 + u[i + 2] ** 2)
        un_hat = u[i] + mu[a] * (1.0 - dil[a]) * ut
        p0, p1, p2 = project_cone(r[i] - un_hat, r[i + 1] - u[i + 1], r[i + 2] - u[i + 2], mu[a])
        acc += (r[i] - p0) ** 2 + (r[i + 1] - p1) ** 2 + (r[i + 2] - p2) ** 2
    return acc


@njit(cache=True)
def norm2(x):
    """The Euclidean norm of a 1-D array, summed in order (the bits of ``np.sqrt(np.sum(x * x))``
    in compiled code, without its temporary array: about 15 ns each of the 0.7 µs compiled
    work of a 1-contact solve)."""
    acc = 0.0
    for i in range(x.size):
        acc += x[i] * x[i]
    return np.sqrt(acc)


@njit(cache=True)
def fc3d_error_kernel(indptr, indices, data, q, mu, dil, r, norm_q):
    u = csr_matvec(indptr, indices, data, r, q)
    scale = max(norm_q, norm2(r), norm2(u))
    err = np.sqrt(error_sum(r, u, mu, dil))
    if scale > _EPS:
        err /= scale
    return err, u


# ---- exact local solver -----------------------------------------------------------------------
@njit(cache=True)
def _slip_eval(A, b, mu, md, th):
    """Slip candidate at tangential angle ``th`` of ``-r_T``: ``(F, r_N, c.u_T)``.

    ``r = r_N (1, -mu c)``, ``u = A r + b``; ``r_N`` from :math:`u_N = \\mu d\\, c\\cdot u_T`;
    ``F = den * (c x u_T)`` (pole-free), zero where :math:`u_T \\parallel c`.
    """
    c1, c2 = np.cos(th), np.sin(th)
    v0 = A[0, 0] - mu * (A[0, 1] * c1 + A[0, 2] * c2)
    v1 = A[1, 0] - mu * (A[1, 1] * c1 + A[1, 2] * c2)
    v2 = A[2, 0] - mu * (A[2, 1] * c1 + A[2, 2] * c2)
    num = -(b[0] - md * (c1 * b[1] + c2 * b[2]))
    den = v0 - md * (c1 * v1 + c2 * v2)
    X = c1 * v2 - c2 * v1
    Y = c1 * b[2] - c2 * b[1]
    F = num * X + den * Y
    if den != 0.0:
        rn = num / den
    else:
        rn = -1.0
    ut1 = rn * v1 + b[1]
    ut2 = rn * v2 + b[2]
    return F, rn, c1 * ut1 + c2 * ut2


@njit(cache=True)
def _slip_eval_d(A, b, mu, md, th):
    """``(F, dF/dth)`` of :func:`_slip_eval` (the derivative by the chain rule through
    ``c = (cos th, sin th)``; one evaluation per Newton step instead of three)."""
    c1, c2 = np.cos(th), np.sin(th)
    d1, d2 = -c2, c1
    v0 = A[0, 0] - mu * (A[0, 1] * c1 + A[0, 2] * c2)
    v1 = A[1, 0] - mu * (A[1, 1] * c1 + A[1, 2] * c2)
    v2 = A[2, 0] - mu * (A[2, 1] * c1 + A[2, 2] * c2)
    w0 = -mu * (A[0, 1] * d1 + A[0, 2] * d2)
    w1 = -mu * (A[1, 1] * d1 + A[1, 2] * d2)
    w2 = -mu * (A[2, 1] * d1 + A[2, 2] * d2)
    num = -(b[0] - md * (c1 * b[1] + c2 * b[2]))
    dnum = md * (d1 * b[1] + d2 * b[2])
    den = v0 - md * (c1 * v1 + c2 * v2)
    dden = w0 - md * (d1 * v1 + d2 * v2 + c1 * w1 + c2 * w2)
    X = c1 * v2 - c2 * v1
    dX = d1 * v2 + c1 * w2 - d2 * v1 - c2 * w1
    Y = c1 * b[2] - c2 * b[1]
    dY = d1 * b[2] - d2 * b[1]
    return num * X + den * Y, dnum * X + num * dX + dden * Y + den * dY


@njit(cache=True)
def _local_residual(A, b, mu, dil, r0, r1, r2):
    u0 = A[0, 0] * r0 + A[0, 1] * r1 + A[0, 2] * r2 + b[0]
    u1 = A[1, 0] * r0 + A[1, 1] * r1 + A[1, 2] * r2 + b[1]
    u2 = A[2, 0] * r0 + A[2, 1] * r1 + A[2, 2] * r2 + b[2]
    un_hat = u0 + mu * (1.0 - dil) * np.sqrt(u1 * u1 + u2 * u2)
    p0, p1, p2 = project_cone(r0 - un_hat, r1 - u1, r2 - u2, mu)
    return np.sqrt((r0 - p0) ** 2 + (r1 - p1) ** 2 + (r2 - p2) ** 2)


@njit(cache=True)
def _refine(A, b, mu, md, lo, hi, flo, fhi):
    """Illinois regula falsi on a sign change of F in ``[lo, hi]``."""
    side = 0
    for _ in range(100):
        th = (lo * fhi - hi * flo) / (fhi - flo)
        if not (lo < th < hi):
            th = 0.5 * (lo + hi)
        f, rn, cu = _slip_eval(A, b, mu, md, th)
        if f == 0.0 or hi - lo < 4e-16 * (1.0 + abs(th)):
            return th
        if (f > 0) == (fhi > 0):
            hi, fhi = th, f
            if side == 1:
                flo *= 0.5
            side = 1
        else:
            lo, flo = th, f
            if side == -1:
                fhi *= 0.5
            side = -1
    return 0.5 * (lo + hi)


@njit(cache=True)
def local_solve(A, b, mu, dil, rp0, rp1, rp2):
    """Exact solution of one contact: :math:`u = A r + b`, :math:`K \\ni r \\perp \\hat u \\in K^*`.

    Enumerates the three cases: separation (``r = 0`` if :math:`b_N \\ge \\mu d |b_T|`),
    stick (``A r = -b`` inside the cone), slip (``r = r_N(1, -\\mu c)``, ``c`` unit, solved
    for the angle of ``c``: Newton from the previous or stick direction, else a 64-point scan
    with regula falsi on every sign change). Among several valid slip roots the one with the
    smallest residual, then nearest the previous ``r``, is kept. Returns ``(r0, r1, r2)``.
    """
    md = mu * dil
    bt = np.sqrt(b[1] ** 2 + b[2] ** 2)
    if b[0] >= md * bt:
        return 0.0, 0.0, 0.0
    # stick: A r = -b (Cramer)
    a00, a01, a02 = A[0, 0], A[0, 1], A[0, 2]
    a10, a11, a12 = A[1, 0], A[1, 1], A[1, 2]
    a20, a21, a22 = A[2, 0], A[2, 1], A[2, 2]
    c00 = a11 * a22 - a12 * a21
    c01 = a12 * a20 - a10 * a22
    c02 = a10 * a21 - a11 * a20
    det = a00 * c00 + a01 * c01 + a02 * c02
    scale = abs(a00) + abs(a11) + abs(a22) + 1e-300
    th0 = np.nan
    if abs(det) > 1e-14 * scale ** 3:
        s0 = -(c00 * b[0] + (a02 * a21 - a01 * a22) * b[1] + (a01 * a12 - a02 * a11) * b[2]) / det
        s1 = -(c01 * b[0] + (a00 * a22 - a02 * a20) * b[1] + (a02 * a10 - a00 * a12) * b[2]) / det
        s2 = -(c02 * b[0] + (a01 * a20 - a00 * a21) * b[1] + (a00 * a11 - a01 * a10) * b[2]) / det
        st = np.sqrt(s1 * s1 + s2 * s2)
        if s0 >= 0.0 and st <= mu * s0 * (1.0 + 1e-14):
            return s0, s1, s2
        if st > 0.0:
            th0 = np.arctan2(-s2, -s1)
    # slip: Newton on the angle from the previous direction (or the stick one)
    rpt = np.sqrt(rp1 * rp1 + rp2 * rp2)
    if rpt > 0.0:
        th0 = np.arctan2(-rp2, -rp1)
    if np.isfinite(th0):
        th = th0
        for _ in range(30):
            f, df = _slip_eval_d(A, b, mu, md, th)
            if df == 0.0:
                break
            step = f / df
            if step > 0.5:
                step = 0.5
            elif step < -0.5:
                step = -0.5
            th -= step
            if abs(step) < 1e-14 * (1.0 + abs(th)):
                break
        f, rn, cu = _slip_eval(A, b, mu, md, th)
        if rn >= 0.0 and np.isfinite(rn) and cu >= 0.0:
            r0, r1, r2 = rn, -mu * rn * np.cos(th), -mu * rn * np.sin(th)
            res = _local_residual(A, b, mu, dil, r0, r1, r2)
            if res <= 1e-12 * (abs(rn) + abs(b[0]) + bt + 1e-300):
                return r0, r1, r2
    # scan
    n = 64
    best = np.inf
    bdist = np.inf
    br0, br1, br2 = 0.0, 0.0, 0.0
    lo = -np.pi
    flo, _r, _c = _slip_eval(A, b, mu, md, lo)
    for k in range(1, n + 1):
        hi = -np.pi + 2 * np.pi * k / n
        fhi, _r, _c = _slip_eval(A, b, mu, md, hi)
        if (flo <= 0.0 < fhi) or (fhi <= 0.0 < flo) or flo == 0.0:
            if flo == 0.0:
                th = lo
            else:
                th = _refine(A, b, mu, md, lo, hi, flo, fhi)
            f, rn, cu = _slip_eval(A, b, mu, md, th)
            if rn >= 0.0 and np.isfinite(rn) and cu >= -1e-12 * (bt + abs(rn)):
                r0, r1, r2 = rn, -mu * rn * np.cos(th), -mu * rn * np.sin(th)
                res = _local_residual(A, b, mu, dil, r0, r1, r2)
                dist = (r0 - rp0) ** 2 + (r1 - rp1) ** 2 + (r2 - rp2) ** 2
                tolr = 1e-12 * (abs(rn) + abs(b[0]) + bt + 1e-300)
                if (res < best and not (best <= tolr and dist > bdist)) or (res <= tolr and dist < bdist):
                    best, bdist = res, dist
                    br0, br1, br2 = r0, r1, r2
        lo, flo = hi, fhi
    if best < np.inf:
        return br0, br1, br2
    # no slip root (degenerate block): one projection step from the previous value
    u0 = a00 * rp0 + a01 * rp1 + a02 * rp2 + b[0]
    u1 = a10 * rp0 + a11 * rp1 + a12 * rp2 + b[1]
    u2 = a20 * rp0 + a21 * rp1 + a22 * rp2 + b[2]
    rho = 1.0 / scale
    un_hat = u0 + mu * (1.0 - dil) * np.sqrt(u1 * u1 + u2 * u2)
    return project_cone(rp0 - rho * un_hat, rp1 - rho * u1, rp2 - rho * u2, mu)


@njit(cache=True)
def diagonal_blocks(indptr, indices, data, nc):
    D = np.zeros((nc, 3, 3))
    for a in range(nc):
        lo = 3 * a
        for l in range(3):
            for k in range(indptr[lo + l], indptr[lo + l + 1]):
                j = indices[k] - lo
                if 0 <= j < 3:
                    D[a, l, j] += data[k]
    return D


@njit(inline="always")
def check_interval(hist_err, hist_it, nh, err, tol, max_interval):
    """Sweeps until the next error check: half the number the last two checks' linear rate
    (in log error) predicts to reach ``tol``, between 1 and ``max_interval``; 1 where the
    error did not fall."""
    if nh >= 2 and 0.0 < err < hist_err[nh - 2]:
        rate = np.log(err / hist_err[nh - 2]) / (hist_it[nh - 1] - hist_it[nh - 2])
        predicted = np.log(tol / err) / rate
        return int(min(float(max_interval), max(1.0, 0.5 * predicted)))
    return 1


@njit(inline="always")
def local_rhs(indptr, indices, data, q, D, r, a, b):
    """Contact ``a``'s right-hand side of a sweep into ``b`` (3,):
    ``b = q_a + sum_{c != a} W_ac r_c = (W r + q)_a - W_aa r_a`` (W in CSR, ``D[a] = W_aa``)."""
    i = 3 * a
    for l in range(3):
        acc = q[i + l]
        for k in range(indptr[i + l], indptr[i + l + 1]):
            acc += data[k] * r[indices[k]]
        b[l] = acc - (D[a, l, 0] * r[i] + D[a, l, 1] * r[i + 1] + D[a, l, 2] * r[i + 2])


@njit(cache=True)
def nsgs(indptr, indices, data, D, q, mu, dil, r, tol, max_iter, hist_err, hist_it, norm_q, max_interval):
    """Non-smooth Gauss–Seidel sweeps over the contacts with :func:`local_solve`.

    Updates ``r`` in place. The full error (:func:`fc3d_error_kernel`, one product with W) is
    evaluated after the sweeps where convergence may have happened: when the relative change of
    ``r`` in the sweep is below ``tol``, and otherwise at intervals predicted from the observed
    linear rate (half the predicted number of sweeps to ``tol``, at most ``max_interval`` sweeps
    apart), and
    after the last sweep. ``hist_err[k]``, ``hist_it[k]``: k-th evaluated error and its sweep.
    Returns ``(sweeps, error, evaluations)``.
    """
    nc = mu.size
    b = np.empty(3)
    err = np.inf
    it = 0
    nh = 0
    next_check = 1
    for it in range(1, max_iter + 1):
        dr2 = 0.0
        r2 = 0.0
        for a in range(nc):
            i = 3 * a
            local_rhs(indptr, indices, data, q, D, r, a, b)
            r0, r1, r2_ = local_solve(D[a], b, mu[a], dil[a], r[i], r[i + 1], r[i + 2])
            dr2 += (r0 - r[i]) ** 2 + (r1 - r[i + 1]) ** 2 + (r2_ - r[i + 2]) ** 2
            r2 += r0 * r0 + r1 * r1 + r2_ * r2_
            r[i], r[i + 1], r[i + 2] = r0, r1, r2_
        light = np.sqrt(dr2 / r2) if r2 > 0.0 else np.sqrt(dr2)
        if it < next_check and light > tol and it < max_iter:
            continue
        err, _u = fc3d_error_kernel(indptr, indices, data, q, mu, dil, r, norm_q)
        hist_err[nh] = err
        hist_it[nh] = it
        nh += 1
        if err <= tol:
            break
        next_check = it + check_interval(hist_err, hist_it, nh, err, tol, max_interval)
    return it, err, nh


# ---- semismooth Newton on the Alart–Curnier function ------------------------------------------
@njit(cache=True)
def alart_curnier(r, u, mu, dil, rho):
    r"""Alart–Curnier function and the blocks of its generalized Jacobian, :math:`J = B_1 + B_2 W`.

    With the normal gap velocity :math:`g_N = u_N - \mu d |u_T|` (``d = 0``: Coulomb),
    :math:`p_N = (r_N - \rho g_N)_+`,

    .. math:: \Phi_N = r_N - p_N, \qquad
              \Phi_T = r_T - P_{D(\mu p_N)}(r_T - \rho u_T),

    ``P_D`` the projection on the disk of radius :math:`\mu p_N`. :math:`\Phi = 0` exactly at a
    solution of the contact law.
    """
    nc = mu.size
    phi = np.empty(3 * nc)
    B1 = np.zeros((nc, 3, 3))
    B2 = np.zeros((nc, 3, 3))
    for a in range(nc):
        i = 3 * a
        m, md, rh = mu[a], mu[a] * dil[a], rho[a]
        ut = np.sqrt(u[i + 1] ** 2 + u[i + 2] ** 2)
        if ut > 0.0:
            t1, t2 = u[i + 1] / ut, u[i + 2] / ut
        else:
            t1, t2 = 0.0, 0.0
        tau = r[i] - rh * (u[i] - md * ut)
        # d pN / d(rN; uN, uT1, uT2)
        if tau > 0.0:
            pn, dr, du0, du1, du2 = tau, 1.0, -rh, rh * md * t1, rh * md * t2
        else:
            pn, dr, du0, du1, du2 = 0.0, 0.0, 0.0, 0.0, 0.0
        z1 = r[i + 1] - rh * u[i + 1]
        z2 = r[i + 2] - rh * u[i + 2]
        zt = np.sqrt(z1 * z1 + z2 * z2)
        R = m * pn
        if zt <= R:
            p1, p2 = z1, z2
            g11, g12, g21, g22 = 1.0, 0.0, 0.0, 1.0
            h1, h2 = 0.0, 0.0
        else:
            e1, e2 = z1 / zt, z2 / zt
            p1, p2 = R * e1, R * e2
            f = R / zt
            g11, g12, g21, g22 = f * (1 - e1 * e1), -f * e1 * e2, -f * e1 * e2, f * (1 - e2 * e2)
            h1, h2 = e1 * m, e2 * m  # dP/dpN
        phi[i] = r[i] - pn
        phi[i + 1] = r[i + 1] - p1
        phi[i + 2] = r[i + 2] - p2
        # B1 = I - dpsi/dr
        B1[a, 0, 0] = 1.0 - dr
        B1[a, 1, 0] = -h1 * dr
        B1[a, 2, 0] = -h2 * dr
        B1[a, 1, 1] = 1.0 - g11
        B1[a, 1, 2] = -g12
        B1[a, 2, 1] = -g21
        B1[a, 2, 2] = 1.0 - g22
        # B2 = -dpsi/du
        B2[a, 0, 0], B2[a, 0, 1], B2[a, 0, 2] = -du0, -du1, -du2
        B2[a, 1, 0] = -h1 * du0
        B2[a, 2, 0] = -h2 * du0
        B2[a, 1, 1] = -h1 * du1 + rh * g11
        B2[a, 1, 2] = -h1 * du2 + rh * g12
        B2[a, 2, 1] = -h2 * du1 + rh * g21
        B2[a, 2, 2] = -h2 * du2 + rh * g22
    return phi, B1, B2


@njit(cache=True)
def jacobian_csr(indptr, indices, data, B1, B2):
    """CSR arrays of :math:`J = B_1 + B_2 W` (``B_1``, ``B_2`` block diagonal, W in CSR).

    Row ``3a + l`` of J has the union of the column patterns of W's rows ``3a..3a+2`` and the
    diagonal block, in increasing column order; the index arrays are int32, as SuperLU takes
    them, so SciPy neither sorts nor converts them.
    """
    nc = B1.shape[0]
    n = 3 * nc
    mark = np.full(n, -1, dtype=np.int64)
    cols = np.empty(n, dtype=np.int64)
    counts = np.zeros(nc, dtype=np.int64)
    for a in range(nc):  # pattern sizes
        m = 0
        for j in range(3 * a, 3 * a + 3):
            mark[j] = a
            m += 1
        for i in range(3 * a, 3 * a + 3):
            for k in range(indptr[i], indptr[i + 1]):
                j = indices[k]
                if mark[j] != a:
                    mark[j] = a
                    m += 1
        counts[a] = m
    if 3 * counts.sum() > 2**31 - 1:
        raise ValueError("the Jacobian has more than 2**31 - 1 nonzeros; constraint: int32 indices")
    jptr = np.zeros(n + 1, dtype=np.int32)
    for a in range(nc):
        for l in range(3):
            jptr[3 * a + l + 1] = jptr[3 * a + l] + counts[a]
    jind = np.empty(jptr[n], dtype=np.int32)
    jdat = np.zeros(jptr[n])
    pos = np.full(n, -1, dtype=np.int64)
    for a in range(nc):
        m = 0
        for j in range(3 * a, 3 * a + 3):
            cols[m] = j
            pos[j] = m
            m += 1
        for i in range(3 * a, 3 * a + 3):
            for k in range(indptr[i], indptr[i + 1]):
                j = indices[k]
                if pos[j] < 0:
                    cols[m] = j
                    pos[j] = m
                    m += 1
        cols[:m] = np.sort(cols[:m])
        for t in range(m):
            pos[cols[t]] = t
        for l in range(3):
            start = jptr[3 * a + l]
            for t in range(m):
                jind[start + t] = cols[t]
            for c in range(3):
                jdat[start + pos[3 * a + c]] += B1[a, l, c]
            for mm in range(3):
                coef = B2[a, l, mm]
                if coef != 0.0:
                    i = 3 * a + mm
                    for k in range(indptr[i], indptr[i + 1]):
                        jdat[start + pos[indices[k]]] += coef * data[k]
        for t in range(m):
            pos[cols[t]] = -1
    return jptr, jind, jdat


# ---- ADMM: cone projections and De Saxcé's correction over all contacts ------------------------
@njit(cache=True)
def project_all(z, mu, out):
    """``out_a = P_K(z_a)`` for every contact (:func:`project_cone`)."""
    for a in range(mu.size):
        i = 3 * a
        out[i], out[i + 1], out[i + 2] = project_cone(z[i], z[i + 1], z[i + 2], mu[a])


@njit(cache=True)
def project_dual_all(z, mu, out):
    r"""``out_a = P_{K^*}(z_a)`` (Moreau: :math:`P_{K^*}(z) = z + P_K(-z)`, :math:`K^*` the
    cone of coefficient :math:`1/\mu`)."""
    for a in range(mu.size):
        i = 3 * a
        p0, p1, p2 = project_cone(-z[i], -z[i + 1], -z[i + 2], mu[a])
        out[i], out[i + 1], out[i + 2] = z[i] + p0, z[i + 1] + p1, z[i + 2] + p2


@njit(cache=True)
def desaxce_shift(u, mu, dil, out):
    r""":math:`s_a = \mu_a (1 - d_a) |u_{aT}|\, e_N`: the modified velocity is :math:`u + s`."""
    for a in range(mu.size):
        i = 3 * a
        out[i] = mu[a] * (1.0 - dil[a]) * np.sqrt(u[i + 1] ** 2 + u[i + 2] ** 2)
        out[i + 1] = 0.0
        out[i + 2] = 0.0


# ---- the polish stage: De Saxcé's natural map and its generalized Jacobian --------------------
@njit(cache=True)
def natural_map(r, u, mu, dil, rho):
    r"""The natural map with De Saxcé's modified velocity and its generalized Jacobian blocks.

    Per contact :math:`z = r - \rho\hat u`, :math:`\hat u = u + \mu(1 - d)|u_T| e_N`,

    .. math:: \Phi(r) = r - P_K(z), \qquad J = B_1 + B_2 W, \quad
              B_1 = I - G, \quad B_2 = \rho\, G\, \partial\hat u/\partial u,

    with :math:`G = \partial P_K/\partial z` on the piece of the projection that ``z`` lies in:
    0 (polar cone: the contact opens), I (inside: it sticks), or on the boundary (it slips),
    :math:`s = (z_N + \mu t)/(1 + \mu^2)`, :math:`e = z_T/t`, :math:`t = |z_T|`,

    .. math:: G = \frac{1}{1 + \mu^2}\begin{pmatrix} 1 & \mu e^T \\ \mu e & \mu^2 e e^T
              \end{pmatrix} + \frac{\mu s}{t}\begin{pmatrix} 0 & 0 \\ 0 & I - e e^T\end{pmatrix}.

    :math:`\Phi = 0` exactly at a solution (for ``rho = 1`` its norm is Siconos' error before
    scaling). Returns ``(phi, B1, B2, pieces)``, ``pieces[a]`` 0 open, 1 stick, 2 slip.
    """
    nc = mu.size
    phi = np.empty(3 * nc)
    B1 = np.zeros((nc, 3, 3))
    B2 = np.zeros((nc, 3, 3))
    pieces = np.empty(nc, dtype=np.int64)
    G = np.zeros((3, 3))
    for a in range(nc):
        i = 3 * a
        m, rh, c = mu[a], rho[a], mu[a] * (1.0 - dil[a])
        ut = np.sqrt(u[i + 1] ** 2 + u[i + 2] ** 2)
        w1, w2 = (u[i + 1] / ut, u[i + 2] / ut) if ut > 0.0 else (0.0, 0.0)
        zn = r[i] - rh * (u[i] + c * ut)
        z1, z2 = r[i + 1] - rh * u[i + 1], r[i + 2] - rh * u[i + 2]
        t = np.sqrt(z1 * z1 + z2 * z2)
        G[:, :] = 0.0
        if m * t <= -zn:
            pieces[a] = 0
            p0, p1, p2 = 0.0, 0.0, 0.0
        elif t <= m * zn:
            pieces[a] = 1
            p0, p1, p2 = zn, z1, z2
            G[0, 0] = G[1, 1] = G[2, 2] = 1.0
        else:
            pieces[a] = 2
            e1, e2 = z1 / t, z2 / t
            k = 1.0 / (1.0 + m * m)
            s = (zn + m * t) * k
            p0, p1, p2 = s, m * s * e1, m * s * e2
            f = m * s / t
            G[0, 0] = k
            G[0, 1], G[0, 2] = k * m * e1, k * m * e2
            G[1, 0], G[2, 0] = k * m * e1, k * m * e2
            G[1, 1] = k * m * m * e1 * e1 + f * (1.0 - e1 * e1)
            G[1, 2] = k * m * m * e1 * e2 - f * e1 * e2
            G[2, 1] = G[1, 2]
            G[2, 2] = k * m * m * e2 * e2 + f * (1.0 - e2 * e2)
        phi[i], phi[i + 1], phi[i + 2] = r[i] - p0, r[i + 1] - p1, r[i + 2] - p2
        for l in range(3):
            for k2 in range(3):
                B1[a, l, k2] = (1.0 if l == k2 else 0.0) - G[l, k2]
            # d u^ / d u = I + c e_N (0, w1, w2)
            B2[a, l, 0] = rh * G[l, 0]
            B2[a, l, 1] = rh * (G[l, 1] + G[l, 0] * c * w1)
            B2[a, l, 2] = rh * (G[l, 2] + G[l, 0] * c * w2)
    return phi, B1, B2, pieces
