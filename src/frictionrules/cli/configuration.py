"""``frictionrules configuration``: a grain sliding over a layer (§3), path following or the
pocket peak force, from options or a TOML file; CSV/JSON/HDF5 table and figure out."""

from __future__ import annotations

from ._common import MAX_COUNT, add_quiet, finite_float, positive_int

#: option -> type; a TOML file may give the same keys (the command line wins)
_KEYS = {"grain": str, "packing": str, "diameter": float, "mu": float, "Q": float,
         "method": str, "scheme": str, "direction": float, "length": float, "steps": int,
         "path": list, "polar": int, "deg": bool}
_DEFAULTS = {"grain": "cylinder", "packing": "single", "diameter": 1.0, "mu": 0.3, "Q": 1.0,
             "method": "exact", "scheme": "euler", "direction": 0.0, "steps": 201, "deg": False}
_TABLES = (".csv", ".json", ".h5", ".hdf5")
#: units of the path table's columns (angles added by run: rad or deg)
_PATH_UNITS = {"distance": "length", "ux": "length", "uy": "length", "uz": "length",
               "Tx": "force", "Ty": "force", "T": "force", "N1": "force", "N2": "force",
               "contacts": "1"}


def register(sub) -> None:
    p = sub.add_parser(
        "configuration", help="grain sliding over a layer: softening along a path (§3)",
        description="Push a cylinder or a sphere over a layer of grains of the same diameter "
                    "(§3, Figs. 8-9). Path mode: the force that keeps it sliding along a straight "
                    "trajectory from its pocket (or a given polyline), the normal forces, the "
                    "dilatancy and the contacts that open or close. Polar mode (--polar N): the "
                    "peak force to leave the pocket against the force direction; directions in "
                    "which the pocket jams (no mechanism starts) are marked jammed in the table.",
        epilog="example: frictionrules configuration --grain sphere --packing hexagonal --mu 0.3 "
               "--direction 30 --deg --length 0.8 --out path.csv --figure path.png")
    p.add_argument("--config", metavar="FILE.toml", help="read the options from a TOML file "
                   f"(keys: {', '.join(_KEYS)})")
    p.add_argument("--grain", choices=("cylinder", "sphere"), help="default: cylinder")
    p.add_argument("--packing", choices=("single", "square", "hexagonal"),
                   help="sphere layer (default: single)")
    p.add_argument("--diameter", type=finite_float, help="grain diameter d (default 1)")
    p.add_argument("--mu", type=finite_float, help="local friction coefficient (default 0.3)")
    p.add_argument("--Q", "-Q", dest="Q", type=finite_float, help="vertical load (default 1)")
    p.add_argument("--method", choices=("exact", "incremental"), help="default: exact")
    p.add_argument("--scheme", choices=("euler", "heun"), help="incremental scheme (default euler)")
    p.add_argument("--direction", type=finite_float, help="direction of the straight path "
                   "(radians, degrees with --deg; default 0)")
    p.add_argument("--length", type=finite_float, help="length of the straight path (default d)")
    p.add_argument("--steps", type=positive_int, help="number of points on the straight path "
                   "(default 201)")
    p.add_argument("--path", metavar="X,Y;X,Y;...", help="polyline of horizontal positions instead "
                   "of a straight path")
    p.add_argument("--polar", type=positive_int, metavar="N",
                   help="pocket peak force in N >= 1 force directions")
    p.add_argument("--deg", action="store_true", default=None,
                   help="angles in degrees (input and output)")
    p.add_argument("--out", metavar="FILE", help="write the table (.csv, .json, .h5)")
    p.add_argument("--figure", metavar="FILE", help="write a figure (.png, .svg or .pdf)")
    add_quiet(p)
    p.set_defaults(run=run)


def _toml_value(source: str, key: str, value):
    import math

    from ..errors import FrictionRulesError
    kind = _KEYS[key]
    ok = isinstance(value, kind) and not (kind is int and isinstance(value, bool))
    if kind is float and isinstance(value, int) and not isinstance(value, bool):
        ok, value = True, float(value)
    if not ok:
        raise FrictionRulesError(f"{source}: {key} = {value!r} violates: must be {kind.__name__}")
    if kind is float and not math.isfinite(value):
        raise FrictionRulesError(f"{source}: {key} = {value!r} violates: must be finite")
    if key in ("polar", "steps") and not 1 <= value <= MAX_COUNT:
        raise FrictionRulesError(f"{source}: {key} = {value!r} violates 1 <= {key} <= {MAX_COUNT}")
    return value


def options(args) -> dict:
    """Merged options: defaults < TOML file < command line; checked types."""
    from ..errors import FrictionRulesError

    opts = dict(_DEFAULTS)
    if args.config:
        from .._toml import load_toml
        data = load_toml(args.config)
        unknown = sorted(set(data) - set(_KEYS))
        if unknown:
            raise FrictionRulesError(f"{args.config}: unknown keys {unknown}; known: {list(_KEYS)}")
        for key, value in data.items():
            opts[key] = _toml_value(args.config, key, value)
        if "path" in data:
            opts["path"] = _polyline(data["path"], f"{args.config}: path")
    for key in _KEYS:
        value = getattr(args, key, None)
        if value is not None:
            opts[key] = _parse_path(value) if key == "path" else value
    return opts


def _polyline(points, name: str):
    """A polyline ``[[x, y], ...]`` of finite numbers as an array (n, 2)."""
    import numpy as np

    from ..errors import FrictionRulesError
    try:
        arr = np.array(points, dtype=float)
    except (TypeError, ValueError):
        arr = None
    if arr is None or arr.ndim != 2 or arr.shape[1] != 2 or len(arr) < 2 or not np.isfinite(arr).all():
        shown = repr(points) if len(repr(points)) < 60 else repr(points)[:57] + "..."
        raise FrictionRulesError(f"{name} = {shown} violates: at least two points [x, y] of "
                                 "finite numbers")
    return arr


def _parse_path(text: str):
    from ..errors import FrictionRulesError
    try:
        points = [[float(v) for v in pt.split(",")] for pt in text.split(";") if pt.strip()]
    except ValueError:
        raise FrictionRulesError(f"--path {text!r} violates the form 'x,y;x,y;...'") from None
    return _polyline(points, "--path")


def build_model(opts):
    import frictionrules as fr
    from ..errors import FrictionRulesError

    if opts["grain"] == "cylinder":
        if opts["packing"] != "single":
            raise FrictionRulesError(f"packing = {opts['packing']!r}: a cylinder rests on a line "
                                     "of cylinders (packing applies to spheres)")
        return fr.CylinderOnLayer(opts["diameter"], opts["mu"])
    if opts["grain"] == "sphere":
        return fr.SphereOnLayer(opts["diameter"], opts["mu"], packing=opts["packing"])
    raise FrictionRulesError(f"grain = {opts['grain']!r} violates grain in ('cylinder', 'sphere')")


def polar_sweep(model, directions, progress=None, Q: float = 1.0) -> dict:
    """Pocket peak force in each direction under the vertical load ``Q``; a direction in which
    the pocket jams (no mechanism starts) is flagged ``jammed`` with an infinite peak instead of
    stopping the sweep.

    Returns the table columns ``direction`` (radians), ``peak``, ``Tx``, ``Ty``, ``contacts``,
    ``jammed``.
    """
    import numpy as np

    from ..errors import FrictionRulesError
    n = len(directions)
    peak, start = np.full(n, np.inf), np.full((n, 2), np.nan)
    count, jammed = np.zeros(n, dtype=int), np.zeros(n, dtype=bool)
    for i, theta in enumerate(directions):
        try:
            res = model.breakout_force([theta], Q=Q)
        except FrictionRulesError:  # the pocket jams in this direction
            jammed[i] = True
        else:
            peak[i], start[i], count[i] = res.peak[0], res.start[0], res.count[0]
        if progress is not None:
            progress(i + 1, n)
    return {"direction": np.asarray(directions, dtype=float), "peak": peak, "Tx": start[:, 0],
            "Ty": start[:, 1], "contacts": count, "jammed": jammed}


def run(args) -> int:
    import numpy as np

    from .._output import FIGURE_SUFFIXES, check_output, write_table
    from . import _common

    out = check_output(args.out, _TABLES, name="--out") if args.out else None
    figure = check_output(args.figure, FIGURE_SUFFIXES, name="--figure") if args.figure else None
    opts = options(args)
    model = build_model(opts)
    scale = np.pi / 180.0 if opts["deg"] else 1.0
    angle = "deg" if opts["deg"] else "rad"
    polar = opts.get("polar")
    if polar:
        th = np.linspace(0.0, 2 * np.pi, int(polar), endpoint=False)
        with _common.progress(args, "configuration --polar", len(th), "directions") as bar:
            columns = polar_sweep(model, th, bar, Q=opts["Q"])
        columns["direction"] = th / scale
        units = {"direction": angle, "peak": "force", "Tx": "force", "Ty": "force",
                 "contacts": "1", "jammed": "1"}
        _print_polar(columns, opts["Q"], angle)
    else:
        if opts.get("path") is not None:
            path = np.asarray(opts["path"], dtype=float)
        else:
            path = model.straight_path(opts["direction"] * scale, opts.get("length"), opts["steps"])
        with _common.progress(args, "configuration") as bar:
            bar.phase(f"following the path ({len(path)} points, {opts['method']})")
            res = model.displacement_path(path, opts["method"], opts["scheme"], Q=opts["Q"])
        columns = res.table()
        columns["alpha"], columns["psi"] = columns["alpha"] / scale, columns["psi"] / scale
        units = {**_PATH_UNITS, "alpha": angle, "psi": angle}
        T = res.force_magnitude
        print(f"{type(model).__name__}: {len(path)} points, method {res.method}")
        Q = opts["Q"]
        print(f"|T|/Q: start {T[0] / Q:.4f}, peak {T.max() / Q:.4f}, "
              f"end {T[-1] / Q:.4f}; dilatancy {res.height[-1] - res.height[0]:+.4g}")
        for i, what, cid in res.events():
            print(f"  point {i}: contact {cid} {'opens' if what == 'open' else 'closes'}")
    meta = _common.metadata(args, model=model, parameters=opts)
    if out is not None:
        write_table(out, columns, units=units, metadata=meta)
        print(f"wrote {out}")
    if figure is not None:
        _figure(model, columns if polar else path, figure, meta, polar=bool(polar), Q=opts["Q"])
        print(f"wrote {figure}")
    return 0


def _print_polar(columns, Q, angle) -> None:
    import numpy as np
    ok = ~columns["jammed"]
    th, peak, count = columns["direction"], columns["peak"], columns["contacts"]
    if ok.any():
        idx = np.flatnonzero(ok)
        lo, hi = idx[np.argmin(peak[ok])], idx[np.argmax(peak[ok])]
        from ..configuration.summary import climbing

        def at(i):
            degrees = "" if angle == "deg" else f" ({np.rad2deg(th[i]):.4g} deg)"
            return f"{peak[i] / Q:.4f} at {th[i]:.4g} {angle}{degrees}, {climbing(count[i])}"
        print(f"pocket peak force |T|/Q: least {at(lo)}; largest {at(hi)}")
    if not ok.all():
        jam = th[~ok]
        print(f"jammed (no mechanism starts) in {len(jam)} of {len(th)} directions: "
              + ", ".join(f"{t:.4g}" for t in jam[:12]) + (" ..." if len(jam) > 12 else "")
              + f" {angle}")


def _figure(model, data, path, meta, *, polar: bool, Q: float) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    from .._output import write_figure
    if polar:
        th = np.linspace(0.0, 2 * np.pi, len(data["peak"]), endpoint=False)
        r = np.where(data["jammed"], np.nan, data["peak"] / Q)
        fig, ax = plt.subplots(figsize=(6, 6), subplot_kw={"projection": "polar"})
        ax.plot(np.append(th, th[0]), np.append(r, r[0]), label="peak |T|/Q")
        if data["jammed"].any():
            edge = np.nanmax(r) * 1.05 if np.isfinite(r).any() else 1.0
            ax.plot(th[data["jammed"]], np.full(int(data["jammed"].sum()), edge), "x",
                    color="tab:red", label="jammed")
        if np.isfinite(r).any():  # radial tick labels along the direction of the least peak
            ax.set_rlabel_position(float(np.rad2deg(th[np.nanargmin(r)])))
        ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize=8)
        ax.set_title("peak |T|/Q against the force direction")
    else:
        from ..plot.configuration import limit_evolution
        ax = limit_evolution(model, data)
        fig = ax.figure
    write_figure(fig, path, metadata=meta, bbox_inches="tight")
    plt.close(fig)
