"""The documentation runs: every code block of README.md and docs/*.md, and the docs site builds.

Each ``python`` block is executed, and each ``bash`` block run by bash, in an empty folder of its
own (no block may depend on another block or on files of the repository). A ``text`` block
directly after a code block is the output the text promises: what the block prints must match
it (``...`` matches anything, whitespace is normalized). A code block preceded by the comment
``<!-- not run: REASON -->`` is skipped with that reason. ``toml`` and ``json`` blocks must
parse. Code in indented blocks would escape all this, so an indented block may not hold a
command or an import.
"""

from __future__ import annotations

import ast
import doctest
import json
import os
import re
import shutil
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest
from markdown_it import MarkdownIt

ROOT = Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
RUN = {"python", "bash"}
DATA = {"toml": tomllib.loads, "json": json.loads}
SHOWN = {"text", "csv", "console-output"}
NOT_RUN = re.compile(r"<!--\s*not run:\s*(?P<reason>\S.*?)\s*-->", re.S)
CODE_LINE = re.compile(r"^\s*(\$ |>>> |frictionrules |python3? |import |from \S+ import )", re.M)


def _blocks(page: Path):
    """``(language, code, line, expected output or None, reason not run or None)`` per fence."""
    tokens = [t for t in MarkdownIt("commonmark").enable("table").parse(page.read_text())
              if t.block and t.nesting >= 0 and t.type != "inline"]  # block openers, in order
    out = []
    for i, tok in enumerate(tokens):
        line = tok.map[0] + 1 if tok.map else 0
        if tok.type == "code_block":
            out.append(("indented", tok.content, line, None, None))
            continue
        if tok.type != "fence":
            continue
        lang = tok.info.strip().split()[0] if tok.info.strip() else ""
        if lang.startswith("{"):
            continue  # a MyST directive ({toctree}, {include}), not code
        prev = tokens[i - 1] if i else None
        skip = NOT_RUN.search(prev.content) if prev is not None and prev.type == "html_block" else None
        nxt = tokens[i + 1] if i + 1 < len(tokens) else None
        expected = None
        if lang in RUN and nxt is not None and nxt.type == "fence" and nxt.info.strip() == "text":
            expected = nxt.content
        if lang == "text" and out and out[-1][3] is not None and prev is not None and prev.type == "fence":
            continue  # the expected output of the block before
        out.append((lang, tok.content, line, expected, skip and skip["reason"]))
    return out


def _cases():
    for page in PAGES:
        rel = page.relative_to(ROOT).as_posix()
        for lang, code, line, expected, reason in _blocks(page):
            marks = [pytest.mark.skip(reason=f"not run: {reason}")] if reason and lang in RUN else []
            yield pytest.param(lang, code, expected, rel, line, id=f"{rel}:{line}", marks=marks)


CASES = list(_cases())


def _check_no_silent_expressions(code: str, where: str) -> None:
    """A bare expression (``r.load, r.mechanism``) shows its value in a REPL but prints
    nothing when the block runs: the text would promise output that never appears."""
    for node in ast.parse(code).body:
        if isinstance(node, ast.Expr) and not isinstance(node.value, (ast.Call, ast.Await)):
            pytest.fail(f"{where}, line {node.lineno}: {ast.unparse(node)!r} prints nothing; "
                        "print it (and show the output in a text block after the code)")


def _check_output(got: str, expected: str, where: str) -> None:
    checker = doctest.OutputChecker()
    flags = doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE
    if not checker.check_output(expected, got, flags):
        pytest.fail(f"{where}: the printed output differs from the text\n"
                    f"--- text says:\n{expected}--- block printed:\n{got}")


@pytest.mark.parametrize("lang, code, expected, page, line", CASES)
def test_code_block(lang, code, expected, page, line, tmp_path, monkeypatch, capsys):
    where = f"{page}:{line}"
    if lang == "python":
        _check_no_silent_expressions(code, where)
        monkeypatch.chdir(tmp_path)
        exec(compile(code, where, "exec"), {"__name__": "__main__"})
        got = capsys.readouterr().out
    elif lang == "bash":
        env = dict(os.environ, PATH=f"{Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}",
                   MPLBACKEND="Agg")
        proc = subprocess.run(["bash", "-euo", "pipefail", "-c", code], cwd=tmp_path, env=env,
                              capture_output=True, text=True, timeout=300)
        assert proc.returncode == 0, f"{where}: exit {proc.returncode}\n{proc.stderr}"
        got = proc.stdout
    elif lang in DATA:
        DATA[lang](code)
        return
    elif lang in SHOWN:
        return
    elif lang == "indented":
        found = CODE_LINE.search(code)
        assert found is None, (f"{where}: {found.group(0).strip()!r} in an indented block does not "
                               "run; use a fenced ```bash or ```python block")
        return
    else:
        pytest.fail(f"{where}: a code block needs a language: one of "
                    f"{sorted(RUN | set(DATA) | SHOWN)} (got {lang!r})")
    if expected is not None:
        _check_output(got, expected, where)


def _cells(row: str) -> int:
    return len(re.split(r"(?<!\\)\|", row.strip().strip("|")))


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.relative_to(ROOT).as_posix())
def test_tables_render_as_written(page):
    """Every row of a table has the header's cells (a ``|`` inside a code span must be written
    ``\\|``, else it splits the cell and the rest of the row is dropped), and no table lacks its
    ``|---|`` line (it would render as one paragraph)."""
    text = page.read_text()
    lines = text.splitlines()
    in_table = set()
    for tok in MarkdownIt("commonmark").enable("table").parse(text):
        if tok.type == "table_open":
            first, end = tok.map
            in_table.update(range(first, end))
            bad = [i + 1 for i in range(first, end) if _cells(lines[i]) != _cells(lines[first])]
            assert not bad, f"{page.name}: rows {bad} do not have the {_cells(lines[first])} cells of the header"
    code = set()
    for tok in MarkdownIt("commonmark").parse(text):
        if tok.type in ("fence", "code_block") and tok.map:
            code.update(range(*tok.map))
    stray = [i + 1 for i, line in enumerate(lines)
             if line.startswith("|") and i not in in_table and i not in code]
    assert not stray, f"{page.name}: lines {stray} look like a table but do not render as one"


def test_every_page_is_in_the_site():
    """A page of docs/ missing from the toctree of docs/index.md is not in the site."""
    index = (ROOT / "docs" / "index.md").read_text()
    listed = set()
    for tok in MarkdownIt("commonmark").parse(index):
        if tok.type == "fence" and tok.info.strip() == "{toctree}":
            listed |= {line.strip() for line in tok.content.splitlines()
                       if line.strip() and not line.startswith(":")}
    missing = [p.name for p in PAGES if p.parent == ROOT / "docs" and p.stem not in listed | {"index"}]
    assert not missing, f"add {missing} to a toctree of docs/index.md"


def test_every_page_is_collected():
    """The pages other developers add are picked up (the glob, not a list)."""
    names = {p.relative_to(ROOT).as_posix() for p in PAGES}
    assert {"README.md", "docs/laws.md", "docs/install.md"} <= names
    assert sum(c.values[0] == "python" for c in CASES) >= 6


BUILD = "python -m sphinx -W -b html docs docs/_build/html"


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    """The site built by the README's command (-W: no warning), the gallery's examples run."""
    assert BUILD in (ROOT / "README.md").read_text()
    tmp = tmp_path_factory.mktemp("site")
    out = tmp / "html"
    argv = BUILD.split()[1:-1] + [str(out)]
    env = dict(os.environ, FRICTIONRULES_DOCS_EXAMPLES="1")
    proc = subprocess.run([sys.executable, *argv, "-q", "-d", str(tmp / "doctrees")], cwd=ROOT,
                          env=env, capture_output=True, text=True, timeout=1800)
    assert proc.returncode == 0, proc.stderr[-5000:]
    return out


def test_docs_site_builds_offline_without_warnings(site):
    """The README's command builds the site (API pages, guide, gallery) without a warning."""
    import frictionrules
    api = "".join(p.read_text() for p in (site / "api").glob("*.html"))
    undocumented = [n for n in frictionrules.__all__ if f'id="frictionrules.{n}"' not in api]
    assert not undocumented, f"no API entry for {undocumented}"
    examples = sorted(p.stem for p in (ROOT / "examples").glob("*.py"))
    assert sorted(p.stem for p in (site / "gallery").glob("*.html")) == sorted(examples + ["index"])
    assert "frictionrules solve" in (site / "api" / "cli.html").read_text()


#: Chromium, headless, with nothing of its own started (no network, sync, updates). No time
#: budget: the test polls the page (DevTools protocol) until it has written its measurement.
CHROMIUM_FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                  "--disable-background-networking", "--disable-component-update",
                  "--disable-sync", "--window-size=1280,1000"]
#: Measured in the browser once the page, its images and its fonts have loaded (the load event,
#: then ``document.fonts.ready``): every image of the text (its natural and shown width, and the
#: width of the text column), every code or output block (the width of its content and of its
#: box). The element it appends last is what the test waits for.
_MEASURE = """
<script>
window.addEventListener("load", function () {
  document.fonts.ready.then(function () {
  var body = document.querySelector("div.body"), out = {images: [], blocks: []};
  body.querySelectorAll("img").forEach(function (i) {
    out.images.push({src: i.getAttribute("src"), natural: i.naturalWidth,
                     shown: i.getBoundingClientRect().width, column: body.clientWidth});
  });
  body.querySelectorAll("pre").forEach(function (p) {
    out.blocks.push({text: p.textContent.slice(0, 60), content: p.scrollWidth, box: p.clientWidth});
  });
  var e = document.createElement("pre");
  e.id = "frictionrules-layout";
  e.textContent = JSON.stringify(out);
  document.body.appendChild(e);
  });
});
</script>
"""


def chromium() -> str:
    """The Chromium of the machine; skips without it, except in CI (CI=true), where .ci/run
    installs the Debian package ``chromium``."""
    path = shutil.which("chromium") or shutil.which("chromium-browser")
    if path is None:
        if os.environ.get("CI") == "true":
            pytest.fail("chromium is missing on CI: .ci/run installs the Debian package")
        pytest.skip("no chromium on this machine (apt-get install chromium)")
    return path


def layout(page: Path, browser: str, profile: Path) -> dict:
    """What Chromium shows of ``page``: a copy of it beside it (same relative links) with the
    measuring script appended, opened headless; the test waits until the page has written its
    measurement (polled through the DevTools protocol), however long loading takes."""
    from _browser import wait_for_text
    probe = page.with_name(page.stem + ".layout-check.html")
    probe.write_text(page.read_text().replace("</body>", _MEASURE + "</body>"))
    try:
        text = wait_for_text(browser, CHROMIUM_FLAGS, profile, probe.as_uri(), "frictionrules-layout")
    finally:
        probe.unlink()
    return json.loads(text)


def test_gallery_pages_show_their_figures_in_a_browser(site, tmp_path):
    """Every gallery page, opened in headless Chromium at 1280 px: at least one figure, loaded
    and no wider than the text; no code or output line running past the right edge of its box;
    no path of the build machine in what the examples print."""
    browser = chromium()
    pages = sorted(p for p in (site / "gallery").glob("*.html") if p.stem != "index")
    assert len(pages) == len(list((ROOT / "examples").glob("*.py")))
    machine = re.compile(re.escape(str(ROOT.parent)) + r"|/tmp/|" + re.escape(str(Path.home())))
    for page in pages:
        seen = layout(page, browser, tmp_path / "profile")
        figures = [i for i in seen["images"] if i["src"].startswith("../_images/")
                   or "figures/" in i["src"]]
        assert figures, f"{page.name}: no figure"
        for image in figures:
            assert image["natural"] > 100, f"{page.name}: {image['src']} did not load"
            assert image["shown"] <= image["column"] + 1, f"{page.name}: {image['src']} too wide"
        wide = [b for b in seen["blocks"] if b["content"] > b["box"] + 1]
        assert not wide, f"{page.name}: a line runs past its box: {wide[0]}"
        text = re.sub(r"<[^>]+>", "", page.read_text())
        assert not machine.search(text), f"{page.name}: {machine.search(text).group(0)}"


def test_gallery_page_shows_what_the_example_prints_and_draws(tmp_path):
    """The gallery runs an example in an empty folder and shows its output and figures."""
    sys.path.insert(0, str(ROOT / "docs" / "_ext"))
    try:
        import frictionrules_docs as gallery
    finally:
        sys.path.pop(0)
    script = tmp_path / "example_plot.py"
    script.write_text('"""A title.\n\nWhat it shows."""\nimport matplotlib.pyplot as plt\n\n'
                      'print("mu = 0.3")\nplt.plot([0, 1], [0, 1])\n')
    status, output, figures, folder = gallery._run_example(script)
    names = [f.name for f in figures]
    shutil.rmtree(folder)
    assert (status, output, names) == ("ok", "mu = 0.3\n", ["figure_0.png"])
    page = gallery._example_page(script, status, output, ["figures/example_plot_0.png"])
    assert page.startswith("# A title\n\nWhat it shows.")
    assert ":lines: 4-" in page and "mu = 0.3" in page and "![example_plot](figures/example_plot_0.png)" in page


HISTORY = re.compile(r"\(issue\b|\bissues? \d+\b|\bthis session\b|\bthis round\b", re.I)


def test_no_project_history_in_user_facing_text():
    """Code, docstrings, messages and docs say what is, not when or in which issue it came."""
    files = [*PAGES, *(ROOT / "src").rglob("*.py"), *(ROOT / "examples").glob("*")]
    found = [f"{f.relative_to(ROOT)}:{i}: {line.strip()}" for f in files if f.is_file()
             for i, line in enumerate(f.read_text(errors="replace").splitlines(), 1)
             if HISTORY.search(line)]
    assert not found, "\n".join(found)
