r"""The history of a batch of contacts, :class:`ContactState`, and the outcome of one update,
:class:`UpdateResult`.

Displacements ``δ = (δt1, δt2, δn)`` with ``δn`` positive on **opening**; forces
``(T1, T2, N)`` with ``N > 0`` in compression (``docs/conventions.md``). The additive split
(4.1) is ``δ = δᵉ + δᵖ``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._returnspec import ELASTIC, OPEN, PLASTIC  # the status codes of an update, per contact
from ..errors import FrictionRulesError, check_finite
from ..laws import LawState

__all__ = ["ContactState", "UpdateResult", "ELASTIC", "PLASTIC", "OPEN"]



def _frozen(a) -> np.ndarray:
    a = np.array(a, dtype=float)
    a.flags.writeable = False
    return a


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
        Accumulated tangential plastic slip κ (4.5), ``>= 0``: tracked for every law; a law
        with the internal variable ``kappa`` (slip hardening, the cap (4.9)) hardens with it.
    beta : (...)
        Fraction of real contact area β (4.5), ``0 < β < 1``; it evolves only for a law with
        the internal variable ``beta`` (the cap) and is carried unchanged otherwise.
    internal : LawState, optional
        The law's other internal variables (a user law's own), shape ``(...)``.
    """

    elastic: np.ndarray
    plastic: np.ndarray
    kappa: np.ndarray = 0.0
    beta: np.ndarray = 0.5
    internal: LawState | None = None

    def __post_init__(self):
        u = check_finite("elastic", self.elastic)
        if u.ndim == 0 or u.shape[-1] != 3:
            raise FrictionRulesError(f"elastic must have shape (..., 3), got {u.shape}")
        shape = u.shape[:-1]
        p = check_finite("plastic", self.plastic)
        if p.shape != u.shape:
            raise FrictionRulesError(f"plastic must have shape {u.shape}, got {p.shape}")
        try:
            kappa = np.broadcast_to(check_finite("kappa", self.kappa), shape)
            beta = np.broadcast_to(check_finite("beta", self.beta), shape)
        except ValueError:
            raise FrictionRulesError(f"kappa and beta must broadcast to the contacts' shape {shape}, "
                                     f"got {np.shape(self.kappa)} and {np.shape(self.beta)}") from None
        if np.any(kappa < 0):
            raise FrictionRulesError("kappa violates kappa >= 0 (accumulated slip)")
        if np.any((beta <= 0) | (beta >= 1)):
            raise FrictionRulesError("beta violates 0 < beta < 1 (fraction of real contact area)")
        internal = self.internal
        if internal is None:
            internal = LawState.empty(shape)
        elif not isinstance(internal, LawState) or internal.shape != shape:
            raise FrictionRulesError(f"internal = {internal!r} violates: a LawState of shape {shape}")
        for name, value in (("elastic", u), ("plastic", p), ("kappa", kappa), ("beta", beta)):
            object.__setattr__(self, name, _frozen(value))
        object.__setattr__(self, "internal", internal)

    @property
    def displacement(self) -> np.ndarray:
        """Total displacement ``δ = δᵉ + δᵖ`` (4.1), shape ``(..., 3)``."""
        return self.elastic + self.plastic

    @property
    def shape(self) -> tuple[int, ...]:
        return self.kappa.shape

    def variable(self, name: str) -> np.ndarray:
        """The internal variable ``name`` (``kappa``, ``beta`` or one of :attr:`internal`)."""
        if name in ("kappa", "beta"):
            return getattr(self, name)
        if name in self.internal.names:
            return getattr(self.internal, name)
        raise FrictionRulesError(f"the contact state has no internal variable {name!r} (it has "
                                 f"kappa, beta{''.join(', ' + n for n in self.internal.names)})")


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
