"""``frictionrules asperity``: the global law of an asperity geometry or a measured surface.

Geometry from options or a TOML file (options override the file)::

    frictionrules asperity surface.x3p --mu 0.3                  # an instrument file
    frictionrules asperity afm.di --mu 0.3 --scale 20 --detrend rows --out afm
    frictionrules asperity --two-flank 60 150 --deg --mu 1 --out fig5
    frictionrules asperity --normals "-0.5,0,0.866;0.5,0,0.866" --mu 0.4 --out n --format json
    frictionrules asperity --profile profile.csv --mu 0.3         # columns x, z
    frictionrules asperity --heightmap map.npy --dx 1e-6 --mu 0.2  # 2-D array h[y, x]
    frictionrules asperity --config geometry.toml

An instrument file (any format SurfaceTopography reads: the extra ``frictionrules[surfaces]``)
is detrended (mean plane by default) and smoothed at the scale ``--scale`` (the cut-off
wavelength of the ISO Gaussian filter, in the file's length unit; default five pixels); the
scale used, the mu(theta) range, the anisotropy ratio, the locked directions and the warnings
are printed. Nothing is written unless ``--out DIR`` is given; then ``limit_curve``,
``mu_theta`` and ``corners`` tables (CSV or JSON, with units and provenance) and
``limit_curve.png`` go into ``DIR``.
"""

from __future__ import annotations

from ._common import add_quiet, finite_float, metadata, positive_int, progress

_GEOMETRIES = ("topography", "two-flank", "normals", "profile", "heightmap")
#: TOML keys of every geometry, and the ones each needs (``file`` paths are relative to the
#: TOML file's folder).
_COMMON = {"geometry", "mu", "local", "Q", "n"}
_KEYS = {"topography": ({"file"}, {"scale", "detrend"}),
         "two-flank": ({"alpha1", "alpha2"}, {"deg"}),
         "normals": ({"normals"}, set()),
         "profile": ({"file"}, set()),
         "heightmap": ({"file"}, {"dx", "dy"})}
#: The option that gives a TOML key.
_OPTION = {"mu": "--mu", "alpha1": "--two-flank", "alpha2": "--two-flank", "normals": "--normals",
           "file": "FILE, --profile or --heightmap"}


def register(sub) -> None:
    p = sub.add_parser("asperity", help="global friction law of an asperity geometry or a "
                                        "measured surface",
                       description="Limit curve, mechanisms, global sliding rule and mu(theta) "
                                   "of a rigid block on facets with local Coulomb friction "
                                   "(paper §2), from a geometry or a measured surface.")
    p.add_argument("file", nargs="?", metavar="FILE",
                   help="an instrument file (AFM, interferometer, X3P, stylus profile ...; "
                        "needs frictionrules[surfaces])")
    g = p.add_argument_group("other geometries (instead of FILE)")
    g.add_argument("--two-flank", nargs=2, type=finite_float, metavar=("ALPHA1", "ALPHA2"),
                   help="the paper's two-flank asperity (Fig. 4), radians unless --deg")
    g.add_argument("--normals", metavar="LIST", help='facet normals "nx,ny,nz;nx,ny,nz;..."')
    g.add_argument("--profile", metavar="CSV", help="profile file with columns x, z (a header "
                                                    "line 'x,z' is allowed)")
    g.add_argument("--heightmap", metavar="NPY", help="height map h[y, x] (.npy or .csv)")
    p.add_argument("--config", metavar="TOML", help="geometry and options from a TOML file")
    s = p.add_argument_group("measured surface (FILE)")
    s.add_argument("--scale", type=finite_float, metavar="LENGTH",
                   help="cut-off wavelength of the Gaussian smoothing in the file's length unit "
                        "(0: none; default five pixels)")
    s.add_argument("--detrend", choices=("plane", "rows", "none"),
                   help="remove the mean plane (default), each scan line's mean line, or nothing")
    p.add_argument("--dx", type=finite_float, help="height-map spacing along x (default 1)")
    p.add_argument("--dy", type=finite_float, help="height-map spacing along y (default dx)")
    p.add_argument("--mu", type=finite_float, help="local friction coefficient")
    p.add_argument("--local", choices=("non-associated", "associated"), help="local sliding rule")
    p.add_argument("--deg", action="store_true", default=None, help="angles in degrees")
    p.add_argument("--Q", type=finite_float, help="vertical load (default 1)")
    p.add_argument("--n", type=positive_int, help="number of directions (>= 4, default 360)")
    p.add_argument("--out", metavar="DIR", help="write the tables and the figure into DIR "
                                                "(nothing is written without it)")
    p.add_argument("--format", choices=("csv", "json"), default=None,
                   help="format of the tables written with --out (default csv)")
    p.add_argument("--no-figure", action="store_true", help="do not draw the figure")
    add_quiet(p)
    p.set_defaults(run=run)


def _settings(args) -> dict:
    from pathlib import Path

    from .._toml import load_toml
    from ..errors import FrictionRulesError
    conf = {}
    if args.config:
        conf = load_toml(args.config)
        if conf.get("file") is not None and isinstance(conf["file"], str):
            conf["file"] = str(Path(args.config).parent / conf["file"])
    chosen = [name for name, val in (("topography", args.file), ("two-flank", args.two_flank),
                                     ("normals", args.normals), ("profile", args.profile),
                                     ("heightmap", args.heightmap)) if val is not None]
    if len(chosen) > 1:
        raise FrictionRulesError(f"geometry options {chosen} violate: give only one")
    if chosen:
        if conf.get("geometry") not in (None, chosen[0]):
            conf = {k: v for k, v in conf.items() if k in _COMMON}
        conf["geometry"] = chosen[0]
        if args.two_flank is not None:
            conf["alpha1"], conf["alpha2"] = args.two_flank
        if args.normals is not None:
            conf["normals"] = args.normals
        if args.file or args.profile or args.heightmap:
            conf["file"] = args.file or args.profile or args.heightmap
    for key in ("dx", "dy", "mu", "local", "deg", "Q", "n", "scale", "detrend"):
        val = getattr(args, key)
        if val is not None:
            conf[key] = val
    geo = conf.get("geometry")
    if geo not in _GEOMETRIES:
        raise FrictionRulesError(f"geometry = {geo!r} violates geometry in {_GEOMETRIES} (give "
                                 "FILE, --two-flank, --normals, --profile, --heightmap or a "
                                 "--config file)")
    need, optional = _KEYS[geo]
    extra = sorted(set(conf) - _COMMON - need - optional)
    if extra:
        raise FrictionRulesError(f"keys {extra} violate: not used by geometry = {geo!r} (its "
                                 f"keys: {sorted(_COMMON | need | optional)})")
    missing = sorted(need - set(conf))
    if "mu" not in conf:
        missing.insert(0, "mu")
    if missing:
        raise FrictionRulesError(f"{', '.join(missing)} missing for geometry = {geo!r}: set it in "
                                 f"the TOML file or give {_OPTION.get(missing[0], missing[0])}")
    return conf


def _number(conf, key, default=None, **bounds) -> float:
    from ..errors import FrictionRulesError, check_scalar
    value = conf.get(key, default)
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise FrictionRulesError(f"{key} = {value!r} violates: a number")
    return check_scalar(key, value, **bounds)


def _count_of_directions(n) -> int:
    from ..errors import FrictionRulesError
    if isinstance(n, bool) or not isinstance(n, int) or n < 4:
        raise FrictionRulesError(f"n = {n!r} violates: an integer n >= 4 (directions)")
    return n


def _law(conf):
    """The facet law (and, for a measured surface, its :class:`SurfaceFriction`)."""
    import numpy as np

    from ..asperities import (FacetSet, TwoFlankAsperity, from_heightmap, from_profile,
                              from_topography, read_surface)
    from ..errors import FrictionRulesError
    mu = _number(conf, "mu", lo=0.0, lo_open=True)
    local, geo = conf.get("local", "non-associated"), conf["geometry"]
    if geo == "topography":
        from ..laws import Coulomb
        surface = from_topography(read_surface(conf["file"]),
                                  Coulomb(mu, dilatant=local == "associated"),
                                  scale=None if conf.get("scale") is None
                                  else _number(conf, "scale", lo=0.0),
                                  detrend=conf.get("detrend", "plane"), n=conf["n"])
        return surface.law, surface
    if geo == "two-flank":
        a1, a2 = _number(conf, "alpha1"), _number(conf, "alpha2")
        if conf.get("deg"):
            a1, a2 = np.deg2rad(a1), np.deg2rad(a2)
        return TwoFlankAsperity(a1, a2, mu, local), None
    if geo == "normals":
        n = conf["normals"]
        if isinstance(n, str):
            try:
                n = [[float(c) for c in row.split(",")] for row in n.split(";") if row.strip()]
            except ValueError as exc:
                raise FrictionRulesError(f"normals = {conf['normals']!r} violates the form "
                                         '"nx,ny,nz;nx,ny,nz"') from exc
        return FacetSet(n, mu, local), None
    data = _read_array(str(conf["file"]), geo)
    if geo == "profile":
        if data.ndim != 2 or data.shape[1] < 2:
            raise FrictionRulesError(f"profile file {conf['file']!r} violates: columns x, z")
        return from_profile(data[:, 0], data[:, 1], mu, local), None
    dx = _number(conf, "dx", 1.0)
    return from_heightmap(data, dx, _number(conf, "dy", dx), mu, local), None


def _read_array(path: str, geo: str):
    """A ``.npy`` array (never pickled objects) or the numbers of a CSV file; a first line
    that is not numbers is a header (``x,z``: the columns are taken by name)."""
    import numpy as np

    from ..errors import FrictionRulesError
    if path.lower().endswith(".npy"):
        with open(path, "rb") as fh:
            try:
                np.lib.format.read_magic(fh)
                fh.seek(0)
                data = np.lib.format.read_array(fh, allow_pickle=False)
            except (ValueError, EOFError) as exc:
                reason = "object arrays are not read" if "allow_pickle" in str(exc) else (
                    str(exc).splitlines() or [type(exc).__name__])[0]
                raise FrictionRulesError(f"{geo} file {path!r} violates: a NumPy .npy array of "
                                         f"numbers ({reason})") from None
        if data.dtype.kind not in "iuf":
            raise FrictionRulesError(f"{geo} file {path!r} violates: a NumPy array of numbers "
                                     f"(got dtype {getattr(data, 'dtype', type(data))})")
        return data.astype(float)
    with open(path, encoding="utf-8", errors="replace") as fh:
        lines = [(i + 1, line.strip()) for i, line in enumerate(fh)]
    lines = [(i, line) for i, line in lines if line and not line.startswith("#")]
    names = None
    rows = []
    for k, (i, line) in enumerate(lines):
        cells = [c.strip() for c in line.split(",")]
        try:
            rows.append([float(c) for c in cells])
        except ValueError:
            if k == 0 and not rows:
                names = [c.lower() for c in cells]
                continue
            raise FrictionRulesError(f"{geo} file {path!r}, line {i}: {line[:60]!r} violates: "
                                     "comma-separated numbers") from None
    if not rows or len({len(r) for r in rows}) != 1:
        raise FrictionRulesError(f"{geo} file {path!r} violates: rows of comma-separated numbers "
                                 "with the same number of columns")
    data = np.array(rows)
    if names and geo == "profile" and {"x", "z"} <= set(names) and len(names) == data.shape[1]:
        data = data[:, [names.index("x"), names.index("z")]]
    return data


def _outputs(args):
    """The files ``--out`` will hold, checked before any work (none without ``--out``)."""
    from pathlib import Path

    from .._output import check_output
    from ..errors import FrictionRulesError
    if args.out is None:
        if args.format is not None:
            raise FrictionRulesError(f"--format {args.format} violates: it chooses the format of "
                                     "the tables written into --out DIR; give --out too (without "
                                     "it the results are printed as text)")
        return None
    from .._output import FIGURE_SUFFIXES, TABLE_SUFFIXES
    out = Path(args.out)
    if (out.exists() and not out.is_dir()) or out.suffix.lower() in TABLE_SUFFIXES + \
            FIGURE_SUFFIXES:
        raise FrictionRulesError(f"--out = {args.out!r} violates: a folder (the tables and the "
                                 "figure are written into it)")
    ext = f".{args.format or 'csv'}"
    files = {"limit_curve": out / f"limit_curve{ext}", "mu_theta": out / f"mu_theta{ext}",
             "corners": out / f"corners{ext}"}
    for path in files.values():
        check_output(path, (ext,), name="--out")
    if not args.no_figure:
        files["figure"] = check_output(out / "limit_curve.png", (".png",), name="--out")
    return files


def run(args) -> int:
    import sys
    import warnings

    import numpy as np

    files = _outputs(args)
    conf = _settings(args)
    conf["n"] = _count_of_directions(conf.get("n", 360))
    Q = _number(conf, "Q", 1.0, lo=0.0, lo_open=True)
    with progress(args, "asperity", total=3, unit="stages") as bar:
        bar.phase("facets and mu(theta)")
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", UserWarning)
            law, surface = _law(conf)
        bar(1)
        n = conf["n"]
        if surface is not None:
            theta, mu_theta, locked = surface.theta, surface.mu, surface.locked
        else:
            theta = np.linspace(-np.pi, np.pi, n, endpoint=False)
            inv = law.inverse_relation(theta, Q)
            locked = inv.locked
            with np.errstate(invalid="ignore"):
                mu_theta = np.where(locked, np.inf, np.hypot(*np.moveaxis(inv.force, -1, 0)) / Q)
        bar.phase("limit curve")
        curve = law.limit_curve(Q, n=n)
        measured = conf["geometry"] in _MEASURED
        if measured:    # corners within a degree or two of 180°: noise of the facet estimate
            curve, merged = curve.merged(), len(curve.corners)
            merged -= len(curve.corners)
        bar(2)
        if files is not None:
            bar.phase("writing")
            written = _write(files, args, conf, law, surface, curve, theta, mu_theta, locked, Q)
        bar(3)
    _report(conf, law, surface, curve, mu_theta, locked, Q, merged if measured else None)
    for w in caught:
        print(f"frictionrules asperity: warning: {w.message}", file=sys.stderr)
    if files is not None:
        for path in written:
            print(f"wrote {path}")
    return 0


def _count(law) -> int:
    """Number of facets of a facet law (a two-flank groove has two)."""
    normals = law.normals() if callable(law.normals) else law.normals
    return len(normals)


def _report(conf, law, surface, curve, mu_theta, locked, Q, merged) -> None:
    """Print the summary; ``merged`` is the number of noise corners merged away (None: the
    geometry is exact and every corner is kept)."""
    import numpy as np
    facets = _count(law)
    if surface is not None:
        unit = surface.unit or "length unit"
        px = " x ".join(f"{v:.4g}" for v in surface.pixel_size)
        print(f"{conf['file']}: {' x '.join(map(str, surface.shape[::-1]))} points, pixel "
              f"{px} {unit}, {surface.undefined} undefined")
        print(f"scale (ISO Gaussian cut-off) {surface.scale:.4g} {unit}, detrend "
              f"{surface.detrend}; steepest facet slope {surface.max_slope:.4g}, rms "
              f"{surface.rms_slope:.4g}")
    print(f"{type(law).__name__}: {facets} facet(s), mu = {law.mu:g}, {law.local}, Q = {Q:g}")
    noise = "" if merged is None else (
        f" (and {merged} within {np.rad2deg(curve.NOISE_CORNER):g} deg of 180 deg, merged away: "
        "noise of the facet estimate)")
    print(f"corners: {len(curve.corners)}, concave: {len(curve.concave_corners)}{noise}")
    for c in curve.corners[:12]:
        print(f"  T = ({c.T[0]:.6g}, {c.T[1]:.6g})  {'+'.join(map(str, c.before))} -> "
              f"{'+'.join(map(str, c.after))}  interior {np.rad2deg(c.interior):.3f} deg"
              f"{'  concave' if c.concave else ''}")
    if len(curve.corners) > 12:
        print(f"  ... {len(curve.corners) - 12} more (corners table with --out)")
    free = mu_theta[~locked]
    line = f"locked directions {int(locked.sum())} of {len(mu_theta)}"
    if surface is not None and surface.near_locking.any():
        line += f" ({int(surface.near_locking.sum())} with mu(theta) > 100)"
    if len(free):
        print(f"mu(theta): min {free.min():.6g}, max {free.max():.6g}, anisotropy "
              f"{free.max() / free.min():.4g}, {line}")
    else:
        print(f"mu(theta): {line}")
    if surface is not None and len(free):
        i = np.flatnonzero(~locked)[np.argmin(surface.carrying[~locked])]
        print(f"bound tan(atan(steepest slope) + atan mu) = {surface.upper_bound:.6g}; carrying "
              f"facets: at least {surface.carrying[i]} of {surface.facets} "
              f"({surface.carrying_fraction[i]:.2g})")


def _write(files, args, conf, law, surface, curve, theta, mu_theta, locked, Q) -> list:
    import numpy as np

    from .._output import write_table
    facets = _count(law)
    params = {k: conf[k] for k in ("mu", "local", "Q", "n", "alpha1", "alpha2", "deg", "dx", "dy",
                                   "file", "detrend") if k in conf}
    if surface is not None:
        params.update(scale=surface.scale, unit=surface.unit, detrend=surface.detrend)
    meta = metadata(args, model=f"{type(law).__name__} ({facets} facets)", parameters=params)
    fin = np.isfinite(curve.load)
    written = [write_table(files["limit_curve"], {
        "direction": curve.direction, "Tx": curve.T[:, 0], "Ty": curve.T[:, 1],
        "load": curve.load, "locked": ~fin, "mechanism": np.array(curve.labels),
        "N_a": curve.normal_forces[:, 0], "N_b": curve.normal_forces[:, 1],
        "Vx": curve.velocity[:, 0], "Vy": curve.velocity[:, 1], "Vz": curve.velocity[:, 2],
        "rule_angle": curve.rule_angle, "quasi_static": curve.quasi_static},
        units={"direction": "rad", "Tx": "force", "Ty": "force", "load": "force", "locked": "1",
               "mechanism": "-", "N_a": "force", "N_b": "force", "Vx": "1", "Vy": "1",
               "Vz": "1", "rule_angle": "rad", "quasi_static": "1"},
        metadata={**meta, "note": "load and T are inf (null in JSON) where locked; forces in "
                                  "the unit of Q"})]
    cols = {"theta": theta, "mu": mu_theta, "locked": locked}
    units = {"theta": "rad", "mu": "1", "locked": "1"}
    if surface is not None:
        cols.update(near_locking=surface.near_locking, carrying=surface.carrying,
                    carrying_fraction=surface.carrying_fraction)
        units.update(near_locking="1", carrying="1", carrying_fraction="1")
    written.append(write_table(files["mu_theta"], cols, units=units, metadata={
        **meta, "note": "mu is inf (null in JSON) where locked; near_locking: mu(theta) > 100 "
                        "classified locked"}))
    c = curve.corners
    written.append(write_table(files["corners"], {
        "Tx": np.array([k.T[0] for k in c]), "Ty": np.array([k.T[1] for k in c]),
        "direction": np.array([k.direction for k in c]),
        "before": np.array(["+".join(map(str, k.before)) for k in c], dtype=str),
        "after": np.array(["+".join(map(str, k.after)) for k in c], dtype=str),
        "interior": np.array([np.rad2deg(k.interior) for k in c]),
        "concave": np.array([k.concave for k in c], dtype=bool)},
        units={"Tx": "force", "Ty": "force", "direction": "rad", "before": "-", "after": "-",
               "interior": "deg", "concave": "1"},
        metadata={**meta, **({"note": f"corners within {np.rad2deg(curve.NOISE_CORNER):g} deg "
                                      "of 180 deg are merged (noise of the facet estimate)"}
                             if conf["geometry"] in _MEASURED else {})}))
    if "figure" in files:
        written.append(_figure(files["figure"], conf, law, curve, Q, meta))
    return written


#: Geometries measured on a real surface: their many facets are drawn by family and their
#: noise corners merged.
_MEASURED = ("topography", "profile", "heightmap")


def _figure(path, conf, law, curve, Q, meta):
    """The limit curve: by mechanism family for a measured surface, by mechanism (with the
    potentials) for a geometry of a few facets."""
    import matplotlib.pyplot as plt
    import numpy as np

    from .._output import write_figure
    from ..plot.asperities import limit_curve, surface_limit_curve
    load = curve.load[np.isfinite(curve.load)]
    box = float(min(2.0 * np.max(load), 4.0 * np.median(load))) if len(load) else 1.0
    rule = f"$\\mu$ = {law.mu:g}, {law.local} local rule, $Q$ = {Q:g}"
    if conf["geometry"] in _MEASURED:
        from pathlib import Path
        ax = surface_limit_curve(curve, box=box)
        ax.set_title(f"limit curve of {Path(str(conf['file'])).name}: {_count(law)} facets\n{rule}",
                     fontsize=9)
    else:
        ax = limit_curve(law, Q, box=box, n=max(conf["n"], 720))
        ax.set_title(f"limit curve of {type(law).__name__}, {_count(law)} facets\n{rule}",
                     fontsize=9)
        ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0, fontsize=7)
    written = write_figure(ax.figure, path, metadata=meta, bbox_inches="tight")
    plt.close(ax.figure)
    return written
