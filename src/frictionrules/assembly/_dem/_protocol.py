r"""Loading tests by the dynamic engine: consolidation, then a stage of mixed control of the
cell with a record every ``record_every`` of strain (``docs/assembly.md``, "Dynamic runs").

**Rates.** The strain rate of a test is that of the inertial number,
``ε̇ = I / (d √(ρ/p))`` (``d`` the mean diameter, ``ρ`` the grains' density, ``p`` the
pressure). A driven strain component runs at ``ε̇`` (the largest of ``load_cell``'s at ``ε̇``,
the others in proportion, so that they end together); a stress target that changes is reached
linearly over the stage; a stage that drives stresses only lasts the time their largest change
takes at the stress rate ``ε̇ k/d`` (``k`` the stiffest contact: an elastic strain rate ``ε̇``).
The servo's strain rate is bounded by ``SERVO_RATE ε̇`` during a stage, ``CONSOLIDATION_RATE ε̇``
during consolidation.

**Consolidation.** Every normal stress is driven to the isotropic ``pressure``, the cell kept
rectangular (its shear strains held, as YADE's ``PeriTriaxController``), until the stress
holds (each component within ``STRESS_TOL`` of the pressure) with an unbalanced-force ratio
below ``UNBALANCED_TOL``: "frictionless" with ``Coulomb(0)`` at
every contact, after which the laws take over with virgin tangential histories; "stress" with
the laws from the start. A consolidation that does not settle within ``CONSOLIDATION_STEPS``
is an error.

By default a frictionless consolidation approaches its pressure from above: it settles first
at ``preload`` times the pressure (to ``preload`` times the unbalanced-force tolerance; the
option of ``triaxial``, :data:`PRELOAD` by default), then at the pressure; ``preload = 1``
compresses from below to the pressure (YADE's protocol). Compressed from below, a frictionless packing near jamming creeps: its
contacts carry the pressure by a fragile network that gives way again and again as the cell
closes, and the relaxation slows down as the overlaps vanish (critical slowing down at the
jamming point); unloaded from a well-connected state, it keeps its network and settles
quickly, as in the compress-then-decompress protocol of O'Hern, Silbert, Liu & Nagel (2003,
PRE 68 011306). (Measured on ``Assembly.random`` packings of 2,000 spheres, seeds 1–3, to
p = 1 with kn = 1e4: 147k, 165k, 162k steps from below; 37k, 25k, 21k from 10 p, the solid
fractions within 0.0004 of those from below; 10,000 spheres: 268k steps against 97k.) The
unloading leaves a fabric that dilates more in shear than one compressed from below
(``docs/assembly.md``, the comparison with YADE).
"""

from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass

import numpy as np

from ...errors import FrictionRulesError
from .._consolidation import PRELOAD
from .._contacts import ContactSet
from .._results import EnergyTerms, SampleState, TriaxialResult
from .._solver import components, triaxial_free
from ._dynamics import Dynamics, unit_rate
from ._engine import Outcome
from ._records import read_record
from ._state import Control

__all__ = ["StageSpec", "run_test", "SERVO_RATE", "CONSOLIDATION_RATE", "STRESS_TOL",
           "UNBALANCED_TOL", "CONSOLIDATION_STEPS", "PRELOAD"]

#: The servo's largest strain rate during a loading stage, in units of the test's rate ε̇.
SERVO_RATE = 10.0
#: ... and during consolidation.
CONSOLIDATION_RATE = 10.0
#: Consolidation: each stress component within this fraction of the pressure ...
STRESS_TOL = 1e-3
#: ... with the unbalanced-force ratio below this.
UNBALANCED_TOL = 1e-4
#: A consolidation that has not settled after this many steps is an error.
CONSOLIDATION_STEPS = 5_000_000
#: Steps between two looks at the clock (progress, max_time), at first.
FIRST_CHUNK = 200


@dataclass(frozen=True)
class StageSpec:
    """The loading stage over :func:`components`: ``free`` (stress-controlled) components
    driven from ``start`` to ``end`` (compression-positive stresses), the others at the
    compression-positive strain rates ``rate``, for ``duration``; ``axial`` the component whose
    strain is the result's axial strain."""

    free: np.ndarray
    start: np.ndarray
    end: np.ndarray
    rate: np.ndarray
    duration: float


def triaxial_stage(kind: str, d: int, pressure: float, axial_strain: float, rate: float,
                   cell: str) -> StageSpec:
    """Axial compression at ``rate`` with σ = pressure held across (plane strain: εyy = 0), the
    cell's shear held as ``cell`` says (:func:`.._solver.triaxial_free`)."""
    comps = components(d)
    diag = np.array([a == b for a, b in comps])
    axial = comps.index((1, 1) if d == 2 else (2, 2))
    free = triaxial_free(kind, d, cell)
    rates = np.zeros(len(comps))
    rates[axial] = rate
    target = np.where(diag, pressure, 0.0)
    return StageSpec(free, target, target, rates, axial_strain / rate)


def mixed_stage(free, start, end, strain, rate: float, k_max: float, mean_radius: float) -> StageSpec:
    """``load_cell``'s stage: strains ``strain`` (the largest at ``rate``), stresses from
    ``start`` to ``end`` (module docstring)."""
    driven = np.abs(np.where(free, 0.0, strain))
    if driven.max() > 0:
        duration = driven.max() / rate
    else:
        duration = np.abs(end - start).max() / (rate * k_max / (2 * mean_radius))
    rates = np.where(free, 0.0, strain / duration)
    return StageSpec(np.asarray(free, bool), start, end, rates, duration)


def _control(spec_free, start, end, rate, duration, max_rate, pressure, settle, d,
             unbalanced_tol: float = UNBALANCED_TOL) -> Control:
    comp = np.array(components(d), dtype=np.int64)
    return Control(comp, np.asarray(spec_free, np.uint8), np.asarray(start, float),
                   np.asarray(end, float), np.asarray(rate, float), float(duration),
                   float(max_rate), float(pressure), STRESS_TOL, float(unbalanced_tol), int(settle))


class _Clock:
    """Steps per call of the engine so that the caller looks at the clock about every 0.2 s."""

    def __init__(self):
        self.chunk = FIRST_CHUNK

    def run(self, dyn, state, control, stop_time, frictionless=False, limit=None):
        steps = self.chunk if limit is None else min(self.chunk, limit)
        t0 = time.perf_counter()
        before = int(state.meters[0]["steps"])
        state, outcome = dyn.run(state, control, stop_time, steps, frictionless)
        done = int(state.meters[0]["steps"]) - before
        spent = time.perf_counter() - t0
        if done == steps and spent > 0:
            self.chunk = int(min(max(100, steps * 0.2 / spent), 10 * steps))
        return state, outcome, done


def _phase(progress, text):
    if progress is not None and hasattr(progress, "phase"):
        progress.phase(text)


def consolidate(dyn: Dynamics, state, pressure: float, rate: float, frictionless: bool,
                progress=None, deadline=None, clock=None, unbalanced_tol: float = UNBALANCED_TOL,
                name: str = "consolidation", preload: float = PRELOAD):
    """Consolidation (module docstring): the normal stresses driven to ``pressure``, the cell's
    shear strains held (a rectangular cell); frictionless, by way of ``preload`` times it
    (``preload = 1``: none, from below). Returns ``(state, done)``; ``done`` False where the
    deadline came first."""
    clock = clock or _Clock()
    m = state.meters[0]
    if frictionless and preload > 1.0 and not m["preloaded"]:
        state, done = _settle(dyn, state, preload * pressure, rate, True, progress, deadline,
                              clock, preload * unbalanced_tol,
                              f"{name} (frictionless, preload {preload:g} p)")
        if not done:
            return state, False
        state.meters[0]["preloaded"] = 1
    return _settle(dyn, state, pressure, rate, frictionless, progress, deadline, clock,
                   unbalanced_tol, f"{name}{' (frictionless)' if frictionless else ''}")


def _settle(dyn, state, pressure, rate, frictionless, progress, deadline, clock, unbalanced_tol,
            name):
    """The normal stresses driven to ``pressure`` until they hold with the forces balanced to
    ``unbalanced_tol`` (the stage reported as ``name``). Returns ``(state, done)``."""
    d = dyn.dim
    comps = components(d)
    diag = np.array([a == b for a, b in comps])
    target = np.where(diag, pressure, 0.0)
    control = _control(diag, target, target, np.zeros(len(comps)), 0.0,
                       CONSOLIDATION_RATE * rate, pressure, True, d, unbalanced_tol)
    start = int(state.meters[0]["steps"])
    while True:
        state, outcome, _ = clock.run(dyn, state, control, math.inf, frictionless)
        m = state.meters[0]
        mean = np.trace(state.stress[:d, :d]) / d
        balance = (f"unbalanced force {m['unbalanced']:.2e}" if math.isfinite(m["unbalanced"])
                   else "no contact yet")
        _phase(progress, f"{name}: p/p* = {mean / pressure:.4f}, {balance}")
        if outcome == Outcome.SETTLED:
            return state, True
        if int(m["steps"]) - start > CONSOLIDATION_STEPS:
            raise FrictionRulesError(
                f"the {name} to pressure = {pressure!r} did not settle within "
                f"{CONSOLIDATION_STEPS} steps (mean stress {mean!r}, unbalanced force "
                f"{float(m['unbalanced']):.3g}); constraint: stress within {STRESS_TOL} of the "
                f"pressure with an unbalanced-force ratio below {unbalanced_tol}")
        if deadline is not None and time.monotonic() > deadline:
            return state, False


def start_stage(state) -> None:
    """The stage starts here: strain, time and energy terms from zero."""
    np.copyto(state.cell.H_ref, state.cell.H)
    m = state.meters
    for name in ("stage_time", "boundary_work", "dissipation", "damping_loss"):
        m[name] = 0.0


def sample_state(dyn: Dynamics, state, record) -> SampleState:
    """The implicit path's :class:`SampleState` of the engine's state (its contacts only)."""
    d = dyn.dim
    p = state.pairs
    members = np.flatnonzero(p.active)
    snap = record.contacts
    contacts = ContactSet(p.i[members].copy(), p.j[members].copy(), p.shift[members, :d].copy(),
                          p.group[members].copy(), tuple(dyn.models), snap.states, snap.frame,
                          snap.force, snap.status)
    return SampleState(record.positions, record.cell, contacts, record.stress, record.strain)


def peak_of(ratio: np.ndarray, axial: np.ndarray, window: float, failure_slope: float):
    """``(failed, peak)``: the running mean of the ratio over ``±window`` of axial strain; the
    sample failed where its slope drops to ``failure_slope`` of the first one; the peak is the
    largest running mean."""
    smooth = np.array([ratio[np.abs(axial - a) <= window + 1e-15].mean() for a in axial])
    if len(smooth) < 3:
        return False, math.inf, smooth
    slope = np.diff(smooth) / np.where(np.diff(axial) != 0, np.diff(axial), np.nan)
    slope = slope[np.isfinite(slope)]
    failed = len(slope) >= 2 and slope[0] > 0 and bool(np.any(slope[1:] <= failure_slope * slope[0]))
    return failed, (float(smooth.max()) if failed else math.inf), smooth


def collect(dyn, kind, records, axial, ended, failure_slope, window, state,
            contacts=None) -> TriaxialResult:
    """The :class:`TriaxialResult` of a dynamic run's records (``contacts``: their snapshots
    when not held by the records, as a run file's :class:`RecordedContacts`)."""
    stress = np.array([r.stress for r in records])
    strain = np.array([r.strain for r in records])
    eig = np.linalg.eigvalsh(stress)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(eig[:, 0] > 0, eig[:, -1] / np.where(eig[:, 0] > 0, eig[:, 0], 1.0), np.inf)
    ax = strain[:, axial, axial]
    failed, peak, _ = peak_of(ratio, ax, window, failure_slope)
    angle = 90.0 if math.isinf(peak) else math.degrees(math.asin((peak - 1) / (peak + 1)))
    field = {name: np.array([getattr(r, name) for r in records]) for name in (
        "time", "coordination", "coordination_without_rattlers", "sliding_fraction",
        "unbalanced_force", "boundary_work", "dissipation", "damping_loss", "elastic_energy",
        "kinetic_energy")}
    energy = EnergyTerms(field["boundary_work"], field["dissipation"], field["damping_loss"],
                         field["elastic_energy"], field["kinetic_energy"])
    contact = field["elastic_energy"] + field["dissipation"]
    cw = np.concatenate(([0.0], np.diff(contact)))
    bw = np.concatenate(([0.0], np.diff(field["boundary_work"])))
    snaps = tuple(r.contacts for r in records) if contacts is None else contacts
    return TriaxialResult(kind, stress, strain, np.trace(strain, axis1=1, axis2=2), ax, ratio, peak,
                          angle, field["coordination"], snaps, np.ones(len(records), bool), cw, bw,
                          failed, False, ended, sample_state(dyn, state, records[-1]), method="dem",
                          time=field["time"],
                          coordination_without_rattlers=field["coordination_without_rattlers"],
                          sliding_fraction=field["sliding_fraction"],
                          unbalanced_force=field["unbalanced_force"], energy=energy, engine=state,
                          positions=np.array([r.positions for r in records]),
                          cells=np.array([r.cell for r in records]))


def run_test(assembly, kind: str, spec_of, options: dict, progress=None, max_time=None,
             run_file=None) -> TriaxialResult:
    """Consolidate, then load; ``spec_of(dyn, rate)`` gives the :class:`StageSpec`."""
    start_clock = time.monotonic()
    deadline = None if max_time is None else start_clock + max_time
    dyn = Dynamics(assembly, density=options["density"], damping=options["damping"])
    p = options["pressure"]
    rate = unit_rate(options["inertial_number"], assembly.radii, options["density"], p)
    spec = spec_of(dyn, rate)
    record_time = options["record_every"] / rate
    total = max(1, int(math.ceil(spec.duration / record_time - 1e-9)))
    writer, records, stage, state = None, [], "consolidation", None
    if run_file is not None:
        from ._runfile import DemRunFile
        writer = DemRunFile.open(run_file, assembly, options)
        restored = writer.restore(dyn)
        if restored is not None:
            stage, state, records = restored
    if state is None:
        state = dyn.init()
        stage = "frictionless" if options["consolidation"] == "frictionless" else "consolidation"
    clock = _Clock()
    if progress is not None:
        progress(len(records) - 1 if records else 0, total)
    laws, _ = dyn.laws(False)
    if stage in ("frictionless", "consolidation"):
        frictionless = stage == "frictionless"
        state, done = consolidate(dyn, state, p, rate, frictionless, progress, deadline, clock,
                                  preload=options["preload"])
        if not done:
            return _stopped(dyn, writer, state, stage, kind, options,
                            f"stopped during the consolidation: max_time = {max_time!r} s reached")
        if frictionless:
            dyn.bring_in_laws(state)
        start_stage(state)
        _phase(progress, "loading")
        records = [read_record(dyn, state, laws)]
        if writer is not None:
            writer.append(0, records[0], state, dyn, "shear")
        stage = "shear"
    axial = 1 if dyn.dim == 2 else 2
    d = dyn.dim
    control = _control(spec.free, spec.start, spec.end, spec.rate, spec.duration,
                       SERVO_RATE * rate, p, False, d)
    ended = "completed"
    driven = int(np.argmax(np.abs(spec.rate)))
    a, b = components(d)[driven]
    goal = abs(spec.rate[driven]) * spec.duration
    extra = 0.0
    while len(records) - 1 < total:
        k = len(records)
        stop = min(k * record_time, spec.duration) + extra
        state, outcome, _ = clock.run(dyn, state, control, stop)
        if outcome == Outcome.REACHED:
            record = read_record(dyn, state, laws)
            if k == total and abs(record.strain[a, b]) < goal and extra < record_time:
                # the last record at the first step past the end's strain (the cell's free
                # shear turns the lab frame's strain off the time's by a few steps)
                extra += 2 * dyn.params().dt
                continue
            records.append(record)
            if writer is not None:
                writer.append(k, records[-1], state, dyn, "shear")
                # the file holds the previous record's contacts now
                records[-2] = dataclasses.replace(records[-2], contacts=None)
            if progress is not None:
                progress(k, total)
        if deadline is not None and time.monotonic() > deadline and len(records) - 1 < total:
            ended = (f"stopped after {len(records) - 1} records: max_time = {max_time!r} s "
                     "reached")
            break
    contacts = None
    if writer is not None:
        contacts = writer.contacts(records)
        writer.close(ended)
    return collect(dyn, kind, records, axial, ended, options["failure_slope"],
                   options["peak_window"], state, contacts)


def _stopped(dyn, writer, state, stage, kind, options, message):
    """A run stopped before its first record: the state so far as one unconverged row (the
    run file keeps the engine's state to resume from)."""
    if writer is not None:
        writer.save_engine(-1, state, dyn, stage)
        writer.close(message)
    laws, _ = dyn.laws(False)
    result = collect(dyn, kind, [read_record(dyn, state, laws)], 1 if dyn.dim == 2 else 2, message,
                     options["failure_slope"], options["peak_window"], state)
    return dataclasses.replace(result, converged=np.array([False]))
