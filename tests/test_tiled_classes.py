"""Issue 33: the Tiled classes are one registry (navmesh/tiled_classes.py) that the loader,
its warnings and docs/levels.md read; a zone kind a stimulus registers is a class at once."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest
from test_tiled import T, MapWriter, write

import navmesh.level_fields as level_fields
from headless.cli import main
from navmesh.errors import LevelError, LevelWarning
from navmesh.level import load_level, register_zone_kind
from navmesh.level_fields import ZONE_KINDS, zone_kinds
from navmesh.tiled_classes import BUILT_IN, markdown_table, object_classes, tiled_classes

ROOT = Path(__file__).resolve().parents[1]


def test_class_names_are_written_only_in_the_registry() -> None:
    """No other navmesh/tiled*.py module spells a class: not as a string, nor quoted or
    in backticks inside one (a message or docstring naming ``'guard'`` reads the registry)."""
    names = {c.name for c in tiled_classes(ZONE_KINDS)}
    found = []
    for path in sorted((ROOT / "navmesh").glob("tiled*.py")):
        if path.name == "tiled_classes.py":
            continue
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Constant) and isinstance(node.value, str):
                text = node.value
                spelled = [n for n in names if text.strip().lower() == n
                           or any(q + n + q in text for q in ("'", '"', "``"))]
                found += [f"{path.name}:{node.lineno}: {n}" for n in spelled]
    assert found == []


def test_docs_list_every_class() -> None:
    text = (ROOT / "docs" / "levels.md").read_text(encoding="utf-8")
    assert markdown_table(ZONE_KINDS) in text
    rows = [line for line in markdown_table(ZONE_KINDS).splitlines() if line.startswith("| `")]
    assert len(rows) == len(tiled_classes(ZONE_KINDS))


def test_the_object_classes_are_the_built_in_ones_then_the_zone_kinds(monkeypatch) -> None:
    monkeypatch.setattr(level_fields, "_zone_kinds", list(ZONE_KINDS))
    register_zone_kind("smoke")
    names = [c.name for c in object_classes(zone_kinds())]
    assert names == [c.name for c in BUILT_IN if c.name != "walls"] + [*ZONE_KINDS, "smoke"]
    assert [c.name for c in tiled_classes(zone_kinds()) if c.single] == ["player", "outline"]


def test_a_registered_zone_kind_is_a_tiled_class(tmp_path, monkeypatch, capsys) -> None:
    """What a plugin stimulus's ``zone_kinds`` does: a ``smoke`` object becomes a zone, and
    ``smoke`` is named among the known classes in ``stealth validate``'s warning."""
    monkeypatch.setattr(level_fields, "_zone_kinds", list(ZONE_KINDS))
    w = MapWriter()
    objects = [w.obj("smoke", 2 * T, 2 * T, 2 * T, T), w.point("gaurd", 16, 16),
               w.point("guard", 16, 16)]
    path = write(tmp_path, w.map(6, 6, [w.objects("o", objects)]))

    def warnings_of_validate() -> list[str]:
        assert main(["validate", str(path)]) == 0
        return [line for line in capsys.readouterr().err.splitlines() if "unknown class" in line]

    before = warnings_of_validate()
    assert len(before) == 2 and "unknown class 'smoke'" in before[0]
    assert "smoke" not in before[1].split("known classes: ")[1]
    register_zone_kind("smoke")
    after = warnings_of_validate()
    assert len(after) == 1 and "unknown class 'gaurd'" in after[0]
    assert after[0].endswith("(known classes: guard, decoy, collectible, player, obstacle, "
                             "outline, exit, dark, concealment, smoke)")
    with pytest.warns(LevelWarning, match="unknown class 'gaurd'"):
        level = load_level(path)
    (zone,) = level.zones["smoke"]
    assert zone.bounds == (2.0, 2.0, 4.0, 3.0)  # pixels / tile size: world units
    assert level.zones["dark"] == () and level.guards == ((0.5, 0.5),)
    point = [w.point("smoke", 40, 40), w.point("guard", 16, 16)]
    with pytest.raises(LevelError, match=r"\(smoke\): a point object has no area"):
        load_level(write(tmp_path, w.map(6, 6, [w.objects("o", point)])))
