"""``frictionrules law NAME|FILE.toml --param value ... --force Tx Ty --normal N [--json]``."""

from __future__ import annotations

from ._common import finite_float

_BOOLEANS = {"true": True, "yes": True, "1": True, "false": False, "no": False, "0": False}


def _options() -> dict:
    """The parameters a command line can give, by name: ``(Parameter, law names taking it)``,
    from the law table (a table of named numbers, a user law's ``params``, is given by
    ``--param``)."""
    from ..laws import LAWS
    out = {}
    for entry in LAWS.values():
        for p in entry.parameters.values():
            if p.kind is not dict:
                out.setdefault(p.name, (p, []))[1].append(entry.name)
    return out


def _laws_help() -> str:
    from ..laws import LAWS
    return "; ".join(f"{e.name} ({', '.join(e.parameters)})" for e in LAWS.values())


def add_law_arguments(p) -> None:
    """The options that give a law's parameters, one per parameter of the law table (shared by
    the subcommands that take a law as ``frictionrules law`` does; :func:`law_of_spec` reads
    them)."""
    for name, (par, laws) in _options().items():
        flags = sorted({f"--{name.replace('_', '-')}", f"--{name}"})
        what = f"{', '.join(laws)}: {par.meaning}" + (" (radians, or degrees with --deg)"
                                                      if par.unit == "rad" else "")
        if par.kind is bool:
            p.add_argument(*flags, dest=name, action="store_true", default=None, help=what)
        elif par.kind is float:
            p.add_argument(*flags, dest=name, type=finite_float, default=None, help=what)
        else:
            p.add_argument(*flags, dest=name, default=None, choices=par.choices or None,
                           metavar=None if par.choices else "EXPR", help=what)
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
                    "when the force slips, or else the direction of T. NAME is a law of the table "
                    "with its parameters as options, or a TOML file holding a [law] table "
                    "(frictionrules.read_law). Laws and their parameters: " + _laws_help(),
        epilog="example: frictionrules law elliptic --mu-x 0.6 --mu-y 0.3 --force 0.3 0.2 --normal 1 --json")
    p.add_argument("name", metavar="NAME", help="a law of the table (or its class name), or "
                   "FILE.toml")
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


def _param_value(par, value: str, item: str):
    from ..errors import FrictionRulesError
    if par.kind is float:
        import argparse
        try:
            return finite_float(value)
        except argparse.ArgumentTypeError:
            raise FrictionRulesError(f"--param {item!r}: {par.name} = {value!r} violates: must be "
                                     "a finite number") from None
    if par.kind is bool:
        if value.strip().lower() not in _BOOLEANS:
            raise FrictionRulesError(f"--param {item!r}: {par.name} = {value!r} violates: true or "
                                     "false")
        return _BOOLEANS[value.strip().lower()]
    return value


def law_of_spec(spec: str, args, what: str = "NAME"):
    """The law of a command line: a TOML law file (:func:`frictionrules.read_law`), or a name
    of the law table with its parameters as options. A user law parses its expressions with
    the whitelist parser: the text is never evaluated as code."""
    from pathlib import Path

    from ..errors import FrictionRulesError
    from ..laws import law_entry, read_law
    if spec.lower().endswith(".toml") or Path(spec).is_file():
        given = [f"--{k.replace('_', '-')}" for k in _options() if getattr(args, k, None)
                 is not None] + [f"--param {item}" for item in args.param]
        if given:
            raise FrictionRulesError(f"{what} = {spec!r} is a law file; the options {given} "
                                     "violate: the law's parameters go in the file")
        return read_law(spec)
    return build_law(law_entry(spec, where=what), args)


def build_law(entry, args):
    """The law of the table entry ``entry`` with the parameters given as options."""
    import numpy as np

    from ..errors import FrictionRulesError
    from ..laws import Parameter

    options = _options()
    table = entry.parameters
    given = {k: getattr(args, k) for k in options if getattr(args, k, None) is not None}
    flag_of = {k: f"--{k.replace('_', '-')}" for k in given}
    free = "params" in table      # the law takes named numbers (a user law's parameters)
    named = {}
    for item in args.param:
        key, sep, value = item.partition("=")
        key = key.strip().replace("-", "_")
        par = table.get(key) or options.get(key, (None,))[0]
        if sep and free and key.isidentifier() and (par is None or par.kind is float):
            named[key] = _param_value(Parameter(key, "a parameter of the expressions"), value,
                                      item)
            continue
        if not sep or par is None or par.kind is dict:
            raise FrictionRulesError(f"--param {item!r} violates: NAME=VALUE with NAME one of "
                                     f"{', '.join(sorted(options))}")
        given[key] = _param_value(par, value, item)
        flag_of[key] = f"--param {key}"
    if free:  # the number options name parameters of the user's expressions
        named = {**{k: given.pop(k) for k in list(given) if k not in table}, **named}
    extra = sorted(set(given) - set(table))
    if extra:
        raise FrictionRulesError(f"law {entry.name!r} takes {', '.join(table)}; not "
                                 f"{', '.join(extra)}")
    if args.deg:
        def rad(k, v):
            return float(np.deg2rad(v)) if k in options and options[k][0].unit == "rad" else v
        given = {k: rad(k, v) for k, v in given.items()}
        named = {k: rad(k, v) for k, v in named.items()}
    missing = [k for k, p in table.items() if p.required and k not in given]
    if missing:
        raise FrictionRulesError(f"law {entry.name!r} needs "
                                 f"{', '.join(flag_of.get(k, '--' + k.replace('_', '-')) for k in missing)} "
                                 f"(its parameters: {', '.join(table)})")
    if named:
        given["params"] = named
    return entry.cls.from_parameters(**given)


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
    angles = {k for k, par in law.parameter_info().items() if par.unit == "rad"}
    parts = [f"{f.name}={np.rad2deg(getattr(law, f.name)):.12g} deg" if f.name in angles
             else f"{f.name}={getattr(law, f.name)!r}" for f in dataclasses.fields(law) if f.repr]
    return f"{type(law).__name__}({', '.join(parts)})"


def run(args) -> int:
    import numpy as np

    from .._output import dumps_json
    from . import _common

    law = law_of_spec(args.name, args)
    theta = None if args.theta is None else (np.deg2rad(args.theta) if args.deg else args.theta)
    if "symbolic" in law.capabilities and law.declared_traits() is None:
        # a law known by its symbolic form only: compiling it takes seconds, say so
        with _common.progress(args, f"law {args.name}") as bar:
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
