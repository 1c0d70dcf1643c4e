"""``frictionrules assembly CONFIG.toml --seeds 1,2,3 --out FOLDER``: an ensemble of random
samples (``frictionrules.ensemble``), one run file per seed in the run folder (a second call
keeps the finished runs and resumes the others), the summary printed and written to
``FOLDER/summary.csv`` and ``summary.json``, the mean curves drawn with ``--figure``."""

from __future__ import annotations

import contextlib

#: The summary's files in the run folder.
SUMMARY_FILES = ("summary.csv", "summary.json")


def _executor(args):
    """The Dask client of ``--workers``/``--scheduler`` as a context, else None."""
    if args.workers:
        from ..parallel import local_cluster
        return local_cluster(args.workers)
    if args.scheduler:
        from ..parallel import dask_client
        return dask_client(args.scheduler)
    return contextlib.nullcontext(None)


def run_ensemble(args, figure) -> int:
    from .._output import check_folder, write_table
    from ..assembly import ensemble, read_samples
    from ..errors import FrictionRulesError
    from . import _common

    if args.vtk:
        raise FrictionRulesError(f"--vtk = {args.vtk!r} violates: a single run (no seeds)")
    if args.out.lower().endswith((".h5", ".hdf5")):
        raise FrictionRulesError(f"--out = {args.out!r} violates: a folder for the runs' files "
                                 "with seeds (one run file per seed)")
    folder = check_folder(args.out)
    if not (args.workers or args.scheduler):
        from .._threads import prefer_openmp
        prefer_openmp()  # the runs go in this process, which does not fork
    with _common.progress(args, "assembly", unit="samples") as bar:
        bar.phase("preparing the samples")
        assemblies, seeds, loading = read_samples(args.config, seeds=args.seeds, progress=bar)
        _common.with_preload(args, loading)
        bar.phase("")
        bar.unit = "runs"
        kind = loading.pop("kind")
        with _executor(args) as executor:
            result = ensemble(assemblies, kind, executor=executor, run_folder=folder,
                              max_time=args.max_time, progress=bar, **loading)
    for run in result.runs:
        seed = seeds[run.sample]
        if run.result is None:
            what = run.error or run.status
        else:
            what = run.result.message
        print(f"seed {seed}: {run.status} ({what}), {run.run_file.name}")
    print(result.format_summary())
    cols, units = result.table()
    meta = _common.metadata(args, model=assemblies[0].model, parameters=dict(kind=kind, **loading),
                            seeds=seeds, runs=[r.run_file.name for r in result.runs])
    for name in SUMMARY_FILES:
        path = write_table(folder / name, cols, units=units, metadata=meta)
        print(f"wrote {path}")
    if figure is not None:
        _figure(args, result, figure, meta)
        print(f"wrote {figure}")
    return 0 if all(r.completed for r in result.runs) else 1


def _figure(args, result, figure, meta) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from .._output import write_figure
    from ..plot.assembly import plot_ensemble
    fig, axes = plt.subplots(1, 2, figsize=(9, 3.6))
    plot_ensemble(result, "stress_ratio", ax=axes[0])
    plot_ensemble(result, "volumetric_strain", ax=axes[1])
    fig.tight_layout()
    write_figure(fig, figure, metadata=meta)
    plt.close(fig)
