r"""Named layouts of the compiled contact update: one law's functions and row, one contact's
state row and one contact's result row.

The compiled update of a contact (:func:`frictionrules.contact._return_kernel.contact_update`,
the one entry every compiled consumer calls: :meth:`ContactModel.update`, the grain
assemblies' dynamic engine) reads and writes flat ``float64`` rows whose fields sit at the
offsets named here, so that a caller never passes positional lists of arrays and never reads
a field by a bare number.

==========  ======================================================================
law fn      addresses of the law's generated functions (``int64``): ``f`` the limit
            condition, ``first`` the residual's quantities, ``full`` the Jacobian's
            (:func:`frictionrules.codegen.local_layout`), ``step`` the whole step of
            a contact (:mod:`frictionrules.contact._step_source`)
law row     ``kt, kn`` stiffnesses (4.2); ``clip`` 1 for a law evaluated at
            ``max(N, 0)``; ``nq`` internal variables; ``has_kappa`` 1 when one of them
            is the accumulated slip κ, ``kappa`` its column; ``ret`` the block of how
            the return is solved (:func:`frictionrules.codegen.return_constants`:
            kind, linear flag, the elliptic return's frame, eigenvalues and ratio); then
            the law's parameter values and its parameter-only subexpressions
            (:func:`frictionrules.contact._generated.parameter_values`)
state row   ``e`` elastic displacement ``δᵉ`` (3), ``p`` plastic displacement ``δᵖ`` (3),
            ``q`` the law's internal variables (``nq``; a row may be longer: the
            caller's widest law)
result row  ``force`` ``(T1, T2, N)`` (3), ``dlam`` the plastic multiplier Δλ,
            ``dissipation`` of the step, ``slip`` the tangential plastic slip of the
            step (4.5)
==========  ======================================================================

Signs as everywhere (``docs/conventions.md``): ``δn > 0`` opening, ``N > 0`` compression.
"""

from __future__ import annotations

from .._returnspec import RETURN_SIZE

__all__ = ["FN_F", "FN_FIRST", "FN_FULL", "FN_STEP", "FN_SIZE", "LAW_KT", "LAW_KN", "LAW_CLIP",
           "LAW_NQ", "LAW_HAS_KAPPA", "LAW_KAPPA", "LAW_RET", "RET_KIND", "RET_LINEAR", "RET_COS", "RET_SIN", "RET_ALPHA1", "RET_ALPHA2", "RET_C",
           "LAW_PARAMS",
           "STATE_E", "STATE_P", "STATE_Q", "state_size", "RES_FORCE", "RES_DLAM",
           "RES_DISSIPATION", "RES_SLIP", "RES_SIZE", "LAW_FIELDS", "STATE_FIELDS",
           "RESULT_FIELDS"]

#: Entries of a law's array of function addresses.
FN_F, FN_FIRST, FN_FULL, FN_STEP = range(4)
FN_SIZE = 4

#: Fields of a law's row before its parameters, in order.
LAW_FIELDS = ("kt", "kn", "clip", "nq", "has_kappa", "kappa")
LAW_KT, LAW_KN, LAW_CLIP, LAW_NQ, LAW_HAS_KAPPA, LAW_KAPPA = range(len(LAW_FIELDS))
#: Offset of the return's block in a law's row, and the fields of that block.
LAW_RET = len(LAW_FIELDS)
RET_KIND, RET_LINEAR, RET_COS, RET_SIN, RET_ALPHA1, RET_ALPHA2, RET_C = (LAW_RET + k
                                                                       for k in range(7))
#: Offset of the law's parameter values in its row.
LAW_PARAMS = LAW_RET + RETURN_SIZE

#: Fields of a contact's state row and their lengths (``q``: the law's ``nq``).
STATE_FIELDS = (("e", 3), ("p", 3), ("q", None))
STATE_E, STATE_P, STATE_Q = 0, 3, 6

#: Fields of a contact's result row and their lengths.
RESULT_FIELDS = (("force", 3), ("dlam", 1), ("dissipation", 1), ("slip", 1))
RES_FORCE, RES_DLAM, RES_DISSIPATION, RES_SLIP = 0, 3, 4, 5
RES_SIZE = 6


def state_size(nq: int) -> int:
    """Length of a state row for a law with ``nq`` internal variables."""
    return STATE_Q + nq
