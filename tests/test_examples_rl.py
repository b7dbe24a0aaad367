"""The RL examples' own parts that need no torch: the mask audit of
examples/train_maskable_ppo.py and the paired play of examples/train_supersuit.py (their
training needs SB3 and torch, which the test extra does not install; docs/api.md has the runs)."""

from __future__ import annotations

import importlib
import sys
from collections.abc import Callable, Iterator
from pathlib import Path
from types import ModuleType

import numpy as np
import pytest

pytest.importorskip("gymnasium")
pytest.importorskip("pettingzoo")

from game.env import StealthEnv, parallel_env  # noqa: E402

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


@pytest.fixture
def examples(monkeypatch: pytest.MonkeyPatch) -> Iterator[Callable[[str], ModuleType]]:
    """Import the examples as their scripts do (each imports ``train_ppo`` beside it)."""
    monkeypatch.syspath_prepend(str(EXAMPLES))
    yield importlib.import_module
    for name in ("train_ppo", "train_maskable_ppo", "train_supersuit"):
        sys.modules.pop(name, None)


def test_mask_audit_counts_the_actions_the_mask_ruled_out(
        examples: Callable[[str], ModuleType]) -> None:
    audit = examples("train_maskable_ppo").MaskAudit(StealthEnv("maze", world__duration=10.0))
    audit.reset(seed=0)
    taken = restricted = 0
    for _ in range(12):
        mask = audit.unwrapped.action_masks()
        closed = np.flatnonzero(mask == 0)
        odd = audit.steps % 2  # a closed action at every other step, where there is one
        action = int(closed[0]) if len(closed) and odd else int(np.flatnonzero(mask)[-1])
        taken += int(not mask[action])
        restricted += int(not mask.all())
        _, _, term, trunc, _ = audit.step(action)
        if term or trunc:
            break
    assert taken > 0  # the maze's walls close some action at some of these steps
    assert (audit.masked, audit.restricted) == (taken, restricted)


def test_play_sides_is_paired_per_seed(examples: Callable[[str], ModuleType]) -> None:
    """Random sides play the same actions on the same seed whoever they meet, so the
    example's differences are paired; the player's return is the unshaped game's."""
    play_sides = examples("train_supersuit").play_sides
    env = parallel_env("maze", world__guards=2, world__duration=4.0,
                       rewards={"seen": 0.0, "proximity": 0.0})
    n = int(env.action_space("player_0").n)

    def random(obs: np.ndarray, rng: np.random.Generator) -> int:
        return int(rng.integers(n))

    first, again = (play_sides(env, random, random, range(3)) for _ in range(2))
    assert all(np.array_equal(first[k], again[k]) for k in first)
    assert ((first["survival"] > 0) & (first["survival"] <= 4.0)).all()
    assert (first["return"] <= first["survival"] + 1e-9).all()  # 1 per second, less HP lost
