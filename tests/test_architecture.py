"""The house rules of issues 22 and 33, read from the code with ``ast``: rules that measure
structure, not size.

Every import at any depth counts (lazy imports inside functions included). On the import
graph that runs (``if TYPE_CHECKING:`` blocks left out): no layering violation (SPEC §1, no
carve-out) and no import cycle at all. On the graph with the type-only imports counted too
(a type named across a module boundary is a dependency all the same): no cycle contains
``game/config.py`` or ``game/schema.py``, and every strongly connected component has at
most two modules (so every cycle is one pair of modules naming each other, never a loop
round three or more); ``navmesh/mesh.py`` imports nothing of ``navmesh/query.py`` (build
apart from query). On the source: one predicate compares a node count with the dense
threshold, at most two places outside ``navmesh/`` read a graph's ``.dense`` (the storage
strategy is chosen in navmesh), one place constructs ``World(...)``, and docs/architecture.md's
table of ``Level``'s fields lists every field.
"""

from __future__ import annotations

import ast
from functools import cache
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("navmesh", "ai", "game", "headless")
# which layers each may import (SPEC §1); game.front is the only pygame importer, and the
# environments (game.env) sit above it: they render through it
ALLOWED = {
    "navmesh": {"navmesh"},
    "ai": {"ai", "navmesh"},
    "game": {"game", "ai", "navmesh"},
    "game.front": {"game.front", "game", "ai", "navmesh"},
    "game.env": {"game.env", "game.front", "game", "ai", "navmesh"},
    "headless": {"headless", "game.env", "game.front", "game", "ai", "navmesh"},
}


def _files() -> list[Path]:
    return sorted(p for package in PACKAGES for p in (ROOT / package).rglob("*.py"))


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def _package_of(path: Path) -> str:
    name = _module_name(path)
    return name if path.name == "__init__.py" else name.rpartition(".")[0]


def _is_type_checking(test: ast.expr) -> bool:
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING")


def _walk_running(tree: ast.AST, type_checking: bool = False):  # type: ignore[no-untyped-def]
    """Every node of ``tree`` except the bodies of ``if TYPE_CHECKING:`` blocks (those too
    with ``type_checking``)."""
    stack = [tree]
    while stack:
        node = stack.pop()
        yield node
        if not type_checking and isinstance(node, ast.If) and _is_type_checking(node.test):
            stack.extend(node.orelse)
            continue
        stack.extend(ast.iter_child_nodes(node))


@cache
def _modules() -> frozenset[str]:
    return frozenset(_module_name(p) for p in _files())


def imports(path: Path, source: str | None = None, package: str | None = None, *,
            type_checking: bool = False) -> list[str]:
    """The modules ``path`` imports at any depth (``from P import m`` names ``P.m`` when that
    is a module of ours), ``TYPE_CHECKING`` blocks excepted unless ``type_checking``
    (tests/test_layering.py counts those too)."""
    tree = ast.parse(source if source is not None else path.read_text(encoding="utf-8"))
    package = _package_of(path) if package is None else package
    found: list[str] = []
    for node in _walk_running(tree, type_checking):
        if isinstance(node, ast.Import):
            found += [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - node.level + 1]
                parent = ".".join(base + ([node.module] if node.module else []))
            else:
                parent = node.module or ""
            for alias in node.names:
                sub = f"{parent}.{alias.name}"
                found.append(sub if sub in _modules() else parent)
    return found


def _layer(module: str) -> str:
    for sub in ("game.front", "game.env"):
        if module == sub or module.startswith(sub + "."):
            return sub
    return module.split(".")[0]


@cache
def _graph(type_checking: bool = False) -> dict[str, set[str]]:
    """Our modules and the modules of ours each imports (type-only ones with ``type_checking``)."""
    ours = _modules()
    graph: dict[str, set[str]] = {}
    for path in _files():
        graph[_module_name(path)] = {m for m in imports(path, type_checking=type_checking)
                                     if m in ours}
    return graph


def layering_violations() -> list[str]:
    bad = []
    for path in _files():
        me = _module_name(path)
        layer = _layer(me)
        for module in imports(path):
            root = module.split(".")[0]
            if root == "pygame" and layer != "game.front":
                bad.append(f"{me} imports {module}")
            if root in PACKAGES and _layer(module) not in ALLOWED[layer]:
                bad.append(f"{me} imports {module}")
    return bad


def import_cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan), sorted."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    on_stack: set[str] = set()
    stack: list[str] = []
    found: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph.get(v, ())):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1 or v in graph.get(v, ()):
                found.append(sorted(component))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return sorted(found)


def test_no_layering_violation_at_any_depth() -> None:
    assert layering_violations() == []


def test_mesh_imports_nothing_of_query() -> None:
    """Build apart from query (Recast / Detour): navmesh/mesh.py reaches nothing of
    navmesh/query.py, type-only and function-level imports counted."""
    found = imports(ROOT / "navmesh" / "mesh.py", type_checking=True)
    assert [m for m in found if m == "navmesh.query" or m.startswith("navmesh.query.")] == []
    assert "navmesh.mesh" in imports(ROOT / "navmesh" / "query.py", type_checking=True)


def test_no_import_cycle_between_modules() -> None:
    """What runs has no cycle at all (imports under ``if TYPE_CHECKING:`` never run)."""
    assert import_cycles(_graph()) == []


def test_no_cycle_contains_the_config_or_its_schema() -> None:
    """Type-only imports counted: the config and its schema sit below everything that reads
    them, even the types they name."""
    bad = [c for c in import_cycles(_graph(type_checking=True))
           if {"game.config", "game.schema"} & set(c)]
    assert bad == []


def test_every_import_cycle_is_a_pair() -> None:
    """Type-only imports counted, every strongly connected component of the import graph
    has at most two modules: two modules may name each other (``game.world`` and the
    ``PlayerActions`` it inherits), no loop runs round three or more."""
    assert [c for c in import_cycles(_graph(type_checking=True)) if len(c) > 2] == []


def _places(predicate) -> list[str]:  # type: ignore[no-untyped-def]
    found = []
    for path in _files():
        tree = ast.parse(path.read_text(encoding="utf-8"))
        found += [f"{path.relative_to(ROOT)}:{node.lineno}"
                  for node in _walk_running(tree) if predicate(path, node)]
    return sorted(found)


def _reads_dense(path: Path, node: ast.AST) -> bool:
    return (path.relative_to(ROOT).parts[0] != "navmesh" and isinstance(node, ast.Attribute)
            and node.attr == "dense")


def _constructs_world(path: Path, node: ast.AST) -> bool:
    if not isinstance(node, ast.Call):
        return False
    f = node.func
    return (isinstance(f, ast.Name) and f.id == "World") or (
        isinstance(f, ast.Attribute) and f.attr == "World")


def test_graph_size_is_read_in_at_most_two_places_outside_navmesh() -> None:
    assert len(_places(_reads_dense)) <= 2, _places(_reads_dense)


def _reads_dense_threshold(path: Path, node: ast.AST) -> bool:
    return (isinstance(node, ast.Name) and node.id == "DENSE_MAX_NODES"
            and isinstance(node.ctx, ast.Load)) or (
        isinstance(node, ast.Attribute) and node.attr == "DENSE_MAX_NODES")


def test_one_predicate_decides_dense_or_searched() -> None:
    """The dense/sparse threshold is read in ``navmesh.distances.keeps_dense`` alone; the
    graph and the memory estimate ask that function."""
    places = _places(_reads_dense_threshold)
    assert len(places) == 1 and places[0].startswith("navmesh/distances.py:"), places
    tree = ast.parse((ROOT / "navmesh" / "distances.py").read_text(encoding="utf-8"))
    (keeps,) = [n for n in tree.body if isinstance(n, ast.FunctionDef) and n.name == "keeps_dense"]
    assert keeps.lineno <= int(places[0].split(":")[1]) <= (keeps.end_lineno or 0)
    for name in ("graph.py", "sizing.py"):
        calls = {n.func.id for n in ast.walk(ast.parse((ROOT / "navmesh" / name).read_text(
            encoding="utf-8"))) if isinstance(n, ast.Call) and isinstance(n.func, ast.Name)}
        assert "keeps_dense" in calls, name


def test_one_place_constructs_a_world() -> None:
    assert len(_places(_constructs_world)) == 1, _places(_constructs_world)


def _doc_table(doc: str, heading: str) -> list[str]:
    """The first column of the first Markdown table after ``heading`` in ``doc``, backticks
    stripped (the header row left out)."""
    lines = doc[doc.index(heading):].splitlines()[1:]
    start = next(i for i, line in enumerate(lines) if line.startswith("|"))
    rows = []
    for line in lines[start + 2:]:
        if not line.startswith("|"):
            break
        rows.append(line.split("|")[1].strip().strip("`"))
    return rows


def test_the_level_table_of_the_architecture_lists_every_field() -> None:
    from dataclasses import fields

    from navmesh.level_format import Level

    doc = (ROOT / "docs" / "architecture.md").read_text(encoding="utf-8")
    table = _doc_table(doc, "### `navmesh.level.Level`")
    assert table == [f.name for f in fields(Level)]


def test_every_sub_package_opens_with_a_one_line_docstring() -> None:
    bad = []
    for init in sorted(p for package in PACKAGES for p in (ROOT / package).rglob("__init__.py")):
        doc = ast.get_docstring(ast.parse(init.read_text(encoding="utf-8")))
        if not doc or not doc.splitlines()[0].strip():
            bad.append(str(init.relative_to(ROOT)))
    assert bad == []


# the checkers themselves

@pytest.mark.parametrize("source, expected", [
    ("from .errors import X", ["game.errors"]),
    ("def f():\n    from game.front import render", ["game.front.render"]),
    ("import pygame", ["pygame"]),
    ("from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    import headless\n", ["typing"]),
    ("class A:\n    def m(self):\n        if x:\n            import headless.cli\n",
     ["headless.cli"]),
])
def test_the_checker_sees_relative_lazy_and_nested_imports(source: str,
                                                            expected: list[str]) -> None:
    assert imports(ROOT / "game" / "probe.py", source) == expected


def test_the_table_reader_reads_the_first_column() -> None:
    doc = "## T\n\ntext\n\n| field | type |\n|---|---|\n| `a` | int |\n| `b` | str |\n\nafter\n"
    assert _doc_table(doc, "## T") == ["a", "b"]


def test_the_cycle_finder_finds_a_lazy_cycle() -> None:
    graph = {"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}
    assert import_cycles(graph) == [["a", "b", "c"]]
    assert import_cycles({"a": {"b"}, "b": set()}) == []
    # two pairs that share a module are one component of three: not "a pair"
    assert import_cycles({"w": {"x", "y"}, "x": {"w"}, "y": {"w"}}) == [["w", "x", "y"]]


def test_the_type_only_graph_sees_the_type_checking_imports(tmp_path: Path) -> None:
    probe = tmp_path / "probe.py"
    probe.write_text("from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n"
                     "    from game.world import World\n", encoding="utf-8")
    assert "game.world" in imports(probe, package="game", type_checking=True)
    assert "game.world" not in imports(probe, package="game")
