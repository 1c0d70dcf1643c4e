"""The table of solver methods: one record per ``method`` name, read by :func:`~frictionrules.solve`,
:func:`~frictionrules.solve_many` and ``frictionrules solve --method``.

A method added here is accepted everywhere, with its options record, its default iteration
limit and its one-line summary (the CLI's help).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import Callable

from ..errors import FrictionRulesError
from ._admm import run_admm
from ._newton import run_newton
from ._nsgs import run_nsgs
from ._options import ADMMOptions, NewtonOptions, NSGSOptions, PolishOptions, ProxOptions
from ._polish import run_polish
from ._prox import run_prox

__all__ = ["SolverMethod", "METHODS", "options_for", "check_method"]


@dataclass(frozen=True)
class SolverMethod:
    """One method of :func:`~frictionrules.solve`.

    Attributes
    ----------
    name : str
        The ``method`` argument.
    summary : str
        One line: what the method does.
    iteration : str
        What ``max_iter`` counts.
    max_iter : int
        The default ``max_iter``.
    options : type or None
        Its options record (None: ``"auto"``, which takes none).
    run : callable or None
        ``run(frame, r, max_iter, monitor, options) -> (r, iterations)`` (None: ``"auto"``).
    """

    name: str
    summary: str
    iteration: str
    max_iter: int
    options: type | None = None
    run: Callable | None = None


#: Every method, by name (``"auto"`` first: the default).
METHODS: dict[str, SolverMethod] = {m.name: m for m in (
    SolverMethod("auto", "chosen from the problem's size, first-order stages then the polish",
                 "iterations of all its stages together", 100000),
    SolverMethod("nsgs", "non-smooth Gauss-Seidel over the contacts, exact local solver",
                 "sweeps", 100000, NSGSOptions, run_nsgs),
    SolverMethod("newton", "semismooth Newton on the Alart-Curnier function", "Newton iterations",
                 200, NewtonOptions, run_newton),
    SolverMethod("prox", "proximal point with an inner semismooth Newton", "outer proximal iterations",
                 200, ProxOptions, run_prox),
    SolverMethod("admm", "ADMM with De Saxce's correction, adaptive penalty, Anderson acceleration",
                 "ADMM iterations", 5000, ADMMOptions, run_admm),
    SolverMethod("polish", "semismooth Newton on the natural map from a settled active set",
                 "Newton steps", 50, PolishOptions, run_polish),
)}


def check_method(method) -> SolverMethod:
    """The table's record of ``method``; raises naming the accepted names."""
    if not isinstance(method, str) or method not in METHODS:
        raise FrictionRulesError(f"method = {method!r}; constraint: one of {sorted(METHODS)}")
    return METHODS[method]


@functools.cache
def _defaults(cls):
    """The default record of an options class (records are frozen: one instance serves all)."""
    return cls()


def options_for(method: str, options):
    """``options`` checked against ``method`` (the method's defaults when None)."""
    cls = METHODS[method].options
    if cls is None:
        if options is not None:
            raise FrictionRulesError(f"options: constraint: none with method = {method!r} (name a method)")
        return None
    if options is None:
        return _defaults(cls)
    if not isinstance(options, cls):
        raise FrictionRulesError(f"options = {options!r} does not match method = {method!r}; "
                                 f"constraint: a {cls.__name__}")
    return options
