"""One home for rotations of the tangential plane: a 2-D rotation by an angle measured
counter-clockwise from the first tangent axis (``docs/conventions.md``)."""

from __future__ import annotations

import numpy as np


def rotation(angle: float) -> np.ndarray:
    """The 2x2 matrix ``R(angle) = [[cos, -sin], [sin, cos]]`` (counter-clockwise, radians)."""
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s], [s, c]])


def rotate(v: np.ndarray, angle: float) -> np.ndarray:
    """Rotate the 2-vectors ``v[..., :2]`` counter-clockwise by ``angle`` (radians):
    ``R(angle) v``; ``v`` itself when the angle is zero."""
    if angle == 0.0:
        return v
    c, s = np.cos(angle), np.sin(angle)
    x, y = v[..., 0], v[..., 1]
    return np.stack((c * x - s * y, s * x + c * y), axis=-1)
