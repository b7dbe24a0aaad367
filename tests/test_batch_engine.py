"""The batch engine (game.batch) equals the pymunk engine trial for trial, whatever its batch.

Small scale here; ``python -m headless.engines`` compares whole sweeps (docs/results.md) and
``benchmarks/batch.py`` the batch of 256.
"""

from __future__ import annotations

import concurrent.futures as cf
import dataclasses
from typing import Any

import numpy as np
import pytest

from ai import register_player_policy, unregister_player_policy
from ai.players import MaxMinPlayer
from ai.view import Action, WorldView
from game.batch import MAX_BATCH, Batch, run_trials, uncovered
from game.config import Config
from game.trial import TrialSpec, run_trial
from headless.presets import load_preset


def _paper(level: str, abstraction: str, seeds: int = 1) -> list[TrialSpec]:
    return [s for s in load_preset("paper").with_seeds(seeds).specs()
            if s.level == level and s.abstraction == abstraction]


def _result(row: dict[str, Any]) -> tuple[Any, ...]:
    return row["key"], row["metrics"], row["visits"], row["attacks"], row["config_hash"]


@pytest.mark.parametrize("level, abstraction", [("arkham", "grid"), ("miami", "partition")])
def test_every_paper_trial_of_a_level_equals_the_reference(level: str, abstraction: str) -> None:
    # all five guard modes x both players x both scenarios of seed 0: 20 trials in one batch
    specs = _paper(level, abstraction)
    assert len(specs) == 20
    batch = [_result(r) for r in run_trials(specs)]
    reference = [_result(run_trial(s)) for s in specs]
    assert batch == reference


def test_a_trial_does_not_depend_on_its_batch_or_the_order() -> None:
    specs = _paper("maze", "grid")[:7]
    alone = _result(run_trials(specs[3:4])[0])
    in_seven = [_result(r) for r in run_trials(specs)]
    reversed_ = [_result(r) for r in run_trials(specs[::-1])][::-1]
    assert in_seven[3] == alone
    assert reversed_ == in_seven


def test_another_process_gives_the_same_rows() -> None:
    specs = _paper("dishonored", "grid")[:3]
    here = [_result(r) for r in run_trials(specs)]
    with cf.ProcessPoolExecutor(1) as pool:
        there = [_result(r) for r in pool.submit(run_trials, specs).result()]
    assert there == here


def test_a_batch_ends_each_trial_at_its_own_time() -> None:
    # capture trials end at the capture; the batch goes on with the others
    specs = [s for s in _paper("maze", "grid", seeds=2) if s.scenario == "capture"]
    batch = Batch(specs)
    steps = 0
    while batch.live.any():
        batch.step()
        steps += 1
    ends = {w.step_index for w in batch.worlds}
    assert max(ends) == steps and len(ends) > 1


def test_each_trial_keeps_its_own_clock_when_some_are_held() -> None:
    # a vector env holds the trials whose move has ended while the others step on: a trial
    # held for a while then stepped again ends as it does stepped without a break
    specs = _paper("miami", "grid")[:6]
    batch = Batch(specs)
    rate = np.arange(len(specs)) % 3 + 1  # trial b steps once every rate[b] calls
    calls = apart = 0
    while batch.live.any():
        batch.step(calls % rate == 0)
        calls += 1
        apart = max(apart, int(np.ptp(batch.clock)))
    assert apart > 300  # the clocks ran far apart on the way
    held = [_result(r) for r in batch.run()]
    assert held == [_result(run_trial(s)) for s in specs]


class _SprintingMaxMin(MaxMinPlayer):
    """MaxMin that sprints at every other decision and walks at the rest: a policy with
    actions of its own, which the batch engine hands the whole world to."""

    policy = "sprinting-maxmin"

    def decide(self, view: WorldView) -> int:
        self.calls = getattr(self, "calls", 0) + 1
        return super().decide(view)

    def actions(self, view: WorldView) -> list[Action]:
        return [Action("sprint" if self.calls % 2 else "walk")]


def test_a_player_with_actions_of_its_own_plays_as_on_the_reference() -> None:
    register_player_policy("sprinting-maxmin", _SprintingMaxMin)
    try:
        plain = [s for s in _paper("maze", "grid") if s.player == "maxmin"][:4]
        specs = [dataclasses.replace(s, player="sprinting-maxmin") for s in plain]
        batch = Batch(specs)
        assert batch.acting.all()
        rows = [_result(r) for r in batch.run()]
        assert rows == [_result(run_trial(s)) for s in specs]
        # the sprints changed the trials (the actions were played, not dropped)
        assert [r[1] for r in rows] != [_result(run_trial(s))[1] for s in plain]
    finally:
        unregister_player_policy("sprinting-maxmin")


def test_trials_of_different_levels_or_settings_are_not_one_batch() -> None:
    a, b = _paper("maze", "grid")[0], _paper("arkham", "grid")[0]
    with pytest.raises(ValueError, match="share level"):
        Batch([a, b])
    with pytest.raises(ValueError, match="at least one"):
        Batch([])
    assert MAX_BATCH == 256


def test_what_it_does_not_cover_is_named() -> None:
    spec = TrialSpec("maze")
    assert uncovered(spec, Config.load()) is None
    assert "awareness" in str(uncovered(spec, Config.load({"awareness.enabled": True})))
    assert "raining" in str(uncovered(spec, Config.load({"stimuli.raining": True})))
    plugin = TrialSpec("maze", stimuli=("examples/siren.py:Siren",))
    assert "plugin stimuli" in str(uncovered(plugin, Config.load()))
    with pytest.raises(ValueError, match='does not cover the team switch'):
        Batch([TrialSpec("maze", overrides=(("alert.enabled", True),))])


def test_a_body_driven_into_a_wall_moves_as_pymunk_moves_it() -> None:
    # the kernels hand a trial with a body at a wall to its own pymunk space (its solver)
    from collections import deque

    from game.trial import make_world

    spec = _paper("maze", "grid")[0]
    reference, batch = make_world(spec, Config.load(spec.settings)), Batch([spec])
    guard = reference.guards[0]
    x, y = guard.pos
    level = reference.level
    # walk straight at the nearest wall, through it, at an angle
    (ax, ay), (bx, by) = min(level.walls, key=lambda w: min(
        (w[0][0] - x) ** 2 + (w[0][1] - y) ** 2, (w[1][0] - x) ** 2 + (w[1][1] - y) ** 2))
    target = (ax + 0.3 * (bx - ax) + 3.0 * (ax - x), ay + 0.3 * (by - ay) + 3.0 * (ay - y))
    for world in (reference, batch.worlds[0]):
        world.guards[0].waypoints = deque([target])
        world.guards[0].target = world.guards[0].node
    batch.push(0)
    contacts = 0
    for _ in range(60):
        reference.step()
        batch.step()
        batch.pull(0)
        assert batch.worlds[0].guards[0].pos == reference.guards[0].pos
        contacts += int(batch.touch[0])
    assert contacts > 0
