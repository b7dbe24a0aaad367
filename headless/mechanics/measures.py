"""Measured effects of the stealth mechanics (``stealth mechanics``; docs/mechanics.md).

The paper validated its seven mechanics by hand-guided playtests only. This experiment
measures each one against a **paired control**: the same seed (so the same guard spawns,
the same guard generator and the same player path) with the mechanic switched off, over
``--seeds`` seeds (default 30). Every figure is a mean with a 95 % percentile bootstrap CI
over seeds (2000 resamples; the difference is bootstrapped over the pairs).

PF guards on one level and abstraction (default miami, grid). Unless a mechanic is about
sight, the guards are *blind* (view range 0) and the player cannot be hurt, so a sighting
never overrides the stimulus being measured. Scenario ``fixed`` speeds (× 1.0).

| mechanic | arm "on" | control | per-seed measure |
|---|---|---|---|
| decoy | level decoy switched on at t = 0 at a node ≥ 8 hops from every guard | not switched on | a guard reaches it within 15 s; time to arrive (censored at 15 s) |
| footstep | wandering player sprints (noise) | walks; same speed (sprint_factor 1) | mean nearest guard–player path distance over 30 s |
| corpse | guard 0 taken down at t = 0, corpse rule on | taken down, no corpse | guard within 1 hop in 20 s; mean nearest hops in [0, 20] s; distance change after removal |
| dark | dark cells decay C at 0.80 | 0.95 (= ρ) | visits per dark cell ÷ visits per lit cell, 60 s |
| concealment | player still in a concealment cell (view × 0.7, decay 0.80) | same cell, no zone effect | detected within 30 s; time to first detection |
| rain | one footstep at hop distance d = 1..7 from the nearest guard, raining | same, clear | draw distance: largest d with a guard within 1 hop of the source in 8 s at every d' ≤ d |

Trials run in a process pool (``--workers``; 1 = in-process). Writes ``mechanics.md`` (the
table), ``mechanics.csv`` (one row per measure) and ``mechanics_trials.csv`` (one row per
seed and measure, both arms) — run by :mod:`headless.mechanics.run`; this module defines the mechanics.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from ai.stimuli import Corpse, Footstep, Rain, StaticDecoy, footstep_rule
from ai.view import Action, Event
from game.world import World

from .beyond import AI_EXPECTED, AI_MECHANICS
from .worlds import BLIND, Measures, WanderPlayer, active_guard_nodes, make_world, run_until

#: the names of the measured stimuli as their classes declare them: each measure's prefix
DECOY, FOOTSTEP, CORPSE, RAIN = (kind.short for kind in (StaticDecoy, Footstep, Corpse, Rain))

BOOTSTRAP = 2000


# ---------------------------------------------------------------------------- the mechanics
# Each returns {measure: {arm: value}} for one seed; arms "on", "control", optionally "baseline".


def decoy(level: str, abstraction: str, seed: int) -> Measures:
    """Static decoy: share reaching it within 15 s, time to arrive (censored at 15 s)."""
    horizon = 15.0
    out = []
    target = -1
    for on in (True, False):
        world = make_world(level, abstraction, seed, BLIND)
        if target < 0:
            far = world.graph.hops_from(active_guard_nodes(world)).min(axis=0) >= 8
            options = np.flatnonzero(far) if far.any() else np.arange(world.graph.n)
            target = int(options[world.stimuli.ctx.rng.integers(len(options))])
        if on:
            world.emit("decoy_activated", target)
        arrival: list[float] = []

        def watch(w: World, arrival: list[float] = arrival, target: int = target) -> None:
            if not arrival and target in active_guard_nodes(w):
                arrival.append(w.t)

        run_until(world, horizon, watch)
        out.append((float(bool(arrival)), arrival[0] if arrival else horizon))
    return {
        f"{DECOY}: a guard reaches it within 15 s (share)": {"on": out[0][0], "control": out[1][0]},
        f"{DECOY}: time to arrive, s (censored at 15)": {"on": out[0][1], "control": out[1][1]},
    }


def footstep(level: str, abstraction: str, seed: int) -> Measures:
    """Footstep noise: nearest guard–player path distance while the player sprints vs walks."""
    horizon = 30.0
    values = []
    for sprint in (True, False):
        world = make_world(level, abstraction, seed, {**BLIND, "world.sprint_factor": 1.0},
                           player=WanderPlayer())
        world.perform(Action("sprint" if sprint else "walk"))
        run_until(world, horizon)
        values.append(float(world.metrics()["avg_guard_player_dist"]))
    return {f"{FOOTSTEP}: mean nearest guard-player distance, units":
            {"on": values[0], "control": values[1]}}


def corpse(level: str, abstraction: str, seed: int) -> Measures:
    """Corpse: convergence in the first 20 s, dispersal after the inspection removed it."""
    horizon, window = 50.0, 10
    tracks: list[np.ndarray] = []
    removal: float | None = None
    for on in (True, False):
        world = make_world(level, abstraction, seed, BLIND)
        if not on:
            world.stimuli.disable("guard_down")
        body = world.guards[0].node
        world.down_guard(0)
        track: list[float] = []
        found = [False]

        def watch(w: World, on: bool = on, track: list[float] = track,
                  found: list[bool] = found, body: int = body) -> None:
            nonlocal removal
            if w.step_index % w.steps_per_tick:
                return
            track.append(float(np.min(w.graph.hops_between(active_guard_nodes(w), body))))
            present = any(isinstance(s, Corpse) for s in w.stimuli.active)
            if on and present:
                found[0] = True
            elif on and found[0] and not present and removal is None:
                removal = w.t

        run_until(world, horizon, watch)
        tracks.append(np.array(track))  # track[k]: nearest hops at t = k + 1 s
    near = [float(np.any(t[:20] <= 1)) for t in tracks]
    mean20 = [float(t[:20].mean()) for t in tracks]
    result = {
        f"{CORPSE}: a guard within 1 hop within 20 s (share)": {"on": near[0], "control": near[1]},
        f"{CORPSE}: mean nearest guard hops, first 20 s": {"on": mean20[0], "control": mean20[1]},
    }
    if removal is not None and removal + window <= horizon:
        k = round(removal) - 1  # index of the removal tick
        change = [float(t[k + 1: k + 1 + window].mean() - t[max(0, k - window) + 1: k + 1].mean())
                  for t in tracks]
        result[f"{CORPSE}: nearest hops, 10 s after removal minus 10 s before"] = {
            "on": change[0], "control": change[1]}
    return result


def dark(level: str, abstraction: str, seed: int) -> Measures:
    """Lighting: visits per dark cell ÷ visits per lit cell over 60 s."""
    ratios = []
    for rate in (None, 0.95):
        overrides = dict(BLIND)
        if rate is not None:
            overrides["zones.dark_confidence_decay"] = rate
        world = make_world(level, abstraction, seed, overrides)
        run_until(world, 60.0)
        mask = world.zones.get("dark", np.zeros(world.graph.n, bool))
        visits = world.m.visits.astype(float)
        lit = visits[~mask].mean() if (~mask).any() else 0.0
        ratios.append(float(visits[mask].mean() / lit) if mask.any() and lit > 0 else math.nan)
    return {"dark: visits per dark cell / per lit cell, 60 s": {"on": ratios[0], "control": ratios[1]}}


def concealment(level: str, abstraction: str, seed: int) -> Measures:
    """Concealment: a still player in a concealment cell, detected or not within 30 s."""
    horizon = 30.0
    out = []
    spot = -1
    for on in (True, False):
        overrides: dict[str, Any] = {"world.player_hp": 1.0e6}
        if not on:
            overrides.update({"zones.concealment_view_scale": 1.0,
                              "zones.concealment_confidence_decay": 0.95})
        world = make_world(level, abstraction, seed, overrides)
        if spot < 0:
            mask = world.zones.get("concealment")
            if mask is None or not mask.any():
                raise ValueError(f"level {level} has no concealment zone")
            options = np.flatnonzero(mask)
            spot = int(options[world.stimuli.ctx.rng.integers(len(options))])
        world.place_player(spot, forget_detection=True)

        seen_from: list[float] = []

        def stop_when_seen(w: World, seen_from: list[float] = seen_from) -> None:
            if w.seen_by:
                px, py = w.player.pos
                seen_from.append(min(math.hypot(w.guards[i].pos[0] - px, w.guards[i].pos[1] - py)
                                     for i in w.seen_by))
                w.stop()

        run_until(world, horizon, stop_when_seen)
        first = world.m.first_detect_time
        out.append((float(first is not None), horizon if first is None else float(first),
                    seen_from[0] if seen_from else math.nan))
    return {
        "concealment: detected within 30 s (share)": {"on": out[0][0], "control": out[1][0]},
        "concealment: time to first detection, s (censored at 30)":
            {"on": out[0][1], "control": out[1][1]},
        "concealment: distance of the guard at first detection, units":
            {"on": out[0][2], "control": out[1][2]},
    }


DRAW_DISTANCES = tuple(range(1, 9))


def _draw(level: str, abstraction: str, seed: int, d: int, sound: str) -> float:
    """One footstep ``d`` hops from the nearest guard at t = 1 s (``sound``: clear, rain or
    none): 1.0 if a guard steps onto its source within d/2 + 3 s (the walk plus 3 s)."""
    world = make_world(level, abstraction, seed, {**BLIND, "stimuli.raining": sound == "rain"})
    run_until(world, 1.0)
    nearest = world.graph.hops_from(active_guard_nodes(world)).min(axis=0)
    options = np.flatnonzero(nearest == d)
    if not len(options):
        return math.nan
    source = int(options[world.stimuli.ctx.rng.integers(len(options))])
    if sound != "none":
        world.stimuli.add(footstep_rule(Event("sprint", source, world.t), world.stimuli.ctx))
        world.stimuli.refresh()
    hit: list[bool] = []

    def watch(w: World) -> None:
        if not hit and source in active_guard_nodes(w):
            hit.append(True)

    run_until(world, 1.0 + d / 2 + 3.0, watch)
    return float(bool(hit))


def rain(level: str, abstraction: str, seed: int) -> Measures:
    """Rain: how far one footstep draws a guard onto its source, raining vs clear (vs none)."""
    arms = {"on": "rain", "control": "clear", "baseline": "none"}
    curve = {arm: [_draw(level, abstraction, seed, d, sound) for d in DRAW_DISTANCES]
             for arm, sound in arms.items()}
    result: Measures = {
        f"curve: footstep {d} hops away draws a guard": {arm: curve[arm][k] for arm in arms}
        for k, d in enumerate(DRAW_DISTANCES)
    }
    share = {arm: float(np.nanmean(values)) if not np.all(np.isnan(values)) else math.nan
             for arm, values in curve.items()}
    result[f"{RAIN}: share of footsteps 1-8 hops away that draw a guard"] = {
        "on": share["on"], "control": share["control"]}
    result[f"{FOOTSTEP}: share of single footsteps 1-8 hops away that draw a guard"] = {
        "on": share["control"], "control": share["baseline"]}
    return result


MECHANICS: dict[str, Callable[[str, str, int], Measures]] = {
    DECOY: decoy,
    FOOTSTEP: footstep,
    CORPSE: corpse,
    "dark": dark,
    "concealment": concealment,
    RAIN: rain,
    **AI_MECHANICS,  # beyond the paper: perception, alert, radio, roles (headless/mechanics_ai.py)
}

#: the direction each measure should move when the mechanic is on: +1 up, -1 down
EXPECTED: dict[str, int] = {
    f"{DECOY}: a guard reaches it within 15 s (share)": +1,
    f"{DECOY}: time to arrive, s (censored at 15)": -1,
    f"{FOOTSTEP}: mean nearest guard-player distance, units": -1,
    f"{FOOTSTEP}: share of single footsteps 1-8 hops away that draw a guard": +1,
    f"{CORPSE}: a guard within 1 hop within 20 s (share)": +1,
    f"{CORPSE}: mean nearest guard hops, first 20 s": -1,
    f"{CORPSE}: nearest hops, 10 s after removal minus 10 s before": +1,
    "dark: visits per dark cell / per lit cell, 60 s": +1,
    "concealment: detected within 30 s (share)": -1,
    "concealment: time to first detection, s (censored at 30)": +1,
    "concealment: distance of the guard at first detection, units": -1,
    f"{RAIN}: share of footsteps 1-8 hops away that draw a guard": -1,
    **AI_EXPECTED,
}

Row = tuple[str, int, str, float]  # measure, seed, arm, value


def run_job(job: tuple[str, str, str, int]) -> list[Row]:
    """One (mechanic, level, abstraction, seed): every arm. Top-level, picklable."""
    mechanic, level, abstraction, seed = job
    measures = MECHANICS[mechanic](level, abstraction, seed)
    return [(measure, seed, arm, value) for measure, arms in measures.items()
            for arm, value in arms.items()]


__all__ = ["EXPECTED", "MECHANICS", "WanderPlayer", "make_world"]
