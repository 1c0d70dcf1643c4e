r"""Displacement control for a grain sliding over a layer: exact and incremental.

Each contact is the local law in the contact's frame (:class:`GrainContact`); the geometry
moves the frame. Two independent computations:

* :func:`exact_path` — geometry and equilibrium. The centre is kept on the contact surface
  (:mod:`.geometry`); the grain velocity :math:`V` is the horizontal direction of the
  trajectory lifted onto the tangent plane(s) of the sliding contact(s), :math:`V\cdot n_k = 0`;
  each sliding contact passes the force :math:`N_k a_k` to its layer grain, :math:`a_k` the
  local inverse relation at the slip of ``V`` in the contact's frame
  (:func:`._contact.carried_force`; :math:`a = \mu\hat V - n` for local Coulomb friction), and
  equilibrium with the horizontal force ``T`` and the vertical load ``Q``,

  .. math:: (T_x, T_y, -Q) = \sum_k N_k a_k,

  gives ``T`` and the ``N_k``. With two sliding contacts (a ridge) ``T`` is taken along the
  motion.
* :func:`incremental_path` — the paper's rate formulation: the limit condition and potential of
  the contact with its moving frame (3.1), (3.2), the flow rule (3.3), the kinematics
  (3.4)/(3.6)/(3.12) (as re-derived, see ``docs/errata.md``) and the consistency condition
  (3.5), integrated step by step (explicit Euler, order 1, or Heun, order 2). The derivatives
  of the local law come from its symbolic form, those of the frame from :mod:`._frame`
  (:func:`._contact.contact_terms`).

Kinematics of one contact (the centre moves on the sphere of radius ``d`` about the layer grain,
:math:`u = c - d\sin\alpha\, e_\psi`): the offset :math:`r = u - c` moves with the grain,
:math:`\dot r = V_h` (a cylinder's offset has no y part), which is

.. math:: \dot\alpha = -\frac{V\cdot e_\psi}{d\cos\alpha},\qquad
          \dot\psi = -\frac{V\cdot e_\psi^\perp}{d\sin\alpha}\ \text{(sphere)},\quad
          \dot\psi = 0\ \text{(cylinder)},

with :math:`e_\psi = (\cos\psi, \sin\psi)`, :math:`e_\psi^\perp = (-\sin\psi, \cos\psi)`. The
frame is differentiated in ``r`` directly, so the top of a layer grain (``alpha = 0``, where
``psi`` is undefined) is no singularity.
"""

from __future__ import annotations

import numpy as np

from ..errors import FrictionRulesError, check_vectors
from ._contact import (LOCK_TOL, carried_force, contact_terms, finite_terms, require_sliding_law,
                       slide)
from ._frame import angle_rates, frames, local_forces, offset_of_angles
from .geometry import active_contacts, angles
from .state import GrainState, PathResult

SCHEMES = ("euler", "heun")
#: A path's tangent changes direction (a corner) where its components change by more than this.
CORNER_TOL = 1e-12
#: Determinant below which the 3x3 equilibrium of a ridge (two contacts) is singular.
SINGULAR_TOL = 1e-12


def as_path(path) -> tuple[np.ndarray, np.ndarray]:
    """Validate a trajectory ``(n, 2)``, ``n >= 2``; return it and unit tangents per point
    (the direction of the segment leaving each point; the last point takes the incoming one)."""
    u = check_vectors("path", path, (2,))
    if u.ndim != 2 or len(u) < 2:
        raise FrictionRulesError(f"path must have shape (n, 2) with n >= 2, got shape {u.shape}")
    seg = np.diff(u, axis=0)
    length = np.hypot(seg[:, 0], seg[:, 1])
    if np.any(length == 0):
        bad = int(np.argmin(length))
        raise FrictionRulesError(f"path[{bad}] == path[{bad + 1}] = {tuple(u[bad])!r}: a zero-length "
                                 "step has no direction (constraint: consecutive points differ)")
    t = seg / length[:, None]
    return u, np.concatenate((t, t[-1:]), axis=0)


def state_at(model, position, direction) -> GrainState:
    """Configuration at ``position`` for a motion along ``direction`` (radians)."""
    p = check_vectors("position", position, (2,)).reshape(1, 2)
    t = np.array([[np.cos(direction), np.sin(direction)]])
    c = active_contacts(model.layer, p, t)
    k = int(c.count[0])
    a, s = angles(c.normal[0, :k], model.layer.cylindrical)
    return GrainState(p[0].copy(), float(c.height[0]), c.ids[0],
                      tuple(float(v) for v in a), tuple(float(v) for v in s))


def _locked(u, i, cid, law):
    return FrictionRulesError(
        f"path[{i}] = {tuple(u[i])!r}: contact {cid} locks for the motion along the path (the "
        f"local law {law!r} would need a tensile normal force to carry Q there, e.g. alpha + "
        "arctan(mu) >= pi/2 for Coulomb): no finite force slides the grain")


# ---- exact: geometry + equilibrium ----------------------------------------------------------
def exact_path(model, path, Q: float) -> PathResult:
    """Force, normal forces and height along ``path`` from the exact geometry and equilibrium."""
    require_sliding_law(model.law, f"{type(model).__name__}.displacement_path")
    u, t = as_path(path)
    c = active_contacts(model.layer, u, t)
    d = model.diameter
    axes = frames(d * c.normal[..., :2], d).axes                  # (n, 2, 3, 3)
    n1 = c.normal[:, 0]
    # grain velocity: horizontal direction lifted onto the tangent plane of the first contact
    V = np.concatenate((t, (-(n1[:, 0] * t[:, 0] + n1[:, 1] * t[:, 1]) / n1[:, 2])[:, None]), axis=1)
    V /= np.linalg.norm(V, axis=1)[:, None]
    carried = carried_force(model.law, axes, np.broadcast_to(V[:, None, :], axes.shape[:2] + (3,)))
    a = carried.force                                             # (n, 2, 3) per unit N_k
    force = np.zeros((len(u), 2))
    normal = np.zeros((len(u), 2))
    for i in range(len(u)):
        k = int(c.count[i])
        if np.any(carried.locked[i, :k]) or (k == 1 and a[i, 0, 2] >= -LOCK_TOL):
            raise _locked(u, i, c.ids[i], model.law)
        if k == 1:
            N = Q / -a[i, 0, 2]
            normal[i, 0] = N
            force[i] = N * a[i, 0, :2]
            continue
        A = np.array([[t[i, 0], -a[i, 0, 0], -a[i, 1, 0]],
                      [t[i, 1], -a[i, 0, 1], -a[i, 1, 1]],
                      [0.0, -a[i, 0, 2], -a[i, 1, 2]]])
        if abs(np.linalg.det(A)) < SINGULAR_TOL:
            raise _locked(u, i, c.ids[i], model.law)
        tau, Na, Nb = np.linalg.solve(A, [0.0, 0.0, Q])
        if min(Na, Nb) < 0:
            raise FrictionRulesError(
                f"path[{i}] = {tuple(u[i])!r}: no compressive pair of contact forces carries a "
                f"force along the motion on this ridge (N = {Na!r}, {Nb!r}; constraint N >= 0)")
        force[i] = tau * t[i]
        normal[i] = (Na, Nb)
    alpha, psi = angles(n1, model.layer.cylindrical)
    return PathResult(u, c.height, force, normal, alpha, psi, c.ids, "exact")


# ---- incremental: the rate relations ----------------------------------------------------------
def _offset(model, alpha, psi) -> np.ndarray:
    return offset_of_angles(alpha, 0.0 if model.layer.cylindrical else psi, model.diameter)


def _rates(model, y, t, Q):
    """d/ds of ``(alpha, psi, Tx, Ty, z)`` at unit speed along ``t``: the kinematics (3.6),
    (3.12), consistency (3.5) and the flow rule (3.3) kept along ``t``."""
    alpha, psi = y[0], y[1]
    d = model.diameter
    fr = frames(_offset(model, alpha, psi), d, rates=True)
    F = finite_terms(contact_terms(model.law, fr.axes, fr.rates, y[2:4], Q,
                                   model.layer.cylindrical), "incremental path")
    # consistency (3.5): f_T . dT + f_u . t = 0 (f_alpha alpha_dot + f_psi psi_dot)
    # flow direction (3.3): d/ds (g_Tx t_y - g_Ty t_x) = 0 on a straight segment
    A = np.array([F.f_T, t[1] * F.g_TT[0] - t[0] * F.g_TT[1]])
    b = -np.array([F.f_u @ t, t[1] * (F.g_Tu[0] @ t) - t[0] * (F.g_Tu[1] @ t)])
    dT = np.linalg.solve(A, b)
    da = angle_rates(alpha, psi, d, t, model.layer.cylindrical)
    # (3.3): V = lambda_dot dg/dF, lambda_dot = 1/|g_T| at unit horizontal speed
    return np.array([da[0], da[1], dT[0], dT[1], -F.g_Q / np.hypot(*F.g_T)])


def _start(model, alpha, psi, t, Q) -> np.ndarray:
    """The force on the limit curve of the contact ``(alpha, psi)`` that slides along ``t``
    (the inverse relation through the contact's frame, :func:`._contact.slide`)."""
    s = slide(model.law, frames(_offset(model, alpha, psi), model.diameter).axes, t, Q)
    if s.locked:
        raise FrictionRulesError(
            f"the contact (alpha = {alpha!r}, psi = {psi!r}) locks for motion along {tuple(t)!r}: "
            "no finite force slides the grain that way")
    return s.force


def incremental_path(model, path, scheme: str, Q: float) -> PathResult:
    """Integrate the rate relations along ``path`` (one sliding contact at a time).

    Between the points the configuration ``(alpha, psi)``, the force and the height follow
    :func:`_rates`; at a corner of the trajectory the force jumps to the point of the current
    limit curve that slides the new way (:func:`._contact.slide`); where another layer grain is
    reached (the envelope changes hands) the new contact closes, the old one opens, and the
    configuration of the new contact is taken from the geometry.
    """
    if scheme not in SCHEMES:
        raise FrictionRulesError(f"scheme = {scheme!r} violates scheme in {SCHEMES}")
    require_sliding_law(model.law, f"{type(model).__name__}.displacement_path")
    u, t = as_path(path)
    geo = active_contacts(model.layer, u, t, max_count=2)
    if geo.count.max() > 1:
        bad = int(np.argmax(geo.count > 1))
        raise FrictionRulesError(
            f"path[{bad}] = {tuple(u[bad])!r}: two contacts slide at once {geo.ids[bad]}; the "
            "incremental method follows one sliding contact (use method='exact')")
    n = len(u)
    out = np.zeros((n, 5))      # alpha, psi, Tx, Ty, z
    normal = np.zeros((n, 2))
    a0, p0 = angles(geo.normal[0, 0], model.layer.cylindrical)
    y = np.array([a0, p0, *_start(model, a0, p0, t[0], Q), geo.height[0]])
    for i in range(n):
        if i > 0:
            h = np.hypot(*(u[i] - u[i - 1]))
            k1 = _rates(model, y, t[i - 1], Q)
            if scheme == "euler":
                y = y + h * k1
            else:
                y = y + 0.5 * h * (k1 + _rates(model, y + h * k1, t[i - 1], Q))
            if geo.ids[i] != geo.ids[i - 1]:          # a new contact closes: restart on it
                a, p = angles(geo.normal[i, 0], model.layer.cylindrical)
                y = np.array([a, p, *_start(model, a, p, t[i], Q), y[4]])
            elif np.abs(t[i] - t[i - 1]).max() > CORNER_TOL:  # corner: slide the new way
                y[2:4] = _start(model, y[0], y[1], t[i], Q)
        out[i] = y
        axes = frames(_offset(model, y[0], y[1]), model.diameter).axes
        normal[i, 0] = local_forces(axes, y[2:4], Q)[2]
    return PathResult(u, out[:, 4].copy(), out[:, 2:4].copy(), normal, out[:, 0].copy(),
                      out[:, 1].copy(), geo.ids, f"incremental-{scheme}")
