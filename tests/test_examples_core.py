"""Examples and the README's snippet are tested scripts."""

import re
import runpy
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def test_example_orthotropic(tmp_path):
    mod = runpy.run_path(str(ROOT / "examples" / "laws_orthotropic.py"))
    deviation = mod["main"](out=str(tmp_path / "o.png"))
    assert deviation["EllipticOrthotropic"] < 1e-9  # normality in the sliding plane
    assert deviation["Huber"] > 5 and deviation["TransformedCoulomb"] > 5
    assert (tmp_path / "o.png").exists()


def test_readme_python_example_runs(capsys):
    text = (ROOT / "README.md").read_text()
    code = re.search(r"```python\n(.*?)```", text, re.S).group(1)
    exec(compile(code, "README.md", "exec"), {})
    out = capsys.readouterr().out
    assert "ellipse" in out


def test_readme_quick_start_has_exactly_two_commands():
    text = (ROOT / "README.md").read_text()
    block = re.search(r"## Quick start.*?```bash\n(.*?)```", text, re.S).group(1)
    commands = [line for line in block.splitlines() if line.strip() and not line.startswith("#")]
    assert len(commands) == 2
    assert "frictionrules paper --out figures" in commands[0]
    assert "pytest" in commands[1]
    assert commands[1] in (ROOT / ".ci" / "run").read_text()  # CI runs exactly this command


@pytest.mark.parametrize("doc", ["docs/conventions.md", "docs/errata.md", "docs/laws.md"])
def test_docs_exist(doc):
    assert (ROOT / doc).stat().st_size > 500
