"""The one output layer: every table (CSV, JSON, HDF5), JSON document and figure is written here.

* **Atomic**: a temporary file in the target folder, renamed onto the target (``os.replace``)
  only when complete; an interrupted run never leaves a half-written file.
* **Permissions from the umask** (``0o666 & ~umask``), as any other program's files.
* **Strict JSON**: a non-finite number is written ``null`` and the document's ``"non_finite"``
  object maps its JSON pointer (RFC 6901) to ``"inf"``, ``"-inf"`` or ``"nan"``; commands add
  the physical flag (``"locked"``, ``"jammed"``) as an ordinary field or column.
* **Units and provenance** in every file: CSV comment lines ``# ...`` right after the column
  names, JSON ``"metadata"`` and ``"units"``, HDF5 attributes; see ``docs/conventions.md``.
* **Suffix checked before the work starts**: :func:`check_output`.
"""

from __future__ import annotations

import contextlib
import csv
import io
import json
import math
import os
import shlex
import sys
import tempfile
from collections.abc import Iterator, Mapping, Sequence
from pathlib import Path

import numpy as np

from ._optional import require
from .errors import FrictionRulesError

#: Suffixes of the table writers (:func:`write_table`).
TABLE_SUFFIXES = (".csv", ".json", ".h5", ".hdf5")
#: Suffixes of the figure writer (:func:`write_figure`).
FIGURE_SUFFIXES = (".png", ".svg", ".pdf")


# ---- paths ------------------------------------------------------------------------------------
def writable_ancestor(path: Path) -> Path | None:
    """The nearest existing ancestor of ``path`` (``path`` itself if it exists) when it is a
    folder this process may write in, else None."""
    folder = _existing(path)
    return folder if folder.is_dir() and os.access(folder, os.W_OK | os.X_OK) else None


def _existing(path: Path) -> Path:
    while not path.exists() and path != path.parent:
        path = path.parent
    return path


def check_output(path, allowed_suffixes: Sequence[str], *, name: str = "--out") -> Path:
    """Check an output path before any work is done; return it as a :class:`Path`.

    The suffix must be one of ``allowed_suffixes`` (case-insensitive), the path must not be a
    folder, and its nearest existing ancestor must be a folder this process may write in.

    Raises
    ------
    FrictionRulesError
        Naming the argument ``name``, the path and the constraint.
    """
    path = Path(path)
    allowed = tuple(s.lower() for s in allowed_suffixes)
    if path.suffix.lower() not in allowed:
        raise FrictionRulesError(f"{name} = {str(path)!r} has suffix {path.suffix!r}; constraint: "
                                 f"one of {', '.join(allowed)}")
    if path.is_dir():
        raise FrictionRulesError(f"{name} = {str(path)!r} is a folder; constraint: a file name")
    if writable_ancestor(path.parent) is None:
        raise FrictionRulesError(f"{name} = {str(path)!r}: {str(_existing(path.parent))!r} is not "
                                 "a writable folder; constraint: a path in a folder you may write in")
    return path


def check_folder(path, *, name: str = "--out", shown=None) -> Path:
    """Check an output folder before any work is done; return it as a :class:`Path`.

    ``path`` may not exist yet; its nearest existing ancestor must be a folder in which this
    process can create a file (tried with a probe file, removed at once: ``/proc`` and
    read-only mounts pass a permission test but refuse files). ``shown``: the path the user
    gave (a file to be written in the folder), named in the message instead of the folder.

    Raises
    ------
    FrictionRulesError
        Naming the argument ``name``, the path and the constraint.
    """
    path = Path(path)
    given = str(path if shown is None else shown)
    existing = _existing(path)
    if not existing.is_dir():
        raise FrictionRulesError(f"{name} = {given!r}: {str(existing)!r} is not a folder; "
                                 "constraint: a folder (new or existing) you may write in")
    try:
        fd, probe = tempfile.mkstemp(dir=existing, prefix=".frictionrules-probe-")
        os.close(fd)
        os.unlink(probe)
    except OSError as exc:
        raise FrictionRulesError(f"{name} = {given!r}: cannot write in {str(existing)!r} "
                                 f"({exc.strerror or type(exc).__name__}); constraint: a folder "
                                 "you may write in") from None
    return path


def file_mode() -> int:
    """Mode of new files: ``0o666 & ~umask`` (the umask read without changing it where possible)."""
    with contextlib.suppress(OSError, ValueError):
        with open("/proc/self/status", encoding="ascii") as fh:
            for line in fh:
                if line.startswith("Umask:"):
                    return 0o666 & ~int(line.split()[1], 8)
    mask = os.umask(0o022)  # no /proc: read it by setting it (and put it back at once)
    os.umask(mask)
    return 0o666 & ~mask


@contextlib.contextmanager
def atomic_path(path) -> Iterator[Path]:
    """Yield a temporary path next to ``path``; on success give it the umask's permissions and
    rename it onto ``path``. Errors name ``path``, never the temporary file.

    Use it with writers that take a file name (``fig.savefig``, ``h5py.File``)::

        with atomic_path("out.h5") as tmp:
            with h5py.File(tmp, "w") as f: ...
    """
    path = Path(path)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=path.suffix or ".tmp",
                                   dir=path.parent)
        os.close(fd)
    except OSError as exc:
        raise type(exc)(exc.errno, f"cannot write {path}: {exc.strerror}") from None
    try:
        yield Path(tmp)
        os.chmod(tmp, file_mode())
        os.replace(tmp, path)
    except BaseException as exc:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        if isinstance(exc, OSError) and exc.filename is not None and str(tmp) in str(exc.filename):
            raise type(exc)(exc.errno, f"cannot write {path}: {exc.strerror}") from None
        raise


def write_text(path, text: str) -> Path:
    """Write ``text`` (UTF-8) to ``path`` atomically; return the path."""
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8")
    return Path(path)


# ---- provenance -------------------------------------------------------------------------------
def command_line(argv: Sequence[str] | None = None) -> str:
    """The command as a shell line, ``frictionrules drive shear.toml --out s.csv``."""
    argv = sys.argv[1:] if argv is None else argv
    return shlex.join(["frictionrules", *map(str, argv)])


def provenance(*, command: str | None = None, model=None, parameters: Mapping | None = None,
               **extra) -> dict:
    """Provenance of an output: package version, command, model (its ``repr``), parameters.

    The result is a plain dict of strings, numbers and dicts, stored as CSV comment lines,
    JSON ``"metadata"`` or HDF5 attributes. No time stamp: the same run writes the same bytes.
    """
    from ._version import __version__
    out: dict = {"software": f"frictionrules {__version__}"}
    if command is not None:
        out["command"] = command
    if model is not None:
        out["model"] = model if isinstance(model, str) else repr(model)
    if parameters:
        out["parameters"] = dict(parameters)
    out.update(extra)
    return out


# ---- strict JSON ------------------------------------------------------------------------------
def _plain(obj):
    """NumPy scalars and arrays as Python numbers and lists."""
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, Path):
        return str(obj)
    return obj


def strict_json(obj, pointer: str = "") -> tuple[object, dict[str, str]]:
    """``obj`` with every non-finite float replaced by ``None``, and the replaced values as
    ``{JSON pointer: "inf" | "-inf" | "nan"}`` (RFC 6901 pointers, e.g. ``/columns/peak/3``)."""
    obj = _plain(obj)
    if isinstance(obj, float):
        if math.isfinite(obj):
            return obj, {}
        return None, {pointer: "nan" if math.isnan(obj) else ("inf" if obj > 0 else "-inf")}
    if isinstance(obj, Mapping):
        out, bad = {}, {}
        for key, value in obj.items():
            escaped = str(key).replace("~", "~0").replace("/", "~1")
            out[str(key)], sub = strict_json(value, f"{pointer}/{escaped}")
            bad.update(sub)
        return out, bad
    if isinstance(obj, (list, tuple)):
        out, bad = [], {}
        for i, value in enumerate(obj):
            clean, sub = strict_json(value, f"{pointer}/{i}")
            out.append(clean)
            bad.update(sub)
        return out, bad
    return obj, {}


def dumps_json(document: Mapping, *, indent: int | None = 1) -> str:
    """Strict JSON text of a mapping, with its ``"non_finite"`` object (always present)."""
    clean, bad = strict_json(document)
    clean["non_finite"] = bad
    return json.dumps(clean, indent=indent, allow_nan=False) + "\n"


def write_json(path, document: Mapping) -> Path:
    """Write a mapping as strict JSON (see :func:`dumps_json`) atomically."""
    return write_text(path, dumps_json(document))


# ---- tables ----------------------------------------------------------------------------------
def _columns(columns: Mapping, units: Mapping) -> dict[str, np.ndarray]:
    cols = {str(k): np.asarray(v) for k, v in columns.items()}
    lengths = {len(v) for v in cols.values()}
    if len(lengths) > 1:
        raise ValueError(f"table columns of different lengths {sorted(lengths)}")
    missing = sorted(set(cols) - set(units))
    if missing:
        raise ValueError(f"table columns without units: {missing}")
    return cols


def _cell(value) -> str:
    if isinstance(value, (bool, np.bool_)):
        return str(int(value))
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    if isinstance(value, (float, np.floating)):
        return repr(float(value))  # 'inf', '-inf', 'nan' for the non-finite (NumPy reads them)
    return str(value)


def table_csv(columns: Mapping, *, units: Mapping, metadata: Mapping | None = None) -> str:
    """CSV text: the column names, then ``# units: ...`` and ``# key: value`` comment lines,
    then one row per entry (NumPy's ``genfromtxt(names=True)`` and ``loadtxt(skiprows=1)``
    read it as it is)."""
    cols = _columns(columns, units)
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(cols)
    buf.write("# units: " + ", ".join(f"{k}={units[k]}" for k in cols) + "\n")
    for key, value in (metadata or {}).items():
        text = value if isinstance(value, str) else json.dumps(strict_json(value)[0])
        buf.write(f"# {key}: {' '.join(str(text).split())}\n")
    for row in zip(*cols.values()):
        w.writerow([_cell(v) for v in row])
    return buf.getvalue()


def table_json(columns: Mapping, *, units: Mapping, metadata: Mapping | None = None) -> str:
    """Strict JSON text ``{"metadata", "units", "columns", "non_finite"}`` of a table."""
    cols = _columns(columns, units)
    return dumps_json({"metadata": dict(metadata or {}), "units": {k: units[k] for k in cols},
                       "columns": cols})


def write_table(path, columns: Mapping, *, units: Mapping, metadata: Mapping | None = None,
                format: str | None = None) -> Path:
    """Write a table of named columns (CSV, JSON or HDF5 by the suffix or ``format``) atomically.

    Parameters
    ----------
    path : path-like
        ``.csv``, ``.json``, ``.h5`` or ``.hdf5``.
    columns : mapping of str to 1-D array
        Columns of equal length (numbers, booleans or strings).
    units : mapping of str to str
        The unit of every column (``docs/conventions.md``: ``force``, ``length``, ``rad``,
        ``deg``, ``1`` for dimensionless numbers, counts and flags, ``-`` for text).
    metadata : mapping, optional
        Provenance (:func:`provenance`) and other facts about the table.
    format : {"csv", "json", "hdf5"}, optional
        The format whatever the suffix.
    """
    path = Path(path)
    suffix = f".{format}" if format else path.suffix.lower()
    if suffix == ".csv":
        return write_text(path, table_csv(columns, units=units, metadata=metadata))
    if suffix == ".json":
        return write_text(path, table_json(columns, units=units, metadata=metadata))
    if suffix in (".h5", ".hdf5"):
        return _table_hdf5(path, _columns(columns, units), units, metadata or {})
    raise FrictionRulesError(f"output {str(path)!r} has suffix {path.suffix!r}; constraint: one "
                             f"of {', '.join(TABLE_SUFFIXES)}")


def _table_hdf5(path: Path, cols: dict, units: Mapping, metadata: Mapping) -> Path:
    h5py = require("h5py", extra="hdf5")
    with atomic_path(path) as tmp, h5py.File(tmp, "w") as h5:
        for name, col in cols.items():
            data = col.astype(h5py.string_dtype()) if col.dtype.kind in "OUS" else col
            h5.create_dataset(name, data=data)
            h5[name].attrs["units"] = units[name]
        for key, value in metadata.items():
            h5.attrs[key] = value if isinstance(value, str) else json.dumps(strict_json(value)[0])
    return path


# ---- figures ---------------------------------------------------------------------------------
def write_figure(fig, path, *, metadata: Mapping | None = None, dpi: int = 150, **savefig) -> Path:
    """Save a Matplotlib figure atomically (PNG, SVG or PDF by the suffix), reproducibly.

    The provenance goes into the file's metadata (PNG text chunks, SVG Dublin Core, PDF info);
    no date is written and SVG ids use a fixed salt, so the same figure gives the same bytes.
    ``savefig`` is passed on to :meth:`matplotlib.figure.Figure.savefig`.
    """
    import matplotlib

    path = Path(path)
    fmt = path.suffix.lower().lstrip(".")
    if f".{fmt}" not in FIGURE_SUFFIXES:
        raise FrictionRulesError(f"figure {str(path)!r} has suffix {path.suffix!r}; constraint: "
                                 f"one of {', '.join(FIGURE_SUFFIXES)}")
    meta = dict(metadata or {})
    software = str(meta.pop("software", "frictionrules"))
    text = "; ".join(f"{k}: {v if isinstance(v, str) else json.dumps(strict_json(v)[0])}"
                     for k, v in meta.items())
    info = {"png": {"Software": software, "Description": text},
            "svg": {"Creator": software, "Date": None, "Description": text},
            "pdf": {"Creator": software, "Producer": software, "CreationDate": None,
                    "Subject": text}}[fmt]
    with matplotlib.rc_context({"svg.hashsalt": "frictionrules"}), atomic_path(path) as tmp:
        fig.savefig(tmp, format=fmt, dpi=dpi, metadata=info, **savefig)
    return path

