r"""Grains and contact forces of a dynamic run over time, for ParaView (VTK files through
meshio; ``docs/assembly.md``, "Dynamic runs").

Three time series, each a ``.pvd`` collection of one ``.vtu`` file per record:

* ``grains.pvd``: the grains as points (vertex cells) with the point data ``radius``,
  ``displacement`` (since the first record, the cell's affine part included) and ``grain``
  (the index);
* ``contacts.pvd``: the contacts as line cells from the centre of grain ``i`` to the centre of
  the image of ``j`` that touches it (``x_j + H s``, ``s`` the contact's image shift, ``H`` the
  record's cell), each line with its own two points, and the cell data ``normal_force``
  (``N``, compression positive), ``tangential_force`` (``|T|``), ``mobilized_friction``
  (``|T|/N``, 0 where open), ``force`` (the force of ``j`` on ``i`` in the global frame,
  ``T1 t1 + T2 t2 - N n``), ``status`` (0 stick, 1 slide, 2 open) and ``grains`` (``i, j``);
* ``cell.pvd``: the periodic cell (a hexahedron, a quadrilateral in 2-D).

Positions are wrapped into the cell (``wrap=True``) so that the sample stays a box while it
deforms; a contact across the boundary then reaches out of the box to the image of ``j``.
Disks (2-D) lie in the plane ``z = 0``. The timestep of the collections is the record's time.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from ..errors import FrictionRulesError

__all__ = ["write_vtk", "VTK_SERIES"]

#: The time series :func:`write_vtk` writes (one ``NAME.pvd`` and ``NAME_000000.vtu``, ...).
VTK_SERIES = ("grains", "contacts", "cell")


def _pad(x: np.ndarray) -> np.ndarray:
    """Points with three coordinates (VTK's), ``z = 0`` for disks."""
    return np.pad(x, ((0, 0), (0, 3 - x.shape[1]))) if x.shape[1] < 3 else x


def _wrapped(x: np.ndarray, h: np.ndarray) -> np.ndarray:
    """Centres moved by whole cell vectors into the cell ``H [0, 1)^d``."""
    s = np.linalg.solve(h, x.T).T
    return x - np.floor(s) @ h.T


def _grains(x, wrapped, x0, radii):
    import meshio
    n = len(x)
    return meshio.Mesh(_pad(wrapped), [("vertex", np.arange(n).reshape(-1, 1))],
                       point_data={"radius": np.asarray(radii, float),
                                   "displacement": _pad(x - x0),
                                   "grain": np.arange(n, dtype=np.int64)})


def _contacts(x, wrapped, h, snap):
    import meshio
    i, j = snap.grains[:, 0], snap.grains[:, 1]
    start = wrapped[i]
    end = start + (x[j] + snap.shift @ h.T - x[i])  # the branch vector to the image of j
    m = len(i)
    points = _pad(np.stack((start, end), axis=1).reshape(-1, x.shape[1])) if m else np.zeros((0, 3))
    lines = np.arange(2 * m, dtype=np.int64).reshape(-1, 2)
    f = snap.force
    frame = snap.frame
    force = f[:, 0, None] * frame[:, 0] + f[:, 1, None] * frame[:, 1] - f[:, 2, None] * frame[:, 2]
    data = {"normal_force": f[:, 2], "tangential_force": np.hypot(f[:, 0], f[:, 1]),
            "mobilized_friction": snap.mobilized_friction, "force": force,
            "status": np.asarray(snap.status, np.int64), "grains": np.asarray(snap.grains, np.int64)}
    return meshio.Mesh(points, [("line", lines)], cell_data={k: [v] for k, v in data.items()})


def _cell(h):
    import meshio
    d = len(h)
    if d == 2:
        corners = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float)
        kind = "quad"
    else:
        corners = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0],
                            [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]], float)
        kind = "hexahedron"
    return meshio.Mesh(_pad(corners @ h.T), [(kind, np.arange(len(corners)).reshape(1, -1))])


def _collection(entries) -> str:
    """The ``.pvd`` index of a time series: ``(time, file name)`` per record (ParaView's
    collection format, an XML list of the data files)."""
    root = ET.Element("VTKFile", type="Collection", version="0.1", byte_order="LittleEndian")
    coll = ET.SubElement(root, "Collection")
    for t, name in entries:
        ET.SubElement(coll, "DataSet", timestep=repr(float(t)), group="", part="0", file=name)
    ET.indent(root)
    return '<?xml version="1.0"?>\n' + ET.tostring(root, encoding="unicode") + "\n"


def write_vtk(result, folder, *, every: int = 1, wrap: bool = True,
              radii=None) -> tuple[Path, ...]:
    r"""Write the grains, contacts and cell of a dynamic run's records as VTK files for
    ParaView: ``grains.pvd``, ``contacts.pvd`` and ``cell.pvd`` in ``folder``, each a time
    series of one ``.vtu`` file per record written.

    Grains are points with ``radius`` and ``displacement`` (show them with ParaView's Glyph
    filter, a sphere scaled by ``radius`` with the scale factor 2); contacts are lines from
    grain ``i`` to the image of grain ``j`` (``x_j + H s``, the record's cell ``H`` and the
    contact's image shift ``s``) with ``normal_force`` ``N`` (compression positive),
    ``tangential_force`` ``|T|``, ``mobilized_friction`` ``|T|/N``, ``force`` (the force of
    ``j`` on ``i``, ``T1 t1 + T2 t2 - N n``, global frame), ``status`` (0 stick, 1 slide,
    2 open) and ``grains``; the force chains are the lines with a Tube filter of radius
    varying with ``normal_force``. Every file is written atomically, the collections last.

    Parameters
    ----------
    result : TriaxialResult
        A result of ``method="dem"`` (it has the grains' positions and the cell at each
        record).
    folder : path
        Where the files go (created if needed; files of the same names are replaced).
    every : int
        Write every ``every``-th record (the first and the last always).
    wrap : bool
        Move the grains' centres into the cell by whole cell vectors (the sample stays a box);
        False draws them where the engine carried them.
    radii : array (n,), optional
        The grains' radii; by default those of the engine's state (``result.engine``). A run of
        ``engine="lammps"`` keeps no engine state: pass ``assembly.radii``.

    Returns
    -------
    tuple of Path
        The three ``.pvd`` files (:data:`VTK_SERIES` order).

    Raises
    ------
    FrictionRulesError
        A result without positions at its records (``method="implicit"``), a bad ``every``,
        or a folder that cannot be written.
    """
    from .._optional import require
    from .._output import atomic_path, check_folder, write_text
    if getattr(result, "positions", None) is None or getattr(result, "cells", None) is None:
        raise FrictionRulesError(f"result of method = {getattr(result, 'method', None)!r} has no "
                                 "positions at its records; constraint: a result of "
                                 "triaxial(..., method='dem') or load_cell(..., method='dem')")
    if not isinstance(every, (int, np.integer)) or isinstance(every, bool) or every < 1:
        raise FrictionRulesError(f"every = {every!r} violates: an integer >= 1")
    meshio = require("meshio", purpose="VTK files")
    folder = check_folder(folder, name="folder")
    folder.mkdir(parents=True, exist_ok=True)
    count = len(result.positions)
    chosen = sorted(set(range(0, count, int(every))) | {count - 1})
    if radii is None:
        if getattr(result, "engine", None) is None:
            raise FrictionRulesError("radii = None violates: the grains' radii for a result "
                                     "without the engine's state (engine='lammps': "
                                     "assembly.radii)")
        radii = result.engine.grains.radius  # the engine's state has the radii
    radii = np.asarray(radii, float)
    if radii.shape != (result.positions.shape[1],):
        raise FrictionRulesError(f"radii of shape {radii.shape} violates: one radius per grain "
                                 f"({result.positions.shape[1]})")
    x0 = result.positions[0]
    entries = {name: [] for name in VTK_SERIES}
    for k in chosen:
        x, h = result.positions[k], result.cells[k]
        wrapped = _wrapped(x, h) if wrap else x
        meshes = {"grains": _grains(x, wrapped, x0, radii),
                  "contacts": _contacts(x, wrapped, h, result.contacts[k]),
                  "cell": _cell(h)}
        for name, mesh in meshes.items():
            file = f"{name}_{k:06d}.vtu"
            with atomic_path(folder / file) as tmp:
                meshio.write(tmp, mesh, file_format="vtu")
            entries[name].append((result.time[k], file))
    return tuple(write_text(folder / f"{name}.pvd", _collection(entries[name])) for name in VTK_SERIES)
