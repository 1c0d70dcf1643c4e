"""Many contacts at once: the frictional contact problem u = W r + q (FCLIB) and its solvers.

:class:`FrictionContactProblem` holds ``W, q`` and a friction law per contact (Coulomb as in
FCLIB, or an elliptic orthotropic cone, or a dilatant / non-associated potential);
:func:`solve` runs ``"nsgs"``, ``"newton"`` or ``"prox"`` to Siconos' error measure
(:func:`fc3d_error`). Numba kernels are imported when a solver first runs.
"""

from .error import fc3d_error, project_cone
from .problem import FrictionContactProblem, Solution
from .solvers import METHODS, solve

__all__ = ["FrictionContactProblem", "Solution", "solve", "fc3d_error", "project_cone", "METHODS"]
