r"""One contact as the compiled steps read and write it, its trial and its outputs, shared by
the general compiled return (:mod:`frictionrules.contact._return_kernel`) and the steps
generated per law structure (:mod:`frictionrules.contact._step_source`), so that both write
the same numbers.

A contact is read from :class:`ContactIn` and written to :class:`ContactOut`, named views:
of a contact's rows (:func:`row_views`, :mod:`frictionrules.contact.layout`) for the compiled
entry, or of the batch's own arrays for the batch loop (no copies); the three scalars of the
result (Δλ, dissipation, slip) are returned.

Elastic law (4.2) :math:`\sigma = (k_t\delta^e_{t1}, k_t\delta^e_{t2}, -k_n\delta^e_n)`; at the
end of a step :math:`\delta^e = E^{-1}\sigma` and :math:`\Delta\delta^p = \delta^e_{tr} -
\delta^e`; the dissipation :math:`T\cdot\Delta\delta^p_t - N\Delta\delta^p_n` and the slip
:math:`|\Delta\delta^p_t|` (4.5) of a plastic step. An open contact keeps no elastic
tangential displacement (free motion goes to ``δtᵖ``) and its normal gap stays elastic.
"""

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from .._returnspec import ELASTIC, OPEN, PLASTIC
from .layout import (RES_DISSIPATION, RES_DLAM, RES_FORCE, RES_SLIP, STATE_E, STATE_P,
                     STATE_Q)


class ContactIn(NamedTuple):
    """One contact at the start of a step: ``e, p`` (3), ``q`` (nq), the increment ``du``
    (3)."""

    e: np.ndarray
    p: np.ndarray
    q: np.ndarray
    du: np.ndarray


class ContactOut(NamedTuple):
    """One contact at the end of a step: ``e, p`` (3), ``q`` (nq), ``force`` (3) and the
    tangent (3, 3), written only when asked for."""

    e: np.ndarray
    p: np.ndarray
    q: np.ndarray
    force: np.ndarray
    tangent: np.ndarray


@njit(inline="always", error_model="numpy", _nrt=False)
def row_views(s, du, s1, res, tan):
    """:class:`ContactIn` and :class:`ContactOut` of a contact's state rows ``s, s1``, its
    increment, result row and tangent."""
    return (ContactIn(s[STATE_E:STATE_E + 3], s[STATE_P:STATE_P + 3], s[STATE_Q:], du),
            ContactOut(s1[STATE_E:STATE_E + 3], s1[STATE_P:STATE_P + 3], s1[STATE_Q:],
                       res[RES_FORCE:RES_FORCE + 3], tan))


@njit(inline="always", error_model="numpy", _nrt=False)
def write_result(res, lam, diss, slip):
    """The scalars of a step into its result row."""
    res[RES_DLAM] = lam
    res[RES_DISSIPATION] = diss
    res[RES_SLIP] = slip


@njit(inline="always", error_model="numpy", _nrt=False)
def trial(c, kt, kn):
    """Elastic trial: ``δᵉ + Δδ`` and the forces (4.2), ``(e0, e1, e2, x0, x1, x2)``."""
    e0 = c.e[0] + c.du[0]
    e1 = c.e[1] + c.du[1]
    e2 = c.e[2] + c.du[2]
    return e0, e1, e2, kt * e0, kt * e1, -kn * e2


@njit(inline="always", error_model="numpy", _nrt=False)
def keep_q(c, out):
    """The internal variables unchanged."""
    for j in range(c.q.shape[0]):
        out.q[j] = c.q[j]


@njit(inline="always", error_model="numpy", _nrt=False)
def _write(c, out, f0, f1, f2, d0, d1, d2, y0, y1, y2):
    out.e[0], out.e[1], out.e[2] = f0, f1, f2
    out.p[0] = c.p[0] + d0
    out.p[1] = c.p[1] + d1
    out.p[2] = c.p[2] + d2
    out.force[0], out.force[1], out.force[2] = y0, y1, y2


@njit(inline="always", error_model="numpy", _nrt=False)
def _zero(tan):
    for a in range(3):
        for b in range(3):
            tan[a, b] = 0.0


@njit(inline="always", error_model="numpy", _nrt=False)
def finish_open(c, out, e0, e1, e2, want):
    """An open contact (or a return to the apex of a cone, with its slip added by the
    caller): no force, tangent 0. Writes every output but the internal variables; returns
    ``(OPEN, Δλ, dissipation, slip)``."""
    f2 = max(e2, 0.0)
    _write(c, out, 0.0, 0.0, f2, e0, e1, e2 - f2, 0.0, 0.0, 0.0)
    if want:
        _zero(out.tangent)
    return OPEN, 0.0, 0.0, 0.0


@njit(inline="always", error_model="numpy", _nrt=False)
def finish_elastic(c, out, e0, e1, e2, x0, x1, x2, kt, kn, want):
    """An elastic step: the trial, tangent ``E = diag(kt, kt, -kn)``. Writes every output but
    the internal variables; returns ``(ELASTIC, Δλ, dissipation, slip)``."""
    _write(c, out, e0, e1, e2, 0.0, 0.0, 0.0, x0, x1, x2)
    if want:
        tan = out.tangent
        _zero(tan)
        tan[0, 0] = kt
        tan[1, 1] = kt
        tan[2, 2] = -kn
    return ELASTIC, 0.0, 0.0, 0.0


@njit(inline="always", error_model="numpy", _nrt=False)
def finish_slip(c, out, e0, e1, e2, y0, y1, y2, lam, kt, kn, slip):
    """A plastic step ending at the forces ``y`` with the multiplier ``lam`` and the slip
    ``|Δδtᵖ|`` given (``Δλ |∂g/∂T|`` of a return whose flow direction is known). Writes every
    output but the internal variables and the tangent; returns ``(PLASTIC, Δλ, dissipation,
    slip)``."""
    f0, f1, f2 = y0 / kt, y1 / kt, -y2 / kn
    d0, d1, d2 = e0 - f0, e1 - f1, e2 - f2
    _write(c, out, f0, f1, f2, d0, d1, d2, y0, y1, y2)
    return PLASTIC, lam, y0 * d0 + y1 * d1 - y2 * d2, slip


@njit(inline="always", error_model="numpy", _nrt=False)
def finish_plastic(c, out, e0, e1, e2, y0, y1, y2, lam, kt, kn):
    """:func:`finish_slip` with the slip ``|Δδtᵖ|`` computed from the displacements."""
    d0, d1 = e0 - y0 / kt, e1 - y1 / kt
    return finish_slip(c, out, e0, e1, e2, y0, y1, y2, lam, kt, kn,
                       math.sqrt(d0 * d0 + d1 * d1))
