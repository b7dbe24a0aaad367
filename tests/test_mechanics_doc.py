"""docs/mechanics.md: the alarm-bell example runs exactly as written and has an effect."""

from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
DOC = ROOT / "docs" / "mechanics.md"
BELL = (10.5, 23.5)  # where the example hangs its bell (miami)


def alarm_bell_block() -> str:
    """The ```python block of the doc that defines ``AlarmBell``, exactly as written."""
    blocks = re.findall(r"```python\n(.*?)```", DOC.read_text(encoding="utf-8"), flags=re.DOTALL)
    found = [b for b in blocks if "class AlarmBell(" in b]
    assert len(found) == 1, "docs/mechanics.md must have one python block defining AlarmBell"
    return found[0]


def sim(*extra: str, trace: Path) -> dict:
    # Blind guards in both arms: only the bell can raise the alert, not a lucky sighting.
    command = [sys.executable, "-m", "headless.cli", "sim", "miami", "--guards", "pf",
               "--scenario", "fixed", "--seed", "3", "--set", "world.view_range=0",
               "--json", "--trace", str(trace), *extra]
    result = subprocess.run(command, capture_output=True, text=True, cwd=ROOT, check=False)
    assert result.returncode == 0, result.stderr
    return json.loads(result.stdout)


def nearest_to_bell(trace: Path, start: float, end: float) -> tuple[float, list[str]]:
    """Mean Manhattan distance from the bell to the nearest guard, and guard states, in [start, end]."""
    distances, states = [], []
    for line in trace.read_text().splitlines():
        record = json.loads(line)
        if start <= record["t"] <= end:
            distances.append(min(abs(g["pos"][0] - BELL[0]) + abs(g["pos"][1] - BELL[1])
                                 for g in record["guards"]))
            states += [g["state"] for g in record["guards"]]
    return float(np.mean(distances)), states


def test_the_doc_block_is_the_shipped_example_and_short():
    block = alarm_bell_block()
    assert block == (ROOT / "examples" / "alarm_bell.py").read_text(encoding="utf-8")
    assert len(block.splitlines()) < 40


def test_alarm_bell_from_the_doc_draws_guards_and_alerts_them(tmp_path: Path):
    plugin = tmp_path / "alarm_bell.py"
    plugin.write_text(alarm_bell_block(), encoding="utf-8")
    with_bell = sim("--stimulus", f"{plugin}:AlarmBell", trace=tmp_path / "with.jsonl")
    without = sim(trace=tmp_path / "without.jsonl")
    assert with_bell["stimuli"] == [f"{plugin}:AlarmBell"] and "stimuli" not in without
    assert set(with_bell["metrics"]) == set(without["metrics"])

    near_with, states_with = nearest_to_bell(tmp_path / "with.jsonl", 10.0, 35.0)
    near_without, states_without = nearest_to_bell(tmp_path / "without.jsonl", 10.0, 35.0)
    assert near_with < 2.0 < near_without - 2.0
    assert states_with and set(states_with) == {"alert"}  # the weight floor
    assert "alert" not in states_without
    # the bell stops at t = 35 s: it leaves the trace and the weight decays back
    records = [json.loads(line) for line in (tmp_path / "with.jsonl").read_text().splitlines()]
    assert any(s["name"] == "alarm_bell" for s in records[20].get("stimuli", []))
    assert "stimuli" not in records[-1]
    assert {g["state"] for g in records[-1]["guards"]} == {"patrol"}


@pytest.mark.parametrize("spec", ["examples/alarm_bell.py:Nope", "examples/missing.py:AlarmBell"])
def test_bad_stimulus_specs_are_one_line_errors(spec: str):
    result = subprocess.run([sys.executable, "-m", "headless.cli", "sim", "miami", "--stimulus",
                             spec], capture_output=True, text=True, cwd=ROOT, check=False)
    assert result.returncode == 2 and result.stdout == ""
    assert len(result.stderr.strip().splitlines()) == 1
    assert result.stderr.startswith("stealth: error: ")


def test_the_siren_block_is_the_shipped_example_and_its_parameter_reaches_it(tmp_path: Path):
    """docs/mechanics.md "A plugin's own parameters": the block, its key, its bound."""
    from ai.stimuli import STIMULUS_TYPES
    from game.config import Config
    from game.errors import ConfigError
    from game.trial import TrialSpec, make_world

    blocks = re.findall(r"```python\n(.*?)```", DOC.read_text(encoding="utf-8"), flags=re.DOTALL)
    found = [b for b in blocks if "class Siren(" in b]
    assert found == [(ROOT / "examples" / "siren.py").read_text(encoding="utf-8")]
    plugin = tmp_path / "siren.py"
    plugin.write_text(found[0], encoding="utf-8")
    before = dict(STIMULUS_TYPES)
    try:
        pulls = []
        for amplitude in (None, 2.0):
            given = () if amplitude is None else (("siren.amplitude", amplitude),)
            spec = TrialSpec("miami", stimuli=(f"{plugin}:Siren",), overrides=given)
            pulls.append(float(make_world(spec).guard_ai.extra_information.min()))
        assert pulls == [-6.0, -2.0]
        with pytest.raises(ConfigError, match=r"siren\.falloff = 1\.5: must be in \(0, 1\]"):
            Config.load(["siren.falloff=1.5"])
    finally:
        STIMULUS_TYPES.clear()
        STIMULUS_TYPES.update(before)
