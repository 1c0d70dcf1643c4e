"""A batch of contacts of one law as the compiled batch loop reads and writes it (the loop
itself is printed with the law's step, :mod:`frictionrules.contact._step_source`): named
arrays in and out, and the copies between them and a contact's rows
(:mod:`frictionrules.contact.layout`)."""

from typing import NamedTuple

import numpy as np
from numba import njit

from .layout import RES_DISSIPATION, RES_DLAM, RES_FORCE, RES_SLIP, STATE_E, STATE_P, STATE_Q


class Batch(NamedTuple):
    """Inputs of a batch of contacts of one law: elastic and plastic displacements ``e, p``
    (n, 3), internal variables ``q`` (n, nq) and increments ``du`` (n, 3)."""

    e: np.ndarray
    p: np.ndarray
    q: np.ndarray
    du: np.ndarray


class BatchResult(NamedTuple):
    """Outputs of a batch, each its own array (as :class:`~frictionrules.contact._step.Step`
    holds them): ``e, p`` (n, 3), ``q`` (n, nq), ``force`` (n, 3), ``dlam``, ``dissipation``,
    ``slip`` (n,), ``status`` (int64), ``failed`` (bool) and ``tangent`` (n, 3, 3), or
    (1, 3, 3) when not asked for."""

    e: np.ndarray
    p: np.ndarray
    q: np.ndarray
    force: np.ndarray
    dlam: np.ndarray
    dissipation: np.ndarray
    slip: np.ndarray
    status: np.ndarray
    failed: np.ndarray
    tangent: np.ndarray


def batch_result(n: int, nq: int, tangent: bool) -> BatchResult:
    """Fresh outputs for ``n`` contacts."""
    return BatchResult(np.empty((n, 3)), np.empty((n, 3)), np.empty((n, nq)), np.empty((n, 3)),
                       np.empty(n), np.empty(n), np.empty(n), np.empty(n, dtype=np.int64),
                       np.empty(n, dtype=np.bool_), np.empty((n if tangent else 1, 3, 3)))


@njit(inline="always", error_model="numpy", _nrt=False)
def load_row(batch, i, s):
    """Contact ``i``'s state row into ``s``."""
    for a in range(3):
        s[STATE_E + a] = batch.e[i, a]
        s[STATE_P + a] = batch.p[i, a]
    for j in range(batch.q.shape[1]):
        s[STATE_Q + j] = batch.q[i, j]


@njit(inline="always", error_model="numpy", _nrt=False)
def store_rows(out, i, s1, res):
    """Contact ``i``'s new state row ``s1`` and result row ``res`` into the outputs."""
    for a in range(3):
        out.e[i, a] = s1[STATE_E + a]
        out.p[i, a] = s1[STATE_P + a]
        out.force[i, a] = res[RES_FORCE + a]
    for j in range(out.q.shape[1]):
        out.q[i, j] = s1[STATE_Q + j]
    out.dlam[i] = res[RES_DLAM]
    out.dissipation[i] = res[RES_DISSIPATION]
    out.slip[i] = res[RES_SLIP]
