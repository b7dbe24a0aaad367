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

from pathlib import Path

import pytest
from test_architecture import imports  # the one import walker of the suite

ROOT = Path(__file__).resolve().parents[1]
OURS = ("navmesh", "ai", "game", "headless")


def _imports(path: Path) -> list[str]:
    """Every module ``path`` imports, at any depth, imports under ``if TYPE_CHECKING:``
    included (stricter than tests/test_architecture.py: not even a type may cross)."""
    return imports(path, type_checking=True)


def _files(package: str) -> list[Path]:
    return sorted((ROOT / package).rglob("*.py"))


def _root(module: str) -> str:
    return module.split(".")[0]


def _violations(package: str, allowed: set[str]) -> list[str]:
    bad = []
    for path in _files(package):
        for module in _imports(path):
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
        for module in _imports(path):
            if _root(module) in ("pygame", "headless") or _under(module, "game.front") or (
                    _under(module, "game.env")):
                bad.append(f"{rel} imports {module}")
    assert bad == []


def test_game_front_imports_nothing_of_headless_or_the_environments() -> None:
    bad = [f"{path.relative_to(ROOT)} imports {module}"
           for path in _files("game/front") for module in _imports(path)
           if _root(module) == "headless" or _under(module, "game.env")]
    assert bad == []


def test_the_environments_import_nothing_of_headless_nor_pygame() -> None:
    bad = [f"{path.relative_to(ROOT)} imports {module}"
           for path in _files("game/env") for module in _imports(path)
           if _root(module) in ("headless", "pygame")]
    assert bad == []


@pytest.mark.parametrize("source, expected", [
    ("from .errors import X", ["game.errors"]),
    ("def f():\n    from game.front import render", ["game.front.render"]),
    ("import pygame", ["pygame"]),
    ("from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    import headless\n",
     ["typing", "headless"]),
])
def test_the_checker_sees_relative_lazy_and_type_only_imports(tmp_path: Path, source: str,
                                                               expected: list[str]) -> None:
    probe = tmp_path / "probe.py"
    probe.write_text(source, encoding="utf-8")
    assert sorted(imports(probe, package="game", type_checking=True)) == sorted(expected)
