"""Paired measurements of the guard mechanics beyond the paper (``stealth mechanics``).

Each against its control on the same seed (docs/mechanics.md), PF guards, scenario
``fixed``, as the paper's seven mechanics are measured in :mod:`headless.mechanics.measures`:

| mechanic | arm "on" | control | per-seed measure |
|---|---|---|---|
| perception | graded perception on; a still player in a dark cell, guards see | off (instant detection) | time to first detection (censored at 30 s) |
| alert | alert phases on; MaxMin player, guards see | off | captures in 60 s |
| radio | guard communication on; MaxMin player | off | captures in 60 s |
| radio | guard 0 taken down at 0 s, no corpse, blind guards, radio on | off | nearest guard hops to its last node, 10–30 s |
| roles | coordinated roles on; MaxMin player | off | captures in 60 s; backtracks |
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from ai import make_player_policy
from game.config import Config
from game.trial import player_params

from .worlds import BLIND, Measures, active_guard_nodes, make_world, run_until
HP = {"world.player_hp": 1.0e6}


def _run(level: str, abstraction: str, seed: int, overrides: dict[str, Any], *,
         maxmin: bool, horizon: float, placed_in: str = "",
         stop_on_detection: bool = False) -> Any:
    """One PF world of the mechanics experiment, run to ``horizon`` seconds."""
    player = (make_player_policy("maxmin", player_params(Config.load(), "fixed"))
              if maxmin else None)
    world = make_world(level, abstraction, seed, overrides, player=player,
                       tag="mechanics-maxmin" if maxmin else "mechanics")
    if placed_in:
        mask = world.zones.get(placed_in)
        if mask is None or not mask.any():
            raise ValueError(f"level {level} has no {placed_in} zone")
        options = np.flatnonzero(mask)
        world.place_player(int(options[world.stimuli.ctx.rng.integers(len(options))]),
                           forget_detection=True)

    def stop(w: Any) -> None:
        if stop_on_detection and w.seen_by:
            w.stop()

    run_until(world, horizon, stop)
    return world


def perception(level: str, abstraction: str, seed: int) -> Measures:
    """A still player in a dark cell: time to first detection, graded vs instant."""
    times = {}
    for arm, on in (("on", True), ("control", False)):
        world = _run(level, abstraction, seed, {**HP, "awareness.enabled": on}, maxmin=False,
                     horizon=30.0, placed_in="dark", stop_on_detection=True)
        first = world.m.first_detect_time
        times[arm] = 30.0 if first is None else float(first)
    return {"perception: time to first detection in the dark, s (censored at 30)": times}


def _captures(switch: str) -> Callable[[str, str, int], Measures]:
    def measure(level: str, abstraction: str, seed: int) -> Measures:
        captures, backtracks = {}, {}
        for arm, on in (("on", True), ("control", False)):
            world = _run(level, abstraction, seed, {f"{switch}.enabled": on}, maxmin=True,
                         horizon=60.0)
            metrics = world.metrics()
            captures[arm] = float(metrics["captures"])
            backtracks[arm] = float(metrics["backtracks"])
        out = {f"{switch}: captures of a MaxMin player in 60 s": captures}
        if switch == "roles":
            out["roles: guard backtracks in 60 s"] = backtracks
        return out

    measure.__name__ = switch
    measure.__doc__ = f"MaxMin player, 60 s: captures (and backtracks) with {switch} on vs off."
    return measure


def missing(level: str, abstraction: str, seed: int) -> Measures:
    """Guard 0 taken down at t = 0, no corpse rule, blind guards: the nearest active
    guard's mean hop distance to its last node in 10–30 s, radio (missing report) vs none."""
    out = {}
    for arm, on in (("on", True), ("control", False)):
        world = make_world(level, abstraction, seed, {**BLIND, "radio.enabled": on})
        world.stimuli.disable("guard_down")
        body = world.guards[0].node
        world.down_guard(0)
        track: list[float] = []

        def watch(w: Any, track: list[float] = track, body: int = body) -> None:
            if w.step_index % w.steps_per_tick == 0 and w.t > 10.0 - 1e-9:
                track.append(float(np.min(w.graph.hops_between(active_guard_nodes(w), body))))

        run_until(world, 30.0, watch)
        out[arm] = float(np.mean(track))
    return {"radio: nearest guard hops to a missing teammate, 10-30 s": out}


def radio(level: str, abstraction: str, seed: int) -> Measures:
    """Radio: captures of a MaxMin player, and the missing-teammate report."""
    return {**_captures("radio")(level, abstraction, seed), **missing(level, abstraction, seed)}


AI_MECHANICS: dict[str, Callable[[str, str, int], Measures]] = {
    "perception": perception,
    "alert": _captures("alert"),
    "radio": radio,
    "roles": _captures("roles"),
}

AI_EXPECTED: dict[str, int] = {
    "perception: time to first detection in the dark, s (censored at 30)": +1,
    "alert: captures of a MaxMin player in 60 s": +1,
    "radio: captures of a MaxMin player in 60 s": +1,
    "radio: nearest guard hops to a missing teammate, 10-30 s": -1,
    "roles: captures of a MaxMin player in 60 s": +1,
    "roles: guard backtracks in 60 s": -1,
}

__all__ = ["AI_EXPECTED", "AI_MECHANICS", "perception"]
