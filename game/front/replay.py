"""``stealth replay TRACE``: play back a trace written by ``stealth sim --trace FILE``.

A trace is JSON lines, one per AI tick (1 s apart), read by :mod:`game.trace`. Between
two lines every agent is moved along the shortest walkable path between its two recorded
positions (the navmesh funnel path, so nobody walks through a wall corner), at constant
speed; a jump longer than any agent can walk in that time (a respawn) is shown as a jump.

A trace written today names its level and the SHA-256 of its file in the first line, so
``--level`` is optional and a replay on another level (or an edited file) is refused; an
older trace without a ``level`` key needs ``--level``. ``stealth replay DIR --trial KEY``
re-simulates a stored trial into a temporary trace first (:func:`replay_trial`). The node numbers refer to the grid or the partition graph; which one is detected from
the positions (``--abstraction`` overrides).
"""

from __future__ import annotations

import argparse
import math
import tempfile
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from game.agents import max_agent_speed
from game.config import Config
from game.front.camera import Camera
from game.front.frame_loop import FrameLoop
from game.front.render import DrawOptions, Renderer, default_window_size, init_pygame, pygame
from game.scene import GuardDrawing, PlayerDrawing, Scene, SceneBuilder
from game.trace import GuardRecord, Trace, TraceError, TraceLine, load_trace, parse_line
from game.trial import TrialSpec
from game.zones import ZoneMap
from navmesh.graph import NodeGraph
from navmesh.level import Level
from navmesh.query import find_path

#: Slack on the fastest agent's speed (``game.agents.max_agent_speed``): a move between two
#: lines longer than this many times what that agent walks in the time is a teleport
#: (respawn) and is not interpolated.
JUMP_SLACK = 1.5
SPEEDS = (0.125, 0.25, 0.5, 1.0, 2.0, 4.0, 8.0, 16.0, 32.0)


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

    def __init__(self, trace: Trace, level: Level, max_speed: float | None = None) -> None:
        from game.config import Config
        from navmesh.graph import graph_for

        self.trace = trace
        self.lines = trace.lines
        self.times = np.array([line.t for line in self.lines])
        mesh = graph_for(level, "partition").mesh
        assert mesh is not None
        self.mesh = mesh
        self._routes: dict[tuple[int, int], _Route] = {}
        self._player_heading = 0.0
        speed = max_agent_speed(Config.defaults()) if max_speed is None else max_speed
        self.jump_speed = JUMP_SLACK * speed

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
                points = np.asarray(find_path(self.mesh, a, b).points, dtype=float)
            except ValueError:  # a recorded point on the wall line: walk straight
                points = np.array([a, b], dtype=float)
            route = _Route(points, jump=False)
            if route.length > self.jump_speed * dt + 1e-6:
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
        config: Config | None = None,
    ) -> None:
        from navmesh.graph import graph_for

        init_pygame()
        config = config if config is not None else Config.defaults()
        self.graph = graph_for(level, abstraction, float(config["world.agent_radius"]))
        self.view_range = float(config["world.view_range"]) * float(
            config[f"scenario.{scenario}.view_range_scale"])
        self.attack_range = float(config["world.attack_range"])
        self.radius = float(config["world.agent_radius"])
        self.hp_max = max(float(config["world.player_hp"]), max(line.hp for line in trace.lines))
        self.builder = SceneBuilder(level, self.graph, view_range=self.view_range,
                                    fov_deg=float(config["world.fov_deg"]))
        zones = ZoneMap.build(level, self.graph, config)  # the world's zones, as in the trial
        self.concealment = zones.mask("concealment")
        self.view_scale = zones.view_scale
        self.playback = Playback(trace, level, max_agent_speed(config))
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
        self.camera = Camera()  # the same camera and minimap as the game (large levels)
        self.renderer = Renderer(self.builder.static, self.screen.get_size(), self.camera)
        self.clock = pygame.time.Clock()
        self._player = self.playback.state(self.t)[2]
        from game.front.sound import SoundBoard

        #: the game's sounds for what the trace's lines say happened (played once per line
        #: reached moving forward; the end's sound once at the end)
        self.sound = SoundBoard()
        self._heard = self.playback.index(self.t + 1e-9)
        self._end_heard = False

    # ------------------------------------------------------------------ input
    HELP = ("Space pause", "Right/Left step one tick", "Up/Down speed", "wheel/+ - zoom",
            "Home restart", "M mesh/grid", "G targets", "Esc quit")

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
        if (factor := self.zoom_input(event)) is not None:
            self.zoom(factor)
        elif event.type == pygame.KEYDOWN:
            key = event.key
            if key == pygame.K_ESCAPE:
                self.running = False
            elif key == pygame.K_SPACE:
                self.paused = not self.paused
            elif key in (pygame.K_RIGHT, pygame.K_PERIOD):
                self._step_line(+1)
            elif key in (pygame.K_LEFT, pygame.K_COMMA):
                self._step_line(-1)
            elif key == pygame.K_UP:
                self._speed(+1)
            elif key == pygame.K_DOWN:
                self._speed(-1)
            elif key in (pygame.K_HOME, pygame.K_BACKSPACE):
                self.t, self.paused = self.playback.start, False
            elif key == pygame.K_m:
                self.show_mesh = not self.show_mesh
            elif key == pygame.K_g:
                self.show_plans = not self.show_plans

    # ------------------------------------------------------------------ frames
    def focus(self) -> tuple[float, float]:
        """The camera follows the replayed player."""
        return self._player

    def scene(self) -> Scene:
        """The picture of the trace at the current playback time."""
        line, guards, ppos, pheading, hp = self.playback.state(self.t)
        self._player = ppos
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
                target=target, awareness=record.awareness, role=record.role,
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
            phase=line.phase,
        )

    def ending(self) -> tuple[str, str]:
        """The banner at the trace's end and its kind: a played session's outcome (its final
        line says), a capture (HP 0 on the last line), else ``"END OF TRACE"``."""
        last = self.playback.lines[-1]
        titles = {"caught": "CAUGHT", "won": "ESCAPED", "survived": "SURVIVED",
                  "time up": "TIME UP"}
        if last.outcome:
            return titles.get(last.outcome, last.outcome.upper()), last.outcome
        if last.hp <= 0:
            return "CAUGHT", "caught"
        return "END OF TRACE", ""

    def _hear(self) -> None:
        """The sounds of the lines reached since the last frame (moving forward), and of
        the end: a line's events (a decoy's landing, a take-down, a switched-on decoy,
        sprint footsteps), a sighting that begins, HP lost; win or lose at the end."""
        i = self.playback.index(self.t + 1e-9)
        lines = self.playback.lines
        if i > self._heard:
            kinds = {"throw_landed": "decoy_landed", "guard_down": "takedown",
                     "decoy_activated": "decoy_on", "sprint": "step_sprint"}
            for k in range(self._heard + 1, i + 1):
                line, before = lines[k], lines[k - 1]
                for event in dict.fromkeys(line.events):
                    if event in kinds:
                        self.sound.play(kinds[event])
                seen = any(g.sees_player for g in line.guards)
                if seen and not any(g.sees_player for g in before.guards):
                    self.sound.play("sighting")
                if line.hp < before.hp - 1e-9:
                    self.sound.play("hurt")
        self._heard = i
        ended = self.t >= self.playback.end
        if ended and not self._end_heard:
            kind = self.ending()[1]
            if kind in ("caught", "won", "survived", "time up"):
                self.sound.game_over(kind)
        self._end_heard = ended

    def close(self) -> None:
        """Stop the sounds (the window closes)."""
        self.sound.close()

    def frame(self, elapsed: float) -> None:
        """One frame: events, playback clock, sounds, drawing, flip."""
        for event in pygame.event.get():
            self.handle(event)
        if not self.running:
            return
        if not self.paused:
            step = (1 / 60 if self.lockstep else elapsed) * self.speed
            self.t = min(self.t + step, self.playback.end)
        self._hear()
        scene = self.scene()
        ended = self.t >= self.playback.end
        banner, color = self.ending()
        info = [f"speed ×{self.speed:g}", f"tick {self.playback.index(self.t + 1e-9) + 1}/{len(self.playback.times)}"]
        if scene.events:
            info.append("events: " + ", ".join(scene.events))
        options = DrawOptions(
            show_mesh=self.show_mesh, show_plans=self.show_plans, paused=self.paused and not ended,
            help=self.HELP, info=info, legend=False,
            banner=banner if ended else None,
            banner_sub=f"at {self.playback.end:.1f} s · Home restart · Left step back · Esc quit",
        )
        self.follow()
        self.renderer.draw(self.screen, scene, options)
        pygame.display.flip()



# ---------------------------------------------------------------------------- command line


def cmd_replay(args: argparse.Namespace, config: Config | None = None) -> int:
    """``stealth replay TRACE [--level LEVEL]``: see the module docstring and docs/play.md.

    ``config``: the configuration the trace was made with (view range, cone, attack range,
    agent radius); the defaults when not known (a trace file alone does not carry it)."""
    from game.front.play_command import finish, lockstep_wanted, open_display
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
    if trace.level_digest is not None and level.digest != trace.level_digest:
        raise UserError(f"{args.trace}: recorded on level {trace.level or '?'} (sha256 "
                        f"{trace.level_digest[:12]}), but {level_name} is another level or an "
                        f"edited file (sha256 {(level.digest or 'none')[:12]}); replay it on "
                        "the level it was recorded on")
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
        show_plans=bool(getattr(args, "plans", False)), config=config,
    )
    try:
        times = viewer.run(args.frames)
        finish(viewer.screen, args.screenshot, times)
    finally:
        viewer.close()
        pygame.display.quit()
    return 0


def replay_trial(spec: TrialSpec, args: argparse.Namespace) -> int:
    """``stealth replay DIR --trial KEY``: re-simulate the trial ``spec`` into a temporary
    trace and play that back with the trial's own configuration (its ``[set]`` values and
    factor levels: a view-range factor draws that range), the caller looks the spec up in
    the store."""
    from game.trial import run_trial

    with tempfile.TemporaryDirectory(prefix="stealth-replay-") as folder:
        path = Path(folder) / "trial.jsonl"
        with path.open("w", encoding="utf-8") as handle:
            run_trial(spec, trace=handle)
        args.trace, args.level = str(path), spec.level
        args.abstraction, args.scenario = spec.abstraction, spec.scenario
        return cmd_replay(args, Config.load(spec.settings))


__all__: Sequence[str] = [
    "GuardRecord", "Playback", "ReplayViewer", "Trace", "TraceError", "TraceLine", "cmd_replay",
    "replay_trial",
    "detect_abstraction", "load_trace", "parse_line",
]
