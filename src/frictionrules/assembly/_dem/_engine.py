r"""The dynamic engine: an (init, advance) pair over :class:`DemState`.

A time step is YADE's engine list, in this order:

1. **neighbours** — the pair list is rebuilt (and the contacts' histories merged into it by
   their keys ``(i, j, K)``) when the rebuild rule of :mod:`._neighbours` says so;
2. **contact kinematics** and 3. **the law kernel** — :func:`._passes.contact_range`, in
   parallel over chunks of pairs;
4. **cell servo** — the velocity gradient ``L`` of the next step (:func:`_servo`);
5. **forces per grain** and 6. **integrate** — :func:`._passes.grain_range`, in parallel over
   chunks of grains (each grain gathers its pairs' forces: no atomics);

then the cell moves, ``H ← (I + dt L) H``. The chunks are fixed by the sizes alone (not by the
number of threads) and their partial sums are added in order: a run gives the same numbers
bit for bit on any number of threads.

**Time step.** ``dt = SAFETY √(m_min / k_max)``: ``m_min`` the lightest grain, ``k_max`` the
stiffest contact (the largest ``kn`` or ``kt`` of the contact models; a law's consistent
tangent never exceeds its elastic stiffness, whatever its state), ``SAFETY`` = 0.25 (YADE's
customary half of the P-wave step is 0.27 on 400 spheres of radii ``r̄(1 ± 0.2)``).

**Cell servo** (the stiffness form of YADE's ``PeriTriaxController``): a stress-controlled
component ``k`` takes the strain that would cancel its stress error against the affine
stiffness of the contact network, ``ε_k = (σ_k - σ*_k)/S_k`` with ``S_k = (1/V) Σ_c (K_c G_k
l)_a l_b`` (``G_k`` the basis of component ``ab``, :func:`.._solver.basis`; ``K_c = kt I +
(kn - kt) n n``, the force-carrying contacts), as the rate ``L_k = ε_k/dt`` bounded by
``max_rate``. The affine stiffness bounds the network's: the servo never overshoots through
the affine response, and the grains' relaxation is followed step by step.
A strain-controlled component has ``L_k = -ε̇_k`` (compression positive ``ε̇``).

**Frictionless stages** (consolidation, packing) only need their end state, an equilibrium:
their grains move by FIRE (Bitzek, Koskinen, Gähler, Moseler & Gumbsch 2006, PRL 97 170201)
instead of damped dynamics. With the power ``P = F·v`` over all grains after the contact
pass: ``P > 0`` mixes every velocity towards its force, ``v ← (1 - α) v + α (|v|/|F|) F``,
and after ``FIRE_DELAY`` such steps grows ``dt`` (by ``FIRE_GROW``, to ``FIRE_DT_MAX`` times
the engine's) and decays ``α``; ``P ≤ 0`` stops every grain, cuts ``dt`` and resets ``α``;
then ``v ← v + dt F/m``, ``x ← x + dt (v + L x)`` (no spins: frictionless contacts carry no
moment). The cell's servo runs as in any stage, with the step of the moment. (Measured on
YADE's clouds of 400 spheres, the consolidation to an unbalanced-force ratio of 1e-4 took
40k–82k steps against 78k–161k by damped dynamics, at the same solid fraction.)

**Energy** (``docs/assembly.md``): with ``m dv'/dt = F`` for the fluctuation velocity, the
power of the boundary ``-V σ:L`` equals the power taken by the contacts' laws (stored plus
dissipated) plus the rate of the fluctuating kinetic energy plus the damping's loss. The
boundary work is added with the mean of the gradients before and after each step, the
kinetic energy taken at the half steps, the damping's work on the mean velocity of each step:
the discrete sums then balance to the order of the step.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from ._neighbours import build_pairs, grain_lists, match_keys
from ._passes import (F_FORCE, F_FORCE2, F_POWER, F_SPEED2, G_DAMPING, G_FORCE, G_KINETIC,
                      G_SHIFT, P_CLOSED, P_DISSIPATION, P_FAILED, P_FORCE, P_OVERLAP, P_SLIDING,
                      P_STIFF, P_VIRIAL, contact_range, fire_range, gather_range, grain_range)
from ._state import Cell, Grains, Lists, Pairs

__all__ = ["SAFETY", "time_step", "advance", "rebuild", "lists_of", "CHUNKS", "Outcome"]

#: Safety factor of the time step on ``√(m_min / k_max)``.
SAFETY = 0.25
#: Most chunks of a parallel pass; fewer for small systems (at least ``MIN_CHUNK`` items each).
CHUNKS = 32
MIN_CHUNK = 64


class Outcome:
    """Why :func:`advance` returned."""

    STEPS, REACHED, SETTLED, REBUILD, FAILED, UNSTABLE = range(6)


def time_step(mass_min: float, k_max: float) -> float:
    """``SAFETY √(m_min / k_max)``."""
    return SAFETY * math.sqrt(mass_min / k_max)


def _chunks(m: int) -> np.ndarray:
    k = max(1, min(CHUNKS, m // MIN_CHUNK))
    return np.linspace(0, m, k + 1).round().astype(np.int64)


def lists_of(pairs: Pairs, n: int, groups: int) -> Lists:
    """The derived lists of a pair list (:class:`Lists`)."""
    order = np.argsort(pairs.group, kind="stable").astype(np.int64)
    group_start = np.searchsorted(pairs.group[order], np.arange(groups + 1)).astype(np.int64)
    grain_start, grain_entry = grain_lists(pairs.i, pairs.j, n)
    return Lists(order, group_start, _chunks(len(order)), grain_start, grain_entry, _chunks(n))


def new_pairs(i, j, shift, group, width: int) -> Pairs:
    """Pairs out of contact (no history)."""
    m = len(i)
    z3 = np.zeros((m, 3))
    return Pairs(i, j, shift, group, np.zeros(m, np.uint8), np.zeros((m, width)), z3.copy(),
                 z3.copy(), np.zeros(m), z3.copy(), z3.copy(), z3.copy(), np.full(m, 2, np.int8),
                 np.zeros(m))


def rebuild(grains: Grains, cell: Cell, pairs: Pairs, params, group_of) -> tuple[Grains, Cell, Pairs]:
    """A new pair list at the present positions; every pair already in the list keeps its
    history. ``group_of(i, j)`` gives the contact model of new pairs."""
    I, J, K = build_pairs(grains.x, grains.radius, cell.H, params.skin, params.dim)
    old = match_keys(pairs.i, pairs.j, pairs.shift, I, J, K)
    new = new_pairs(I, J, K, group_of(I, J), pairs.state.shape[1])
    kept = old >= 0
    src = old[kept]
    for name in ("active", "state", "normal", "t1", "gap", "force", "gforce", "torque", "status",
                 "slip"):
        getattr(new, name)[kept] = getattr(pairs, name)[src]
    # an active contact left out is beyond the skin now: deleted, as the contact pass would
    np.copyto(grains.x_build, grains.x)
    np.copyto(cell.H_build, cell.H)
    return grains, cell, new


@njit(inline="always")
def _volume(H, dim):
    if dim == 2:
        return H[0, 0] * H[1, 1] - H[0, 1] * H[1, 0]
    return np.linalg.det(H)


@njit(error_model="numpy", cache=True)
def _target(control, k, time):
    """The stress target of a stress-controlled component at the stage's ``time``."""
    f = 1.0 if control.duration <= 0.0 else min(1.0, time / control.duration)
    return control.start[k] + (control.end[k] - control.start[k]) * f


@njit(error_model="numpy", cache=True)
def _servo(L, control, stress, stiff, volume, dt, time):
    """The velocity gradient of the next step (module docstring) into ``L``."""
    comp = control.comp
    for k in range(comp.shape[0]):
        a, b = comp[k, 0], comp[k, 1]
        if control.free[k]:
            err = stress[a, b] - _target(control, k, time)
            S = stiff[a if a == b else 6 - a - b] / volume
            rate = err / (S * dt) if S > 0.0 else math.copysign(control.max_rate, err)
            rate = max(-control.max_rate, min(control.max_rate, rate))
        else:
            rate = -control.rate[k]
        L[a, b] = rate
        L[b, a] = rate


@njit(error_model="numpy", cache=True)
def _settled(control, stress, unbalanced, time):
    """Every stress-controlled component at its target and the forces balanced."""
    if unbalanced > control.unbalanced_tol:
        return False
    comp = control.comp
    for k in range(comp.shape[0]):
        if control.free[k]:
            err = stress[comp[k, 0], comp[k, 1]] - _target(control, k, time)
            if abs(err) > control.stress_tol * control.scale:
                return False
    return True


#: Numba's parallel transforms of a step: the passes' ``prange`` loops alone. Each array
#: expression of the step would otherwise be a parallel region of its own, the threads woken
#: for a few numbers several times a step (10,800 spheres: 2 threads 1.25x -> 1.79x one's speed).
_PARALLEL = {"prange": True, "numpy": False, "setitem": False, "reduction": False,
             "comprehension": False, "stencil": False, "fusion": False, "inplace_binop": False}


#: FIRE in a frictionless stage (module docstring): steps downhill before the step may grow,
#: its growth and its cut, the mixing's start and decay, the largest and the smallest step
#: (times the engine's ``dt``). The largest, ``0.5 √(m_min / k_max)``, is within the stability
#: limit of the lightest grain with its usual contacts, and a step that goes unstable turns
#: uphill and is cut. (2,000 spheres consolidated by way of 10 p to p = 1 with kn = 1e4, seeds
#: 1–3: 40k, 34k, 63k steps at 1.5; 37k, 25k, 21k at 2; 31k, 26k, 54k at 2.5.)
FIRE_DELAY, FIRE_GROW, FIRE_CUT, FIRE_ALPHA, FIRE_DECAY, FIRE_DT_MAX, FIRE_DT_MIN = (
    5, 1.1, 0.5, 0.1, 0.99, 2.0, 0.02)


@njit(parallel=_PARALLEL, cache=True, error_model="numpy")
def _fire_step(lists, grains, cell, pairs, params, m, dt, force, F_build, gpart):
    """A FIRE step of the grains (module docstring): the forces gathered with the power
    ``F·v`` and the norms, the velocities mixed (or stopped after an uphill step), the Euler
    step. Returns ``Σ|F|`` and the next step's ``dt``."""
    gchunk = lists.grain_chunk
    ngchunk = gchunk.shape[0] - 1
    for k in prange(ngchunk):
        gather_range(gchunk[k], gchunk[k + 1], lists, grains, pairs, force, gpart[k])
    power = f2 = v2 = fsum = 0.0
    for k in range(ngchunk):
        power += gpart[k, F_POWER]
        f2 += gpart[k, F_FORCE2]
        v2 += gpart[k, F_SPEED2]
        fsum += gpart[k, F_FORCE]
    gpart[:, :] = 0.0
    if m.fire_alpha <= 0.0:
        m.fire_alpha = FIRE_ALPHA
    alpha = m.fire_alpha
    dt_next = dt
    if power > 0.0 or f2 == 0.0:
        keep = 1.0 - alpha
        mix = alpha * math.sqrt(v2 / f2) if f2 > 0.0 else 0.0
        m.fire_npos += 1
        if m.fire_npos > FIRE_DELAY:
            dt_next = min(dt * FIRE_GROW, FIRE_DT_MAX * params.dt)
            m.fire_alpha = alpha * FIRE_DECAY
    else:
        keep = mix = 0.0
        m.fire_npos = 0
        dt_next = max(dt * FIRE_CUT, FIRE_DT_MIN * params.dt)
        m.fire_alpha = FIRE_ALPHA
    for k in prange(ngchunk):
        fire_range(gchunk[k], gchunk[k + 1], grains, cell, force, dt, keep, mix, F_build, gpart[k])
    return fsum, dt_next


@njit(parallel=_PARALLEL, cache=True, error_model="numpy")
def _advance(lists, grains, cell, pairs, laws, workspaces, params, control, meters, stress,
             scratch, parts, max_steps, stop_time):
    m = meters[0]
    dt, dim = params.dt, params.dim
    if params.frictionless and m.fire_dt > 0.0:
        dt = m.fire_dt
    chunk, gchunk, gstart = lists.chunk, lists.grain_chunk, lists.group_start
    nchunk, ngchunk = chunk.shape[0] - 1, gchunk.shape[0] - 1
    G = laws.fn.shape[0]
    part, gpart, stiff, force = parts
    S, DU, RES, TAN = scratch
    H, L = cell.H, cell.L
    L_old = np.empty((3, 3))
    F_build = np.empty((3, 3))
    H_new = np.empty((3, 3))
    Hb_inv = np.linalg.inv(cell.H_build)
    for step in range(max_steps):
        # contacts: kinematics and the law
        part[:, :] = 0.0
        part[:, P_FAILED] = -1.0
        for k in prange(nchunk):
            lo, hi = chunk[k], chunk[k + 1]
            for g in range(G):
                a, b = max(lo, gstart[g]), min(hi, gstart[g + 1])
                if a < b:
                    contact_range(a, b, laws.fn[g], laws.row[g], laws.virgin[g],
                                  workspaces[int(k) * G + g], lists, grains, cell, pairs, params,
                                  (S[k], DU[k], RES[k], TAN[k]), part[k])
        total = np.zeros(P_FAILED)
        failed = -1
        overlap = 0.0
        stiff[:] = 0.0
        for k in range(nchunk):
            for c in range(P_OVERLAP):
                total[c] += part[k, c]
            overlap = max(overlap, part[k, P_OVERLAP])
            for c in range(6):
                stiff[c] += part[k, P_STIFF + c]
            if part[k, P_FAILED] >= 0.0 and failed < 0:
                failed = int(part[k, P_FAILED])
        volume = _volume(H, dim)
        for a in range(3):
            for b in range(3):
                stress[a, b] = 0.5 * (total[P_VIRIAL + 3 * a + b] + total[P_VIRIAL + 3 * b + a]) / volume
        m.dissipation += total[P_DISSIPATION]
        m.closed = int(total[P_CLOSED])
        m.sliding = int(total[P_SLIDING])
        m.max_overlap = overlap
        if failed >= 0:
            m.failed_pair = failed
            return 4, step  # FAILED
        if overlap > params.max_overlap:
            return 5, step  # UNSTABLE
        # the cell servo: L of the next step
        L_old[:, :] = L
        _servo(L, control, stress, stiff, volume, dt, m.stage_time)
        work = 0.0
        for a in range(3):
            for b in range(3):
                work -= stress[a, b] * 0.5 * (L_old[a, b] + L[a, b])
        m.boundary_work += work * volume * dt
        # forces per grain and the leapfrog
        for a in range(3):
            for b in range(3):
                acc = H[a, b]
                for c in range(3):
                    acc += dt * L[a, c] * H[c, b]
                H_new[a, b] = acc
        F_build[:, :] = H_new @ Hb_inv
        gpart[:, :] = 0.0
        if params.frictionless:
            fsum, dt_next = _fire_step(lists, grains, cell, pairs, params, m, dt, force, F_build,
                                       gpart)
        else:
            for k in prange(ngchunk):
                grain_range(gchunk[k], gchunk[k + 1], lists, grains, cell, pairs, params, F_build,
                            gpart[k])
            fsum = 0.0
            for k in range(ngchunk):
                fsum += gpart[k, G_FORCE]
        kin = loss = shift = 0.0
        for k in range(ngchunk):
            kin += gpart[k, G_KINETIC]
            loss += gpart[k, G_DAMPING]
            shift = max(shift, gpart[k, G_SHIFT])
        m.kinetic = kin
        m.damping_loss += loss
        n = grains.x.shape[0]
        closed = total[P_CLOSED]
        m.unbalanced = (fsum / n) / (total[P_FORCE] / closed) if closed > 0 else np.inf
        # the cell moves
        H[:, :] = H_new
        m.time += dt
        m.stage_time += dt
        m.steps += 1
        if params.frictionless:
            dt = dt_next
            m.fire_dt = dt
        if not (math.isfinite(kin) and math.isfinite(m.boundary_work)):
            return 5, step + 1  # UNSTABLE
        strain = 0.0
        for a in range(3):
            for b in range(3):
                d = F_build[a, b] - (1.0 if a == b else 0.0)
                strain += d * d
        m.max_shift = shift + 0.5 * math.sqrt(strain) * params.cutoff
        if control.settle and _settled(control, stress, m.unbalanced, m.stage_time):
            return 2, step + 1  # SETTLED
        if m.stage_time >= stop_time:
            return 1, step + 1  # REACHED
        if m.max_shift > 0.5 * params.skin:
            return 3, step + 1  # REBUILD
    return 0, max_steps  # STEPS


def advance(state, lists, laws, workspaces, params, control, scratch, parts, max_steps: int,
            stop_time: float):
    """Up to ``max_steps`` steps, stopping early (the :class:`Outcome`) where the stage's time
    reaches ``stop_time``, the stage settles (``control.settle``), the neighbours must be
    rebuilt, a contact update fails or the motion is unstable. Returns ``(outcome, steps)``."""
    return _advance(lists, state.grains, state.cell, state.pairs, laws, workspaces, params,
                    control, state.meters, state.stress, scratch, parts, int(max_steps),
                    float(stop_time))
