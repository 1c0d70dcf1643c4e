"""``frictionrules export LAW_SPEC --target TARGET --out DIR --kt KT [--kn KN]``: write a law as
an Abaqus user subroutine (FRIC, VFRIC, UINTER) or a C kernel, with its input snippet and
README."""

from __future__ import annotations

from ._common import finite_float

TARGETS = ("abaqus-fric", "abaqus-vfric", "abaqus-uinter", "c")
#: Laws a TOML file may name with ``type`` (else ``[law]`` is a user law).
_TOML_TYPES = ("Coulomb", "EllipticOrthotropic", "Huber", "TransformedCoulomb", "WedgeAsperity",
               "EllipsoidCap", "FacetSet")


def register(sub) -> None:
    from .law import LAWS, add_law_arguments
    p = sub.add_parser(
        "export", help="write a law as an Abaqus user subroutine (FRIC, VFRIC, UINTER) or C code",
        description="Print the law's return mapping from its symbolic form as fixed-form Fortran "
                    "(Abaqus FRIC, VFRIC, UINTER) or C99, with an input snippet and a README "
                    "naming every PROPS and STATEV entry. LAW_SPEC is a law as 'frictionrules "
                    "law' takes it (" + ", ".join(LAWS) + ", with its parameter options) or a "
                    "TOML file whose [law] table holds a user law (limit, potential, params, "
                    "state, rates) or a built-in law (type = one of " + ", ".join(_TOML_TYPES)
                    + ", and its parameters); an optional [hardening] table (h, kappa_h) adds "
                    "slip hardening.",
        epilog="example: frictionrules export elliptic --mu-x 0.6 --mu-y 0.3 --target abaqus-fric "
               "--kt 1e4 --out fric")
    p.add_argument("spec", metavar="LAW_SPEC", help=f"one of: {', '.join(LAWS)}; or FILE.toml")
    add_law_arguments(p)
    p.add_argument("--deg", action="store_true", help="angles (alpha, angle) in degrees")
    p.add_argument("--target", required=True, choices=TARGETS, help="what to write")
    p.add_argument("--out", required=True, metavar="DIR", help="folder to write to")
    p.add_argument("--kt", type=finite_float, required=True,
                   help="elastic-slip (tangential penalty) stiffness, > 0")
    p.add_argument("--kn", type=finite_float, default=None,
                   help="normal penalty stiffness, > 0 (abaqus-uinter and c)")
    p.add_argument("--hardening", nargs=2, type=finite_float, default=None,
                   metavar=("H", "KAPPA_H"), help="slip hardening mu(1 + H(1 - exp(-kappa/KAPPA_H)))")
    p.add_argument("--name", default=None, help="identifier of the generated code (default: the "
                   "law's class name)")
    p.set_defaults(run=run)


def _toml_law(path: str):
    """``(law, hardening table or None)`` of a TOML law file."""
    import frictionrules as fr
    from .._toml import load_toml
    from ..errors import FrictionRulesError
    doc = load_toml(path)
    unknown = sorted(set(doc) - {"law", "hardening"})
    if unknown:
        raise FrictionRulesError(f"{path}: unknown tables {unknown}; known: law, hardening")
    table = doc.get("law")
    if not isinstance(table, dict):
        raise FrictionRulesError(f"{path}: [law] = {table!r} violates: a table (limit, "
                                 "potential, params, state, rates; or type and parameters)")
    table = dict(table)
    kind = table.pop("type", None)
    if kind is None:
        law = fr.UserLaw.from_mapping(table, name=f"{path}: [law]")
    elif kind not in _TOML_TYPES:
        raise FrictionRulesError(f"{path}: [law] type = {kind!r} violates: one of "
                                 f"{', '.join(_TOML_TYPES)} (or no type: a user law)")
    else:
        try:
            law = _built_in(fr, kind, table)
        except TypeError as exc:
            raise FrictionRulesError(f"{path}: [law] {kind}: {exc}") from None
    hard = doc.get("hardening")
    if hard is not None and not isinstance(hard, dict):
        raise FrictionRulesError(f"{path}: [hardening] = {hard!r} violates: a table (h, kappa_h)")
    return law, hard


def _built_in(fr, kind, table):
    if kind == "EllipsoidCap":
        A = fr.laws.AreaHardening(**{k: table.pop(k) for k in ("p", "h", "kappa_h") if k in table})
        B = fr.laws.AreaGrowth(**{k: table.pop(k) for k in ("b",) if k in table})
        return fr.EllipsoidCap(A=A, B=B, **table)
    return getattr(fr, kind)(**table)


def run(args) -> int:
    from pathlib import Path

    import frictionrules as fr
    from ..errors import FrictionRulesError
    from .law import _law_name, build_law

    hardening = None
    if args.spec.lower().endswith(".toml") or Path(args.spec).is_file():
        law, hard = _toml_law(args.spec)
        if hard is not None:
            try:
                hardening = fr.SlipHardening(**hard)
            except TypeError as exc:
                raise FrictionRulesError(f"{args.spec}: [hardening]: {exc}") from None
    else:
        import argparse
        try:
            name = _law_name(args.spec)
        except argparse.ArgumentTypeError as exc:
            raise FrictionRulesError(f"LAW_SPEC = {args.spec!r} violates: {exc}; or a TOML "
                                     "file") from None
        law = build_law(name, args)
    if args.hardening is not None:
        if hardening is not None:
            raise FrictionRulesError("--hardening and a [hardening] table violate: give one")
        hardening = fr.SlipHardening(*args.hardening)
    result = fr.export(law, args.target, args.out, kt=args.kt, kn=args.kn, hardening=hardening,
                       name=args.name)
    print(summary(result))
    for path in result.files:
        print(f"wrote {path}")
    return 0


def summary(result) -> str:
    """One line in the words of the host: the Abaqus keyword and its PROPERTIES and DEPVAR, or
    the C arrays ``params`` and ``state``."""
    values = ", ".join(f"{n}={v:.6g}" for n, v in zip(result.props_names, result.props))
    if result.target == "c":
        return (f"c: params[{len(result.props)}] = {{{values}}}, state[{result.nstatv}]"
                + ("; the tangent is unsymmetric (a general 3 x 3 matrix)"
                   if result.unsymmetric else ""))
    keyword = "*SURFACE INTERACTION, USER" if result.target == "abaqus-uinter" else "*FRICTION, USER"
    return (f"{result.target}: {keyword}, DEPVAR={result.nstatv}, PROPERTIES={len(result.props)}"
            f" ({values})" + ("; unsymmetric tangent: *STEP, UNSYMM=YES"
                              if result.unsymmetric and result.target != "abaqus-vfric" else ""))
