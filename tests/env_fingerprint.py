"""Per-step fingerprints of the environments, for tests/test_env_fingerprint.py.

    PYTHONPATH=. python tests/env_fingerprint.py --record   # rewrite tests/data/env_fingerprint.json

A fixed seed and action sequence is played; every step's observation bytes, reward,
termination flags and info are hashed (sha256, first 16 hex digits), so a change anywhere
in the world, the guards, the observation or the reward shows at the first step it
touches. Recorded from the code before the env's speed work (issue 23); re-record only for
a deliberate change of the simulation, never to make a speed-up pass. Re-recorded in issue
41 for the player's new ``gain`` move feature alone: with those columns taken out of the
player's observations, the new code gave the 1,025 digests recorded before, every one.
"""

from __future__ import annotations

import hashlib
import json
import struct
import sys
from pathlib import Path
from typing import Any

import numpy as np

REFERENCE = Path(__file__).parent / "data" / "env_fingerprint.json"
#: the reward terms in force when the reference was recorded (the defaults changed since:
#: the fingerprint pins the simulation, so it keeps the terms it was recorded with)
RECORDED_REWARDS = {"survival": 0.1, "hp": 1.0, "capture": 10.0, "seen": 2.0, "proximity": 6.0}
#: agent names as they were recorded (the player became "player_0" in issue 41)
_RECORDED_NAMES = {"player_0": "player"}
#: (name, builder kind, level, abstraction, steps)
CASES = (("gym-miami-grid", "gym", "miami", "grid", 400),
         ("gym-miami-partition", "gym", "miami", "partition", 250),
         ("parallel-maze-grid", "parallel", "maze", "grid", 200),
         ("parallel-maze-partition", "parallel", "maze", "partition", 150))


def _digest(*parts: Any) -> str:
    h = hashlib.sha256()
    for part in parts:
        if isinstance(part, np.ndarray):
            h.update(str(part.dtype).encode() + str(part.shape).encode() + part.tobytes())
        elif isinstance(part, float):
            h.update(struct.pack("<d", part))
        elif isinstance(part, dict):
            for key in sorted(part):
                value = part[key]
                if key == "action_mask":  # hashed as the values it was recorded with (bool
                    value = np.asarray(value).astype(bool)  # then; int8 now, issue 41)
                h.update(_RECORDED_NAMES.get(key, key).encode())
                h.update(_digest(value).encode())
        else:
            h.update(repr(part).encode())
    return h.hexdigest()[:16]


def play(kind: str, level: str, abstraction: str, steps: int) -> list[str]:
    """One hash per reset and per step of the fixed play of one case."""
    from game.env import StealthEnv, parallel_env  # noqa: PLC0415

    rng = np.random.default_rng(20230)
    out: list[str] = []
    if kind == "gym":
        env = StealthEnv(level, abstraction=abstraction, rewards=RECORDED_REWARDS)
        obs, info = env.reset(seed=7)
        out.append(_digest(obs, info))
        n = int(env.action_space.n)  # type: ignore[attr-defined]
        for _ in range(steps):
            obs, reward, terminated, truncated, info = env.step(int(rng.integers(n)))
            out.append(_digest(obs, float(reward), terminated, truncated, info))
            if terminated or truncated:
                obs, info = env.reset()
                out.append(_digest(obs, info))
        return out
    penv = parallel_env(level, abstraction, rewards=RECORDED_REWARDS)
    pobs, infos = penv.reset(seed=7)
    out.append(_digest(pobs, infos))
    m = int(penv.action_space("player_0").n)
    for _ in range(steps):
        actions = {a: int(rng.integers(m)) for a in penv.agents}
        pobs, rewards, terms, truncs, infos = penv.step(actions)
        out.append(_digest(pobs, {a: float(r) for a, r in rewards.items()}, terms, truncs, infos))
        if not penv.agents:
            pobs, infos = penv.reset()
            out.append(_digest(pobs, infos))
    return out


def fingerprints() -> dict[str, list[str]]:
    return {name: play(kind, level, abstraction, steps)
            for name, kind, level, abstraction, steps in CASES}


if __name__ == "__main__":
    if sys.argv[1:] != ["--record"]:
        sys.exit("usage: python tests/env_fingerprint.py --record")
    REFERENCE.write_text(json.dumps(fingerprints(), indent=0) + "\n")
    print(f"wrote {REFERENCE}")
