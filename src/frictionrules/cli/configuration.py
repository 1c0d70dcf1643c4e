"""``frictionrules configuration``: a grain sliding over a layer (§3), path following or the
pocket peak force, from options or a TOML file; CSV/JSON table and figure out."""

from __future__ import annotations

import json

#: option -> type; a TOML file may give the same keys (the command line wins)
_KEYS = {"grain": str, "packing": str, "diameter": float, "mu": float, "Q": float,
         "method": str, "scheme": str, "direction": float, "length": float, "steps": int,
         "path": list, "polar": int, "deg": bool}
_DEFAULTS = {"grain": "cylinder", "packing": "single", "diameter": 1.0, "mu": 0.3, "Q": 1.0,
             "method": "exact", "scheme": "euler", "direction": 0.0, "steps": 201, "deg": False}


def register(sub) -> None:
    p = sub.add_parser(
        "configuration", help="grain sliding over a layer: softening along a path (§3)",
        description="Push a cylinder or a sphere over a layer of grains of the same diameter "
                    "(§3, Figs. 8-9). Path mode: the force that keeps it sliding along a straight "
                    "trajectory from its pocket (or a given polyline), the normal forces, the "
                    "dilatancy and the contacts that open or close. Polar mode (--polar N): the "
                    "peak force to leave the pocket against the force direction.",
        epilog="example: frictionrules configuration --grain sphere --packing hexagonal --mu 0.3 "
               "--direction 30 --deg --length 0.8 --out path.csv --figure path.png")
    p.add_argument("--config", metavar="FILE.toml", help="read the options from a TOML file "
                   f"(keys: {', '.join(_KEYS)})")
    p.add_argument("--grain", choices=("cylinder", "sphere"), help="default: cylinder")
    p.add_argument("--packing", choices=("single", "square", "hexagonal"),
                   help="sphere layer (default: single)")
    p.add_argument("--diameter", type=float, help="grain diameter d (default 1)")
    p.add_argument("--mu", type=float, help="local friction coefficient (default 0.3)")
    p.add_argument("--Q", "-Q", dest="Q", type=float, help="vertical load (default 1)")
    p.add_argument("--method", choices=("exact", "incremental"), help="default: exact")
    p.add_argument("--scheme", choices=("euler", "heun"), help="incremental scheme (default euler)")
    p.add_argument("--direction", type=float, help="direction of the straight path (radians, "
                   "degrees with --deg; default 0)")
    p.add_argument("--length", type=float, help="length of the straight path (default d)")
    p.add_argument("--steps", type=int, help="number of points on the straight path (default 201)")
    p.add_argument("--path", metavar="X,Y;X,Y;...", help="polyline of horizontal positions instead "
                   "of a straight path")
    p.add_argument("--polar", type=int, metavar="N", help="pocket peak force in N force directions")
    p.add_argument("--deg", action="store_true", default=None, help="angles in degrees")
    p.add_argument("--out", metavar="FILE.csv|FILE.json", help="write the table (CSV or JSON)")
    p.add_argument("--figure", metavar="FILE.png", help="write a figure (png, svg or pdf)")
    p.set_defaults(run=run)


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
            kind = _KEYS[key]
            ok = isinstance(value, kind) or (kind is float and isinstance(value, int)
                                             and not isinstance(value, bool))
            if not ok:
                raise FrictionRulesError(f"{args.config}: {key} = {value!r} must be {kind.__name__}")
            opts[key] = value
    for key in _KEYS:
        value = getattr(args, key, None)
        if value is not None:
            opts[key] = _parse_path(value) if key == "path" else value
    return opts


def _parse_path(text: str) -> list:
    from ..errors import FrictionRulesError
    try:
        return [[float(v) for v in pt.split(",")] for pt in text.split(";") if pt.strip()]
    except ValueError as exc:
        raise FrictionRulesError(f"--path {text!r} is not 'x,y;x,y;...'") from exc


def build_model(opts):
    import frictionrules as fr
    from ..errors import FrictionRulesError

    if opts["grain"] == "cylinder":
        if opts["packing"] != "single":
            raise FrictionRulesError(f"packing = {opts['packing']!r}: a cylinder rests on a line "
                                     "of cylinders (packing applies to spheres)")
        return fr.CylinderOnLayer(opts["diameter"], opts["mu"], opts["Q"])
    if opts["grain"] == "sphere":
        return fr.SphereOnLayer(opts["diameter"], opts["mu"], opts["Q"], opts["packing"])
    raise FrictionRulesError(f"grain = {opts['grain']!r} violates grain in ('cylinder', 'sphere')")


def _write_table(path, columns: dict) -> None:
    from .._atomic import write_text

    names = list(columns)
    if str(path).lower().endswith(".json"):
        write_text(path, json.dumps({k: [v.item() if hasattr(v, "item") else v
                                         for v in columns[k]] for k in names}, indent=1) + "\n")
        return
    rows = [",".join(names)]
    for i in range(len(columns[names[0]])):
        rows.append(",".join(repr(float(columns[k][i])) for k in names))
    write_text(path, "\n".join(rows) + "\n")


def run(args) -> int:
    import numpy as np

    from .._atomic import atomic_path

    opts = options(args)
    model = build_model(opts)
    scale = np.pi / 180.0 if opts["deg"] else 1.0
    if opts.get("polar"):
        th = np.linspace(0.0, 2 * np.pi, int(opts["polar"]), endpoint=False)
        res = model.breakout_force(th)
        columns = {"direction": th / scale, "peak": res.peak, "Tx": res.start[:, 0],
                   "Ty": res.start[:, 1], "contacts": res.count}
        lo, hi = int(np.argmin(res.peak)), int(np.argmax(res.peak))
        print(f"pocket peak force |T|/Q: min {res.peak[lo] / model.Q:.4f} at "
              f"{th[lo] / scale:.4g} (over {res.count[lo]}), max {res.peak[hi] / model.Q:.4f} at "
              f"{th[hi] / scale:.4g} (over {res.count[hi]})")
    else:
        if opts.get("path") is not None:
            path = np.asarray(opts["path"], dtype=float)
        else:
            path = model.straight_path(opts["direction"] * scale, opts.get("length"), opts["steps"])
        res = model.displacement_path(path, opts["method"], opts["scheme"])
        columns = res.table()
        T = res.force_magnitude
        print(f"{type(model).__name__}: {len(path)} points, method {res.method}")
        print(f"|T|/Q: start {T[0] / model.Q:.4f}, peak {T.max() / model.Q:.4f}, "
              f"end {T[-1] / model.Q:.4f}; dilatancy {res.height[-1] - res.height[0]:+.4g}")
        for i, what, cid in res.events():
            print(f"  point {i}: contact {cid} {'opens' if what == 'open' else 'closes'}")
    if args.out:
        _write_table(args.out, columns)
        print(f"wrote {args.out}")
    if args.figure:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        from ..plot.configuration import limit_evolution
        if opts.get("polar"):
            fig, ax = plt.subplots(figsize=(6, 6), subplot_kw={"projection": "polar"})
            ax.plot(np.append(th, th[0]), np.append(res.peak, res.peak[0]) / model.Q)
            ax.set_title("peak |T|/Q against the force direction")
        else:
            ax = limit_evolution(model, path)
            fig = ax.figure
        fmt = str(args.figure).rsplit(".", 1)[-1].lower()
        with atomic_path(args.figure) as tmp:
            fig.savefig(tmp, format=fmt if fmt in ("png", "svg", "pdf") else "png", dpi=150,
                        bbox_inches="tight")
        plt.close(fig)
        print(f"wrote {args.figure}")
    return 0
