r"""The frame of a grain contact and its derivatives with respect to the grain's position.

A contact between the upper grain and a layer grain whose centre is at the horizontal offset
:math:`r = u - c` from it (``u`` the upper grain's centre, ``c`` the layer grain's, both
grains of diameter ``d``, the centres at the distance ``d``) has the unit normal, from the layer
grain into the upper grain,

.. math:: n = \frac{(r_x,\ r_y,\ \sqrt{d^2 - |r|^2})}{d}
            = (-\sin\alpha\cos\psi,\ -\sin\alpha\sin\psi,\ \cos\alpha),

(the inclination ``alpha`` and the up-slope azimuth ``psi`` of the tangent plane, (3.1)) and the
frame of ``docs/conventions.md`` ("A facet's frame"): :math:`t_1` the unit projection of the
global x axis onto the tangent plane, :math:`t_2 = n\times t_1`,

.. math:: t_1 = \frac{e_x - n_x n}{\sqrt{1 - n_x^2}} .

(The normal is never along x: the centres are not level, :math:`|r| < d`.) The local law of the
contact acts on the force the grain exerts on the layer grain, :math:`F = T_1 t_1 + T_2 t_2 - N
n`, so :math:`(T_1, T_2, N) = (F\cdot t_1, F\cdot t_2, -F\cdot n)`, and the grain's velocity is
the slip :math:`(V\cdot t_1, V\cdot t_2, V\cdot n)`.

The frame is computed with NumPy from this definition (:func:`axes_of`); its derivatives with
respect to the offset and those of the angles (the geometric part of the rate relations (3.4),
(3.6), (3.12): the grain's motion moves the frame) are derived with SymPy from the same
definition and compiled once. In the offset the frame has no singularity on the top of a layer
grain, where ``psi`` is undefined.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from .._optional import require

__all__ = ["Frames", "axes_of", "frames", "frame_of_angles", "local_forces", "offset_of_angles",
           "angle_rates"]


@dataclass(frozen=True)
class Frames:
    """Frames of contacts and, optionally, their derivatives.

    Attributes
    ----------
    axes : array (..., 3, 3)
        Rows ``t1, t2, n``.
    rates : array (..., 2, 3, 3) or None
        ``d axes / d r_x`` and ``d axes / d r_y`` (``r`` the horizontal offset).
    """

    axes: np.ndarray
    rates: np.ndarray | None = None


@functools.lru_cache(maxsize=None)
def _compiled():
    """Lambdified ``(axes, d axes/d r_x, d axes/d r_y)`` as functions of ``(r_x, r_y, d)``."""
    sp = require("sympy", extra="symbolic")
    rx, ry = sp.symbols("r_x r_y", real=True)
    d = sp.Symbol("d", positive=True)
    n = sp.Matrix([rx, ry, sp.sqrt(d**2 - rx**2 - ry**2)]) / d
    t1 = (sp.Matrix([1, 0, 0]) - n[0] * n) / (sp.sqrt(d**2 - rx**2) / d)
    t2 = n.cross(t1)
    axes = sp.Matrix.vstack(t1.T, t2.T, n.T)
    exprs = [axes.tolist(), sp.diff(axes, rx).tolist(), sp.diff(axes, ry).tolist()]
    return sp.lambdify((rx, ry, d), exprs, modules="numpy", cse=True)


@functools.lru_cache(maxsize=None)
def _compiled_kinematics():
    r"""Lambdified :math:`\partial(\alpha, \psi)/\partial r` of ``(alpha, psi, d)`` for a sphere
    (the inverse of the Jacobian of :math:`r = -d\sin\alpha\,e_\psi`) and
    :math:`\partial\alpha/\partial r_x` for a cylinder (:math:`r_x = -d\sin\alpha`)."""
    sp = require("sympy", extra="symbolic")
    a, p = sp.symbols("alpha psi", real=True)
    d = sp.Symbol("d", positive=True)
    r = sp.Matrix([-d * sp.sin(a) * sp.cos(p), -d * sp.sin(a) * sp.sin(p)])
    sphere = sp.simplify(r.jacobian([a, p]).inv())
    cylinder = sp.simplify(1 / sp.diff(r[0].subs(p, 0), a))
    return (sp.lambdify((a, p, d), sphere.tolist(), modules="numpy", cse=True),
            sp.lambdify((a, d), cylinder, modules="numpy"))


def angle_rates(alpha: float, psi: float, d: float, velocity, cylindrical: bool) -> np.ndarray:
    r"""``(alpha_dot, psi_dot)`` of a contact when the grain moves with the horizontal velocity
    ``velocity`` (2,): the kinematics (3.6) (cylinder, ``psi_dot = 0``) and (3.12) (sphere,
    re-derived), :math:`\dot\alpha = -V\cdot e_\psi/(d\cos\alpha)`,
    :math:`\dot\psi = -V\cdot e_\psi^\perp/(d\sin\alpha)`. On the top of a sphere
    (``sin alpha = 0``) ``psi`` is undefined and held.
    """
    V = np.asarray(velocity, dtype=float)
    sphere, cylinder = _compiled_kinematics()
    if cylindrical:
        return np.array([float(cylinder(alpha, d)) * V[0], 0.0])
    if np.sin(alpha) == 0.0:
        return np.array([-(V[0] * np.cos(psi) + V[1] * np.sin(psi)) / d, 0.0])
    return np.array(sphere(alpha, psi, d), dtype=float) @ V


def _array(nested, shape) -> np.ndarray:
    """Nested lists of scalars or arrays -> one array ``shape + (3, 3)``."""
    return np.stack([np.stack([np.broadcast_to(np.asarray(v, dtype=float), shape) for v in row],
                              axis=-1) for row in nested], axis=-2)


def axes_of(offset, d: float) -> np.ndarray:
    """Frames (rows ``t1, t2, n``) of the contacts at the horizontal offsets ``offset``
    ``(..., 2)``, ``|r| < d`` (NumPy: the definition above)."""
    r = np.asarray(offset, dtype=float)
    z = np.sqrt(np.maximum(d * d - np.sum(r * r, axis=-1), 0.0))
    n = np.concatenate((r, z[..., None]), axis=-1) / d
    t1 = np.zeros_like(n)
    t1[..., 0] = 1.0
    t1 -= n[..., :1] * n
    t1 /= np.sqrt(1.0 - n[..., :1] ** 2)
    return np.stack((t1, np.cross(n, t1), n), axis=-2)


def frames(offset, d: float, rates: bool = False) -> Frames:
    """Frames of the contacts at the horizontal offsets ``offset`` ``(..., 2)`` (``|r| < d``)
    and, with ``rates``, their derivatives with respect to the offset (derived with SymPy)."""
    r = np.asarray(offset, dtype=float)
    axes = axes_of(r, d)
    if not rates:
        return Frames(axes)
    _, drx, dry = _compiled()(r[..., 0], r[..., 1], float(d))
    shape = r.shape[:-1]
    return Frames(axes, np.stack((_array(drx, shape), _array(dry, shape)), axis=-3))


def offset_of_angles(alpha, psi, d: float = 1.0) -> np.ndarray:
    """Offset ``r = -d sin(alpha) (cos psi, sin psi)`` of a contact with the inclination
    ``alpha`` (signed for cylinders) and the up-slope azimuth ``psi``."""
    alpha, psi = np.broadcast_arrays(np.asarray(alpha, dtype=float), np.asarray(psi, dtype=float))
    return -d * np.sin(alpha)[..., None] * np.stack((np.cos(psi), np.sin(psi)), axis=-1)


def frame_of_angles(alpha, psi) -> np.ndarray:
    """The frame (rows ``t1, t2, n``) of a contact with the angles ``(alpha, psi)``."""
    return axes_of(offset_of_angles(alpha, psi), 1.0)


def local_forces(axes: np.ndarray, T, Q) -> np.ndarray:
    """``(T1, T2, N)`` of the contacts with the frames ``axes`` ``(..., 3, 3)`` when the grain
    passes the whole load ``F = (Tx, Ty, -Q)`` to them: :math:`(F\\cdot t_1, F\\cdot t_2,
    -F\\cdot n)`."""
    T = np.asarray(T, dtype=float)
    Q = np.asarray(Q, dtype=float)
    T, Q = np.broadcast_arrays(T, Q[..., None])
    F = np.concatenate((T, -Q[..., :1]), axis=-1)
    sigma = np.einsum("...ij,...j->...i", axes, F)
    sigma[..., 2] *= -1.0
    return sigma
