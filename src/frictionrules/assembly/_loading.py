r"""Quasi-static loading of an assembly: mixed stress/strain control of the cell, step cutting,
the triaxial tests.

Every component of the cell's symmetric strain is either strain-controlled (its increment is
prescribed) or stress-controlled (the stress it is conjugate to is prescribed at the end of the
increment). An increment that does not converge is cut in two (the stress targets halfway), up
to ``max_cuts`` times; a run never accepts an unconverged increment.
"""

from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass

import numpy as np

from ..errors import FrictionRulesError, check_scalar
from ._contacts import ContactSet, branches, build, embed, skin
from ._consolidation import PRELOAD, check_preload, consolidation_of
from ._geometry import Assembly
from ._results import SampleState, TriaxialResult, snapshot
from ._solver import CELLS, components, move, solve_increment, stress_of, triaxial_free

__all__ = ["Control", "triaxial", "check_triaxial", "load_cell", "initial_state", "run", "KINDS",
           "METHODS", "ENGINES"]

#: The triaxial tests of :func:`triaxial`.
KINDS = ("axisymmetric", "plane_strain", "biaxial")
#: The methods of :func:`triaxial` and :func:`load_cell`.
METHODS = ("implicit", "dem")
#: The engines of :func:`triaxial`'s method "dem".
ENGINES = ("frictionrules", "lammps")


@dataclass(frozen=True)
class Control:
    """One increment of mixed control of the cell (arrays over :func:`components`).

    ``free[k]`` True: the compression-positive stress ``target[k]`` is reached at the end of
    the increment; False: the compression-positive strain grows by ``strain[k]``.
    """

    free: tuple
    target: tuple
    strain: tuple


def initial_state(assembly: Assembly) -> SampleState:
    """The sample as built: contacts found with the tolerance, zero forces, zero strain."""
    contacts = build(assembly, assembly.positions, assembly.cell)
    d = assembly.dim
    return SampleState(assembly.positions, assembly.cell, contacts, np.zeros((d, d)), np.zeros((d, d)))


def prepared_state(assembly: Assembly, pressure: float, report=None,
                   preload: float = PRELOAD) -> SampleState:
    """The sample compressed without friction to ``pressure`` by way of ``preload`` times it
    (its normal springs balanced, no tangential force): the start of a random sample's
    consolidation. ``report(text)``, when given, hears how the compression goes."""
    from ._dem import frictionless_compression
    base = build(assembly, assembly.positions, assembly.cell)
    kns = {m.kn for m in base.models}
    kn = float(np.mean(sorted(kns)))
    x, h = frictionless_compression(assembly.positions, assembly.radii, assembly.cell, kn, pressure,
                                    report=report, preload=preload)
    contacts = build(assembly, x, h, check_overlap=False)
    force = snapshot(contacts).force
    l3 = embed(branches(x, h, contacts.i, contacts.j, contacts.shift))
    d = assembly.dim
    stress = stress_of(force, contacts.frames, l3, float(np.linalg.det(h)), d)
    return SampleState(x, h, contacts, stress, np.zeros((d, d)))


def _check_laws(assembly: Assembly, state: SampleState) -> None:
    if state.contacts.size == 0:
        raise FrictionRulesError("the assembly has no contacts (every gap exceeds tolerance = "
                                 f"{assembly.tolerance!r}); constraint: grains in contact")


def _value(stress: np.ndarray, d: int) -> np.ndarray:
    return np.array([stress[a, b] for a, b in components(d)])


def _attempt(assembly, state: SampleState, control: Control, cuts: int, rtol: float):
    """Advance by one control increment, cutting it where Newton fails. Returns (state, works,
    converged)."""
    d = assembly.dim
    free = np.asarray(control.free, dtype=bool)
    target = np.asarray(control.target, dtype=float)
    dstrain = np.asarray(control.strain, dtype=float)
    out = solve_increment(state.positions, assembly.radii, state.cell, state.contacts, free,
                          -dstrain, target, rtol=rtol, gap=assembly.tolerance,
                          max_move=0.5 * skin(assembly))
    if out.converged:
        return _advance(assembly, state, out), (out.contact_work, out.boundary_work), True
    if cuts <= 0:
        return state, (0.0, 0.0), False
    now = _value(state.stress, d)
    half = Control(control.free, tuple(np.where(free, 0.5 * (now + target), 0.0)), tuple(0.5 * dstrain))
    mid, w1, ok = _attempt(assembly, state, half, cuts - 1, rtol)
    if not ok:
        return state, (0.0, 0.0), False
    rest = Control(control.free, control.target, tuple(0.5 * dstrain))
    end, w2, ok = _attempt(assembly, mid, rest, cuts - 1, rtol)
    if not ok:
        return state, (0.0, 0.0), False
    return end, (w1[0] + w2[0], w1[1] + w2[1]), True


def _advance(assembly, state: SampleState, out) -> SampleState:
    positions, cell = move(state.positions, state.cell, out)
    c = state.contacts
    moved = ContactSet(c.i, c.j, c.shift, c.group, c.models, out.states, c.frames)
    contacts = build(assembly, positions, cell, moved)
    contacts = _with_force(contacts, moved, out)
    return SampleState(positions, cell, contacts, out.stress, state.strain - 0.5 * (
        out.strain_increment + out.strain_increment.T))


def _with_force(contacts: ContactSet, moved: ContactSet, out) -> ContactSet:
    """Attach the increment's forces and statuses (by contact key) for the snapshot."""
    index = {k: c for c, k in enumerate(moved.keys())}
    force = np.zeros((contacts.size, 3))
    status = np.full(contacts.size, 2, dtype=np.int64)
    for c, k in enumerate(contacts.keys()):
        o = index.get(k)
        if o is not None:
            force[c], status[c] = out.force[o], out.status[o]
    return dataclasses.replace(contacts, force=force, status=status)


def run(assembly: Assembly, state: SampleState, controls, *, rtol: float = 1e-10, max_cuts: int = 8,
        progress=None, on_increment=None, max_time: float | None = None):
    """Apply the controls one after the other from ``state``.

    Returns ``(rows, ended, limit_point)``: one row ``(state, works, converged)`` per increment
    done, how the run ended, and whether it ended at a limit point under stress control.
    """
    rows = []
    start = time.monotonic()
    total = len(controls)
    for k, control in enumerate(controls):
        new, works, ok = _attempt(assembly, state, control, max_cuts, rtol)
        rows.append((new, works, ok))
        if on_increment is not None:
            on_increment(k, new, works, ok)
        if progress is not None:
            progress(k + 1, total)
        if not ok:
            pure_stress = not np.any(np.asarray(control.strain)[~np.asarray(control.free)])
            if pure_stress:
                return rows, (f"limit point: no equilibrium under the stress of increment {k + 1} "
                              f"(after {max_cuts} cuts)"), True
            return rows, f"increment {k + 1} did not converge after {max_cuts} cuts", False
        state = new
        if max_time is not None and time.monotonic() - start > max_time and k + 1 < total:
            return rows, f"stopped after {k + 1} increments: max_time = {max_time!r} s reached", False
    return rows, "completed", False


def _consolidation_controls(d: int, pressure: float, consolidation: int) -> list:
    """The consolidation's increments: the normal stresses to the pressure in ``consolidation``
    equal steps, the cell kept rectangular."""
    comps = components(d)
    diag = np.array([a == b for a, b in comps])
    return [Control(tuple(bool(b) for b in diag),
                    tuple(np.where(diag, pressure * (k + 1) / consolidation, 0.0)),
                    tuple([0.0] * len(comps))) for k in range(consolidation)]


def _shearing_controls(kind: str, d: int, pressure: float, axial_strain: float, increments: int,
                       cell: str) -> list:
    """A triaxial test's shearing increments: the axial strain in equal steps, the lateral
    stresses held at the pressure, the cell's shear as ``cell`` says."""
    comps = components(d)
    diag = np.array([a == b for a, b in comps])
    axial = 1 if d == 2 else 2
    free = triaxial_free(kind, d, cell)
    target = np.where(diag, pressure, 0.0)
    step = np.zeros(len(comps))
    step[comps.index((axial, axial))] = axial_strain / increments
    return [Control(tuple(free), tuple(np.where(free, target, 0.0)), tuple(step))] * increments


def check_cell(cell: str) -> None:
    if cell not in CELLS:
        raise FrictionRulesError(f"cell = {cell!r} violates: one of {', '.join(CELLS)}")


def check_method(method: str) -> None:
    if method not in METHODS:
        raise FrictionRulesError(f"method = {method!r} violates: one of {', '.join(METHODS)}")


def check_engine(engine: str, method: str, run_file=None, ranks=1, lammps_dir=None,
                 restart_every=None) -> None:
    """The engine of a test: ours, or LAMMPS (``method="dem"`` only, no run file); LAMMPS's
    own options are refused with ours rather than ignored."""
    if engine not in ENGINES:
        raise FrictionRulesError(f"engine = {engine!r} violates: one of {', '.join(ENGINES)}")
    if engine != "lammps":
        for name, value, default in (("ranks", ranks, 1), ("lammps_dir", lammps_dir, None),
                                     ("restart_every", restart_every, None)):
            if value != default:
                raise FrictionRulesError(f"{name} = {value!r} violates: {default!r} for engine = "
                                         f"{engine!r} (an option of engine = 'lammps')")
        return
    if engine == "lammps" and method != "dem":
        raise FrictionRulesError(f"method = {method!r} violates: 'dem' for engine = 'lammps'")
    if engine == "lammps" and run_file is not None:
        raise FrictionRulesError(f"run_file = {str(run_file)!r} violates: None for engine = "
                                 "'lammps' (run files hold our engine's state; LAMMPS keeps its "
                                 "files in lammps_dir)")
    if restart_every is not None:
        check_scalar("restart_every", restart_every, lo=0.0, lo_open=True)


def _check_common(failure_slope, max_time) -> None:
    check_scalar("failure_slope", failure_slope, lo=0.0, lo_open=True, hi=1.0)
    if max_time is not None:
        check_scalar("max_time", max_time, lo=0.0, lo_open=True)


def check_kind(kind: str, dim: int) -> None:
    if kind not in KINDS:
        raise FrictionRulesError(f"kind = {kind!r} violates: one of {', '.join(KINDS)}")
    if (kind == "biaxial") != (dim == 2):
        want = "biaxial" if dim == 2 else "axisymmetric or plane_strain"
        raise FrictionRulesError(f"kind = {kind!r} violates: {want} for an assembly of dim = {dim}")


def check_triaxial(assembly: Assembly, kind: str, *, pressure: float, axial_strain: float,
                   increments, consolidation_increments, rtol, max_cuts, failure_slope, max_time,
                   consolidation: str, method: str, inertial_number, damping, density,
                   record_every, peak_window, cell: str, engine: str = "frictionrules",
                   ranks=1, lammps_dir=None, run_file=None,
                   restart_every=None, preload: float = PRELOAD) -> tuple[float, float]:
    """The arguments of :func:`triaxial` checked as it checks them before it runs (the options
    of the method that runs; those of the other are ignored, as by :func:`triaxial`); returns
    the pressure and the axial strain as floats. :func:`ensemble` checks every run with it
    before any runs."""
    check_kind(kind, assembly.dim)
    check_cell(cell)
    p = check_scalar("pressure", pressure, lo=0.0, lo_open=True)
    a = check_scalar("axial_strain", axial_strain, lo=0.0, lo_open=True, hi=0.5)
    check_method(method)
    check_engine(engine, method, run_file, ranks, lammps_dir, restart_every)
    _check_common(failure_slope, max_time)
    check_preload(preload, consolidation_of(assembly, consolidation))
    if method == "dem":
        from ._dem import check_dem_options
        opts = check_dem_options(inertial_number=inertial_number, damping=damping,
                                 density=density, record_every=record_every,
                                 peak_window=peak_window)
        if opts["record_every"] > a:
            raise FrictionRulesError(f"record_every = {opts['record_every']!r} violates: at most "
                                     f"axial_strain = {a!r}")
        if restart_every is not None:
            from ._lammps._runner import restart_records
            restart_records(restart_every, opts["record_every"], a)
        return p, a
    for name, value, lo in (("increments", increments, 1), ("consolidation_increments",
                                                             consolidation_increments, 1),
                            ("max_cuts", max_cuts, 0)):
        if not isinstance(value, (int, np.integer)) or value < lo:
            raise FrictionRulesError(f"{name} = {value!r} violates: an integer >= {lo}")
    check_scalar("rtol", rtol, lo=0.0, lo_open=True, hi=1e-2)
    return p, a


def triaxial(assembly: Assembly, kind: str, *, pressure: float, axial_strain: float = 0.01,
             increments: int = 100, consolidation_increments: int = 1, rtol: float = 1e-10,
             max_cuts: int = 8, failure_slope: float = 1e-2, progress=None,
             max_time: float | None = None, run_file=None,
             consolidation: str = "auto", method: str = "implicit",
             inertial_number: float = 4e-4, damping: float = 0.2, density: float = 1.0,
             record_every: float = 1e-3, peak_window: float = 2.5e-3,
             cell: str = "rectangular", engine: str = "frictionrules", ranks: int = 1,
             lammps_dir=None, restart_every: float | None = None,
             preload: float = PRELOAD) -> TriaxialResult:
    r"""Consolidate the sample to the isotropic ``pressure``, then compress it along the axis.

    Two methods: "implicit" (the default) follows equilibrium increment by increment (Newton's
    method with the laws' consistent tangents): exact for lattices, elastic moduli and small
    strains, and stops where a random packing has no neighbouring equilibrium. "dem" integrates
    the grains' damped dynamics (the compiled dynamic engine, ``docs/assembly.md``, "Dynamic
    runs") at the strain rate of the inertial number: random packings to large strain.

    Parameters
    ----------
    assembly : Assembly
        The sample (its contacts' laws must have the capability ``"symbolic"``, checked by
        ``ContactModel``).
    kind : {"axisymmetric", "plane_strain", "biaxial"}
        "axisymmetric": ``σxx = σyy = pressure`` held, ``εzz`` driven; "plane_strain":
        ``εyy = 0``, ``σxx = pressure`` held, ``εzz`` driven; "biaxial" (2-D):
        ``σxx = pressure`` held, ``εyy`` driven.
    pressure : float
        Confining stress (compression positive, force/length² in 3-D, force/length in 2-D).
    axial_strain : float
        Total axial strain of the shearing stage (compression positive).
    increments : int
        Equal increments of axial strain.
    consolidation_increments : int
        Increments of the isotropic stage (stress-controlled, from zero stress).
    consolidation : {"auto", "stress", "frictionless"}
        "stress": the isotropic stage starts from the sample as built; "frictionless": the
        sample is first compressed without friction to ``pressure`` (normal springs ``kn``
        balanced, as DEM prepares samples), then the isotropic stage runs with the laws;
        "auto": "frictionless" for grains of unequal radii in a rectangular cell (random
        packings), "stress" otherwise.
    preload : float
        "frictionless": the compression first settles at ``preload`` times the pressure, then
        is unloaded to it (a multiple >= 1; 1: compressed from below to the pressure, as YADE's
        ``PeriTriaxController`` does). Unloaded from 10 p (the default), a packing settles in
        fewer steps, but dilates more in shear than one compressed from below
        (``docs/assembly.md``, "Dynamic runs"). A consolidation "stress" takes the default only.
    rtol : float
        Newton tolerance on the residual forces, moments and stresses, relative to the largest
        contact force (its moment, the virial).
    max_cuts : int
        Halvings of an increment that does not converge before the run stops.
    failure_slope : float
        The sample has failed where the slope of the stress ratio against the axial strain
        drops to ``failure_slope`` times its initial (elastic) slope or below: the peak or the
        plateau of a mechanism.
    progress : callable, optional
        ``progress(done, total)`` after every increment; where it also has a method
        ``phase(text)`` (as the command line's progress bar), the preparation of the sample
        (frictionless compression, consolidation) reports its stages through it.
    max_time : float, optional
        Stop after this many seconds (the increments done are kept).
    run_file : path, optional
        HDF5 run file (``.h5``) written as the run goes; a run whose file exists resumes from
        its last increment (:mod:`frictionrules.assembly` run files).
    method : {"implicit", "dem"}
        Quasi-static increments or the dynamic engine (above). "dem" ignores ``increments``,
        ``consolidation_increments``, ``rtol`` and ``max_cuts``.
    inertial_number : float
        "dem": ``I = ε̇ d √(ρ/p)`` of the axial strain rate ``ε̇`` (``d`` the mean diameter);
        quasi-static below about 1e-3.
    damping : float
        "dem": Cundall's non-viscous damping coefficient, in [0, 1).
    density : float
        "dem": the grains' density (mass per volume; per area for disks).
    record_every : float
        "dem": axial strain between two records (the rows of the result).
    peak_window : float
        "dem": half-width (axial strain) of the running mean of σ1/σ3 whose largest value is the
        peak (the dynamic ratio fluctuates about its quasi-static value); 0 for none.
    cell : {"rectangular", "flexible"}
        The shearing stage's cell: "rectangular" holds its shear strains at zero (rigid smooth
        platens; YADE's ``PeriTriaxController``, most periodic DEM studies); "flexible" holds
        its shear stresses at zero (the closed forms of regular arrays, Thornton's and Rowe's,
        assume it: an array that slides unsymmetrically carries shear stresses in a rectangular
        cell). :func:`load_cell` frees any component.
    engine : {"frictionrules", "lammps"}
        "dem": our compiled engine, or the same test in LAMMPS (``docs/assembly.md``,
        "LAMMPS"): its files written (:func:`write_lammps_triaxial`), LAMMPS run on ``ranks``
        MPI ranks, its records read back (:func:`read_lammps_triaxial`); the result's
        ``message`` names the engine and the differences of protocol. Spheres, a rectangular
        cell, "axisymmetric" or "plane_strain" only; no ``run_file``.
    ranks : int
        ``engine="lammps"``: MPI ranks (``mpirun -np ranks``).
    lammps_dir : path, optional
        ``engine="lammps"``: the folder of LAMMPS's files (kept); a temporary one otherwise.
        Called again with the same sample and options and the same folder, a run that
        finished there is read back (nothing runs) and one that was interrupted resumes from
        its last complete restart file (``restart_every``), as a run file resumes.
    restart_every : float, optional
        ``engine="lammps"``: axial strain between two restart files of the shear (a whole
        number of ``record_every``; :func:`write_lammps_triaxial`); none by default.

    Returns
    -------
    TriaxialResult
    """
    p, a = check_triaxial(assembly, kind, pressure=pressure, axial_strain=axial_strain,
                          increments=increments, consolidation_increments=consolidation_increments,
                          rtol=rtol, max_cuts=max_cuts, failure_slope=failure_slope,
                          max_time=max_time, consolidation=consolidation, method=method,
                          inertial_number=inertial_number, damping=damping, density=density,
                          record_every=record_every, peak_window=peak_window, cell=cell,
                          engine=engine, ranks=ranks, lammps_dir=lammps_dir, run_file=run_file,
                          restart_every=restart_every, preload=preload)
    preload = float(preload)
    if engine == "lammps":
        from ._lammps import lammps_triaxial
        return lammps_triaxial(assembly, kind, pressure=p, axial_strain=a, ranks=ranks,
                               lammps_dir=lammps_dir, progress=progress, max_time=max_time,
                               consolidation=consolidation, inertial_number=inertial_number,
                               damping=damping, density=density, record_every=record_every,
                               peak_window=peak_window, failure_slope=failure_slope, cell=cell,
                               restart_every=restart_every, preload=preload)
    if method == "dem":
        from ._dem import dem_triaxial
        return dem_triaxial(assembly, kind, pressure=p, axial_strain=a, failure_slope=failure_slope,
                            consolidation=consolidation, preload=preload, progress=progress,
                            max_time=max_time, run_file=run_file, inertial_number=inertial_number,
                            damping=damping, density=density, record_every=record_every,
                            peak_window=peak_window, cell=cell)
    consolidation = consolidation_of(assembly, consolidation)
    cons = _consolidation_controls(assembly.dim, p, int(consolidation_increments))
    shear = _shearing_controls(kind, assembly.dim, p, a, int(increments), cell)
    options = dict(kind=kind, cell=cell, pressure=p, axial_strain=a, increments=int(increments),
                   consolidation_increments=int(consolidation_increments), rtol=rtol,
                   max_cuts=int(max_cuts), failure_slope=failure_slope, consolidation=consolidation,
                   preload=preload)
    return _run_test(assembly, kind, cons, shear, options, progress, max_time, run_file)


def _run_test(assembly, kind, cons, shear, options, progress, max_time, run_file) -> TriaxialResult:
    rtol, max_cuts = options["rtol"], options["max_cuts"]
    writer, done = None, []
    if run_file is not None:
        from ._runfile import RunFile
        writer = RunFile.open(run_file, assembly, options)
        done = writer.rows()
    phase = getattr(progress, "phase", None) or (lambda text: None)
    if done:
        rows = done
        state = rows[-1][0]
    else:
        if options["consolidation"] == "frictionless":
            state0 = prepared_state(assembly, options["pressure"], report=phase,
                                    preload=options["preload"])
            cons = cons[-1:]  # at the pressure already: one increment brings in the laws
        else:
            state0 = initial_state(assembly)
        _check_laws(assembly, state0)
        phase(f"consolidation to pressure {options['pressure']:.6g}")
        rows_c, ended, limit = run(assembly, state0, cons, rtol=rtol, max_cuts=max_cuts)
        if not rows_c[-1][2]:
            raise FrictionRulesError(f"the sample could not be consolidated to pressure = "
                                     f"{options['pressure']!r}: {ended}")
        state = rows_c[-1][0]
        rows = [(state, (0.0, 0.0), True)]
        if writer is not None:
            writer.append(0, state, (0.0, 0.0), True)
    remaining = shear[len(rows) - 1:]
    start_count = len(rows) - 1

    def record(k, new, works, ok):
        if writer is not None:
            writer.append(start_count + k + 1, new, works, ok)

    def bar(done_, total):
        if progress is not None:
            progress(start_count + done_, len(shear))

    phase("")
    if remaining and rows[-1][2]:
        new_rows, ended, limit = run(assembly, state, remaining, rtol=rtol, max_cuts=max_cuts,
                                     progress=bar, on_increment=record, max_time=max_time)
        rows = rows + new_rows
    else:
        ended = "completed" if rows[-1][2] else "the run file ends at an increment that did not converge"
        limit = False
    if writer is not None:
        writer.close(ended)
    return collect(assembly, kind, rows, ended, limit, options["failure_slope"])


def collect(assembly, kind, rows, ended, limit, failure_slope) -> TriaxialResult:
    d = assembly.dim
    axial = 1 if d == 2 else 2
    stress = np.array([r[0].stress for r in rows])
    strain = np.array([r[0].strain for r in rows])
    eig = np.linalg.eigvalsh(stress)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(eig[:, 0] > 0, eig[:, -1] / np.where(eig[:, 0] > 0, eig[:, 0], 1.0), np.inf)
    ax = strain[:, axial, axial]
    ok = np.array([r[2] for r in rows])
    good = np.flatnonzero(ok)
    failed = False
    peak = math.inf
    if len(good) >= 3:
        slope = np.diff(ratio[good]) / np.where(np.diff(ax[good]) != 0, np.diff(ax[good]), np.nan)
        slope = slope[np.isfinite(slope)]
        if len(slope) >= 2 and slope[0] > 0:
            failed = bool(np.any(slope[1:] <= failure_slope * slope[0]))
    if failed:
        peak = float(ratio[good].max())
    angle = 90.0 if math.isinf(peak) else math.degrees(math.asin((peak - 1) / (peak + 1)))
    snaps = tuple(snapshot(r[0].contacts) for r in rows)
    coord = np.array([2 * np.count_nonzero(s.force[:, 2] > 0) / assembly.size for s in snaps])
    cw = np.array([r[1][0] for r in rows])
    bw = np.array([r[1][1] for r in rows])
    return TriaxialResult(kind, stress, strain, np.trace(strain, axis1=1, axis2=2), ax, ratio, peak,
                          angle, coord, snaps, ok, cw, bw, failed, bool(limit), ended, rows[-1][0])


_NAMES = {2: ("xx", "yy", "xy"), 3: ("xx", "yy", "zz", "yz", "xz", "xy")}


def load_cell(assembly: Assembly, control: dict, *, pressure: float, increments: int = 100,
              consolidation_increments: int = 1, rtol: float = 1e-10, max_cuts: int = 8,
              failure_slope: float = 1e-2, progress=None, max_time: float | None = None,
              run_file=None, consolidation: str = "auto", method: str = "implicit",
              inertial_number: float = 4e-4, damping: float = 0.2, density: float = 1.0,
              record_every: float = 1e-3, peak_window: float = 2.5e-3,
              preload: float = PRELOAD) -> TriaxialResult:
    """General mixed control of the cell: consolidate to ``pressure``, then drive any
    components of stress or strain.

    Parameters
    ----------
    control : dict
        Component name (``"xx", "yy", "zz", "yz", "xz", "xy"``; 2-D: ``"xx", "yy", "xy"``) →
        ``("stress", value)`` (the compression-positive stress reached linearly at the last
        increment) or ``("strain", value)`` (the compression-positive strain added in equal
        increments). Components not given hold their stress: ``pressure`` on the diagonal, 0
        off it. At least one component must be driven (a strain or a changing stress).

    The other parameters are those of :func:`triaxial`; the result's ``kind`` is "mixed" and its
    ``axial_strain`` the zz (2-D: yy) component. With ``method="dem"`` the largest driven strain
    runs at the rate of the inertial number and the others in proportion (a stress-only path
    at the stress rate of that elastic strain rate), a record every ``record_every`` of it.
    """
    d = assembly.dim
    names = _NAMES[d]
    p = check_scalar("pressure", pressure, lo=0.0, lo_open=True)
    if not isinstance(control, dict):
        raise FrictionRulesError(f"control = {control!r} violates: a dict component -> (kind, value)")
    comps = components(d)
    free = np.ones(len(comps), dtype=bool)
    target = np.array([p if a == b else 0.0 for a, b in comps])
    total = np.zeros(len(comps))
    for name, spec in control.items():
        if name not in names:
            raise FrictionRulesError(f"control key {name!r} violates: one of {', '.join(names)}")
        if not (isinstance(spec, (tuple, list)) and len(spec) == 2 and spec[0] in ("stress", "strain")):
            raise FrictionRulesError(f"control[{name!r}] = {spec!r} violates: ('stress', value) or "
                                     "('strain', value)")
        k = names.index(name)
        value = check_scalar(f"control[{name!r}]", spec[1])
        if spec[0] == "stress":
            target[k] = value
        else:
            free[k] = False
            total[k] = value
    start = np.array([p if a == b else 0.0 for a, b in comps])
    if not np.any(total[~free]) and np.allclose(target[free], start[free]):
        raise FrictionRulesError(f"control = {control!r} violates: at least one driven component "
                                 "(a nonzero strain or a stress other than the consolidation's)")
    check_method(method)
    preload = check_preload(preload, consolidation_of(assembly, consolidation))
    if method == "dem":
        _check_common(failure_slope, max_time)
        from ._dem import dem_load_cell
        return dem_load_cell(assembly, control, free=free, start=start, end=target, strain=total,
                             pressure=p, failure_slope=failure_slope, consolidation=consolidation,
                             preload=preload, progress=progress, max_time=max_time, run_file=run_file,
                             inertial_number=inertial_number, damping=damping, density=density,
                             record_every=record_every, peak_window=peak_window)
    if not isinstance(increments, (int, np.integer)) or increments < 1:
        raise FrictionRulesError(f"increments = {increments!r} violates: an integer >= 1")
    cons = _consolidation_controls(d, p, int(consolidation_increments))
    shear = [Control(tuple(free), tuple(np.where(free, start + (target - start) * (k + 1) / increments, 0.0)),
                     tuple(np.where(free, 0.0, total / increments))) for k in range(int(increments))]
    consolidation = consolidation_of(assembly, consolidation)
    options = dict(kind="mixed", control={k: list(v) for k, v in control.items()}, pressure=p,
                   increments=int(increments), consolidation_increments=int(consolidation_increments),
                   rtol=rtol, max_cuts=int(max_cuts), failure_slope=failure_slope,
                   consolidation=consolidation, preload=preload)
    return _run_test(assembly, "mixed", cons, shear, options, progress, max_time, run_file)
