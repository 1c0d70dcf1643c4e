"""``frictionrules drive PATH.toml [--out FILE] [--plot [FILE]]``: drive one contact along a
mixed-control path read from TOML (model, segments, optional output file)."""

from __future__ import annotations

from ._common import add_quiet


def register(sub) -> None:
    p = sub.add_parser(
        "drive", help="drive one elastic-plastic contact along a mixed-control path (TOML)",
        description="Read [model] (kn, kt, beta, [model.law]: a law in the layout of "
                    "frictionrules.read_law, any law of the table, UserLaw included), optional "
                    "[output] file (relative to the TOML file) and [[segment]] tables (targets "
                    "T1|dt1, T2|dt2, N|dn and steps) from PATH.toml, drive the contact implicitly, "
                    "print a summary and write the table (CSV, JSON or HDF5 by suffix). See "
                    "docs/contact.md.",
        epilog="example: frictionrules drive examples/contact_shear.toml --out shear.csv --plot")
    p.add_argument("path", metavar="PATH.toml", help="drive file")
    p.add_argument("--out", metavar="FILE", help="result table (.csv, .json, .h5); overrides "
                   "[output] file")
    p.add_argument("--plot", nargs="?", const="", metavar="FILE",
                   help="plot T1-dt1, T2-dt2 and N-dn under the law's name (.png, .svg or "
                        ".pdf; without FILE: the --out file with suffix .png)")
    add_quiet(p)
    p.set_defaults(run=run)


def run(args) -> int:
    from pathlib import Path

    from .._output import FIGURE_SUFFIXES, check_output
    from ..contact.driver import SUFFIXES, drive, read_toml
    from ..errors import FrictionRulesError
    from . import _common

    model, path, opts = read_toml(args.path)
    out = args.out if args.out is not None else opts["output"]
    name = "--out" if args.out is not None else f"{args.path}: [output] file"
    out = check_output(out, SUFFIXES, name=name) if out is not None else None
    png = None
    if args.plot is not None:
        if args.plot:
            png = check_output(args.plot, FIGURE_SUFFIXES, name="--plot")
        elif out is not None:
            png = out.with_suffix(".png")
        else:
            raise FrictionRulesError("--plot without FILE needs --out (the figure goes beside the "
                                     "table); constraint: --plot FILE.png|svg|pdf or --out FILE")
    with _common.progress(args, "drive", len(path)) as bar:
        result = drive(model, path, beta=opts["beta"], progress=bar)
    F, d = result.force[-1], result.displacement[-1]
    beta = f", β = {result.beta[-1]:.6g}" if "beta" in result.law_variables else ""
    print(f"{len(path)} steps; final T = ({F[0]:.6g}, {F[1]:.6g}), N = {F[2]:.6g}; "
          f"δ = ({d[0]:.6g}, {d[1]:.6g}, {d[2]:.6g}); κ = {result.kappa[-1]:.6g}{beta}; "
          f"plastic work {result.work[-1]:.6g}")
    meta = _common.metadata(args, model=model, source=str(Path(args.path)))
    if out is not None:
        written = result.write(out, attrs=meta)
        print(f"wrote {written}")
    if png is not None:
        _plot(result, model, png, meta)
        print(f"wrote {png}")
    return 0


def _plot(result, model, png, meta) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from .._output import write_figure
    from ..plot.contact import drive_curves
    title = f"{model.law!r}\nkn = {model.kn:g}, kt = {model.kt:g}" + (
        f", hardening {model.hardening!r}" if model.hardening is not None else "")
    axes = drive_curves(result, title=title)
    write_figure(axes[0].figure, png, metadata=meta, dpi=120)
    plt.close(axes[0].figure)
