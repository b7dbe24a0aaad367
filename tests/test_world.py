"""The simulated world: vision, attack and HP timing, respawn, metrics, walls, determinism."""

from __future__ import annotations

import json
import math
import subprocess
import sys

import numpy as np
import pytest
import shapely

from ai import make_guard_ai, make_player_policy
from ai.view import GuardAI, PlayerPolicy, WorldView
from game.config import Config
from game.world import World
from navmesh.graph import NodeGraph
from navmesh.level import bundled_level_names, load_level, parse_level

DT = 0.05


def corridor_level(length: int = 10, **extra: object):
    """A one-cell corridor of ``length`` walkable cells (columns 1..length) in a wall ring."""
    grid = ["#" * (length + 2), "#" + "." * length + "#", "#" * (length + 2)]
    data = {"format": "stealth-level/1", "name": "corridor", "grid": grid,
            "guards": [[1.5, 1.5]], **extra}
    return parse_level(data, "corridor.json")


def room_level():
    """An open 9×9 room with a 1×5 wall piece in the middle (cells (4, 2..6))."""
    grid = ["#" * 11] + ["#" + "." * 9 + "#" for _ in range(9)] + ["#" * 11]
    grid[5] = "#..." + "#" * 3 + "...#"
    data = {"format": "stealth-level/1", "name": "room", "grid": grid,
            "guards": [[1.5, 1.5]],
            "zones": {"concealment": [[[8, 8], [10, 8], [10, 10], [8, 10]]]}}
    return parse_level(data, "room.json")


class StayGuards(GuardAI):
    """Guards that never move (vision tests place them by hand)."""

    mode = "stay"

    def reset(self, graph: NodeGraph, rng: np.random.Generator, n_guards: int) -> None:
        pass

    def decide(self, i: int, view: WorldView) -> int:
        return int(view.guard_nodes[i])


class StayPlayer(PlayerPolicy):
    policy = "stay"

    def reset(self, graph: NodeGraph, rng: np.random.Generator) -> None:
        pass

    def decide(self, view: WorldView) -> int:
        return view.player_node


def put_player(world: World, xy: tuple[float, float]) -> None:
    world.player.place(xy)
    world.player.node = world.graph.node_at(*xy)


def make(level, guard_ai, player, *, scenario="capture", overrides=(), seed=0, **kw) -> World:
    config = Config.load(["world.spawns=level", *overrides])
    return World(level, "grid", guard_ai, player, config=config, scenario=scenario,
                 seed=seed, **kw)


# ---------------------------------------------------------------------- vision
class TestVision:
    def setup_method(self) -> None:
        self.world = make(room_level(), StayGuards(), StayPlayer(), scenario="fixed")
        self.guard = self.world.guards[0]
        self.guard.place((1.5, 1.5))
        self.guard.heading = 0.0  # facing +x
        put_player(self.world, (1.5, 3.5))  # out of the concealment zone

    def test_in_range_in_cone_in_line_of_sight_is_seen(self) -> None:
        assert self.world.sees(self.guard, (7.5, 2.5))

    def test_outside_cone_is_not_seen(self) -> None:
        self.guard.heading = math.pi  # facing -x, the target is behind
        assert not self.world.sees(self.guard, (7.5, 2.5))
        self.guard.heading = 0.0
        # 60 degrees off the heading with a 90-degree cone
        assert not self.world.sees(self.guard, (1.5 + 2, 1.5 + 2 * math.sqrt(3)))

    def test_behind_a_wall_is_not_seen(self) -> None:
        # the wall occupies cells (5, 4..6) -> y in [5, 6), x in [4, 7)
        self.guard.place((5.5, 2.5))
        self.guard.heading = math.pi / 2  # facing +y (down)
        assert self.world.sees(self.guard, (5.5, 4.5))
        assert not self.world.sees(self.guard, (5.5, 7.5))

    def test_view_range_and_its_scaling(self) -> None:
        target = (1.5 + 7.9, 1.5)
        assert self.world.sees(self.guard, target)  # fixed: range 8.0
        capture = make(room_level(), StayGuards(), StayPlayer(), scenario="capture")
        guard = capture.guards[0]
        guard.place((1.5, 1.5))
        guard.heading = 0.0
        put_player(capture, (1.5, 3.5))
        assert capture.view_range == pytest.approx(6.4)  # capture: range x 0.8
        assert not capture.sees(guard, target)
        assert capture.sees(guard, (1.5 + 6.3, 1.5))

    def test_concealment_shortens_the_view_range(self) -> None:
        world = self.world
        guard = self.guard
        guard.place((2.5, 9.5))
        guard.heading = 0.0
        inside = (8.5, 9.5)  # 6 units away, inside the concealment zone
        put_player(world, inside)
        assert not world.sees(guard, inside)  # 6 > 8 * 0.7 = 5.6
        put_player(world, (7.5, 9.5))
        assert world.sees(guard, (7.5, 9.5))


# ---------------------------------------------------------------------- hand-worked trial
def test_cheat_guard_in_a_corridor_every_metric_by_hand() -> None:
    """One Cheat guard at column 1 walks to a player who stays at column 10.

    Capture scenario: view 8 x 0.8 = 6.4, guard speed 2. The guard at x = 1.5 + 2t comes
    within attack range 1.5 of the player at x = 10.5 at t = 3.75 and the 3 HP last exactly
    3 s: captured at 6.75 s. It sees the player (heading +x) once 10.5 - x <= 6.4, at
    t = 1.3. It covers all 10 cells and never backtracks.
    """
    world = make(corridor_level(), make_guard_ai("cheat"), StayPlayer(),
                 overrides=["world.guards=1"])
    assert world.player.pos == (10.5, 1.5)  # farthest node from the guard, out of sight
    m = world.run()
    assert m["captured"] is True and m["captures"] == 1
    assert m["capture_time"] == pytest.approx(6.75)
    assert world.t == pytest.approx(6.75)
    assert m["first_detect_time"] == pytest.approx(1.3, abs=DT + 1e-9)
    assert m["coverage"] == 1.0
    assert m["backtracks"] == 0
    # guard node column floor(1.5 + 2t) until it reaches column 10 (t = 4.5): distance in cells
    steps = np.arange(1, 136)
    expected = np.maximum(0, 10 - np.floor(1.5 + 2 * DT * steps)).mean()
    assert m["avg_guard_player_dist"] == pytest.approx(expected, abs=0.05)
    assert world.m.visits.sum() == 10  # each cell entered once
    assert world.m.attacks.sum() == pytest.approx(3.0)  # HP lost, all at the player's node
    assert world.m.attacks[world.graph.node_at(10.5, 1.5)] == pytest.approx(3.0)


def test_hp_drains_per_guard_in_range() -> None:
    """Two guards within range of the player take its 3 HP in 1.5 s (one alone: 3 s)."""
    level = corridor_level(guards=[[9.5, 1.5], [10.5, 1.5]])
    world = make(level, StayGuards(), StayPlayer(), overrides=["world.guards=2"])
    put_player(world, (10.5, 1.5))
    world._sense()
    m = world.run()
    assert m["capture_time"] == pytest.approx(1.5)


def test_fixed_time_counts_captures_and_respawns() -> None:
    """Fixed-time: a guard parked next to the start captures every 3 s for 60 s."""
    level = corridor_level(length=4, guards=[[3.5, 1.5]])
    world = make(level, StayGuards(), StayPlayer(), scenario="fixed",
                 overrides=["world.guards=1"])
    respawns = []
    world.on_tick = lambda w: respawns.extend(e for e in w.tick_events if e.kind == "respawn")
    m = world.run()
    assert world.t == pytest.approx(60.0)
    # start at column 1 (distance 2 from the guard, attack range 1.5 -> out of range)...
    assert m["captures"] == 0 or m["capture_time"] is not None
    # ...so place the player in range and count: 60 s / 3 s = 20 captures
    world = make(level, StayGuards(), StayPlayer(), scenario="fixed",
                 overrides=["world.guards=1", "world.attack_range=3.5"])
    m = world.run()
    assert m["captures"] == 20
    assert m["capture_time"] == pytest.approx(3.0)
    assert world.hp == pytest.approx(3.0)  # the 20th capture at 60 s respawned with full HP


# ---------------------------------------------------------------------- walls
def _check_agents_stay_inside(level_name: str, abstraction: str, interactive: bool,
                              mode: str, seed: int, seconds: float) -> None:
    """Every physics step: every agent centre inside the walkable area, no move crosses a wall."""
    level = load_level(level_name)
    world = World(level, abstraction, make_guard_ai(mode), make_player_policy("evade"),
                  config=Config.defaults(), scenario="fixed", seed=seed, interactive=interactive)
    steps = round(seconds / world.dt)
    agents = world.guards + [world.player]
    track = np.empty((steps + 1, len(agents), 2))
    teleported = np.zeros((steps, len(agents)), dtype=bool)
    track[0] = [a.pos for a in agents]
    for k in range(steps):
        captures = world.m.captures
        world.step()
        track[k + 1] = [a.pos for a in agents]
        teleported[k, -1] = world.m.captures > captures  # a fixed-time respawn is not a walk
    points = track.reshape(-1, 2)
    inside = shapely.contains_xy(level.walkable.buffer(1e-6), points[:, 0], points[:, 1])
    assert inside.all(), f"{level_name}/{abstraction}: agent centre outside the walkable area"
    starts = track[:-1].reshape(-1, 2)
    ends = track[1:].reshape(-1, 2)
    moves = shapely.linestrings(np.stack([starts, ends], axis=1))
    moved = (np.linalg.norm(ends - starts, axis=1) > 0) & ~teleported.reshape(-1)
    crossing = shapely.intersects(moves[moved], level.walkable.boundary)
    assert not crossing.any(), f"{level_name}/{abstraction}: an agent passed through a wall"


@pytest.mark.parametrize("abstraction", ["grid", "partition"])
@pytest.mark.parametrize("level_name", bundled_level_names())
def test_agents_never_leave_the_walkable_area(level_name: str, abstraction: str) -> None:
    """Several trials per level at the headless step (1/20 s): wandering and hunting guards."""
    _check_agents_stay_inside(level_name, abstraction, False, "random", seed=3, seconds=20.0)
    _check_agents_stay_inside(level_name, abstraction, False, "pf", seed=4, seconds=20.0)


@pytest.mark.parametrize("abstraction", ["grid", "partition"])
@pytest.mark.parametrize("level_name", bundled_level_names())
def test_agents_never_leave_the_walkable_area_at_60_hz(level_name: str, abstraction: str) -> None:
    _check_agents_stay_inside(level_name, abstraction, True, "cheat", seed=5, seconds=10.0)


# ---------------------------------------------------------------------- determinism
#: SPEC §11: every definition of the keyed metrics, reported beside the SPEC §9 ones
METRIC_DEFINITIONS = ("coverage_visited", "coverage_seen", "coverage_per_guard",
                      "backtracks_targets", "backtracks_entries", "dist_path", "dist_euclidean",
                      "coverage_area", "coverage_seen_area", "coverage_seen_per_guard")


@pytest.mark.parametrize("scenario", ["capture", "fixed"])
@pytest.mark.parametrize("abstraction", ["grid", "partition"])
def test_same_sim_twice_in_separate_processes_is_identical(abstraction: str, scenario: str) -> None:
    command = [sys.executable, "-m", "headless.cli", "sim", "miami", "--guards", "cheat",
               "--player", "evade", "--abstraction", abstraction, "--scenario", scenario,
               "--seed", "7", "--json"]
    first = subprocess.run(command, capture_output=True, text=True, check=True).stdout
    second = subprocess.run(command, capture_output=True, text=True, check=True).stdout
    assert first == second
    document = json.loads(first)
    assert set(document["metrics"]) == {"captured", "capture_time", "captures", "coverage",
                                        "avg_guard_player_dist", "first_detect_time",
                                        "backtracks", *METRIC_DEFINITIONS}


def test_seeds_differ_and_spawns_are_shared_across_modes() -> None:
    from game.trial import TrialSpec, make_world

    a = make_world(TrialSpec("maze", "grid", "cheat", "evade", "fixed", 1))
    b = make_world(TrialSpec("maze", "grid", "random", "evade", "fixed", 1))
    c = make_world(TrialSpec("maze", "grid", "cheat", "evade", "fixed", 2))
    nodes = lambda w: [g.node for g in w.guards] + [w.player.node]  # noqa: E731
    assert nodes(a) == nodes(b)  # paired comparison between guard modes
    assert nodes(a) != nodes(c)


# ---------------------------------------------------------------------- scripted actions
class SprintAndThrowPlayer(PlayerPolicy):
    """Stays put, sprints, and throws one decoy two cells to its left at its first decision."""

    policy = "scripted"

    def reset(self, graph: NodeGraph, rng: np.random.Generator) -> None:
        self.thrown = False

    def decide(self, view: WorldView) -> int:
        return view.player_node

    def actions(self, view: WorldView):
        from ai.view import Action

        if self.thrown:
            return ()
        self.thrown = True
        x, y = view.player_pos
        return (Action("sprint"), Action("throw", (float(x) - 2.0, float(y))))


def test_scripted_policies_can_act_like_the_keyboard() -> None:
    world = make(corridor_level(), StayGuards(), SprintAndThrowPlayer(), scenario="fixed",
                 overrides=["world.guards=1"])
    kinds = []
    world.on_tick = lambda w: kinds.extend(e.kind for e in w.tick_events)
    for _ in range(round(1.0 / world.dt) + 1):
        world.step()
    assert world.sprinting
    assert "throw_landed" in kinds
    landed = next(s for s in world.stimuli.active if getattr(s, "node", -1) >= 0)
    assert tuple(world.graph.node_cell[landed.node]) == (1, 8)  # two cells left of column 10


def test_unknown_action_is_a_clear_error() -> None:
    from ai.view import Action

    world = make(corridor_level(), StayGuards(), StayPlayer(), overrides=["world.guards=1"])
    with pytest.raises(ValueError, match="unknown player action 'fly'"):
        world.perform(Action("fly"))


def test_a_respawn_is_not_a_walk() -> None:
    """A sprinting player who never walks makes no footsteps, even when respawns move it.

    Corridor of 5 cells with the guard in the middle and attack range over all of it: the
    player is captured every 3 s and respawns at either end (a blind guard: a tie drawn per
    respawn).
    """
    level = corridor_level(length=5, guards=[[3.5, 1.5]])
    world = make(level, StayGuards(), StayPlayer(), scenario="fixed",
                 overrides=["world.guards=1", "world.attack_range=3.5", "world.view_range=0"])
    world.sprinting = True
    kinds, spots = [], set()
    world.on_tick = lambda w: kinds.extend(e.kind for e in w.tick_events)
    while not world.done:
        world.step()
        spots.add(world.player.node)
    assert world.m.captures == 20
    assert len(spots) == 2, "respawns used both ends (else the test proves nothing)"
    assert "sprint" not in kinds
