r"""Proximal point with an inner semismooth Newton (``method="prox"``).

:math:`r_{k+1}` solves the problem with :math:`W + \sigma I`, :math:`q - \sigma r_k` (better
conditioned, unique solution), each by a few Newton steps (:mod:`._newton`); :math:`\sigma`
shrinks while the outer error falls (:class:`ProxOptions`). It is the fastest on the badly
conditioned problems (stacks, towers), as Siconos' PROX is.
"""

from __future__ import annotations

import numpy as np

from ._frame import _Frame, _Monitor
from ._newton import newton_steps
from ._options import ProxOptions


def run_prox(fr: _Frame, r, max_iter: int, mon: _Monitor, opts: ProxOptions):
    """Outer proximal iterations from ``r``; returns ``(r, outer iterations)``."""
    import scipy.sparse as sp

    from . import _kernels as K
    n = 3 * fr.nc
    sigma = opts.sigma0 * fr.mean_diag
    eye = sp.identity(n, format="csr")
    err = fr.error(r)
    if err <= mon.tol:
        return r, 0
    it = 0
    while it < max_iter:
        it += 1
        Ws = (fr.W + sigma * eye).tocsr()
        qs = fr.q - sigma * r
        rho = fr.rho(Ws)
        inner_tol = max(0.1 * mon.tol, opts.inner_rtol * err)

        def stop(rr, uu, qs=qs, rk=r, sigma=sigma):
            e = np.sqrt(K.error_sum(rr, uu, fr.mu, fr.d))
            if e <= inner_tol * max(np.linalg.norm(qs), np.linalg.norm(rr), np.linalg.norm(uu), 1e-300):
                return True
            # the outer problem's own error: u = W r + q = (Ws r + qs) - sigma (r - r_k); once it
            # is within tol, further inner steps are wasted
            return fr.error(rr, uu - sigma * (rr - rk)) <= mon.tol

        r_new, _ = newton_steps(fr, Ws, qs, r.copy(), rho, stop, opts.inner_max_iter,
                                lambda k, rr, uu: mon.out_of_time(), opts.newton)
        err_new = fr.error(r_new)
        sigma *= opts.shrink if err_new < err else opts.grow
        r, err = r_new, err_new
        if mon.record("prox", it, r, err):
            break
    return r, it
