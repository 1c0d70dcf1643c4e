"""``frictionrules assembly CONFIG.toml --out run.h5``: load a grain assembly (sample, laws,
loading from TOML), writing the HDF5 run file as the run goes; a run file that exists is
resumed."""

from __future__ import annotations

from ._common import add_quiet, finite_float


def register(sub) -> None:
    p = sub.add_parser(
        "assembly", help="triaxial test of a grain assembly with a law at every contact (TOML)",
        description="Read [sample] (lattice or random packing), [model] (kn, kt, [model.law]) and "
                    "[loading] (kind, pressure, axial_strain, increments) from CONFIG.toml, run "
                    "the test increment by increment, write every increment to the HDF5 run file "
                    "(--out; an existing file of the same run resumes) and print the peak. See "
                    "docs/assembly.md.",
        epilog="example: frictionrules assembly examples/assembly_fcc.toml --out fcc.h5 --figure fcc.png")
    p.add_argument("config", metavar="CONFIG.toml", help="run description")
    p.add_argument("--out", metavar="RUN.h5", required=True, help="HDF5 run file (.h5, .hdf5)")
    p.add_argument("--figure", metavar="FILE", help="stress ratio and volumetric strain against "
                   "axial strain (.png, .svg, .pdf)")
    p.add_argument("--max-time", type=finite_float, metavar="SECONDS",
                   help="stop after this time (the file keeps every finished increment)")
    add_quiet(p)
    p.set_defaults(run=run)


def run(args) -> int:
    from .._output import FIGURE_SUFFIXES, check_output
    from ..assembly import read_config, triaxial
    from . import _common

    out = check_output(args.out, (".h5", ".hdf5"))
    figure = check_output(args.figure, FIGURE_SUFFIXES, name="--figure") if args.figure else None
    with _common.progress(args, "assembly", unit="increments") as bar:
        bar.phase("preparing the sample")
        assembly, loading = read_config(args.config)
        bar(0, loading.get("increments", 100))
        result = triaxial(assembly, run_file=out, max_time=args.max_time, progress=bar, **loading)
    print(f"{assembly.size} grains, {len(result.converged) - 1} increments ({result.message}); "
          f"{_strength(result)}; final volumetric strain {result.volumetric_strain[-1]:.6g}")
    print(f"wrote {out}")
    if figure is not None:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        from .._output import write_figure
        from ..plot.assembly import plot_response
        fig, axes = plt.subplots(1, 2, figsize=(9, 3.6))
        plot_response(result, axes=axes)
        fig.tight_layout()
        write_figure(fig, figure, metadata=_common.metadata(args, model=assembly.model))
        plt.close(fig)
        print(f"wrote {figure}")
    # a run that stopped at an increment that did not converge did not finish its test
    return 0 if result.converged[-1] else 1


def _strength(result) -> str:
    """The peak, or how far the run came without one (never an infinite strength)."""
    if result.failed:
        return (f"peak σ1/σ3 = {result.peak_ratio:.6g}, friction angle "
                f"{result.peak_friction_angle:.4g} deg")
    good = result.converged
    reached = (f"axial strain {result.axial_strain[good][-1]:.6g} (largest σ1/σ3 "
               f"{result.stress_ratio[good].max():.6g})")
    if result.message == "completed":
        return f"no peak up to {reached}"
    return f"no peak reached before the run stopped at {reached}"
