"""Traces (SPEC §9): one JSON line per AI tick, written by the world, read by the replay.

A trace line holds ``t``, ``player {pos, hp, node}``, ``guards [{pos, heading,
sees_player, node, target, state, active}]``, ``events`` and, when stimuli are active,
``stimuli [{name, node, ...}]``. The first line also names the trial's level (``level``:
a bundled name or the file's absolute path, ``level_digest``: the SHA-256 of its file) and
``abstraction``, so a replay on another level is refused; the last line is the final state
(marked ``"final": true`` when the trial ended between two AI ticks; a played session's
final line also names its ``"outcome"`` and may repeat the last tick's moment, which the
reader then takes as that moment's line). :func:`trace_record` builds a line from a
:class:`~game.world.World`, :func:`attach_trace` writes one per AI tick to a file, and
:func:`load_trace` reads and validates a file (every problem is a one-line
:class:`TraceError`).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import IO, TYPE_CHECKING, Any

from ai.plugin_call import call
from ai.stimuli import STIMULUS_TYPES
from navmesh.files import FileRefused, read_regular
from navmesh.level import LEVELS_DIR, MISSIONS_DIR, Level

if TYPE_CHECKING:
    from .world import World


MAX_TRACE_BYTES = 256 * 2**20
"""Largest trace file read (256 MiB; a 60-s trial's trace is tens of kB)."""


def _round(value: float | None) -> float | None:
    return None if value is None else round(value, 6)


def trace_record(world: World) -> dict[str, Any]:
    """One trace line (SPEC §9): time, agents, who sees the player, HP, events; with the
    mechanics beyond the paper on (game.team) also ``phase`` and per guard ``awareness``
    and ``role``."""
    top, per_guard = world.team.trace_fields(world)
    return {
        "t": _round(world.t),
        "player": {
            "pos": [round(v, 4) for v in world.player.pos],
            "hp": round(world.hp, 4),
            "node": world.player.node,
        },
        "guards": [
            {
                "pos": [round(v, 4) for v in g.pos],
                "heading": round(g.heading, 4),
                "sees_player": i in world.seen_by,
                "node": g.node,
                "target": g.target,
                "state": world.guard_ai.state_name(i),
                "active": g.active,
                **per_guard[i],
            }
            for i, g in enumerate(world.guards)
        ],
        "events": [
            {"kind": e.kind, "node": e.node, "t": _round(e.t), **dict(e.data)}
            for e in world.tick_events
        ],
        **({"stimuli": [call(s, s.describe) for s in world.stimuli.active]}
           if world.stimuli else {}),
        **top,
    }


def level_ref(level: Level) -> str:
    """How a trace names its level: a bundled level by its name, a file by its absolute path."""
    if level.path is None:
        return level.name
    path = level.path.resolve()
    if path.parent in (LEVELS_DIR.resolve(), MISSIONS_DIR.resolve()):
        return path.stem
    return str(path)


class TraceWriter:
    """Writes a trial's trace: its first line names the level (``level``, ``level_digest``,
    ``abstraction``), then one line per AI tick, and :meth:`finish` adds the final state
    (the trial can end between AI ticks, e.g. at a capture at 57.8 s)."""

    def __init__(self, world: World, handle: IO[str], *, explain: bool = False) -> None:
        self.handle, self.explain = handle, explain
        self.last_t: float | None = None
        header = {"level": level_ref(world.level), "level_digest": world.level.digest,
                  "abstraction": world.abstraction}
        self.write(world, header)
        world.on_tick = self.write

    def write(self, world: World, extra: dict[str, Any] | None = None) -> None:
        """Write ``world``'s line now."""
        record = {**(extra or {}), **trace_record(world)}
        if self.explain:
            record["explain"] = world.guard_ai.explain(0)
        self.handle.write(json.dumps(record) + "\n")
        self.last_t = record["t"]

    def finish(self, world: World, outcome: str = "") -> None:
        """Write the final state, unless the last AI tick already wrote this moment;
        ``outcome`` (a played session's: ``"caught"``, ``"won"``, ...) goes on it, in a line
        of its own when the tick wrote the moment."""
        if self.last_t is None or _round(world.t) != self.last_t or outcome:
            self.write(world, {"final": True, **({"outcome": outcome} if outcome else {})})


def attach_trace(world: World, handle: IO[str], *, explain: bool = False) -> TraceWriter:
    """Write ``world``'s line now (t = 0) and after every AI tick to ``handle``; call the
    result's :meth:`~TraceWriter.finish` when the trial has ended.

    With ``explain`` each line also carries the first guard's last decision explained.
    """
    return TraceWriter(world, handle, explain=explain)


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
    #: awareness as a fraction of the detection threshold (graded perception), else None
    awareness: float | None = None
    #: coordinated role (``chaser``, ``interceptor``, ``holder``; "" none)
    role: str = ""


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
    #: the team's alert phase, if traced ("" otherwise)
    phase: str = ""
    #: how a played session ended (``"caught"``, ``"won"``, ...), on its final line only
    outcome: str = ""


@dataclass(frozen=True)
class Trace:
    """A parsed trace and what its lines say about the trial (level, abstraction)."""

    path: str
    lines: tuple[TraceLine, ...]
    level: str | None = None
    abstraction: str | None = None
    #: SHA-256 of the level file the trace was recorded on (``Level.digest``), if it says
    level_digest: str | None = None


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


def _drawn(name: Any) -> bool:
    """Whether a traced stimulus that sits on a node is drawn there: its class's
    :attr:`~ai.stimuli.Stimulus.marker` when a class of that name is known
    (:data:`~ai.stimuli.STIMULUS_TYPES`: the built-ins, the plugins loaded); one this
    process does not know (a plugin not loaded) is drawn, as it may be a marker."""
    declared = STIMULUS_TYPES.get(name) if isinstance(name, str) else None
    return True if declared is None else bool(declared.marker)


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
            awareness=None if g.get("awareness") is None
            else _number(g["awareness"], f"{at}.awareness"),
            role=str(g.get("role") or ""),
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
        and st["node"] >= 0 and _drawn(st.get("name"))
    ) if isinstance(record.get("stimuli", []), list) else ()
    return TraceLine(
        markers=markers,
        t=_number(_need(record, "t", where), f"{where}: t"),
        player_pos=_point(_need(player, "pos", f"{where}: player"), f"{where}: player.pos"),
        hp=_number(_need(player, "hp", f"{where}: player"), f"{where}: player.hp"),
        player_node=_node(player.get("node"), f"{where}: player.node"),
        guards=tuple(guards),
        events=events,
        phase=str(record.get("phase") or ""),
        outcome=str(record["outcome"])[:20] if isinstance(record.get("outcome"), str) else "",
    )


def load_trace(path: str | Path) -> Trace:
    """Read and validate a trace file; every problem is a one-line :class:`TraceError`."""
    name = str(path)
    try:
        text = read_regular(path, MAX_TRACE_BYTES).decode("utf-8")
    except FileRefused as refused:
        raise TraceError(f"{name}: {refused}") from None
    except FileNotFoundError:
        raise TraceError(f"{name}: no such file") from None
    except IsADirectoryError:
        raise TraceError(f"{name}: is a directory, not a trace file") from None
    except UnicodeDecodeError:
        raise TraceError(f"{name}: not a text file (expected JSON lines)") from None
    except OSError as error:
        raise TraceError(f"{name}: cannot read ({error.strerror or error})") from None
    lines: list[TraceLine] = []
    level = abstraction = digest = None
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
        if isinstance(record.get("level_digest"), str):
            digest = record["level_digest"]
        if lines:
            if len(line.guards) != len(lines[0].guards):
                raise TraceError(f"{where}: guards: {len(line.guards)} guards, but the first "
                                 f"line has {len(lines[0].guards)}")
            if line.t == lines[-1].t and record.get("final") is True:
                lines[-1] = line  # the tick's moment again, as the end (a session's outcome)
                continue
            if line.t <= lines[-1].t:
                raise TraceError(f"{where}: t: {line.t:g} does not increase (previous {lines[-1].t:g})")
        lines.append(line)
    if not lines:
        raise TraceError(f"{name}: empty trace (no JSON lines)")
    return Trace(name, tuple(lines), level, abstraction, digest)


__all__ = ["GuardRecord", "Trace", "TraceError", "TraceLine", "TraceWriter", "attach_trace",
           "level_ref", "load_trace", "parse_line", "trace_record"]
