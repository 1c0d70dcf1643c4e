"""Argument helpers shared by the subcommands: checked number types, outputs, provenance,
progress."""

from __future__ import annotations

import argparse
import math


def finite_float(text: str) -> float:
    """argparse type: a finite real number (``-1e-6`` and ``-0.5`` included)."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"{text!r} violates: must be a finite number")
    return value


#: Largest count a command accepts (points of a path, directions of a sweep): a bound, so that
#: a mistyped number is an error and not a run of days.
MAX_COUNT = 1_000_000


def positive_int(text: str) -> int:
    """argparse type: an integer in ``[1, MAX_COUNT]``."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not an integer") from None
    if not 1 <= value <= MAX_COUNT:
        raise argparse.ArgumentTypeError(f"{value} violates: must be an integer >= 1 and "
                                         f"<= {MAX_COUNT}")
    return value


def add_quiet(parser) -> None:
    parser.add_argument("--quiet", action="store_true",
                        help="no progress on stderr (shown on a terminal, one summary line otherwise)")


def progress(args, label: str, total: int | None = None, unit: str = "steps"):
    """The progress reporter of a command (silent with ``--quiet``)."""
    from .._progress import Progress
    return Progress(label, total, unit=unit, enabled=not getattr(args, "quiet", False))


def metadata(args, *, model=None, parameters=None, **extra) -> dict:
    """Provenance of a command's outputs: version, command line, model, parameters."""
    from .._output import provenance
    return provenance(command=getattr(args, "command_line", None), model=model,
                      parameters=parameters, **extra)


def with_preload(args, loading: dict) -> None:
    """``frictionrules assembly --preload`` into the keyword arguments of ``triaxial`` read
    from [loading] (the option overrides the file's ``preload``)."""
    if args.preload is not None:
        loading["preload"] = args.preload
