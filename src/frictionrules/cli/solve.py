"""``frictionrules solve FILE.hdf5 | DIR``: solve FCLIB problems and print or tabulate the results.

A thin layer over :func:`frictionrules.solve_many`: a folder run writes its table as results
arrive and resumes from it; ``--workers``/``--scheduler`` spread the problems over a local Dask
cluster or a running one. The methods are the solver's table (``multicontact.METHODS``).
Printed times are each solve's CPU time (and wall time); the start of a cluster and of its
worker processes is reported apart.
"""

from __future__ import annotations

import argparse


def _positive_int(text):
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"invalid integer value: {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"{value} violates >= 1")
    return value


def _float_type(strict: bool):
    """An argparse type: a finite number, > 0 (``strict``) or >= 0."""
    def parse(text):
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"invalid number: {text!r}") from None
        if not (value > 0 if strict else value >= 0) or value == float("inf"):
            raise argparse.ArgumentTypeError(f"{value} violates: finite and {'>' if strict else '>='} 0")
        return value
    return parse


_positive_float, _tolerance = _float_type(True), _float_type(False)


def register(sub) -> None:
    p = sub.add_parser(
        "solve", help="solve FCLIB frictional contact problems",
        description="Read an FCLIB HDF5 file (or every *.hdf5 in a folder), solve it and print "
                    "contacts, method, iterations, error (Siconos' measure), time and, when not "
                    "converged, why. Exit code 0 when every problem converged, 1 otherwise, 2 on "
                    "bad input.")
    p.add_argument("path", metavar="FILE_OR_DIR", help="an FCLIB .hdf5 file or a folder of them")
    from ..multicontact import METHODS
    p.add_argument("--method", default="auto", choices=tuple(METHODS),
                   help="solver (default: auto); " + "; ".join(f"{m.name}: {m.summary}" for m in METHODS.values()))
    p.add_argument("--tol", type=_tolerance, default=1e-8, help="tolerance on the error (default: 1e-8)")
    p.add_argument("--max-iter", type=_positive_int, default=None,
                   help="iteration limit (default: per method, see docs/multicontact.md)")
    p.add_argument("--time-limit", type=_positive_float, default=None, metavar="SECONDS",
                   help="wall-clock limit per problem; a problem stopped by it is reported as not "
                        "converged (reason time_limit). It bounds the solve, not the start-up before "
                        "it (loading the compiled kernels or, on a first run, compiling them, which "
                        "cannot be interrupted), reported apart on the last line")
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
    from .._output import check_folder, check_output
    path = check_output(path, suffixes, name=option)
    check_folder(path.parent, name=option, shown=path)


def _row(rec) -> str:
    if rec.reason == "bad input":
        return f"{rec.name:45s} error: {rec.message}"
    flag = "" if rec.converged else f"  (not converged: {rec.reason})"
    method = rec.solution.method if rec.solution is not None else rec.method
    return (f"{rec.name:45s} {rec.contacts:8d} {method:>11s} {rec.iterations:7d} "
            f"{rec.error:9.2e} {rec.cpu_seconds:8.3f} {rec.seconds:8.3f}{flag}"
            + ("  (from --csv)" if rec.resumed else ""))


def run(args) -> int:
    from pathlib import Path

    import shlex
    import sys
    import time

    from ..parallel import dask_client, local_cluster
    from .._progress import Progress
    from ..batch import solve_many
    from ..errors import FrictionRulesError
    from ..io import read_fclib

    path = Path(args.path)
    folder = path.is_dir()
    if not folder and not path.is_file():
        raise FrictionRulesError(f"{path}: no such FCLIB file or folder")
    if args.csv:
        _check_output("--csv", args.csv, (".csv",))
    if args.save_solution:
        if folder:
            _check_output("--save-solution", Path(args.save_solution) / "probe.hdf5", (".hdf5",))
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

    print(f"{'file':45s} {'contacts':>8s} {'method':>11s} {'iter':>7s} {'error':>9s} {'cpu/s':>8s} {'wall/s':>8s}",
          flush=True)
    command = getattr(args, "command_line", None) or " ".join(shlex.quote(a) for a in sys.argv)
    with Progress("solve", unit="problems") as progress:
        finished = [0]

        def on_result(rec):
            finished[0] += 1
            progress.phase("")
            progress(finished[0])
            print(_row(rec), flush=True)

        save = args.save_solution
        metadata = {"command": command, "workers": args.workers, "scheduler": args.scheduler}
        kwargs = dict(method=args.method, tol=args.tol, max_iter=args.max_iter,
                      time_limit=args.time_limit, warm_start=args.warm_start, out=args.csv,
                      on_result=on_result, metadata=metadata)
        cluster_seconds = None
        if not folder:
            records = _solve_file(path, kwargs, progress, save)
        elif args.workers or args.scheduler:
            t0 = time.perf_counter()
            context = local_cluster(args.workers) if args.workers else dask_client(args.scheduler)
            with context as client:
                cluster_seconds = time.perf_counter() - t0
                records = solve_many(path, executor=client, save_solutions=save, **kwargs)
        else:
            records = solve_many(path, save_solutions=save, **_with_progress(kwargs, progress))
        for rec in records:
            if rec.resumed:
                print(_row(rec))
        progress.close(summary_line(records, cluster_seconds))
    if args.csv:
        print(f"wrote {args.csv}")
    if save and not folder:
        print(f"wrote {save}")
    return 0 if all(r.converged for r in records) else 1


def summary_line(records, cluster_seconds=None) -> str:
    """One line: how many problems converged, failed or were unreadable, the solvers' CPU time
    and, apart, the start-up of the processes (and of the cluster)."""
    solved = [r for r in records if r.reason != "bad input"]
    conv = sum(r.converged for r in solved)
    bad = len(records) - len(solved)
    cpu = sum(r.cpu_seconds for r in records if not r.resumed)
    startup = sum(r.startup_seconds for r in records if not r.resumed)
    resumed = sum(r.resumed for r in records)
    return (f"{conv} converged, {len(solved) - conv} not converged, {bad} unreadable"
            + (f", {resumed} from the earlier table" if resumed else "")
            + f"; {cpu:.2f} s of solver CPU time; start-up {startup:.2f} s"
            + (f" (cluster {cluster_seconds:.2f} s)" if cluster_seconds is not None else "") + " apart")


def _with_progress(kwargs, progress):
    """The serial run's keyword arguments: on a terminal its problems report their iterations."""
    if not progress.terminal:
        return kwargs

    import time
    last = [0.0]

    def show(name, info):                   # redrawn at most 4 times a second
        if time.monotonic() - last[0] >= 0.25:
            last[0] = time.monotonic()
            progress.phase(f"{name}: {info.method} iteration {info.iteration}, error {info.error:.2e}")
    return dict(kwargs, callback=show)


def _solve_file(path, kwargs, progress, save):
    """One file, solved here; ``save`` receives its solution."""
    from ..batch import solve_many
    from ..errors import FrictionRulesError
    from ..io import write_solution
    records = solve_many([path], **_with_progress(dict(kwargs, on_result=None), progress))
    rec = records[0]
    if rec.reason == "bad input":           # e.g. a warm start of the wrong size: exit 2
        raise FrictionRulesError(rec.message)
    kwargs["on_result"](rec)
    if save and rec.solution is not None:
        write_solution(save, rec.solution, source=rec.name, tol=kwargs["tol"])
    return records
