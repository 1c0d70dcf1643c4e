r"""The elastic-plastic contact model of §4: :class:`ContactModel`, its history
:class:`ContactState` and the outcome of one update, :class:`UpdateResult`.

Conventions (``docs/conventions.md``, ``docs/contact.md``): displacements
``δ = (δt1, δt2, δn)`` with ``δn`` positive on **opening**; forces ``(T1, T2, N)`` with
``N > 0`` in compression. The additive split (4.1) ``δ = δᵉ + δᵖ`` and the elastic law (4.2)
read

.. math:: T = k_t(\delta_t - \delta_t^p), \qquad N = -k_n(\delta_n - \delta_n^p),

(the paper's ``δ̇ₙᵉ = Ṅ/Kₙ`` measures ``δn`` positive in closure; see ``docs/errata.md``).
The sliding rule (4.3) is :math:`\dot\delta^p = \dot\lambda(g_{,T_1}, g_{,T_2}, -g_{,N})`
and the hardening variables follow (4.5): :math:`\dot\kappa = |\dot\delta^p_t|`,
:math:`\dot\beta = B(\beta)\,\dot\lambda\,g_{,N}` (compaction positive).

**Separation.** Where the trial normal force ``-kn (δn - δnᵖ) <= 0`` the contact is open: both
forces vanish, ``δnᵖ``, ``κ`` and ``β`` are kept, and the tangential plastic displacement
follows the total one (a free, non-dissipative rigid motion: on closing again the contact
sticks where it is).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import FrictionRulesError, check_finite, check_scalar
from ..laws.base import FrictionLaw
from .cap import EllipsoidCap

__all__ = ["ContactModel", "ContactState", "SlipHardening", "UpdateResult"]

#: Status codes of an update, per contact.
ELASTIC, PLASTIC, OPEN = 0, 1, 2
_MAX_SUBSTEP_DEPTH = 10


def _frozen(a) -> np.ndarray:
    a = np.array(a, dtype=float)
    a.flags.writeable = False
    return a


@dataclass(frozen=True)
class SlipHardening:
    r"""Slip hardening of a protocol law: :math:`\hat f(T, N, \kappa) = f(T, s(\kappa)N)`,
    :math:`s(\kappa) = 1 + h(1 - e^{-\kappa/\kappa_h})` (the potential is scaled the same way).

    For a law linear in N (Coulomb, the orthotropic laws) this multiplies every friction
    coefficient by ``s(κ)``: hardening for ``h > 0``, softening for ``-1 < h < 0``. The
    hardening modulus (4.7) is :math:`H = -f_{,N} N s'(\kappa)|g_{,T}|`.
    """

    h: float
    kappa_h: float

    def __post_init__(self):
        object.__setattr__(self, "h", check_scalar("h", self.h, lo=-1.0, lo_open=True))
        object.__setattr__(self, "kappa_h", check_scalar("kappa_h", self.kappa_h, lo=0.0, lo_open=True))

    def scale(self, kappa):
        return 1.0 + self.h * (1.0 - np.exp(-np.asarray(kappa) / self.kappa_h))

    def scale_derivative(self, kappa):
        return self.h / self.kappa_h * np.exp(-np.asarray(kappa) / self.kappa_h)


@dataclass(frozen=True, eq=False)
class ContactState:
    """History of a batch of contacts (read-only arrays; every update returns a new state).

    The total displacement ``δ = δᵉ + δᵖ`` (4.1) is the property :attr:`displacement`; the
    elastic part is stored, not recomputed, so that the forces keep full precision when
    ``|δᵉ| << |δ|``.

    Attributes
    ----------
    elastic : (..., 3)
        Elastic (reversible) part ``δᵉ = (δt1ᵉ, δt2ᵉ, δnᵉ)``, ``δn > 0`` opening; where the contact
        is open ``δnᵉ > 0`` is the gap and ``δtᵉ = 0``.
    plastic : (..., 3)
        Plastic (irreversible) part ``δᵖ`` (4.1).
    kappa : (...)
        Accumulated tangential plastic slip κ (4.5).
    beta : (...)
        Fraction of real contact area β (4.5); constant for laws without a cap.
    """

    elastic: np.ndarray
    plastic: np.ndarray
    kappa: np.ndarray
    beta: np.ndarray

    def __post_init__(self):
        u = check_finite("elastic", self.elastic)
        if u.ndim == 0 or u.shape[-1] != 3:
            raise FrictionRulesError(f"elastic must have shape (..., 3), got {u.shape}")
        shape = u.shape[:-1]
        p = check_finite("plastic", self.plastic)
        if p.shape != u.shape:
            raise FrictionRulesError(f"plastic must have shape {u.shape}, got {p.shape}")
        kappa = np.broadcast_to(check_finite("kappa", self.kappa), shape)
        beta = np.broadcast_to(check_finite("beta", self.beta), shape)
        if np.any(kappa < 0):
            raise FrictionRulesError("kappa violates kappa >= 0 (accumulated slip)")
        if np.any((beta <= 0) | (beta >= 1)):
            raise FrictionRulesError("beta violates 0 < beta < 1 (fraction of real contact area)")
        for name, value in (("elastic", u), ("plastic", p), ("kappa", kappa), ("beta", beta)):
            object.__setattr__(self, name, _frozen(value))

    @property
    def displacement(self) -> np.ndarray:
        """Total displacement ``δ = δᵉ + δᵖ`` (4.1), shape ``(..., 3)``."""
        return self.elastic + self.plastic

    @property
    def shape(self) -> tuple[int, ...]:
        return self.kappa.shape


@dataclass(frozen=True, eq=False)
class UpdateResult:
    """Outcome of :meth:`ContactModel.update` for a batch of contacts.

    Attributes
    ----------
    state : ContactState
        The new history.
    force : (..., 3)
        ``(T1, T2, N)`` at the end of the step.
    dlam : (...)
        Plastic multiplier increment Δλ (0 where elastic or open).
    status : (...) int
        0 elastic, 1 plastic, 2 open (separated).
    dissipation : (...)
        Plastic work of the step, :math:`T\\cdot\\Delta\\delta_t^p - N\\Delta\\delta_n^p`
        (end-of-step forces, as backward Euler), ``>= 0``.
    tangent : (..., 3, 3) or None
        Consistent tangent ``d(T1, T2, N)/d(δt1, δt2, δn)`` when requested.
    """

    state: ContactState
    force: np.ndarray
    dlam: np.ndarray
    status: np.ndarray
    dissipation: np.ndarray
    tangent: np.ndarray | None = None


@dataclass(frozen=True)
class ContactModel:
    r"""Elastic-plastic contact (§4): elastic layer (4.2), sliding rule (4.3) of any law.

    Parameters
    ----------
    law : FrictionLaw or EllipsoidCap
        Any law of the core protocol (associated or not), or the hardening cap (4.9).
    kn, kt : float
        Normal and tangential stiffness of the contact layer (force/length), ``> 0``.
    hardening : SlipHardening, optional
        Slip hardening of a protocol law (not for the cap, which carries its own A, B).

    Notes
    -----
    :meth:`update` integrates one step implicitly (backward Euler, closest-point projection
    by Newton, substepping when Newton fails); Coulomb and EllipticOrthotropic without
    hardening and the default cap run in compiled (Numba) kernels, every other law in the
    generic NumPy path that uses the law's gradients and SymPy-derived Hessians.
    """

    law: object
    kn: float
    kt: float
    hardening: SlipHardening | None = None

    def __post_init__(self):
        if not isinstance(self.law, (FrictionLaw, EllipsoidCap)):
            raise FrictionRulesError(f"law = {self.law!r} violates: must be a FrictionLaw or EllipsoidCap")
        object.__setattr__(self, "kn", check_scalar("kn", self.kn, lo=0.0, lo_open=True))
        object.__setattr__(self, "kt", check_scalar("kt", self.kt, lo=0.0, lo_open=True))
        if self.hardening is not None and not isinstance(self.hardening, SlipHardening):
            raise FrictionRulesError(f"hardening = {self.hardening!r} violates: must be a SlipHardening or None")
        if self.hardening is not None and isinstance(self.law, EllipsoidCap):
            raise FrictionRulesError("hardening must be None for an EllipsoidCap (it carries A and B)")

    # ---- helpers ------------------------------------------------------------------------
    @property
    def _Dv(self) -> np.ndarray:
        return np.array([self.kt, self.kt, self.kn])

    @property
    def elastic_tangent(self) -> np.ndarray:
        """``E = diag(kt, kt, -kn)``: d(T1, T2, N)/d(δt1, δt2, δn) of the elastic law (4.2)."""
        return np.diag([self.kt, self.kt, -self.kn])

    def _surface(self):
        from .integrate import surface_for
        return surface_for(self.law, self.hardening)

    def initial_state(self, shape=(), beta=0.5) -> ContactState:
        """Virgin contacts: zero displacements, ``κ = 0`` and the given area fraction ``β``."""
        shape = (int(shape),) if np.ndim(shape) == 0 else tuple(int(k) for k in shape)
        beta = check_scalar("beta", beta, lo=0.0, hi=1.0, lo_open=True, hi_open=True)
        z = np.zeros(shape + (3,))
        return ContactState(z, z, np.zeros(shape), np.full(shape, beta))

    def force(self, state: ContactState) -> np.ndarray:
        """``(T1, T2, N)`` of a state by the elastic law (4.2); zero where the contact is open."""
        e = state.elastic
        N = -self.kn * e[..., 2]
        closed = N > 0
        return np.stack((np.where(closed, self.kt * e[..., 0], 0.0), np.where(closed, self.kt * e[..., 1], 0.0),
                         np.where(closed, N, 0.0)), axis=-1)

    def yield_value(self, state: ContactState) -> np.ndarray:
        """f at the state's forces and hardening variables (0 where open)."""
        sig, q, closed = self._flat_forces(state)
        out = np.zeros(len(sig))
        if closed.any():
            out[closed] = self._surface().limit(sig[closed], q[closed])
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
            loc = self._surface().evaluate(sig[closed], q[closed])
            scale = np.linalg.norm(loc.df, axis=-1) * np.linalg.norm(sig[closed], axis=-1)
            # Inside, where ∇f may vanish (the centre of the cap), |f| bounds the scale: -1 there.
            out[closed] = loc.f / np.maximum(scale, np.abs(loc.f))
        return out.reshape(state.shape)

    def _flat_forces(self, state):
        sig = self.force(state).reshape(-1, 3)
        q = np.stack((state.kappa.ravel(), state.beta.ravel()), axis=-1)
        return sig, q, sig[:, 2] > 0

    def _increments(self, state, increments) -> np.ndarray:
        du = check_finite("increments", increments)
        if du.shape != state.shape + (3,):
            try:
                du = np.broadcast_to(du, state.shape + (3,))
            except ValueError:
                raise FrictionRulesError(f"increments must have shape {state.shape + (3,)} "
                                         f"(δt1, δt2, δn per contact), got {du.shape}") from None
        return du

    def kernel(self):
        """The compiled kernel used for this model's law, or None (generic NumPy path)."""
        from ..laws.coulomb import Coulomb
        from ..laws.orthotropic import EllipticOrthotropic
        if self.hardening is None and type(self.law) in (Coulomb, EllipticOrthotropic, EllipsoidCap):
            return type(self.law).__name__
        return None

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
            Use the compiled kernel where there is one (default); False forces the generic path.

        Returns
        -------
        UpdateResult
        """
        du = self._increments(state, increments).reshape(-1, 3)
        e = state.elastic.reshape(-1, 3)
        p = state.plastic.reshape(-1, 3)
        q = np.stack((state.kappa.ravel(), state.beta.ravel()), axis=-1)
        name = self.kernel() if compiled else None
        if name is not None:
            from ._kernels import run_kernel
            e1, p1, q1, sig, dlam, status, diss = run_kernel(self, name, e, p, q, du)
            dsig = None
            failed = np.flatnonzero(status < 0)
            if failed.size:
                # The compiled cap iteration failed there: the generic path substeps.
                g = _generic_step(self._surface(), e[failed], p[failed], q[failed], du[failed], self._Dv, 0)
                e1[failed], p1[failed], q1[failed], sig[failed], dlam[failed], status[failed], diss[failed] = g[:7]
        else:
            e1, p1, q1, sig, dlam, status, diss, dsig = _generic_step(self._surface(), e, p, q, du, self._Dv, 0)
        tan = None
        if tangent:
            tan = self._tangent(sig, q1, dlam, status, dsig).reshape(state.shape + (3, 3))
        return _result(state.shape, e1, p1, q1, sig, dlam, status, diss, tan)

    def _tangent(self, sig, q, dlam, status, dsig):
        """Consistent tangent: ``(dσ/dσ_trial) E`` where closed, 0 where open."""
        from .integrate import tangent_at
        n = len(sig)
        if dsig is None:
            dsig = np.zeros((n, 3, 3))
            dsig[status == ELASTIC] = np.eye(3)
            pl = status == PLASTIC
            if pl.any():
                dsig[pl] = tangent_at(self._surface(), sig[pl], q[pl], dlam[pl], self._Dv)
        return np.where((status == OPEN)[:, None, None], 0.0, dsig @ self.elastic_tangent)

    def rate_update(self, state: ContactState, increments) -> UpdateResult:
        """One explicit step of the rate form (4.7), (4.10)–(4.11), for verification.

        Forward Euler on the elastic-plastic rate equations with the elastic part of a step
        that reaches the surface split off; no return to the surface (the drift is O(step)).
        """
        from .integrate import rate_step
        du = self._increments(state, increments).reshape(-1, 3)
        e = state.elastic.reshape(-1, 3)
        p = state.plastic.reshape(-1, 3)
        q = np.stack((state.kappa.ravel(), state.beta.ravel()), axis=-1)
        sig0 = self.force(state).reshape(-1, 3)
        e_tr = e + du
        sig = _trial(e_tr, self._Dv)
        open_ = sig[:, 2] <= 0
        q1, dlam = q.copy(), np.zeros(len(e))
        c = ~open_
        if c.any():
            s, qq, dl = rate_step(self._surface(), sig0[c], q[c], (du @ self.elastic_tangent)[c], self._Dv)
            sig[c], q1[c], dlam[c] = s, qq, dl
        status = np.where(open_, OPEN, np.where(dlam > 0, PLASTIC, ELASTIC))
        e1, p1, sig, diss = _finish(e_tr, p, sig, status, self._Dv)
        return _result(state.shape, e1, p1, q1, sig, dlam, status, diss, None)


def _result(shape, e1, p1, q1, sig, dlam, status, diss, tan):
    new = ContactState(e1.reshape(shape + (3,)), p1.reshape(shape + (3,)), q1[:, 0].reshape(shape),
                       q1[:, 1].reshape(shape))
    return UpdateResult(new, sig.reshape(shape + (3,)), dlam.reshape(shape), status.reshape(shape),
                        diss.reshape(shape), tan)


def _trial(e, Dv):
    """Elastic law (4.2): ``(T1, T2, N) = (kt δt1ᵉ, kt δt2ᵉ, -kn δnᵉ)``."""
    return np.stack((Dv[0] * e[:, 0], Dv[1] * e[:, 1], -Dv[2] * e[:, 2]), axis=-1)


def _finish(e_tr, p, sig, status, Dv):
    """Elastic and plastic parts consistent with the end forces, open contacts, dissipation.

    Plastic rows: ``δᵉ = E⁻¹σ`` and ``Δδᵖ = δᵉ_trial - δᵉ``; open rows: ``δtᵉ = 0`` (free
    tangential motion goes to ``δtᵖ``), the normal gap ``δnᵉ >= 0`` stays elastic (after a
    return to the apex, ``δnᵉ = 0``: the contact is just closed, without force).
    """
    open_ = status == OPEN
    sig = np.where(open_[:, None], 0.0, sig)
    e1 = np.stack((sig[:, 0] / Dv[0], sig[:, 1] / Dv[1], -sig[:, 2] / Dv[2]), axis=-1)
    e1[open_, 2] = np.maximum(e_tr[open_, 2], 0.0)
    e1 = np.where((status == ELASTIC)[:, None], e_tr, e1)
    d = e_tr - e1
    p1 = p + d
    diss = np.where(status == PLASTIC, sig[:, 0] * d[:, 0] + sig[:, 1] * d[:, 1] - sig[:, 2] * d[:, 2], 0.0)
    return e1, p1, sig, diss


def _generic_step(surface, e, p, q, du, Dv, depth):
    """Backward-Euler step over a batch with the generic return mapping; substeps on failure."""
    from .integrate import _TOL, return_map
    n = len(e)
    e_tr = e + du
    sig = _trial(e_tr, Dv)
    q1 = q.copy()
    dlam = np.zeros(n)
    status = np.where(sig[:, 2] <= 0, OPEN, ELASTIC)
    dsig = np.where((status == OPEN)[:, None, None], 0.0, np.eye(3))
    closed = np.flatnonzero(status != OPEN)
    failed = closed[:0]
    if closed.size:
        f = surface.limit(sig[closed], q[closed])
        pl = closed[f > 0]
        if pl.size:
            rr = return_map(surface, sig[pl], q[pl], Dv)
            ok = pl[rr.converged]
            sig[ok], q1[ok], dlam[ok] = rr.sigma[rr.converged], rr.q[rr.converged], rr.dlam[rr.converged]
            dsig[ok] = rr.dsigma_dtrial[rr.converged]
            status[ok] = PLASTIC
            failed = pl[~rr.converged]
            # A return that would pass the apex of a cone ends there: zero force, the whole
            # elastic displacement turned plastic, κ grown by its tangential part (4.5). So does
            # one that ends at forces zero to the Newton tolerance of the trial.
            tiny = np.linalg.norm(sig[ok], axis=-1) <= _TOL * np.linalg.norm(_trial(e_tr[ok], Dv), axis=-1)
            apex = ok[(sig[ok, 2] < 0) | tiny]
            if failed.size and hasattr(surface, "apex_region"):
                # In the apex region, or with a trial N that is zero to the tolerance.
                at_apex = (surface.apex_region(sig[failed], q[failed], Dv)
                           | (sig[failed, 2] <= _TOL * np.linalg.norm(sig[failed], axis=-1)))
                apex, failed = np.concatenate((apex, failed[at_apex])), failed[~at_apex]
            status[apex] = OPEN
            q1[apex, 0] = q[apex, 0] + np.hypot(e_tr[apex, 0], e_tr[apex, 1])
    e1, p1, sig, diss = _finish(e_tr, p, sig, status, Dv)
    if failed.size:
        if depth >= _MAX_SUBSTEP_DEPTH:
            raise FrictionRulesError(
                f"the return mapping did not converge for {failed.size} contact(s) (first: index "
                f"{int(failed[0])}, increment {du[failed[0]].tolist()}) even after {2**depth} substeps")
        half = 0.5 * du[failed]
        a = _generic_step(surface, e[failed], p[failed], q[failed], half, Dv, depth + 1)
        b = _generic_step(surface, a[0], a[1], a[2], half, Dv, depth + 1)
        e1[failed], p1[failed], q1[failed], sig[failed] = b[:4]
        status[failed] = np.where((a[5] == PLASTIC) & (b[5] == ELASTIC), PLASTIC, b[5])
        dlam[failed] = a[4] + b[4]
        diss[failed] = a[6] + b[6]
        dsig[failed] = b[7]
    return e1, p1, q1, sig, dlam, status, diss, dsig
