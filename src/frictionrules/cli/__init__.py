"""Command-line interface: ``frictionrules SUBCOMMAND ...``.

The CLI is thin: each subcommand module parses its options into library objects, calls the
library and prints or writes. A subcommand module provides ``register(subparsers)``, which adds
its parser and sets ``run=function(args) -> int``. Library imports happen inside ``run`` so
that ``frictionrules --help`` stays fast.
"""

from __future__ import annotations

import argparse
import importlib
import sys

from ..errors import FrictionRulesError

#: Subcommand modules of this package, in the order ``--help`` lists them.
SUBCOMMANDS = ("paper", "law", "solve", "configuration", "drive", "asperity")


class _Parser(argparse.ArgumentParser):
    """Argument parser whose usage errors are one line on stderr with exit code 2."""

    def error(self, message):
        self.exit(2, f"{self.prog}: error: {message}\n")


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="frictionrules",
        description="Contact friction as plasticity: laws, sliding rules, asperity mechanisms, "
                    "contact integration and multi-contact solvers.")
    from .. import __version__
    parser.add_argument("--version", action="version", version=f"frictionrules {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for name in SUBCOMMANDS:
        importlib.import_module(f".{name}", __name__).register(sub)
    return parser


def main(argv=None) -> int:
    """Entry point of the ``frictionrules`` console script; returns the exit code.

    Bad input (a :class:`FrictionRulesError`, a missing or unreadable file) and a missing
    optional package exit with code 2 and a one-line message on stderr.
    """
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.run(args) or 0)
    except ModuleNotFoundError as exc:  # an optional package: name the extra that installs it
        from .._optional import missing_module_message
        if (msg := missing_module_message(exc)) is None:
            raise
        print(f"frictionrules {args.command}: error: {msg}", file=sys.stderr)
        return 2
    except (FrictionRulesError, OSError) as exc:
        msg = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        print(f"frictionrules {args.command}: error: {msg}", file=sys.stderr)
        return 2


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
