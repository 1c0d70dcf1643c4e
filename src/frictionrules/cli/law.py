"""``frictionrules law NAME --param value ... --force Tx Ty --normal N [--json]``."""

from __future__ import annotations

from ._common import finite_float

#: CLI name -> (class name in frictionrules, parameters it takes)
LAWS = {
    "coulomb": ("Coulomb", ("mu", "dilatant")),
    "elliptic": ("EllipticOrthotropic", ("mu_x", "mu_y", "angle")),
    "huber": ("Huber", ("mu_1", "mu_2", "angle")),
    "transformed": ("TransformedCoulomb", ("mu_x", "mu_y", "angle")),
    "wedge": ("WedgeAsperity", ("alpha", "mu", "local")),
    "user": ("UserLaw", ("limit", "potential", "NAME=VALUE parameters")),
}
_ALIASES = {"ellipticorthotropic": "elliptic", "orthotropic": "elliptic",
            "transformedcoulomb": "transformed", "wedgeasperity": "wedge", "userlaw": "user"}
_ANGLES = ("angle", "alpha")
_FLOATS = ("mu", "mu_x", "mu_y", "mu_1", "mu_2", "angle", "alpha")
_EXPRESSIONS = ("limit", "potential")
_BOOLEANS = {"true": True, "yes": True, "1": True, "false": False, "no": False, "0": False}


def _law_name(text: str) -> str:
    key = text.lower().replace("-", "").replace("_", "")
    key = _ALIASES.get(key, key)
    if key not in LAWS:
        import argparse
        raise argparse.ArgumentTypeError(
            f"unknown law {text!r}; choose from {', '.join(LAWS)} (or the class names)")
    return key


def add_law_arguments(p) -> None:
    """The options that give a law's parameters (shared by the subcommands that take a law
    as ``frictionrules law`` does; :func:`build_law` reads them)."""
    for name in _FLOATS:
        flags = sorted({f"--{name.replace('_', '-')}", f"--{name}"})
        p.add_argument(*flags, dest=name, type=finite_float, default=None,
                       help=f"parameter {name}" + (" (radians, or degrees with --deg)" if name in _ANGLES else ""))
    p.add_argument("--dilatant", action="store_true", default=None, help="coulomb: associated rule (1.6)")
    p.add_argument("--local", choices=("non-associated", "associated"), default=None,
                   help="wedge: local sliding rule")
    p.add_argument("--limit", default=None, metavar="EXPR",
                   help="user: f in T1, T2, N, e.g. 'sqrt(T1^2 + T2^2) - 0.3*N' (numbers, + - * / "
                        "** ^, sqrt, abs, exp, log, sin, cos, tan, atan, atan2, Max, Min, ...)")
    p.add_argument("--potential", default=None, metavar="EXPR", help="user: g in T1, T2, N")
    p.add_argument("--param", action="append", default=[], metavar="NAME=VALUE",
                   help="any parameter as NAME=VALUE (repeatable); for a user law, the value of "
                        "a parameter its expressions name (--param mu=0.3)")


def register(sub) -> None:
    p = sub.add_parser(
        "law", help="evaluate a friction law at a force: f, state, slip direction, mu(theta)",
        description="Evaluate a law at (T, N): the limit condition f and the state (stick inside "
                    "the limit surface, slip on it), the slip direction of its sliding rule when "
                    "it slips, the directional friction coefficient mu(theta) and the angle beta "
                    "of the limit force that slides at theta. theta is --theta, or the slip angle "
                    "when the force slips, or else the direction of T. Laws and their "
                    "parameters: " + "; ".join(f"{k} ({', '.join(v[1])})" for k, v in LAWS.items()),
        epilog="example: frictionrules law elliptic --mu-x 0.6 --mu-y 0.3 --force 0.3 0.2 --normal 1 --json")
    p.add_argument("name", type=_law_name, metavar="NAME", help=f"one of: {', '.join(LAWS)}")
    add_law_arguments(p)
    p.add_argument("--force", nargs=2, type=finite_float, required=True, metavar=("T1", "T2"),
                   help="tangential force (for wedge: horizontal load Tx Ty)")
    p.add_argument("--normal", type=finite_float, required=True, metavar="N",
                   help="normal force, compression positive (for wedge: vertical load Q)")
    p.add_argument("--theta", type=finite_float, default=None,
                   help="slip angle for mu(theta) (default: the slip angle when the force slips, "
                        "else the direction of T)")
    p.add_argument("--deg", action="store_true", help="angles (alpha, angle, theta, output) in degrees")
    p.add_argument("--json", action="store_true", help="print JSON instead of text (strict JSON: "
                   "a locked mu(theta) is null with \"locked\": true)")
    p.add_argument("--quiet", action="store_true", help="no progress on stderr (user laws)")
    p.set_defaults(run=run)


def _param_value(key: str, value: str, item: str):
    from ..errors import FrictionRulesError
    if key in _FLOATS:
        import argparse
        try:
            return finite_float(value)
        except argparse.ArgumentTypeError:
            raise FrictionRulesError(f"--param {item!r}: {key} = {value!r} violates: must be a "
                                     "finite number") from None
    if key == "dilatant":
        if value.strip().lower() not in _BOOLEANS:
            raise FrictionRulesError(f"--param {item!r}: dilatant = {value!r} violates: true or false")
        return _BOOLEANS[value.strip().lower()]
    return value


def build_law(name: str, args):
    """The law object of the CLI arguments (shared with tests and other subcommands).

    A user law parses its expressions with the whitelist parser: the text is never evaluated
    as code.
    """
    import numpy as np

    import frictionrules as fr
    from ..errors import FrictionRulesError

    cls_name, accepted = LAWS[name]
    given = {k: getattr(args, k, None) for k in (*_FLOATS, "dilatant", "local", *_EXPRESSIONS)}
    flag_of = {k: f"--{k.replace('_', '-')}" for k in given}
    named = {}  # a user law's own parameters (--param mu=0.3 for the symbol mu)
    for item in args.param:
        key, sep, value = item.partition("=")
        key = key.strip().replace("-", "_")
        if sep and name == "user" and key not in _EXPRESSIONS and key.isidentifier():
            named[key] = _param_value("mu", value, item)  # a number, like mu
            continue
        if not sep or key not in given:
            raise FrictionRulesError(f"--param {item!r} violates: NAME=VALUE with NAME one of "
                                     f"{', '.join(sorted(given))}")
        given[key] = _param_value(key, value, item)
        flag_of[key] = f"--param {key}"
    params = {k: v for k, v in given.items() if v is not None}
    if name == "user":  # the number options name parameters of the user's expressions
        named = {**{k: params.pop(k) for k in _FLOATS if k in params}, **named}
    extra = sorted(set(params) - set(accepted))
    if extra:
        raise FrictionRulesError(f"law {name!r} takes {', '.join(accepted)}; not {', '.join(extra)}")
    if args.deg:
        params = {k: (float(np.deg2rad(v)) if k in _ANGLES else v) for k, v in params.items()}
        named = {k: (float(np.deg2rad(v)) if k in _ANGLES else v) for k, v in named.items()}
    if name == "user" and named:
        params["params"] = named
    import inspect
    cls = getattr(fr, cls_name)
    required = [k for k, p in inspect.signature(cls).parameters.items()
                if p.default is inspect.Parameter.empty and p.kind is p.POSITIONAL_OR_KEYWORD]
    missing = [k for k in required if k not in params]
    if missing:
        raise FrictionRulesError(f"law {name!r} needs {', '.join(flag_of[k] for k in missing)} "
                                 f"(its parameters: {', '.join(accepted)})")
    return cls(**params)


def evaluate(law, T, N, theta=None) -> dict:
    """The numbers printed by ``frictionrules law``, as a dict (angles in radians).

    ``state`` is ``"stick"`` (f < 0), ``"slip"`` (on the limit surface) or ``"inadmissible"``
    (f > 0); ``slip_direction`` is None unless the force slips. ``theta`` is the given angle,
    else the slip angle when the force slips, else the direction of ``T`` (``theta_from`` says
    which). ``friction_coefficient`` is mu(theta), ``inf`` with ``locked`` True where no finite
    force slides at theta; ``force_angle`` is the angle beta of the limit force that slides at
    theta ((1.14)) and ``force_direction`` the angle of the given ``T``.
    """
    import numpy as np

    from ..errors import FrictionRulesError

    T = np.asarray(T, dtype=float)
    f = float(law.limit(T, N))
    scale = max(float(np.hypot(*T)), abs(float(N)), 1e-300)
    state = "stick" if f < -1e-12 * scale else ("slip" if f <= 1e-12 * scale else "inadmissible")
    out = {"law": repr(law), "force": [float(x) for x in T], "normal": float(N), "limit": f,
           "state": state, "slip_direction": None}
    if np.hypot(*T) > 0:
        out["force_direction"] = float(np.arctan2(T[1], T[0]))
    if state == "slip":
        out["slip_direction"] = [float(x) for x in law.slip_direction(T, N)]
    v = out["slip_direction"]
    if theta is not None:
        out["theta"], out["theta_from"] = float(theta), "--theta"
    elif v is not None and np.hypot(v[0], v[1]) > 0:
        out["theta"], out["theta_from"] = float(np.arctan2(v[1], v[0])), "slip"
    else:
        out["theta"], out["theta_from"] = out.get("force_direction", 0.0), "force"
    at = float(N) if N > 0 else 1.0  # mu(theta) = |T|/N at the given N (1 if N = 0)
    mu = float(law.friction_coefficient(out["theta"], at))
    out["friction_coefficient"] = mu
    out["locked"] = not np.isfinite(mu)
    if not out["locked"]:
        try:
            out["force_angle"] = float(law.force_angle(out["theta"], at))
        except FrictionRulesError:  # locked after all: no limit force at theta
            out["locked"] = True
    return out


_ANGLE_KEYS = ("theta", "force_angle", "force_direction")


def law_text(law, deg: bool) -> str:
    """``repr(law)``, with its angle parameters (``alpha``, ``angle``) in degrees when ``deg``:
    the law as the command line was given it."""
    import dataclasses

    import numpy as np
    if not deg or not dataclasses.is_dataclass(law):
        return repr(law)
    parts = [f"{f.name}={np.rad2deg(getattr(law, f.name)):.12g} deg" if f.name in _ANGLES
             else f"{f.name}={getattr(law, f.name)!r}" for f in dataclasses.fields(law) if f.repr]
    return f"{type(law).__name__}({', '.join(parts)})"


def run(args) -> int:
    import numpy as np

    from .._output import dumps_json
    from . import _common

    law = build_law(args.name, args)
    theta = None if args.theta is None else (np.deg2rad(args.theta) if args.deg else args.theta)
    if args.name == "user":  # compiling the symbolic law takes seconds: say so on a terminal
        with _common.progress(args, "law user") as bar:
            bar.phase("compiling the law")
            out = evaluate(law, np.array(args.force), args.normal, theta)
    else:
        out = evaluate(law, np.array(args.force), args.normal, theta)
    unit = "deg" if args.deg else "rad"
    out["law"] = law_text(law, args.deg)
    if args.deg:
        out = {k: (float(np.rad2deg(v)) if k in _ANGLE_KEYS else v) for k, v in out.items()}
    if args.json:
        out["units"] = {"force": "force", "normal": "force", "limit": "units of f",
                        "slip_direction": "1",
                        "friction_coefficient": "1", **{k: unit for k in _ANGLE_KEYS if k in out}}
        print(dumps_json(out, indent=2), end="")
        return 0
    state = {"stick": "stick: inside the limit surface", "slip": "slip: on the limit surface",
             "inadmissible": "inadmissible: outside the limit surface"}[out["state"]]
    print(f"law                   {out['law']}")
    print(f"force, normal         T = ({out['force'][0]:.6g}, {out['force'][1]:.6g}), N = {out['normal']:.6g}"
          + (f"; T at {out['force_direction']:.6g} {unit}" if "force_direction" in out else ""))
    print(f"limit f               {out['limit']:.6g}")
    print(f"state                 {state}")
    sd = out["slip_direction"]
    print("slip direction        " + (f"(v1, v2, vn) = ({sd[0]:.6g}, {sd[1]:.6g}, {sd[2]:.6g})"
                                      if sd is not None else f"none ({out['state']})"))
    source = {"--theta": "given", "slip": "the slip angle", "force": "the direction of T"}
    print(f"slip angle theta      {out['theta']:.6g} {unit}  ({source[out['theta_from']]})")
    print("mu(theta)             " + ("inf  (locked: no finite force slides at theta)" if out["locked"]
                                       else f"{out['friction_coefficient']:.6g}"))
    if "force_angle" in out:
        print(f"limit force at theta  angle beta = {out['force_angle']:.6g} {unit}, "
              f"|T|/N = {out['friction_coefficient']:.6g}")
    return 0
