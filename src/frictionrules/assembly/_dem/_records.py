r"""What a record of a dynamic run holds, read from the engine's state.

* the compression-positive stress ``σ = (1/V) Σ_c f_c ⊗ l_c`` of the last step;
* the **logarithmic (Hencky) strain** of the cell since the stage's start, compression
  positive: ``ε = -½ log(F Fᵀ)``, ``F = H H_ref^{-1}``; its trace is the volumetric strain
  ``-log(V/V_ref)`` (dilation negative);
* the coordination ``Z = 2 N_c/N`` (``N_c`` force-carrying contacts) and the mechanical
  coordination without rattlers (Thornton 2000) ``Z_m = (2 N_c - N_1)/(N - N_0 - N_1)``,
  ``N_0``, ``N_1`` the grains with none or one force-carrying contact;
* the sliding fraction (force-carrying contacts whose last update was plastic), the
  unbalanced-force ratio (mean ``|F|`` of the grains over the mean contact force, YADE's
  ``unbalancedForce``);
* the energy terms since the stage's start (:class:`frictionrules.assembly.EnergyTerms`): the
  boundary work, the laws' dissipation, the damping's loss, and the elastic energy of the
  contacts ``Σ ½ (T²/kt + N²/kn)`` and the fluctuating kinetic energy at the record;
* the contacts (every pair in contact, open ones of the skin included) as a
  :class:`ContactSnapshot` (None in a record already written to a run file, which holds
  them).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...contact.layout import LAW_KN, LAW_KT
from .._results import ContactSnapshot
from ._passes import frame_t1
from ._state import DemState

__all__ = ["Record", "read_record", "hencky"]


@dataclass(frozen=True, eq=False)
class Record:
    """One record of a dynamic run (the module docstring)."""

    time: float
    steps: int
    stress: np.ndarray
    strain: np.ndarray
    coordination: float
    coordination_without_rattlers: float
    sliding_fraction: float
    unbalanced_force: float
    boundary_work: float
    dissipation: float
    damping_loss: float
    elastic_energy: float
    kinetic_energy: float
    contacts: ContactSnapshot
    positions: np.ndarray
    cell: np.ndarray


def hencky(H: np.ndarray, H_ref: np.ndarray, d: int) -> np.ndarray:
    """``-½ log(F Fᵀ)`` of ``F = H H_ref^{-1}`` (the d × d block)."""
    F = H[:d, :d] @ np.linalg.inv(H_ref[:d, :d])
    w, v = np.linalg.eigh(F @ F.T)
    return -0.5 * (v * np.log(w)) @ v.T


def frames_of(normal: np.ndarray, t1: np.ndarray) -> np.ndarray:
    """Rows ``(t1, t2, n)`` (m, 3, 3)."""
    return np.stack((t1, np.cross(normal, t1), normal), axis=1)


def read_record(dyn, state: DemState, laws) -> Record:
    """The record of the engine's present state (``laws``: the compiled laws of the models)."""
    d = dyn.dim
    p = state.pairs
    m = state.meters[0]
    n = state.size
    members = np.flatnonzero(p.active)
    normal = p.normal[members]
    force = p.force[members]
    carrying = force[:, 2] > 0
    nc = int(np.count_nonzero(carrying))
    counts = np.bincount(p.i[members][carrying], minlength=n) + np.bincount(p.j[members][carrying], minlength=n)
    n0, n1 = int(np.count_nonzero(counts == 0)), int(np.count_nonzero(counts == 1))
    mech = (2 * nc - n1) / (n - n0 - n1) if n - n0 - n1 > 0 else 0.0
    sliding = np.count_nonzero(p.status[members][carrying] == 1)
    rows = laws.row[p.group[members]]
    closed = np.where(carrying[:, None], force, 0.0)
    elastic = 0.5 * float(np.sum((closed[:, 0]**2 + closed[:, 1]**2) / rows[:, LAW_KT]
                                 + closed[:, 2]**2 / rows[:, LAW_KN]))
    t1 = frame_t1(normal, *map(float, dyn.assembly.reference_axis))
    snap = ContactSnapshot(np.stack((p.i[members], p.j[members]), axis=1), p.shift[members, :d].copy(),
                           frames_of(normal, t1), force.copy(),
                           p.state[members, 3:6].copy(), p.status[members].astype(np.int64),
                           dyn.states_of(state, members), p.group[members].copy())
    H = state.cell.H
    return Record(float(m["stage_time"]), int(m["steps"]), state.stress[:d, :d].copy(),
                  hencky(H, state.cell.H_ref, d), 2.0 * nc / n, float(mech),
                  sliding / nc if nc else 0.0, float(m["unbalanced"]), float(m["boundary_work"]),
                  float(m["dissipation"]), float(m["damping_loss"]), elastic, float(m["kinetic"]),
                  snap, state.grains.x[:, :d].copy(), H[:d, :d].copy())
