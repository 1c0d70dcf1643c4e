"""The shape of the package: no import cycles (module-level or inside functions), no private
name imported across packages, modules of a readable size, the public API re-exported."""

import ast
from pathlib import Path

import pytest

import frictionrules

SRC = Path(frictionrules.__file__).parent
MAX_LINES = 650


def _modules():
    out = {}
    for path in sorted(SRC.rglob("*.py")):
        rel = path.relative_to(SRC.parent).with_suffix("")
        parts = list(rel.parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        out[".".join(parts)] = path
    return out


def _resolve(module: str, path: Path, node: ast.ImportFrom) -> str:
    if node.level == 0:
        return node.module or ""
    package = module.split(".") if path.name == "__init__.py" else module.split(".")[:-1]
    base = package[:len(package) - (node.level - 1)]
    return ".".join(base + ([node.module] if node.module else []))


def _imports():
    """Edges module -> imported frictionrules module (with the names imported)."""
    mods = _modules()
    edges = {m: set() for m in mods}
    names = []
    for mod, path in mods.items():
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom):
                target = _resolve(mod, path, node)
                if not target.startswith("frictionrules"):
                    continue
                for alias in node.names:
                    sub = f"{target}.{alias.name}"
                    edges[mod].add(sub if sub in mods else target)
                    names.append((mod, target, alias.name))
            elif isinstance(node, ast.Import):
                for alias in node.names:
                    if alias.name.startswith("frictionrules"):
                        edges[mod].add(alias.name)
    return mods, edges, names


def _owner(target: str, name: str, mods) -> str | None:
    """The package a private module or name belongs to (None when nothing is private):
    ``frictionrules.laws`` for ``frictionrules.laws._symbolic``; ``frictionrules`` for the
    package-wide ``frictionrules._atomic``."""
    parts = target.split(".")
    for i, p in enumerate(parts):
        if p.startswith("_") and not p.startswith("__"):
            return ".".join(parts[:i])
    if name.startswith("_") and not name.startswith("__"):
        return target if target in mods and mods[target].name == "__init__.py" else ".".join(parts[:-1])
    return None


def test_no_import_cycles():
    mods, edges, _ = _imports()
    # a package's __init__ re-exporting its own modules is not a cycle of the design
    graph = {m: {t for t in ts if t in mods and not (m.startswith(t + ".") and t != m)} for m, ts in edges.items()}
    state, stack, cycles = {}, [], []

    def visit(m):
        state[m] = 1
        stack.append(m)
        for t in graph[m]:
            if state.get(t) == 1:
                cycles.append(stack[stack.index(t):] + [t])
            elif t not in state:
                visit(t)
        stack.pop()
        state[m] = 2

    for m in graph:
        if m not in state:
            visit(m)
    assert not cycles, "import cycles:\n" + "\n".join(" -> ".join(c) for c in cycles[:10])


def test_no_private_name_imported_across_packages():
    mods, _, names = _imports()
    bad = []
    for mod, target, name in names:
        owner = _owner(target, name, mods)
        if owner is not None and not (mod == owner or mod.startswith(owner + ".")):
            bad.append(f"{mod}: from {target} import {name}")
    assert not bad, "\n".join(bad)


#: Modules being split by concern (remove an entry when its split lands).
BEING_SPLIT: set[str] = set()


@pytest.mark.parametrize("module", [pytest.param(m, marks=pytest.mark.xfail(reason="being split"))
                                    if m in BEING_SPLIT else m for m in sorted(_modules())])
def test_module_size(module):
    lines = len(_modules()[module].read_text().splitlines())
    assert lines <= MAX_LINES, f"{module} has {lines} lines; split it by concern"


def test_public_api_is_exported():
    for name in frictionrules.__all__:
        assert getattr(frictionrules, name) is not None
    for name in ("Coulomb", "EllipticOrthotropic", "Huber", "TransformedCoulomb", "UserLaw",
                 "WedgeAsperity", "TwoFlankAsperity", "FacetSet", "from_profile", "from_heightmap",
                 "fit", "CylinderOnLayer", "SphereOnLayer", "ContactModel", "ContactState",
                 "EllipsoidCap", "SlipHardening", "drive", "FrictionContactProblem", "solve",
                 "read_fclib", "write_fclib"):
        assert name in frictionrules.__all__


def test_no_control_characters_in_sources():
    """A TAB or a backspace in a docstring is an escape gone wrong (``"\tau"`` outside a raw
    string): it corrupts the rendered formula."""
    root = Path(frictionrules.__file__).parent
    bad = [f"{p.relative_to(root)}:{i}" for p in sorted(root.rglob("*.py"))
           for i, line in enumerate(p.read_text().splitlines(), 1)
           if any(c in line for c in "\t\b\f\v\a")]
    assert not bad, bad
