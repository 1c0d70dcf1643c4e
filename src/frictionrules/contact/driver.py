"""Single-contact driver with mixed control: :func:`drive`, its :class:`Path` and
:class:`DriveResult`, path readers (Python, CSV, TOML) and result writers (CSV, HDF5).

In each step every component pair is controlled either by its force or by its displacement:
``T1`` or ``dt1``, ``T2`` or ``dt2``, ``N`` or ``dn`` (``dn`` positive on opening, ``N > 0``
compression). The prescribed values are the targets at the end of the step; the free
displacements are found by Newton's method on the consistent tangent.
"""

from __future__ import annotations

import csv
from dataclasses import dataclass, field
from pathlib import Path as _FilePath

import numpy as np

from .._returnspec import backtrack, sufficient_decrease
from ..errors import FrictionRulesError, check_finite
from .model import ContactModel
from .state import OPEN, ContactState

__all__ = ["DriveResult", "Path", "drive", "read_path", "read_toml"]

#: Steps tried by the line search of a force-controlled step (Newton's step down to 2^-29 of
#: it): the response is piecewise smooth, and a step that only crosses into another piece
#: (elastic, plastic, open) may need many halvings to decrease the residual.
DRIVER_HALVINGS = 30
#: Component pairs (force name, displacement name) in the order (t1, t2, n).
PAIRS = (("T1", "dt1"), ("T2", "dt2"), ("N", "dn"))
_NAMES = {name: (i, k == 0) for i, pair in enumerate(PAIRS) for k, name in enumerate(pair)}


@dataclass(frozen=True, eq=False)
class Path:
    """A loading path: per step and component, a force or a displacement target.

    Steps are grouped in segments; within a segment each prescribed quantity goes linearly
    from its value at the start of the segment (known only while driving) to the segment's
    target, reaching the fraction ``ramp`` of the way at the end of each step.

    Attributes
    ----------
    force_control : (steps, 3) bool
        True where the component (t1, t2, n) is force-controlled (T1, T2, N) in that step,
        False where its displacement (dt1, dt2, dn) is prescribed.
    values : (steps, 3)
        Targets of the segment each step belongs to.
    ramp : (steps,)
        Fraction of the segment reached at the end of the step, in (0, 1]; 1 by default
        (every step its own segment).
    segment : (steps,) int
        Segment index of each step (non-decreasing); ``arange(steps)`` by default.
    """

    force_control: np.ndarray
    values: np.ndarray
    ramp: np.ndarray | None = None
    segment: np.ndarray | None = None

    def __post_init__(self):
        v = check_finite("values", self.values)
        fc = np.asarray(self.force_control, dtype=bool)
        if v.ndim != 2 or v.shape[1] != 3 or fc.shape != v.shape:
            raise FrictionRulesError(f"values and force_control must have the same shape (steps, 3), "
                                     f"got {v.shape} and {fc.shape}")
        ramp = np.ones(len(v)) if self.ramp is None else check_finite("ramp", self.ramp)
        seg = np.arange(len(v)) if self.segment is None else np.asarray(self.segment, dtype=int)
        if ramp.shape != (len(v),) or np.any((ramp <= 0) | (ramp > 1)):
            raise FrictionRulesError("ramp violates: shape (steps,), 0 < ramp <= 1")
        if seg.shape != (len(v),) or np.any(np.diff(seg) < 0):
            raise FrictionRulesError("segment violates: shape (steps,), non-decreasing")
        for name, value in (("values", v), ("force_control", fc), ("ramp", ramp), ("segment", seg)):
            object.__setattr__(self, name, value)

    def __len__(self) -> int:
        return len(self.values)

    @classmethod
    def from_segments(cls, segments) -> "Path":
        """Build a path from segments, each a mapping like ``{"N": 1.0, "dt1": 0.2, "steps": 50}``.

        A segment ramps linearly, in ``steps`` equal steps (default 1), from the values at its
        start to its targets; a pair it does not name keeps its control and target. At the
        start every component is displacement-controlled at 0.
        """
        control = np.zeros(3, dtype=bool)
        value = np.zeros(3)
        rows_c, rows_v, ramp, seg_id = [], [], [], []
        for k, seg in enumerate(segments):
            seg = dict(seg)
            steps = seg.pop("steps", 1)
            if not isinstance(steps, (int, np.integer)) or steps < 1:
                raise FrictionRulesError(f"segment {k}: steps = {steps!r} violates: integer >= 1")
            new_c, new_v = control.copy(), value.copy()
            seen = set()
            for name, target in seg.items():
                if name not in _NAMES:
                    raise FrictionRulesError(f"segment {k}: unknown key {name!r}; choose from "
                                             f"{sorted(_NAMES)} and 'steps'")
                i, is_force = _NAMES[name]
                if i in seen:
                    raise FrictionRulesError(f"segment {k}: two targets for component {PAIRS[i]}")
                seen.add(i)
                new_c[i] = is_force
                new_v[i] = float(check_finite(f"segment {k}: {name}", target))
            for s in range(1, steps + 1):
                rows_c.append(new_c)
                rows_v.append(new_v)
                ramp.append(s / steps)
                seg_id.append(k)
            control, value = new_c, new_v
        if not rows_v:
            raise FrictionRulesError("the path has no steps")
        return cls(np.array(rows_c), np.array(rows_v), np.array(ramp), np.array(seg_id))


#: Columns of a drive result table, in order.
COLUMNS = ("step", "T1", "T2", "N", "dt1", "dt2", "dn", "dt1p", "dt2p", "dnp", "kappa", "beta", "work", "status")
#: Unit of each column (docs/conventions.md): forces, displacements, plastic work.
UNITS = {"step": "1", "T1": "force", "T2": "force", "N": "force", "dt1": "length", "dt2": "length",
         "dn": "length", "dt1p": "length", "dt2p": "length", "dnp": "length", "kappa": "length",
         "beta": "1", "work": "force*length", "status": "1"}
#: Most steps a drive file may ask for (a bound, so that a mistyped number is an error).
MAX_FILE_STEPS = 1_000_000
#: Suffixes :meth:`DriveResult.write` accepts.
SUFFIXES = (".csv", ".json", ".h5", ".hdf5")


@dataclass(frozen=True, eq=False)
class DriveResult:
    """Table of a driven path, one row per state (row 0 the initial state).

    Attributes
    ----------
    force : (rows, 3) ``(T1, T2, N)``; displacement, plastic : (rows, 3) ``(δt1, δt2, δn)``
    and its plastic part; kappa, beta : (rows,); work : (rows,) cumulative plastic work;
    status : (rows,) 0 elastic, 1 plastic, 2 open (of the step that ended there);
    law_variables : the internal variables of the law (``law.state_names``): the table has a
    ``beta`` column only for a law with the area fraction β (the cap of §4), whose ``beta``
    otherwise stays at its initial value and means nothing.
    """

    force: np.ndarray
    displacement: np.ndarray
    plastic: np.ndarray
    kappa: np.ndarray
    beta: np.ndarray
    work: np.ndarray
    status: np.ndarray
    final: ContactState = field(repr=False)
    law_variables: tuple[str, ...] = ("kappa", "beta")

    def columns(self) -> dict[str, np.ndarray]:
        """The table as named columns (see :data:`COLUMNS`; ``beta`` only where the law has
        it)."""
        out = {"step": np.arange(len(self.kappa))}
        for k, name in enumerate(("T1", "T2", "N")):
            out[name] = self.force[:, k]
        for k, name in enumerate(("dt1", "dt2", "dn")):
            out[name] = self.displacement[:, k]
            out[name + "p"] = self.plastic[:, k]
        out.update(kappa=self.kappa, beta=self.beta, work=self.work, status=self.status)
        return {name: out[name] for name in COLUMNS
                if name != "beta" or "beta" in self.law_variables}

    def to_csv(self, path, attrs=None) -> _FilePath:
        """Write the table as CSV (atomically): column names, ``# units`` and ``attrs`` comment
        lines, then the rows (``numpy.genfromtxt(path, delimiter=",", names=True)`` reads it)."""
        from .._output import write_table
        return write_table(path, self.columns(), units=UNITS, metadata=attrs, format="csv")

    def to_hdf5(self, path, attrs=None) -> _FilePath:
        """Write the table as HDF5, one dataset per column with its ``units`` attribute
        (atomically); ``attrs`` go on the root."""
        from .._output import write_table
        return write_table(path, self.columns(), units=UNITS, metadata=attrs, format="hdf5")

    def write(self, path, attrs=None) -> _FilePath:
        """Write the table (CSV, JSON or HDF5 by the suffix: :data:`SUFFIXES`) atomically, with
        the unit of every column (:data:`UNITS`) and ``attrs`` (provenance) as metadata."""
        from .._output import write_table
        suffix = _FilePath(path).suffix.lower()
        if suffix not in SUFFIXES:
            raise FrictionRulesError(f"output {str(path)!r} has suffix {suffix!r}; constraint: one "
                                     f"of {', '.join(SUFFIXES)}")
        return write_table(path, self.columns(), units=UNITS, metadata=attrs)


def drive(model: ContactModel, path, state: ContactState | None = None, *, beta=0.5,
          tol: float = 1e-10, max_iter: int = 50, progress=None) -> DriveResult:
    """Drive one contact along a mixed-control path, implicitly.

    Parameters
    ----------
    model : ContactModel
    path : Path or sequence of segment mappings (see :meth:`Path.from_segments`)
    state : ContactState, optional
        Start state of one contact (shape ``()``); virgin with area fraction ``beta`` if omitted.
    tol : float
        Relative tolerance on the prescribed forces.
    progress : callable, optional
        Called as ``progress(done, total)`` after each step.

    Returns
    -------
    DriveResult
    """
    if not isinstance(path, Path):
        path = Path.from_segments(path)
    if state is None:
        state = model.initial_state(beta=beta)
    if state.shape != ():
        raise FrictionRulesError(f"state must be a single contact (shape ()), got shape {state.shape}")
    E = model.elastic_tangent
    rows = [(model.force(state), state, 0.0, 0)]
    work = 0.0
    for k in range(len(path)):
        fc = path.force_control[k]
        if k == 0 or path.segment[k] != path.segment[k - 1]:
            start = np.where(fc, model.force(state), state.displacement)
        target = start + (path.values[k] - start) * path.ramp[k]
        dc = ~fc
        du = np.zeros(3)
        du[dc] = target[dc] - state.displacement[dc]
        res = model.update(state, du, tangent=fc.any())
        if fc.any():
            scale = max(np.abs(target).max(), np.abs(res.force).max(), np.abs(model.force(state)).max(), 1e-300)
            for it in range(max_iter + 1):
                r = _extended_force(model, res)[fc] - target[fc]
                if np.all(np.abs(r) <= tol * scale):
                    break
                if it == max_iter:
                    raise FrictionRulesError(
                        f"step {k}: the prescribed forces {dict(zip(np.array(['T1', 'T2', 'N'])[fc], target[fc]))} "
                        f"were not reached in {max_iter} iterations (residual {np.abs(r).max():.3g}); "
                        "the contact may be at a softening peak or open under force control")
                C = res.tangent if res.status != OPEN else E
                J = C[np.ix_(fc, fc)]
                if abs(np.linalg.det(J)) <= 1e-14 * np.abs(E[np.ix_(fc, fc)]).prod():
                    J = E[np.ix_(fc, fc)]
                step = np.linalg.solve(J, r)
                # Backtracking: the response is only piecewise smooth (elastic, plastic, open),
                # and full Newton steps can cycle between pieces; the last step tried is
                # taken when none decreases the residual enough.
                norm = np.linalg.norm(r)

                def evaluate(alpha, du=du, step=step):
                    trial = du.copy()
                    trial[fc] -= alpha * step
                    return trial, model.update(state, trial, tangent=True)

                def accept(value, alpha, norm=norm):
                    miss = np.linalg.norm(_extended_force(model, value[1])[fc] - target[fc])
                    return sufficient_decrease(miss, norm, alpha)

                _, (du, res), _ = backtrack(evaluate, accept, 1.0, DRIVER_HALVINGS)
        state = res.state
        work += float(res.dissipation)
        rows.append((res.force, state, work, int(res.status)))
        if progress is not None:
            progress(k + 1, len(path))
    return DriveResult(
        force=np.array([r[0] for r in rows]),
        displacement=np.array([r[1].displacement for r in rows]),
        plastic=np.array([r[1].plastic for r in rows]),
        kappa=np.array([float(r[1].kappa) for r in rows]),
        beta=np.array([float(r[1].beta) for r in rows]),
        work=np.array([r[2] for r in rows]),
        status=np.array([r[3] for r in rows]),
        final=state, law_variables=tuple(model.effective_law.state_names))


def _extended_force(model, res):
    """End forces, with the (negative) trial normal force ``-kn δnᵉ`` where the contact is open,
    so that Newton's method under normal force control sees the gap and closes it."""
    F = np.array(res.force, dtype=float)
    if res.status == OPEN:
        F[2] = -model.kn * res.state.elastic[2]
    return F


# ---- readers --------------------------------------------------------------------------------
def read_path(file) -> Path:
    """Read a path from CSV or TOML (by suffix).

    CSV: a header naming one of each pair (e.g. ``N,dt1,T2``) and one row of targets per step.
    TOML: ``[[segment]]`` tables as in :meth:`Path.from_segments` (see :func:`read_toml`).
    """
    file = _FilePath(file)
    suffix = file.suffix.lower()
    if suffix == ".csv":
        return _read_csv(file)
    if suffix == ".toml":
        return read_toml(file)[1]
    raise FrictionRulesError(f"path file {str(file)!r} has suffix {suffix!r}; constraint: .csv or .toml")


def _read_csv(file) -> Path:
    try:
        with open(file, newline="", encoding="utf-8") as fh:
            rows = [r for r in csv.reader(fh) if r and not r[0].lstrip().startswith("#")]
    except (UnicodeDecodeError, csv.Error) as exc:
        raise FrictionRulesError(f"{file}: not a CSV text file ({exc})") from None
    if len(rows) < 2:
        raise FrictionRulesError(f"{file}: a CSV path needs a header and at least one row")
    header = [h.strip() for h in rows[0]]
    idx = {}
    for j, name in enumerate(header):
        if name not in _NAMES:
            raise FrictionRulesError(f"{file}: unknown column {name!r}; choose from {sorted(_NAMES)}")
        i, _ = _NAMES[name]
        if i in idx:
            raise FrictionRulesError(f"{file}: two columns for component {PAIRS[i]}")
        idx[i] = j
    fc = np.zeros((len(rows) - 1, 3), dtype=bool)
    values = np.zeros((len(rows) - 1, 3))
    for i, j in idx.items():
        fc[:, i] = _NAMES[header[j]][1]
        try:
            values[:, i] = [float(r[j]) for r in rows[1:]]
        except (ValueError, IndexError) as exc:
            raise FrictionRulesError(f"{file}: column {header[j]!r} has a missing or non-numeric entry") from exc
    return Path(fc, values)


def _table(value, where: str, file) -> dict:
    """A TOML table (a dict), or a FrictionRulesError naming where it should be."""
    if not isinstance(value, dict):
        raise FrictionRulesError(f"{file}: {where} = {value!r} violates: must be a table")
    return dict(value)


def read_toml(file):
    """Read a drive file: ``(model, path, options)``.

    ::

        [model]
        kn = 100.0
        kt = 100.0
        beta = 0.5                  # initial area fraction
        [model.law]                 # a law in the one layout (frictionrules.read_law)
        type = "EllipsoidCap"       # any law of frictionrules.LAWS, "UserLaw" included
        m = 0.6
        [output]
        file = "out.csv"            # optional: .csv, .json or .h5, relative to this file's folder
        [[segment]]
        N = 0.4
        dt1 = 0.0
        T2 = 0.0
        steps = 20

    ``options`` holds ``beta`` and the output file (or None).
    """
    from .._toml import load_toml
    from ..laws import SlipHardening, law_from_mapping
    file = _FilePath(file)
    doc = load_toml(file)
    unknown = sorted(set(doc) - {"model", "output", "segment"})
    if unknown:
        raise FrictionRulesError(f"{file}: unknown tables {unknown}; known: model, output, segment")
    model_t = _table(doc.get("model", {}), "[model]", file)
    if "law" not in model_t:
        raise FrictionRulesError(f"{file}: missing [model.law] table")
    law = law_from_mapping(model_t.pop("law"), where=f"{file}: [model.law]")
    hard = model_t.pop("hardening", None)  # the spelling before [model.law.hardening]
    beta = model_t.pop("beta", 0.5)
    try:
        hardening = SlipHardening.from_parameters(**_table(hard, "[model.hardening]", file)) \
            if hard else None
        model = ContactModel(law, hardening=hardening, **model_t)
    except TypeError as exc:
        raise FrictionRulesError(f"{file}: [model]: {exc}") from exc
    model.initial_state(beta=beta)  # checks beta where it enters
    segments = doc.get("segment")
    if not isinstance(segments, list) or not segments:
        raise FrictionRulesError(f"{file}: no [[segment]] tables")
    tables = [_table(seg, f"segment {k}", file) for k, seg in enumerate(segments)]
    total = sum(t.get("steps", 1) for t in tables if isinstance(t.get("steps", 1), int))
    if total > MAX_FILE_STEPS:
        raise FrictionRulesError(f"{file}: {total} steps in all; constraint: at most "
                                 f"{MAX_FILE_STEPS} in a drive file")
    path = Path.from_segments(tables)
    out = _table(doc.get("output", {}), "[output]", file).get("file")
    if out is not None:
        if not isinstance(out, str) or not out:
            raise FrictionRulesError(f"{file}: [output] file = {out!r} violates: a file name")
        out = file.parent / out
    return model, path, {"beta": beta, "output": out}
