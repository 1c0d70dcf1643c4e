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


#: Import edges known to close a cycle, each with a comment naming who removes it (none today).
KNOWN_CYCLE_EDGES: set = set()


def _ancestors(module: str) -> set[str]:
    parts = module.split(".")
    return {".".join(parts[:i]) for i in range(1, len(parts))}


def _import_graph():
    """Module -> the modules importing it runs: the module imported and, as Python does, the
    package faces (``__init__``) on its path that are not already being imported because they
    contain the importer. A face importing its own modules (its re-exports) is an edge like any
    other: a module below a face that reads a name from it (the version, once) closes a cycle
    through the face's re-exports, and so does a module that imports a package whose face
    re-exports a module importing it back."""
    mods, edges, _ = _imports()
    graph = {}
    for m, targets in edges.items():
        out = set()
        for t in targets:
            if t not in mods:
                continue
            out |= {a for a in _ancestors(t) | {t} if a in mods and a != m and
                    (a == t or a not in _ancestors(m))}
        graph[m] = out - {t for t in out if (m, t) in KNOWN_CYCLE_EDGES}
    return mods, graph


def _cycles(graph) -> list[list[str]]:
    state, stack, cycles = {}, [], []

    def visit(m):
        state[m] = 1
        stack.append(m)
        for t in sorted(graph[m]):
            if state.get(t) == 1:
                cycles.append(stack[stack.index(t):] + [t])
            elif t not in state:
                visit(t)
        stack.pop()
        state[m] = 2

    for m in sorted(graph):
        if m not in state:
            visit(m)
    return cycles


def test_no_import_cycles():
    _, graph = _import_graph()
    cycles = _cycles(graph)
    assert not cycles, "import cycles:\n" + "\n".join(" -> ".join(c) for c in cycles[:10])


def test_known_cycle_edges_still_exist():
    """An entry of KNOWN_CYCLE_EDGES whose import is gone is removed from the list."""
    _, edges, _ = _imports()
    assert all(t in edges[m] for m, t in KNOWN_CYCLE_EDGES)


def test_the_cycle_check_sees_a_cycle_through_a_package_face():
    """io -> multicontact.problem initializes the multicontact face, which imports _solve: an
    edge _solve -> io (batch solving of files below io.py, as it once was) closes a cycle
    through the face, and the graph sees it."""
    _, graph = _import_graph()
    graph["frictionrules.multicontact._solve"] = graph["frictionrules.multicontact._solve"] | {"frictionrules.io"}
    assert any("frictionrules.io" in c for c in _cycles(graph))


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


def _concrete_laws() -> set[str]:
    """Names of the concrete law classes: dataclasses deriving from FrictionLaw, wherever
    they are defined (every module imported)."""
    import dataclasses
    import importlib
    import pkgutil

    from frictionrules.laws import FrictionLaw
    for info in pkgutil.walk_packages(frictionrules.__path__, "frictionrules."):
        if not info.name.endswith("__main__"):
            importlib.import_module(info.name)
    out, todo = set(), [FrictionLaw]
    while todo:
        cls = todo.pop()
        todo += cls.__subclasses__()
        if cls is not FrictionLaw and dataclasses.is_dataclass(cls) and \
                "__dataclass_fields__" in vars(cls):
            out.add(cls.__name__)
    return out


def _type_tests(tree: ast.AST):
    """``(line, class names)`` of every isinstance/issubclass call and ``type(x) is/== C``."""
    def names(node):
        if isinstance(node, ast.Tuple):
            return [n for e in node.elts for n in names(e)]
        if isinstance(node, ast.Name):
            return [node.id]
        if isinstance(node, ast.Attribute):
            return [node.attr]
        return []

    for node in ast.walk(tree):
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and \
                node.func.id in ("isinstance", "issubclass") and len(node.args) == 2:
            yield node.lineno, names(node.args[1])
        elif isinstance(node, ast.Compare):
            sides = [node.left, *node.comparators]
            if any(isinstance(s, ast.Call) and isinstance(s.func, ast.Name) and
                   s.func.id == "type" for s in sides):
                yield node.lineno, [n for s in sides for n in names(s)]


def test_no_isinstance_on_a_concrete_law_outside_laws():
    """A consumer asks a law for its capabilities and traits (``law.traits``,
    ``law.capabilities``, ``law.state_names``), never for its class: a law added to
    ``laws/`` then works everywhere, and a user law written for a built-in one behaves as it."""
    concrete = _concrete_laws()
    assert {"Coulomb", "EllipsoidCap", "UserLaw", "FacetSet"} <= concrete
    bad = []
    for mod, path in _modules().items():
        if mod == "frictionrules.laws" or mod.startswith("frictionrules.laws."):
            continue
        for line, used in _type_tests(ast.parse(path.read_text())):
            hits = sorted(set(used) & concrete)
            if hits:
                bad.append(f"{path.relative_to(SRC.parent)}:{line}: {', '.join(hits)}")
    assert not bad, "\n".join(bad)


def test_the_type_test_scan_sees_each_form():
    tree = ast.parse("isinstance(a, Coulomb)\nisinstance(a, (float, laws.Huber))\n"
                     "type(a) is UserLaw\nissubclass(c, EllipsoidCap)\n")
    assert [n for _, n in _type_tests(tree)] == [["Coulomb"], ["float", "Huber"], ["UserLaw"],
                                                  ["EllipsoidCap"]]
