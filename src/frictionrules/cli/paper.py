"""``frictionrules paper --out DIR``: make the figures, index them and print the key numbers."""

from __future__ import annotations

_DESCRIPTION = """\
Reproduce the paper. Writes every figure (PNG and SVG by default) under DIR: the paper's
figures in DIR/paper/ (fig1a_coulomb_cone, ... fig10c_cap_shear_curves), the figures beyond
the paper in DIR/extra/, and DIR/index.md listing each figure with its caption. Run without
--only it also prints the table of key numbers (the paper's values beside ours).

--only STEM makes only the named figures and computes only what they need: no key numbers
unless --numbers is given. --list prints the figures and their captions. Progress goes to
stderr: a counter on a terminal, one summary line otherwise."""


def register(sub) -> None:
    import argparse
    p = sub.add_parser("paper", help="reproduce the paper's figures and print key numbers",
                       description=_DESCRIPTION, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--out", default="figures", metavar="DIR",
                   help="output folder (default: figures); figures go to DIR/paper/ and DIR/extra/")
    p.add_argument("--format", dest="formats", action="append", choices=("png", "svg", "pdf"),
                   help="file format, repeatable (default: png and svg)")
    p.add_argument("--only", action="append", metavar="STEM",
                   help="make only this figure (repeatable), e.g. fig5_two_flank or paper/fig5_two_flank; "
                        "skips the key numbers unless --numbers is given")
    p.add_argument("--numbers", action="store_true",
                   help="print the key-number table also with --only (it is printed by default "
                        "when every figure is made)")
    p.add_argument("--list", action="store_true", help="list the figures with their captions and exit")
    p.set_defaults(run=run)


def run(args) -> int:
    from .._progress import Progress
    from ..paper import check_requirements, format_table, key_numbers, make_figures, select

    chosen = select(args.only, argument="--only")
    if args.list:
        for f in chosen:
            print(f"{f.name}\n    {f.caption}")
        return 0
    from pathlib import Path

    from .._output import check_folder
    from ..paper import EXTRA, PAPER
    for folder in (Path(args.out), Path(args.out) / PAPER, Path(args.out) / EXTRA):
        check_folder(folder, name="--out")
    check_requirements()
    numbers = args.numbers or not args.only
    total = len(chosen) + numbers
    with Progress("paper", total=total, unit="steps") as step:
        written = make_figures(args.out, formats=tuple(args.formats or ("png", "svg")),
                               names=args.only, progress=lambda done, _: step(done, total))
        if numbers:
            step.phase("key numbers")
            table = format_table(key_numbers())
            step(total, total)
        else:
            table = None
    print(f"wrote {len(written)} files to {args.out}/ (captions in {args.out}/index.md)")
    for path in written:
        print(f"  {path}")
    if table is not None:
        print()
        print(table)
    return 0
