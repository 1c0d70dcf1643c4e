"""Many contacts at once: the frictional contact problem u = W r + q (FCLIB) and its solvers.

:class:`FrictionContactProblem` holds ``W, q`` and a friction law per contact (Coulomb as in
FCLIB, or an elliptic orthotropic cone, or a dilatant / non-associated potential);
:func:`solve` runs one of the methods of :data:`METHODS` (``"auto"``, ``"nsgs"``,
``"newton"``, ``"prox"``, ``"admm"``, ``"polish"``) to Siconos' error measure
(:func:`fc3d_error`; :func:`law_error` for laws that are not elliptic cones), with named options records (:class:`NSGSOptions`,
:class:`NewtonOptions`, :class:`ProxOptions`, :class:`ADMMOptions`, :class:`PolishOptions`).
A Delassus operator kept by its factors :math:`J M^{-1} J^T` (a multibody engine's) is swept
without forming W by :func:`solve_factored` (:mod:`.factored`).
Numba kernels are imported when a solver first runs. Batches of FCLIB files are solved by
:func:`frictionrules.batch.solve_many`, above the file layer.
"""

from ._methods import METHODS, SolverMethod
from ._options import ADMMOptions, IterationInfo, NewtonOptions, NSGSOptions, PolishOptions, ProxOptions
from ._relaxation import RelaxationComparison, compare_relaxation
from ._solve import solve, solve_batch, thread_limits
from .error import fc3d_error, project_cone
from ._law_path import contact_dissipation, law_error
from .problem import FrictionContactProblem, Solution
from ._solve import SMALL_MAX, SMALL_MODES
from .factored import ContactLaws, TreeBlocks, solve_factored

__all__ = ["FrictionContactProblem", "Solution", "solve", "solve_batch", "fc3d_error", "project_cone", "METHODS",
           "SolverMethod", "NSGSOptions", "NewtonOptions", "ProxOptions", "ADMMOptions", "PolishOptions",
           "IterationInfo", "compare_relaxation", "RelaxationComparison", "thread_limits", "law_error",
           "contact_dissipation", "SMALL_MAX", "SMALL_MODES", "ContactLaws", "TreeBlocks", "solve_factored"]
