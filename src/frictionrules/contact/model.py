r"""The elastic-plastic contact model of §4: :class:`ContactModel`.

Conventions (``docs/conventions.md``, ``docs/contact.md``): displacements
``δ = (δt1, δt2, δn)`` with ``δn`` positive on **opening**; forces ``(T1, T2, N)`` with
``N > 0`` in compression. The additive split (4.1) ``δ = δᵉ + δᵖ`` and the elastic law (4.2)
read

.. math:: T = k_t(\delta_t - \delta_t^p), \qquad N = -k_n(\delta_n - \delta_n^p),

(the paper's ``δ̇ₙᵉ = Ṅ/Kₙ`` measures ``δn`` positive in closure; see ``docs/errata.md``).
The sliding rule (4.3) is :math:`\dot\delta^p = \dot\lambda(g_{,T_1}, g_{,T_2}, -g_{,N})`
and the law's internal variables follow (4.5), :math:`\dot q = \dot\lambda\,h(T, N, q)`
(for the cap :math:`\dot\kappa = |\dot\delta^p_t|`, :math:`\dot\beta = B(\beta)\,\dot\lambda\,
g_{,N}`, compaction positive).

**Separation.** Where the trial normal force ``-kn (δn - δnᵖ) <= 0`` the contact is open: both
forces vanish, ``δnᵖ`` and the internal variables are kept, and the tangential plastic
displacement follows the total one (a free, non-dissipative rigid motion: on closing again
the contact sticks where it is).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from ..errors import FrictionRulesError, check_finite, check_scalar
from ..laws import FrictionLaw, HardenedLaw, LawState, SlipHardening, require
from ._step import Step, finish, generic_step, slip_increment, trial
from .state import ELASTIC, OPEN, PLASTIC, ContactState, UpdateResult

__all__ = ["ContactModel"]


@functools.lru_cache(maxsize=1)
def _has_numba() -> bool:
    """Whether Numba is installed (the generated compiled return needs it; without it the
    NumPy return mapping runs)."""
    import importlib.util
    return importlib.util.find_spec("numba") is not None


@dataclass(frozen=True)
class ContactModel:
    r"""Elastic-plastic contact (§4): elastic layer (4.2), sliding rule (4.3) of any law.

    Parameters
    ----------
    law : FrictionLaw
        Any law of the protocol with a symbolic form (capability ``"symbolic"``): the built-in
        laws, user laws, the hardening cap (4.9), a law with slip hardening.
    kn, kt : float
        Normal and tangential stiffness of the contact layer (force/length), ``> 0``.
    hardening : SlipHardening, optional
        Slip hardening of a law without internal variables: the model integrates
        ``HardenedLaw(law, hardening)``.

    Notes
    -----
    :meth:`update` integrates one step implicitly (backward Euler, closest-point projection
    by Newton, substepping when Newton fails). Every law runs a compiled return mapping
    generated from its symbolic form (Numba; built once per law structure and cached on disk,
    see :mod:`frictionrules.contact._generated`), which also gives the consistent tangent; a
    law that offers a hand-written compiled return (capability ``"closed_form_return"``:
    Coulomb) runs that instead when no tangent is asked for. Without Numba, and with
    ``compiled=False``, the return mapping runs in NumPy.
    """

    law: FrictionLaw
    kn: float
    kt: float
    hardening: SlipHardening | None = None

    def __post_init__(self):
        object.__setattr__(self, "kn", check_scalar("kn", self.kn, lo=0.0, lo_open=True))
        object.__setattr__(self, "kt", check_scalar("kt", self.kt, lo=0.0, lo_open=True))
        if self.hardening is not None and not isinstance(self.hardening, SlipHardening):
            raise FrictionRulesError(f"hardening = {self.hardening!r} violates: must be a SlipHardening or None")
        if not isinstance(self.law, FrictionLaw):
            raise FrictionRulesError(f"law = {self.law!r} violates: must be a friction law of frictionrules")
        if self.hardening is not None and self.law.state_names:
            raise FrictionRulesError(f"hardening must be None for a law with internal variables "
                                     f"{list(self.law.state_names)} (law = {type(self.law).__name__})")
        require(self.effective_law, "symbolic", "ContactModel(law=...)")

    # ---- the law -------------------------------------------------------------------------
    @functools.cached_property
    def effective_law(self) -> FrictionLaw:
        """The law integrated: ``law``, or ``HardenedLaw(law, hardening)``."""
        return self.law if self.hardening is None else HardenedLaw(self.law, self.hardening)

    @property
    def _names(self) -> tuple[str, ...]:
        return self.effective_law.state_names

    @functools.cached_property
    def _surface(self):
        from .integrate import Surface
        return Surface(self.effective_law)

    @property
    def _Dv(self) -> np.ndarray:
        return np.array([self.kt, self.kt, self.kn])

    @property
    def elastic_tangent(self) -> np.ndarray:
        """``E = diag(kt, kt, -kn)``: d(T1, T2, N)/d(δt1, δt2, δn) of the elastic law (4.2)."""
        return np.diag([self.kt, self.kt, -self.kn])

    def kernel(self):
        """Name of the law's hand-written compiled return, or None (the derived return)."""
        law = self.effective_law
        if "closed_form_return" in law.capabilities:
            return law.closed_form_return().kernel
        return None

    def compiled(self):
        """This model as the compiled entry takes it (:class:`CompiledLaw`: the addresses of
        the law's generated functions and its row of stiffnesses and parameters), for a
        compiled loop that calls ``frictionrules.contact.contact_update`` per contact (the
        grain assemblies' dynamic engine). Needs Numba and SymPy."""
        from ._generated import compiled_law
        return compiled_law(self.effective_law, self.kt, self.kn)

    # ---- states ----------------------------------------------------------------------------
    def initial_state(self, shape=(), beta=0.5, **internal) -> ContactState:
        """Virgin contacts: zero displacements, ``κ = 0``, the area fraction ``β`` and the law's
        initial internal variables (``internal`` overrides a user law's own)."""
        shape = (int(shape),) if np.ndim(shape) == 0 else tuple(int(k) for k in shape)
        beta = check_scalar("beta", beta, lo=0.0, hi=1.0, lo_open=True, hi_open=True)
        if "beta" in self._names:
            internal["beta"] = beta
        q0 = self.effective_law.initial_state(shape, **internal)
        own = [n for n in self._names if n not in ("kappa", "beta")]
        extra = LawState(tuple(own), np.stack([getattr(q0, n) for n in own], axis=-1)
                         if own else np.zeros(shape + (0,)))
        kappa = getattr(q0, "kappa") if "kappa" in self._names else np.zeros(shape)
        z = np.zeros(shape + (3,))
        return ContactState(z, z, kappa, np.full(shape, beta), extra)

    def _q(self, state: ContactState) -> np.ndarray:
        """The law's internal variables ``(n, nq)`` from a state."""
        cols = [state.variable(n).ravel() for n in self._names]
        return np.stack(cols, axis=-1) if cols else np.zeros((int(np.prod(state.shape)), 0))

    def law_state(self, state: ContactState) -> LawState:
        """The law's internal variables of ``state`` as a :class:`LawState`."""
        return LawState(self._names, self._q(state).reshape(state.shape + (len(self._names),)))

    def _new_state(self, state: ContactState, step: Step) -> ContactState:
        shape = state.shape
        names = self._names
        q1 = step.q
        if "kappa" in names:
            kappa = q1[:, names.index("kappa")]
        else:
            kappa = state.kappa.ravel() + step.slip
        beta = q1[:, names.index("beta")] if "beta" in names else state.beta.ravel()
        own = [n for n in names if n not in ("kappa", "beta")]
        extra = LawState(tuple(own), (np.stack([q1[:, names.index(n)] for n in own], axis=-1)
                                      if own else np.zeros((len(q1), 0))).reshape(shape + (len(own),)))
        return ContactState(step.e.reshape(shape + (3,)), step.p.reshape(shape + (3,)),
                            kappa.reshape(shape), beta.reshape(shape), extra)

    def force(self, state: ContactState) -> np.ndarray:
        """``(T1, T2, N)`` of a state by the elastic law (4.2); zero where the contact is open."""
        e = state.elastic
        N = -self.kn * e[..., 2]
        closed = N > 0
        return np.stack((np.where(closed, self.kt * e[..., 0], 0.0), np.where(closed, self.kt * e[..., 1], 0.0),
                         np.where(closed, N, 0.0)), axis=-1)

    def yield_value(self, state: ContactState) -> np.ndarray:
        """f at the state's forces and internal variables (0 where open)."""
        sig, q, closed = self._flat_forces(state)
        out = np.zeros(len(sig))
        if closed.any():
            out[closed] = self._surface.limit(sig[closed], q[closed])
        return out.reshape(state.shape)

    def yield_residual(self, state: ContactState) -> np.ndarray:
        r"""f normalized to a force scale: :math:`f / (|\nabla_\sigma f|\,|\sigma|)` (0 where open).

        ``f/|∇f|`` is, to first order, the distance of the forces from the surface, so this is
        the relative distance, comparable between laws of any degree (e.g. the quadratic cap).
        The denominator is at least ``|f|``, so the value lies in ``[-1, 1]``.
        """
        sig, q, closed = self._flat_forces(state)
        out = np.zeros(len(sig))
        if closed.any():
            loc = self._surface.evaluate(sig[closed], q[closed])
            scale = np.linalg.norm(loc.df, axis=-1) * np.linalg.norm(sig[closed], axis=-1)
            # Inside, where ∇f may vanish (the centre of the cap), |f| bounds the scale: -1 there.
            out[closed] = loc.f / np.maximum(scale, np.abs(loc.f))
        return out.reshape(state.shape)

    def _flat_forces(self, state):
        sig = self.force(state).reshape(-1, 3)
        return sig, self._q(state), sig[:, 2] > 0

    def _increments(self, state, increments) -> np.ndarray:
        du = check_finite("increments", increments)
        if du.shape != state.shape + (3,):
            try:
                du = np.broadcast_to(du, state.shape + (3,))
            except ValueError:
                raise FrictionRulesError(f"increments must have shape {state.shape + (3,)} "
                                         f"(δt1, δt2, δn per contact), got {du.shape}") from None
        return du

    # ---- the update ---------------------------------------------------------------------
    def update(self, state: ContactState, increments, tangent: bool = False,
               compiled: bool = True) -> UpdateResult:
        """Integrate one step of prescribed displacement increments, implicitly.

        Parameters
        ----------
        state : ContactState
            History at the start of the step (not modified).
        increments : array (..., 3)
            ``(Δδt1, Δδt2, Δδn)`` per contact, broadcast to ``state.shape + (3,)``.
        tangent : bool
            Also return the consistent tangent ``d(T1, T2, N)/d(δt1, δt2, δn)``.
        compiled : bool
            Use a compiled return (default): the law's hand-written one where it has one and
            no tangent is asked for, else the one generated from its symbolic form. False
            forces the return mapping derived in NumPy.

        Returns
        -------
        UpdateResult
        """
        du = self._increments(state, increments).reshape(-1, 3)
        e = state.elastic.reshape(-1, 3)
        p = state.plastic.reshape(-1, 3)
        q = self._q(state)
        kappa_index = self._names.index("kappa") if "kappa" in self._names else None
        name = self.kernel() if compiled else None
        tan = None
        if name is not None and not tangent:
            from ._kernel_batch import batch_of, step_of
            from ._kernels import run_kernel
            out = run_kernel(self.effective_law.closed_form_return(), self.kt, self.kn,
                             batch_of(e, p, q, du))
            step, failed = step_of(out), out.failed
        elif compiled and _has_numba():
            from ._generated import generated_step
            step, failed, tan = generated_step(self.effective_law, self.kt, self.kn, e, p, q, du,
                                               tangent)
        else:
            step, failed = generic_step(self._surface, e, p, q, du, self._Dv, kappa_index), None
        if failed is not None and failed.any():
            # The compiled iteration failed there: the derived return substeps.
            idx = np.flatnonzero(failed)
            g = generic_step(self._surface, e[idx], p[idx], q[idx], du[idx], self._Dv, kappa_index)
            for field in ("e", "p", "q", "force", "dlam", "status", "dissipation", "slip"):
                getattr(step, field)[idx] = getattr(g, field)
            if tan is not None:
                tan[idx] = self._tangent(g)
        if tangent:
            tan = (self._tangent(step) if tan is None else tan).reshape(state.shape + (3, 3))
        shape = state.shape
        return UpdateResult(self._new_state(state, step), step.force.reshape(shape + (3,)),
                            step.dlam.reshape(shape), step.status.reshape(shape),
                            step.dissipation.reshape(shape), tan)

    def _tangent(self, step: Step):
        """Consistent tangent: ``(dσ/dσ_trial) E`` where closed, 0 where open."""
        from .integrate import tangent_at
        dsig = step.dsigma
        if dsig is None:
            n = len(step.force)
            dsig = np.zeros((n, 3, 3))
            dsig[step.status == ELASTIC] = np.eye(3)
            pl = step.status == PLASTIC
            if pl.any():
                dsig[pl] = tangent_at(self._surface, step.force[pl], step.q[pl], step.dlam[pl], self._Dv)
        return np.where((step.status == OPEN)[:, None, None], 0.0, dsig @ self.elastic_tangent)

    def rate_update(self, state: ContactState, increments) -> UpdateResult:
        """One explicit step of the rate form (4.7), (4.10)–(4.11), for verification.

        Forward Euler on the elastic-plastic rate equations with the elastic part of a step
        that reaches the surface split off; no return to the surface (the drift is O(step)).
        """
        from .integrate import rate_step
        du = self._increments(state, increments).reshape(-1, 3)
        e = state.elastic.reshape(-1, 3)
        p = state.plastic.reshape(-1, 3)
        q = self._q(state)
        sig0 = self.force(state).reshape(-1, 3)
        e_tr = e + du
        sig = trial(e_tr, self._Dv)
        open_ = sig[:, 2] <= 0
        q1, dlam = q.copy(), np.zeros(len(e))
        c = ~open_
        if c.any():
            s, qq, dl = rate_step(self._surface, sig0[c], q[c], (du @ self.elastic_tangent)[c], self._Dv)
            sig[c], q1[c], dlam[c] = s, qq, dl
        status = np.where(open_, OPEN, np.where(dlam > 0, PLASTIC, ELASTIC))
        e1, p1, sig, diss = finish(e_tr, p, sig, status, self._Dv)
        step = Step(e1, p1, q1, sig, dlam, status, diss, slip_increment(e_tr, e1, status))
        shape = state.shape
        return UpdateResult(self._new_state(state, step), sig.reshape(shape + (3,)), dlam.reshape(shape),
                            status.reshape(shape), diss.reshape(shape), None)
