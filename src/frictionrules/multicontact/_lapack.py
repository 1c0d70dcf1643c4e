"""LAPACK's least-squares solve (``dgelsd``) for compiled code, without Numba's ``np.linalg.lstsq``.

:func:`min_norm_solve` gives what ``np.linalg.lstsq(J, b, -1.0)[0]`` gives for a square ``J``
(the same LAPACK routine, ``dgelsd``, with the same arguments: the minimum-norm least-squares
solution, singular values below machine precision times the largest treated as zero), from
SciPy's LAPACK (``scipy.linalg.cython_lapack``, the library Numba's own ``lstsq`` calls).

Why not Numba's ``np.linalg.lstsq``: compiling it (its argument checks, error messages and the
one- and two-dimensional variants of its right-hand side) took 6-12 s of the first call of
``frictionrules solve`` on a 2-core machine, more than the rest of the small-problem path;
this call compiles in a fraction of a second.

The routine is reached through a named symbol (``llvmlite.binding.add_symbol``), not a function
pointer, so that functions calling it stay cacheable by Numba (``cache=True``): the cached
machine code names the symbol, resolved again when a process loads it.
"""

from __future__ import annotations

import math

import numpy as np

from .._optional import require

numba = require("numba", extra="kernels")
types = numba.types

_SYMBOL = "frictionrules_dgelsd"


def _register() -> None:
    import llvmlite.binding as llvm
    from numba.core.extending import get_cython_function_address

    require("scipy", extra="solvers")
    llvm.add_symbol(_SYMBOL, get_cython_function_address("scipy.linalg.cython_lapack", "dgelsd"))


_register()

#: ``dgelsd(m, n, nrhs, a, lda, b, ldb, s, rcond, rank, work, lwork, iwork, info)``, every
#: argument by pointer (Fortran's convention; integers are C ints).
_dgelsd = types.ExternalFunction(_SYMBOL, types.void(*(types.voidptr,) * 14))


@numba.njit(cache=True)
def min_norm_solve(J, b):
    """The minimum-norm least-squares solution ``x`` of ``J x = b`` (``J`` square, ``(n, n)``;
    ``np.linalg.lstsq(J, b, rcond=-1)[0]``); a vector of NaN where LAPACK reports a failure
    (the SVD did not converge) or ``J``, ``b`` are not finite."""
    # Loops, not slice assignments or np.all: those compile Numba's shape checks and their
    # formatted error messages, seconds of a first call.
    n = b.size
    x = np.empty(n)
    a = np.empty((n, n))                 # C order of J.T: J in Fortran order
    rhs = np.empty(n)
    finite = True
    for i in range(n):
        x[i] = np.nan
        rhs[i] = b[i]
        finite = finite and math.isfinite(b[i])
        for j in range(n):
            a[j, i] = J[i, j]
            finite = finite and math.isfinite(J[i, j])
    if not finite:
        return x
    s = np.empty(max(n, 1))
    ints = np.empty(8, dtype=np.intc)    # m, n, nrhs, lda, ldb, rank, lwork, info
    ints[0], ints[1], ints[2], ints[3], ints[4], ints[5], ints[6], ints[7] = n, n, 1, max(n, 1), max(n, 1), 0, -1, 0
    rcond = np.empty(1)
    rcond[0] = -1.0
    query, iquery = np.empty(1), np.empty(1, dtype=np.intc)
    _dgelsd(ints[0:].ctypes, ints[1:].ctypes, ints[2:].ctypes, a.ctypes, ints[3:].ctypes, rhs.ctypes,
            ints[4:].ctypes, s.ctypes, rcond.ctypes, ints[5:].ctypes, query.ctypes, ints[6:].ctypes,
            iquery.ctypes, ints[7:].ctypes)
    if ints[7] != 0:
        return x
    ints[6] = max(int(query[0]), 1)
    work, iwork = np.empty(ints[6]), np.empty(max(iquery[0], 1), dtype=np.intc)
    _dgelsd(ints[0:].ctypes, ints[1:].ctypes, ints[2:].ctypes, a.ctypes, ints[3:].ctypes, rhs.ctypes,
            ints[4:].ctypes, s.ctypes, rcond.ctypes, ints[5:].ctypes, work.ctypes, ints[6:].ctypes,
            iwork.ctypes, ints[7:].ctypes)
    if ints[7] == 0:
        for i in range(n):
            x[i] = rhs[i]
    return x
