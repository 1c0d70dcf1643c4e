"""Compiled (Numba) batched updates written by hand: Coulomb and the ellipsoidal cap.

Imported on first use (Numba loads here, not at ``import frictionrules``). Each kernel loops
over contacts in parallel (``prange``) and writes into preallocated outputs; arrays are
row-major ``(n, 3)`` for displacements ``(δt1, δt2, δn)`` and forces ``(T1, T2, N)``, ``(n,)``
otherwise. Inputs: the elastic and plastic displacements ``e``, ``p``, the slip ``kappa`` and
the increments ``du``. The equations are those of :mod:`frictionrules.contact.integrate`,
solved in closed form (Coulomb: radial return) or by a reduced Newton iteration (the cap). The
tests compare both kernels with the generic return mapping;
``benchmarks/c/contact_kernels.c`` is the Coulomb arithmetic in C. They stay while they are
faster than the return generated from the law's symbolic form by more than 10 %
(``benchmarks/contact_update.py``).
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

ELASTIC, PLASTIC, OPEN = 0, 1, 2


@njit(inline="always")
def _trial(i, e, du, kt, kn):
    """Elastic trial of contact ``i``: displacements ``δᵉ + Δδ`` and forces (4.2), N > 0 closed."""
    e0 = e[i, 0] + du[i, 0]
    e1 = e[i, 1] + du[i, 1]
    e2 = e[i, 2] + du[i, 2]
    return e0, e1, e2, kt * e0, kt * e1, -kn * e2


@njit(inline="always")
def _open(i, e2, p, kappa, out_e, out_p, out_kappa, out_force, out_dlam, out_status, out_diss, t1, t2):
    out_e[i, 0] = 0.0
    out_e[i, 1] = 0.0
    out_e[i, 2] = e2
    out_p[i, 0] = p[i, 0] + t1
    out_p[i, 1] = p[i, 1] + t2
    out_p[i, 2] = p[i, 2]
    out_force[i, 0] = 0.0
    out_force[i, 1] = 0.0
    out_force[i, 2] = 0.0
    out_kappa[i] = kappa[i]
    out_dlam[i] = 0.0
    out_status[i] = OPEN
    out_diss[i] = 0.0


@njit(inline="always")
def _elastic(i, e0, e1, e2, T1, T2, N, p, kappa, out_e, out_p, out_kappa, out_force, out_dlam,
             out_status, out_diss):
    out_e[i, 0] = e0
    out_e[i, 1] = e1
    out_e[i, 2] = e2
    out_p[i, 0] = p[i, 0]
    out_p[i, 1] = p[i, 1]
    out_p[i, 2] = p[i, 2]
    out_force[i, 0] = T1
    out_force[i, 1] = T2
    out_force[i, 2] = N
    out_kappa[i] = kappa[i]
    out_dlam[i] = 0.0
    out_status[i] = ELASTIC
    out_diss[i] = 0.0


@njit(inline="always")
def _plastic(i, e0, e1, e2, T1, T2, N, kt, kn, dl, dkappa, p, kappa, out_e, out_p, out_kappa,
             out_force, out_dlam, out_status, out_diss):
    f0 = T1 / kt
    f1 = T2 / kt
    f2 = -N / kn
    d0 = e0 - f0
    d1 = e1 - f1
    d2 = e2 - f2
    out_e[i, 0] = f0
    out_e[i, 1] = f1
    out_e[i, 2] = f2
    out_p[i, 0] = p[i, 0] + d0
    out_p[i, 1] = p[i, 1] + d1
    out_p[i, 2] = p[i, 2] + d2
    out_force[i, 0] = T1
    out_force[i, 1] = T2
    out_force[i, 2] = N
    out_kappa[i] = kappa[i] + dkappa
    out_dlam[i] = dl
    out_status[i] = PLASTIC
    out_diss[i] = T1 * d0 + T2 * d1 - N * d2


@njit(inline="always", error_model="numpy")
def _coulomb_update_one(i, e, p, kappa, du, kt, kn, mu, dilatant, out_e, out_p, out_kappa, out_force,
                        out_dlam, out_status, out_diss):
    e0, e1, e2, T1, T2, N = _trial(i, e, du, kt, kn)
    if N <= 0.0:
        _open(i, e2, p, kappa, out_e, out_p, out_kappa, out_force, out_dlam, out_status, out_diss, e0,
              e1)
        return
    r = np.sqrt(T1 * T1 + T2 * T2)
    f = r - mu * N
    if f <= 0.0:
        _elastic(i, e0, e1, e2, T1, T2, N, p, kappa, out_e, out_p, out_kappa, out_force, out_dlam,
                 out_status, out_diss)
        return
    if dilatant:
        dl = f / (kt + kn * mu * mu)
        N = N + kn * mu * dl
    else:
        dl = f / kt
    c = mu * N / r
    _plastic(i, e0, e1, e2, T1 * c, T2 * c, N, kt, kn, dl, dl, p, kappa, out_e, out_p, out_kappa,
             out_force, out_dlam, out_status, out_diss)


#: Division by a reciprocal and fused multiply-add (no NaN/inf assumptions): within an ulp of
#: the plain arithmetic, and the radial return runs at C speed (0.86x -> 0.96x of gcc -O3).
_FAST = {"arcp", "contract"}


@njit(parallel=True, cache=True, error_model="numpy", fastmath=_FAST)
def coulomb_update(e, p, kappa, du, kt, kn, mu, dilatant,
                   out_e, out_p, out_kappa, out_force, out_dlam, out_status, out_diss):
    """Backward-Euler radial return of Coulomb friction, ``f = |T| - mu N``.

    ``dilatant`` selects g = f ((1.6): normal slip ``mu |Δδtᵖ|``, opening) instead of g = |T|.
    """
    for i in prange(e.shape[0]):
        _coulomb_update_one(i, e, p, kappa, du, kt, kn, mu, dilatant, out_e, out_p, out_kappa,
                            out_force, out_dlam, out_status, out_diss)


@njit(cache=True, error_model="numpy", fastmath=_FAST)
def coulomb_update_serial(e, p, kappa, du, kt, kn, mu, dilatant,
                          out_e, out_p, out_kappa, out_force, out_dlam, out_status, out_diss):
    """Serial twin of :func:`coulomb_update` for small batches (no thread launch)."""
    for i in range(e.shape[0]):
        _coulomb_update_one(i, e, p, kappa, du, kt, kn, mu, dilatant, out_e, out_p, out_kappa,
                            out_force, out_dlam, out_status, out_diss)


@njit(inline="always")
def _cap_residual(lam, kap, bet, t2tr, Ntr, kt, kn, m2, om, p_, h, kh, b, kap_n, bet_n, fs):
    """Residual and Jacobian of the reduced cap return in ``x = (Δλ, κ, β)`` (see cap_update)."""
    a = 1.0 + 2.0 * lam * kt / m2
    bb = 1.0 + 2.0 * kn * om * lam
    ex = np.exp(-kap / kh)
    s = 1.0 + h * (1.0 - ex)
    A = p_ * bet * s
    A_k = p_ * bet * h * ex / kh
    A_b = p_ * s
    N = (Ntr + 2.0 * kn * om * lam * A) / bb
    t2 = t2tr / (a * a)
    t = np.sqrt(t2)
    B = b * bet * (1.0 - bet)
    dB = b * (1.0 - 2.0 * bet)
    G = N - A
    dN_dl = 2.0 * kn * om * (A - N) / bb
    dN_dA = 2.0 * kn * om * lam / bb
    dt2_dl = -2.0 * t2 * (2.0 * kt / m2) / a
    dt_dl = -t * (2.0 * kt / m2) / a
    r1 = (N * N - 2.0 * A * N + t2 / m2) / fs
    r2 = kap - kap_n - lam * 2.0 * t / m2
    r3 = bet - bet_n - 2.0 * om * lam * B * G
    fA = 2.0 * G * dN_dA - 2.0 * N
    j11 = (2.0 * G * dN_dl + dt2_dl / m2) / fs
    j12 = fA * A_k / fs
    j13 = fA * A_b / fs
    j21 = -2.0 * t / m2 - lam * 2.0 * dt_dl / m2
    j22 = 1.0
    j23 = 0.0
    dG_dA = dN_dA - 1.0
    j31 = -2.0 * om * (B * G + lam * B * dN_dl)
    j32 = -2.0 * om * lam * B * dG_dA * A_k
    j33 = 1.0 - 2.0 * om * lam * (dB * G + B * dG_dA * A_b)
    return r1, r2, r3, j11, j12, j13, j21, j22, j23, j31, j32, j33, N, a


@njit(inline="always", error_model="numpy")
def _cap_update_one(i, e, p, kappa, beta, du, kt, kn, m2, om, p_, h, kh, b, out_e, out_p, out_kappa,
                    out_beta, out_force, out_dlam, out_status, out_diss):
    e0, e1, e2, T1, T2, N = _trial(i, e, du, kt, kn)
    out_beta[i] = beta[i]
    if N <= 0.0:
        _open(i, e2, p, kappa, out_e, out_p, out_kappa, out_force, out_dlam, out_status, out_diss, e0,
              e1)
        return
    A0 = p_ * beta[i] * (1.0 + h * (1.0 - np.exp(-kappa[i] / kh)))
    t2tr = T1 * T1 + T2 * T2
    if N * N - 2.0 * A0 * N + t2tr / m2 <= 0.0:
        _elastic(i, e0, e1, e2, T1, T2, N, p, kappa, out_e, out_p, out_kappa, out_force, out_dlam,
                 out_status, out_diss)
        return
    fs = A0 * A0 + N * N + t2tr / m2
    sk = kt / np.sqrt(fs)
    lam = 0.0
    kap = kappa[i]
    bet = beta[i]
    ok = False
    (r1, r2, r3, j11, j12, j13, j21, j22, j23, j31, j32, j33, Nn, a) = _cap_residual(
        lam, kap, bet, t2tr, N, kt, kn, m2, om, p_, h, kh, b, kappa[i], beta[i], fs)
    merit = np.sqrt(r1 * r1 + (r2 * sk) ** 2 + r3 * r3)
    for _ in range(60):
        if merit <= 1e-14:
            ok = True
            break
        det = (j11 * (j22 * j33 - j23 * j32) - j12 * (j21 * j33 - j23 * j31)
               + j13 * (j21 * j32 - j22 * j31))
        if det == 0.0 or not np.isfinite(det):
            break
        d1 = -(r1 * (j22 * j33 - j23 * j32) - j12 * (r2 * j33 - j23 * r3)
               + j13 * (r2 * j32 - j22 * r3)) / det
        d2 = -(j11 * (r2 * j33 - j23 * r3) - r1 * (j21 * j33 - j23 * j31)
               + j13 * (j21 * r3 - r2 * j31)) / det
        d3 = -(j11 * (j22 * r3 - r2 * j32) - j12 * (j21 * r3 - r2 * j31)
               + r1 * (j21 * j32 - j22 * j31)) / det
        alpha = 1.0
        accepted = False
        for _ in range(30):
            lt = lam + alpha * d1
            kt_ = kap + alpha * d2
            bt = bet + alpha * d3
            if lt >= 0.0 and bt > 0.0 and bt < 1.0:
                (s1, s2, s3, k11, k12, k13, k21, k22, k23, k31, k32, k33, Nt, at) = _cap_residual(
                    lt, kt_, bt, t2tr, N, kt, kn, m2, om, p_, h, kh, b, kappa[i], beta[i], fs)
                mt = np.sqrt(s1 * s1 + (s2 * sk) ** 2 + s3 * s3)
                if mt <= (1.0 - 1e-4 * alpha) * merit:
                    lam, kap, bet, merit, Nn, a = lt, kt_, bt, mt, Nt, at
                    r1, r2, r3, j11, j12, j13, j21, j22, j23, j31, j32, j33 = (
                        s1, s2, s3, k11, k12, k13, k21, k22, k23, k31, k32, k33)
                    accepted = True
                    break
            alpha *= 0.5
        if not accepted:
            break
    if not ok:
        out_status[i] = -1
        return
    _plastic(i, e0, e1, e2, T1 / a, T2 / a, Nn, kt, kn, lam, kap - kappa[i], p, kappa, out_e, out_p,
             out_kappa, out_force, out_dlam, out_status, out_diss)
    out_beta[i] = bet


@njit(parallel=True, cache=True, error_model="numpy")
def cap_update(e, p, kappa, beta, du, kt, kn, m, om, p_, h, kh, b,
               out_e, out_p, out_kappa, out_beta, out_force, out_dlam, out_status, out_diss):
    r"""Backward-Euler return onto the ellipsoidal cap (4.9) with the default A(κ, β), B(β).

    For given ``Δλ`` and ``A`` the return is explicit: :math:`T = T^{tr}/(1 + 2\Delta\lambda k_t/m^2)`,
    :math:`N = (N^{tr} + 2k_n\omega\Delta\lambda A)/(1 + 2k_n\omega\Delta\lambda)`; Newton's method
    with backtracking solves the remaining three equations ``f = 0``,
    :math:`\kappa = \kappa_n + 2\Delta\lambda|T|/m^2`,
    :math:`\beta = \beta_n + 2\omega\Delta\lambda B(\beta)(N - A)` for ``(Δλ, κ, β)``.
    A contact whose iteration fails gets status -1 (the caller falls back to the generic path).
    """
    m2 = m * m
    for i in prange(e.shape[0]):
        _cap_update_one(i, e, p, kappa, beta, du, kt, kn, m2, om, p_, h, kh, b, out_e, out_p, out_kappa,
                        out_beta, out_force, out_dlam, out_status, out_diss)


@njit(cache=True, error_model="numpy")
def cap_update_serial(e, p, kappa, beta, du, kt, kn, m, om, p_, h, kh, b,
                      out_e, out_p, out_kappa, out_beta, out_force, out_dlam, out_status, out_diss):
    """Serial twin of :func:`cap_update` for small batches (no thread launch)."""
    m2 = m * m
    for i in range(e.shape[0]):
        _cap_update_one(i, e, p, kappa, beta, du, kt, kn, m2, om, p_, h, kh, b, out_e, out_p, out_kappa,
                        out_beta, out_force, out_dlam, out_status, out_diss)


def outputs(n: int) -> tuple:
    """Fresh output arrays ``(e, p, kappa, force, dlam, status, diss)`` for ``n`` contacts."""
    return (np.empty((n, 3)), np.empty((n, 3)), np.empty(n), np.empty((n, 3)), np.empty(n),
            np.empty(n, dtype=np.int8), np.empty(n))


#: Below this batch size the serial twins run (a thread launch costs more than the work).
SERIAL_BELOW = 2048


def _coulomb(serial, e, p, q, du, kt, kn, params, out):
    mu, dilatant = params
    (coulomb_update_serial if serial else coulomb_update)(e, p, np.zeros(len(e)), du, kt, kn, mu,
                                                          bool(dilatant), *out)
    return q.copy(), out[2]


def _cap(serial, e, p, q, du, kt, kn, params, out):
    kappa, beta = np.ascontiguousarray(q[:, 0]), np.ascontiguousarray(q[:, 1])
    beta1 = np.empty(len(e))
    (cap_update_serial if serial else cap_update)(e, p, kappa, beta, du, kt, kn, *params,
                                                  *out[:3], beta1, *out[3:])
    return np.stack((out[2], beta1), axis=-1), out[2] - q[:, 0]


#: The hand-written kernels, by the name a law's closed-form return gives: each runs a batch
#: and returns the new internal variables and the accumulated slip of the step.
KERNELS = {"coulomb": _coulomb, "cap": _cap}


def run_kernel(cfr, kt, kn, e, p, q, du):
    """Run a law's closed-form return ``cfr`` (:class:`~frictionrules.laws.ClosedFormReturn`).

    ``q`` holds the law's internal variables ``(n, nq)``: none for Coulomb, ``(kappa, beta)``
    for the cap. Returns the step's rows and a boolean array of contacts whose
    iteration failed (the caller integrates those with the derived return mapping).
    """
    from ._step import Step
    out = outputs(len(e))
    e, p, du = (np.ascontiguousarray(a) for a in (e, p, du))
    q1, slip = KERNELS[cfr.kernel](len(e) < SERIAL_BELOW, e, p, q, du, kt, kn, cfr.params, out)
    e1, p1, _, force, dlam, status, diss = out
    failed = status < 0
    status = np.where(failed, 0, status).astype(np.int64)
    return Step(e1, p1, q1, force, dlam, status, diss, np.where(failed, 0.0, slip)), failed
