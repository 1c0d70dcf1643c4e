"""State and result records of the configuration-softening models (frozen dataclasses)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["GrainState", "PathResult", "LimitPoint", "ForceControlResult", "PeakForcePolar"]


@dataclass(frozen=True)
class GrainState:
    """Configuration of the upper grain: where it is and on which layer grains it slides.

    Attributes
    ----------
    position : array (2,)
        Horizontal position of the centre (the pocket is the origin).
    height : float
        Height of the centre above the layer centres.
    contacts : tuple of tuple of int
        Ids (lattice coordinates) of the sliding contacts.
    alpha, psi : tuple of float
        Inclination and up-slope azimuth of the tangent plane of each contact (radians), (3.1).
    """

    position: np.ndarray
    height: float
    contacts: tuple
    alpha: tuple
    psi: tuple


@dataclass(frozen=True)
class PathResult:
    """Displacement-controlled sliding along a trajectory of horizontal positions.

    Attributes
    ----------
    position : array (n, 2)
        Prescribed horizontal positions ``u``.
    height : array (n,)
        Height of the centre (its change from the start is the dilatancy).
    force : array (n, 2)
        Horizontal force ``T = (Tx, Ty)`` that keeps the grain sliding along the trajectory.
    normal : array (n, 2)
        Normal forces of the first and second sliding contact (0 where only one slides).
    alpha, psi : array (n,)
        Configuration of the first sliding contact.
    contacts : tuple
        Per point, the ids of the sliding contacts.
    method : str
        ``"exact"`` (geometry and equilibrium) or ``"incremental-euler"`` / ``"incremental-heun"``
        (the rate relations (3.3)–(3.13) with the consistency condition (3.5)).
    """

    position: np.ndarray
    height: np.ndarray
    force: np.ndarray
    normal: np.ndarray
    alpha: np.ndarray
    psi: np.ndarray
    contacts: tuple
    method: str

    @property
    def distance(self) -> np.ndarray:
        """Arc length ``|u|`` travelled along the trajectory, shape ``(n,)``."""
        step = np.hypot(*np.diff(self.position, axis=0).T)
        return np.concatenate(([0.0], np.cumsum(step)))

    @property
    def force_magnitude(self) -> np.ndarray:
        return np.hypot(self.force[:, 0], self.force[:, 1])

    def events(self) -> list[tuple[int, str, tuple]]:
        """``(index, "open" | "close", id)``: contacts that open or close between points."""
        out = []
        for i in range(1, len(self.contacts)):
            before, after = set(self.contacts[i - 1]), set(self.contacts[i])
            out += [(i, "open", c) for c in sorted(before - after)]
            out += [(i, "close", c) for c in sorted(after - before)]
        return out

    def table(self) -> dict[str, np.ndarray]:
        """Columns for a CSV/JSON table."""
        return {"distance": self.distance, "ux": self.position[:, 0], "uy": self.position[:, 1],
                "uz": self.height - self.height[0], "Tx": self.force[:, 0], "Ty": self.force[:, 1],
                "T": self.force_magnitude, "N1": self.normal[:, 0], "N2": self.normal[:, 1],
                "alpha": self.alpha, "psi": self.psi,
                "contacts": np.array([len(c) for c in self.contacts])}


@dataclass(frozen=True)
class LimitPoint:
    """Where a force-controlled path reaches the limit curve and the force cannot grow further.

    ``index`` is the last point that sticks, ``fraction`` in [0, 1] locates the limit point on
    the increment to the next point (0 when the run starts on the limit curve), ``force`` is the
    force there and ``state`` the configuration, whose ``contacts`` are the contacts that start
    to slide (the mechanism: one, or two at once on a ridge). ``velocity`` (3,) is the unit
    grain velocity of the mechanism (``Vz > 0`` upwards): displacement control along its
    horizontal part continues past the limit point.
    """

    index: int
    fraction: float
    force: np.ndarray
    state: GrainState
    velocity: np.ndarray | None = None


@dataclass(frozen=True)
class ForceControlResult:
    """Force-controlled run: the displacements produced by prescribed forces ((3.7), (3.13)).

    Attributes
    ----------
    force, position : arrays (m, 2)
        The forces processed (the first ``m`` of those given) and the positions they produce.
    height : array (m,)
    sliding : array (m,) of bool
        True where the grain slides (on the limit curve), False where it sticks.
    limit_point : LimitPoint or None
        The limit point, where softening begins: there the force can no longer increase.
    completed : bool
        False when the run stopped because a force increment pushed beyond the limit curve
        (softening, :math:`h < 0`: no static solution, the grain runs away).
    state : GrainState
        Final configuration.
    """

    force: np.ndarray
    position: np.ndarray
    height: np.ndarray
    sliding: np.ndarray
    limit_point: LimitPoint | None
    completed: bool
    state: GrainState


@dataclass(frozen=True)
class PeakForcePolar:
    """Direction-dependent peak force of a grain pushed out of its pocket.

    Attributes
    ----------
    direction : array (n,)
        Direction of the horizontal force (``breakout_force``) or displacement
        (``SphereOnLayer.peak_force``), radians.
    peak : array (n,)
        The peak ``|T|``: the break-out force, or the largest ``|T|`` on the way up.
    start : array (n, 2)
        The force at the start of the motion.
    count : array (n,) of int
        How many layer grains the grain climbs over at once (1 or 2).
    mechanism : tuple
        Per direction, the ids of the layer grains it climbs over.
    """

    direction: np.ndarray
    peak: np.ndarray
    start: np.ndarray
    count: np.ndarray
    mechanism: tuple = ()
