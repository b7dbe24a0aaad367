"""The environments play exactly as recorded: a fixed seed and action sequence gives the
same observations, rewards, flags and infos at every step (tests/env_fingerprint.py).

Guards the env's speed work (issue 23): a faster step must not change a single bit.
"""

from __future__ import annotations

import json

import pytest

pytest.importorskip("gymnasium")
pytest.importorskip("pettingzoo")

from env_fingerprint import CASES, REFERENCE, play  # noqa: E402


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_env_plays_exactly_as_recorded(case: tuple) -> None:
    name, kind, level, abstraction, steps = case
    expected = json.loads(REFERENCE.read_text())[name]
    got = play(kind, level, abstraction, steps)
    first = next((i for i, (a, b) in enumerate(zip(got, expected, strict=False)) if a != b), None)
    assert first is None and len(got) == len(expected), (
        f"{name}: differs from the recorded play at entry {first} of {len(expected)}")
