r"""SymPy derivation of the §3 contact functions and their derivatives, compiled on first use.

The limit condition and potential of one sliding contact are the wedge law (2.2), (2.6) in the
frame rotated by the azimuth ``psi`` of the contact's up-slope direction ((3.11), counter-
clockwise convention, see :mod:`frictionrules.configuration.geometry`), with a *signed*
inclination ``alpha`` in (-pi/2, pi/2) so that a grain passes over the top (``alpha = 0``)
without a jump of the up-slope direction:

.. math::
    T'_x &= T_x\cos\psi + T_y\sin\psi,\qquad T'_y = -T_x\sin\psi + T_y\cos\psi,\\
    T_1 &= T'_x\cos\alpha - Q\sin\alpha,\quad T_2 = T'_y,\quad N = T'_x\sin\alpha + Q\cos\alpha,\\
    f &= \sqrt{T_1^2 + T_2^2} - \mu N,\qquad g = \sqrt{T_1^2 + T_2^2}.

For ``0 < alpha < pi/2`` and ``psi = 0`` these are exactly
``WedgeAsperity(alpha, mu).limit`` and ``.potential`` (the tests check it).
"""

from __future__ import annotations

import functools

import numpy as np

from .._optional import require

#: Names of the compiled quantities, in the order :func:`contact_functions` returns them.
NAMES = ("f", "f_Tx", "f_Ty", "f_alpha", "f_psi", "g_Tx", "g_Ty",
         "g_TxTx", "g_TxTy", "g_TyTy", "g_Txalpha", "g_Tyalpha", "g_Txpsi", "g_Typsi", "g_Q", "N")


def expressions():
    """``(symbols, f, g, N)``: the SymPy expressions above; symbols ``(Tx, Ty, alpha, psi, Q, mu)``."""
    sp = require("sympy", extra="symbolic")

    Tx, Ty, a, p = sp.symbols("T_x T_y alpha psi", real=True)
    Q, mu = sp.symbols("Q mu", positive=True)
    tpx = Tx * sp.cos(p) + Ty * sp.sin(p)
    tpy = -Tx * sp.sin(p) + Ty * sp.cos(p)
    t1 = tpx * sp.cos(a) - Q * sp.sin(a)
    n = tpx * sp.sin(a) + Q * sp.cos(a)
    g = sp.sqrt(t1**2 + tpy**2)
    return (Tx, Ty, a, p, Q, mu), g - mu * n, g, n


@functools.lru_cache(maxsize=None)
def contact_functions():
    """Compiled ``F(Tx, Ty, alpha, psi, Q, mu) -> dict`` of the quantities in :data:`NAMES`."""
    sp = require("sympy", extra="symbolic")

    syms, f, g, n = expressions()
    Tx, Ty, a, p = syms[:4]
    exprs = [f, sp.diff(f, Tx), sp.diff(f, Ty), sp.diff(f, a), sp.diff(f, p),
             sp.diff(g, Tx), sp.diff(g, Ty),
             sp.diff(g, Tx, Tx), sp.diff(g, Tx, Ty), sp.diff(g, Ty, Ty),
             sp.diff(g, Tx, a), sp.diff(g, Ty, a), sp.diff(g, Tx, p), sp.diff(g, Ty, p),
             sp.diff(g, syms[4]), n]
    fn = sp.lambdify(syms, exprs, modules="numpy", cse=True)

    def evaluate(Tx, Ty, alpha, psi, Q, mu) -> dict:
        with np.errstate(divide="ignore", invalid="ignore"):
            vals = fn(Tx, Ty, alpha, psi, Q, mu)
        return {k: np.asarray(v, dtype=float) for k, v in zip(NAMES, vals)}

    return evaluate
