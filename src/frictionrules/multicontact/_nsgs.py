r"""Non-smooth Gauss–Seidel (``method="nsgs"``).

Sweep the contacts, each solved exactly with the others frozen
(:func:`._kernels.local_solve`: separation, stick or slip found by enumeration); compiled with
Numba. The sweeps run in chunks of about ``NSGSOptions.chunk_seconds``, between which the
callback is called and the time limit checked. One sweep costs O(nnz(W)).
"""

from __future__ import annotations

import time

import numpy as np

from ._frame import _Frame, _Monitor
from ._options import NSGSOptions


def run_nsgs(fr: _Frame, r, max_iter: int, mon: _Monitor, opts: NSGSOptions):
    """Sweeps from ``r`` (updated in place) until converged, stopped or ``max_iter``.

    Returns the number of sweeps.
    """
    from . import _kernels as K
    D = K.diagonal_blocks(*fr.csr, fr.nc)
    done, chunk = 0, 1
    while done < max_iter:
        n = min(chunk, max_iter - done)
        hist_err, hist_it = np.full(n, np.nan), np.zeros(n, dtype=np.int64)
        t = time.perf_counter()
        it, err, nh = K.nsgs(*fr.csr, D, fr.q, fr.mu, fr.d, r, mon.tol, n, hist_err, hist_it, fr.norm_q,
                             opts.max_check_interval)
        per_sweep = (time.perf_counter() - t) / max(it, 1)
        for k in range(nh - 1):
            mon.errors.append(float(hist_err[k]))
            mon.iterations.append(mon.offset + done + int(hist_it[k]))
        done += it
        if mon.record("nsgs", done, r, err):
            break
        chunk = int(max(1, min(10 * chunk + 10, opts.chunk_seconds / max(per_sweep, 1e-9))))
    return done
