r"""The state record of the dynamic engine and the groups of arrays its compiled stages take.

Everything is three-dimensional inside the engine: disks are spheres of the plane ``z = 0``
with the cell's third vector ``(0, 0, 1)`` never searched for images; their spins and moments
have only a z component, because every contact normal lies in the plane.

The state (:class:`DemState`) is the record a run file stores and restores bit for bit:
grains (positions, fluctuation velocities, spins), the cell (its matrix, velocity gradient and
the geometry of the last neighbour build), the pairs with the contacts' histories, and the
meters (time, step count, energy terms). The derived lists (:class:`Lists`: the pairs per
contact model and per grain, the chunks of the parallel passes) follow from the pairs alone.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

__all__ = ["Grains", "Cell", "Pairs", "Lists", "Laws", "Params", "Control", "DemState",
           "METERS", "new_meters", "OPEN", "ELASTIC", "PLASTIC"]

#: Contact statuses (as :mod:`frictionrules.contact.state`): stick, slide, open.
ELASTIC, PLASTIC, OPEN = 0, 1, 2


class Grains(NamedTuple):
    """Grains (rows): positions ``x`` (never wrapped), fluctuation velocities ``v`` (the
    velocity minus the cell's ``L x``), spins ``w``, at the half steps of the leapfrog; radii,
    inverse masses and inverse moments of inertia; ``x_build``, the positions of the last
    neighbour build."""

    x: np.ndarray
    v: np.ndarray
    w: np.ndarray
    radius: np.ndarray
    inv_mass: np.ndarray
    inv_inertia: np.ndarray
    x_build: np.ndarray


class Cell(NamedTuple):
    """The cell ``H`` (columns: cell vectors), the velocity gradient ``L`` that moved it during
    the last step (``H ← (I + dt L) H``), the cell of the last neighbour build and the cell at
    the start of the stage (the reference of the strain)."""

    H: np.ndarray
    L: np.ndarray
    H_build: np.ndarray
    H_ref: np.ndarray


class Pairs(NamedTuple):
    """The pair list (sorted by ``(i, j, shift)``) and the contacts' histories.

    ``active`` 1 for a contact (touched since it entered the list and not opened beyond the
    skin); ``state`` its law's state row (:mod:`frictionrules.contact.layout`: ``e, p, q``, in
    the local frame); ``normal``, ``t1`` its frame (``t2 = n × t1``) and ``gap`` at the last
    step; ``force`` ``(T1, T2, N)``, ``gforce`` the force of ``j`` on ``i`` in the global frame
    and ``torque`` ``n × gforce`` (the moment on either grain is its radius times it);
    ``status`` of the last update."""

    i: np.ndarray
    j: np.ndarray
    shift: np.ndarray
    group: np.ndarray
    active: np.ndarray
    state: np.ndarray
    normal: np.ndarray
    t1: np.ndarray
    gap: np.ndarray
    force: np.ndarray
    gforce: np.ndarray
    torque: np.ndarray
    status: np.ndarray
    slip: np.ndarray


class Lists(NamedTuple):
    """Derived from the pairs: ``order`` (pairs by contact model), ``group_start`` (G + 1),
    ``chunk`` bounds of the contact pass in ``order``; ``grain_start``, ``grain_entry`` (each
    grain's pairs, :func:`grain_lists`) and ``grain_chunk`` bounds of the grain pass."""

    order: np.ndarray
    group_start: np.ndarray
    chunk: np.ndarray
    grain_start: np.ndarray
    grain_entry: np.ndarray
    grain_chunk: np.ndarray


class Laws(NamedTuple):
    """The contact models as the compiled entry takes them, one row per model: ``fn`` (G, 3)
    addresses, ``row`` (G, R) law rows (padded), ``nq`` (G,), ``virgin`` (G, W) the state row
    of a contact at first touch (zero displacements, the law's initial internal variables)."""

    fn: np.ndarray
    row: np.ndarray
    nq: np.ndarray
    virgin: np.ndarray


class Params(NamedTuple):
    """Numbers of a run: time step, Cundall's damping coefficient, skin, reference axis of the
    contact frames, dimension, the largest overlap accepted (a fraction of the smaller radius),
    the neighbours' cut-off ``2 r_max + skin``; ``frictionless`` 1 during a frictionless stage
    (:func:`._passes.contact_range`; its grains move by FIRE, :mod:`._engine`)."""

    dt: float
    damping: float
    skin: float
    axis0: float
    axis1: float
    axis2: float
    dim: int
    max_overlap: float
    cutoff: float
    frictionless: int


class Control(NamedTuple):
    """The control of the cell during one stage, over the components ``comp`` (k, 2) of
    :func:`frictionrules.assembly._solver.components`.

    ``free[k]`` 1: the compression-positive stress is driven from ``start[k]`` to ``end[k]``
    linearly in the stage's time (reaching it at ``duration``) by the servo; 0: the
    compression-positive strain rate ``rate[k]``. ``max_rate`` bounds the servo's strain rate;
    ``stress_tol`` (relative to ``scale``) and ``unbalanced_tol`` define equilibrium
    (``settle`` 1: the stage ends there)."""

    comp: np.ndarray
    free: np.ndarray
    start: np.ndarray
    end: np.ndarray
    rate: np.ndarray
    duration: float
    max_rate: float
    scale: float
    stress_tol: float
    unbalanced_tol: float
    settle: int


#: The meters of a run (one structured row): time and steps; the stage's time; energy terms
#: since the start of the stage (boundary work, the laws' dissipation, the damping's loss) and
#: the kinetic energy at the last half step; the unbalanced-force ratio, force-carrying and
#: sliding contacts, the largest overlap over the smaller radius; the first pair whose update
#: failed (-1: none); FIRE's step, mixing and count of steps downhill (0: not started); 1 once
#: a frictionless consolidation has settled at its preload (:mod:`._protocol`).
METERS = np.dtype([("time", "f8"), ("steps", "i8"), ("stage_time", "f8"), ("boundary_work", "f8"),
                   ("dissipation", "f8"), ("damping_loss", "f8"), ("kinetic", "f8"),
                   ("unbalanced", "f8"), ("closed", "i8"), ("sliding", "i8"),
                   ("max_overlap", "f8"), ("failed_pair", "i8"), ("max_shift", "f8"),
                   ("fire_dt", "f8"), ("fire_alpha", "f8"), ("fire_npos", "i8"),
                   ("preloaded", "i8")])


def new_meters() -> np.ndarray:
    m = np.zeros(1, dtype=METERS)
    m["failed_pair"] = -1
    return m


@dataclass(frozen=True, eq=False)
class DemState:
    """The dynamic engine's state: grains, cell, pairs with the contacts' histories, stress
    and meters. The engine advances the arrays in place (a run file copies them)."""

    grains: Grains
    cell: Cell
    pairs: Pairs
    stress: np.ndarray
    meters: np.ndarray

    @property
    def size(self) -> int:
        return len(self.grains.x)
