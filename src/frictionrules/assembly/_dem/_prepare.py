r"""Samples prepared by the dynamic engine: the frictionless compression of a cloud of grains
(:meth:`frictionrules.Assembly.random` and the "frictionless" consolidation of both methods).

Frictionless grains with linear normal springs ``kn`` in a periodic cell whose every normal
stress is driven by the servo (:mod:`._engine`) to the isotropic ``pressure``, the cell's
shear strains held (a rectangular cell); the compression ends where each normal stress is within
:data:`._protocol.STRESS_TOL` of the pressure with an unbalanced-force ratio below
:data:`._protocol.UNBALANCED_TOL` (YADE's ``PeriTriaxController`` with ``maxUnbalanced``).
A cloud far below jamming carries no stress: the servo then compresses at its largest rate.
The grains of these frictionless stages move by FIRE (:mod:`._engine`).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from ...errors import FrictionRulesError
from ._dynamics import Dynamics
from ._engine import Outcome
from ._protocol import CONSOLIDATION_RATE, PRELOAD, UNBALANCED_TOL, _Clock, _control, consolidate

__all__ = ["frictionless_compression", "compress_to", "PREPARATION_INERTIAL_NUMBER"]

#: Inertial number of a preparation's strain rate (a compression the grains follow
#: quasi-statically; the grains move by FIRE, :mod:`._engine`: only the end state matters).
PREPARATION_INERTIAL_NUMBER = 1e-3


class _Cloud(NamedTuple):
    """Grains as :class:`Dynamics` reads an assembly: one frictionless contact model."""

    positions: np.ndarray
    radii: np.ndarray
    cell: np.ndarray
    model: object
    reference_axis: tuple = (1.0, 0.0, 0.0)

    @property
    def dim(self) -> int:
        return self.positions.shape[1]


def _engine(positions, radii, cell, kn: float, density: float):
    from ...contact import ContactModel
    from ...laws import Coulomb
    sample = _Cloud(np.asarray(positions, float), np.asarray(radii, float),
                    np.asarray(cell, float), ContactModel(Coulomb(0.0), kn=kn, kt=kn))
    dyn = Dynamics(sample, density=density, damping=0.0)  # frictionless stages move by FIRE
    return dyn, dyn.init()


def _rate(radii, density: float, pressure: float) -> float:
    return PREPARATION_INERTIAL_NUMBER / (2.0 * float(np.mean(radii)) * math.sqrt(density / pressure))


def _result(dyn, state):
    d = dyn.dim
    H = state.cell.H[:d, :d].copy()
    x = state.grains.x[:, :d].copy()
    return x, H


def frictionless_compression(positions, radii, cell, kn: float, pressure: float, *,
                             density: float = 1.0,
                             unbalanced_tol: float = UNBALANCED_TOL, report=None,
                             name: str = "consolidation",
                             preload: float = PRELOAD) -> tuple[np.ndarray, np.ndarray]:
    """Compress frictionless grains (normal springs ``kn``) until they carry the isotropic
    ``pressure`` in equilibrium (module docstring), by way of ``preload`` times it (1: from
    below; :func:`._protocol.consolidate`). Returns ``(positions, cell)``; ``report(text)``,
    when given, hears how the compression goes (its stage called ``name``)."""
    dyn, state = _engine(positions, radii, cell, kn, density)
    progress = None if report is None else _Report(report)
    state, _ = consolidate(dyn, state, pressure, _rate(radii, density, pressure), True, progress,
                           unbalanced_tol=unbalanced_tol, name=name, preload=preload)
    return _result(dyn, state)


def compress_to(positions, radii, cell, solid_fraction: float, *, kn: float = 1.0,
                density: float = 1.0):
    """Compress the cell isotropically (every normal strain at the same rate) to the
    ``solid_fraction``, then hold it until the grains' overlaps are gone (a packing below
    jamming carries no stress). Returns ``(positions, cell)``."""
    dyn, state = _engine(positions, radii, cell, kn, density)
    d = dyn.dim
    r = np.asarray(radii, float)
    solid = float(np.sum(np.pi * r**2 if d == 2 else 4.0 / 3.0 * np.pi * r**3))
    volume = abs(float(np.linalg.det(np.asarray(cell, float))))
    strain = math.log(solid / (solid_fraction * volume)) / -d  # compression positive, per axis
    pressure = 1e-4 * kn / (2.0 * float(r.mean()))
    rate = _rate(r, density, pressure) * CONSOLIDATION_RATE
    from .._solver import components
    comps = components(d)
    diag = np.array([a == b for a, b in comps], dtype=float)
    zero = np.zeros(len(comps))
    compress = _control(np.zeros(len(comps)), zero, zero, diag * rate, strain / rate, rate,
                        pressure, False, d)
    clock = _Clock()
    while True:
        state, outcome, _ = clock.run(dyn, state, compress, strain / rate)
        if outcome == Outcome.REACHED:
            break
    hold = _control(np.zeros(len(comps)), zero, zero, zero, 0.0, rate, pressure, False, d)
    for _ in range(10_000):
        if int(state.meters[0]["closed"]) == 0:
            return _result(dyn, state)
        state, _, _ = clock.run(dyn, state, hold, math.inf)
    raise FrictionRulesError(f"solid_fraction = {solid_fraction!r} violates: below jamming (the "
                             "grains still overlap after the compression)")


class _Report:
    """A progress callback's ``phase`` onto a ``report(text)`` function."""

    def __init__(self, report):
        self.phase = report
