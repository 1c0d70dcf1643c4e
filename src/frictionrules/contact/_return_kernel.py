"""The compiled return mapping shared by every law: one Numba kernel, the law's functions as
arguments.

A law enters as three compiled C-callable functions printed from its symbolic form by
:mod:`frictionrules.contact._generated` (``lf``: f only; ``l1``: f, ∇f, ∂f/∂q, ∇g, h; ``l2``:
every quantity of :func:`frictionrules.codegen.local_layout`), each
``(T1, T2, N, *q, *p, *w) -> int`` writing into the flat layout ``w``
(:data:`LOCAL_SIGNATURE`), passed by address, so this kernel is compiled once, for every law,
and cached by Numba; a new law compiles only its three small functions.

The algorithm is the one of :func:`frictionrules.contact.integrate.return_map` and
:func:`frictionrules.contact._step.generic_step`, contact by contact: elastic trial (4.2),
separation, the limit check, backward Euler solved by Newton's method on the dimensionless
residual with a backtracking line search, returns that end at the apex of a cone, the
consistent tangent (the σ-block of the inverse Jacobian times E), and substeps where Newton's
iteration fails.

:func:`contact_update` is the one compiled entry for one contact of any law, called from the
batch kernel :func:`update` here (:meth:`ContactModel.update`) and from the time loop of the
grain assemblies' dynamic engine; it reads and writes the named rows of
:mod:`frictionrules.contact.layout` (a law's row, a contact's state row, its result row) with
a per-thread :class:`Workspace`.
"""


import math
from typing import NamedTuple

import numpy as np
from numba import njit

from .layout import LAW_CLIP, LAW_HAS_KAPPA, LAW_KAPPA, LAW_KN, LAW_KT, LAW_NQ, LAW_PARAMS, RES_DISSIPATION, RES_DLAM, RES_FORCE, RES_SLIP, RET_KIND, STATE_E, STATE_P, STATE_Q
from .._returnspec import ELASTIC as _ELASTIC
from .._returnspec import OPEN as _OPEN
from .._returnspec import PLASTIC as _PLASTIC
from .._returnspec import RETURN_ELLIPTIC as _RETURN_ELLIPTIC
from .._returnspec import RETURN_RADIAL as _RETURN_RADIAL
from .._returnspec import TOL as _TOL
from ._kernel_law import _eval, _layout
from ._kernel_newton import _apex_region, _factor, _jacobian, _lu_solve, _return, _tangent_cone
from ._kernel_special import _elliptic, _radial


class Workspace(NamedTuple):
    """Scratch arrays of one thread's contact updates for laws with one number ``nq`` of
    internal variables (:func:`workspace`): the trial forces, the vectors of the Newton
    iteration, the law's quantities at the iterate and at a line-search trial, the Jacobian
    and its pivots, and two state rows and an increment for substeps. Sized exactly (views cut
    per contact from a larger one cost a third of a Coulomb update), so a loop over laws with
    different ``nq`` keeps one workspace per ``nq``."""

    sig_tr: np.ndarray
    dv: np.ndarray
    qn: np.ndarray
    V: np.ndarray
    w: np.ndarray
    wk: np.ndarray
    J: np.ndarray
    piv: np.ndarray
    cur: np.ndarray
    nxt: np.ndarray
    du: np.ndarray


@njit(cache=True)
def workspace(nq):
    """A :class:`Workspace` for laws with ``nq`` internal variables."""
    m = 4 + nq
    size = _layout(nq)[8]
    return Workspace(np.empty(3), np.empty(3), np.empty(nq), np.zeros((7, m)), np.zeros(size),
                     np.zeros(size), np.empty((m, m)), np.empty(m, dtype=np.int64),
                     np.empty(STATE_Q + nq), np.empty(STATE_Q + nq), np.empty(3))


@njit(inline="always", error_model="numpy", _nrt=False)
def _attempt(fn, law, s, du, s1, res, ws, want_tangent, tan):
    """One backward-Euler step of one contact (no substeps): trial, limit check, return,
    outputs. Returns ``(status, failed)``; a failed Newton iteration leaves the trial. ``ws``
    is sized for the law's ``nq``."""
    lf, l1, l2 = fn[0], fn[1], fn[2]
    kt, kn = law[LAW_KT], law[LAW_KN]
    clip = law[LAW_CLIP] != 0.0
    kind_r = int(law[RET_KIND])
    NQ = int(law[LAW_NQ])
    _M = 4 + NQ
    p = law[LAW_PARAMS:]
    dv, sig_tr, qn = ws.dv, ws.sig_tr, ws.qn
    dv[0], dv[1], dv[2] = kt, kt, kn
    V = ws.V
    w, wk = ws.w, ws.wk
    J, piv = ws.J, ws.piv
    x, step = V[0], V[6]
    et0 = s[STATE_E] + du[0]
    et1 = s[STATE_E + 1] + du[1]
    et2 = s[STATE_E + 2] + du[2]
    sig_tr[0] = kt * et0
    sig_tr[1] = kt * et1
    sig_tr[2] = -kn * et2
    for j in range(NQ):
        qn[j] = s[STATE_Q + j]
        s1[STATE_Q + j] = qn[j]
    failed = False
    kind = _OPEN
    apex = False
    dlam = 0.0
    s0 = sv1 = s2 = 0.0
    if sig_tr[2] > 0.0:
        # The residual's quantities at the trial: the limit check, and the return's start.
        _eval(lf, l1, l2, clip, sig_tr[0], sig_tr[1], sig_tr[2], qn, p, w, 1)
        if w[0] <= 0.0:
            kind = _ELASTIC
            s0, sv1, s2 = sig_tr[0], sig_tr[1], sig_tr[2]
        elif ((kind_r == _RETURN_RADIAL and _radial(lf, l1, clip, law, sig_tr, qn, p, dv, w, wk, x))
              or (kind_r == _RETURN_ELLIPTIC and _elliptic(law, sig_tr, kt, w[0], x))
              or _return(lf, l1, l2, clip, sig_tr, qn, p, dv, V, w, wk, J, piv)):
            s0, sv1, s2 = x[0], x[1], x[2]
            dlam = x[_M - 1]
            ntr2 = sig_tr[0] ** 2 + sig_tr[1] ** 2 + sig_tr[2] ** 2
            if s2 < 0.0 or s0 * s0 + sv1 * sv1 + s2 * s2 <= _TOL * _TOL * ntr2:
                apex = True
            else:
                kind = _PLASTIC
                for j in range(NQ):
                    s1[STATE_Q + j] = x[3 + j]
        else:
            ntr = math.sqrt(sig_tr[0] ** 2 + sig_tr[1] ** 2 + sig_tr[2] ** 2)
            if sig_tr[2] <= _TOL * ntr or _apex_region(lf, l1, l2, clip, sig_tr, qn, p, dv, w):
                apex = True
            else:
                failed = True
                kind = _ELASTIC
                s0, sv1, s2 = sig_tr[0], sig_tr[1], sig_tr[2]
    if kind == _OPEN:
        s0 = sv1 = s2 = 0.0
        f0, f1, f2 = 0.0, 0.0, max(et2, 0.0)
    elif kind == _ELASTIC:
        f0, f1, f2 = et0, et1, et2
    else:
        f0, f1, f2 = s0 / kt, sv1 / kt, -s2 / kn
    d0, d1, d2 = et0 - f0, et1 - f1, et2 - f2
    s1[STATE_E], s1[STATE_E + 1], s1[STATE_E + 2] = f0, f1, f2
    s1[STATE_P] = s[STATE_P] + d0
    s1[STATE_P + 1] = s[STATE_P + 1] + d1
    s1[STATE_P + 2] = s[STATE_P + 2] + d2
    res[RES_FORCE], res[RES_FORCE + 1], res[RES_FORCE + 2] = s0, sv1, s2
    res[RES_DLAM] = dlam
    slip = 0.0
    if kind == _PLASTIC:
        res[RES_DISSIPATION] = s0 * d0 + sv1 * d1 - s2 * d2
        slip = math.sqrt(d0 * d0 + d1 * d1)
    else:
        res[RES_DISSIPATION] = 0.0
    if apex:
        a_slip = math.sqrt(et0 * et0 + et1 * et1)
        slip += a_slip
        if law[LAW_HAS_KAPPA] != 0.0:
            kc = int(law[LAW_KAPPA])
            s1[STATE_Q + kc] = qn[kc] + a_slip
    res[RES_SLIP] = slip
    if want_tangent and not failed:
        for a in range(3):
            for b in range(3):
                tan[a, b] = 0.0
        if kind == _ELASTIC:
            tan[0, 0] = kt
            tan[1, 1] = kt
            tan[2, 2] = -kn
        elif kind == _PLASTIC:
            # dσ/dσ_trial: the σ-block of the inverse (unscaled) Jacobian, times E.
            _eval(lf, l1, l2, clip, x[0], x[1], x[2], x[3:3 + NQ], p, w, 2)
            if NQ == 0 and _tangent_cone(w, dlam, dv, tan):
                return kind, failed
            _jacobian(w, dlam, dv, J)
            if _factor(J, piv):
                for c in range(3):
                    for a in range(_M):
                        step[a] = 1.0 if a == c else 0.0
                    _lu_solve(J, piv, step)
                    ec = kt if c < 2 else -kn
                    for a in range(3):
                        tan[a, c] = step[a] * ec
            else:
                failed = True
    return kind, failed


@njit(inline="always", error_model="numpy", _nrt=False)
def contact_update(fn, law, s, du, s1, res, ws, max_depth, want_tangent, tan):
    """One step of one contact with any law: the compiled entry of every consumer.

    Parameters
    ----------
    fn : int64 array (3,)
        Addresses of the law's generated local functions (f; the residual's quantities; the
        Jacobian's) — :attr:`CompiledLaw.fn`.
    law : float64 array
        The law's row (:mod:`frictionrules.contact.layout`: stiffnesses, flags, parameters).
    s : float64 array
        The contact's state row at the start of the step (``e, p, q``); not modified.
    du : float64 array (3,)
        Increment of the local displacement ``(Δδt1, Δδt2, Δδn)``, ``δn > 0`` opening.
    s1, res : float64 arrays
        Written: the state row at the end of the step and the result row (forces, Δλ,
        dissipation, slip).
    ws : Workspace
        Scratch arrays of the calling thread for the law's ``nq`` (:func:`workspace`).
    max_depth : int
        Where Newton's iteration fails the step is halved, recursively, to at most
        ``2**max_depth`` substeps (0: no substeps; the state is left at the trial and
        ``failed`` is True).
    want_tangent : bool
        Write the consistent tangent ``d(T1, T2, N)/d(δt1, δt2, δn)`` into ``tan`` (3, 3)
        (only without substeps: it is not computed for a substepped step).

    Returns
    -------
    status : int
        0 elastic, 1 plastic, 2 open (``frictionrules.contact.state``).
    failed : bool
        True where the step did not converge even after the substeps.
    """
    kind, failed = _attempt(fn, law, s, du, s1, res, ws, want_tangent, tan)
    if not failed or max_depth == 0:
        return kind, failed
    # Halve the step where the iteration fails, as the exported C and Fortran updates do: the
    # substeps of depth d are 2**-d of the step, taken in order from the start's state.
    n = STATE_Q + int(law[LAW_NQ])
    cur, nxt, dus = ws.cur, ws.nxt, ws.du
    for k in range(n):
        cur[k] = s[k]
    full = 1 << max_depth
    pos, depth = 0, 1
    kind = prev = _ELASTIC
    dlam = diss = slip = 0.0
    while pos < full:
        frac = math.ldexp(1.0, -depth)
        for a in range(3):
            dus[a] = du[a] * frac
        now, bad = _attempt(fn, law, cur, dus, nxt, res, ws, False, tan)
        if bad:
            if depth >= max_depth:
                return _ELASTIC, True
            depth += 1
            continue
        prev, kind = kind, now
        dlam += res[RES_DLAM]
        diss += res[RES_DISSIPATION]
        slip += res[RES_SLIP]
        for k in range(n):
            cur[k] = nxt[k]
        pos += full >> depth
        while depth > 0 and pos % (full >> (depth - 1)) == 0:
            depth -= 1
    for k in range(n):
        s1[k] = cur[k]
    res[RES_DLAM], res[RES_DISSIPATION], res[RES_SLIP] = dlam, diss, slip
    if kind == _ELASTIC and prev == _PLASTIC:
        kind = _PLASTIC
    return kind, False


@njit(error_model="numpy", _nrt=False)
def _range(fn, law, S, DU, S1, RES, STATUS, FAILED, TAN, want_tangent, max_depth, lo, hi, ws):
    """Contacts ``lo <= i < hi`` with one workspace (no reference counting in the loop)."""
    for i in range(lo, hi):
        STATUS[i], FAILED[i] = contact_update(fn, law, S[i], DU[i], S1[i], RES[i], ws,
                                              max_depth, want_tangent, TAN[i if want_tangent else 0])


@njit(nogil=True, cache=True, error_model="numpy")
def update(fn, law, inputs, outputs, want_tangent, max_depth, lo, hi):
    """Contacts ``lo <= i < hi`` of one law (without the GIL: the caller runs chunks on
    threads). ``inputs = (S, DU)``: state rows (n, 6 + nq) and increments (n, 3);
    ``outputs = (S1, RES, STATUS, FAILED, TAN)``: state rows, result rows (n, 6), status
    (int8), failure flags (bool) and tangents (n, 3, 3) or (1, 3, 3)."""
    S, DU = inputs
    S1, RES, STATUS, FAILED, TAN = outputs
    ws = workspace(int(law[LAW_NQ]))
    _range(fn, law, S, DU, S1, RES, STATUS, FAILED, TAN, want_tangent, max_depth, lo, hi, ws)
