"""``frictionrules asperity``: the global law of an asperity geometry (table + figure).

Geometry from options or a TOML file (options override the file)::

    frictionrules asperity --two-flank 60 150 --deg --mu 1 --out fig5
    frictionrules asperity --normals "-0.5,0,0.866;0.5,0,0.866" --mu 0.4 --format json
    frictionrules asperity --profile profile.csv --mu 0.3            # columns x, z
    frictionrules asperity --heightmap map.npy --dx 1e-6 --mu 0.2     # 2-D array h[y, x]
    frictionrules asperity --config geometry.toml

TOML keys: ``geometry`` (``"two-flank"``, ``"normals"``, ``"profile"``, ``"heightmap"``),
``alpha1``, ``alpha2``, ``deg``, ``normals`` (list of 3-lists), ``file``, ``dx``, ``dy``,
``mu``, ``local``, ``Q``, ``n``.

Writes ``limit_curve.csv`` (or ``.json``): load direction, limit load, mechanism, normal
forces, block velocity, angle between the global slip and the normal of the limit surface,
quasi-static flag (0: the static maximum limits, see ``LimitLoad``);
``mu_theta.csv``/``.json``: the directional friction coefficient; and ``limit_curve.png``.
Prints the corners of the limit curve.
"""

from __future__ import annotations

_GEOMETRIES = ("two-flank", "normals", "profile", "heightmap")


def register(sub) -> None:
    p = sub.add_parser("asperity", help="global friction law of an asperity geometry",
                       description="Limit curve, mechanisms, global sliding rule and mu(theta) "
                                   "of a rigid block on facets with local Coulomb friction "
                                   "(paper §2).")
    g = p.add_argument_group("geometry (one of)")
    g.add_argument("--two-flank", nargs=2, type=float, metavar=("ALPHA1", "ALPHA2"),
                   help="the paper's two-flank asperity (Fig. 4), radians unless --deg")
    g.add_argument("--normals", metavar="LIST", help='facet normals "nx,ny,nz;nx,ny,nz;..."')
    g.add_argument("--profile", metavar="CSV", help="profile file with columns x, z")
    g.add_argument("--heightmap", metavar="NPY", help="height map h[y, x] (.npy or .csv)")
    p.add_argument("--config", metavar="TOML", help="geometry and options from a TOML file")
    p.add_argument("--dx", type=float, help="height-map spacing along x (default 1)")
    p.add_argument("--dy", type=float, help="height-map spacing along y (default dx)")
    p.add_argument("--mu", type=float, help="local friction coefficient")
    p.add_argument("--local", choices=("non-associated", "associated"), help="local sliding rule")
    p.add_argument("--deg", action="store_true", default=None, help="angles in degrees")
    p.add_argument("--Q", type=float, help="vertical load (default 1)")
    p.add_argument("--n", type=int, help="number of load directions (default 360)")
    p.add_argument("--out", default="asperity", metavar="DIR", help="output folder")
    p.add_argument("--format", choices=("csv", "json"), default="csv", help="table format")
    p.add_argument("--no-figure", action="store_true", help="do not draw the figure")
    p.set_defaults(run=run)


def _settings(args) -> dict:
    from .._toml import load_toml
    from ..errors import FrictionRulesError
    conf = load_toml(args.config) if args.config else {}
    chosen = [name for name, val in (("two-flank", args.two_flank), ("normals", args.normals),
                                     ("profile", args.profile), ("heightmap", args.heightmap))
              if val is not None]
    if len(chosen) > 1:
        raise FrictionRulesError(f"geometry options {chosen} violate: give only one")
    if chosen:
        conf["geometry"] = chosen[0]
        if args.two_flank is not None:
            conf["alpha1"], conf["alpha2"] = args.two_flank
        if args.normals is not None:
            conf["normals"] = args.normals
        if args.profile or args.heightmap:
            conf["file"] = args.profile or args.heightmap
    for key in ("dx", "dy", "mu", "local", "deg", "Q", "n"):
        val = getattr(args, key)
        if val is not None:
            conf[key] = val
    if conf.get("geometry") not in _GEOMETRIES:
        raise FrictionRulesError(f"geometry = {conf.get('geometry')!r} violates geometry in "
                                 f"{_GEOMETRIES} (give --two-flank, --normals, --profile, "
                                 "--heightmap or a --config file)")
    if "mu" not in conf:
        raise FrictionRulesError("mu is missing: give --mu or mu = ... in the TOML file")
    return conf


def _law(conf):
    import numpy as np

    from ..asperities import FacetSet, TwoFlankAsperity, from_heightmap, from_profile
    from ..errors import FrictionRulesError
    mu, local, geo = conf["mu"], conf.get("local", "non-associated"), conf["geometry"]
    if geo == "two-flank":
        a1, a2 = float(conf["alpha1"]), float(conf["alpha2"])
        if conf.get("deg"):
            a1, a2 = np.deg2rad(a1), np.deg2rad(a2)
        return TwoFlankAsperity(a1, a2, mu, local)
    if geo == "normals":
        n = conf["normals"]
        if isinstance(n, str):
            try:
                n = [[float(c) for c in row.split(",")] for row in n.split(";") if row.strip()]
            except ValueError as exc:
                raise FrictionRulesError(f"normals = {conf['normals']!r} violates the form "
                                         '"nx,ny,nz;nx,ny,nz"') from exc
        return FacetSet(n, mu, local)
    path = conf.get("file")
    if not path:
        raise FrictionRulesError(f"file is missing for geometry = {geo!r}")
    data = np.load(path) if str(path).endswith(".npy") else np.loadtxt(path, delimiter=",",
                                                                       ndmin=2)
    if geo == "profile":
        if data.ndim != 2 or data.shape[1] < 2:
            raise FrictionRulesError(f"profile file {path!r} must have columns x, z")
        return from_profile(data[:, 0], data[:, 1], mu, local)
    dx = float(conf.get("dx", 1.0))
    return from_heightmap(data, dx, float(conf.get("dy", dx)), mu, local)


def run(args) -> int:
    import json
    from pathlib import Path

    import numpy as np

    from .._atomic import atomic_path, write_text

    conf = _settings(args)
    law = _law(conf)
    Q, n = float(conf.get("Q", 1.0)), int(conf.get("n", 360))
    curve = law.limit_curve(Q, n=n)
    theta = np.linspace(-np.pi, np.pi, n, endpoint=False)
    mu_theta = law.friction_coefficient(theta, Q)
    out = Path(args.out)
    cols = ("direction", "Tx", "Ty", "load", "mechanism", "N_a", "N_b", "Vx", "Vy", "Vz",
            "rule_angle", "quasi_static")
    rows = [(float(curve.direction[i]), float(curve.T[i, 0]), float(curve.T[i, 1]),
             float(curve.load[i]), curve.labels[i], float(curve.normal_forces[i, 0]),
             float(curve.normal_forces[i, 1]), *map(float, curve.velocity[i]),
             float(curve.rule_angle[i]), str(int(curve.quasi_static[i])))
            for i in range(len(curve.load))]
    mu_rows = [(float(t), float(m)) for t, m in zip(theta, mu_theta)]
    written = []
    if args.format == "json":
        written.append(write_text(out / "limit_curve.json", json.dumps(
            {"law": repr(law), "Q": Q, "columns": cols,
             "rows": [[None if isinstance(v, float) and not np.isfinite(v) else v for v in r]
                      for r in rows],
             "corners": [{"T": c.T.tolist(), "interior_deg": float(np.rad2deg(c.interior)),
                          "concave": c.concave, "before": c.before, "after": c.after}
                         for c in curve.corners]}, indent=1)))
        written.append(write_text(out / "mu_theta.json", json.dumps(
            {"theta": theta.tolist(),
             "mu": [m if np.isfinite(m) else None for _, m in mu_rows]}, indent=1)))
    else:
        def fmt(v):
            return v if isinstance(v, str) else f"{v:.10g}"
        written.append(write_text(out / "limit_curve.csv", "\n".join(
            [",".join(cols)] + [",".join(map(fmt, r)) for r in rows]) + "\n"))
        written.append(write_text(out / "mu_theta.csv", "\n".join(
            ["theta,mu"] + [f"{t:.10g},{m:.10g}" for t, m in mu_rows]) + "\n"))
    if not args.no_figure:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        from ..plot.asperities import limit_curve
        fin = curve.load[np.isfinite(curve.load)]
        box = float(min(2.0 * np.max(fin), 4.0 * np.median(fin))) if len(fin) else 1.0
        ax = limit_curve(law, Q, box=box, n=max(n, 720))
        ax.set_title(f"{type(law).__name__}, mu = {law.mu:g}, {law.local}", fontsize=9)
        ax.legend(loc="lower left", fontsize=7)
        with atomic_path(out / "limit_curve.png") as tmp:
            ax.figure.savefig(tmp, format="png", dpi=150, bbox_inches="tight")
        plt.close(ax.figure)
        written.append(out / "limit_curve.png")
    print(f"{type(law).__name__}: {len(law._facets.normals)} facet(s), mu = {law.mu:g}, "
          f"{law.local}, Q = {Q:g}")
    print(f"corners: {len(curve.corners)}, concave: {len(curve.concave_corners)}")
    for c in curve.corners:
        print(f"  T = ({c.T[0]:.6g}, {c.T[1]:.6g})  {'+'.join(map(str, c.before))} -> "
              f"{'+'.join(map(str, c.after))}  interior {np.rad2deg(c.interior):.3f} deg"
              f"{'  concave' if c.concave else ''}")
    fin = np.isfinite(mu_theta)
    if fin.any():
        print(f"mu(theta): min {mu_theta[fin].min():.6g}, max {mu_theta[fin].max():.6g}, "
              f"locked directions {int((~fin).sum())} of {len(mu_theta)}")
    for path in written:
        print(f"wrote {path}")
    return 0
