"""Awareness meters and the team's phase: traced, parsed, in the scene, drawn (dummy SDL)."""

from __future__ import annotations

import dataclasses
import json
import os

os.environ["SDL_VIDEODRIVER"] = "dummy"
os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")

import numpy as np
import pygame
import pytest

from game.front.render import BAD, DrawOptions, Renderer
from game.scene import SceneBuilder
from game.trace import parse_line, trace_record
from game.trial import TrialSpec, make_world

ON = (("awareness.enabled", "true"), ("alert.enabled", "true"), ("roles.enabled", "true"))


def world_at_detection():
    world = make_world(TrialSpec("arkham", "grid", "pf", "maxmin", "fixed", 3, overrides=ON))
    while world.m.first_detect_time is None:
        world.step()
    while world.step_index % world.steps_per_tick:
        world.step()
    return world


def test_trace_lines_carry_awareness_role_and_phase_and_parse_back() -> None:
    world = world_at_detection()
    record = json.loads(json.dumps(trace_record(world)))
    assert record["phase"] == "alert"
    seer = world.seen_by[0] if world.seen_by else 0
    assert 0.0 <= record["guards"][seer]["awareness"] <= 1.0
    assert {g["role"] for g in record["guards"]} <= {"chaser", "interceptor", "holder", ""}
    line = parse_line(record, "t")
    assert line.phase == "alert"
    assert line.guards[seer].awareness == record["guards"][seer]["awareness"]


def test_the_mark_over_a_fully_aware_guard_is_a_red_box() -> None:
    pygame.display.init()
    pygame.font.init()
    pygame.display.set_mode((960, 800))
    try:
        world = world_at_detection()
        builder = SceneBuilder(world.level, world.graph, view_range=world.view_range, fov_deg=90.0)
        scene = builder.from_world(world)
        assert scene.phase == "alert"
        i = next(k for k, g in enumerate(scene.guards) if g.awareness is not None and g.active)
        full = dataclasses.replace(scene.guards[i], awareness=1.0)
        none = dataclasses.replace(scene.guards[i], awareness=None)
        renderer = Renderer(builder.static, (960, 800))
        images = []
        for guard in (full, none):
            guards = tuple(guard if k == i else g for k, g in enumerate(scene.guards))
            surface = pygame.Surface(renderer.layout.size).convert()
            renderer.draw(surface, dataclasses.replace(scene, guards=guards), DrawOptions())
            images.append(pygame.surfarray.array3d(surface))
        x, y = renderer.to_screen(*scene.guards[i].pos)
        radius = max(5.0, scene.agent_radius * renderer.layout.scale)
        # the awareness mark sits above the guard: a full one is a red "!" box (its bottom
        # row, left of the glyph), and without awareness (nor sight) there is none
        px, py = int(x) - 7, int(y - radius - 8)
        assert tuple(images[0][px, py]) == pytest.approx(BAD, abs=2)
        assert not np.array_equal(images[0][px, py], images[1][px, py])
    finally:
        pygame.display.quit()
