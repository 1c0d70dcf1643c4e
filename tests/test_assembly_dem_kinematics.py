"""The contact pass's kinematics (``assembly/_dem/_passes.py``) against independent derivations:
the frame of a branch (:func:`_frame`) against the projection of the reference axis on the
contact plane, and the turn of a contact's tangential history (:func:`_turn`, :func:`_rotate`)
against Rodrigues' rotations of the history as a 3-vector — the rotation taking the old normal
to the new one about their common perpendicular, then the twist about the new normal — read
in the new frame. Signs: ``docs/conventions.md``."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from frictionrules.assembly._contacts import frames
from frictionrules.assembly._dem._passes import _frame, _rotate, _turn, frame_t1

unit = st.tuples(*[st.floats(-1.0, 1.0)] * 3).filter(lambda v: 0.1 < np.linalg.norm(v))
length = st.floats(0.1, 10.0)
EPS = np.finfo(float).eps


def _unit(v):
    v = np.asarray(v, float)
    return v / np.linalg.norm(v)


def _rodrigues(v, axis, angle):
    """``v`` turned by ``angle`` about the unit ``axis``."""
    return (v * math.cos(angle) + np.cross(axis, v) * math.sin(angle)
            + axis * (axis @ v) * (1.0 - math.cos(angle)))


def _conditioning(n, a):
    """``1/sin`` of the angle between the reference axis and the normal: the frame's round-off
    is a few ``eps`` times it (``t1`` divides by ``|l × a|``, computed without cancellation)."""
    return 1.0 / max(np.linalg.norm(np.cross(n, a)), 1e-6)


def _frame_of(lv, axis):
    d2 = float(lv @ lv)
    return np.array(_frame(lv[0], lv[1], lv[2], d2, math.sqrt(d2), *axis))


@settings(max_examples=300, deadline=None)
@given(unit, length, unit)
def test_frame_of_a_branch_is_the_reference_axis_projected_on_the_contact_plane(n, d, a):
    n, a = _unit(n), _unit(a)
    t1 = _frame_of(d * n, a)
    tol = 16 * EPS * _conditioning(n, a)
    if 1.0 - (a @ n) ** 2 >= 1e-12:
        want = (a - (a @ n) * n) / np.linalg.norm(a - (a @ n) * n)
        np.testing.assert_allclose(t1, want, atol=tol)
    assert abs(t1 @ n) <= tol and abs(np.linalg.norm(t1) - 1.0) <= tol
    # the rule of the records' frames (frames from the normals alone) is the same
    np.testing.assert_allclose(t1, frames(n[None], a)[0, 0], atol=tol)
    np.testing.assert_allclose(t1, frame_t1(n[None], *a)[0], atol=tol)


def test_frame_where_the_axis_is_normal_to_the_contact_takes_the_next_axis():
    """The axis x along the normal: t1 is the next global axis, y (and z after y, x after z)."""
    for axis, nxt in (((1.0, 0.0, 0.0), (0.0, 1.0, 0.0)), ((0.0, 1.0, 0.0), (0.0, 0.0, 1.0)),
                      ((0.0, 0.0, 1.0), (1.0, 0.0, 0.0))):
        np.testing.assert_allclose(_frame_of(2.5 * np.array(axis), axis), nxt, atol=1e-15)


@settings(max_examples=300, deadline=None)
@given(unit, unit, st.floats(0.0, 1.2), length, unit, st.floats(-0.3, 0.3),
       st.floats(-2.0, 2.0), st.floats(-2.0, 2.0))
def test_turned_history_is_the_rotated_vector_in_the_new_frame(n0, k, theta, d, a, h, u1, u2):
    """The old normal ``n0`` turned by ``theta`` (< π/2 here; a step turns a contact by far
    less) about an axis normal to it gives ``n``; the history ``u1 t1_old + u2 t2_old`` turned
    by the same rotation and then by ``2 atan h`` about ``n`` has, in the new frame, the
    components of :func:`_rotate` ``(_turn(...))``; and its length is kept."""
    n0, a = _unit(n0), _unit(a)
    perp = np.cross(n0, _unit(k))
    if np.linalg.norm(perp) < 1e-3:
        return
    perp = _unit(perp)
    n = _rodrigues(n0, perp, theta)
    old = np.array(frames(n0[None], a)[0])
    t1_old, t2_old = old[0], old[1]
    lv = d * n
    t1 = _frame_of(lv, a)
    t2 = np.cross(n, t1)
    twist = 2.0 * math.atan(h)
    turned = _rodrigues(_rodrigues(u1 * t1_old + u2 * t2_old, perp, theta), n, twist)
    cp, sp = _turn(*n0, *t1_old, *lv, d, *n, *t1, *t2, (1.0 - h * h) / (1.0 + h * h),
                   2.0 * h / (1.0 + h * h))
    got = _rotate(u1, u2, cp, sp)
    tol = 32 * EPS * _conditioning(n, a)
    np.testing.assert_allclose(got, (turned @ t1, turned @ t2), atol=tol * max(abs(u1), abs(u2), 1.0))
    assert abs(cp * cp + sp * sp - 1.0) <= tol


def test_frame_near_the_axis_loses_no_more_than_its_conditioning():
    """Normals 1e-6 to 0.3 rad from the reference axis (closer, the next axis takes over): the
    frame is unit, normal to n and the projection's direction to a few eps / sin(angle) — the
    square of ``|l × a|`` has no cancellation."""
    rng = np.random.default_rng(7)
    for angle in (1.01e-6, 1e-5, 1e-3, 0.3):
        for _ in range(200):
            a = _unit(rng.normal(size=3))
            p = _unit(np.cross(a, rng.normal(size=3)))
            n = a * math.cos(angle) + p * math.sin(angle)
            t1 = _frame_of(rng.uniform(0.1, 10.0) * n, a)
            tol = 16 * EPS * _conditioning(n, a)
            assert abs(np.linalg.norm(t1) - 1.0) <= tol and abs(t1 @ n) <= tol
            np.testing.assert_allclose(t1, frames(n[None], a)[0, 0], atol=tol)
