"""benchmarks/ppo_learning.py (run by hand, not here): its arguments and how it scores.

The benchmark itself trains SB3 PPO for minutes per training seed (docs/api.md); these
tests only check what it refuses and that its held-out play is scored by the game's
return, with every shaping term off, whatever env options it is given.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

pytest.importorskip("gymnasium")
pytest.importorskip("pettingzoo")

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "benchmarks"))
import ppo_learning  # noqa: E402

from game.env import REWARDS, SHAPING  # noqa: E402


def test_bad_arguments_are_one_line_and_exit_2() -> None:
    done = subprocess.run([sys.executable, str(ROOT / "benchmarks" / "ppo_learning.py"),
                           "--steps", "0"], capture_output=True, text=True, timeout=120)
    assert done.returncode == 2 and done.stdout == ""
    assert done.stderr.splitlines() == [
        "ppo_learning: error: argument --steps: expected a whole number >= 1, not 0"]


@pytest.mark.parametrize(("argv", "words"), [
    (["--test-seeds", "1"], "argument --test-seeds: expected a whole number >= 2"),
    (["--train-seeds", "two"], "argument --train-seeds: expected a whole number, not 'two'"),
    (["--env", "obs_radius"], "argument --env: expected KEY=VALUE, not 'obs_radius'"),
    (["--env", "obs_radius=-1"], "cannot build the env: obs_radius must be"),
    (["--env", "rewards={\"speed\": 1}"], "cannot build the env: unknown reward terms"),
    (["--json", "/no/such/folder/out.json"], "argument --json: no folder for"),
    (["--env", "world__gards=2"], "cannot build the env: world.gards: unknown config key"),
])
def test_what_the_arguments_refuse(argv: list[str], words: str,
                                   capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as stop:
        ppo_learning.parse_args(["--level", "maze", *argv])
    assert stop.value.code == 2
    err = capsys.readouterr().err
    assert err.startswith("ppo_learning: error: ") and words in err and err.count("\n") == 1


def test_env_options_are_json_and_held_out_play_scores_the_game_alone() -> None:
    args = ppo_learning.parse_args(["--level", "maze", "--env", "world__guards=2",
                                    "--env", 'rewards={"seen": 5, "capture": 4}'])
    assert args.env_kwargs == {"world__guards": 2, "rewards": {"seen": 5, "capture": 4}}
    assert (args.steps, args.train_seeds, args.test_seeds, args.n_envs) == (60_000, 4, 50, 1)
    env = ppo_learning._make_env(args.level, args.env_kwargs, game_only=True)
    assert env.match.n_guards == 2
    assert env.match.rewards == {**REWARDS, "capture": 4, **dict.fromkeys(SHAPING, 0.0)}
