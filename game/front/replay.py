"""``stealth replay TRACE``: play back a trace written by ``stealth sim --trace FILE``.

A trace is JSON lines, one per AI tick (1 s apart): ``t``, ``player {pos, hp, node}``,
``guards [{pos, heading, sees_player, node, target, state, active}]``, ``events``. Between
two lines every agent is moved along the shortest walkable path between its two recorded
positions (the navmesh funnel path, so nobody walks through a wall corner), at constant
speed; a jump longer than any agent can walk in that time (a respawn) is shown as a jump.

The lines carry no level name, so ``--level`` is required unless a line has a ``level``
key. The node numbers refer to the grid or the partition graph; which one is detected from
the positions (``--abstraction`` overrides).
"""

from __future__ import annotations

import argparse
import json
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from game.front.render import DrawOptions, FrameLoop, Renderer, default_window_size, init_pygame, pygame
from game.scene import GuardDrawing, PlayerDrawing, Scene, SceneBuilder
from navmesh.graph import NodeGraph
from navmesh.level import Level

#: Faster than any agent walks (2 units/s × capture 1.2 × sprint 1.6 ≈ 3.84, plus slack):
#: a longer move between two lines is a teleport (respawn) and is not interpolated.
MAX_SPEED = 6.0
SPEEDS = (0.125, 0.25, 0.5, 1.0, 2.0, 4.0, 8.0, 16.0, 32.0)


class TraceError(ValueError):
    """A trace file that cannot be replayed; the message is one line."""


@dataclass(frozen=True)
class GuardRecord:
    """One guard in one trace line."""

    pos: tuple[float, float]
    heading: float
    sees_player: bool
    node: int | None = None
    target: int | None = None
    state: str = ""
    active: bool = True


@dataclass(frozen=True)
class TraceLine:
    """One line (one AI tick) of a trace."""

    t: float
    player_pos: tuple[float, float]
    hp: float
    player_node: int | None
    guards: tuple[GuardRecord, ...]
    events: tuple[str, ...]
    #: nodes of the active stimuli that sit somewhere (decoys, corpses, throws), if traced
    markers: tuple[int, ...] = ()


@dataclass(frozen=True)
class Trace:
    """A parsed trace and what its lines say about the trial (level, abstraction)."""

    path: str
    lines: tuple[TraceLine, ...]
    level: str | None = None
    abstraction: str | None = None


# ---------------------------------------------------------------------------- parsing


def _need(obj: dict[str, Any], key: str, where: str) -> Any:
    if key not in obj:
        raise TraceError(f"{where}: missing field {key!r}")
    return obj[key]


def _number(value: Any, where: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise TraceError(f"{where}: expected a finite number, got {json.dumps(value)[:40]}")
    return float(value)


def _point(value: Any, where: str) -> tuple[float, float]:
    if not isinstance(value, list) or len(value) != 2:
        raise TraceError(f"{where}: expected [x, y], got {json.dumps(value)[:40]}")
    return (_number(value[0], f"{where}[0]"), _number(value[1], f"{where}[1]"))


def _node(value: Any, where: str) -> int | None:
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, int) or value < 0:
        raise TraceError(f"{where}: expected a node number, got {json.dumps(value)[:40]}")
    return int(value)


def _object(value: Any, where: str) -> dict[str, Any]:
    if not isinstance(value, dict):
        raise TraceError(f"{where}: expected an object, got {json.dumps(value)[:40]}")
    return value


def parse_line(record: Any, where: str) -> TraceLine:
    """Validate one decoded trace line."""
    record = _object(record, where)
    player = _object(_need(record, "player", where), f"{where}: player")
    guards_raw = _need(record, "guards", where)
    if not isinstance(guards_raw, list) or not guards_raw:
        raise TraceError(f"{where}: guards: expected a non-empty list")
    guards = []
    for k, raw in enumerate(guards_raw):
        at = f"{where}: guards[{k}]"
        g = _object(raw, at)
        sees = _need(g, "sees_player", at)
        if not isinstance(sees, bool):
            raise TraceError(f"{at}.sees_player: expected true or false")
        active = g.get("active", True)
        if not isinstance(active, bool):
            raise TraceError(f"{at}.active: expected true or false")
        guards.append(GuardRecord(
            pos=_point(_need(g, "pos", at), f"{at}.pos"),
            heading=_number(_need(g, "heading", at), f"{at}.heading"),
            sees_player=sees,
            node=_node(g.get("node"), f"{at}.node"),
            target=_node(g.get("target"), f"{at}.target"),
            state=str(g.get("state") or ""),
            active=active,
        ))
    events_raw = record.get("events", [])
    if not isinstance(events_raw, list):
        raise TraceError(f"{where}: events: expected a list")
    events = tuple(
        str(e.get("kind", "?")) if isinstance(e, dict) else str(e) for e in events_raw
    )
    markers = tuple(
        int(st["node"]) for st in record.get("stimuli", []) or []
        if isinstance(st, dict) and isinstance(st.get("node"), int) and not isinstance(st["node"], bool)
        and st["node"] >= 0 and st.get("name") not in ("footstep", "rain")
    ) if isinstance(record.get("stimuli", []), list) else ()
    return TraceLine(
        markers=markers,
        t=_number(_need(record, "t", where), f"{where}: t"),
        player_pos=_point(_need(player, "pos", f"{where}: player"), f"{where}: player.pos"),
        hp=_number(_need(player, "hp", f"{where}: player"), f"{where}: player.hp"),
        player_node=_node(player.get("node"), f"{where}: player.node"),
        guards=tuple(guards),
        events=events,
    )


def load_trace(path: str | Path) -> Trace:
    """Read and validate a trace file; every problem is a one-line :class:`TraceError`."""
    name = str(path)
    try:
        text = Path(path).read_text(encoding="utf-8")
    except FileNotFoundError:
        raise TraceError(f"{name}: no such file") from None
    except IsADirectoryError:
        raise TraceError(f"{name}: is a directory, not a trace file") from None
    except UnicodeDecodeError:
        raise TraceError(f"{name}: not a text file (expected JSON lines)") from None
    except OSError as error:
        raise TraceError(f"{name}: cannot read ({error.strerror or error})") from None
    lines: list[TraceLine] = []
    level = abstraction = None
    for number, raw in enumerate(text.splitlines(), start=1):
        if not raw.strip():
            continue
        where = f"{name} line {number}"
        try:
            record = json.loads(raw)
        except json.JSONDecodeError as error:
            raise TraceError(f"{where}: not JSON ({error.msg} at column {error.colno})") from None
        except (ValueError, RecursionError) as error:
            raise TraceError(f"{where}: not JSON ({error})") from None
        line = parse_line(record, where)
        if isinstance(record.get("level"), str):
            level = record["level"]
        if record.get("abstraction") in ("grid", "partition"):
            abstraction = record["abstraction"]
        if lines:
            if len(line.guards) != len(lines[0].guards):
                raise TraceError(f"{where}: guards: {len(line.guards)} guards, but the first "
                                 f"line has {len(lines[0].guards)}")
            if line.t <= lines[-1].t:
                raise TraceError(f"{where}: t: {line.t:g} does not increase (previous {lines[-1].t:g})")
        lines.append(line)
    if not lines:
        raise TraceError(f"{name}: empty trace (no JSON lines)")
    return Trace(name, tuple(lines), level, abstraction)


def detect_abstraction(trace: Trace, graphs: dict[str, NodeGraph]) -> str:
    """The abstraction whose node numbers agree best with the recorded positions."""
    samples: list[tuple[tuple[float, float], int]] = []
    for line in trace.lines[:60]:
        if line.player_node is not None:
            samples.append((line.player_pos, line.player_node))
        samples += [(g.pos, g.node) for g in line.guards if g.node is not None]
    if not samples:
        return "grid"
    scores = {}
    for name, graph in graphs.items():
        scores[name] = sum(1 for (x, y), node in samples if node < graph.n and graph.node_at(x, y) == node)
    return max(scores, key=lambda k: (scores[k], k == "grid"))


def check_nodes(trace: Trace, graph: NodeGraph, abstraction: str) -> None:
    """Every node number of the trace must exist in ``graph``."""
    for number, line in enumerate(trace.lines, start=1):
        nodes = [line.player_node] + [g.node for g in line.guards] + [g.target for g in line.guards]
        nodes += list(line.markers)
        for node in nodes:
            if node is not None and node >= graph.n:
                raise TraceError(
                    f"{trace.path}: trace line {number}: node {node} does not exist in the "
                    f"{abstraction} graph ({graph.n} nodes); wrong --level or --abstraction?"
                )


# ---------------------------------------------------------------------------- playback


class _Route:
    """A polyline walked at constant speed over one interval (or a jump)."""

    def __init__(self, points: np.ndarray, jump: bool) -> None:
        self.points = points
        self.jump = jump
        seg = np.hypot(*np.diff(points, axis=0).T) if len(points) > 1 else np.zeros(0)
        self.cum = np.concatenate([[0.0], np.cumsum(seg)])
        self.length = float(self.cum[-1])

    def at(self, alpha: float) -> tuple[tuple[float, float], float | None]:
        """Position at fraction ``alpha`` of the interval and the direction of motion there."""
        if self.jump:
            p = self.points[0] if alpha < 0.5 else self.points[-1]
            return (float(p[0]), float(p[1])), None
        if self.length < 1e-9:
            p = self.points[0]
            return (float(p[0]), float(p[1])), None
        s = alpha * self.length
        k = int(np.clip(np.searchsorted(self.cum, s, side="right") - 1, 0, len(self.points) - 2))
        a, b = self.points[k], self.points[k + 1]
        span = self.cum[k + 1] - self.cum[k]
        f = 0.0 if span < 1e-12 else (s - self.cum[k]) / span
        p = a + (b - a) * f
        return (float(p[0]), float(p[1])), math.atan2(b[1] - a[1], b[0] - a[0])


def _lerp_angle(a: float, b: float, f: float) -> float:
    d = (b - a + math.pi) % (2 * math.pi) - math.pi
    return a + d * f


class Playback:
    """Agent states at any time of a trace, interpolated along walkable paths."""

    def __init__(self, trace: Trace, level: Level) -> None:
        from navmesh.graph import graph_for

        self.trace = trace
        self.lines = trace.lines
        self.times = np.array([line.t for line in self.lines])
        mesh = graph_for(level, "partition").mesh
        assert mesh is not None
        self.mesh = mesh
        self._routes: dict[tuple[int, int], _Route] = {}
        self._player_heading = 0.0

    @property
    def start(self) -> float:
        return float(self.times[0])

    @property
    def end(self) -> float:
        return float(self.times[-1])

    def index(self, t: float) -> int:
        """Index of the last line at or before ``t``."""
        return int(np.clip(np.searchsorted(self.times, t, side="right") - 1, 0, len(self.times) - 1))

    def _route(self, i: int, agent: int) -> _Route:
        """Route of ``agent`` (-1 = player) from line i to line i + 1."""
        key = (i, agent)
        route = self._routes.get(key)
        if route is None:
            a, b = self._pos(i, agent), self._pos(i + 1, agent)
            dt = self.times[i + 1] - self.times[i]
            try:
                points = np.asarray(self.mesh.find_path(a, b).points, dtype=float)
            except ValueError:  # a recorded point on the wall line: walk straight
                points = np.array([a, b], dtype=float)
            route = _Route(points, jump=False)
            if route.length > MAX_SPEED * dt + 1e-6:
                route = _Route(np.array([a, b], dtype=float), jump=True)
            self._routes[key] = route
        return route

    def _pos(self, i: int, agent: int) -> tuple[float, float]:
        line = self.lines[i]
        return line.player_pos if agent < 0 else line.guards[agent].pos

    def state(self, t: float) -> tuple[TraceLine, list[tuple[tuple[float, float], float]], tuple[float, float], float, float]:
        """At time ``t``: the current line, guard (pos, heading)s, player pos, heading and HP."""
        i = self.index(t)
        line = self.lines[i]
        if i + 1 >= len(self.lines) or t <= self.times[i]:
            guards = [(g.pos, g.heading) for g in line.guards]
            return line, guards, line.player_pos, self._player_heading, line.hp
        nxt = self.lines[i + 1]
        f = float((t - self.times[i]) / (self.times[i + 1] - self.times[i]))
        guards = []
        for k, g in enumerate(line.guards):
            pos, direction = self._route(i, k).at(f)
            heading = direction if direction is not None else _lerp_angle(g.heading, nxt.guards[k].heading, f)
            guards.append((pos, heading))
        pos, direction = self._route(i, -1).at(f)
        if direction is not None:
            self._player_heading = direction
        hp = line.hp + (nxt.hp - line.hp) * f if nxt.hp <= line.hp else line.hp
        return line, guards, pos, self._player_heading, hp


# ---------------------------------------------------------------------------- the window


class ReplayViewer(FrameLoop):
    """Window that plays a trace: pause, step, speed, mesh and target display."""

    def __init__(
        self, trace: Trace, level: Level, abstraction: str, *, scenario: str = "capture",
        speed: float = 1.0, lockstep: bool = True, show_mesh: bool = False,
        show_plans: bool = False, size: tuple[int, int] | None = None,
    ) -> None:
        from game.config import Config
        from navmesh.graph import graph_for

        init_pygame()
        config = Config.defaults()
        self.graph = graph_for(level, abstraction)
        self.view_range = float(config["world.view_range"]) * float(
            config[f"scenario.{scenario}.view_range_scale"])
        self.attack_range = float(config["world.attack_range"])
        self.radius = float(config["world.agent_radius"])
        self.hp_max = max(float(config["world.player_hp"]), max(line.hp for line in trace.lines))
        self.builder = SceneBuilder(level, self.graph, view_range=self.view_range,
                                    fov_deg=float(config["world.fov_deg"]))
        self.concealment = self._zone_mask(level, "concealment")
        # Per node, the factor on the view range while the player stands there (as World).
        self.view_scale = np.ones(self.graph.n)
        for key, value in config.section("zones").items():
            if key.endswith("_view_scale"):
                mask = self._zone_mask(level, key[: -len("_view_scale")])
                self.view_scale = np.where(mask, np.minimum(self.view_scale, float(value)), self.view_scale)
        self.playback = Playback(trace, level)
        self.abstraction = abstraction
        self.t = self.playback.start
        self.speed = float(speed)
        self.lockstep = lockstep
        self.paused = False
        self.running = True
        self.show_mesh, self.show_plans = show_mesh, show_plans
        size = size or default_window_size(self.builder.static)
        pygame.display.set_caption(f"Stealthfield replay — {Path(trace.path).name}")
        self.screen = pygame.display.set_mode(size, pygame.RESIZABLE)
        self.renderer = Renderer(self.builder.static, self.screen.get_size())
        self.clock = pygame.time.Clock()

    def _zone_mask(self, level: Level, kind: str) -> np.ndarray:
        import shapely

        mask = np.zeros(self.graph.n, dtype=bool)
        x, y = self.graph.positions[:, 0], self.graph.positions[:, 1]
        for polygon in level.zones.get(kind, ()):
            mask |= shapely.intersects_xy(polygon, x, y)
        return mask

    # ------------------------------------------------------------------ input
    HELP = ("Space pause", "Right/Left step one tick", "Up/Down speed", "Home restart",
            "M mesh/grid", "G targets", "Esc quit")

    def _step_line(self, direction: int) -> None:
        self.paused = True
        i = self.playback.index(self.t + 1e-9)
        i = int(np.clip(i + direction, 0, len(self.playback.times) - 1))
        self.t = float(self.playback.times[i])

    def _speed(self, direction: int) -> None:
        k = min(range(len(SPEEDS)), key=lambda j: abs(SPEEDS[j] - self.speed))
        self.speed = SPEEDS[int(np.clip(k + direction, 0, len(SPEEDS) - 1))]

    def handle(self, event: pygame.event.Event) -> None:
        """React to one pygame event."""
        if self.handle_window(event):
            return
        if event.type == pygame.KEYDOWN:
            key = event.key
            if key == pygame.K_ESCAPE:
                self.running = False
            elif key == pygame.K_SPACE:
                self.paused = not self.paused
            elif key in (pygame.K_RIGHT, pygame.K_PERIOD):
                self._step_line(+1)
            elif key in (pygame.K_LEFT, pygame.K_COMMA):
                self._step_line(-1)
            elif key in (pygame.K_UP, pygame.K_PLUS, pygame.K_EQUALS, pygame.K_KP_PLUS):
                self._speed(+1)
            elif key in (pygame.K_DOWN, pygame.K_MINUS, pygame.K_KP_MINUS):
                self._speed(-1)
            elif key in (pygame.K_HOME, pygame.K_BACKSPACE):
                self.t, self.paused = self.playback.start, False
            elif key == pygame.K_m:
                self.show_mesh = not self.show_mesh
            elif key == pygame.K_g:
                self.show_plans = not self.show_plans

    # ------------------------------------------------------------------ frames
    def scene(self) -> Scene:
        """The picture of the trace at the current playback time."""
        line, guards, ppos, pheading, hp = self.playback.state(self.t)
        node = self.graph.node_at(*ppos)
        concealed = bool(self.concealment[node])
        reach = self.view_range * float(self.view_scale[node])
        drawings = []
        for record, (pos, heading) in zip(line.guards, guards):
            target = None
            if self.show_plans and record.target is not None:
                tx, ty = self.graph.positions[record.target]
                target = (float(tx), float(ty))
            drawings.append(GuardDrawing(
                pos=pos, heading=heading, active=record.active, sees_player=record.sees_player,
                state=record.state if record.active else "down",
                cone=self.builder.cone(pos, heading, reach) if record.active else np.zeros((0, 2)),
                target=target,
            ))
        seen = tuple(k for k, g in enumerate(line.guards) if g.sees_player)
        return Scene(
            static=self.builder.static, t=self.t, duration=self.playback.end,
            guards=tuple(drawings),
            player=PlayerDrawing(pos=ppos, heading=pheading, hp=hp, hp_max=self.hp_max,
                                 concealed=concealed),
            seen_by=seen, status="playing", mode="replay", abstraction=self.abstraction,
            reach=reach, attack_range=self.attack_range, agent_radius=self.radius,
            events=line.events,
            markers=self.graph.positions[list(line.markers)].reshape(-1, 2),
        )

    def frame(self, elapsed: float) -> None:
        """One frame: events, playback clock, drawing, flip."""
        for event in pygame.event.get():
            self.handle(event)
        if not self.running:
            return
        if not self.paused:
            step = (1 / 60 if self.lockstep else elapsed) * self.speed
            self.t = min(self.t + step, self.playback.end)
        scene = self.scene()
        ended = self.t >= self.playback.end
        info = [f"speed ×{self.speed:g}", f"tick {self.playback.index(self.t + 1e-9) + 1}/{len(self.playback.times)}"]
        if scene.events:
            info.append("events: " + ", ".join(scene.events))
        options = DrawOptions(
            show_mesh=self.show_mesh, show_plans=self.show_plans, paused=self.paused and not ended,
            help=self.HELP, info=info, legend=False,
            banner="END OF TRACE" if ended else None, banner_sub="Home restart · Left step back · Esc quit",
        )
        self.renderer.draw(self.screen, scene, options)
        pygame.display.flip()



# ---------------------------------------------------------------------------- command line


def cmd_replay(args: argparse.Namespace) -> int:
    """``stealth replay TRACE [--level LEVEL]``: see the module docstring and docs/play.md."""
    from game.front.play import finish, lockstep_wanted, open_display
    from game.errors import FrontError as UserError
    from navmesh.graph import graph_for
    from navmesh.level import load_level

    speed = float(getattr(args, "speed", 1.0))
    if not (math.isfinite(speed) and speed > 0):
        raise UserError(f"--speed: expected a positive number, got {speed:g}")
    if args.frames is not None and args.frames < 1:
        raise UserError(f"--frames: expected a positive number of frames, got {args.frames}")
    try:
        trace = load_trace(args.trace)
    except TraceError as error:
        raise UserError(str(error)) from None
    level_name = args.level or trace.level
    if level_name is None:
        raise UserError(f"{args.trace}: the trace does not name its level; pass --level LEVEL")
    level = load_level(level_name)
    abstraction = getattr(args, "abstraction", None) or trace.abstraction
    if abstraction is None:
        graphs = {name: graph_for(level, name) for name in ("grid", "partition")}
        abstraction = detect_abstraction(trace, graphs)
    try:
        check_nodes(trace, graph_for(level, abstraction), abstraction)
        for line in trace.lines:  # positions must lie in the level
            for x, y in [line.player_pos] + [g.pos for g in line.guards]:
                if not (-1 <= x <= level.cols * level.cell_size + 1
                        and -1 <= y <= level.rows * level.cell_size + 1):
                    raise TraceError(f"{args.trace}: t={line.t:g}: position ({x:g}, {y:g}) is "
                                     f"outside level {level.name}; wrong --level?")
    except TraceError as error:
        raise UserError(str(error)) from None
    open_display()
    viewer = ReplayViewer(
        trace, level, abstraction, scenario=getattr(args, "scenario", "capture"), speed=speed,
        lockstep=lockstep_wanted(args.frames), show_mesh=bool(getattr(args, "mesh", False)),
        show_plans=bool(getattr(args, "plans", False)),
    )
    try:
        times = viewer.run(args.frames)
        finish(viewer.screen, args.screenshot, times)
    finally:
        pygame.display.quit()
    return 0


__all__: Sequence[str] = [
    "Playback", "ReplayViewer", "Trace", "TraceError", "TraceLine", "cmd_replay",
    "detect_abstraction", "load_trace",
]
