r"""Grain assemblies in a periodic cell: :class:`Assembly` and the regular lattices.

A grain ``i`` is a rigid disk (2-D) or sphere (3-D) of radius ``r_i`` centred at ``x_i``. The
cell is the matrix ``H`` whose **columns** are the cell vectors; the sample is the periodic
repetition ``x_i + H k`` (``k`` integer). Under a homogeneous deformation of the cell the
displacement gradient ``ΔE`` moves the cell, ``H ← (I + ΔE) H``, and every grain by ``ΔE x_i``
plus its own fluctuation (``docs/assembly.md``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from ..contact import ContactModel
from ..errors import FrictionRulesError, check_finite, check_scalar

__all__ = ["Assembly", "LATTICES", "FCC_FRAMES"]

#: The regular arrays of :meth:`Assembly.lattice`.
LATTICES = ("fcc", "sc", "hex2d", "square2d")
#: The frames of the face-centred cubic array.
FCC_FRAMES = ("cube", "layer")


def _unit_cell(name: str, frame: str, r: float) -> tuple[np.ndarray, np.ndarray]:
    """Grain centres (rows) and cell (columns) of one repeat of a lattice of radius ``r``."""
    if name == "sc":
        return np.zeros((1, 3)), 2 * r * np.eye(3)
    if name == "square2d":
        return np.zeros((1, 2)), 2 * r * np.eye(2)
    if name == "hex2d":  # rows along x, one row above the other in the hollows
        return np.array([[0.0, 0.0], [r, np.sqrt(3) * r]]), np.diag([2 * r, 2 * np.sqrt(3) * r])
    a = 2 * np.sqrt(2) * r  # the cube edge of the fcc array
    if frame == "cube":
        x = 0.5 * a * np.array([[0, 0, 0], [0, 1, 1], [1, 0, 1], [1, 1, 0]], dtype=float)
        return x, a * np.eye(3)
    # layer: x = [110], y = [1-10], z = [001]; square (001) layers stacked in the hollows
    b = a / np.sqrt(2)
    return np.array([[0.0, 0.0, 0.0], [0.5 * b, 0.5 * b, 0.5 * a]]), np.diag([b, b, a])


@dataclass(frozen=True, eq=False)
class Assembly:
    r"""Rigid grains in a periodic cell with a contact law at every contact.

    Parameters
    ----------
    positions : array (n, d)
        Grain centres, ``d = 2`` (disks in the xy plane) or ``d = 3`` (spheres).
    radii : array (n,) or float
        Grain radii, ``> 0``.
    cell : array (d, d)
        Cell matrix; its **columns** are the cell vectors (right-handed, ``det > 0``).
    model : ContactModel or callable
        The elastic-plastic contact (§4: a law of the library with the stiffnesses ``kn``,
        ``kt``) of every contact, or a function ``model(i, j) -> ContactModel`` giving the
        contact between grains ``i`` and ``j`` its own.
    reference_axis : array (3,)
        The axis ``a`` that orients every contact frame: ``t1`` is the unit projection of
        ``a`` onto the contact plane, ``t1 = (a - (a·n) n)/|a - (a·n) n|`` (of the next global
        axis, y after x, z after y, x after z, where ``a`` is normal to the contact),
        ``t2 = n × t1``. An orthotropic law's ``angle`` is measured from ``t1``. Default: x.
    tolerance : float
        Gap (length) below which two grains are in contact, and the largest overlap
        accepted; ``>= 0``.

    Notes
    -----
    Contacts are found from the geometry (:meth:`contacts`); the normal ``n`` of the contact
    between grains ``i`` and ``j`` (or an image of ``j``) points from ``i`` to ``j``.
    """

    positions: np.ndarray
    radii: np.ndarray
    cell: np.ndarray
    model: ContactModel | Callable[[int, int], ContactModel]
    reference_axis: np.ndarray = (1.0, 0.0, 0.0)
    tolerance: float = 1e-9

    def __post_init__(self):
        x = check_finite("positions", self.positions)
        if x.ndim != 2 or x.shape[1] not in (2, 3) or len(x) == 0:
            raise FrictionRulesError(f"positions must have shape (n, 2) or (n, 3) with n >= 1, "
                                     f"got {x.shape}")
        n, d = x.shape
        r = check_finite("radii", self.radii)
        try:
            r = np.array(np.broadcast_to(r, (n,)), dtype=float)
        except ValueError:
            raise FrictionRulesError(f"radii must be a scalar or have shape ({n},), got {r.shape}") from None
        if np.any(r <= 0):
            raise FrictionRulesError(f"radii = {r.min()!r} violates radii > 0")
        h = check_finite("cell", self.cell)
        if h.shape != (d, d):
            raise FrictionRulesError(f"cell must have shape ({d}, {d}) (columns: cell vectors), "
                                     f"got {h.shape}")
        volume = float(np.linalg.det(h))
        if not volume > 0:
            raise FrictionRulesError(f"cell has det = {volume!r}; constraint: det > 0 (right-handed "
                                     "cell vectors that tile space)")
        tol = check_scalar("tolerance", self.tolerance, lo=0.0)
        axis = check_finite("reference_axis", self.reference_axis)
        if axis.shape != (3,) or not np.linalg.norm(axis) > 0:
            raise FrictionRulesError(f"reference_axis = {axis.tolist()!r} violates: a nonzero 3-vector")
        if d == 2 and abs(axis[2]) > 1e-12 * np.linalg.norm(axis):
            raise FrictionRulesError(f"reference_axis = {axis.tolist()!r} violates: in the xy plane "
                                     "for disks (its z component 0)")
        # Each grain must fit in the cell: the distance between opposite faces is at least the
        # largest diameter, so that only the nearest images can touch (one layer of images).
        width = volume / np.linalg.norm(_face_areas(h), axis=1)
        if np.any(width < 2 * r.max() - tol):
            raise FrictionRulesError(
                f"cell widths {np.round(width, 12).tolist()} violate: at least the largest "
                f"diameter {2 * r.max()!r} (a grain would overlap its own image: the cell does "
                "not tile)")
        if not (isinstance(self.model, ContactModel) or callable(self.model)):
            raise FrictionRulesError(f"model = {self.model!r} violates: a ContactModel or a "
                                     "function (i, j) -> ContactModel")
        for name, value in (("positions", x), ("radii", r), ("cell", h),
                            ("reference_axis", axis / np.linalg.norm(axis))):
            value = np.array(value, dtype=float)
            value.flags.writeable = False
            object.__setattr__(self, name, value)
        object.__setattr__(self, "tolerance", tol)

    # ---- sizes ------------------------------------------------------------------------------
    @property
    def dim(self) -> int:
        """2 (disks) or 3 (spheres)."""
        return self.positions.shape[1]

    @property
    def size(self) -> int:
        """Number of grains."""
        return len(self.positions)

    @property
    def volume(self) -> float:
        """Cell volume (area in 2-D)."""
        return float(np.linalg.det(self.cell))

    @property
    def solid_fraction(self) -> float:
        """Volume of the grains over the cell volume."""
        r = self.radii
        solid = np.pi * np.sum(r**2) if self.dim == 2 else 4 / 3 * np.pi * np.sum(r**3)
        return float(solid / self.volume)

    def model_of(self, i: int, j: int) -> ContactModel:
        """The contact model of the contact between grains ``i`` and ``j``."""
        if isinstance(self.model, ContactModel):
            return self.model
        m = self.model(int(i), int(j))
        if not isinstance(m, ContactModel):
            raise FrictionRulesError(f"model({i}, {j}) = {m!r} violates: must return a ContactModel")
        return m

    # ---- constructors -------------------------------------------------------------------------
    @classmethod
    def lattice(cls, name: str, model, *, radius: float = 1.0, cells=1, frame: str = "cube",
                reference_axis=(1.0, 0.0, 0.0), tolerance: float = 1e-9) -> "Assembly":
        r"""A regular array of equal grains.

        Parameters
        ----------
        name : {"fcc", "sc", "hex2d", "square2d"}
            Face-centred cubic (12 contacts per sphere), simple cubic (6), the hexagonal array
            of disks with its rows along x (6), the square array of disks (4).
        model : ContactModel or callable
            As for :class:`Assembly`.
        radius : float
            Grain radius.
        cells : int or sequence of int
            Repeats of the unit cell along each axis.
        frame : {"cube", "layer"}
            For "fcc": x, y, z on the cube axes, or x = [110], y = [1-10], z = [001] (the
            square (001) layers of the array normal to z).
        """
        if name not in LATTICES:
            raise FrictionRulesError(f"name = {name!r} violates: one of {', '.join(LATTICES)}")
        if frame not in FCC_FRAMES:
            raise FrictionRulesError(f"frame = {frame!r} violates: one of {', '.join(FCC_FRAMES)}")
        if name != "fcc" and frame != "cube":
            raise FrictionRulesError(f"frame = {frame!r} violates: only the fcc array has frames "
                                     "(leave the default 'cube')")
        r = check_scalar("radius", radius, lo=0.0, lo_open=True)
        x, h = _unit_cell(name, frame, r)
        d = h.shape[0]
        reps = np.broadcast_to(np.asarray(cells), (d,)) if np.ndim(cells) == 0 else np.asarray(cells)
        if reps.shape != (d,) or reps.dtype.kind not in "iu" or np.any(reps < 1):
            raise FrictionRulesError(f"cells = {cells!r} violates: a positive integer or {d} of them")
        shifts = np.stack(np.meshgrid(*[np.arange(k) for k in reps], indexing="ij"), -1).reshape(-1, d)
        positions = (x[None, :, :] + (shifts @ h.T)[:, None, :]).reshape(-1, d)
        return cls(positions, r, h * reps[None, :], model, reference_axis, tolerance)

    @classmethod
    def random(cls, n: int, dim: int, model, *, radius=1.0, polydispersity: float = 0.0,
               solid_fraction: float | None = None, seed: int = 0, reference_axis=(1.0, 0.0, 0.0),
               tolerance: float = 1e-9, progress=None) -> "Assembly":
        """A dense random packing by seeded compaction (:func:`random_packing`): a cloud of
        ``n`` grains compressed without friction by the dynamic engine to random close packing
        (or to ``solid_fraction``), then expanded until its grains just touch. ``progress``,
        when given, hears the compaction's stages through its ``phase(text)``."""
        from ._random import random_packing
        report = getattr(progress, "phase", None)
        pack = random_packing(n, dim, radius=radius, polydispersity=polydispersity,
                              solid_fraction=solid_fraction, seed=seed, report=report)
        return cls(pack.positions, pack.radii, pack.cell, model, reference_axis,
                   max(tolerance, pack.tolerance))

    def with_geometry(self, positions, cell) -> "Assembly":
        """The same grains and contacts' models at new positions in a new cell."""
        return Assembly(positions, self.radii, cell, self.model, self.reference_axis, self.tolerance)

    def __repr__(self) -> str:
        return (f"Assembly(n={self.size}, dim={self.dim}, volume={self.volume:.6g}, "
                f"solid_fraction={self.solid_fraction:.4f}, model={self.model!r})")


def _face_areas(h: np.ndarray) -> np.ndarray:
    """Normals of the faces opposite each cell vector scaled by their area (rows): the
    columns of ``det(H) H^{-T}``; face widths are ``det(H)/|row|``."""
    return np.linalg.det(h) * np.linalg.inv(h)

