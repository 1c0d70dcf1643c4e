"""Installed size of the core and of each extra, each in a fresh virtual environment.

Run: ``python benchmarks/install_size.py [EXTRA ...]`` (default: the core and every extra of
``pyproject.toml``; writes ``benchmarks/results/install_size.md``). The wheel of the checkout is
built once; each row is ``du -sk`` of the environment's site-packages after
``pip install "WHEEL[EXTRA]"`` minus the same of a bare environment (pip and setuptools),
so it counts frictionrules and every dependency it pulls in. Needs the package index pip is
set up to use; takes a few minutes.
"""

from __future__ import annotations

import shutil
import subprocess
import sys
import sysconfig
import tempfile
import tomllib
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _table import write_table  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]


def site_packages_kb(venv: Path) -> int:
    """``du -sk`` of the environment's site-packages (kB)."""
    rel = Path(sysconfig.get_path("purelib")).relative_to(sys.prefix)
    out = subprocess.run(["du", "-sk", str(venv / rel)], check=True, capture_output=True, text=True)
    return int(out.stdout.split()[0])


def fresh_venv(path: Path) -> Path:
    subprocess.run([sys.executable, "-m", "venv", str(path)], check=True)
    return path / "bin" / "python"


def installed(python: Path) -> list[str]:
    out = subprocess.run([str(python), "-m", "pip", "list", "--format=freeze"], check=True,
                         capture_output=True, text=True).stdout
    return sorted(line.split("==")[0].lower() for line in out.splitlines() if "==" in line)


def main(extras: list[str]) -> None:
    declared = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["optional-dependencies"]
    extras = extras or ["core", *declared]
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        subprocess.run([sys.executable, "-m", "pip", "wheel", "-q", "--no-deps", "-w", str(tmp),
                        str(ROOT)], check=True)
        wheel = next(tmp.glob("frictionrules-*.whl"))
        bare_python = fresh_venv(tmp / "bare")
        bare, base = site_packages_kb(tmp / "bare"), set(installed(bare_python))
        rows = []
        for extra in extras:
            venv = tmp / f"venv-{extra}"
            python = fresh_venv(venv)
            target = str(wheel) if extra == "core" else f"{wheel}[{extra}]"
            subprocess.run([str(python), "-m", "pip", "install", "-q", target], check=True)
            mb = (site_packages_kb(venv) - bare) / 1024
            added = [p for p in installed(python) if p not in base and p != "frictionrules"]
            rows.append([f"`{extra}`", f"{mb:.0f}", len(added), ", ".join(added)])
            print(f"{extra}: {mb:.0f} MB", flush=True)
            shutil.rmtree(venv)
    write_table("install_size", "Installed size of frictionrules with each extra",
                ["install", "MB", "packages", "what it adds to a bare environment"], rows,
                notes="Each row: site-packages of a fresh venv after pip install WHEEL[EXTRA], "
                      "minus a bare venv (du -sk).")


if __name__ == "__main__":
    main(sys.argv[1:])
