"""The compiled return mapping's access to a law: its generated local functions
(:data:`LOCAL_SIGNATURE`) and its generated step (:data:`STEP_SIGNATURE`) called by address,
the offsets of the local functions' flat layout, and the kink rule."""

import math

import numpy as np
from llvmlite import ir
from numba import njit, types
from numba.extending import intrinsic

from .._returnspec import KINK_POINTS as _KINK_POINTS
from .._returnspec import KINK_RADIUS as _KINK_RADIUS


_PTR = types.CPointer(types.float64)
#: C signature of a law's local function ``(T1, T2, N, *q, *p, *w) -> 0`` (a Numba ``cfunc``).
LOCAL_SIGNATURE = types.int64(types.float64, types.float64, types.float64, _PTR, _PTR, _PTR)
#: C signature of a law's generated step ``(*s, *du, *law, *s1, *res, *tan, want_tangent) ->
#: status`` on the named rows of :mod:`frictionrules.contact.layout` (``tan`` row-major 3 × 3):
#: ``ELASTIC``, ``PLASTIC``, ``OPEN``, or ``GENERAL`` where the general return takes over.
STEP_SIGNATURE = types.int64(_PTR, _PTR, _PTR, _PTR, _PTR, _PTR, types.int64)


def _data(context, builder, signature, args, first):
    """Pointers to the data of the array arguments from ``first`` on."""
    dbl = ir.DoubleType()
    return [builder.bitcast(context.make_array(t)(context, builder, v).data, dbl.as_pointer())
            for t, v in zip(signature.args[first:], args[first:])]


@intrinsic
def _call_local(typingctx, address, x0, x1, x2, q, p, w):
    """Call the local function at ``address`` (:data:`LOCAL_SIGNATURE`) with the data of the
    arrays ``q, p, w``: a plain C call, as cheap as a call between compiled functions."""
    sig = types.int64(address, x0, x1, x2, q, p, w)

    def codegen(context, builder, signature, args):
        dbl = ir.DoubleType()
        fnty = ir.FunctionType(ir.IntType(64), [dbl, dbl, dbl] + [dbl.as_pointer()] * 3)
        fn = builder.inttoptr(args[0], fnty.as_pointer())
        return builder.call(fn, list(args[1:4]) + _data(context, builder, signature, args, 4))

    return sig, codegen


@intrinsic
def _call_step(typingctx, address, s, du, law, s1, res, tan, want):
    """Call the step at ``address`` (:data:`STEP_SIGNATURE`) with the data of the arrays (C
    order) and ``want`` (an int64)."""
    sig = types.int64(address, s, du, law, s1, res, tan, want)

    def codegen(context, builder, signature, args):
        dbl = ir.DoubleType()
        fnty = ir.FunctionType(ir.IntType(64), [dbl.as_pointer()] * 6 + [ir.IntType(64)])
        fn = builder.inttoptr(args[0], fnty.as_pointer())
        return builder.call(fn, _data(context, builder, signature, args[:7], 1) + [args[7]])

    return sig, codegen


@njit(inline="always")
def _layout(nq):
    """Offsets of df, dfq, dg, hgg, hgq, h, dhs, dhq in the flat layout, and its size: the
    layout of :func:`frictionrules.codegen.local_layout`, as compiled code needs it (a test
    checks that the two agree)."""
    return (1, 4, 4 + nq, 7 + nq, 16 + nq, 16 + 4 * nq, 16 + 5 * nq, 16 + 8 * nq,
            16 + 8 * nq + nq * nq)


@njit(inline="always", error_model="numpy", _nrt=False)
def _eval(lf, l1, l2, clip, s0, s1, s2, q, p, w, level):
    """The law's quantities at (T1, T2, N, q) into ``w``, finite at kinks: a derivative that
    is not finite (0/0 at the apex of a cone) is written as 0, the minimal-norm subgradient, by
    the generated function itself; a limit condition that is not finite there follows the kink
    rule of :mod:`frictionrules._returnspec`."""
    n = max(s2, 0.0) if clip else s2
    if level == 0:
        _call_local(lf, s0, s1, n, q, p, w)
    elif level == 1:
        _call_local(l1, s0, s1, n, q, p, w)
    else:
        _call_local(l2, s0, s1, n, q, p, w)
    if not math.isfinite(w[0]):
        r = _KINK_RADIUS * (math.sqrt(s0 * s0 + s1 * s1) + abs(n)) + 1e-300
        best = -np.inf
        for j in range(_KINK_POINTS):
            a = (2.0 * math.pi / _KINK_POINTS) * j
            _call_local(lf, s0 + r * math.cos(a), s1 + r * math.sin(a), n, q, p, w)
            if w[0] > best:
                best = w[0]
        w[0] = best
