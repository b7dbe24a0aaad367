"""The one level cache (navmesh.level.cached_level) and the graph cache keyed on content.

Editing a level file between two trials in one process must give the new level and the
new graph, even when the edit keeps the file's size and modification time.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest

from game.trial import TrialSpec, make_world, run_trial
from navmesh.graph import graph_for
from navmesh.level import cached_level, load_level

ROOM = ["######", "#....#", "#....#", "#....#", "######"]


def write_room(path: Path, grid: list[str]) -> None:
    level = {"format": "stealth-level/1", "name": "room", "grid": grid,
             "guards": [[1.5, 1.5], [4.5, 1.5], [4.5, 3.5]]}
    path.write_text(json.dumps(level))


def edit_keeping_size_and_mtime(path: Path, grid: list[str]) -> None:
    """Rewrite the file with a same-length grid and put its old mtime back."""
    before = path.stat()
    write_room(path, grid)
    os.utime(path, ns=(before.st_atime_ns, before.st_mtime_ns))
    after = path.stat()
    assert (after.st_size, after.st_mtime_ns) == (before.st_size, before.st_mtime_ns)


def test_unchanged_file_is_one_level_and_one_graph(tmp_path: Path) -> None:
    path = tmp_path / "room.json"
    write_room(path, ROOM)
    first = cached_level(path)
    assert cached_level(str(path)) is first
    assert cached_level(tmp_path / ".." / tmp_path.name / "room.json") is first  # same resolved file
    assert graph_for(first, "grid") is graph_for(load_level(path), "grid")  # keyed on content


@pytest.mark.parametrize("abstraction", ["grid", "partition"])
def test_editing_the_file_between_two_trials_gives_the_new_level_and_graph(
    tmp_path: Path, abstraction: str
) -> None:
    path = tmp_path / "room.json"
    write_room(path, ROOM)
    spec = TrialSpec(str(path), abstraction, "pf", "maxmin", "capture", seed=3,
                     overrides=(("world.duration", "2"),))
    old = make_world(spec)
    old_row = run_trial(spec)
    assert int(old.level.occupancy.sum()) == 12

    blocked = ["######", "#....#", "#..#.#", "#....#", "######"]  # one cell walled in
    edit_keeping_size_and_mtime(path, blocked)
    new = make_world(spec)
    new_row = run_trial(spec)

    assert new.level is not old.level
    assert int(new.level.occupancy.sum()) == 11
    assert new.graph is not old.graph
    assert new.graph is graph_for(new.level, abstraction)
    if abstraction == "grid":
        assert (old.graph.n, new.graph.n) == (12, 11)
        assert (len(old_row["visits"]), len(new_row["visits"])) == (12, 11)
    else:  # the new hole is in the walkable polygon and so in the mesh
        assert len(new.level.walkable.interiors) == 1 and not old.level.walkable.interiors
        assert new.graph.mesh is not None and new.graph.mesh.locate(3.5, 2.5) == -1
        assert old.graph.mesh is not None and old.graph.mesh.locate(3.5, 2.5) >= 0
    # a level loaded before the edit keeps the graph of its own content
    assert graph_for(old.level, abstraction) is old.graph
