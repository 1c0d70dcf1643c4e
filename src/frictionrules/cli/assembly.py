"""``frictionrules assembly CONFIG.toml --out run.h5``: load a grain assembly (sample, laws,
loading from TOML), writing the HDF5 run file as the run goes; a run file that exists is
resumed. ``method = "dem"`` in ``[loading]`` runs the dynamic engine; ``--engine lammps``
(or ``engine = "lammps"`` in ``[loading]``) runs the same test in LAMMPS on ``--ranks`` MPI
ranks (no run file: LAMMPS's files go to ``--lammps-dir``, where the same command resumes
from the last restart file of ``--restart-every``). With seeds (``--seeds`` or
``[sample] seeds``) an ensemble of random samples runs (``_ensemble``), ``--out`` its run
folder."""

from __future__ import annotations

import math

from ._common import add_quiet, finite_float, positive_int


def register(sub) -> None:
    p = sub.add_parser(
        "assembly", help="triaxial test of a grain assembly with a law at every contact (TOML)",
        description="Read [sample] (lattice or random packing), [model] (kn, kt, [model.law]) and "
                    "[loading] (kind, pressure, axial_strain, increments; or method = \"dem\" and "
                    "the dynamic engine's options) from CONFIG.toml, run the test, write every "
                    "increment (record) to the HDF5 run file (--out; an existing file of the same "
                    "run resumes) and print the peak. With seeds (--seeds or [sample] seeds), an "
                    "ensemble: one run per seed in the folder --out, the means with their 95 % "
                    "confidence intervals printed and written. --engine lammps runs the dynamic "
                    "test in LAMMPS on --ranks MPI ranks instead (docs/assembly.md, \"LAMMPS\").",
        epilog="example: frictionrules assembly examples/assembly_fcc.toml --out fcc.h5 --figure fcc.png")
    p.add_argument("config", metavar="CONFIG.toml", help="run description")
    p.add_argument("--out", metavar="RUN.h5", help="HDF5 run file (.h5, .hdf5); with seeds, a "
                   "folder: one run file per seed and the summary (summary.csv, summary.json); "
                   "required but with --engine lammps, which keeps its files in --lammps-dir")
    p.add_argument("--engine", choices=("frictionrules", "lammps"),
                   help="method \"dem\": our engine (the default) or the same test in LAMMPS "
                   "(overrides engine in [loading]; implies method = \"dem\")")
    p.add_argument("--ranks", type=positive_int, metavar="N",
                   help="--engine lammps: MPI ranks (mpirun -np N; overrides ranks in [loading])")
    p.add_argument("--lammps-dir", metavar="FOLDER",
                   help="--engine lammps: keep LAMMPS's files (input, data, records, log) here "
                   "(a temporary folder otherwise); the same command again reads a finished "
                   "run back and resumes an interrupted one from its last restart file")
    p.add_argument("--restart-every", type=finite_float, metavar="STRAIN",
                   help="--engine lammps: a restart file of the shear every STRAIN of axial "
                   "strain (a whole number of record_every; overrides restart_every in "
                   "[loading]), from which the same command resumes")
    p.add_argument("--preload", type=finite_float, metavar="X",
                   help="the frictionless consolidation settles first at X times the pressure, "
                        "then is unloaded to it (X >= 1; 1: compressed from below, as YADE; "
                        "default 10; overrides preload in [loading])")
    p.add_argument("--figure", metavar="FILE", help="stress ratio and volumetric strain against "
                   "axial strain; method \"dem\": also the coordination, the sliding fraction and "
                   "the force network at the last record (.png, .svg, .pdf)")
    p.add_argument("--vtk", metavar="FOLDER", help="method \"dem\": grains, contacts and cell at "
                   "every record as VTK files for ParaView (grains.pvd, contacts.pvd, cell.pvd)")
    p.add_argument("--vtk-every", type=positive_int, default=1, metavar="N",
                   help="write every N-th record to --vtk (the first and the last always)")
    p.add_argument("--max-time", type=finite_float, metavar="SECONDS",
                   help="stop after this time (the file keeps every finished increment or record); "
                        "with seeds, the time of the whole ensemble (runs not started are "
                        "started by the next call)")
    p.add_argument("--seeds", type=seed_list, metavar="S1,S2,...",
                   help="an ensemble: the random sample of [sample] with each of these seeds "
                        "(instead of [sample] seeds); prints and writes the means of the peak and "
                        "critical friction angles, the final volumetric strain, coordination and "
                        "sliding fraction with their 95 %% confidence intervals")
    where = p.add_mutually_exclusive_group()
    where.add_argument("--workers", type=positive_int, default=None, metavar="N",
                       help="an ensemble's runs on a local Dask cluster of N worker processes "
                            "(needs the extra frictionrules[dask])")
    where.add_argument("--scheduler", metavar="ADDRESS",
                       help="an ensemble's runs on the Dask cluster whose scheduler is at ADDRESS "
                            "(tcp://host:8786)")
    add_quiet(p)
    p.set_defaults(run=run)


def seed_list(text: str) -> list:
    """argparse type: comma-separated distinct integers >= 0 (``1,2,3``)."""
    import argparse
    try:
        seeds = [int(t) for t in text.split(",")]
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} violates: comma-separated integers "
                                         "(1,2,3)") from None
    if any(s < 0 for s in seeds) or len(set(seeds)) != len(seeds):
        raise argparse.ArgumentTypeError(f"{text!r} violates: distinct integers >= 0")
    return seeds


def run(args) -> int:
    from .._output import FIGURE_SUFFIXES, check_folder, check_output
    from .._threads import prefer_openmp
    from ..assembly import read_samples, triaxial
    from ..errors import FrictionRulesError, check_scalar
    from . import _common

    figure = check_output(args.figure, FIGURE_SUFFIXES, name="--figure") if args.figure else None
    vtk = check_folder(args.vtk, name="--vtk") if args.vtk else None
    if args.preload is not None:
        check_scalar("--preload", args.preload, lo=1.0)
    if args.seeds is not None or _lists_seeds(args.config):
        if (args.engine == "lammps" or args.ranks is not None or args.lammps_dir is not None
                or args.restart_every is not None):
            raise FrictionRulesError("--engine lammps violates: not with seeds (an ensemble runs "
                                     "our engine; run LAMMPS once per sample)")
        if args.out is None:
            raise FrictionRulesError("--out is required (with seeds: the ensemble's run folder)")
        from ._ensemble import run_ensemble
        return run_ensemble(args, figure)
    if args.workers or args.scheduler:
        raise FrictionRulesError("--workers/--scheduler: constraint: an ensemble (--seeds or "
                                 "[sample] seeds)")
    prefer_openmp()  # this process runs the engine and does not fork
    with _common.progress(args, "assembly", unit="increments") as bar:
        bar.phase("preparing the sample")
        (assembly,), _, loading = read_samples(args.config, progress=bar)
        _common.with_preload(args, loading)
        lammps = _engine_options(args, loading)
        out = None
        if lammps:
            if args.out is not None:
                raise FrictionRulesError(f"--out = {args.out!r} violates: not with --engine "
                                         "lammps (run files hold our engine's state; LAMMPS "
                                         "keeps its files in --lammps-dir)")
        elif args.out is None:
            raise FrictionRulesError("--out is required (the HDF5 run file; --engine lammps "
                                     "keeps its files in --lammps-dir instead)")
        else:
            out = check_output(args.out, (".h5", ".hdf5"))
        dem = loading.get("method", "implicit") == "dem"
        if vtk is not None and not dem:
            raise FrictionRulesError(f"--vtk = {args.vtk!r} needs method = \"dem\" in [loading] of "
                                     f"{args.config} (the records of the dynamic engine)")
        if dem:
            bar.unit = "records"
            bar.phase("")  # the engine names its own stages
        else:
            bar(0, loading.get("increments", 100))
        if out is not None:
            loading["run_file"] = out
        result = triaxial(assembly, max_time=args.max_time, progress=bar, **loading)
    if dem:
        print(_dem_summary(assembly, result))
    else:
        print(f"{assembly.size} grains, {len(result.converged) - 1} increments ({result.message}); "
              f"{_strength(result)}; final volumetric strain {result.volumetric_strain[-1]:.6g}")
    if out is not None:
        print(f"wrote {out}")
    elif args.lammps_dir is not None:
        print(f"LAMMPS's files in {args.lammps_dir}")
    if figure is not None:
        _figure(args, result, assembly, figure, dem)
        print(f"wrote {figure}")
    if vtk is not None:
        from ..assembly import write_vtk
        files = write_vtk(result, vtk, every=args.vtk_every, radii=assembly.radii)
        print(f"wrote {', '.join(str(f) for f in files)}")
    return _exit_code(result, dem)


def _lists_seeds(config) -> bool:
    """Whether the TOML file's [sample] lists seeds (an ensemble)."""
    from .._toml import load_toml
    sample = load_toml(config).get("sample", {})
    return isinstance(sample, dict) and "seeds" in sample


def _engine_options(args, loading: dict) -> bool:
    """``--engine``, ``--ranks``, ``--lammps-dir`` into the keyword arguments of ``triaxial``
    (the options override [loading]); True for the LAMMPS engine."""
    from ..errors import FrictionRulesError
    if args.engine is not None:
        loading["engine"] = args.engine
        if args.engine == "lammps":
            if loading.get("method", "dem") != "dem":
                raise FrictionRulesError(f"--engine lammps violates: method = \"dem\" in "
                                         f"[loading] of {args.config} (method = "
                                         f"{loading['method']!r})")
            loading["method"] = "dem"
    lammps = loading.get("engine", "frictionrules") == "lammps"
    for name, value in (("--ranks", args.ranks), ("--lammps-dir", args.lammps_dir),
                        ("--restart-every", args.restart_every)):
        if value is not None and not lammps:
            raise FrictionRulesError(f"{name} = {value!r} violates: an option of --engine lammps")
    if args.ranks is not None:
        loading["ranks"] = args.ranks
    if args.lammps_dir is not None:
        loading["lammps_dir"] = args.lammps_dir
    if args.restart_every is not None:
        if not args.restart_every > 0:
            raise FrictionRulesError(f"--restart-every = {args.restart_every!r} violates: > 0 "
                                     "(axial strain between two restart files)")
        loading["restart_every"] = args.restart_every
    return lammps


def _exit_code(result, dem: bool) -> int:
    """1 for a run that did not finish its test, else 0."""
    if dem:
        # a run stopped (max_time) before its peak did not find the strength it was run for
        done = result.failed or result.message.startswith("completed")
        return 0 if result.converged[-1] and done else 1
    # a run that stopped at an increment that did not converge did not finish its test
    return 0 if result.converged[-1] else 1


def _figure(args, result, assembly, figure, dem: bool) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from .._output import write_figure
    from . import _common
    if dem:
        from ..plot.assembly import plot_dem_run
        fig = plot_dem_run(result)[0, 0].figure
    else:
        from ..plot.assembly import plot_response
        fig, axes = plt.subplots(1, 2, figsize=(9, 3.6))
        plot_response(result, axes=axes)
        fig.tight_layout()
    write_figure(fig, figure, metadata=_common.metadata(args, model=assembly.model))
    plt.close(fig)


def _strength(result) -> str:
    """The peak, or how far the run came without one (never an infinite strength)."""
    if result.failed:
        return (f"peak σ1/σ3 = {result.peak_ratio:.6g}, friction angle "
                f"{result.peak_friction_angle:.4g} deg")
    good = result.converged
    reached = (f"axial strain {result.axial_strain[good][-1]:.6g} (largest σ1/σ3 "
               f"{result.stress_ratio[good].max():.6g})")
    if result.message.startswith("completed"):
        return f"no peak up to {reached}"
    return f"no peak reached before the run stopped at {reached}"


def _angle(ratio: float) -> float:
    """Mobilized friction angle (degrees) of σ1/σ3: sin φ = (R - 1)/(R + 1)."""
    return math.degrees(math.asin((ratio - 1) / (ratio + 1)))


def _dem_summary(assembly, result) -> str:
    """A dynamic run's lines: the peak (or how far the run came without one), the state at its
    end, the energy balance."""
    head = f"{assembly.size} grains, {len(result.time) - 1} records ({result.message})"
    if not result.converged[-1]:
        return f"{head}; no peak reached before the run stopped during the consolidation"
    if result.failed:
        strength = (f"peak σ1/σ3 = {result.peak_ratio:.6g} (running mean), friction angle "
                    f"{result.peak_friction_angle:.4g} deg")
    else:
        reached = (f"axial strain {result.axial_strain[-1]:.6g} (largest σ1/σ3 "
                   f"{result.stress_ratio.max():.6g})")
        strength = (f"no peak up to {reached}" if result.message.startswith("completed")
                    else f"no peak reached before the run stopped at {reached}")
    if len(result.time) == 1:
        return f"{head}; {strength}"
    z = result.coordination[-1]
    zm = result.coordination_without_rattlers[-1]
    sliding = result.sliding_fraction[-1]
    text = (f"{head}; {strength}\n"
            f"at axial strain {result.axial_strain[-1]:.6g}: σ1/σ3 {result.stress_ratio[-1]:.6g} "
            f"(friction angle {_angle(result.stress_ratio[-1]):.4g} deg), volumetric strain "
            f"{result.volumetric_strain[-1]:.6g}, Z {z:.4g} ({zm:.4g} without rattlers), "
            + (f"sliding fraction {sliding:.3g}" if math.isfinite(sliding) else
               "no sliding fraction (not offered by the pair style)"))
    if result.energy is None:
        return text
    return (f"{text}\n"
            f"energy balance: error {100 * result.energy.relative_error:.3g} % of the boundary work")
