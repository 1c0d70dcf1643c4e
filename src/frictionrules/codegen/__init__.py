"""Code generation from a law's symbolic form: one program, several printers.

:func:`local_program` turns a :class:`~frictionrules.laws.SymbolicLaw` into straight-line code —
common subexpressions, then every quantity the implicit return mapping needs (f, g's gradient,
the evolution h of the internal variables and their derivatives) in one fixed layout. Printers
write that program in a target language; the compiled return mapping of
:mod:`frictionrules.contact` prints it for Numba, the exporter of :func:`frictionrules.export`
in C99 and fixed-form Fortran 77.
"""

from ._c import c_block, c_function, c_helpers, used_inputs
from ._fortran import fixed_form, fortran_helpers, fortran_subroutine
from ._program import LOCAL_FIELDS, Program, local_layout, local_program
from ._python import parameter_temps, python_block, python_function
from ._step import step_programs
from ._structure import (ELLIPTIC_CONES_SIZE, ReturnStructure, elliptic_cones, return_constants,
                         return_structure)

__all__ = ["LOCAL_FIELDS", "Program", "local_layout", "local_program", "python_function",
           "parameter_temps", "c_function", "c_helpers", "fortran_subroutine", "fortran_helpers",
           "fixed_form", "ReturnStructure", "return_structure", "return_constants", "step_programs",
           "elliptic_cones", "ELLIPTIC_CONES_SIZE",
           "python_block", "c_block", "used_inputs"]
