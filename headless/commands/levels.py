"""``stealth levels``, ``validate`` and ``path``: the commands about level files themselves.

Kept apart from :mod:`headless.cli`, which registers them: the parser names the commands,
this module answers them.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Any

__all__ = ["cmd_levels", "cmd_path", "cmd_validate", "emit_json", "level_stats", "levels_table"]

EXIT_USER_ERROR = 2


def emit_json(document: Any) -> None:
    """Print ``document`` as the one JSON document of stdout."""
    json.dump(document, sys.stdout, indent=2)
    sys.stdout.write("\n")


# ---------------------------------------------------------------------- levels / validate
def _navmesh(level: Any) -> Any:
    """The level's navmesh (the partition graph's, cached per process)."""
    from navmesh.graph import graph_for

    mesh = graph_for(level, "partition").mesh
    if mesh is None:  # pragma: no cover - a partition graph always has its mesh
        raise RuntimeError(f"level {level.name}: the partition graph has no navmesh")
    return mesh


def level_stats(level: Any) -> dict[str, Any]:
    """Paper Table 1 for one level: navmesh triangles and areas, grid size and counts."""
    mesh = _navmesh(level)
    walkable = int(level.occupancy.sum())
    return {
        "name": level.name,
        "triangles": int(len(mesh.triangles)),
        "min_area": round(float(mesh.areas.min()), 4),
        "max_area": round(float(mesh.areas.max()), 4),
        "avg_area": round(float(mesh.areas.mean()), 4),
        "rows": level.rows,
        "cols": level.cols,
        "walkable": walkable,
        "blocked": int(level.occupancy.size - walkable),
    }


def cmd_levels(args: argparse.Namespace) -> int:
    from navmesh.level import bundled_level_names, load_level

    from navmesh.sizing import check_fits, check_mesh_work

    names = args.level or bundled_level_names()
    levels = [load_level(name) for name in names]
    for name, level in zip(names, levels, strict=True):
        check_fits(level, str(name))  # refuse before building what cannot fit
        check_mesh_work(level)  # or what would not end (the line sim gives on the partition)
    rows = [level_stats(level) for level in levels]
    if args.json:
        emit_json(rows)
        return 0
    for line in levels_table(rows):
        print(line)
    return 0


#: ``stealth levels``' columns: heading, left-aligned, and the cell text of a row
_COLUMNS: tuple[tuple[str, bool, Any], ...] = (
    ("level", True, lambda r: str(r["name"])),
    ("tris", False, lambda r: str(r["triangles"])),
    ("min area", False, lambda r: f"{r['min_area']:.4f}"),
    ("max area", False, lambda r: f"{r['max_area']:.4f}"),
    ("avg area", False, lambda r: f"{r['avg_area']:.4f}"),
    ("rows", False, lambda r: str(r["rows"])),
    ("cols", False, lambda r: str(r["cols"])),
    ("walkable", False, lambda r: _count(r["walkable"], r)),
    ("blocked", False, lambda r: _count(r["blocked"], r)),
)


def _count(cells: int, row: dict[str, Any]) -> str:
    return f"{cells} ({100 * cells / (row['walkable'] + row['blocked']):.0f}%)"


def levels_table(rows: list[dict[str, Any]]) -> list[str]:
    """The text table of :func:`level_stats` rows: each column as wide as its widest value
    or heading, two spaces between columns (so large areas and counts never run together).
    """
    cells = [[text(r) for _, _, text in _COLUMNS] for r in rows]
    widths = [max([len(head)] + [len(line[k]) for line in cells])
              for k, (head, _, _) in enumerate(_COLUMNS)]
    lines = []
    for line in [[head for head, _, _ in _COLUMNS], *cells]:
        parts = [value.ljust(width) if left else value.rjust(width)
                 for value, width, (_, left, _) in zip(line, widths, _COLUMNS, strict=True)]
        lines.append("  ".join(parts).rstrip())
    return lines


def cmd_validate(args: argparse.Namespace) -> int:
    from navmesh.errors import LevelError
    from navmesh.sizing import check_fits
    from navmesh.level import load_level

    from ai.stimuli import load_stimulus

    for plugin in args.stimulus:  # its zone kinds, before the levels that use them
        load_stimulus(plugin)
    failed = 0
    for name in args.level:
        try:
            level = load_level(name)
            check_fits(level, str(name))
        except LevelError as error:
            print(f"stealth: error: {error}", file=sys.stderr)
            failed += 1
        else:
            if not _body_fits(name, level):
                failed += 1
                continue
            print(f"{name}: ok ({level.name}, {level.rows}x{level.cols}, "
                  f"{int(level.occupancy.sum())} walkable cells)", file=sys.stderr)
    return EXIT_USER_ERROR if failed else 0


def _body_fits(name: str, level: Any) -> bool:
    """Warn of passages narrower than an agent (``world.agent_radius``) and of a navmesh
    past its bound (:func:`navmesh.sizing.check_mesh_work`: only the grid runs the level);
    False, after one error line, when the walkable area is disconnected for its body (the
    check every command shares: :func:`navmesh.clearance.check_body`)."""
    from game.config import Config
    from navmesh.clearance import check_body
    from navmesh.errors import LevelError
    from navmesh.sizing import check_mesh_work

    radius = float(Config.defaults()["world.agent_radius"])
    src = Path(name).name if Path(name).suffix else name
    try:
        report = check_body(level, radius, src)
    except LevelError as error:
        print(f"stealth: error: {error}", file=sys.stderr)
        return False
    for x, y in report.narrow:
        print(f"{src}: warning: passage narrower than {2 * radius:g} units near ({x:.1f}, {y:.1f})",
              file=sys.stderr)
    try:  # the partition abstraction's bound: a level only the grid runs is still valid
        check_mesh_work(level, src)
    except LevelError as error:
        print(f"{src}: warning: the partition abstraction refuses this level: {error.problem}",
              file=sys.stderr)
    return True


# ---------------------------------------------------------------------- path
def cmd_path(args: argparse.Namespace) -> int:
    from navmesh.level import load_level
    from navmesh.query import find_path

    path = find_path(_navmesh(load_level(args.level)), args.from_, args.to)
    points = [[float(x), float(y)] for x, y in path.points]
    if args.json:
        emit_json({"points": points, "length": float(path.length)})
    else:
        print(f"length {float(path.length):.4f} through {len(points)} points")
        for x, y in points:
            print(f"  {x:.4f},{y:.4f}")
    return 0
