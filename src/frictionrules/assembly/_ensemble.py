r"""Ensembles of loading tests: many samples, laws and pressures on any executor, summarised
by means with 95 % confidence intervals (``docs/assembly.md``, "Ensembles").

One run is one draw: the peak angle or the volumetric strain of a random sample moves from one
sample to the next (and with round-off alone). :func:`ensemble` runs :func:`triaxial` for every
sample and every point of a grid of options, each run on its own (its own run file in a run
folder), and summarises each condition (a contact model and a point of the grid) over its
samples.
"""

from __future__ import annotations

import hashlib
import inspect
import itertools
import json
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import FrictionRulesError, check_scalar
from ._geometry import Assembly
from ._loading import check_triaxial, triaxial
from ._results import TriaxialResult
from ._runfile import _sample_key
from ._statistics import CURVES, QUANTITIES, ConfidenceInterval, MeanCurve, end_values, interval, mean_curve

__all__ = ["ensemble", "EnsembleResult", "EnsembleRun", "EnsembleSummary", "RUN_STATUSES"]

#: What became of a run: "new" (run from the start), "resumed" (continued from its run file),
#: "kept" (its run file had finished: read back, nothing run), "failed" (raised an error: see
#: ``error``), "not started" (the ensemble's ``max_time`` had passed before it began).
RUN_STATUSES = ("new", "resumed", "kept", "failed", "not started")

#: The unit of the summary table's numbers: that of the row's quantity (its ``unit`` column).
_ROW = "the row's unit"

#: Arguments of :func:`triaxial` that :func:`ensemble` sets itself.
_OWN = ("assembly", "kind", "progress", "max_time", "run_file")


def _defaults() -> dict:
    return {name: p.default for name, p in inspect.signature(triaxial).parameters.items()
            if name not in _OWN}


@dataclass(frozen=True, eq=False)
class EnsembleRun:
    """One run of an ensemble.

    Attributes
    ----------
    index : int
        Its place in :attr:`EnsembleResult.runs`.
    sample : int
        The index of its assembly in ``assemblies``.
    options : dict
        The values of the options that vary (the grid's point; empty without a grid).
    condition : int
        The index of its condition in :attr:`EnsembleResult.summary`.
    result : TriaxialResult or None
        None where the run failed or did not start.
    status : str
        One of :data:`RUN_STATUSES`.
    error : str
        The error of a failed run, else empty.
    run_file : Path or None
        Its run file (with a run folder).
    seconds : float
        Wall time of the run in its worker.
    """

    index: int
    sample: int
    options: dict
    condition: int
    result: TriaxialResult | None
    status: str
    error: str = ""
    run_file: Path | None = None
    seconds: float = 0.0

    @property
    def completed(self) -> bool:
        """True where the run reached its axial strain (``result.message == "completed"``):
        the runs the summary is over."""
        return self.result is not None and self.result.message == "completed"


@dataclass(frozen=True, eq=False)
class EnsembleSummary:
    """The summary of one condition: its runs and the mean of each quantity with its 95 %
    confidence interval over the completed runs.

    Attributes
    ----------
    index : int
        Its place in :attr:`EnsembleResult.summary`.
    model : str
        The contact model of its assemblies.
    options : dict
        The grid's point (empty without a grid).
    runs : tuple of int
        The indices of its runs in :attr:`EnsembleResult.runs`.
    completed : int
        How many of them completed (the intervals are over these; the peak over those that
        also failed, as its ``n`` says).
    peak_friction_angle, critical_friction_angle : ConfidenceInterval
        Degrees: at the peak of σ1/σ3; the mean over the last fifth of the axial strain.
    volumetric_strain_end, coordination_end, sliding_fraction_end : ConfidenceInterval
        At the end of the runs (volumetric strain compression positive, dilation negative).
    """

    index: int
    model: str
    options: dict
    runs: tuple
    completed: int
    peak_friction_angle: ConfidenceInterval
    critical_friction_angle: ConfidenceInterval
    volumetric_strain_end: ConfidenceInterval
    coordination_end: ConfidenceInterval
    sliding_fraction_end: ConfidenceInterval


@dataclass(frozen=True, eq=False)
class EnsembleResult:
    """The outcome of :func:`ensemble`.

    Attributes
    ----------
    kind : str
        The test.
    runs : tuple of EnsembleRun
        Every run, in the order of :func:`ensemble` (whatever the order of completion).
    summary : tuple of EnsembleSummary
        One per condition, in the order of their first run.
    """

    kind: str
    runs: tuple
    summary: tuple

    def completed_results(self, condition: int = 0) -> list:
        """The results of the completed runs of a condition."""
        return [self.runs[i].result for i in self.summary[condition].runs if self.runs[i].completed]

    def curve(self, quantity: str = "stress_ratio", condition: int = 0) -> MeanCurve:
        """The mean curve of ``quantity`` (one of ``stress_ratio``, ``friction_angle``,
        ``volumetric_strain``, ``coordination``) over the completed runs of a condition,
        against the axial strain, with its 95 % band."""
        if quantity not in CURVES:
            raise FrictionRulesError(f"quantity = {quantity!r} violates: one of {', '.join(CURVES)}")
        if isinstance(condition, bool) or not isinstance(condition, (int, np.integer)) or not (
                0 <= condition < len(self.summary)):
            raise FrictionRulesError(f"condition = {condition!r} violates: an integer in "
                                     f"[0, {len(self.summary) - 1}]")
        return mean_curve(self.completed_results(int(condition)), quantity)

    def table(self) -> tuple[dict, dict]:
        """The summary as a table ``(columns, units)``: one row per condition and quantity
        (``frictionrules._output.write_table`` writes it as CSV or JSON)."""
        cols = {k: [] for k in ("condition", "model", "options", "quantity", "unit", "runs",
                                "completed", "n", "mean", "low", "high", "half_width", "std")}
        for s in self.summary:
            for name, unit in QUANTITIES.items():
                ci = getattr(s, name)
                for key, value in (("condition", s.index), ("model", s.model),
                                   ("options", json.dumps(s.options, sort_keys=True)),
                                   ("quantity", name), ("unit", unit), ("runs", len(s.runs)),
                                   ("completed", s.completed), ("n", ci.n), ("mean", ci.mean),
                                   ("low", ci.low), ("high", ci.high),
                                   ("half_width", ci.half_width), ("std", ci.std)):
                    cols[key].append(value)
        units = {"condition": "1", "model": "-", "options": "-", "quantity": "-", "unit": "-",
                 "runs": "1", "completed": "1", "n": "1", "mean": _ROW, "low": _ROW,
                 "high": _ROW, "half_width": _ROW, "std": _ROW}
        return cols, units

    def format_summary(self) -> str:
        """The summary as lines of text: per condition, its runs and each quantity's mean
        ± the half-width of its 95 % interval."""
        lines = []
        for s in self.summary:
            counts = {st: sum(self.runs[i].status == st for i in s.runs) for st in RUN_STATUSES}
            shown = ", ".join(f"{v} {k}" for k, v in counts.items() if v)
            where = ", ".join(f"{k} = {v}" for k, v in s.options.items())
            lines.append(f"condition {s.index}: {s.model}{'; ' + where if where else ''}")
            lines.append(f"  {len(s.runs)} runs ({shown}); over the {s.completed} completed "
                         "(mean ± 95 % confidence half-width, Student t):")
            for name, unit in QUANTITIES.items():
                label = f"{name} ({unit})" if unit != "1" else name
                lines.append(f"  {label:<34} {getattr(s, name)}")
        return "\n".join(lines)


def _model_label(assembly: Assembly) -> str:
    model = assembly.model
    return repr(model) if not callable(model) or hasattr(model, "law") else (
        f"model(i, j) = {getattr(model, '__qualname__', type(model).__name__)}")


def _grid(options: dict) -> tuple[list, list]:
    """``(points, fixed)``: the points of the grid of sequence-valued options (the last varying
    fastest) and the options that do not vary."""
    varying = {k: v for k, v in options.items() if isinstance(v, (list, tuple))}
    for name, values in varying.items():
        if len(values) == 0:
            raise FrictionRulesError(f"{name} = {values!r} violates: a value or a non-empty sequence")
    names = list(varying)
    points = [dict(zip(names, combo)) for combo in itertools.product(*varying.values())]
    return points, {k: v for k, v in options.items() if k not in varying}


def _file_name(assembly: Assembly, kind: str, options: dict) -> str:
    """A run file's name: a digest of the sample and the options (the same run finds its file
    whatever its place in the list)."""
    text = json.dumps([_sample_key(assembly), kind, options], sort_keys=True, default=repr)
    return hashlib.sha256(text.encode()).hexdigest()[:16] + ".h5"


def _finished(path: Path | None) -> bool | None:
    """None without a run file; whether it records a run that ended (not interrupted, not
    stopped by a time limit)."""
    if path is None or not path.exists():
        return None
    from .._optional import require
    h5py = require("h5py", purpose="assembly run files")
    try:
        with h5py.File(path, "r") as h5:
            status = str(h5.attrs.get("status", "running"))
    except OSError:
        return False
    return status != "running" and not status.startswith("stopped")


def _run_one(task) -> tuple:
    """One run in a worker: ``(result, status, error, seconds)``."""
    assembly, kind, options, run_file, deadline = task
    start = time.monotonic()
    finished = _finished(run_file)
    max_time = None
    if deadline is not None and not finished:
        max_time = deadline - time.time()
        if max_time <= 0:
            return None, "not started", "", 0.0
    status = "new" if finished is None else ("kept" if finished else "resumed")
    try:
        result = triaxial(assembly, kind, run_file=run_file, max_time=max_time, **options)
    except (FrictionRulesError, np.linalg.LinAlgError) as exc:
        return None, "failed", str(exc), time.monotonic() - start
    return result, status, "", time.monotonic() - start


def ensemble(assemblies, kind: str, *, executor=None, run_folder=None,
             max_time: float | None = None, progress=None, **options) -> EnsembleResult:
    r"""Run :func:`triaxial` on many samples, contact models and loading options, on any
    executor, and summarise each condition by its means and their 95 % confidence intervals.

    Parameters
    ----------
    assemblies : sequence of Assembly
        The samples (e.g. ``Assembly.random(n, dim, model, seed=s)`` for several seeds). Their
        contact models set the conditions: assemblies of the same model (same ``repr``) are
        samples of one condition; others (another law, other stiffnesses) are other conditions.
    kind : {"axisymmetric", "plane_strain", "biaxial"}
        The test (:func:`triaxial`).
    executor : None, concurrent.futures.Executor or distributed.Client
        Where the runs go (:mod:`frictionrules.parallel`): None runs them in this process, in
        order. The numbers do not depend on it.
    run_folder : path, optional
        A folder for the runs' files, one HDF5 run file per run, named by a digest of its
        sample and options. A second call with the same folder keeps the runs that finished
        (read back, nothing run) and resumes the others from their last record.
    max_time : float, optional
        Seconds for the whole ensemble: each run gets the time left when it starts, a run that
        would start later is not started; the runs keep what they did (their status says).
    progress : callable, optional
        ``progress(done, total)`` in this process as runs finish.
    **options
        The keyword arguments of :func:`triaxial` (``pressure`` is required). A list or tuple
        value varies over a grid: the runs are every assembly at every point of the Cartesian
        product of the sequence-valued options (``pressure=[0.5, 1.0]``); each point is a
        condition of its own.

    Returns
    -------
    EnsembleResult
        ``runs`` in the order: for each point of the grid (the last option varying fastest),
        each assembly in turn; ``summary``: one :class:`EnsembleSummary` per condition (a model
        and a point of the grid), its intervals over the runs that completed. For ``n`` values
        the interval is :math:`\bar x \pm t_{0.975,n-1}\,s/\sqrt n` (Student's t, ``s`` the
        sample standard deviation); ``n = 1``: unbounded (``-inf``, ``inf``); ``n = 0``: NaN.

    Raises
    ------
    FrictionRulesError
        For an empty or non-assembly ``assemblies``, an unknown option, or a value
        :func:`triaxial` refuses (checked for every run before any runs). A run that raises
        while it runs is kept as "failed" with its error; the others go on.
    """
    if isinstance(assemblies, Assembly) or not hasattr(assemblies, "__len__"):
        raise FrictionRulesError(f"assemblies = {assemblies!r} violates: a sequence of Assembly")
    assemblies = list(assemblies)
    if not assemblies:
        raise FrictionRulesError("assemblies = [] violates: at least one Assembly")
    for k, a in enumerate(assemblies):
        if not isinstance(a, Assembly):
            raise FrictionRulesError(f"assemblies[{k}] = {a!r} violates: an Assembly")
    defaults = _defaults()
    unknown = sorted(set(options) - set(defaults))
    if unknown:
        hint = "; a run folder (run_folder=) holds the runs' files" if "run_file" in unknown else ""
        raise FrictionRulesError(f"option {unknown[0]!r} violates: one of {', '.join(sorted(defaults))}"
                                 f"{hint}")
    if "pressure" not in options:
        raise FrictionRulesError("pressure is missing; constraint: the confining pressure (a "
                                 "number or a sequence)")
    if max_time is not None:
        max_time = check_scalar("max_time", max_time, lo=0.0, lo_open=True)
    points, fixed = _grid(options)
    runs, tasks, keys = [], [], {}
    folder = None
    if run_folder is not None:
        from .._output import check_folder
        folder = check_folder(run_folder, name="run_folder")
        folder.mkdir(parents=True, exist_ok=True)
    files = {}
    for point in points:
        for s, assembly in enumerate(assemblies):
            full = {**defaults, **fixed, **point}
            check_triaxial(assembly, kind, max_time=max_time, **full)
            if folder is not None and full["engine"] == "lammps":
                raise FrictionRulesError(f"run_folder = {str(run_folder)!r} violates: None for "
                                         "engine = 'lammps' (run files hold our engine's state)")
            key = (_model_label(assembly), json.dumps(point, sort_keys=True, default=repr))
            condition = keys.setdefault(key, len(keys))
            run_file = None
            if folder is not None:
                run_file = folder / _file_name(assembly, kind, full)
                if run_file in files:
                    raise FrictionRulesError(
                        f"assemblies[{s}] repeats assemblies[{files[run_file]}] with the same "
                        "options; constraint: distinct runs in a run folder (one file each)")
                files[run_file] = s
            runs.append((s, point, condition, run_file))
            tasks.append((assembly, kind, {**fixed, **point}, run_file))
    deadline = None if max_time is None else time.time() + max_time
    tasks = [t + (deadline,) for t in tasks]
    from ..parallel import run_tasks
    outcomes = [None] * len(tasks)
    for done, (i, outcome) in enumerate(run_tasks(_run_one, tasks, executor), start=1):
        outcomes[i] = outcome
        if progress is not None:
            progress(done, len(tasks))
    records = tuple(EnsembleRun(i, s, dict(point), c, *outcome[:2], error=outcome[2],
                                run_file=f, seconds=outcome[3])
                    for i, ((s, point, c, f), outcome) in enumerate(zip(runs, outcomes)))
    return EnsembleResult(kind, records, _summaries(records, keys))


def _summaries(records, keys: dict) -> tuple:
    out = []
    for (model, point), c in sorted(keys.items(), key=lambda kv: kv[1]):
        members = [r for r in records if r.condition == c]
        values = [end_values(r.result) for r in members if r.completed]
        stats = {name: interval([v[name] for v in values if v[name] is not None])
                 for name in QUANTITIES}
        out.append(EnsembleSummary(c, model, json.loads(point), tuple(r.index for r in members),
                                   len(values), **stats))
    return tuple(out)
