"""``frictionrules solve FILE.hdf5 | DIR``: solve FCLIB problems and print or tabulate the results."""

from __future__ import annotations

CSV_HEADER = "file,contacts,method,iterations,error,converged,seconds"


def register(sub) -> None:
    p = sub.add_parser("solve", help="solve FCLIB frictional contact problems",
                       description="Read an FCLIB HDF5 file (or every *.hdf5 in a folder), solve it "
                                   "and print contacts, iterations, error (Siconos' measure) and time.")
    p.add_argument("path", metavar="FILE_OR_DIR", help="an FCLIB .hdf5 file or a folder of them")
    p.add_argument("--method", default="nsgs", choices=("nsgs", "newton", "prox"),
                   help="solver (default: nsgs)")
    p.add_argument("--tol", type=float, default=1e-8, help="tolerance on the error (default: 1e-8)")
    p.add_argument("--max-iter", type=int, default=None, help="iteration limit (default: per method)")
    p.add_argument("--csv", metavar="OUT.csv", help="also write the table to this CSV file")
    p.set_defaults(run=run)


def run(args) -> int:
    from pathlib import Path

    from .._atomic import write_text
    from ..errors import FrictionRulesError
    from ..io import read_fclib
    from ..multicontact import FrictionContactProblem, solve

    path = Path(args.path)
    files = sorted(path.glob("*.hdf5")) if path.is_dir() else [path]
    if path.is_dir() and not files:
        raise FrictionRulesError(f"folder {path} holds no *.hdf5 file")
    # load the compiled kernels once, so that the printed times are the solvers' own
    solve(FrictionContactProblem([[1.0, 0, 0], [0, 1, 0], [0, 0, 1]], [-1.0, 2.0, 0.0], [0.5]),
          method=args.method)
    rows = [CSV_HEADER]
    print(f"{'file':45s} {'contacts':>8s} {'method':>7s} {'iter':>7s} {'error':>9s} {'time/s':>8s}")
    failed = 0
    for f in files:
        try:
            problem = read_fclib(f)
        except FrictionRulesError as err:
            if not path.is_dir():
                raise
            failed += 1                     # one bad file in a folder: report it, go on
            print(f"{f.name:45s} error: {err}")
            rows.append(f"{f.name},,{args.method},,,0,")
        else:
            s = solve(problem, method=args.method, tol=args.tol, max_iter=args.max_iter)
            flag = "" if s.converged else "  (not converged)"
            failed += not s.converged
            print(f"{f.name:45s} {problem.nc:8d} {args.method:>7s} {s.iterations:7d} "
                  f"{s.error:9.2e} {s.seconds:8.3f}{flag}")
            rows.append(f"{f.name},{problem.nc},{args.method},{s.iterations},{s.error:.3e},"
                        f"{int(s.converged)},{s.seconds:.6f}")
        if args.csv:                        # rewritten atomically after every file:
            write_text(args.csv, "\n".join(rows) + "\n")   # an interrupted run keeps its rows
    if args.csv:
        print(f"wrote {args.csv}")
    return 1 if failed else 0
