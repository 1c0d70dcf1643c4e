"""The compiled batched update of Coulomb friction written by hand (radial return in closed
form, both rules), on the batch layout of :mod:`frictionrules.contact._kernel_batch`.

Imported on first use (Numba loads here, not at ``import frictionrules``). The equations are
those of :mod:`frictionrules.contact.integrate`; the tests compare the kernel with the NumPy
return mapping derived from the law's symbolic form; ``benchmarks/c/contact_kernels.c`` is the
same arithmetic in C. The kernel stays while it is faster than the return generated from the
law's symbolic form by more than 10 % (``benchmarks/contact_update.py``).
"""

from __future__ import annotations

import math

from numba import njit, uint64

from .._returnspec import ELASTIC, OPEN, PLASTIC

#: Division by a reciprocal and fused multiply-add (no NaN/inf assumptions): within an ulp of
#: the plain arithmetic.
_FAST = {"arcp", "contract"}


@njit(inline="always", error_model="numpy", _nrt=False)
def _write(batch, out, i, f0, f1, f2, T1, T2, N, dl, status):
    """Contact ``i`` ends with elastic displacement ``f`` and forces ``(T1, T2, N)``."""
    e, p = batch.e, batch.p
    d0 = e[i, 0] + batch.du[i, 0] - f0
    d1 = e[i, 1] + batch.du[i, 1] - f1
    d2 = e[i, 2] + batch.du[i, 2] - f2
    out.e[i, 0], out.e[i, 1], out.e[i, 2] = f0, f1, f2
    out.p[i, 0], out.p[i, 1], out.p[i, 2] = p[i, 0] + d0, p[i, 1] + d1, p[i, 2] + d2
    out.force[i, 0], out.force[i, 1], out.force[i, 2] = T1, T2, N
    out.dlam[i] = dl
    out.dissipation[i] = T1 * d0 + T2 * d1 - N * d2 if status == PLASTIC else 0.0
    out.slip[i] = dl
    out.status[i] = status
    out.failed[i] = False


@njit(nogil=True, cache=True, error_model="numpy", fastmath=_FAST, _nrt=False)
def coulomb_range(kt, kn, mu, dilatant, batch, out, lo, hi):
    """Backward-Euler radial return of Coulomb friction, ``f = |T| - mu N``, for contacts
    ``lo <= i < hi`` (without the GIL: the caller runs chunks on threads; without reference
    counting and with an unsigned index, as the generated loop).

    ``dilatant`` selects g = f ((1.6): normal slip ``mu |Δδtᵖ|``, opening) instead of g = |T|:
    ``Δλ = f/(kt + kn mu²)`` and ``N += kn mu Δλ``, else ``Δλ = f/kt``; ``T = mu N T_tr/|T_tr|``,
    and the slip of the step is Δλ (|∂g/∂T| = 1).
    """
    e, du = batch.e, batch.du
    for i in range(uint64(lo), uint64(hi)):
        e0 = e[i, 0] + du[i, 0]
        e1 = e[i, 1] + du[i, 1]
        e2 = e[i, 2] + du[i, 2]
        T1, T2, N = kt * e0, kt * e1, -kn * e2
        if N <= 0.0:
            _write(batch, out, i, 0.0, 0.0, e2, 0.0, 0.0, 0.0, 0.0, OPEN)
            continue
        r = math.sqrt(T1 * T1 + T2 * T2)
        f = r - mu * N
        if f <= 0.0:
            _write(batch, out, i, e0, e1, e2, T1, T2, N, 0.0, ELASTIC)
            continue
        if dilatant:
            dl = f / (kt + kn * mu * mu)
            N = N + kn * mu * dl
        else:
            dl = f / kt
        c = mu * N / r
        _write(batch, out, i, T1 * c / kt, T2 * c / kt, -N / kn, T1 * c, T2 * c, N, dl, PLASTIC)


def run_kernel(cfr, kt, kn, batch):
    """Run a law's hand-written return ``cfr`` (:class:`~frictionrules.laws.ClosedFormReturn`,
    ``"coulomb"``: ``(mu, dilatant)``) over a batch; returns its
    :class:`~frictionrules.contact._kernel_batch.BatchResult`."""
    from ._kernel_batch import run_chunks
    mu, dilatant = cfr.params
    return run_chunks(coulomb_range, (float(kt), float(kn), float(mu), bool(dilatant)), batch, 0,
                      False)
