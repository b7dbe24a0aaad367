"""The import contract of SPEC §1, checked on the source with ``ast``.

* ``navmesh`` imports nothing of ``ai``, ``game``, ``headless``;
* ``ai`` imports only ``navmesh`` (of ours);
* ``game`` core (outside ``game/front`` and ``game/env``) never imports pygame, ``headless``,
  ``game.front`` or ``game.env``, at any depth;
* ``game/front`` imports nothing of ``headless`` or ``game.env``;
* ``game/env`` (the environments, which render through the front end) imports nothing of
  ``headless`` and never pygame itself.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
OURS = ("navmesh", "ai", "game", "headless")


def _imports(path: Path, package: str | None = None) -> list[tuple[str, bool]]:
    """``(module, at_module_level)`` of every import in ``path`` (relative ones resolved
    against ``package``, by default the package the file lies in)."""
    tree = ast.parse(path.read_text(encoding="utf-8"), str(path))
    if package is None:
        package = ".".join(path.relative_to(ROOT).with_suffix("").parts[:-1])
    top_level = {id(node) for node in tree.body}
    for node in tree.body:  # imports under `if TYPE_CHECKING:` / try at module level count too
        if isinstance(node, (ast.If, ast.Try)):
            top_level |= {id(n) for n in ast.walk(node)}
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - node.level + 1]
                names = [".".join(base + ([node.module] if node.module else []))]
            else:
                names = [node.module or ""]
        else:
            continue
        found += [(name, id(node) in top_level) for name in names]
    return found


def _files(package: str) -> list[Path]:
    return sorted((ROOT / package).rglob("*.py"))


def _root(module: str) -> str:
    return module.split(".")[0]


def _violations(package: str, allowed: set[str]) -> list[str]:
    bad = []
    for path in _files(package):
        for module, _ in _imports(path):
            if _root(module) in OURS and _root(module) not in allowed:
                bad.append(f"{path.relative_to(ROOT)} imports {module}")
    return bad


def test_navmesh_imports_nothing_of_the_others() -> None:
    assert _violations("navmesh", {"navmesh"}) == []


def test_ai_imports_only_navmesh() -> None:
    assert _violations("ai", {"ai", "navmesh"}) == []


def _under(module: str, package: str) -> bool:
    return module == package or module.startswith(package + ".")


def test_game_core_never_imports_pygame_headless_the_front_end_or_the_environments() -> None:
    bad = []
    for path in _files("game"):
        rel = path.relative_to(ROOT)
        if rel.parts[1] in ("front", "env"):
            continue
        for module, _ in _imports(path):
            if _root(module) in ("pygame", "headless") or _under(module, "game.front") or (
                    _under(module, "game.env")):
                bad.append(f"{rel} imports {module}")
    assert bad == []


def test_game_front_imports_nothing_of_headless_or_the_environments() -> None:
    bad = [f"{path.relative_to(ROOT)} imports {module}"
           for path in _files("game/front") for module, _ in _imports(path)
           if _root(module) == "headless" or _under(module, "game.env")]
    assert bad == []


def test_the_environments_import_nothing_of_headless_nor_pygame() -> None:
    bad = [f"{path.relative_to(ROOT)} imports {module}"
           for path in _files("game/env") for module, _ in _imports(path)
           if _root(module) in ("headless", "pygame")]
    assert bad == []


@pytest.mark.parametrize("source, expected", [
    ("from .errors import X", ("game.errors", True)),
    ("def f():\n    from game.front import render", ("game.front", False)),
    ("import pygame", ("pygame", True)),
])
def test_the_checker_sees_relative_and_lazy_imports(tmp_path: Path, source: str,
                                                    expected: tuple[str, bool]) -> None:
    probe = tmp_path / "probe.py"
    probe.write_text(source, encoding="utf-8")
    assert expected in _imports(probe, "game")
