"""The compiled return mapping shared by every law: one Numba kernel, the law's functions as
arguments.

A law enters as compiled C-callable functions printed from its symbolic form by
:mod:`frictionrules.contact._generated`, passed by address (:mod:`frictionrules.contact.layout`
``FN_*``), so this kernel is compiled once, for every law, and cached by Numba; a new law
compiles only its own small functions:

* its **step** (:mod:`frictionrules.contact._step_source`): the whole step of a contact in
  straight-line code — trial, separation, limit check and, for the structures the code
  generator recognises (radial, elliptic), the return — or ``GENERAL``, where this kernel's
  general return takes the contact;
* its three **local functions** (``lf``: f only; ``l1``: f, ∇f, ∂f/∂q, ∇g, h; ``l2``: every
  quantity of :func:`frictionrules.codegen.local_layout`), each ``(T1, T2, N, *q, *p, *w)``
  writing into the flat layout ``w`` (:data:`LOCAL_SIGNATURE`), for the general return.

The general return is the algorithm of :func:`frictionrules.contact.integrate.return_map` and
:func:`frictionrules.contact._step.generic_step`, contact by contact: elastic trial (4.2),
separation, the limit check, backward Euler solved by Newton's method on the dimensionless
residual with a backtracking line search (or the elliptic return of the law's row), returns
that end at the apex of a cone, the consistent tangent (the σ-block of the inverse Jacobian
times E), and substeps where Newton's iteration fails.

:func:`contact_update` is the one compiled entry for one contact of any law, called from the
time loop of the grain assemblies' dynamic engine and from any user's compiled loop; it reads
and writes the named rows of :mod:`frictionrules.contact.layout` (a law's row, a contact's
state row, its result row) with a per-thread :class:`Workspace`. The batch loop of
:meth:`ContactModel.update` (printed with the law's step, :mod:`._step_source`) runs the same
step and :func:`general_return` contact by contact.
"""


import math
from typing import NamedTuple

import numpy as np
from numba import njit

from .._returnspec import ELASTIC as _ELASTIC
from .._returnspec import GENERAL as _GENERAL
from .._returnspec import OPEN as _OPEN
from .._returnspec import PLASTIC as _PLASTIC
from .._returnspec import RETURN_ELLIPTIC as _RETURN_ELLIPTIC
from .._returnspec import TOL as _TOL
from ._kernel_law import _call_step, _eval, _layout
from ._kernel_newton import _apex_region, _factor, _jacobian, _lu_solve, _return, _tangent_cone
from ._kernel_outputs import (finish_elastic, finish_open, finish_plastic, keep_q, row_views,
                              trial, write_result)
from ._kernel_special import elliptic_return
from .layout import (FN_F, FN_FIRST, FN_FULL, FN_STEP, LAW_CLIP, LAW_HAS_KAPPA, LAW_KAPPA, LAW_KN,
                     LAW_KT, LAW_NQ, LAW_PARAMS, RES_DISSIPATION, RES_DLAM, RES_SLIP, RET_KIND,
                     STATE_Q)


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


@njit(cache=True, error_model="numpy", _nrt=False)
def general_return(fn, law, s, du, s1, res, ws, want_tangent, tan):
    """One backward-Euler step of one contact by the general return (no substeps): trial,
    limit check, Newton's return (the elliptic one where the law's row says so), apex,
    outputs. Returns ``(status, failed)``; a failed Newton iteration leaves the trial. ``ws``
    is sized for the law's ``nq``."""
    c, out = row_views(s, du, s1, res, tan)
    kind, lam, diss, slip, failed = _general(fn, law, c, out, ws, want_tangent)
    write_result(res, lam, diss, slip)
    return kind, failed


@njit(inline="always", error_model="numpy", _nrt=False)
def _general(fn, law, c, out, ws, want_tangent):
    lf, l1, l2 = fn[FN_F], fn[FN_FIRST], fn[FN_FULL]
    kt, kn = law[LAW_KT], law[LAW_KN]
    clip = law[LAW_CLIP] != 0.0
    NQ = int(law[LAW_NQ])
    _M = 4 + NQ
    p = law[LAW_PARAMS:]
    dv, sig_tr, qn = ws.dv, ws.sig_tr, ws.qn
    dv[0], dv[1], dv[2] = kt, kt, kn
    V = ws.V
    w, wk = ws.w, ws.wk
    J, piv = ws.J, ws.piv
    x, step = V[0], V[6]
    tan = out.tangent
    et0, et1, et2, sig_tr[0], sig_tr[1], sig_tr[2] = trial(c, kt, kn)
    keep_q(c, out)
    for j in range(NQ):
        qn[j] = c.q[j]
    if not sig_tr[2] > 0.0:
        return finish_open(c, out, et0, et1, et2, want_tangent) + (False,)
    # The residual's quantities at the trial: the limit check, and the return's start.
    _eval(lf, l1, l2, clip, sig_tr[0], sig_tr[1], sig_tr[2], qn, p, w, 1)
    if w[0] <= 0.0:
        return finish_elastic(c, out, et0, et1, et2, sig_tr[0], sig_tr[1], sig_tr[2], kt, kn,
                              want_tangent) + (False,)
    if law[RET_KIND] == _RETURN_ELLIPTIC:
        ok, x[0], x[1], x[_M - 1] = elliptic_return(law, sig_tr[0], sig_tr[1], kt, w[0])
        x[2] = sig_tr[2]
    else:
        ok = False
    apex = False
    if ok or _return(lf, l1, l2, clip, sig_tr, qn, p, dv, V, w, wk, J, piv):
        ntr2 = sig_tr[0] ** 2 + sig_tr[1] ** 2 + sig_tr[2] ** 2
        apex = x[2] < 0.0 or x[0] * x[0] + x[1] * x[1] + x[2] * x[2] <= _TOL * _TOL * ntr2
    else:
        ntr = math.sqrt(sig_tr[0] ** 2 + sig_tr[1] ** 2 + sig_tr[2] ** 2)
        if not (sig_tr[2] <= _TOL * ntr or _apex_region(lf, l1, l2, clip, sig_tr, qn, p, dv, w)):
            return finish_elastic(c, out, et0, et1, et2, sig_tr[0], sig_tr[1], sig_tr[2], kt,
                                  kn, False) + (True,)
        apex = True
        x[_M - 1] = 0.0
    dlam = x[_M - 1]
    if apex:
        # The return ends at the apex: the contact is just closed, without force, and the
        # whole tangential elastic displacement becomes slip.
        finish_open(c, out, et0, et1, et2, want_tangent)
        a_slip = math.sqrt(et0 * et0 + et1 * et1)
        if law[LAW_HAS_KAPPA] != 0.0:
            kc = int(law[LAW_KAPPA])
            out.q[kc] = c.q[kc] + a_slip
        return _OPEN, dlam, 0.0, a_slip, False
    for j in range(NQ):
        out.q[j] = x[3 + j]
    kind, dlam, diss, slip = finish_plastic(c, out, et0, et1, et2, x[0], x[1], x[2], dlam, kt, kn)
    if not want_tangent:
        return kind, dlam, diss, slip, False
    # dσ/dσ_trial: the σ-block of the inverse (unscaled) Jacobian, times E.
    _eval(lf, l1, l2, clip, x[0], x[1], x[2], x[3:3 + NQ], p, w, 2)
    if NQ == 0 and _tangent_cone(w, dlam, dv, tan):
        return kind, dlam, diss, slip, False
    _jacobian(w, dlam, dv, J)
    if not _factor(J, piv):
        return kind, dlam, diss, slip, True
    for b in range(3):
        for a in range(_M):
            step[a] = 1.0 if a == b else 0.0
        _lu_solve(J, piv, step)
        eb = kt if b < 2 else -kn
        for a in range(3):
            tan[a, b] = step[a] * eb
    return kind, dlam, diss, slip, False


@njit(cache=True, error_model="numpy", _nrt=False)
def limit_value(fn, law, q, T1, T2, N, ws):
    """The law's limit condition :math:`f(T_1, T_2, N, q)` by its generated ``f`` alone (the
    limit check of :func:`contact_update`, with its kink rule: where f is not finite at the
    apex of a cone, the largest value on a small circle around it), for a caller that needs to
    know only whether a force is inside the limit surface (``f <= 0``) — tens of times cheaper
    than a whole update. ``q`` the internal variables (``nq`` of the law's row), ``ws`` a
    :func:`workspace` for that ``nq``."""
    w = ws.w
    _eval(fn[FN_F], fn[FN_FIRST], fn[FN_FULL], law[LAW_CLIP] != 0.0, T1, T2, N, q,
          law[LAW_PARAMS:], w, 0)
    return w[0]


@njit(inline="always", error_model="numpy", _nrt=False)
def _attempt(fn, law, s, du, s1, res, ws, want_tangent, tan):
    """One step of one contact (no substeps): the law's generated step, which takes elastic,
    open and the contacts of a special return in straight-line code, else the general
    return."""
    kind = _call_step(fn[FN_STEP], s, du, law, s1, res, tan, 1 if want_tangent else 0)
    if kind != _GENERAL:
        return kind, False
    return general_return(fn, law, s, du, s1, res, ws, want_tangent, tan)


@njit(inline="always", error_model="numpy", _nrt=False)
def contact_update(fn, law, s, du, s1, res, ws, max_depth, want_tangent, tan):
    """One step of one contact with any law: the compiled entry of every consumer.

    Parameters
    ----------
    fn : int64 array (4,)
        Addresses of the law's generated functions (:mod:`frictionrules.contact.layout`
        ``FN_*``: f; the residual's quantities; the Jacobian's; the whole step) —
        :attr:`CompiledLaw.fn`.
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
