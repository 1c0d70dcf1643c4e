r"""A rigid block translating on planar facets, each with a local friction law (§2 generalized).

Frame and signs (``docs/conventions.md``, "Laws in external loads" and "A facet's frame"): x, y
horizontal, z up. The block is loaded by :math:`F = (T_x, T_y, -Q)`, ``Q > 0`` pressing it
down, and translates with the velocity :math:`V = (V_x, V_y, V_z)`, ``Vz > 0`` upwards. Facet
``j`` has the unit normal :math:`n_j` pointing from the support into the block, with
:math:`n_{jz} > 0` (the facets face upwards; vertical walls and overhangs are not modelled), and
its own frame :math:`(t_{1j}, t_{2j}, n_j)`, :math:`t_{1j}` the unit projection of x onto the
facet plane. The block loads the facet with :math:`T_1 t_{1j} + T_2 t_{2j} - N n_j` and the
facet's local law :math:`f_j(T, N) \le 0` bounds that force; the block's velocity is the
facet's slip, :math:`(V\cdot t_{1j}, V\cdot t_{2j}, V\cdot n_j)`.

The block is in a sliding state when the forces balance ``F`` with a velocity that is
kinematically admissible for every facet (no interpenetration, and for a dilatant local law
at least the opening its sliding rule gives), a facet that separates carrying nothing. The
*limit load* in a horizontal direction ``d`` is the smallest factor :math:`t \ge 0` for which
:math:`F = (t d, -Q)` admits a mechanism; it is ``inf`` (locked) when none does. For
non-associated local laws it is capped by the static maximum (the limit load of the associated
twins, g = f: beyond it no equilibrium exists at all), where the block loses equilibrium without
a quasi-static mechanism (``LimitLoad.quasi_static``); so the non-associated load never exceeds
the associated one (Radenkovic). The facets must carry ``Q`` alone (checked on construction).

The mechanism search lives in private modules: :mod:`._coulomb` (local Coulomb friction, the
fast path), :mod:`._general` and :mod:`._local` (any local law), :mod:`._inverse` (corners,
the load for a slip), :mod:`._law` (the protocol), :mod:`._results`.
"""

from __future__ import annotations

import functools
import numbers
from dataclasses import dataclass

import numpy as np

from ..errors import FrictionRulesError, check_finite, check_scalar
from ..laws import Coulomb
from ._coulomb import CoulombGeometry, downward_velocity
from ._general import GeneralGeometry
from ._hull import boundary_facets, facet_frames
from ._law import FacetLaw
from ._local import local_law
from ._results import Corner, LimitCurve, LimitLoad, LimitLoads

__all__ = ["FacetSet", "LimitLoad", "LimitLoads", "LimitCurve", "Corner"]

LOCALS = ("non-associated", "associated")


def local_argument(law, mu, K: int | None, where: str):
    """The local law argument as stored: a float (local Coulomb ``mu``), a law, or a tuple of
    ``K`` of those (one per facet). ``mu=`` is the keyword the argument had before it took
    laws."""
    if mu is not None:
        if law is not None:
            raise FrictionRulesError(f"{where}: give the local law once, as law or as mu")
        law = mu
    if law is None:
        raise FrictionRulesError(f"{where}: the local law is missing; constraint: a friction law "
                                 "or a number mu (local Coulomb friction)")

    def one(x, name):
        if isinstance(x, numbers.Real) and not isinstance(x, bool) or (
                isinstance(x, np.ndarray) and x.ndim == 0):
            return check_scalar(name, x, lo=0.0, lo_open=True)
        if getattr(x, "capabilities", None) is None:
            raise FrictionRulesError(f"{where}: {name} = {x!r} violates: a number (local Coulomb "
                                     "mu) or a friction law of frictionrules")
        return x

    if isinstance(law, (list, tuple, np.ndarray)):
        items = list(law)
        if K is not None and len(items) != K:
            raise FrictionRulesError(f"{where}: law has {len(items)} entries; constraint: one "
                                     f"local law for all facets or one per facet ({K})")
        return tuple(one(x, f"law[{i}]") for i, x in enumerate(items))
    return one(law, "mu")


def law_parameters(law) -> dict[str, float]:
    """Fittable parameters of a local law argument: ``mu`` for a number, the law's own for one
    law, none for one law per facet."""
    if isinstance(law, float):
        return {"mu": law}
    if isinstance(law, tuple):
        return {}
    return dict(law.parameters)


def replace_law(law, changes: dict):
    """The local law argument with some of :func:`law_parameters` changed."""
    unknown = sorted(set(changes) - set(law_parameters(law)))
    if unknown:
        raise FrictionRulesError(f"parameters {unknown} violate: the local law's parameters are "
                                 f"{sorted(law_parameters(law))}")
    if not changes:
        return law
    return changes["mu"] if isinstance(law, float) else law.replace(**changes)


@dataclass(frozen=True, init=False)
class FacetSet(FacetLaw):
    r"""A rigid block on planar facets with a local friction law on each, as a law in external
    loads.

    Parameters
    ----------
    normals : array (K, 3)
        Facet normals, pointing from the support into the block, each with ``nz > 0``
        (normalized on input; stored as a tuple of tuples so that the law is hashable).
    law : float, FrictionLaw, or sequence of K of those
        The local law of the facets: a number is the local Coulomb coefficient ``mu > 0``
        (the fast path); a law of the protocol in ``(T, N)`` without internal variables, in
        each facet's frame (``docs/conventions.md``: ``t1`` the projection of x onto the
        facet, a law's angles measured from it) — Coulomb, dilatant Coulomb,
        ``EllipticOrthotropic``, ``Huber``, ``TransformedCoulomb``, user laws whose limit
        curve scales with ``N``; or one such per facet. ``mu=`` is accepted for a number.
    local : {"non-associated", "associated"}
        For a number: Coulomb's rule without normal slip (1.5) or the dilatant rule (1.6). For
        a law: ``"non-associated"`` (the default) keeps the law's own sliding rule,
        ``"associated"`` replaces its potential by its limit condition (g = f, normal slip
        included).

    The facets must carry the vertical load alone (``Q z`` inside the sum of their friction
    cones: the block does not slide down under ``Q`` with ``T = 0``); otherwise
    :class:`FrictionRulesError` is raised, as for a local law the search cannot use (one with
    internal variables, a law in external loads, or one whose limit curve does not scale with
    ``N``), naming what is missing.

    Notes
    -----
    Only the set of normal *directions* matters: a rigid block loads whichever facets its
    mechanism needs, whatever their areas. A facet set with one facet of inclination ``alpha``
    is the :class:`frictionrules.WedgeAsperity` ``(alpha, mu)``.
    """

    normals: tuple
    law: object
    local: str = "non-associated"

    def __init__(self, normals, law=None, local: str = "non-associated", *, mu=None):
        n = check_finite("normals", normals)
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
        if local not in LOCALS:
            raise FrictionRulesError(f"local = {local!r} violates local in {LOCALS}")
        object.__setattr__(self, "normals", tuple(tuple(float(c) for c in row) for row in n))
        object.__setattr__(self, "law", local_argument(law, mu, len(n), "FacetSet"))
        object.__setattr__(self, "local", local)
        self._check_carried()

    def _check_carried(self):
        if self._coulomb is not None:
            mu = self._coulomb[0]
            V = downward_velocity(self.normal_array[self._sliding], mu)
            what = f"(mu = {mu!r})"
        else:
            V = self._solver.downward_velocity()
            what = "with their local laws"
        if V is not None:
            raise FrictionRulesError(
                f"the facets {what} cannot carry the vertical load alone, the block slides down "
                f"under Q with T = 0 (the downward velocity {np.round(V, 6).tolist()} lies in "
                "every facet's dual friction cone); constraint: Q z inside the sum of the "
                "facets' friction cones. Level the surface or check the normals")

    @property
    def _facets(self) -> FacetSet:
        return self

    @property
    def normal_array(self) -> np.ndarray:
        """The unit normals as an array ``(K, 3)``."""
        return np.array(self.normals)

    def frames(self) -> np.ndarray:
        """Each facet's frame, shape ``(K, 3, 3)``: rows ``t1, t2, n`` (``docs/conventions.md``):
        ``t1`` the unit projection of x onto the facet plane, ``t2 = n x t1``."""
        n = self.normal_array
        return np.stack((*facet_frames(n), n), axis=1)

    @property
    def local_laws(self) -> tuple:
        """The local law of each facet (a number ``mu`` as :class:`frictionrules.Coulomb`, with
        the dilatant rule for ``local="associated"``)."""
        laws = self.law if isinstance(self.law, tuple) else (self.law,) * len(self.normals)
        dil = self.local == "associated"
        return tuple(Coulomb(x, dilatant=dil) if isinstance(x, float) else x for x in laws)

    @property
    def mu(self) -> float:
        """The local Coulomb coefficient, where every facet has local Coulomb friction with one
        coefficient; otherwise :class:`FrictionRulesError`."""
        if self._coulomb is None:
            raise FrictionRulesError("FacetSet.mu: the facets' local laws are not Coulomb with one "
                                     "coefficient; see .law")
        return self._coulomb[0]

    @property
    def parameters(self) -> dict[str, float]:
        """The local law's parameters (``mu`` for a number; none for one law per facet)."""
        return law_parameters(self.law)

    def replace(self, **changes) -> "FacetSet":
        """The facet set with the local law's parameters changed."""
        return FacetSet(self.normals, replace_law(self.law, changes), self.local)

    @functools.cached_property
    def _sliding(self) -> np.ndarray:
        """Indices of the facets that can slide (:func:`._hull.boundary_facets`)."""
        return boundary_facets(self.normal_array)

    @functools.cached_property
    def _adaptors(self) -> list:
        """The search's view of each facet's local law (one adaptor per distinct law)."""
        made, out = {}, []
        for law in self.local_laws:
            key = _key(law)
            if key not in made:
                a = local_law(law, "FacetSet")
                made[key] = a.twin() if self.local == "associated" else a
            out.append(made[key])
        return out

    @functools.cached_property
    def _coulomb(self) -> tuple[float, bool] | None:
        """``(mu, dilatant)`` when every facet has local Coulomb friction with one coefficient
        (the fast path), else ``None``."""
        if isinstance(self.law, float):
            return self.law, self.local == "associated"
        a = self._adaptors
        mus = {getattr(x, "coulomb", None) for x in a}
        ds = {x.cone.dilatancy if hasattr(x, "cone") else None for x in a}
        if len(mus) == 1 and None not in mus and len(ds) == 1 and ds <= {0.0, 1.0}:
            return mus.pop(), ds.pop() == 1.0
        return None

    @functools.cached_property
    def _solver(self):
        if self._coulomb is not None:
            mu, dilatant = self._coulomb
            return CoulombGeometry.build(self.normal_array, self._sliding, mu, dilatant)
        return GeneralGeometry.build(self.normal_array, self._sliding, self._adaptors)


def _key(law):
    try:
        hash(law)
    except TypeError:
        return id(law)
    return law
