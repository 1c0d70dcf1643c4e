r"""A rigid block translating on planar facets, each with a local friction law (§2 generalized).

Frame and signs (``docs/conventions.md``, "Laws in external loads"): x, y horizontal, z up. The
block is loaded by :math:`F = (T_x, T_y, -Q)`, ``Q > 0`` pressing it down, and translates with
the velocity :math:`V = (V_x, V_y, V_z)`, ``Vz > 0`` upwards. Facet ``j`` has the unit normal
:math:`n_j` pointing from the support into the block, with :math:`n_{jz} > 0` (the facets face
upwards; vertical walls and overhangs are not modelled). Its reaction on the block is
:math:`R_j = N_j n_j + f_j`, :math:`N_j \ge 0`, :math:`|f_j| \le \mu N_j`.

The block is in a sliding state when :math:`F + \sum_j R_j = 0` with a velocity that is
kinematically admissible, :math:`V\cdot n_j \ge 0` for every facet (no interpenetration), a
facet that separates (:math:`V\cdot n_j > 0`) carrying nothing. The *limit load* in a
horizontal direction ``d`` is the smallest factor :math:`t \ge 0` for which the load
:math:`F = (t d, -Q)` admits a mechanism; it is ``inf`` (locked) when none does. For the
non-associated rule it is capped by the static maximum (the associated limit load: beyond it no
equilibrium exists at all), where the block loses equilibrium without a quasi-static mechanism
(``LimitLoad.quasi_static``); so the non-associated load never exceeds the associated one
(Radenkovic). The facets must carry ``Q`` alone (checked on construction).

The mechanism search lives in private modules: :mod:`._coulomb` (local Coulomb friction),
:mod:`._inverse` (corners, the load for a slip), :mod:`._law` (the protocol), :mod:`._results`.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from ..errors import FrictionRulesError, check_finite, check_scalar
from ._coulomb import CoulombGeometry, downward_velocity
from ._hull import boundary_facets
from ._law import FacetLaw
from ._results import Corner, LimitCurve, LimitLoad, LimitLoads

__all__ = ["FacetSet", "LimitLoad", "LimitLoads", "LimitCurve", "Corner"]

LOCALS = ("non-associated", "associated")


@dataclass(frozen=True)
class FacetSet(FacetLaw):
    r"""A rigid block on planar facets with local Coulomb friction, as a law in external loads.

    Parameters
    ----------
    normals : array (K, 3)
        Facet normals, pointing from the support into the block, each with ``nz > 0``
        (normalized on input; stored as a tuple of tuples so that the law is hashable).
    mu : float
        Local friction coefficient, ``mu > 0``.
    local : {"non-associated", "associated"}
        Local sliding rule: Coulomb without normal slip (1.5) or the dilatant rule (1.6).

    The facets must carry the vertical load alone (``Q z`` inside the sum of their friction
    cones: the block does not slide down under ``Q`` with ``T = 0``); otherwise
    :class:`FrictionRulesError` is raised.

    Notes
    -----
    Only the set of normal *directions* matters: a rigid block loads whichever facets its
    mechanism needs, whatever their areas. A facet set with one facet of inclination ``alpha``
    is the :class:`frictionrules.WedgeAsperity` ``(alpha, mu)``.
    """

    normals: tuple
    mu: float
    local: str = "non-associated"

    def __post_init__(self):
        n = check_finite("normals", self.normals)
        if n.ndim != 2 or n.shape[-1] != 3 or len(n) == 0:
            raise FrictionRulesError(f"normals must have shape (K, 3) with K >= 1, got shape "
                                     f"{n.shape}")
        norm = np.linalg.norm(n, axis=-1)
        if np.any(norm == 0):
            i = int(np.argmin(norm))
            raise FrictionRulesError(f"normals[{i}] = {n[i].tolist()!r} violates |n| > 0")
        n = n / norm[:, None]
        if np.any(n[:, 2] <= 1e-9):
            i = int(np.argmin(n[:, 2]))
            raise FrictionRulesError(f"normals[{i}] = {n[i].tolist()!r} violates nz > 0 (facets "
                                     "must face upwards, into the block)")
        object.__setattr__(self, "normals", tuple(tuple(float(c) for c in row) for row in n))
        object.__setattr__(self, "mu", check_scalar("mu", self.mu, lo=0.0, lo_open=True))
        if self.local not in LOCALS:
            raise FrictionRulesError(f"local = {self.local!r} violates local in {LOCALS}")
        V = downward_velocity(self.normal_array[self._sliding], self.mu)
        if V is not None:
            raise FrictionRulesError(
                f"the facets (mu = {self.mu!r}) cannot carry the vertical load alone, the block "
                f"slides down under Q with T = 0 (the downward velocity {np.round(V, 6).tolist()} "
                "lies in every facet's dual friction cone); constraint: Q z inside the sum of "
                "the facets' friction cones. Level the surface or check the normals")

    @property
    def _facets(self) -> FacetSet:
        return self

    @property
    def normal_array(self) -> np.ndarray:
        """The unit normals as an array ``(K, 3)``."""
        return np.array(self.normals)

    @functools.cached_property
    def _sliding(self) -> np.ndarray:
        """Indices of the facets that can slide (:func:`._hull.boundary_facets`)."""
        return boundary_facets(self.normal_array)

    @functools.cached_property
    def _solver(self) -> CoulombGeometry:
        return CoulombGeometry.build(self.normal_array, self._sliding, self.mu,
                                     self.local == "associated")
