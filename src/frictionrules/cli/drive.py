"""``frictionrules drive PATH.toml [--out FILE] [--plot [PNG]]``: drive one contact along a
mixed-control path read from TOML (model, segments, optional output file)."""

from __future__ import annotations

import sys


def register(sub) -> None:
    p = sub.add_parser(
        "drive", help="drive one elastic-plastic contact along a mixed-control path (TOML)",
        description="Read [model] (kn, kt, beta, [model.law], optional [model.hardening]), optional "
                    "[output] file and [[segment]] tables (targets T1|dt1, T2|dt2, N|dn and steps) "
                    "from PATH.toml, drive the contact implicitly, print a summary and write the "
                    "table (CSV or HDF5 by suffix). See docs/contact.md.",
        epilog="example: frictionrules drive examples/contact_shear.toml --out shear.csv --plot")
    p.add_argument("path", metavar="PATH.toml", help="drive file")
    p.add_argument("--out", metavar="FILE", help="result table (.csv, .h5); overrides [output] file")
    p.add_argument("--plot", nargs="?", const="", metavar="PNG",
                   help="plot T1-dt1 and N-dn (default file: PATH with suffix .png)")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(run=run)


class ProgressBar:
    """A one-line text progress bar on a stream (stderr), drawn only for long paths."""

    def __init__(self, total: int, stream=None, width: int = 40, min_total: int = 200):
        self.total, self.width = total, width
        self.stream = stream if stream is not None else sys.stderr
        self.enabled = total >= min_total
        self.last = -1

    def __call__(self, done: int, total: int) -> None:
        if not self.enabled:
            return
        filled = self.width * done // total
        if filled == self.last and done != total:
            return
        self.last = filled
        bar = "#" * filled + "-" * (self.width - filled)
        self.stream.write(f"\rdrive [{bar}] {done}/{total}")
        if done == total:
            self.stream.write("\n")
        self.stream.flush()


def run(args) -> int:
    from pathlib import Path

    from ..contact.driver import drive, read_toml
    model, path, opts = read_toml(args.path)
    bar = ProgressBar(len(path), min_total=10**9 if args.quiet else 200)
    result = drive(model, path, beta=opts["beta"], progress=bar)
    F, d = result.force[-1], result.displacement[-1]
    print(f"{len(path)} steps; final T = ({F[0]:.6g}, {F[1]:.6g}), N = {F[2]:.6g}; "
          f"δ = ({d[0]:.6g}, {d[1]:.6g}, {d[2]:.6g}); κ = {result.kappa[-1]:.6g}, β = {result.beta[-1]:.6g}; "
          f"plastic work {result.work[-1]:.6g}")
    out = args.out if args.out is not None else opts["output"]
    if out is not None:
        written = result.write(out, attrs={"model": repr(model), "source": str(args.path)})
        print(f"wrote {written}")
    if args.plot is not None:
        png = Path(args.plot) if args.plot else Path(args.path).with_suffix(".png")
        _plot(result, png)
        print(f"wrote {png}")
    return 0


def _plot(result, png) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from .._atomic import atomic_path
    fig, (a, b) = plt.subplots(1, 2, figsize=(9, 3.6))
    a.plot(result.displacement[:, 0], result.force[:, 0])
    a.set_xlabel(r"$\delta_{t1}$")
    a.set_ylabel(r"$T_1$")
    b.plot(result.displacement[:, 2], result.force[:, 2])
    b.set_xlabel(r"$\delta_n$ (opening > 0)")
    b.set_ylabel(r"$N$ (compression > 0)")
    fig.tight_layout()
    with atomic_path(png) as tmp:
        fig.savefig(tmp, format="png", dpi=120)
    plt.close(fig)
