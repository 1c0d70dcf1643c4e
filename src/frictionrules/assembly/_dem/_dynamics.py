r"""One assembly in the dynamic engine: its grains' masses, its contact models compiled, the
engine's numbers and scratch; :meth:`Dynamics.init` makes the state, :meth:`Dynamics.run`
advances it (rebuilding the neighbours as it goes).

Grains have the mass of their volume times ``density``: ``m = ρ (4/3) π r³``, moment of
inertia ``(2/5) m r²`` for spheres; ``m = ρ π r²`` (per unit thickness), ``(1/2) m r²`` for
disks. The skin of the neighbour list is ``SKIN`` times the mean radius.
"""

from __future__ import annotations

import dataclasses
import math

import numba
import numpy as np

from ...contact import ContactModel, ContactState, workspace
from ...errors import FrictionRulesError
from ...laws import Coulomb, LawState
from ._engine import CHUNKS, Outcome, advance, lists_of, new_pairs, rebuild, time_step
from ._passes import G_SIZE, P_SIZE
from ._state import Cell, DemState, Grains, Laws, Params, new_meters

__all__ = ["Dynamics", "SKIN", "MAX_OVERLAP", "PARALLEL_PAIRS"]

#: Skin of the neighbour list, in mean radii.
SKIN = 0.1
#: Pairs below which a run keeps to one thread: a parallel pass costs a few microseconds of
#: synchronisation per step on an idle machine, and far more where other processes hold the
#: cores (a thread descheduled at the barrier stalls the others).
PARALLEL_PAIRS = 16384
#: Float64 words per cache line and more (128 bytes: two lines, as adjacent-line prefetching
#: pairs them).
_LINE = 16
#: Largest overlap accepted, as a fraction of the smaller radius: beyond it the motion is
#: unstable (or the contacts far too soft for the loading).
MAX_OVERLAP = 0.5


def embed_positions(x: np.ndarray) -> np.ndarray:
    """Positions (n, d) as (n, 3) rows (z = 0 for disks)."""
    out = np.zeros((len(x), 3))
    out[:, :x.shape[1]] = x
    return out


def embed_cell(h: np.ndarray) -> np.ndarray:
    """A cell (d, d) as (3, 3); for disks the third vector is ``(0, 0, 1)`` (never searched)."""
    out = np.eye(3)
    d = h.shape[0]
    out[:d, :d] = h
    return out


class _Groups:
    """The contact model of each pair: one model for all, or ``assembly.model_of(i, j)`` asked
    once per pair of grains."""

    def __init__(self, assembly):
        self.assembly = assembly
        self.single = isinstance(assembly.model, ContactModel)
        self.models = [assembly.model] if self.single else []
        self.first = [(0, 0)] if self.single else []
        self.known: dict[tuple[int, int], int] = {}

    def __call__(self, I, J) -> np.ndarray:
        if self.single:
            return np.zeros(len(I), dtype=np.int64)
        out = np.empty(len(I), dtype=np.int64)
        for c, key in enumerate(zip(I.tolist(), J.tolist())):
            g = self.known.get(key)
            if g is None:
                m = self.assembly.model_of(*key)
                try:
                    g = self.models.index(m)
                except ValueError:
                    self.models.append(m)
                    self.first.append(key)
                    g = len(self.models) - 1
                self.known[key] = g
            out[c] = g
        return out


def compile_laws(models, width: int) -> Laws:
    """:class:`Laws` of the contact models (state rows of ``width``)."""
    compiled = [m.compiled() for m in models]
    rows = np.zeros((len(models), max(len(c.row) for c in compiled)))
    virgin = np.zeros((len(models), width))
    for g, (m, c) in enumerate(zip(models, compiled)):
        rows[g, :len(c.row)] = c.row
        if c.nq:
            virgin[g, 6:6 + c.nq] = m.law_state(m.initial_state(1)).values[0]
    return Laws(np.array([c.fn for c in compiled], dtype=np.int64), rows,
                np.array([c.nq for c in compiled], dtype=np.int64), virgin)


def contact_states(model: ContactModel, rows: np.ndarray, slip: np.ndarray) -> ContactState:
    """The :class:`ContactState` of contacts of ``model`` from their state rows."""
    names = tuple(model.effective_law.state_names)
    q = rows[:, 6:6 + len(names)]
    m = len(rows)
    kappa = q[:, names.index("kappa")] if "kappa" in names else slip.copy()
    beta = q[:, names.index("beta")] if "beta" in names else np.full(m, 0.5)
    own = [n for n in names if n not in ("kappa", "beta")]
    internal = LawState(tuple(own), q[:, [names.index(n) for n in own]] if own else np.zeros((m, 0)))
    return ContactState(rows[:, 0:3].copy(), rows[:, 3:6].copy(), kappa, beta, internal)


class Dynamics:
    """The dynamic engine for one assembly (see the module docstring)."""

    def __init__(self, assembly, *, density: float, damping: float):
        self.assembly = assembly
        self.dim = assembly.dim
        r = assembly.radii
        if self.dim == 3:
            mass = density * 4.0 / 3.0 * np.pi * r**3
            inertia = 0.4 * mass * r**2
        else:
            mass = density * np.pi * r**2
            inertia = 0.5 * mass * r**2
        self.mass, self.inertia = mass, inertia
        self.groups = _Groups(assembly)
        x = embed_positions(assembly.positions)
        H = embed_cell(assembly.cell)
        self.skin = SKIN * float(np.mean(r))
        self._params = dict(damping=float(damping), skin=self.skin,
                            axis0=float(assembly.reference_axis[0]),
                            axis1=float(assembly.reference_axis[1]),
                            axis2=float(assembly.reference_axis[2]), dim=self.dim,
                            max_overlap=MAX_OVERLAP, cutoff=2 * float(r.max()) + self.skin)
        from ._neighbours import build_pairs
        I, J, K = build_pairs(x, r, H, self.skin, self.dim)
        self._first = (x, H, I, J, K, self.groups(I, J))
        self.models = list(self.groups.models)
        self._laws = {}
        self.lists = None

    # ---- laws --------------------------------------------------------------------------------
    def width(self) -> int:
        return 6 + max(len(m.effective_law.state_names) for m in self.models)

    def laws(self, frictionless: bool = False):
        """The compiled laws (and a workspace per chunk and model) of the models, or of
        frictionless contacts with the same stiffnesses."""
        key = (frictionless, len(self.models))
        if key not in self._laws:
            models = self.models if not frictionless else [
                ContactModel(Coulomb(0.0), kn=m.kn, kt=m.kt) for m in self.models]
            laws = compile_laws(models, self.width())
            from numba.typed import List
            ws = List()
            for _ in range(CHUNKS):
                for nq in laws.nq:
                    ws.append(workspace(int(nq)))
            self._laws[key] = (laws, ws)
        return self._laws[key]

    @property
    def k_max(self) -> float:
        return max(max(m.kn, m.kt) for m in self.models)

    def params(self, frictionless: bool = False) -> Params:
        dt = time_step(float(self.mass.min()), self.k_max)
        return Params(dt=dt, frictionless=int(frictionless), **self._params)

    # ---- state -------------------------------------------------------------------------------
    def init(self) -> DemState:
        """The assembly at rest: zero velocities and spins, no contact history."""
        x, H, I, J, K, group = self._first
        n = len(x)
        grains = Grains(x.copy(), np.zeros((n, 3)), np.zeros((n, 3)), self.assembly.radii.copy(),
                        1.0 / self.mass, 1.0 / self.inertia, x.copy())
        cell = Cell(H.copy(), np.zeros((3, 3)), H.copy(), H.copy())
        pairs = new_pairs(I, J, K, group, self.width())
        return DemState(grains, cell, pairs, np.zeros((3, 3)), new_meters())

    def _scratch(self, width):
        """Each chunk's scratch rows and partial sums, every row on cache lines of its own (a
        thread writing its row would otherwise invalidate its neighbours': false sharing), and the
        forces on the grains of a FIRE step."""
        def rows(*shape):
            size = int(np.prod(shape))
            line = -(-size // _LINE) * _LINE
            return np.zeros((CHUNKS, line))[:, :size].reshape((CHUNKS,) + shape)
        return ((rows(width), rows(3), rows(6), rows(3, 3)),
                (rows(P_SIZE), rows(G_SIZE), np.zeros(6), np.zeros((len(self.mass), 3))))

    def run(self, state: DemState, control, stop_time: float, max_steps: int,
            frictionless: bool = False) -> tuple[DemState, int]:
        """Advance until the stage's time reaches ``stop_time``, the stage settles, or
        ``max_steps`` steps are done (rebuilding the neighbours as needed). Returns the state
        and the :class:`Outcome` (STEPS, REACHED or SETTLED); a failed contact update or an
        unstable motion raises :class:`FrictionRulesError`."""
        laws, ws = self.laws(frictionless)
        params = self.params(frictionless)
        scratch, parts = self._scratch(state.pairs.state.shape[1])
        threads = numba.get_num_threads()
        numba.set_num_threads(1 if len(state.pairs.i) < PARALLEL_PAIRS else threads)
        try:
            return self._run(state, control, stop_time, max_steps, laws, ws, params, scratch, parts)
        finally:
            numba.set_num_threads(threads)

    def _run(self, state, control, stop_time, max_steps, laws, ws, params, scratch, parts):
        done = 0
        while done < max_steps:
            if self.lists is None or self.lists[0] is not state.pairs:
                self.lists = (state.pairs, lists_of(state.pairs, state.size, len(laws.fn)))
            outcome, steps = advance(state, self.lists[1], laws, ws, params, control, scratch,
                                     parts, max_steps - done, stop_time)
            done += steps
            if outcome == Outcome.REBUILD:
                state = self.rebuild(state)
                continue
            if outcome == Outcome.FAILED:
                raise self._failure(state, laws)
            if outcome == Outcome.UNSTABLE:
                raise self._unstable(state, params)
            return state, outcome
        return state, Outcome.STEPS

    def rebuild(self, state: DemState) -> DemState:
        n_models = len(self.groups.models)
        grains, cell, pairs = rebuild(state.grains, state.cell, state.pairs, self.params(), self.groups)
        if len(self.groups.models) != n_models:
            self.models = list(self.groups.models)
            if 6 + max(len(m.effective_law.state_names) for m in self.models) > pairs.state.shape[1]:
                pairs = _widen(pairs, self.width())
        return dataclasses.replace(state, grains=grains, cell=cell, pairs=pairs)

    def _failure(self, state, laws) -> FrictionRulesError:
        c = int(state.meters[0]["failed_pair"])
        p = state.pairs
        model = self.models[int(p.group[c])]
        return FrictionRulesError(
            f"the contact update of law {model.effective_law!r} did not converge at the contact "
            f"between grains {int(p.i[c])} and {int(p.j[c])} (step {int(state.meters[0]['steps'])}, "
            f"even with 2**10 substeps); constraint: a law whose return mapping converges")

    def _unstable(self, state, params) -> FrictionRulesError:
        m = state.meters[0]
        return FrictionRulesError(
            f"the motion became unstable at step {int(m['steps'])} (largest overlap "
            f"{float(m['max_overlap']):.3g} of the smaller radius, limit {params.max_overlap}; "
            f"kinetic energy {float(m['kinetic']):.3g}); constraint: contacts stiff enough for "
            f"the loading and a stable time step (dt = {params.dt:.3g})")

    def group_keys(self, state) -> np.ndarray:
        """A pair of grains of each contact model (G, 2), to restore the models' order."""
        return np.array(self.groups.first, dtype=np.int64).reshape(-1, 2)

    def restore_groups(self, keys: np.ndarray) -> None:
        """The contact models in the order of a saved run (:meth:`group_keys`)."""
        g = self.groups
        g.models = [self.assembly.model_of(int(i), int(j)) for i, j in keys]
        g.first = [(int(i), int(j)) for i, j in keys]
        g.known = {}
        self.models = list(g.models)
        self._laws = {}

    # ---- histories -----------------------------------------------------------------------------
    def bring_in_laws(self, state: DemState) -> None:
        """The laws take over from the frictionless contacts: every contact keeps its normal
        displacement and starts its tangential history virgin."""
        laws, _ = self.laws(False)
        p = state.pairs
        active = p.active.astype(bool)
        normal = p.state[:, 2].copy()
        p.state[active] = laws.virgin[p.group[active]]
        p.state[active, 2] = normal[active]
        p.slip[:] = 0.0

    def states_of(self, state: DemState, members: np.ndarray) -> tuple:
        """The :class:`ContactState` of the pairs ``members``, one batch per model."""
        p = state.pairs
        out = []
        for g, model in enumerate(self.models):
            idx = members[p.group[members] == g]
            out.append(contact_states(model, p.state[idx], p.slip[idx]))
        return tuple(out)


def _widen(pairs, width):
    state = np.zeros((len(pairs.i), width))
    state[:, :pairs.state.shape[1]] = pairs.state
    return pairs._replace(state=state)


def unit_rate(inertial_number: float, radii: np.ndarray, density: float, pressure: float) -> float:
    """The strain rate of the inertial number ``I = ε̇ d √(ρ/p)`` (``d`` the mean diameter)."""
    return inertial_number / (2.0 * float(np.mean(radii)) * math.sqrt(density / pressure))
