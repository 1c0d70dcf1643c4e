"""The optional packages each command needs, checked together before the command starts, so that
one line names every missing package and the one ``pip install`` that brings them all (instead
of asking for ``hdf5``, then for ``solvers``, ...).

What the library imports lazily deeper down is still guarded where it is imported
(:func:`frictionrules._optional.require`); this table only brings the message forward.
"""

from __future__ import annotations

_KERNELS_AND_SYMBOLS = ("numba", "sympy")


def needs(args) -> tuple[tuple[str, ...], str | None]:
    """``(packages, extra)``: the packages the command of ``args`` needs with its options, and the
    extra that installs them all (None: each package's own extra)."""
    command = args.command
    if command == "paper":
        from ..paper import REQUIRES
        return ((), None) if args.list else (REQUIRES, "paper")
    if command == "solve":
        parallel = ("distributed",) if args.workers or args.scheduler else ()
        return ("h5py", "scipy", "threadpoolctl", "numba", *parallel), None
    if command == "drive":
        return (*_KERNELS_AND_SYMBOLS, *(("matplotlib",) if args.plot is not None else ())), None
    if command == "assembly":
        return ("h5py", *_KERNELS_AND_SYMBOLS, *(("matplotlib",) if args.figure else ())), None
    if command == "export":
        return ("sympy",), None
    if command == "configuration":
        return ("matplotlib",) if args.figure else (), None
    if command == "asperity":
        surface = ("SurfaceTopography", "scipy") if args.file else ()
        figure = ("matplotlib",) if args.out is not None and not args.no_figure else ()
        return (*surface, *figure), None
    return (), None


def check_needs(args) -> None:
    """Raise one :class:`~frictionrules.FrictionRulesError` naming every missing package."""
    from .._optional import require_all
    packages, extra = needs(args)
    require_all(packages, extra=extra, purpose=f"frictionrules {args.command}")
