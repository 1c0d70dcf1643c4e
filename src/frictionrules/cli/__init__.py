"""Command-line interface: ``frictionrules SUBCOMMAND ...``.

The CLI is thin: each subcommand module parses its options into library objects, calls the
library and prints or writes. A subcommand module provides ``register(subparsers)``, which adds
its parser and sets ``run=function(args) -> int``. Library imports happen inside ``run`` so
that ``frictionrules --help`` stays fast.

Exit codes: 0 success; 2 bad input (a usage error, a :class:`FrictionRulesError`, a missing or
unreadable file), one line on stderr naming the argument, the value and the constraint; 1 an
internal error (a bug: one line naming it; ``--debug`` or ``FRICTIONRULES_DEBUG=1`` shows the
traceback); 130 interrupted. A reader that closes the pipe early (``| head``) changes
nothing but what is printed: the rest of the output is discarded, the files are still written and
the exit code is the command's own (see :mod:`._streams`).
"""

from __future__ import annotations

import argparse
import importlib
import os
import re
import sys

from ..errors import FrictionRulesError

#: Subcommand modules of this package, in the order ``--help`` lists them.
SUBCOMMANDS = ("paper", "law", "solve", "configuration", "drive", "asperity", "export", "assembly")

#: Arguments that are values, not options, although they start with "-": numbers such as
#: ``-0.5``, ``-1e-6``, ``-inf`` and lists that start with one, ``-0.5,0,0.866;0.5,0,0.866``.
NEGATIVE_NUMBER = re.compile(
    r"^-(?:(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?|inf(?:inity)?|nan)(?:[,;:\s].*)?$",
    re.IGNORECASE | re.DOTALL)


class _Parser(argparse.ArgumentParser):
    """Argument parser whose usage errors are one line on stderr with exit code 2, and which
    takes negative numbers (and lists that start with one) as values."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = NEGATIVE_NUMBER

    def error(self, message):
        self.exit(2, f"{self.prog}: error: {' '.join(str(message).split())}\n")


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="frictionrules",
        description="Contact friction as plasticity: laws, sliding rules, asperity mechanisms, "
                    "contact integration and multi-contact solvers.")
    from .._version import __version__
    parser.add_argument("--version", action="version", version=f"frictionrules {__version__}")
    parser.add_argument("--debug", action="store_true",
                        help="show the traceback of an internal error (or FRICTIONRULES_DEBUG=1)")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for name in SUBCOMMANDS:
        importlib.import_module(f".{name}", __name__).register(sub)
    for p in sub.choices.values():  # --debug after the command too
        p.add_argument("--debug", action="store_true", default=argparse.SUPPRESS,
                       help="show the traceback of an internal error")
    return parser


def _one_line(exc: BaseException) -> str:
    text = " ".join(str(exc).split())
    return text or type(exc).__name__


def main(argv=None) -> int:
    """Entry point of the ``frictionrules`` console script; returns the exit code.

    Bad input (a :class:`FrictionRulesError`, a missing or unreadable file) and a missing
    optional package exit with code 2 and a one-line message on stderr; any other exception is
    an internal error, exit code 1, one line naming it (the traceback with ``--debug`` or
    ``FRICTIONRULES_DEBUG=1``). Standard output and error tolerate a reader that closes the
    pipe.
    """
    from ._streams import tolerate_closed_pipes
    with tolerate_closed_pipes():
        return _main(argv)


def _main(argv) -> int:
    from .._output import command_line
    from ._needs import check_needs

    argv = [str(a) for a in (sys.argv[1:] if argv is None else argv)]
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # usage error (2, one line already printed), --help, --version (0)
        return 0 if exc.code is None else exc.code if isinstance(exc.code, int) else 2
    args.command_line = command_line(argv)
    debug = args.debug or os.environ.get("FRICTIONRULES_DEBUG", "") not in ("", "0")
    try:
        check_needs(args)
        from .._progress import CompileNotice
        with CompileNotice(enabled=_compiles(args)):   # a line on a terminal while Numba compiles
            return int(args.run(args) or 0)
    except ModuleNotFoundError as exc:  # an optional package: name the extra that installs it
        from .._optional import missing_module_message
        if (msg := missing_module_message(exc)) is None:
            return _internal_error(args.command, exc, debug)
        print(f"frictionrules {args.command}: error: {msg}", file=sys.stderr)
        return 2
    except (FrictionRulesError, OSError) as exc:
        print(f"frictionrules {args.command}: error: {_one_line(exc)}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"frictionrules {args.command}: interrupted", file=sys.stderr)
        return 130
    except Exception as exc:
        return _internal_error(args.command, exc, debug)


def _compiles(args) -> bool:
    """Whether the command of ``args`` may compile kernels (it needs Numba), and is not quiet."""
    from ._needs import needs
    return "numba" in needs(args)[0] and not getattr(args, "quiet", False)


def _internal_error(command: str, exc: Exception, debug: bool) -> int:
    """One line naming an unexpected exception (a bug), exit code 1; re-raised with ``debug``."""
    if debug:
        raise exc
    text = _one_line(exc)
    text = text if len(text) <= 300 else text[:297] + "..."
    print(f"frictionrules {command}: internal error: {type(exc).__name__}: {text} (a bug: please "
          "report it with the traceback that FRICTIONRULES_DEBUG=1 or --debug shows)",
          file=sys.stderr)
    return 1


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
