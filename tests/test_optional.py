"""A light core: NumPy is all the built-in laws and ``frictionrules law`` need; every heavy part
comes with an extra of pyproject.toml, and a missing one is a one-line FrictionRulesError (exit
code 2 on the command line) naming the extra to install.

The optional packages are hidden from a subprocess by a meta-path finder that raises
``ModuleNotFoundError`` for them, as if they were not installed (the real thing, fresh
environments per extra, is ``benchmarks/install_size.py``).
"""

from __future__ import annotations

import json
import re
import subprocess
import sys
import textwrap
import tomllib
from pathlib import Path

import pytest

from frictionrules import FrictionRulesError
from frictionrules._optional import EXTRAS, missing_module_message, require
from frictionrules.paper import REQUIRES

ROOT = Path(__file__).resolve().parents[1]
PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text())
OPTIONAL = sorted(EXTRAS)

_PRELUDE = """
import json, sys, traceback
HIDDEN = set(sys.argv[1].split(","))

class _Hide:
    def find_spec(self, name, path=None, target=None):
        if name.partition(".")[0] in HIDDEN:
            raise ModuleNotFoundError(f"No module named {name!r}", name=name)
        return None

sys.meta_path.insert(0, _Hide())
results = {}

def case(label, code):
    try:
        exec(code, {})
        results[label] = "ok"
    except SystemExit as exc:
        results[label] = f"exit {exc.code}"
    except BaseException as exc:
        results[label] = f"{type(exc).__name__}: {exc}"
"""


def run_hidden(hidden, cases: dict[str, str], tmp_path) -> tuple[dict[str, str], str]:
    """Run each snippet of ``cases`` with the packages ``hidden``; (results, stderr)."""
    body = "".join(f"case({label!r}, {textwrap.dedent(code)!r})\n" for label, code in cases.items())
    script = _PRELUDE + body + "print(json.dumps(results))\n"
    proc = subprocess.run([sys.executable, "-c", script, ",".join(hidden)], cwd=tmp_path,
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    return json.loads(proc.stdout.strip().splitlines()[-1]), proc.stderr


def cli(*argv: str) -> str:
    return f"import sys\nfrom frictionrules.cli import main\nsys.exit(main({list(argv)!r}))"


LAW_COMMANDS = {
    "law coulomb": cli("law", "coulomb", "--mu", "0.3", "--force", "0.1", "0.2", "--normal", "1"),
    "law elliptic": cli("law", "elliptic", "--mu-x", "0.6", "--mu-y", "0.3", "--force", "0.3",
                        "0.2", "--normal", "1", "--json"),
    "law huber": cli("law", "huber", "--mu-1", "0.6", "--mu-2", "0.3", "--force", "0.3", "0.2",
                     "--normal", "1", "--theta", "0.4"),
    "law transformed": cli("law", "transformed", "--mu-x", "0.6", "--mu-y", "0.3", "--force",
                           "0.3", "0.2", "--normal", "1", "--theta", "0.4"),
    "law wedge": cli("law", "wedge", "--alpha", "30", "--deg", "--mu", "0.5", "--force", "1",
                     "0.2", "--normal", "1", "--theta", "0.5"),
    "help": cli("--help"),
    "api": """
        import numpy as np
        import frictionrules as fr
        for law in (fr.Coulomb(0.3), fr.Coulomb(0.3, dilatant=True), fr.Huber(0.6, 0.3),
                    fr.EllipticOrthotropic(0.6, 0.3, angle=0.2), fr.TransformedCoulomb(0.6, 0.3),
                    fr.WedgeAsperity(np.pi / 6, 0.5)):
            T = law.force_for_slip([1.0, 0.5], 1.0)
            law.limit(T, 1.0), law.slip_direction(T, 1.0), law.dissipation([1.0, 0.5], 1.0)
            law.friction_coefficient(np.linspace(0, 2 * np.pi, 9)), law.force_angle(0.3)
            fr.compare_rules(law, T, 1.0)
    """,
}


def test_core_runs_the_built_in_laws_and_the_law_command(tmp_path):
    results, stderr = run_hidden(OPTIONAL, LAW_COMMANDS, tmp_path)
    assert results == {label: ("exit 0" if label != "api" else "ok") for label in LAW_COMMANDS}, stderr


def test_paper_on_the_core_exits_2_naming_the_paper_extra(tmp_path):
    results, stderr = run_hidden(OPTIONAL, {"paper": cli("paper", "--out", "figures")}, tmp_path)
    assert results["paper"] == "exit 2"
    lines = stderr.strip().splitlines()
    assert len(lines) == 1, stderr
    assert lines[0] == ('frictionrules paper: error: frictionrules paper needs matplotlib, numba, '
                        'scipy and sympy, which are not installed: pip install '
                        '"frictionrules[paper]"'), lines[0]
    assert not (tmp_path / "figures").exists()  # checked before any work


@pytest.mark.parametrize("hidden, argv, message", [
    (("h5py", "scipy", "numba"), ["solve", "problem.hdf5"],
     'frictionrules solve needs h5py, scipy and numba, which are not installed: '
     'pip install "frictionrules[hdf5,kernels,solvers]"'),
    (("numba", "matplotlib"), ["drive", "shear.toml", "--plot", "p.png"],
     'frictionrules drive needs numba and matplotlib, which are not installed: '
     'pip install "frictionrules[figures,kernels]"'),
    (("SurfaceTopography", "matplotlib"), ["asperity", "map.x3p", "--mu", "0.3", "--out", "a"],
     'frictionrules asperity needs SurfaceTopography and matplotlib, which are not installed: '
     'pip install "frictionrules[figures,surfaces]"'),
])
def test_every_missing_extra_is_named_at_once(hidden, argv, message, tmp_path):
    """One line names every package the command needs and the one pip command for them all,
    before the command reads its input (the files named here do not exist)."""
    results, stderr = run_hidden(hidden, {"cli": cli(*argv)}, tmp_path)
    assert results["cli"] == "exit 2"
    assert stderr.strip().splitlines() == [f"frictionrules {argv[0]}: error: {message}"]


def test_paper_list_needs_no_extra(tmp_path):
    results, stderr = run_hidden(OPTIONAL, {"list": cli("paper", "--list")}, tmp_path)
    assert results["list"] == "exit 0", stderr


@pytest.mark.parametrize("package, cases", [
    ("matplotlib", {"plot": "import frictionrules.plot"}),
    ("scipy", {"problem": "import frictionrules as fr; fr.FrictionContactProblem([[1, 0, 0], [0, 1, 0], [0, 0, 1]], [-1, 0, 0], 0.3)",
               "heightmap": "import numpy as np, frictionrules as fr; "
                            "fr.from_heightmap(np.random.default_rng(0).random((8, 8)), 1.0, 1.0, 0.3)"}),
    ("numba", {"solve": "import frictionrules as fr; fr.solve(fr.FrictionContactProblem([[1, 0, 0], [0, 1, 0], [0, 0, 1]], [-1, 0, 0], 0.3))"}),
    ("h5py", {"read_fclib": "import frictionrules as fr; fr.read_fclib('missing.hdf5')"}),
    ("sympy", {"cylinder": "import frictionrules as fr; c = fr.CylinderOnLayer(1.0, 0.3); "
                           "c.displacement_path(c.straight_path(0.0, 0.5, 11), method='incremental')"}),
])
def test_a_missing_extra_is_one_line_naming_it(package, cases, tmp_path):
    results, stderr = run_hidden([package], cases, tmp_path)
    extra = EXTRAS[package]
    for label, got in results.items():
        assert got == (f'FrictionRulesError: {package} is not installed: '
                       f'pip install "frictionrules[{extra}]"'), (label, got, stderr)


@pytest.mark.parametrize("package, argv", [
    ("sympy", ["law", "user", "--limit", "sqrt(T1**2 + T2**2) - 0.3*N", "--force", "0.1", "0.1",
               "--normal", "1"]),
    ("matplotlib", ["asperity", "--two-flank", "60", "150", "--deg", "--mu", "1", "--out", "fig5"]),
])
def test_the_cli_names_the_extra_of_any_missing_package(package, argv, tmp_path):
    """Also where the library imports the package without the helper."""
    results, stderr = run_hidden([package], {"cli": cli(*argv)}, tmp_path)
    assert results["cli"] == "exit 2"
    line = stderr.strip().splitlines()[-1]
    assert f"{package}" in line and line.endswith(
        f'not installed: pip install "frictionrules[{EXTRAS[package]}]"'), stderr


def test_require_returns_the_module_or_names_the_extra():
    import numpy
    assert require("numpy", extra="core") is numpy
    with pytest.raises(FrictionRulesError, match=r'^frictionrules_nope is not installed: '
                                                 r'pip install "frictionrules\[figures\]"$'):
        require("frictionrules_nope", extra="figures")
    with pytest.raises(FrictionRulesError, match=r'^x needs frictionrules_nope, which is not '
                                                 r'installed: pip install "frictionrules\[all\]"$'):
        require("frictionrules_nope", purpose="x")
    assert missing_module_message(ModuleNotFoundError("No module named 'numba.core'",
                                                      name="numba.core")) == (
        'numba is not installed: pip install "frictionrules[kernels]"')
    assert missing_module_message(ModuleNotFoundError("no", name="frictionrules.nope")) is None


def test_require_reports_a_package_that_is_installed_but_broken(tmp_path, monkeypatch):
    (tmp_path / "frictionrules_broken.py").write_text("raise ImportError('built for another NumPy')\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    with pytest.raises(FrictionRulesError, match=r"^frictionrules_broken is installed but cannot be "
                                                 r"imported \(built for another NumPy\); reinstall"):
        require("frictionrules_broken", extra="kernels")


def _expand(extra: str) -> set[str]:
    """Distribution names an extra installs, following ``frictionrules[...]`` references."""
    names = set()
    for req in PYPROJECT["project"]["optional-dependencies"][extra]:
        name = re.match(r"[A-Za-z0-9_.-]+", req).group(0).lower()
        if name == "frictionrules":
            for inner in re.search(r"\[(.*)\]", req).group(1).split(","):
                names |= _expand(inner.strip())
        else:
            names.add(name)
    return names


def test_extras_are_consistent():
    extras = PYPROJECT["project"]["optional-dependencies"]
    assert PYPROJECT["project"]["dependencies"] == ["numpy>=1.24"]   # the light core
    assert set(EXTRAS.values()) <= set(extras)                        # the helper names real extras
    # what paper checks for (threadpoolctl comes with `solvers`: the solvers limit BLAS threads)
    assert _expand("paper") - {"threadpoolctl"} == set(REQUIRES)
    runtime = set(extras) - {"all", "docs", "test", "paper"}
    assert all(_expand(e) <= _expand("all") for e in runtime), "`all` misses an extra"
    assert _expand("all") | _expand("docs") <= _expand("test"), "`test` must install everything"


def test_py_typed_is_shipped():
    assert (ROOT / "src" / "frictionrules" / "py.typed").exists()
    assert "py.typed" in PYPROJECT["tool"]["setuptools"]["package-data"]["frictionrules"]
