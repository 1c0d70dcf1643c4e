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


def batch_of(e, p, q, du) -> Batch:
    """A :class:`Batch` of the arrays (C-ordered float copies only where they are not)."""
    return Batch(*(np.ascontiguousarray(a, dtype=float) for a in (e, p, q, du)))


def step_of(out: BatchResult):
    """The :class:`~frictionrules.contact._step.Step` of a batch's outputs (no copies)."""
    from ._step import Step
    return Step(out.e, out.p, out.q, out.force, out.dlam, out.status, out.dissipation, out.slip)


#: Contacts per thread below which one thread runs (a thread costs more than the work).
SERIAL_BELOW = 2048


def run_chunks(loop, head: tuple, batch: Batch, nq: int, tangent: bool) -> BatchResult:
    """Run the compiled batch loop ``loop(*head, batch, out, lo, hi)`` (which releases the
    GIL) over fresh outputs, in chunks of contacts on Numba's number of threads."""
    from numba import get_num_threads
    n = len(batch.du)
    out = batch_result(n, nq, tangent)
    threads = min(get_num_threads(), n // SERIAL_BELOW)
    if threads <= 1:
        loop(*head, batch, out, 0, n)
        return out
    from concurrent.futures import ThreadPoolExecutor
    cuts = np.linspace(0, n, 4 * threads + 1).astype(int)
    with ThreadPoolExecutor(threads) as pool:
        jobs = [pool.submit(loop, *head, batch, out, int(a), int(b))
                for a, b in zip(cuts[:-1], cuts[1:])]
        for job in jobs:
            job.result()
    return out


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
