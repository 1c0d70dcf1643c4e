"""``frictionrules paper --out DIR``: make every figure and print the key numbers."""

from __future__ import annotations


def register(sub) -> None:
    p = sub.add_parser("paper", help="reproduce the paper's figures and print key numbers",
                       description="Write every figure the library can make (PNG and SVG) to DIR "
                                   "and print a table of key numbers.")
    p.add_argument("--out", default="figures", metavar="DIR", help="output folder (default: figures)")
    p.add_argument("--format", dest="formats", action="append", choices=("png", "svg", "pdf"),
                   help="file format, repeatable (default: png and svg)")
    p.add_argument("--only", action="append", metavar="STEM", help="make only this figure (repeatable)")
    p.set_defaults(run=run)


def run(args) -> int:
    from ..errors import FrictionRulesError
    from ..paper import FIGURES, format_table, key_numbers, make_figures

    known = {stem for stem, _ in FIGURES}
    for stem in args.only or ():
        if stem not in known:
            raise FrictionRulesError(f"--only {stem!r} is not a figure; choose from {sorted(known)}")
    written = make_figures(args.out, formats=tuple(args.formats or ("png", "svg")), names=args.only)
    print(f"wrote {len(written)} files to {args.out}/")
    for path in written:
        print(f"  {path}")
    print()
    print(format_table(key_numbers()))
    return 0
