"""MuJoCo models stepped by the library's many-contact solve (the extra ``mujoco``).

MuJoCo keeps the model, collision detection, the mass matrix and the integration; each step's
contact impulses solve :class:`~frictionrules.FrictionContactProblem` with the friction law
that ``laws`` gives each pair of geoms, in material axes that ``axes`` fixes to a geom.
:func:`step` advances one ``model.opt.timestep``; :class:`Simulator` keeps the warm start and
the statistics of a run. ``mujoco`` itself is imported at the first step (``docs/mujoco.md``).
"""

from ._assemble import AXIS_NORMAL_TOL
from ._step import Simulator, StepResult, step

__all__ = ["step", "Simulator", "StepResult", "AXIS_NORMAL_TOL"]
