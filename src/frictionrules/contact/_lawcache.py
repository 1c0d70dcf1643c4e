r"""What the first run of a law derived with SymPy, kept on disk for the runs after it.

A law's compiled return mapping needs three things that SymPy derives from its symbolic form
(:mod:`frictionrules.contact._generated`): the generated module's source, the constants of its
return structure (:func:`frictionrules.codegen.return_constants`) and the values of its
parameter-only subexpressions (:func:`~frictionrules.contact._generated.parameter_values`).
Deriving them costs a warm process most of its time (SymPy's import, the derivatives, the
common subexpressions: about 1.6 s of ``frictionrules drive``'s 2.7 s). The first run writes
them to an **entry** beside the generated module; a later run reads the entry and imports the
module without SymPy.

* **Key.** The law's complete definition: its class and its table in the one layout
  (:func:`frictionrules.laws.law_to_mapping`, which :func:`~frictionrules.laws.law_from_mapping`
  turns back into an equal law; a ``UserLaw``'s expressions are text in it), with the
  library's version, a digest of the sources that derive and print the code (the laws, the
  code generator, the kernels the module includes) and SymPy's version. The entry's name is
  the SHA-256 of that key; the entry repeats the key, which a read compares in full. A law
  outside the law table (no layout) has no entry: it is derived in each process, as before.
* **Content** (JSON): the key, the module's name and the SHA-256 of its text, the number of
  internal variables, and the two arrays of floats, each as ``float.hex`` (exact: a hit gives
  the same row, bit for bit, as the derivation).
* **Trust.** An entry is used only where it parses, has this format's fields, repeats this
  key, and the module file beside it has the recorded digest; anything else (a truncated or
  hand-edited file, another version's module under the same name) is a miss: derived again and
  written over. The entry holds data only; the module it names is the generator's own output,
  imported as the first run imports it.
* **Writes** go to a temporary file in the same folder, renamed onto the entry (the module
  likewise): a reader sees a whole old entry, a whole new one, or none; two processes writing
  the same entry at once each rename a whole file of the same content.

The folder is :func:`frictionrules.contact._generated.cache_dir` (``$FRICTIONRULES_CACHE_DIR``,
else beside Numba's cache under ``$NUMBA_CACHE_DIR``, else the user's cache folder).
"""

from __future__ import annotations

import functools
import hashlib
import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

__all__ = ["LawEntry", "law_key", "read_entry", "write_entry", "entry_path", "generator_digest",
           "FORMAT", "MODULE_PREFIX"]

#: The entry's layout version (a change of the fields makes older entries misses).
FORMAT = 1
#: The generated modules' names start with this (an entry naming another module is a miss).
MODULE_PREFIX = "frictionrules_law_"

#: The package's sources a generated module and its constants follow, relative to the package:
#: folders (every ``.py`` file in them) and files.
_SOURCES = ("laws", "codegen", "contact/_generated.py", "contact/_lawcache.py",
            "contact/_step_source.py", "contact/_kernel_batch.py", "contact/_kernel_law.py",
            "contact/_kernel_newton.py", "contact/_kernel_outputs.py",
            "contact/_kernel_special.py", "contact/_return_kernel.py", "contact/layout.py",
            "_returnspec.py", "_version.py")


@dataclass(frozen=True)
class LawEntry:
    """What a law's compiled kernel needs beyond its module: the module's name and the digest of
    its text, the number of internal variables, the return structure's constants and the
    parameter values with the parameter-only subexpressions (read-only arrays)."""

    module: str
    module_sha256: str
    nq: int
    return_constants: np.ndarray
    parameter_values: np.ndarray


@functools.lru_cache(maxsize=1)
def generator_digest() -> str:
    """SHA-256 of the sources that derive and print a law's code (:data:`_SOURCES`), of the
    library's version and of SymPy's version (read from its metadata: SymPy not imported)."""
    from importlib import metadata

    from .._version import __version__
    root = Path(__file__).resolve().parents[1]
    files = []
    for name in _SOURCES:
        path = root / name
        files += sorted(path.rglob("*.py")) if path.is_dir() else [path]
    h = hashlib.sha256(f"frictionrules {__version__}\n".encode())
    try:
        h.update(f"sympy {metadata.version('sympy')}\n".encode())
    except metadata.PackageNotFoundError:
        h.update(b"sympy missing\n")
    for path in files:
        h.update(str(path.relative_to(root)).encode() + b"\0")
        h.update(path.read_bytes() + b"\0")
    return h.hexdigest()


def law_key(law) -> str | None:
    """The entry key of ``law`` (module docstring), or None for a law without a layout."""
    from ..errors import FrictionRulesError
    from ..laws import law_to_mapping
    try:
        mapping = law_to_mapping(law)
        text = json.dumps(mapping, sort_keys=True, allow_nan=True)
    except (FrictionRulesError, TypeError, ValueError):
        return None
    cls = type(law)
    return json.dumps({"format": FORMAT, "class": f"{cls.__module__}.{cls.__qualname__}",
                       "law": text, "generator": generator_digest()}, sort_keys=True)


def entry_path(folder: Path, key: str) -> Path:
    return folder / f"law-{hashlib.sha256(key.encode()).hexdigest()[:32]}.json"


def _floats(values) -> np.ndarray:
    if not isinstance(values, list) or not all(isinstance(v, str) for v in values):
        raise ValueError("not a list of hex floats")
    out = np.array([float.fromhex(v) for v in values], dtype=float)
    out.flags.writeable = False
    return out


def read_entry(folder: Path, key: str) -> LawEntry | None:
    """The entry of ``key`` in ``folder`` where it can be trusted (module docstring), else
    None."""
    path = entry_path(folder, key)
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
        if not isinstance(doc, dict) or doc.get("format") != FORMAT or doc.get("key") != key:
            return None
        module, digest, nq = doc["module"], doc["module_sha256"], doc["nq"]
        if (not isinstance(module, str) or not module.startswith(MODULE_PREFIX)
                or not module.isidentifier() or not isinstance(nq, int)
                or not isinstance(digest, str)):
            return None
        text = (folder / f"{module}.py").read_bytes()
        if hashlib.sha256(text).hexdigest() != digest:
            return None
        return LawEntry(module, digest, nq, _floats(doc["return_constants"]),
                        _floats(doc["parameter_values"]))
    except (OSError, ValueError, KeyError, TypeError, UnicodeDecodeError):
        return None


def write_entry(folder: Path, key: str, entry: LawEntry) -> None:
    """Write the entry of ``key`` atomically (a failure to write is not an error: the next run
    derives the law again)."""
    from .._output import write_text
    doc = {"format": FORMAT, "key": key, "module": entry.module,
           "module_sha256": entry.module_sha256, "nq": int(entry.nq),
           "return_constants": [float(v).hex() for v in entry.return_constants],
           "parameter_values": [float(v).hex() for v in entry.parameter_values]}
    try:
        write_text(entry_path(folder, key), json.dumps(doc, indent=1))
    except OSError:
        pass
