"""Observations of the environments' agents: fixed-shape float32 arrays (docs/api.md).

A window of ``(2r+1)²`` cells around the agent (channels :data:`PLAYER_CHANNELS` or
:data:`GUARD_CHANNELS`) followed by the agent's own features and what it knows of the
others; every entry lies in ``[-OBS_BOUND, OBS_BOUND]``. The player's guards are given
relative to it in view-range units, nearest first, and each of its actions with how far its
target lies from the guards it perceives and how much farther than where it stands
(:data:`PLAYER_GUARD`, :data:`MOVE_FEATURES`): what a policy needs to step away from a guard
without learning the level's geometry first.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np
import shapely
from shapely.geometry import LineString

from ai.pf import PotentialFieldGuards
from ai.view import WorldView
from navmesh.graph import NodeGraph
from navmesh.level import Level

if TYPE_CHECKING:
    from ..world import World

__all__ = ["GUARD_CHANNELS", "GUARD_FEATURES", "MOVE_FEATURES", "OBS_BOUND", "OTHER_GUARD",
           "Observer", "PLAYER_AS_SEEN", "PLAYER_CHANNELS", "PLAYER_FEATURES", "PLAYER_GUARD",
           "STATE_FEATURES", "STATE_GUARD", "active_guards"]

#: Every observation entry lies in [-OBS_BOUND, OBS_BOUND] (most in [-1, 1]).
OBS_BOUND = 10.0
#: Names of the window channels of a player's / a guard's observation.
PLAYER_CHANNELS = ("walkable", "player", "guards")
GUARD_CHANNELS = ("walkable", "player", "guards", "information", "confidence")
PLAYER_FEATURES = ("x", "y", "cos_heading", "sin_heading", "hp", "time", "detected")
GUARD_FEATURES = ("x", "y", "cos_heading", "sin_heading", "player_hp", "time", "sees_player")
OTHER_GUARD = ("known", "dx", "dy", "cos_heading", "sin_heading")
#: The player's slot per guard, nearest perceived guard first (offsets ÷ view range).
PLAYER_GUARD = ("known", "dx", "dy", "distance", "cos_heading", "sin_heading", "facing")
#: The player's features per action: it moves (not stay / into a wall); the path
#: distance from its target to the nearest perceived guard ÷ (2 × view range), at most 1;
#: and how much farther from that guard its target lies than the player's own node does,
#: in moves (÷ the graph's mean edge length), within ±1 (0 with no guard perceived).
#: ``gain`` repeats what ``safety`` says in units a policy reads without large weights:
#: one move is ±1 there, ±0.08 in ``safety`` (issue 41, docs/api.md).
MOVE_FEATURES = ("open", "safety", "gain")
PLAYER_AS_SEEN = ("known", "dx", "dy")
#: The global state (``parallel_env``'s ``state()``, for a centralised critic): the true
#: positions of everyone, whatever anyone perceives; positions ÷ the level's width / height.
STATE_FEATURES = ("time", "player_x", "player_y", "player_cos_heading", "player_sin_heading",
                  "player_hp", "detected")
#: The global state's slot per guard, in guard order.
STATE_GUARD = ("active", "x", "y", "cos_heading", "sin_heading", "sees_player")


def active_guards(view: WorldView) -> np.ndarray:
    """Which guards are in play (all of them when the view does not say)."""
    if view.guard_active is None:
        return np.ones(len(view.guard_nodes), dtype=bool)
    return view.guard_active


class Observer:
    """Encodes what the player or a guard perceives of one level as a flat array."""

    def __init__(self, level: Level, graph: NodeGraph, radius: int, view_range: float,
                 duration: float, hp_max: float, n_guards: int, moves: np.ndarray) -> None:
        if radius < 0:
            raise ValueError("obs_radius must be >= 0")
        self.level, self.radius, self.view_range = level, int(radius), view_range
        self.graph, self.moves = graph, moves
        self.duration, self.hp_max, self.n_guards = duration, hp_max, n_guards
        rows, cols = level.rows, level.cols
        cs = level.cell_size
        self.cell_size = cs
        #: the length the player's guard offsets and move safety are measured in: the view
        #: range, or one cell when the guards are blind (view range 0, docs/api.md)
        self.range_unit = view_range if view_range > 0 else cs
        self.width, self.height = cols * cs, rows * cs
        self.diagonal = math.hypot(self.width, self.height)
        r = self.radius
        self.occupancy = np.pad(level.occupancy.astype(np.float32), r)
        if graph.cell_node is not None:
            cell_node = np.asarray(graph.cell_node)
        else:
            cell_node = np.full((rows, cols), -1, dtype=np.int64)
            for row, col in zip(*np.nonzero(level.occupancy), strict=True):
                cell_node[row, col] = graph.node_at((col + 0.5) * cs, (row + 0.5) * cs)
        self.cell_node = np.pad(cell_node, r, constant_values=-1)
        self.walkable = level.walkable
        shapely.prepare(self.walkable)
        #: the length one move covers, what ``gain`` counts in
        self.edge = float(graph.mean_edge_length) or cs

    def _cell(self, pos: Any) -> tuple[int, int]:
        return (min(max(int(pos[1] // self.cell_size), 0), self.level.rows - 1),
                min(max(int(pos[0] // self.cell_size), 0), self.level.cols - 1))

    def _window(self, centre: Any, channels: int) -> tuple[np.ndarray, int, int]:
        r = self.radius
        row, col = self._cell(centre)
        win = np.zeros((channels, 2 * r + 1, 2 * r + 1), dtype=np.float32)
        win[0] = self.occupancy[row:row + 2 * r + 1, col:col + 2 * r + 1]
        return win, row, col

    def _mark(self, win: np.ndarray, channel: int, row: int, col: int, pos: Any) -> None:
        r = self.radius
        pr, pc = self._cell(pos)
        if abs(pr - row) <= r and abs(pc - col) <= r:
            win[channel, pr - row + r, pc - col + r] += 1.0

    def player_sees(self, view: WorldView, j: int) -> bool:
        """The player perceives guard ``j`` within view range with a clear line (no cone)."""
        a, b = view.player_pos, view.guard_positions[j]
        if not active_guards(view)[j] or math.dist(a, b) > self.view_range:
            return False
        return math.dist(a, b) < 1e-9 or bool(self.walkable.covers(LineString([a, b])))

    def _self_features(self, world: World, pos: Any, heading: float, view: WorldView) -> list[float]:
        return [pos[0] / self.width, pos[1] / self.height, math.cos(heading), math.sin(heading),
                world.hp / self.hp_max, min(1.0, view.t / self.duration)]

    def _guard_features(self, view: WorldView, origin: Any, known: list[bool]) -> list[float]:
        out: list[float] = []
        for j in range(self.n_guards):
            if known[j]:
                d = (view.guard_positions[j] - origin) / self.diagonal
                h = view.guard_headings[j]
                out += [1.0, d[0], d[1], math.cos(h), math.sin(h)]
            else:
                out += [0.0] * len(OTHER_GUARD)
        return out

    def perceived(self, view: WorldView) -> list[int]:
        """The guards the player perceives (:meth:`player_sees` of each), one shapely call
        for every line of sight."""
        a = view.player_pos
        active = active_guards(view)
        candidates, lines = [], []
        for j, b in enumerate(view.guard_positions):
            if not active[j]:
                continue
            d = math.dist(a, b)
            if d > self.view_range:
                continue
            candidates.append(j)
            lines.append(None if d < 1e-9 else (a, b))
        if not candidates:
            return []
        need = [k for k, line in enumerate(lines) if line is not None]
        if need:
            clear = shapely.covers(self.walkable, shapely.linestrings(
                np.array([lines[k] for k in need], dtype=np.float64)))
            for k, ok in zip(need, clear.tolist(), strict=True):
                if not ok:
                    candidates[k] = -1
        return [j for j in candidates if j >= 0]

    def observe_player(self, world: World, view: WorldView) -> np.ndarray:
        """The player's observation (layout: docs/api.md, "Observations")."""
        pos = view.player_pos
        win, row, col = self._window(pos, len(PLAYER_CHANNELS))
        self._mark(win, 1, row, col, pos)
        known = self.perceived(view)
        for j in known:
            self._mark(win, 2, row, col, view.guard_positions[j])
        heading = world.player.heading
        vec = self._self_features(world, pos, heading, view) + [float(bool(view.seen_by))]
        scale = self.range_unit
        slots = []
        for j in known:
            d = view.guard_positions[j] - pos
            dist = math.hypot(d[0], d[1])
            h = float(view.guard_headings[j])
            # facing: cos of the angle between the guard's heading and its line to the player
            facing = 1.0 if dist < 1e-9 else -(d[0] * math.cos(h) + d[1] * math.sin(h)) / dist
            slots.append((dist, [1.0, d[0] / scale, d[1] / scale, dist / scale,
                                 math.cos(h), math.sin(h), facing]))
        slots.sort(key=lambda slot: slot[0])
        for _, slot in slots:
            vec += slot
        vec += [0.0] * (len(PLAYER_GUARD) * (self.n_guards - len(slots)))
        node = int(view.player_node)
        targets = self.moves[node]
        cap = 2.0 * scale
        if known:
            near = np.minimum(self.graph.nearest_dist(view.guard_nodes[known], limit=cap)[targets], cap)
            safety = (near / cap).tolist()
            gain = np.clip((near - near[0]) / self.edge, -1.0, 1.0).tolist()
        else:
            safety = [1.0] * len(targets)
            gain = [0.0] * len(targets)
        for a, target in enumerate(targets.tolist()):
            vec += [float(a == 0 or target != node), safety[a], gain[a]]
        return self._pack(win, vec)

    def observe_guard(self, world: World, view: WorldView, i: int,
                      guards: PotentialFieldGuards | None) -> np.ndarray:
        """Guard ``i``'s observation: what the team knows plus the team's fields."""
        pos = view.guard_positions[i]
        win, row, col = self._window(pos, len(GUARD_CHANNELS))
        team_sees = bool(view.seen_by)
        if team_sees:
            self._mark(win, 1, row, col, view.player_pos)
        for j in range(self.n_guards):
            if active_guards(view)[j]:
                self._mark(win, 2, row, col, view.guard_positions[j])
        if guards is not None:
            fields = guards.fields()
            r = self.radius
            nodes = self.cell_node[row:row + 2 * r + 1, col:col + 2 * r + 1]
            inside = nodes >= 0
            info = np.asarray(fields["I"]) + np.asarray(fields["I_extra"])
            c_scale = guards.config.C0 / max(1e-9, 1.0 - guards.config.rho)
            win[3][inside] = info[nodes[inside]] / guards.config.I0
            win[4][inside] = np.asarray(fields["C"])[nodes[inside]] / c_scale
        vec = self._self_features(world, pos, float(view.guard_headings[i]), view)
        vec += [float(i in view.seen_by)]
        vec += self._guard_features(view, pos, [bool(a) for a in active_guards(view)])
        d = (view.player_pos - pos) / self.diagonal
        vec += [1.0, d[0], d[1]] if team_sees else [0.0, 0.0, 0.0]
        return self._pack(win, vec)

    def state(self, world: World, view: WorldView) -> np.ndarray:
        """The global state: :data:`STATE_FEATURES`, then :data:`STATE_GUARD` per guard."""
        pos, heading = view.player_pos, world.player.heading
        vec = [min(1.0, view.t / self.duration), pos[0] / self.width, pos[1] / self.height,
               math.cos(heading), math.sin(heading), world.hp / self.hp_max,
               float(bool(view.seen_by))]
        active = active_guards(view)
        for j in range(self.n_guards):
            g, h = view.guard_positions[j], float(view.guard_headings[j])
            vec += [float(active[j]), g[0] / self.width, g[1] / self.height,
                    math.cos(h), math.sin(h), float(j in view.seen_by)]
        return np.clip(np.asarray(vec, dtype=np.float32), -OBS_BOUND, OBS_BOUND)

    def state_size(self) -> int:
        return len(STATE_FEATURES) + len(STATE_GUARD) * self.n_guards

    @staticmethod
    def _pack(win: np.ndarray, vec: list[float]) -> np.ndarray:
        """The window then the features, as float32 clipped to ±OBS_BOUND (each feature is
        rounded to float32 first, then clipped, as one concatenated array would be)."""
        side = win.size
        out = np.empty(side + len(vec), dtype=np.float32)
        out[:side] = win.ravel()
        out[side:] = vec
        return np.clip(out, -OBS_BOUND, OBS_BOUND, out=out)

    def obs_size(self, guard: bool) -> int:
        side = (2 * self.radius + 1) ** 2
        if guard:
            return (len(GUARD_CHANNELS) * side + len(GUARD_FEATURES)
                    + len(OTHER_GUARD) * self.n_guards + len(PLAYER_AS_SEEN))
        return (len(PLAYER_CHANNELS) * side + len(PLAYER_FEATURES)
                + len(PLAYER_GUARD) * self.n_guards + len(MOVE_FEATURES) * self.moves.shape[1])
