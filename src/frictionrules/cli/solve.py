"""``frictionrules solve FILE.hdf5 | DIR``: solve FCLIB problems and print or tabulate the results.

A thin layer over :func:`frictionrules.solve_many`: a folder run writes its table as results
arrive and resumes from it; ``--workers``/``--scheduler`` spread the problems over a local Dask
cluster or a running one.
"""

from __future__ import annotations

import argparse

METHOD_CHOICES = ("auto", "nsgs", "newton", "prox", "admm")


def _positive_int(text):
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"invalid integer value: {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"{value} violates >= 1")
    return value


def _positive_float(text):
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"invalid number: {text!r}") from None
    if not value > 0 or value == float("inf"):
        raise argparse.ArgumentTypeError(f"{value} violates: finite and > 0")
    return value


def _tolerance(text):
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"invalid number: {text!r}") from None
    if not 0 <= value < float("inf"):
        raise argparse.ArgumentTypeError(f"{value} violates: finite and >= 0")
    return value


def register(sub) -> None:
    p = sub.add_parser(
        "solve", help="solve FCLIB frictional contact problems",
        description="Read an FCLIB HDF5 file (or every *.hdf5 in a folder), solve it and print "
                    "contacts, method, iterations, error (Siconos' measure), time and, when not "
                    "converged, why. Exit code 0 when every problem converged, 1 otherwise, 2 on "
                    "bad input.")
    p.add_argument("path", metavar="FILE_OR_DIR", help="an FCLIB .hdf5 file or a folder of them")
    p.add_argument("--method", default="auto", choices=METHOD_CHOICES,
                   help="solver (default: auto, chosen from the problem's size and structure)")
    p.add_argument("--tol", type=_tolerance, default=1e-8, help="tolerance on the error (default: 1e-8)")
    p.add_argument("--max-iter", type=_positive_int, default=None,
                   help="iteration limit (default: per method, see docs/multicontact.md)")
    p.add_argument("--time-limit", type=_positive_float, default=None, metavar="SECONDS",
                   help="wall-clock limit per problem; a problem stopped by it is reported as not "
                        "converged (reason time_limit)")
    p.add_argument("--csv", metavar="OUT.csv",
                   help="also write the table to this CSV file, after every problem; a folder run "
                        "skips the files this table already lists for the same method (resume)")
    p.add_argument("--restart", action="store_true",
                   help="solve every file again even if --csv already lists it")
    p.add_argument("--save-solution", metavar="PATH",
                   help="write the solution (r, u, error, reason) as HDF5: to PATH for a file, or "
                        "into the folder PATH (one file per problem, named like it) for a folder")
    p.add_argument("--warm-start", nargs="?", const="guess", default=None, metavar="SOLUTION",
                   help="start from the file's /guesses/1/r (no value), or from a solution saved by "
                        "--save-solution (a file, or a folder of them)")
    where = p.add_mutually_exclusive_group()
    where.add_argument("--workers", type=_positive_int, default=None, metavar="N",
                       help="solve a folder on a local Dask cluster of N worker processes "
                            "(needs the extra frictionrules[dask])")
    where.add_argument("--scheduler", metavar="ADDRESS",
                       help="solve a folder on the Dask cluster whose scheduler is at ADDRESS "
                            "(tcp://host:8786)")
    p.set_defaults(run=run)


def _check_output(option: str, path, suffixes) -> None:
    """Fail before any work if ``path`` has the wrong suffix or its folder cannot be written."""
    import os
    import tempfile
    from pathlib import Path

    from ..errors import FrictionRulesError
    path = Path(path)
    if suffixes and path.suffix.lower() not in suffixes:
        raise FrictionRulesError(f"{option} {path}: constraint: a file name ending in "
                                 f"{' or '.join(suffixes)}")
    folder = path.parent
    try:
        folder.mkdir(parents=True, exist_ok=True)
        fd, probe = tempfile.mkstemp(dir=folder, prefix=".frictionrules-probe-")
        os.close(fd)
        os.unlink(probe)
    except OSError as exc:
        raise FrictionRulesError(f"{option} {path}: cannot write in {folder} "
                                 f"({exc.strerror or type(exc).__name__})") from None


def _row(rec) -> str:
    if rec.reason == "bad input":
        return f"{rec.name:45s} error: {rec.message}"
    flag = "" if rec.converged else f"  (not converged: {rec.reason})"
    method = rec.solution.method if rec.solution is not None else rec.method
    return (f"{rec.name:45s} {rec.contacts:8d} {method:>11s} {rec.iterations:7d} "
            f"{rec.error:9.2e} {rec.seconds:8.3f}{flag}" + ("  (from --csv)" if rec.resumed else ""))


class _Progress:
    """Progress on stderr when it is a terminal: the running problem's error, rewritten in
    place at most twice a second; nothing otherwise (one summary line is printed at the end)."""

    def __init__(self, stream):
        self.stream = stream
        self.live = stream.isatty()
        self.last = 0.0
        self.shown = False

    def iteration(self, name: str, info) -> None:
        import time
        if not self.live or time.monotonic() - self.last < 0.5:
            return
        self.last = time.monotonic()
        self.stream.write(f"\r{name}: {info.method} iteration {info.iteration}, error {info.error:.2e}, "
                          f"{info.seconds:.1f} s\033[K")
        self.stream.flush()
        self.shown = True

    def clear(self) -> None:
        if self.shown:
            self.stream.write("\r\033[K")
            self.stream.flush()
            self.shown = False


def run(args) -> int:
    import sys
    from pathlib import Path

    from .._parallel import dask_client, local_cluster
    from ..errors import FrictionRulesError
    from ..io import read_fclib
    from ..multicontact import FrictionContactProblem, solve
    from ..multicontact._many import solve_many, summary_line

    path = Path(args.path)
    folder = path.is_dir()
    if not folder and not path.is_file():
        raise FrictionRulesError(f"{path}: no such FCLIB file or folder")
    if args.csv:
        _check_output("--csv", args.csv, (".csv",))
    if args.save_solution:
        if folder:
            _check_output("--save-solution", Path(args.save_solution) / "probe.hdf5", ())
        else:
            _check_output("--save-solution", args.save_solution, (".hdf5", ".h5"))
    if args.warm_start not in (None, "guess") and not Path(args.warm_start).exists():
        raise FrictionRulesError(f"--warm-start {args.warm_start}: no such file or folder")
    if (args.workers or args.scheduler) and not folder:
        raise FrictionRulesError("--workers/--scheduler: constraint: a folder of problems")
    if args.restart and args.csv and Path(args.csv).exists():
        Path(args.csv).unlink()
    if not folder:
        read_fclib(path)                    # a bad file is bad input: one line, exit 2
    # load the compiled kernels once, so that the printed times are the solvers' own
    solve(FrictionContactProblem([[1.0, 0, 0], [0, 1, 0], [0, 0, 1]], [-1.0, 2.0, 0.0], [0.5]),
          method=args.method if args.method != "auto" else "nsgs")

    progress = _Progress(sys.stderr)
    print(f"{'file':45s} {'contacts':>8s} {'method':>11s} {'iter':>7s} {'error':>9s} {'time/s':>8s}",
          flush=True)

    def on_result(rec):
        progress.clear()
        print(_row(rec), flush=True)

    save = args.save_solution
    kwargs = dict(method=args.method, tol=args.tol, max_iter=args.max_iter, time_limit=args.time_limit,
                  warm_start=args.warm_start, out=args.csv, on_result=on_result)
    if not folder:
        records = _solve_file(path, kwargs, progress, save)
    elif args.workers or args.scheduler:
        context = local_cluster(args.workers) if args.workers else dask_client(args.scheduler)
        with context as client:
            records = solve_many(path, executor=client, save_solutions=save, **kwargs)
    else:
        records = solve_many(path, save_solutions=save, **_with_progress(kwargs, progress))
    for rec in records:
        if rec.resumed:
            print(_row(rec))
    progress.clear()
    if not progress.live:
        print(summary_line(records), file=sys.stderr)
    if args.csv:
        print(f"wrote {args.csv}")
    if save and not folder:
        print(f"wrote {save}")
    return 0 if all(r.converged for r in records) else 1


def _with_progress(kwargs, progress):
    """The serial run's keyword arguments: on a terminal its problems report their iterations."""
    return dict(kwargs, callback=progress.iteration) if progress.live else kwargs


def _solve_file(path, kwargs, progress, save):
    """One file, solved here; ``save`` receives its solution."""
    from ..io import write_solution
    from ..multicontact._many import solve_many
    from ..errors import FrictionRulesError
    records = solve_many([path], **_with_progress(dict(kwargs, on_result=None), progress))
    rec = records[0]
    if rec.reason == "bad input":           # e.g. a warm start of the wrong size: exit 2
        raise FrictionRulesError(rec.message)
    kwargs["on_result"](rec)
    if save and rec.solution is not None:
        write_solution(save, rec.solution, source=rec.name, tol=kwargs["tol"])
    return records
