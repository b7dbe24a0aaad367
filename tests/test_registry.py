"""Extending without editing core files: a test-only guard mode and a test-only overlay.

These are the two rows of docs/architecture.md's "to add X, touch Y" table done for real.
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np
import pytest

from ai import (
    GUARD_MODES, GuardAI, guard_mode, make_guard_ai, register_guard_mode, unregister_guard_mode,
)
from ai.errors import UnknownNameError
from game.config import Config
from game.scene import OVERLAYS, Overlay, SceneBuilder, overlay_key, register_overlay, \
    unregister_overlay
from game.trial import TrialSpec, make_world, run_trial
from headless.cli import build_parser
from navmesh.errors import StealthError


class SentryGuards(GuardAI):
    """Test-only mode: every guard stays on its spawn node forever; exposes one field."""

    mode = "sentry"

    def reset(self, graph, rng, n_guards) -> None:
        self.graph = graph
        self.ticks = 0

    def tick(self, view, dt) -> None:
        self.ticks += 1

    def decide(self, i, view) -> int:
        return int(view.guard_nodes[i])

    def fields(self) -> dict[str, np.ndarray]:
        return {"ticks": np.full(self.graph.n, float(self.ticks))}


@pytest.fixture
def sentry() -> Iterator[str]:
    register_guard_mode("sentry", SentryGuards, display="Sentry")
    try:
        yield "sentry"
    finally:
        unregister_guard_mode("sentry")


def test_a_registered_guard_mode_runs_a_trial_without_core_edits(sentry: str) -> None:
    assert guard_mode(sentry).display == "Sentry" and guard_mode(sentry).section == "sentry"
    spec = TrialSpec(level="maze", guards=sentry, player="maxmin",
                     overrides=(("world.duration", 5.0),))
    world = make_world(spec)
    starts = [g.node for g in world.guards]
    metrics = world.run()
    assert isinstance(world.guard_ai, SentryGuards) and world.guard_ai.ticks == 5
    assert [g.node for g in world.guards] == starts  # sentries never leave their node
    assert metrics["backtracks"] == 0
    row = run_trial(spec)
    assert row["guards"] == sentry and row["metrics"]["coverage"] == metrics["coverage"]
    # the CLI offers it too: its choices come from the registry
    args = build_parser().parse_args(["sim", "maze", "--guards", sentry])
    assert args.guards == sentry


def test_an_unknown_mode_is_a_one_line_stealth_error() -> None:
    with pytest.raises(UnknownNameError, match="unknown guard mode 'sentry'") as info:
        make_guard_ai("sentry")
    assert isinstance(info.value, StealthError) and "pf" in str(info.value)
    assert "sentry" not in GUARD_MODES


def test_a_registered_overlay_is_drawn_from_the_modes_fields(sentry: str) -> None:
    register_overlay(Overlay("T", "AI ticks so far", ("ticks",), aliases=("ticks",)))
    try:
        assert overlay_key("ticks") == "T" and list(OVERLAYS)[-1] == "T"
        world = make_world(TrialSpec(level="maze", guards=sentry), Config.load(
            {"world.duration": 3.0}))
        world.run()
        builder = SceneBuilder(world.level, world.graph, view_range=world.view_range,
                               fov_deg=90.0)
        scene = builder.from_world(world, "T")
        assert scene.layer is not None and scene.layer.label == "AI ticks so far"
        assert np.all(scene.layer.values == 3.0) and scene.field_note == ""
        # a mode without that field says so instead of drawing nothing silently
        other = make_world(TrialSpec(level="maze", guards="pf"), Config.load(
            {"world.duration": 1.0}))
        assert builder.from_world(other, "T").field_note == "field T not available"
        assert builder.from_world(make_world(TrialSpec(level="maze", guards="random")),
                                  "T").field_note == "no fields in mode random"
    finally:
        unregister_overlay("T")
    with pytest.raises(ValueError, match="unknown overlay"):
        overlay_key("ticks")
