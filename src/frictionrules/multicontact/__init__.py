"""Many contacts at once: the frictional contact problem u = W r + q (FCLIB) and its solvers.

:class:`FrictionContactProblem` holds ``W, q`` and a friction law per contact (Coulomb as in
FCLIB, or an elliptic orthotropic cone, or a dilatant / non-associated potential);
:func:`solve` runs ``"auto"``, ``"nsgs"``, ``"newton"``, ``"prox"`` or ``"admm"`` to Siconos'
error measure (:func:`fc3d_error`), with named options records (:class:`NSGSOptions`,
:class:`NewtonOptions`, :class:`ProxOptions`, :class:`ADMMOptions`). Numba kernels are
imported when a solver first runs.
"""

from ._options import ADMMOptions, IterationInfo, NewtonOptions, NSGSOptions, ProxOptions
from ._many import SolveRecord, solve_many
from ._relaxation import RelaxationComparison, compare_relaxation
from ._solve import METHODS, solve
from .error import fc3d_error, project_cone
from .problem import FrictionContactProblem, Solution

__all__ = ["FrictionContactProblem", "Solution", "solve", "fc3d_error", "project_cone", "METHODS",
           "NSGSOptions", "NewtonOptions", "ProxOptions", "ADMMOptions", "IterationInfo", "solve_many", "SolveRecord",
           "compare_relaxation", "RelaxationComparison"]
