r"""Path following for a grain sliding over a layer: displacement and force control.

Three independent computations:

* :func:`exact_path` — geometry and equilibrium. The centre is kept on the contact surface
  (:mod:`.geometry`); the grain velocity :math:`V` is the horizontal direction of the
  trajectory lifted onto the tangent plane(s) of the sliding contact(s), :math:`V\cdot n_k = 0`;
  each sliding contact carries :math:`N_k (n_k - \mu \hat V)` (local Coulomb friction opposing
  the slip), and equilibrium with the horizontal force ``T`` and the vertical load ``Q``,

  .. math:: (T_x, T_y, 0) + \sum_k N_k (n_k - \mu\hat V) = (0, 0, Q),

  gives ``T`` and the ``N_k``. With two sliding contacts (a ridge) ``T`` is taken along the
  motion.
* :func:`incremental_path` — the paper's rate formulation: the wedge limit condition (2.2) and
  potential (2.6) with varying ``(alpha, psi)``, the flow rule (3.3), the kinematic rates
  (3.6)/(3.12) (as re-derived, see ``docs/errata.md``) and the consistency condition (3.5),
  integrated step by step (explicit Euler, order 1, or Heun, order 2).
* :func:`force_path` — force control: displacement increments from force increments,
  :math:`\dot\lambda = \dot f_T / h` ((3.7), (3.13)), with the limit point detected.

Kinematics of one contact (re-derived; the centre moves on the sphere of radius ``d`` about the
layer grain, :math:`u = c - d\sin\alpha\, e_\psi`):

.. math:: \dot\alpha = -\frac{V\cdot e_\psi}{d\cos\alpha},\qquad
          \dot\psi = -\frac{V\cdot e_\psi^\perp}{d\sin\alpha}\ \text{(sphere)},\quad
          \dot\psi = 0\ \text{(cylinder)},

with :math:`e_\psi = (\cos\psi, \sin\psi)`, :math:`e_\psi^\perp = (-\sin\psi, \cos\psi)`.
"""

from __future__ import annotations

import numpy as np

from .._optional import require
from ..errors import FrictionRulesError, check_vectors
from ._symbolic import contact_functions
from .geometry import active_contacts, angles
from .state import ForceControlResult, GrainState, LimitPoint, PathResult

SCHEMES = ("euler", "heun")


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


# ---- exact: geometry + equilibrium ----------------------------------------------------------
def exact_path(model, path) -> PathResult:
    """Force, normal forces and height along ``path`` from the exact geometry and equilibrium."""
    u, t = as_path(path)
    c = active_contacts(model.layer, u, t)
    mu, Q = model.mu, model.Q
    n1 = c.normal[:, 0]
    # grain velocity: horizontal direction lifted onto the tangent plane of the first contact
    vz = -(n1[:, 0] * t[:, 0] + n1[:, 1] * t[:, 1]) / n1[:, 2]
    V = np.concatenate((t, vz[:, None]), axis=1)
    V /= np.linalg.norm(V, axis=1)[:, None]
    a = c.normal - mu * V[:, None, :]                      # (n, 2, 3): force per unit N_k
    force = np.zeros((len(u), 2))
    normal = np.zeros((len(u), 2))
    one = c.count == 1
    den = a[:, 0, 2]
    locked = one & (den <= 1e-12)
    if locked.any():
        bad = int(np.argmax(locked))
        raise FrictionRulesError(
            f"path[{bad}] = {tuple(u[bad])!r}: the contact locks (n_z - mu V_z = {den[bad]!r} <= 0, "
            "alpha + arctan(mu) >= pi/2 along the motion): no finite force slides the grain")
    N = np.where(one, Q / np.where(one, den, 1.0), 0.0)
    normal[one, 0] = N[one]
    force[one] = 0.0 - N[one, None] * a[one, 0, :2]
    for i in np.flatnonzero(~one):
        A = np.array([[t[i, 0], a[i, 0, 0], a[i, 1, 0]],
                      [t[i, 1], a[i, 0, 1], a[i, 1, 1]],
                      [0.0, a[i, 0, 2], a[i, 1, 2]]])
        tau, Na, Nb = np.linalg.solve(A, [0.0, 0.0, Q])
        if min(Na, Nb) < 0:
            raise FrictionRulesError(
                f"path[{i}] = {tuple(u[i])!r}: no compressive pair of contact forces carries a "
                f"force along the motion on this ridge (N = {Na!r}, {Nb!r}; constraint N >= 0)")
        force[i] = tau * t[i]
        normal[i] = (Na, Nb)
    alpha, psi = angles(n1, model.layer.cylindrical)
    return PathResult(u, c.height, force, normal, alpha, psi, c.ids, "exact")


# ---- the wedge law in the contact frame ------------------------------------------------------
def _rotate(v, angle):
    c, s = np.cos(angle), np.sin(angle)
    return np.array([c * v[0] - s * v[1], s * v[0] + c * v[1]])


def inverse_force(alpha, psi, direction, mu, Q) -> np.ndarray:
    r"""Force on the limit curve (2.2) whose slip (2.3), (3.3) is horizontal along ``direction``.

    In the contact frame (rotated by ``psi``) the horizontal slip is
    :math:`(e_1\cos\alpha, e_2)`, so :math:`e \propto (V'_x/\cos\alpha, V'_y)` and

    .. math:: N = \frac{Q}{\cos\alpha - \mu e_1\sin\alpha},\quad
              T'_x = N(\sin\alpha + \mu e_1\cos\alpha),\quad T'_y = \mu N e_2

    (the closed form of ``WedgeAsperity.force_for_slip``, with a signed ``alpha``).
    """
    v = _rotate(np.asarray(direction, dtype=float), -psi)
    e = np.array([v[0] / np.cos(alpha), v[1]])
    e /= np.hypot(*e)
    den = np.cos(alpha) - mu * e[0] * np.sin(alpha)
    if den <= 1e-12:
        raise FrictionRulesError(
            f"the contact locks at alpha = {alpha!r}, psi = {psi!r} for motion along "
            f"{tuple(direction)!r}: cos(alpha) - mu e1 sin(alpha) = {den!r} <= 0")
    n = Q / den
    return _rotate(np.array([n * (np.sin(alpha) + mu * e[0] * np.cos(alpha)), mu * n * e[1]]), psi)


def _needs_friction(model):
    if model.mu <= 0:
        raise FrictionRulesError(
            f"mu = {model.mu!r} violates mu > 0 for the rate form: with mu = 0 the limit curve is a "
            "point at the apex of the potential, whose gradient (the slip direction) is undefined "
            "there (use method='exact')")


def _kinematics(alpha, psi, V, d, cylindrical):
    """``(dalpha, dpsi)`` for the horizontal velocity ``V`` ((3.6), (3.12) re-derived)."""
    if cylindrical:
        return -V[0] / (d * np.cos(alpha)), 0.0
    along = V[0] * np.cos(psi) + V[1] * np.sin(psi)
    across = -V[0] * np.sin(psi) + V[1] * np.cos(psi)
    s = np.sin(alpha)
    return -along / (d * np.cos(alpha)), (-across / (d * s) if s != 0 else 0.0)


def _rates(y, t, model):
    """d/ds of ``(alpha, psi, Tx, Ty, z)`` at unit speed along ``t``: kinematics, consistency
    (3.5) and the flow rule (3.3) kept along ``t``."""
    alpha, psi, tx, ty, _ = y
    F = contact_functions()(tx, ty, alpha, psi, model.Q, model.mu)
    da, dp = _kinematics(alpha, psi, t, model.diameter, model.layer.cylindrical)
    # consistency (3.5): f_T . dT + f_alpha dalpha + f_psi dpsi = 0
    # flow direction (3.3): d/ds (g_Tx t_y - g_Ty t_x) = 0 on a straight segment
    A = np.array([[F["f_Tx"], F["f_Ty"]],
                  [t[1] * F["g_TxTx"] - t[0] * F["g_TxTy"], t[1] * F["g_TxTy"] - t[0] * F["g_TyTy"]]])
    b = -np.array([F["f_alpha"] * da + F["f_psi"] * dp,
                   (t[1] * F["g_Txalpha"] - t[0] * F["g_Tyalpha"]) * da
                   + (t[1] * F["g_Txpsi"] - t[0] * F["g_Typsi"]) * dp])
    dT = np.linalg.solve(A, b)
    # (3.3): V = lambda_dot grad g, so lambda_dot = 1/|g_T| at unit speed and dz = -lambda_dot g_Q
    dz = -F["g_Q"] / np.hypot(F["g_Tx"], F["g_Ty"])
    return np.array([da, dp, dT[0], dT[1], dz])


def incremental_path(model, path, scheme: str = "euler") -> PathResult:
    """Integrate the rate relations along ``path`` (one sliding contact at a time).

    Between the points the configuration ``(alpha, psi)``, the force and the height follow
    :func:`_rates`; at a corner of the trajectory the force jumps to the point of the current
    limit curve that slides the new way (:func:`inverse_force`); where another layer grain is
    reached (the envelope changes hands) the new contact closes, the old one opens, and the
    configuration of the new contact is taken from the geometry.
    """
    if scheme not in SCHEMES:
        raise FrictionRulesError(f"scheme = {scheme!r} violates scheme in {SCHEMES}")
    _needs_friction(model)
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
    y = np.array([a0, p0, *inverse_force(a0, p0, t[0], model.mu, model.Q), geo.height[0]])
    F = contact_functions()
    for i in range(n):
        if i > 0:
            h = np.hypot(*(u[i] - u[i - 1]))
            k1 = _rates(y, t[i - 1], model)
            if scheme == "euler":
                y = y + h * k1
            else:
                y = y + 0.5 * h * (k1 + _rates(y + h * k1, t[i - 1], model))
            if geo.ids[i] != geo.ids[i - 1]:          # a new contact closes: restart on it
                a, p = angles(geo.normal[i, 0], model.layer.cylindrical)
                y = np.array([a, p, *inverse_force(a, p, t[i], model.mu, model.Q), y[4]])
            elif np.abs(t[i] - t[i - 1]).max() > 1e-12:  # corner: slide the new way
                y[2:4] = inverse_force(y[0], y[1], t[i], model.mu, model.Q)
        out[i] = y
        normal[i, 0] = F(y[2], y[3], y[0], y[1], model.Q, model.mu)["N"]
    return PathResult(u, out[:, 4], out[:, 2:4].copy(), normal, out[:, 0].copy(), out[:, 1].copy(),
                      geo.ids, f"incremental-{scheme}")


# ---- force control ----------------------------------------------------------------------------
def hardening_modulus(F, alpha, psi, model) -> float:
    r"""Modulus ``h`` of :math:`\dot\lambda = \dot f_T / h`:
    :math:`h = -(f_{,\alpha}\,\alpha_{,\lambda} + f_{,\psi}\,\psi_{,\lambda})`, the rates per unit
    :math:`\dot\lambda` of slip :math:`V = \dot\lambda\, g_{,T}`. On the limit curve it equals
    :math:`-(1+\mu^2)N/d` for a sphere and :math:`-(1+\mu^2)N e_1^2/d` for a cylinder (corrected
    (3.7), (3.13)): always softening."""
    G = np.array([F["g_Tx"], F["g_Ty"]])
    da, dp = _kinematics(alpha, psi, G, model.diameter, model.layer.cylindrical)
    return -(F["f_alpha"] * da + F["f_psi"] * dp)


def climbing_limit(T, alpha, psi, mu, Q) -> float:
    """:math:`f_c = \\sqrt{\\max(T_{up}, 0)^2 + T_2^2} - \\mu N` in the contact frame (convex in
    T), :math:`T_{up}` the in-plane force up the slope (:func:`_upslope`)."""
    return float(np.hypot(max(_upslope(T, alpha, psi, Q), 0.0), _rotate(T, -psi)[1])
                 - mu * (_rotate(T, -psi)[0] * np.sin(alpha) + Q * np.cos(alpha)))


def _upslope(T, alpha, psi, Q) -> float:
    """In-plane force component up the slope: ``T1`` for ``alpha >= 0``, ``-T1`` for a signed
    (cylinder, past the top or on the left neighbour) ``alpha < 0``."""
    t1 = _rotate(np.asarray(T, dtype=float), -psi)[0] * np.cos(alpha) - Q * np.sin(alpha)
    return float(t1 if alpha >= 0 else -t1)


def force_path(model, forces, state: GrainState) -> ForceControlResult:
    r"""Follow prescribed horizontal forces ``forces`` ``(n, 2)`` from ``state`` (one contact).

    While the grain sticks the relevant limit is the climbing branch of the wedge,
    :math:`f_c = \sqrt{\max(T_1, 0)^2 + T_2^2} - \mu N` (a pull down the slope, ``T1 < 0``, is
    carried by the rest of the layer, the pocket the grain starts from; ``f_c = f`` where
    ``T1 >= 0``). While :math:`f_c < 0` the grain sticks. The first increment that crosses it
    defines the limit point (found by bisection on the convex ``f``); because :math:`h < 0`
    the force cannot grow beyond it and the run stops there. From a state on the limit curve,
    increments with :math:`\dot f_T \le 0` follow the active (softening) branch,
    :math:`\dot\lambda = \dot f_T/h`, :math:`du = \dot\lambda\, g_{,T}`,
    :math:`dz = -\dot\lambda\, g_{,Q}`; an increment with :math:`\dot f_T > 0` there stops the run.
    """
    T = check_vectors("forces", forces, (2,))
    if T.ndim != 2 or len(T) < 1:
        raise FrictionRulesError(f"forces must have shape (n, 2), got shape {T.shape}")
    if len(state.contacts) != 1:
        raise FrictionRulesError(f"state.contacts = {state.contacts!r}: force control follows one "
                                 "sliding contact (constraint: len(contacts) == 1)")
    _needs_friction(model)
    F = contact_functions()
    mu, Q, tol = model.mu, model.Q, 1e-9 * model.Q
    alpha, psi = state.alpha[0], state.psi[0]
    pos, z, cid = np.array(state.position, dtype=float), state.height, state.contacts
    f0 = climbing_limit(T[0], alpha, psi, mu, Q)
    if f0 > tol:
        raise FrictionRulesError(f"forces[0] = {tuple(T[0])!r} lies outside the limit curve "
                                 f"(f = {f0!r} > 0)")
    sliding = [f0 >= -tol]
    positions, heights = [pos.copy()], [z]
    completed = True

    def snapshot():
        return GrainState(pos.copy(), float(z), cid, (float(alpha),), (float(psi),))

    limit = LimitPoint(0, 0.0, T[0].copy(), snapshot()) if sliding[0] else None

    for i in range(len(T) - 1):
        dT = T[i + 1] - T[i]
        Fi = F(T[i, 0], T[i, 1], alpha, psi, Q, mu)
        if not sliding[-1]:
            f1 = climbing_limit(T[i + 1], alpha, psi, mu, Q)
            if f1 <= tol:
                sliding.append(f1 >= -tol)
                positions.append(pos.copy())
                heights.append(z)
                if sliding[-1] and limit is None:
                    limit = LimitPoint(i, 1.0, T[i + 1].copy(), snapshot())
                continue
            brentq = require("scipy.optimize", extra="solvers").brentq
            s = brentq(lambda s: climbing_limit(T[i] + s * dT, alpha, psi, mu, Q), 0.0, 1.0,
                       xtol=1e-14)
            Ts = T[i] + s * dT
            t1 = _upslope(Ts, alpha, psi, Q)
            if t1 <= 0:
                raise FrictionRulesError(
                    f"forces[{i + 1}] = {tuple(T[i + 1])!r}: the force reaches the limit curve of "
                    f"contact {cid[0]} on its down-slope part (T1 = {t1!r} <= 0), where the grain "
                    "would slide back into the pocket; the one-contact model does not follow that")
            limit = LimitPoint(i, float(s), Ts, snapshot())
            completed = False
            break
        fT = Fi["f_Tx"] * dT[0] + Fi["f_Ty"] * dT[1]
        h = hardening_modulus(Fi, alpha, psi, model)
        if fT > 0 and h <= 0:
            completed = False
            break
        lam = fT / h
        G = np.array([Fi["g_Tx"], Fi["g_Ty"]])
        du = lam * G
        da, dp = _kinematics(alpha, psi, du, model.diameter, model.layer.cylindrical)
        alpha, psi = alpha + da, psi + dp
        pos = pos + du
        z = z - lam * float(Fi["g_Q"])
        sliding.append(True)
        positions.append(pos.copy())
        heights.append(z)
    m = len(positions)
    return ForceControlResult(T[:m].copy(), np.array(positions), np.array(heights),
                              np.array(sliding), limit, completed, snapshot())
