r"""One backward-Euler step over a batch of contacts with the generic return mapping.

Arrays are rows per contact: elastic and plastic displacements ``e, p`` ``(n, 3)``, the law's
internal variables ``q`` ``(n, nq)``, increments ``du`` ``(n, 3)``; ``Dv = (kt, kt, kn)``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._returnspec import ELASTIC, MAX_SUBSTEP_DEPTH, OPEN, PLASTIC, TOL
from ..errors import FrictionRulesError


@dataclass(frozen=True, eq=False)
class Step:
    """Rows of a step's outcome: ``e, p, q, force, dlam, status, dissipation``, the increment of
    accumulated tangential plastic slip ``slip`` (4.5) and the tangent block ``dsigma`` =
    dσ/dσ_trial ``(n, 3, 3)`` (None when not computed)."""

    e: np.ndarray
    p: np.ndarray
    q: np.ndarray
    force: np.ndarray
    dlam: np.ndarray
    status: np.ndarray
    dissipation: np.ndarray
    slip: np.ndarray
    dsigma: np.ndarray | None = None


def trial(e, Dv):
    """Elastic law (4.2): ``(T1, T2, N) = (kt δt1ᵉ, kt δt2ᵉ, -kn δnᵉ)``."""
    return np.stack((Dv[0] * e[:, 0], Dv[1] * e[:, 1], -Dv[2] * e[:, 2]), axis=-1)


def finish(e_tr, p, sig, status, Dv):
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


def slip_increment(e_tr, e1, status):
    """Length of the tangential plastic slip of a step: ``|Δδtᵖ|`` where plastic, the whole
    tangential elastic displacement after a return to the apex (status open, ``e1`` zero), 0
    where elastic or open (free tangential motion of an open contact is not slip)."""
    d = np.hypot(e_tr[:, 0] - e1[:, 0], e_tr[:, 1] - e1[:, 1])
    return np.where(status == PLASTIC, d, 0.0)


def generic_step(surface, e, p, q, du, Dv, kappa_index, depth=0) -> Step:
    """Backward-Euler step over a batch with the generic return mapping; substeps on failure.

    ``kappa_index`` is the column of ``q`` holding the accumulated slip κ (None if the law has
    none): a return that ends at the apex of a cone turns the whole tangential elastic
    displacement into slip, and κ grows by its length (4.5).
    """
    from .integrate import return_map
    n = len(e)
    e_tr = e + du
    sig = trial(e_tr, Dv)
    q1 = q.copy()
    dlam = np.zeros(n)
    status = np.where(sig[:, 2] <= 0, OPEN, ELASTIC)
    dsig = np.where((status == OPEN)[:, None, None], 0.0, np.eye(3))
    closed = np.flatnonzero(status != OPEN)
    failed = closed[:0]
    apex_slip = np.zeros(n)
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
            # elastic displacement turned plastic. So does one that ends at forces zero to the
            # Newton tolerance of the trial.
            tiny = np.linalg.norm(sig[ok], axis=-1) <= TOL * np.linalg.norm(trial(e_tr[ok], Dv), axis=-1)
            apex = ok[(sig[ok, 2] < 0) | tiny]
            if failed.size:
                # In the apex region, or with a trial N that is zero to the tolerance.
                at_apex = (surface.apex_region(sig[failed], q[failed], Dv)
                           | (sig[failed, 2] <= TOL * np.linalg.norm(sig[failed], axis=-1)))
                apex, failed = np.concatenate((apex, failed[at_apex])), failed[~at_apex]
            status[apex] = OPEN
            q1[apex] = q[apex]
            apex_slip[apex] = np.hypot(e_tr[apex, 0], e_tr[apex, 1])
            if kappa_index is not None:
                q1[apex, kappa_index] += apex_slip[apex]
    e1, p1, sig, diss = finish(e_tr, p, sig, status, Dv)
    out = Step(e1, p1, q1, sig, dlam, status, diss, slip_increment(e_tr, e1, status) + apex_slip, dsig)
    if failed.size:
        if depth >= MAX_SUBSTEP_DEPTH:
            raise FrictionRulesError(
                f"the return mapping did not converge for {failed.size} contact(s) (first: index "
                f"{int(failed[0])}, increment {du[failed[0]].tolist()}) even after {2**depth} substeps")
        half = 0.5 * du[failed]
        a = generic_step(surface, e[failed], p[failed], q[failed], half, Dv, kappa_index, depth + 1)
        b = generic_step(surface, a.e, a.p, a.q, half, Dv, kappa_index, depth + 1)
        for name in ("e", "p", "q", "force", "dsigma"):
            getattr(out, name)[failed] = getattr(b, name)
        out.slip[failed] = a.slip + b.slip
        out.status[failed] = np.where((a.status == PLASTIC) & (b.status == ELASTIC), PLASTIC, b.status)
        out.dlam[failed] = a.dlam + b.dlam
        out.dissipation[failed] = a.dissipation + b.dissipation
    return out
