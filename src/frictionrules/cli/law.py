"""``frictionrules law NAME --param value ... --force Tx Ty --normal N [--json]``."""

from __future__ import annotations

import json

#: CLI name -> (class name in frictionrules, parameters it takes)
LAWS = {
    "coulomb": ("Coulomb", ("mu", "dilatant")),
    "elliptic": ("EllipticOrthotropic", ("mu_x", "mu_y", "angle")),
    "huber": ("Huber", ("mu_1", "mu_2", "angle")),
    "transformed": ("TransformedCoulomb", ("mu_x", "mu_y", "angle")),
    "wedge": ("WedgeAsperity", ("alpha", "mu", "local")),
    "user": ("UserLaw", ("limit", "potential")),
}
_ALIASES = {"ellipticorthotropic": "elliptic", "orthotropic": "elliptic",
            "transformedcoulomb": "transformed", "wedgeasperity": "wedge", "userlaw": "user"}
_ANGLES = ("angle", "alpha")
_FLOATS = ("mu", "mu_x", "mu_y", "mu_1", "mu_2", "angle", "alpha")


def _law_name(text: str) -> str:
    key = text.lower().replace("-", "").replace("_", "")
    key = _ALIASES.get(key, key)
    if key not in LAWS:
        import argparse
        raise argparse.ArgumentTypeError(
            f"unknown law {text!r}; choose from {', '.join(LAWS)} (or the class names)")
    return key


def register(sub) -> None:
    p = sub.add_parser(
        "law", help="evaluate a friction law at a force: f, slip direction, mu(theta)",
        description="Evaluate a law at (T, N): the limit condition f, the slip direction of its "
                    "sliding rule and the directional friction coefficient mu(theta). Laws and "
                    "their parameters: " + "; ".join(f"{k} ({', '.join(v[1])})" for k, v in LAWS.items()),
        epilog="example: frictionrules law elliptic --mu-x 0.6 --mu-y 0.3 --force 0.3 0.2 --normal 1 --json")
    p.add_argument("name", type=_law_name, metavar="NAME", help=f"one of: {', '.join(LAWS)}")
    for name in _FLOATS:
        flags = sorted({f"--{name.replace('_', '-')}", f"--{name}"})
        p.add_argument(*flags, dest=name, type=float, default=None,
                       help=f"parameter {name}" + (" (radians, or degrees with --deg)" if name in _ANGLES else ""))
    p.add_argument("--dilatant", action="store_true", default=None, help="coulomb: associated rule (1.6)")
    p.add_argument("--local", choices=("non-associated", "associated"), default=None,
                   help="wedge: local sliding rule")
    p.add_argument("--limit", default=None, metavar="EXPR", help="user: f in T1, T2, N (SymPy syntax)")
    p.add_argument("--potential", default=None, metavar="EXPR", help="user: g in T1, T2, N")
    p.add_argument("--param", action="append", default=[], metavar="NAME=VALUE",
                   help="any parameter as NAME=VALUE (repeatable)")
    p.add_argument("--force", nargs=2, type=float, required=True, metavar=("T1", "T2"),
                   help="tangential force (for wedge: horizontal load Tx Ty)")
    p.add_argument("--normal", type=float, required=True, metavar="N",
                   help="normal force, compression positive (for wedge: vertical load Q)")
    p.add_argument("--theta", type=float, default=None,
                   help="slip angle for mu(theta) (default: the slip angle at the given force)")
    p.add_argument("--deg", action="store_true", help="angles (alpha, angle, theta, output) in degrees")
    p.add_argument("--json", action="store_true", help="print JSON instead of text")
    p.set_defaults(run=run)


def build_law(name: str, args):
    """The law object of the CLI arguments (shared with tests and other subcommands)."""
    import numpy as np

    import frictionrules as fr
    from ..errors import FrictionRulesError

    cls_name, accepted = LAWS[name]
    given = {k: getattr(args, k, None) for k in (*_FLOATS, "dilatant", "local", "limit", "potential")}
    for item in args.param:
        key, sep, value = item.partition("=")
        key = key.strip().replace("-", "_")
        if not sep or key not in given:
            raise FrictionRulesError(f"--param {item!r} is not NAME=VALUE with a known NAME")
        given[key] = float(value) if key in _FLOATS else value
    params = {k: v for k, v in given.items() if v is not None}
    extra = sorted(set(params) - set(accepted))
    if extra:
        raise FrictionRulesError(f"law {name!r} takes {', '.join(accepted)}; not {', '.join(extra)}")
    if args.deg:
        params = {k: (np.deg2rad(v) if k in _ANGLES else v) for k, v in params.items()}
    try:
        return getattr(fr, cls_name)(**params)
    except TypeError as exc:
        raise FrictionRulesError(f"law {name!r} needs its parameters {', '.join(accepted)}: {exc}") from exc


def evaluate(law, T, N, theta=None) -> dict:
    """The numbers printed by ``frictionrules law`` as a dict."""
    import numpy as np

    f = float(law.limit(T, N))
    scale = max(float(np.hypot(*T)), abs(N), 1e-300)
    state = "stick" if f < -1e-12 * scale else ("sliding (on the limit surface)" if f <= 1e-12 * scale
                                                 else "inadmissible (outside the limit surface)")
    out = {"law": repr(law), "force": list(map(float, T)), "normal": float(N), "limit": f, "state": state}
    try:
        v = law.slip_direction(T, N)
        out["slip_direction"] = [float(x) for x in v]
    except ValueError as exc:
        v, out["slip_direction"] = None, str(exc)
    if theta is None:
        theta = (float(np.arctan2(v[1], v[0])) if v is not None and np.hypot(v[0], v[1]) > 0
                 else float(np.arctan2(T[1], T[0])))
    out["theta"] = theta
    out["friction_coefficient"] = float(law.friction_coefficient(theta))
    if np.isfinite(out["friction_coefficient"]):
        out["force_angle"] = float(law.force_angle(theta))
    return out


def run(args) -> int:
    import numpy as np

    law = build_law(args.name, args)
    theta = None if args.theta is None else (np.deg2rad(args.theta) if args.deg else args.theta)
    out = evaluate(law, np.array(args.force), args.normal, theta)
    if args.deg:
        out = {k: (float(np.rad2deg(v)) if k in ("theta", "force_angle") else v) for k, v in out.items()}
    if args.json:
        print(json.dumps(out, indent=2))
        return 0
    unit = "deg" if args.deg else "rad"
    print(f"law                   {out['law']}")
    print(f"force, normal         T = {out['force']}, N = {out['normal']}")
    print(f"limit f               {out['limit']:.6g}  ({out['state']})")
    sd = out["slip_direction"]
    print("slip direction        " + (f"(v1, v2, vn) = ({sd[0]:.6g}, {sd[1]:.6g}, {sd[2]:.6g})"
                                      if isinstance(sd, list) else sd))
    print(f"slip angle theta      {out['theta']:.6g} {unit}")
    print(f"mu(theta)             {out['friction_coefficient']:.6g}")
    if "force_angle" in out:
        print(f"force angle beta      {out['force_angle']:.6g} {unit}")
    return 0
