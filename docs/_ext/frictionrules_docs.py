"""Sphinx extension of the frictionrules docs: generated API, command-line and gallery pages.

At ``builder-inited`` it writes (only files whose text changed, so rebuilds stay incremental):

* ``api/<subpackage>.rst``: one page per public subpackage, documenting the names of
  ``frictionrules.__all__`` that live there (as ``frictionrules.NAME``) and the other names of
  the subpackage's own ``__all__`` (as ``frictionrules.SUBPACKAGE.NAME``); ``api/cli.md`` with
  the ``--help`` of every subcommand. A name of ``frictionrules.__all__`` that no page
  documents is a warning (and so an error under ``-W``).
* ``gallery/<example>.md``: one page per script of ``examples/``: its docstring, its source,
  what it prints and the figures it makes, from running it as ``python examples/NAME.py`` in
  an empty folder (in parallel, with a time limit): every example saves its figures in the
  current folder and names them relatively, so the page shows each figure and no path of the
  build machine. An example that needs data not present (the FCLIB problems or the measured
  surfaces beside the repository) says so on its page. ``FRICTIONRULES_DOCS_EXAMPLES=0``
  builds the pages without running the examples.

Both folders are generated: they are git-ignored and never edited by hand.
"""

from __future__ import annotations

import ast
import concurrent.futures
import importlib
import inspect
import os
import pkgutil
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

from sphinx.util import logging

logger = logging.getLogger(__name__)

DOCS = Path(__file__).resolve().parents[1]
ROOT = DOCS.parent
EXAMPLES = ROOT / "examples"

#: Order of the API pages; other public subpackages follow alphabetically.
ORDER = ("laws", "asperities", "configuration", "contact", "multicontact", "io", "plot", "errors")
#: Public modules that are not API pages (the CLI gets its own page).
SKIP = {"cli", "paper"}
#: A short description of the names that are not classes or functions.
DATA = {"T1": "SymPy symbol of the tangential force T1, for user laws (SymPy loads on first use).",
        "T2": "SymPy symbol of the tangential force T2, for user laws.",
        "N": "SymPy symbol of the normal force N, for user laws.",
        "LAWS": "The law table (read-only): short name -> ``LawEntry`` (the class, its "
                "parameters with meaning, unit and bounds).",
        "EXPORT_TARGETS": "The export targets (read-only): name -> ``ExportTarget`` (title, "
                          "the files written, the writer, what it can express)."}
#: The API page of a name of :data:`DATA` not on the ``laws`` page.
DATA_HOME = {"EXPORT_TARGETS": "_export"}
EXAMPLE_TIMEOUT = 600


def _write(path: Path, text: str) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    if not path.exists() or path.read_text() != text:
        path.write_text(text)


def _subpackages() -> list[str]:
    """Public subpackages, and private packages whose names are re-exported (``_export``,
    documented as ``export``)."""
    import frictionrules
    found = [m.name for m in pkgutil.iter_modules(frictionrules.__path__)
             if (not m.name.startswith("_") or m.ispkg) and m.name.lstrip("_") not in SKIP]
    return sorted(found, key=lambda n: (ORDER.index(n.lstrip("_")) if n.lstrip("_") in ORDER
                                        else len(ORDER), n.lstrip("_")))


def _home(obj, name: str) -> str | None:
    """The subpackage of ``frictionrules`` that defines ``obj`` (``laws`` for a SymPy symbol)."""
    if name in DATA:
        return DATA_HOME.get(name, "laws")
    module = getattr(obj, "__module__", "") or ""
    parts = module.split(".")
    return parts[1] if len(parts) > 1 and parts[0] == "frictionrules" else None


def _directive(obj) -> str:
    if inspect.isclass(obj):
        return "autoclass"
    if callable(obj):
        return "autofunction"
    return "autodata"


def _api_page(sub: str, entries: list[tuple[str, str, object]]) -> str:
    """The page of ``frictionrules.<sub>``: its docstring, then ``(module, name, object)``."""
    title = f"``frictionrules.{sub.lstrip('_')}``"
    lines = [title, "=" * len(title), "", f".. automodule:: frictionrules.{sub}", "   :no-members:",
             ""]
    current = None
    for module, name, obj in entries:
        if module != current:
            lines += [f".. currentmodule:: {module}", ""]
            current = module
        lines += _entry(name, obj)
    return "\n".join(lines) + "\n"


def _entry(name: str, obj) -> list[str]:
    if name in DATA:
        return [f".. data:: {name}", "", f"   {DATA[name]}", ""]
    kind = _directive(obj)
    out = [f".. {kind}:: {name}"]
    if kind == "autoclass":
        out += ["   :members:", "   :show-inheritance:"]
    if kind == "autodata":
        out += ["   :no-value:"]
    return out + [""]


def _cli_page() -> str:
    os.environ["COLUMNS"] = "96"  # argparse wraps the help text to the terminal width
    from frictionrules.cli import SUBCOMMANDS, build_parser
    parser = build_parser()
    sub = next(a for a in parser._actions if a.__class__.__name__ == "_SubParsersAction")
    parts = ["# Command line", "",
             "`frictionrules COMMAND ...`; bad input exits with code 2 and a one-line message.", "",
             "```text", parser.format_help().rstrip(), "```", ""]
    for name in SUBCOMMANDS:
        parts += [f"## `frictionrules {name}`", "", "```text",
                  sub.choices[name].format_help().rstrip(), "```", ""]
    return "\n".join(parts)


def write_api(app) -> None:
    """Each public object once, on the page of the subpackage that defines it, under its
    shortest public name: ``frictionrules.NAME``, else ``frictionrules.<sub>.NAME``."""
    import frictionrules
    subs = _subpackages()
    by_sub: dict[str, list[tuple[str, str, object]]] = {s: [] for s in subs}
    seen: set[int] = set()
    public = [("frictionrules", n, getattr(frictionrules, n)) for n in frictionrules.__all__]
    for sub in subs:
        module = importlib.import_module(f"frictionrules.{sub}")
        public += [(module.__name__, n, getattr(module, n)) for n in getattr(module, "__all__", ())]
    for module, name, obj in public:
        if id(obj) in seen:
            continue
        seen.add(id(obj))
        home = _home(obj, name)
        if home in by_sub:
            by_sub[home].append((module, name, obj))
        elif module == "frictionrules":
            logger.warning(f"frictionrules.{name} has no API page (its module is {home!r})")
    api = DOCS / "api"
    for sub in subs:
        _write(api / f"{sub.lstrip('_')}.rst", _api_page(sub, by_sub[sub]))
    _write(api / "cli.md", _cli_page())
    toc = "\n".join([s.lstrip("_") for s in subs] + ["cli"])
    _write(api / "index.md", "# API reference\n\nEverything is importable from `frictionrules`; "
           "each page documents one subpackage.\n\n```{toctree}\n:maxdepth: 1\n\n" + toc + "\n```\n")


# ---- gallery -------------------------------------------------------------------------------
_RUNNER = """
import runpy, sys
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
from pathlib import Path
script = sys.argv[1]
sys.argv = [script]  # as `python script.py`: the script sees no arguments
runpy.run_path(script, run_name="__main__")
if not any(Path(".").rglob("*.png")):  # the figures the script drew but did not save
    for i, num in enumerate(plt.get_fignums()):
        plt.figure(num).savefig(f"figure_{i}.png", dpi=100, bbox_inches="tight")
"""


def _run_example(script: Path) -> tuple[str, str, list[Path], Path]:
    """Run ``script`` in an empty folder: (status, output, figures, folder)."""
    folder = Path(tempfile.mkdtemp(prefix=f"gallery-{script.stem}-"))
    env = dict(os.environ, MPLBACKEND="Agg")
    try:
        proc = subprocess.run([sys.executable, "-c", _RUNNER, str(script)], cwd=folder, env=env,
                              capture_output=True, text=True, timeout=EXAMPLE_TIMEOUT)
    except subprocess.TimeoutExpired:
        return "timeout", "", [], folder
    figures = sorted(folder.rglob("*.png"))
    if proc.returncode == 0:
        return "ok", proc.stdout.replace(f"{folder}{os.sep}", ""), figures, folder
    last = (proc.stderr.strip().splitlines() or [""])[-1]
    return "failed", last, figures, folder


#: Data an example may read, beside the repository: folder of ../shared -> the variable that
#: points elsewhere.
DATA_FOLDERS = {"fclib": "FRICTIONRULES_FCLIB", "surfaces": "FRICTIONRULES_SURFACES"}


def _needs_missing_data(script: Path) -> bool:
    """True for an example that reads the FCLIB problems or the measured surfaces of
    ``../shared`` when they are not there (nor where their variable points)."""
    text = script.read_text()
    return any(f'"{name}"' in text and not (ROOT.parent / "shared" / name).is_dir()
               and not os.environ.get(variable) for name, variable in DATA_FOLDERS.items())


def _example_page(script: Path, status: str, output: str, figures: list[str]) -> str:
    tree = ast.parse(script.read_text())
    doc = ast.get_docstring(tree) or script.stem
    title, _, rest = doc.partition("\n")
    first = tree.body[1].lineno if ast.get_docstring(tree) and len(tree.body) > 1 else 1
    rel = os.path.relpath(script, DOCS / "gallery")
    parts = [f"# {title.strip().rstrip('.')}", "", rest.strip(), "",
             f"Source: `examples/{script.name}` (below without its docstring).", "",
             f"```{{literalinclude}} {rel}", ":language: python", f":lines: {first}-", "```", ""]
    if status == "ok":
        parts += ["## Output", "", "```text", output.rstrip() or "(prints nothing)", "```", ""]
        for fig in figures:
            parts += [f"![{script.stem}]({fig})", ""]
    elif status == "not run":
        parts += ["## Output", "", "Not run in this build (`FRICTIONRULES_DOCS_EXAMPLES=0`); "
                  "`tests/test_examples.py` runs it.", ""]
    elif status == "skipped":
        parts += ["## Output", "", "Not run here: it reads data files (FCLIB problems or measured "
                  "surfaces) that were not found beside the repository (`../shared`).", ""]
    return "\n".join(parts)


def write_gallery(app) -> None:
    gallery = DOCS / "gallery"
    images = gallery / "figures"
    shutil.rmtree(images, ignore_errors=True)
    scripts = sorted(EXAMPLES.glob("*.py"))
    run = os.environ.get("FRICTIONRULES_DOCS_EXAMPLES", "1") != "0"
    todo = [s for s in scripts if run and not _needs_missing_data(s)]
    results = {s: ("skipped" if run else "not run", "", [], None) for s in scripts if s not in todo}
    workers = min(2, os.cpu_count() or 1)
    logger.info(f"running {len(todo)} examples for the gallery ...")
    with concurrent.futures.ThreadPoolExecutor(workers) as pool:
        for script, res in zip(todo, pool.map(_run_example, todo)):
            results[script] = res
    entries = []
    for script in scripts:
        status, output, figures, folder = results[script]
        if status in ("failed", "timeout"):
            logger.warning(f"gallery: examples/{script.name} {status}: {output}")
        names = []
        for i, fig in enumerate(figures):
            name = f"{script.stem}_{i}{fig.suffix}"
            images.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(fig, images / name)
            names.append(f"figures/{name}")
        if folder is not None:
            shutil.rmtree(folder, ignore_errors=True)
        _write(gallery / f"{script.stem}.md", _example_page(script, status, output, names))
        entries.append(script.stem)
    _write(gallery / "index.md",
           "# Examples\n\nEach example is a script in `examples/`, run by the test suite "
           "(`tests/test_examples.py`) and here, when the site is built: its source, what it "
           "prints and the figures it makes.\n\n```{toctree}\n:maxdepth: 1\n\n"
           + "\n".join(entries) + "\n```\n")


# ---- docstrings ------------------------------------------------------------------------------
#: Inline literals, roles (:math:`...`) and interpreted text, left as they are.
_LITERAL = re.compile(r"(``.+?``|:\w+:`[^`]+`|`[^`]+`_?)")
#: ``|T|`` in prose is an absolute value here, never a reStructuredText substitution.
_BARS = re.compile(r"(?<![\\|\w])\|(?=[^\s|])([^|`\n]*?[^\s|\\])\|(?![\w|])")


_DIRECTIVE = re.compile(r"^\s*\.\. [\w:-]+::")


def escape_absolute_values(app, what, name, obj, options, lines) -> None:
    """Write ``|x|`` of the docstrings' prose as ``\\|x\\|`` so docutils keeps it as text;
    directives (``.. math::``) and literal blocks (after ``::``) are left as they are."""
    block = None  # indentation of the directive or paragraph whose indented block is skipped
    for i, line in enumerate(lines):
        indent = len(line) - len(line.lstrip())
        if block is not None and (not line.strip() or indent > block):
            continue
        block = None
        if _DIRECTIVE.match(line) or line.rstrip().endswith("::"):
            block = indent
            if _DIRECTIVE.match(line):
                continue
        parts = _LITERAL.split(line)
        parts[::2] = [_BARS.sub(r"\\|\1\\|", part) for part in parts[::2]]
        lines[i] = "".join(parts)


def keep_literal_block_after_summary(app, what, name, obj, options, lines) -> None:
    """numpydoc dedents the text after the summary paragraph, so a literal block that follows a
    summary ending in ``::`` would lose its indentation; end the summary with ``:`` and give the
    block its own ``::`` paragraph (rendered the same). Runs before numpydoc."""
    end = next((i for i, line in enumerate(lines) if not line.strip()), len(lines))
    if 0 < end < len(lines) and lines[end - 1].rstrip().endswith("::"):
        lines[end - 1] = lines[end - 1].rstrip()[:-1]
        lines[end:end] = ["", "::"]


def setup(app):
    app.connect("autodoc-process-docstring", keep_literal_block_after_summary, priority=100)
    app.connect("autodoc-process-docstring", escape_absolute_values)
    app.connect("builder-inited", write_api)
    app.connect("builder-inited", write_gallery)
    return {"version": "1.0", "parallel_read_safe": True, "parallel_write_safe": True}
