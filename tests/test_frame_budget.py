"""The frame's extra-work budget follows the frame's own measured cost (issue 25).

FrameBudget is pure: these tests feed it made-up frame costs (a quick machine, a slow one,
a jittery one) and check what it grants to the work ahead and to striped composition;
WorkAhead is checked with a stand-in world; the queue it feeds (ai.prefetch) for its order
and its duplicates; the static layer for a stripe count that changes between layers.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field

os.environ["SDL_VIDEODRIVER"] = "dummy"
os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")

import numpy as np
import pytest

from ai.params import PFParams
from ai.field_matrices import FieldMatrices
from ai.prefetch import Prefetch
from game.front.frame_budget import FrameBudget
from game.front.work_ahead import WorkAhead
from navmesh.graph import NodeGraph


def _fed(costs: list[float], **kwargs: float) -> FrameBudget:
    budget = FrameBudget(**kwargs)  # type: ignore[arg-type]
    for cost in costs:
        budget.observe(cost)
    return budget


def test_a_slower_machine_gets_a_smaller_work_ahead() -> None:
    quick, slow = _fed([0.002] * 60), _fed([0.006] * 60)
    assert quick.spare(0.002) > slow.spare(0.006)
    assert quick.spare(0.002) == pytest.approx(quick.target - 0.002 - quick.min_margin)
    assert slow.spare(0.006) == pytest.approx(slow.target - 0.006 - slow.min_margin)


def test_a_jittery_machine_keeps_a_larger_margin() -> None:
    steady = _fed([0.004] * 100)
    jittery = _fed([0.003] * 90 + [0.007] * 10)  # p95 4 ms above the median
    assert jittery.margin == pytest.approx(0.004)
    assert steady.margin == steady.min_margin
    assert jittery.spare(0.003) < steady.spare(0.003)


def test_too_slow_a_frame_still_gets_the_floor_and_more_when_behind() -> None:
    budget = _fed([0.015] * 30)
    assert budget.spare(0.015) == budget.floor  # past the target: only the floor
    assert budget.spare(0.015, behind=True) == 2 * budget.floor
    assert _fed([0.0] * 30).spare(0.0) == budget.cap  # never more than the cap


def test_a_spike_on_a_quick_machine_gets_nothing_ahead() -> None:
    quick = _fed([0.002] * 60)  # an AI tick's frame of 9 ms among frames of 2 ms
    assert quick.spare(0.009) == 0.0 and quick.spare(0.009, behind=True) == 0.0
    assert quick.spare(0.005) > 0  # late in the period but not past the target
    slow = _fed([0.009] * 60)  # every frame takes 9 ms: the floor, not nothing
    assert slow.spare(0.009) == slow.floor


def test_the_budget_follows_the_machine_as_it_changes() -> None:
    budget = _fed([0.002] * 120, window=120)
    quick = budget.spare(budget.typical)
    for _ in range(120):  # the machine gets loaded: the old frames leave the window
        budget.observe(0.006)
    assert budget.typical == pytest.approx(0.006) and budget.frames == 120
    assert budget.spare(budget.typical) < quick


def test_work_is_spread_over_more_frames_on_a_slower_machine() -> None:
    quick, slow = _fed([0.002] * 60), _fed([0.007] * 60)
    assert quick.stripes(0.012) < slow.stripes(0.012)
    assert quick.stripes(0.0) == 1
    assert slow.stripes(10.0) == slow.max_stripes


def test_a_budget_refuses_settings_it_cannot_work_with() -> None:
    for bad in ({"period": 0.0}, {"share": 0.0}, {"share": 1.5}, {"window": 0},
                {"floor": 0.01, "cap": 0.001}):
        with pytest.raises(ValueError):
            FrameBudget(**bad)  # type: ignore[arg-type]


# ---------------------------------------------------------------------------- WorkAhead


@dataclass
class _Guard:
    node: int
    target: int
    active: bool = True


@dataclass
class _GuardAI:
    left: bool = False
    expected: list[tuple[int, ...]] = field(default_factory=list)
    budgets: list[float] = field(default_factory=list)

    def expect(self, nodes: tuple[int, ...]) -> None:
        self.expected.append(tuple(nodes))

    def prepare(self, budget: float) -> bool:
        self.budgets.append(budget)
        return self.left


@dataclass
class _World:
    guards: list[_Guard]
    guard_ai: _GuardAI


def test_work_ahead_tells_the_guards_nodes_once_and_grants_the_budget() -> None:
    world = _World([_Guard(1, 2), _Guard(5, 6, active=False), _Guard(7, 7)], _GuardAI())
    work = WorkAhead(_fed([0.003] * 30))
    work.after_frame(world, 0.003, idle=False)  # type: ignore[arg-type]
    work.after_frame(world, 0.003, idle=False)  # type: ignore[arg-type]
    assert world.guard_ai.expected == [(1, 2, 7, 7)]  # the down guard's nodes are not read
    assert world.guard_ai.budgets == [pytest.approx(work.budget.spare(0.003))] * 2
    world.guards[0].node = 2  # it arrived: told again
    world.guard_ai.left = True  # and the work ahead is not done
    work.after_frame(world, 0.020, idle=False)  # type: ignore[arg-type]
    assert world.guard_ai.expected[-1] == (2, 2, 7, 7)
    assert len(world.guard_ai.budgets) == 2  # a spike: told the nodes, no work ahead
    for _ in range(60):  # the machine slows down for good: the floor, doubled when behind
        work.after_frame(world, 0.020, idle=False)  # type: ignore[arg-type]
    assert world.guard_ai.budgets[-1] == 2 * work.budget.floor
    world.guard_ai = _GuardAI()  # a restart: the new guard AI is told the same nodes
    work.after_frame(world, 0.003, idle=True)  # type: ignore[arg-type]
    assert not world.guard_ai.budgets and not world.guard_ai.expected  # idle: no work
    work.after_frame(world, 0.003, idle=False)  # type: ignore[arg-type]
    assert world.guard_ai.expected == [(2, 2, 7, 7)]


# ---------------------------------------------------------------------------- the queue


def _prefetch() -> Prefetch:
    occupancy = np.random.default_rng(3).random((20, 30)) > 0.25
    graph = NodeGraph.from_grid(occupancy, 1.0, dense=False)
    return Prefetch(FieldMatrices(graph, PFParams()).spreads)


def test_a_ball_is_queued_once_and_a_guards_node_goes_first() -> None:
    prefetch = _prefetch()
    for node in (10, 20, 10, 30, 20):
        prefetch.expect(node)
    assert list(prefetch.ahead) == [("C", 10), ("C", 20), ("C", 30)]
    prefetch.expect(30, urgent=True)  # a guard stands there now: the next tick reads it
    prefetch.expect(40, urgent=True)
    assert list(prefetch.ahead) == [("C", 40), ("C", 30), ("C", 10), ("C", 20)]
    assert prefetch.run(0.0)  # one ring of the first: work is left
    assert prefetch.searching is not None and prefetch.searching[1] == 40
    prefetch.expect(40)  # being searched: not queued again
    assert ("C", 40) not in prefetch.ahead
    assert not prefetch.run(10.0)  # all done: nothing left
    assert not prefetch.ahead and prefetch.searching is None
    prefetch.expect(10)  # kept already: nothing to search
    assert not prefetch.ahead

