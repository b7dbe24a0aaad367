"""Extending without editing core files: a test-only guard mode and a test-only overlay.

These are the two rows of docs/architecture.md's "to add X, touch Y" table done for real.
"""

from __future__ import annotations

import ast
import inspect
import json
import os
import sqlite3
import subprocess
import sys
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from ai.baselines import RandomWalkGuards
from ai.bounds import POSITIVE
from ai.params import PFParams, Params
from game.errors import ConfigError
from ai import (
    GUARD_MODES, GuardAI, guard_mode, make_guard_ai, register_guard_mode, unregister_guard_mode,
)
from ai.errors import StimulusError, UnknownNameError
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


# ------------------------------------------------ a registration brings its parameters and names


@dataclass(frozen=True)
class PatrolParams(Params):
    """Test-only: one parameter, the patrol's pace."""

    speed: float = 1.0

    bounds = {"speed": POSITIVE}


class PatrolGuards(RandomWalkGuards):
    """Test-only mode: the random walk, built from :class:`PatrolParams`."""

    mode = "patrol"

    def __init__(self, params: Mapping[str, Any] | None = None) -> None:
        super().__init__(params)
        self.settings = PatrolParams.from_mapping(params)


@pytest.fixture
def patrol() -> Iterator[str]:
    register_guard_mode("patrol", PatrolGuards, display="Patrol", short="P",
                        params=PatrolParams)
    try:
        yield "patrol"
    finally:
        unregister_guard_mode("patrol")


def test_a_registered_mode_brings_its_parameters_table_label_and_play_key(
        patrol: str, tmp_path: Path) -> None:
    from game.config import check_value
    from game.front.keys import key_help, mode_on_key, mode_order
    from game.schema import bound_of
    from headless.analysis.tables import GUARD_NAMES, GUARD_SHORT, table_rows, write_table

    # the config: its key, default and bound come from the parameter class
    assert Config.defaults()["patrol.speed"] == 1.0
    assert bound_of("patrol.speed") is PatrolParams.bounds["speed"]
    with pytest.raises(ConfigError, match=r"patrol\.speed = -1\.0: must be in \(0, inf\)"):
        Config.load(["patrol.speed=-1"])
    # run_trial with its key runs, and the mode is built with the value
    spec = TrialSpec(level="maze", guards=patrol, player="maxmin",
                     overrides=(("patrol.speed", 1.0), ("world.duration", 3.0)))
    row = run_trial(spec)
    assert row["guards"] == patrol and row["config"]["patrol.speed"] == 1.0
    faster = TrialSpec(level="maze", guards=patrol, overrides=(("patrol.speed", 2.5),))
    guards = make_world(faster).guard_ai
    assert isinstance(guards, PatrolGuards) and guards.settings.speed == 2.5
    # Table 3 and the figures name it from the registration
    assert GUARD_NAMES["patrol"] == "Patrol" and GUARD_SHORT["patrol"] == "P"
    write_table(table_rows([{**row, **row["metrics"]}]), tmp_path, 1)
    assert "| Patrol | MaxMin |" in (tmp_path / "table.md").read_text(encoding="utf-8")
    # play: the next number key after the five built-ins
    assert mode_order().index(patrol) == 5 and mode_on_key(6) == patrol
    assert ("1-6", "restart with guards pf/random/fsm/staleness/cheat/patrol") in key_help()
    unregister_guard_mode(patrol)  # and gone again: no key, no default, no play key
    with pytest.raises(ConfigError, match="patrol.speed: unknown config key"):
        check_value("patrol.speed", 1.0)
    assert patrol not in mode_order() and mode_on_key(6) is None and patrol not in GUARD_NAMES


def test_a_section_holds_one_parameter_class(patrol: str) -> None:
    with pytest.raises(ValueError, match=r"section \[patrol\] already holds"):
        register_guard_mode("patrol2", PatrolGuards, section="patrol", params=PFParams)
    register_guard_mode("patrol2", PatrolGuards, section="world", params=PatrolParams)
    try:
        with pytest.raises(ConfigError, match=r"patrol2: config section \[world\] is the world's"):
            Config.defaults()
    finally:
        unregister_guard_mode("patrol2")


#: the built-ins' names: a table of them belongs to the registry (ai/__init__.py, outside
#: game/ and headless/); presets and targets/*.toml/csv are data and may name them
BUILT_IN = ("pf", "random", "fsm", "staleness", "cheat", "maxmin", "safetygraph", "evade")

#: files that use a built-in by name, one choice each, not a table of modes (why):
CHOOSE_A_MODE = {
    "headless/cli.py": "the sim / play --guards and --player defaults",
    "game/env/match.py": "the environment's external guards are PF guards on [pf]",
    "game/front/play.py": "the player slot of a human game (evade, never asked)",
    "game/front/screenshots.py": "each screenshot of the docs picks its guards",
    "headless/mechanics/worlds.py": "the mechanics experiment is PF guards against its players",
    "headless/mechanics/beyond.py": "ditto: PF guards against MaxMin",
    "headless/analysis/beside_paper.py": "the paper-literal rows exist for PF only",
    "headless/sessions/record.py": "a session is compared with the paper's two policies",
}


def _strings(path: Path) -> Iterator[tuple[int, str]]:
    """The string constants of a module outside its docstrings (doctests are examples)."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    docs = {id(node.body[0].value) for node in ast.walk(tree)
            if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef))
            and node.body and isinstance(node.body[0], ast.Expr)
            and isinstance(node.body[0].value, ast.Constant)}
    for node in ast.walk(tree):
        if isinstance(node, ast.Constant) and isinstance(node.value, str) and id(node) not in docs:
            yield node.lineno, node.value


def test_no_mode_name_is_written_again_outside_the_registry() -> None:
    root = Path(__file__).resolve().parents[1]
    files = sorted(p for d in ("game", "headless") for p in (root / d).rglob("*.py"))
    # the acceptance grep, docstrings included: `grep -rn '"staleness"' game headless`
    quoted = [f"{p.relative_to(root)}:{n}" for p in files
              for n, line in enumerate(p.read_text(encoding="utf-8").splitlines(), 1)
              if '"staleness"' in line or "'staleness'" in line]
    assert quoted == []
    # every built-in but "random" (also a spawn and respawn rule) as a string in code
    found = {(str(p.relative_to(root)), n, s) for p in files for n, s in _strings(p)
             if s in BUILT_IN and s != "random"}
    assert {f for f, _, _ in found} <= set(CHOOSE_A_MODE), sorted(found)
    assert set(GUARD_MODES) >= set(BUILT_IN[:5])


# ------------------------------------------- a plugin stimulus brings its parameters and names


BELL = '''
from dataclasses import dataclass

from ai.bounds import NON_NEGATIVE
from ai.params import Params
from ai.stimuli import Stimulus


@dataclass(frozen=True)
class BellParams(Params):
    amplitude: float = 6.0
    bounds = {"amplitude": NON_NEGATIVE}


class Bell(Stimulus):
    name, display, short = "bell", "Alarm bell", "B"
    parameters = BellParams

    def start(self, ctx):
        self.amplitude = ctx.params_of(self).amplitude
        self.layer = -self.amplitude * ctx.falloff(0, 0.5)

    def inject(self, ctx):
        return self.layer

    def describe(self):
        return {"name": self.name, "node": -1, "amplitude": self.amplitude}


class Plain(Stimulus):
    name = "plain"

    def inject(self, ctx):
        return -1.0 * ctx.falloff(0, 0.5)


class Beacon(Stimulus):  # sits on node 0; drawn there as declared
    name, node, marker = "beacon", 0, True


class Hum(Stimulus):  # sits on node 0, not drawn
    name, node = "hum", 0


@dataclass(frozen=True)
class NoBound(Params):
    x: float = 1.0


class Unbounded(Stimulus):
    name, parameters = "unbounded", NoBound


class OnPf(Stimulus):
    name, section, parameters = "onpf", "pf", BellParams
'''


@pytest.fixture
def bell(tmp_path: Path) -> Iterator[Path]:
    """The plugin file; the stimulus classes it registers are forgotten afterwards."""
    from ai.stimuli import STIMULUS_TYPES

    before = dict(STIMULUS_TYPES)
    path = tmp_path / "bell.py"
    path.write_text(BELL, encoding="utf-8")
    try:
        yield path
    finally:
        STIMULUS_TYPES.clear()
        STIMULUS_TYPES.update(before)


def test_a_plugin_stimulus_takes_its_parameters_from_the_config(bell: Path, capsys) -> None:
    from ai.stimuli import STIMULUS_TYPES
    from headless.cli import main

    trace = bell.with_name("bell.jsonl")
    assert main(["sim", "maze", "--seed", "1", "--stimulus", f"{bell}:Bell",
                 "--set", "bell.amplitude=2.5", "--set", "world.duration=2",
                 "--trace", str(trace)]) == 0
    first = json.loads(trace.read_text(encoding="utf-8").splitlines()[0])
    assert first["stimuli"] == [{"name": "bell", "node": -1, "amplitude": 2.5}]
    declared = STIMULUS_TYPES["bell"]
    assert (declared.display, declared.short, declared.section) == ("Alarm bell", "B", "bell")
    # the key's default and bound come from the class; the value reaches the stimulus
    assert Config.defaults()["bell.amplitude"] == 6.0
    for value, layer in ((None, -6.0), (0.0, 0.0), (1.5, -1.5)):
        spec = TrialSpec("maze", seed=1, stimuli=(f"{bell}:Bell",),
                         overrides=() if value is None else (("bell.amplitude", value),))
        assert make_world(spec).guard_ai.extra_information[0] == layer
    # an out-of-range value is one line, exit code 2
    capsys.readouterr()
    assert main(["sim", "maze", "--stimulus", f"{bell}:Bell", "--set", "bell.amplitude=-1"]) == 2
    err = capsys.readouterr().err
    assert err == "stealth: error: bell.amplitude = -1.0: must be in [0, inf)\n"
    # a plugin without parameters works as before and adds no config key
    keys = set(Config.defaults().as_dict())
    plain = TrialSpec("maze", seed=1, stimuli=(f"{bell}:Plain",))
    assert make_world(plain).guard_ai.extra_information[0] == -1.0
    assert set(Config.defaults().as_dict()) == keys
    assert not any(k.startswith("plain.") for k in keys)


def test_a_preset_sets_a_plugin_parameter(bell: Path) -> None:
    from headless.presets import load_preset

    preset_file = bell.with_name("bell.toml")
    preset_file.write_text(
        'description = "bell"\nlevels = ["maze"]\nabstractions = ["grid"]\nguards = ["pf"]\n'
        'players = ["maxmin"]\nscenarios = ["capture"]\nseeds = 1\nstimuli = ["bell.py:Bell"]\n'
        '[set]\n"bell.amplitude" = 0.5\n', encoding="utf-8")
    spec = load_preset(str(preset_file)).specs()[0]
    assert make_world(spec).guard_ai.extra_information[0] == -0.5


def test_bad_parameter_declarations_are_one_line_errors(bell: Path) -> None:
    from ai.stimuli import load_stimulus

    with pytest.raises(StimulusError, match=r"unbounded: parameters NoBound\.x declares no bound"):
        load_stimulus(f"{bell}:Unbounded")
    with pytest.raises(StimulusError, match=r"onpf: config section \[pf\] already holds the "
                                            "parameters of 'pf'"):
        load_stimulus(f"{bell}:OnPf")


def test_the_replay_draws_what_the_stimulus_declares_a_marker(bell: Path) -> None:
    from ai.stimuli import STIMULUS_TYPES
    from game.trace import parse_line, trace_record

    world = make_world(TrialSpec("maze", seed=1, stimuli=(f"{bell}:Beacon", f"{bell}:Hum")))
    record = json.loads(json.dumps(trace_record(world)))
    assert [s["name"] for s in record["stimuli"]] == ["beacon", "hum"]
    assert parse_line(record, "line 1").markers == (0,)  # the beacon's: a hum is not drawn
    del STIMULUS_TYPES["hum"]  # a plugin this process did not load may be a marker: drawn
    assert parse_line(record, "line 1").markers == (0, 0)
    # the built-ins answer the same question: footsteps and rain are not drawn, throws are
    assert [STIMULUS_TYPES[n].marker for n in ("footstep", "rain", "thrown_decoy", "decoy",
                                               "corpse")] == [False, False, True, True, True]


# ------------------------------------------ an installed guard mode: found by every process


#: an installed package holding the Patrol mode above, registered on import
PATROL_PACKAGE = "\n".join([
    "from __future__ import annotations", "from dataclasses import dataclass",
    "from ai import register_guard_mode", "from ai.baselines import RandomWalkGuards",
    "from ai.bounds import POSITIVE", "from ai.params import Params",
    inspect.getsource(PatrolParams), inspect.getsource(PatrolGuards),
    'register_guard_mode("patrol", PatrolGuards, display="Patrol", short="P", '
    'params=PatrolParams)'])


def _install(site: Path, package: str, source: str, entry: str,
             group: str = "stealthfield.guard_modes") -> Path:
    """An installed-looking distribution in ``site``: ``package.py`` and its dist-info
    declaring ``entry`` under ``[group]``."""
    (site / f"{package}.py").write_text(source, encoding="utf-8")
    info = site / f"{package}-0.1.dist-info"
    info.mkdir()
    (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {package}\nVersion: 0.1\n",
                                   encoding="utf-8")
    (info / "entry_points.txt").write_text(f"[{group}]\n{entry}\n",
                                           encoding="utf-8")
    return site


def _stealth(site: Path, *args: str, code: str = "") -> subprocess.CompletedProcess[str]:
    """``stealth ARGS`` in a fresh interpreter whose path holds ``site`` (nothing imports
    the plugin by hand); ``code`` runs first (e.g. choosing the spawn start method)."""
    root = Path(__file__).resolve().parents[1]
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(root), str(site)])}
    script = f"import sys\n{code}\nfrom headless.cli import main\nsys.exit(main(sys.argv[1:]))"
    return subprocess.run([sys.executable, "-c", script, *args], capture_output=True,
                          text=True, timeout=300, env=env, cwd=site)


def test_an_installed_guard_mode_is_found_by_the_cli_its_config_and_a_sweeps_workers(
        tmp_path: Path) -> None:
    site = _install(tmp_path, "patrolpkg", PATROL_PACKAGE, "patrol = patrolpkg")
    code = ("import sys\nfrom importlib.metadata import entry_points\n"
            "print([ep.value for ep in entry_points(group='stealthfield.guard_modes')])")
    found = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                           timeout=60, env={**os.environ, "PYTHONPATH": str(site)})
    assert found.stdout.strip() == "['patrolpkg']", found.stderr  # discovered as installed
    sim = _stealth(site, "sim", "maze", "--guards", "patrol", "--set", "patrol.speed=2",
                   "--set", "world.duration=5", "--json")
    assert sim.returncode == 0, sim.stderr
    row = json.loads(sim.stdout)
    assert row["guards"] == "patrol" and row["config"]["patrol.speed"] == 2.0
    # a preset names it; the trials run in worker processes started fresh (spawn), which
    # find it themselves, with the same config as the single trial above
    preset = tmp_path / "patrol.toml"
    preset.write_text('levels = ["maze"]\nabstractions = ["grid"]\nguards = ["patrol"]\n'
                      'players = ["maxmin"]\nscenarios = ["capture"]\nseeds = 2\n\n[set]\n'
                      '"world.duration" = 5.0\n"patrol.speed" = 2.0\n', encoding="utf-8")
    run = _stealth(site, "run", "--preset", str(preset), "--out", str(tmp_path / "out"),
                   "--workers", "2",
                   code="import multiprocessing; multiprocessing.set_start_method('spawn')")
    assert run.returncode == 0, run.stderr
    with sqlite3.connect(tmp_path / "out" / "results.sqlite") as db:
        stored = db.execute("SELECT guards, config_hash, error FROM trials").fetchall()
    assert stored == [("patrol", row["config_hash"], None)] * 2


def test_a_broken_installed_guard_mode_is_one_line_naming_its_entry_point(
        tmp_path: Path) -> None:
    site = _install(tmp_path, "brokenpkg", 'raise RuntimeError("no patrol today")\n',
                    "patrol = brokenpkg")
    result = _stealth(site, "sim", "maze", "--guards", "patrol")
    assert result.returncode == 2 and result.stdout == ""
    assert result.stderr == ("stealth: error: patrol: cannot load entry point 'brokenpkg' "
                             "(stealthfield.guard_modes): RuntimeError: no patrol today\n")
    assert _stealth(site, "--help").returncode == 0  # the top-level help reads no registry


def test_an_installed_player_policy_may_be_registered_by_a_function(tmp_path: Path) -> None:
    source = ("from ai import register_player_policy\n\n\ndef register():\n"
              "    register_player_policy('still', 'ai.players:EvadePlayer', display='Still')\n")
    site = _install(tmp_path, "stillpkg", source, "still = stillpkg:register",
                    "stealthfield.player_policies")
    listed = _stealth(site, "sim", "--help")
    assert listed.returncode == 0 and "maxmin, safetygraph, evade, still" in " ".join(
        listed.stdout.split())
    sim = _stealth(site, "sim", "maze", "--player", "still", "--set", "world.duration=2",
                   "--json")
    assert sim.returncode == 0 and json.loads(sim.stdout)["player"] == "still", sim.stderr
