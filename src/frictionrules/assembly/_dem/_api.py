"""The dynamic engine's loading tests, as ``triaxial`` and ``load_cell`` call them."""

from __future__ import annotations

import numpy as np

from ...errors import check_scalar
from .._consolidation import consolidation_of
from ._protocol import mixed_stage, run_test, triaxial_stage

__all__ = ["dem_triaxial", "dem_load_cell", "check_dem_options"]


def check_dem_options(*, inertial_number, damping, density, record_every, peak_window) -> dict:
    """The dynamic engine's own arguments, checked."""
    return dict(inertial_number=check_scalar("inertial_number", inertial_number, lo=0.0, lo_open=True, hi=0.1),
                damping=check_scalar("damping", damping, lo=0.0, hi=1.0, hi_open=True),
                density=check_scalar("density", density, lo=0.0, lo_open=True),
                record_every=check_scalar("record_every", record_every, lo=0.0, lo_open=True),
                peak_window=check_scalar("peak_window", peak_window, lo=0.0))


def dem_triaxial(assembly, kind: str, *, pressure: float, axial_strain: float, failure_slope: float,
                 consolidation: str, preload: float, progress, max_time, run_file, cell: str,
                 **dem) -> object:
    """``triaxial(..., method="dem")`` (arguments checked by the caller but ``dem``)."""
    opts = check_dem_options(**dem)  # record_every <= axial_strain: checked by check_triaxial
    options = dict(kind=kind, method="dem", cell=cell, pressure=pressure, axial_strain=axial_strain,
                   failure_slope=failure_slope, consolidation=consolidation_of(assembly, consolidation),
                   preload=preload, **opts)
    d = assembly.dim
    return run_test(assembly, kind, lambda dyn, rate: triaxial_stage(kind, d, pressure, axial_strain, rate, cell),
                    options, progress, max_time, run_file)


def dem_load_cell(assembly, control: dict, *, free, start, end, strain, pressure: float,
                  failure_slope: float, consolidation: str, preload: float, progress, max_time,
                  run_file, **dem):
    """``load_cell(..., method="dem")``: the control already parsed into ``free``, ``start``,
    ``end`` (stresses) and ``strain`` (totals) over the components."""
    opts = check_dem_options(**dem)
    options = dict(kind="mixed", method="dem", control={k: list(v) for k, v in control.items()},
                   pressure=pressure, failure_slope=failure_slope,
                   consolidation=consolidation_of(assembly, consolidation), preload=preload,
                   **opts)

    def spec(dyn, rate):
        return mixed_stage(free, start, end, strain, rate, dyn.k_max, float(np.mean(assembly.radii)))
    return run_test(assembly, "mixed", spec, options, progress, max_time, run_file)
