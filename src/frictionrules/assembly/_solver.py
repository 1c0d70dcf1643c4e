r"""One quasi-static increment of an assembly: equilibrium of every grain with the contact laws,
solved implicitly by Newton's method.

Unknowns: the grains' translations ``Δw`` (fluctuations about the homogeneous motion; grain 0
fixed against the rigid translation), their rotations ``Δθ`` (about z for disks) and the free
(stress-controlled) components of the cell's symmetric displacement gradient ``ΔE``. The
local displacement of contact ``c`` (grains ``i``, ``j``, frame rows ``Q = (t1, t2, n)``,
branch ``l``) is linear in them,

.. math:: \Delta u_c = Q\,\bigl(\Delta w_j - \Delta w_i - (r_i\Delta\theta_i + r_j\Delta\theta_j)
          \times n + \Delta E\, l\bigr) = B_c\,\Delta x,

and with the generalized force ``P = (T1, T2, -N)`` conjugate to it the equations are the
principle of virtual work, ``Bᵀ P(u) + f = 0``: the force and moment of every grain and, for a
stress-controlled component ``k`` (basis ``G_k``), :math:`V(\sigma^* - \sigma):G_k = 0` with
the compression-positive stress :math:`\sigma = \frac1V\sum_c f_c\otimes l_c`, ``f = -Qᵀ P``
the force of ``i`` on ``j`` (``docs/assembly.md``). The Jacobian is ``Bᵀ S B`` with the
consistent tangents ``S = diag(1, 1, -1) ∂(T1, T2, N)/∂u`` of ``ContactModel.update``, one
batched call per contact model. Mechanisms (modes of the Jacobian without stiffness), changes of
a contact's status on the way and rattlers are handled in :mod:`._newton`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..contact.state import OPEN
from ._contacts import ContactSet, branches, embed
from ._newton import along_mechanism, line_search, newton_direction, rattlers

__all__ = ["Kinematics", "Outcome", "solve_increment", "components", "stress_of"]

#: Above this many unknowns the Jacobian is sparse (SciPy).
DENSE_LIMIT = 400
#: Newton iterations that change no contact's status without halving the merit after which
#: an increment is given up.
STALL = 6
_SIGN = np.array([1.0, 1.0, -1.0])


def components(dim: int) -> tuple[tuple[int, int], ...]:
    """The symmetric components of the cell strain, in the order of the control arrays."""
    if dim == 2:
        return ((0, 0), (1, 1), (0, 1))
    return ((0, 0), (1, 1), (2, 2), (1, 2), (0, 2), (0, 1))


#: The cell of a triaxial test's shearing stage: its shear strains held or its shear stresses.
CELLS = ("rectangular", "flexible")


def triaxial_free(kind: str, dim: int, cell: str) -> np.ndarray:
    """The stress-controlled components of a triaxial test's shearing stage (over
    :func:`components`): the lateral normal stresses (plane strain: the out-of-plane normal
    strain held instead), the axial strain driven. ``cell`` "rectangular": the cell's shear
    strains held at zero, as between rigid smooth platens (and YADE's ``PeriTriaxController``);
    "flexible": its shear stresses held at zero instead (a flexible membrane all round)."""
    comps = components(dim)
    free = np.array([a == b or cell == "flexible" for a, b in comps])
    free[comps.index((1, 1) if dim == 2 else (2, 2))] = False
    if kind == "plane_strain":
        free[comps.index((1, 1))] = False
    return free


def basis(dim: int) -> np.ndarray:
    """``G_k`` (ncomp, 3, 3): ``e_a⊗e_a`` on the diagonal, ``e_a⊗e_b + e_b⊗e_a`` off it, so that
    ``ΔE = Σ_k e_k G_k`` has the tensor components ``e_k``."""
    comps = components(dim)
    g = np.zeros((len(comps), 3, 3))
    for k, (a, b) in enumerate(comps):
        g[k, a, b] = 1.0
        g[k, b, a] = 1.0
    return g


@dataclass(frozen=True, eq=False)
class Kinematics:
    """The linear map ``B`` from the unknowns to the contacts' local displacements."""

    B: object            # (3m, ndof) dense array or CSR matrix
    ndof_grains: int
    ncomp: int
    branch: np.ndarray   # (m, 3)
    volume: float

    def columns(self, free: np.ndarray, fixed: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Columns of the unknowns and of the prescribed cell components.

        The unknowns: the translations and rotations of the grains not ``fixed`` (n,) bool,
        but the translation of the first of them (it holds the sample against a rigid
        translation), and the free cell components.
        """
        d, g, n, nr = self.dim, self.ndof_grains, self.grains, self.rotations
        moving = np.flatnonzero(~fixed)
        trans = (moving[1:, None] * d + np.arange(d)).ravel()
        rot = (n * d + moving[:, None] * nr + np.arange(nr)).ravel()
        cell = g + np.arange(self.ncomp)
        return np.concatenate((trans, rot, cell[free])), cell[~free]

    @property
    def dim(self) -> int:
        return 2 if self.ncomp == 3 else 3

    @property
    def rotations(self) -> int:
        """Rotations per grain (1 for disks, 3 for spheres)."""
        return 1 if self.dim == 2 else 3

    @property
    def grains(self) -> int:
        return self.ndof_grains // (self.dim + self.rotations)


def kinematics(positions, radii, cell, contacts: ContactSet) -> Kinematics:
    """``B`` at the geometry of the start of the increment."""
    n, d = positions.shape
    m = contacts.size
    nr = 1 if d == 2 else 3
    ncomp = len(components(d))
    Q = contacts.frames
    l3 = embed(branches(positions, cell, contacts.i, contacts.j, contacts.shift))
    nrm = Q[:, 2, :]
    i, j = contacts.i, contacts.j
    Bw = Q[:, :, :d]
    if d == 2:
        Br = np.einsum("mab,mb->ma", Q, np.cross(nrm, np.array([0.0, 0.0, 1.0])))[:, :, None]
    else:
        skew = np.zeros((m, 3, 3))
        skew[:, 0, 1], skew[:, 0, 2], skew[:, 1, 2] = -nrm[:, 2], nrm[:, 1], -nrm[:, 0]
        skew -= skew.transpose(0, 2, 1)
        Br = Q @ skew  # Q [n]x : θ -> Q (n × θ)
    G = basis(d)
    Bc = np.einsum("mab,kbc,mc->mak", Q, G, l3)
    vals = np.concatenate((-Bw, Bw, radii[i, None, None] * Br, radii[j, None, None] * Br, Bc), axis=2)
    ar_d, ar_r = np.arange(d), np.arange(nr)
    cols = np.concatenate((i[:, None] * d + ar_d, j[:, None] * d + ar_d,
                           n * d + i[:, None] * nr + ar_r, n * d + j[:, None] * nr + ar_r,
                           np.broadcast_to(n * (d + nr) + np.arange(ncomp), (m, ncomp))), axis=1)
    rows = np.broadcast_to(3 * np.arange(m)[:, None, None] + np.arange(3)[None, :, None], vals.shape)
    cols = np.broadcast_to(cols[:, None, :], vals.shape)
    ndof = n * (d + nr) + ncomp
    if ndof <= DENSE_LIMIT:
        B = np.zeros((3 * m, ndof))
        np.add.at(B, (rows.ravel(), cols.ravel()), vals.ravel())
    else:
        from .._optional import require
        sparse = require("scipy.sparse", purpose="assemblies with more than a few grains")
        B = sparse.coo_matrix((vals.ravel(), (rows.ravel(), cols.ravel())), shape=(3 * m, ndof)).tocsr()
    volume = float(np.linalg.det(cell))
    return Kinematics(B, n * (d + nr), ncomp, l3, volume)


def stress_of(force: np.ndarray, frames: np.ndarray, branch: np.ndarray, volume: float,
              dim: int) -> np.ndarray:
    r"""Compression-positive stress :math:`\sigma = \frac1V\sum_c f_c\otimes l_c` (symmetrized),
    ``f = N n - T1 t1 - T2 t2`` the force of ``i`` on ``j``; (dim, dim)."""
    f = -np.einsum("ma,mab->mb", force * _SIGN, frames)
    s = np.einsum("ma,mb->ab", f, branch) / volume
    s = 0.5 * (s + s.T)
    return s[:dim, :dim]


@dataclass(frozen=True, eq=False)
class Outcome:
    """The end of one increment (converged or not)."""

    converged: bool
    iterations: int
    residual: float
    states: tuple
    force: np.ndarray        # (m, 3) (T1, T2, N)
    status: np.ndarray       # (m,)
    displacement: np.ndarray  # (m, 3) local increments Δu
    grain_translation: np.ndarray  # (n, d) fluctuation increments
    grain_rotation: np.ndarray     # (n, nr)
    strain_increment: np.ndarray   # (dim, dim) ΔE (tension positive displacement gradient)
    stress: np.ndarray       # (dim, dim) compression positive
    contact_work: float      # Σ P·Δu
    boundary_work: float     # -V σ:ΔE


@dataclass(frozen=True, eq=False)
class _Eval:
    u: np.ndarray
    force: np.ndarray
    tangent: np.ndarray
    status: np.ndarray
    states: tuple
    R: np.ndarray
    residual: float
    merit: float


def _elastic_tangents(contacts: ContactSet, status: np.ndarray) -> np.ndarray:
    """The elastic tangents of the closed contacts (0 where open): the stiffness a mode of the
    Jacobian is measured against to tell a mechanism (:func:`._newton.newton_direction`)."""
    out = np.zeros((contacts.size, 3, 3))
    for g, model in enumerate(contacts.models):
        idx = contacts.members(g)
        out[idx] = np.where((status[idx] != OPEN)[:, None, None], model.elastic_tangent, 0.0)
    return out


def _update_all(contacts: ContactSet, u: np.ndarray, predictor: bool, gap: float = 0.0):
    m = contacts.size
    force, tangent = np.zeros((m, 3)), np.zeros((m, 3, 3))
    status = np.zeros(m, dtype=np.int64)
    states = []
    for g, model in enumerate(contacts.models):
        idx = contacts.members(g)
        res = model.update(contacts.states[g], u[idx], tangent=True)
        force[idx], status[idx] = res.force, res.status
        tan = res.tangent
        if predictor:
            # Start of the increment: contacts closed (or touching within the tolerance) at its
            # start stiffen elastically, so that a sample at zero force has a stiffness.
            touching = contacts.states[g].elastic[:, 2] <= gap
            tan = np.where(touching[:, None, None], model.elastic_tangent, tan)
        tangent[idx] = tan
        states.append(res.state)
    return force, tangent, status, tuple(states)


def solve_increment(positions, radii, cell, contacts: ContactSet, free: np.ndarray,
                    prescribed: np.ndarray, target: np.ndarray, *, rtol: float = 1e-10,
                    max_iterations: int = 40, gap: float = 0.0, max_move: float = np.inf) -> Outcome:
    """Solve one increment by Newton's method.

    Parameters
    ----------
    positions, radii, cell, contacts
        The geometry and the contacts at the start of the increment.
    free : (ncomp,) bool
        True where the cell component is stress-controlled (an unknown).
    prescribed : (ncomp,)
        ``ΔE_k`` of the strain-controlled components (tension positive; ignored where free).
    target : (ncomp,)
        Compression-positive stress ``σ*_ab`` at the end of the increment where free.
    gap : float
        Contacts open by at most this gap at the start stiffen elastically in the first
        Newton direction (the contact tolerance of the assembly).
    max_move : float
        Largest change of a contact displacement in one Newton iteration (half the skin of the
        contact set).
    """
    n, d = positions.shape
    nr = 1 if d == 2 else 3
    kin = kinematics(positions, radii, cell, contacts)
    mult = np.array([1.0 if a == b else 2.0 for a, b in components(d)])
    fixed = rattlers(n, contacts.i, contacts.j, contacts.per_contact("elastic")[:, 2] <= gap)
    vec = np.zeros(kin.ndof_grains + kin.ncomp)   # every grain and cell unknown
    it = 0
    while True:
        ev, vec, passes = _newton(kin, contacts, free, prescribed, target * mult, fixed, vec, rtol,
                                  max_iterations, gap, max_move, r_mean=float(np.mean(radii)))
        it += passes
        converged = bool(np.isfinite(ev.residual) and ev.residual <= rtol)
        # A grain left out as a rattler must carry no force at the solution, else it takes
        # part: solve again with it.
        loaded = fixed & np.isin(np.arange(n), np.concatenate(
            (contacts.i[ev.status != OPEN], contacts.j[ev.status != OPEN])))
        if not (converged and loaded.any()):
            break
        fixed &= ~loaded
    u, force, status, states, residual = ev.u, ev.force, ev.status, ev.states, ev.residual
    # the motion of the increment
    g = kin.ndof_grains
    dw = vec[:n * d].reshape(n, d)
    dtheta = vec[n * d:g].reshape(n, nr)
    e = np.where(free, vec[g:], prescribed)
    dE = np.einsum("k,kab->ab", e, basis(d))[:d, :d]
    sigma = stress_of(force, contacts.frames, kin.branch, kin.volume, d)
    contact_work = float(np.sum(force * _SIGN * u))
    boundary_work = float(-kin.volume * np.sum(sigma * dE))
    return Outcome(converged, it, residual, states, force, status, u, dw, dtheta, dE, sigma,
                   contact_work, boundary_work)


def _newton(kin, contacts, free, prescribed, target, fixed, vec, rtol, max_iterations, gap,
            max_move, r_mean):
    """Newton's iteration from the unknowns ``vec`` with the grains ``fixed`` left out;
    returns ``(last evaluation, unknowns, iterations)``.

    ``target`` is ``σ*_k`` times the multiplicity of the component (2 off the diagonal).
    """
    n, d = kin.grains, kin.dim
    m = contacts.size
    cols_free, cols_pres = kin.columns(free, fixed)
    B = kin.B
    dense = isinstance(B, np.ndarray)
    B_free, B_pres = B[:, cols_free], B[:, cols_pres]
    u0 = B_pres @ prescribed[~free]
    nfree = len(cols_free)
    ncell = int(free.sum())
    # -V σ*:G_k of the stress-controlled components (the "external" part of the residual)
    f_ext = np.zeros(nfree)
    if ncell:
        f_ext[-ncell:] = kin.volume * target[free]
    row_kind = np.where(cols_free < n * d, 0, np.where(cols_free < kin.ndof_grains, 1, 2))
    lnorm = np.linalg.norm(kin.branch, axis=1)
    start_force = contacts.force if contacts.force is not None else np.zeros((m, 3))
    f0 = max(float(np.abs(start_force).max()) if m else 0.0,
             float(np.abs(f_ext).max()) / max(float(lnorm.sum()), 1e-300) if ncell else 0.0)
    f0 = f0 if f0 > 0 else 1.0
    weight = 1.0 / np.array([f0, f0 * r_mean, f0 * max(float(lnorm.sum()), 1e-300)])[row_kind]

    def evaluate(x, predictor=False):
        u = (u0 + B_free @ x).reshape(m, 3)
        force, tangent, status, states = _update_all(contacts, u, predictor, gap)
        R = B_free.T @ (force * _SIGN).ravel() + f_ext
        fmax = float(np.abs(force).max()) if m else 0.0
        virial = float(np.sum(np.abs(force).max(axis=1) * lnorm)) if m else 0.0
        ext = float(np.abs(f_ext).max()) if ncell else 0.0
        scale = np.array([fmax, fmax * r_mean, max(virial, ext)])
        scale = np.where(scale > 0, scale, 1.0)[row_kind]
        residual = float(np.max(np.abs(R) / scale)) if nfree else 0.0
        merit = float(np.linalg.norm(R * weight))
        return _Eval(u, force, tangent, status, states, R, residual, merit)

    def trust(dx):
        # no contact moves by more than half the skin in one iteration (a mechanism of the
        # linearized problem would throw grains through each other)
        du_max = float(np.abs(B_free @ dx).max()) if m else 0.0
        return dx * (max_move / du_max) if du_max > max_move else dx

    x = vec[cols_free]
    ev = evaluate(x, predictor=not x.any())
    it, best, stalled = 0, ev.merit, 0
    while np.isfinite(ev.residual) and ev.residual > rtol and it < max_iterations:
        it += 1
        # Newton's step with the consistent tangents, without its part on the mechanisms;
        # where the residual is mostly the load on a mechanism, the mechanism is moved to
        # its next change of status instead. Where the step must be damped (contacts that
        # start or stop sliding, open or close on the way), the step of the elastic tangents
        # is tried as well and the better of the two taken: it lets many contacts change
        # status in one iteration.
        elastic = _SIGN[None, :, None] * _elastic_tangents(contacts, ev.status)
        split = newton_direction(B_free, _SIGN[None, :, None] * ev.tangent, elastic, ev.R, dense)
        if split is None:
            break
        dx, z, load = split
        if np.linalg.norm(load * weight) >= 0.5 * ev.merit:
            step = along_mechanism(evaluate, B_free, x, ev, z, max_move, rtol)
        else:
            step = line_search(evaluate, x, trust(dx), ev, rtol)
            if step is None or (step[2] < 1.0 and step[1].residual > rtol):
                split = newton_direction(B_free, elastic, elastic, ev.R, dense)
                other = None if split is None else line_search(evaluate, x, trust(split[0]), ev,
                                                               rtol)
                if other is not None and (step is None or other[1].merit < step[1].merit):
                    step = other
        if step is None:
            break
        changed = np.any(step[1].status != ev.status)
        x, ev = step[0], step[1]
        # On a fixed set of sticking, sliding and open contacts Newton converges
        # quadratically: a merit that has not halved in STALL iterations that change no
        # status will not reach the tolerance (a limit point); the caller cuts the increment.
        if ev.merit < 0.5 * best:
            best, stalled = ev.merit, 0
        elif not changed:
            stalled += 1
            if stalled >= STALL:
                break
    vec = np.zeros_like(vec)
    vec[cols_free] = x
    vec[cols_pres] = prescribed[~free]
    return ev, vec, it


def move(positions, cell, out: Outcome) -> tuple[np.ndarray, np.ndarray]:
    """Positions and cell at the end of an increment: ``x ← x + ΔE x + Δw``, ``H ← (I + ΔE) H``."""
    dE = out.strain_increment
    return positions + positions @ dE.T + out.grain_translation, cell + dE @ cell
