"""Records of assembly runs: the sample's state, a snapshot of its contacts, the run's result."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._contacts import ContactSet

__all__ = ["SampleState", "ContactSnapshot", "TriaxialResult", "EnergyTerms", "snapshot"]


@dataclass(frozen=True, eq=False)
class SampleState:
    """The state of a sample between increments.

    Attributes
    ----------
    positions : (n, d)
        Grain centres.
    cell : (d, d)
        Cell matrix (columns: cell vectors).
    contacts : ContactSet
        Contacts with their laws' histories.
    stress : (d, d)
        Compression-positive stress.
    strain : (d, d)
        Compression-positive strain (sum of the increments' symmetric displacement gradients).
    """

    positions: np.ndarray
    cell: np.ndarray
    contacts: ContactSet
    stress: np.ndarray
    strain: np.ndarray


@dataclass(frozen=True, eq=False)
class ContactSnapshot:
    """Every contact at the end of one increment.

    Attributes
    ----------
    grains : (m, 2) int
        Grains ``i``, ``j`` of each contact.
    shift : (m, d) int
        Image shift of ``j``.
    frame : (m, 3, 3)
        Rows ``(t1, t2, n)`` of each contact at the start of the increment.
    force : (m, 3)
        ``(T1, T2, N)`` of the law, ``N > 0`` compression (the force of ``j`` on ``i`` is
        ``T1 t1 + T2 t2 - N n``).
    slip : (m, 3)
        Accumulated plastic displacement ``δᵖ = (δt1ᵖ, δt2ᵖ, δnᵖ)`` (4.1), ``δn > 0`` opening.
    status : (m,) int
        0 elastic (stick), 1 plastic (sliding), 2 open.
    states : tuple of ContactState
        The laws' full histories, one batch per contact model (``group`` indexes them).
    group : (m,) int
        The contact model of each contact.
    """

    grains: np.ndarray
    shift: np.ndarray
    frame: np.ndarray
    force: np.ndarray
    slip: np.ndarray
    status: np.ndarray
    states: tuple
    group: np.ndarray

    @property
    def size(self) -> int:
        return len(self.grains)

    @property
    def mobilized_friction(self) -> np.ndarray:
        """``|T|/N`` per contact (0 where open)."""
        t = np.hypot(self.force[:, 0], self.force[:, 1])
        n = self.force[:, 2]
        return np.divide(t, n, out=np.zeros_like(t), where=n > 0)


@dataclass(frozen=True, eq=False)
class EnergyTerms:
    r"""The energy terms of a dynamic run's shearing stage, at its records (work and energy
    since the stage started; ``docs/assembly.md``, "Energy").

    The boundary work :math:`W = -\int V\sigma:L\,dt` (compression-positive stress, velocity
    gradient ``L``) goes into the contacts — the elastic energy
    :math:`\sum_c \tfrac12(T^2/k_t + N^2/k_n)` and the dissipation of the laws' own return
    mappings — the kinetic energy of the grains' fluctuating motion and the loss of the
    non-viscous damping: ``W = ΔE_elastic + D + ΔE_kinetic + D_damping``.

    Attributes
    ----------
    boundary_work, dissipation, damping_loss : (k,)
        Since the start of the stage.
    elastic, kinetic : (k,)
        At each record.
    """

    boundary_work: np.ndarray
    dissipation: np.ndarray
    damping_loss: np.ndarray
    elastic: np.ndarray
    kinetic: np.ndarray

    @property
    def balance(self) -> np.ndarray:
        """``W - ΔE_elastic - D - ΔE_kinetic - D_damping`` at each record (0 exactly in
        continuous time)."""
        return (self.boundary_work - (self.elastic - self.elastic[0]) - self.dissipation
                - (self.kinetic - self.kinetic[0]) - self.damping_loss)

    @property
    def relative_error(self) -> float:
        """The largest ``|balance|`` over the largest ``|W|`` of the run."""
        scale = float(np.max(np.abs(self.boundary_work)))
        return float(np.max(np.abs(self.balance))) / scale if scale > 0 else 0.0


@dataclass(frozen=True, eq=False)
class TriaxialResult:
    r"""The history of a loading test, one row per increment (row 0: the consolidated sample).

    Attributes
    ----------
    kind : str
        "axisymmetric", "plane_strain", "biaxial" or "mixed".
    stress : (k, d, d)
        Compression-positive stress :math:`\sigma = \frac1V\sum_c f_c \otimes l_c`.
    strain : (k, d, d)
        Compression-positive strain (the sum of the increments, a logarithmic strain for
        coaxial loading).
    volumetric_strain : (k,)
        ``trace(strain)``, compression positive (dilation negative).
    axial_strain : (k,)
        The driven strain component (z in 3-D, y in 2-D).
    stress_ratio : (k,)
        ``σ1/σ3``, the largest over the smallest principal stress.
    peak_ratio : float
        ``σ1/σ3`` at the peak; ``inf`` where the sample never failed (``failed`` False).
    peak_friction_angle : float
        Degrees, :math:`\sin\varphi = (R - 1)/(R + 1)` at the peak ratio ``R`` (90 for ``inf``).
    coordination : (k,)
        Mean number of closed contacts per grain, ``2 m_closed/n``.
    contacts : sequence of ContactSnapshot
        Every contact's force, slip and state per increment: a tuple, or, for a dynamic run
        with a ``run_file``, a sequence that reads each record's contacts from the file when
        indexed and holds the last one (the file must stay as the run left it).
    converged : (k,) bool
        True for an accepted (converged) increment. The run stops at the first increment that
        does not converge even after step cutting; its row repeats the last equilibrium.
    contact_work, boundary_work : (k,)
        Per increment, the work of the contact forces on the contacts' displacements
        :math:`\sum_c P_c\cdot\Delta u_c` and the work of the boundary stress
        :math:`-V\sigma:\Delta E` (equal at equilibrium; ``docs/assembly.md``).
    failed : bool
        True where the sample reached a limit (peak or plateau of the stress ratio).
    limit_point : bool
        True where the sample lost stability under stress control (no equilibrium exists for
        the next increment of load).
    message : str
        How the run ended.
    final : SampleState
        The state after the last converged increment (a run continues from it).
    method : str
        "implicit" (quasi-static increments) or "dem" (the dynamic engine: one row per record).
    time : (k,) or None
        DEM: the time of each record (the consolidated sample at 0).
    coordination_without_rattlers : (k,) or None
        DEM: the mechanical coordination ``(2 N_c - N_1)/(N - N_0 - N_1)`` (``N_0``, ``N_1``
        grains with none or one force-carrying contact).
    sliding_fraction : (k,) or None
        DEM: the fraction of the force-carrying contacts that slide.
    unbalanced_force : (k,) or None
        DEM: the mean force on a grain over the mean contact force.
    energy : EnergyTerms or None
        DEM: the energy terms of the shearing stage.
    engine : DemState or None
        DEM: the engine's state at the end (positions, velocities, spins, cell, contacts'
        histories).
    positions : (k, n, d) or None
        DEM: the grains' centres at each record (never wrapped into the cell).
    cells : (k, d, d) or None
        DEM: the cell at each record (columns: the cell vectors).
    """

    kind: str
    stress: np.ndarray
    strain: np.ndarray
    volumetric_strain: np.ndarray
    axial_strain: np.ndarray
    stress_ratio: np.ndarray
    peak_ratio: float
    peak_friction_angle: float
    coordination: np.ndarray
    contacts: tuple
    converged: np.ndarray
    contact_work: np.ndarray
    boundary_work: np.ndarray
    failed: bool
    limit_point: bool
    message: str
    final: SampleState
    method: str = "implicit"
    time: np.ndarray | None = None
    coordination_without_rattlers: np.ndarray | None = None
    sliding_fraction: np.ndarray | None = None
    unbalanced_force: np.ndarray | None = None
    energy: EnergyTerms | None = None
    engine: object = None
    positions: np.ndarray | None = None
    cells: np.ndarray | None = None

    def __repr__(self) -> str:
        return (f"TriaxialResult(kind={self.kind!r}, increments={len(self.converged) - 1}, "
                f"peak_ratio={self.peak_ratio:.6g}, peak_friction_angle={self.peak_friction_angle:.4g}, "
                f"failed={self.failed}, message={self.message!r})")


def snapshot(contacts: ContactSet) -> ContactSnapshot:
    """The :class:`ContactSnapshot` of contacts (forces from their states where the increment
    left none)."""
    force, status = contacts.force, contacts.status
    if force is None:
        force = np.zeros((contacts.size, 3))
        for g, model in enumerate(contacts.models):
            force[contacts.members(g)] = model.force(contacts.states[g])
        status = np.where(force[:, 2] > 0, 0, 2)
    return ContactSnapshot(np.stack((contacts.i, contacts.j), axis=1), contacts.shift, contacts.frames,
                           force, contacts.per_contact("plastic"), status, contacts.states, contacts.group)
