"""The `stealth` command line: JSON shapes of SPEC §9 and one-line errors with exit code 2."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from headless.cli import main

TABLE1 = {  # paper Table 1: rows, cols, walkable, blocked
    "arkham": (28, 26, 548, 180),
    "dishonored": (26, 39, 726, 288),
    "miami": (26, 21, 377, 169),
    "maze": (20, 20, 206, 194),
    "tlou": (14, 30, 255, 165),
}


def run_cli(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "headless.cli", *args],
                          capture_output=True, text=True, timeout=120)


def test_levels_json_reports_table1(capsys: pytest.CaptureFixture) -> None:
    assert main(["levels", "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)
    assert {r["name"] for r in rows} == set(TABLE1)
    for r in rows:
        assert set(r) == {"name", "triangles", "min_area", "max_area", "avg_area",
                          "rows", "cols", "walkable", "blocked"}
        assert (r["rows"], r["cols"], r["walkable"], r["blocked"]) == TABLE1[r["name"]]
        assert r["triangles"] > 0 and 0 < r["min_area"] <= r["avg_area"] <= r["max_area"]


def test_path_json_shape(capsys: pytest.CaptureFixture) -> None:
    assert main(["path", "maze", "--from", "1.5,1.5", "--to", "18.5,18.5", "--json"]) == 0
    document = json.loads(capsys.readouterr().out)
    assert set(document) == {"points", "length"}
    assert document["points"][0] == [1.5, 1.5] and document["points"][-1] == [18.5, 18.5]
    assert document["length"] >= (17**2 + 17**2) ** 0.5


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["path", "maze", "--from", "0.5,0.5", "--to", "18.5,18.5"], "outside the walkable area"),
        (["sim", "maze", "--guards", "sniper"], "invalid choice"),
        (["sim", "maze", "--set", "world.viewrange=3"], "world.viewrange"),
        (["sim", "no-such-level"], "no-such-level"),
        (["sim", "maze", "--trace", "/no/such/dir/trace.jsonl"], "--trace"),
        (["validate", "no-such-level.json"], "no-such-level.json"),
        (["path", "maze", "--from", "1.5", "--to", "2,2"], "X,Y"),
    ],
)
def test_user_errors_are_one_line_with_exit_code_2(args: list[str], needle: str) -> None:
    result = run_cli(*args)
    assert result.returncode == 2, result.stderr
    assert "Traceback" not in result.stderr
    lines = [line for line in result.stderr.splitlines() if line.strip()]
    assert needle in lines[-1]
    assert result.stdout == ""


def test_broken_level_file(tmp_path) -> None:
    bad = tmp_path / "broken.json"
    bad.write_text('{"format": "stealth-level/1", "name": "b", "grid": ["..", "."], "guards": [[0.5, 0.5]]}')
    result = run_cli("sim", str(bad))
    assert result.returncode == 2 and "Traceback" not in result.stderr
    assert "broken.json" in result.stderr and "grid" in result.stderr


def test_sim_json_is_the_only_stdout_and_trace_lines(tmp_path) -> None:
    trace = tmp_path / "trace.jsonl"
    result = run_cli("sim", "tlou", "--guards", "pf", "--player", "maxmin", "--json",
                     "--trace", str(trace), "--explain", "--set", "world.duration=5")
    assert result.returncode == 0, result.stderr
    document = json.loads(result.stdout)
    assert set(document) >= {"level", "abstraction", "guards", "player", "scenario", "seed",
                             "metrics", "config_hash", "config"}
    assert document["config"]["world.duration"] == 5.0  # the trial records what it ran with
    lines = [json.loads(line) for line in trace.read_text().splitlines()]
    assert [line["t"] for line in lines] == [0.0, 1.0, 2.0, 3.0, 4.0, 5.0]
    for line in lines:
        assert set(line["player"]) >= {"pos", "hp"}
        assert len(line["guards"]) == 3
        assert all(set(g) >= {"pos", "heading", "sees_player"} for g in line["guards"])
        assert isinstance(line["events"], list)
    explained = [line["explain"] for line in lines[1:] if line.get("explain")]
    assert explained, "PF decisions are explained in the trace"


def test_argparse_mistakes_are_the_same_one_line_error(capsys: pytest.CaptureFixture) -> None:
    for argv in (["bogus"], ["sim"], ["run", "--workers", "two"], ["levels", "--no-such"]):
        assert main(argv) == 2
        captured = capsys.readouterr()
        lines = captured.err.splitlines()
        assert len(lines) == 1 and lines[0].startswith("stealth: error: "), captured.err
        assert "usage:" not in captured.err and captured.out == ""


def test_version_and_presets(capsys: pytest.CaptureFixture) -> None:
    from importlib.metadata import version

    with pytest.raises(SystemExit) as info:
        main(["--version"])
    assert info.value.code == 0
    assert capsys.readouterr().out.strip() == f"stealth {version('stealthfield')}"
    assert main(["presets"]) == 0
    lines = capsys.readouterr().out.splitlines()
    quick = next(line for line in lines if line.startswith("quick "))
    assert "1,000 trials" in quick and {line.split()[0] for line in lines} >= {"smoke", "paper"}
    assert main(["presets", "--json"]) == 0
    listed = json.loads(capsys.readouterr().out)
    assert {"name": "smoke", "description": listed[-1]["description"]} == listed[-1]


@pytest.mark.parametrize("command", ["levels", "validate", "path", "sim", "mechanics",
                                     "presets", "run", "report", "play", "replay", "tune",
                                     "analyse"])
def test_every_option_is_documented_with_its_default(command: str) -> None:
    from headless.cli import build_parser

    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, type(parser._subparsers._actions[-1]))
               ).choices[command]
    text = sub.format_help()
    for action in sub._actions:
        assert action.help, f"{command} {action.dest}: no help"
        shown = action.default not in (None, False, [])
        if shown and action.dest != "help":
            assert f"(default: {action.default})" in " ".join(text.split()), (command, action.dest)


def test_play_help_lists_the_keys_without_importing_pygame() -> None:
    code = ("import sys; from headless.cli import main\n"
            "try:\n    main(['play', '--help'])\nexcept SystemExit:\n    pass\n"
            "assert 'pygame' not in sys.modules, 'pygame was imported'\n")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                            timeout=60)
    assert result.returncode == 0, result.stderr
    from game.front.keys import key_help

    for keys, what in key_help():
        assert keys in result.stdout and what in result.stdout


def test_sim_reads_and_checks_the_level_and_the_config_once(capsys: pytest.CaptureFixture) -> None:
    """``stealth sim`` parses the level, loads the config and checks the agent's body against
    the level once each, and hands them to the trial (cProfile counts the calls)."""
    import cProfile
    import pstats

    from game.config import Config
    from navmesh.clearance import check_body
    from navmesh.level_format import parse_level

    profile = cProfile.Profile()
    profile.enable()
    try:
        code = main(["sim", "maze", "--guards", "pf", "--player", "maxmin",
                     "--set", "world.duration=5"])
    finally:
        profile.disable()
    assert code == 0 and "maze grid guards=pf" in capsys.readouterr().out
    calls = {where: counts[1] for where, counts in pstats.Stats(profile).stats.items()}  # type: ignore[attr-defined]
    for function in (parse_level, Config.load, check_body):
        where = (function.__code__.co_filename, function.__code__.co_firstlineno,
                 function.__code__.co_name)
        assert calls.get(where) == 1, (function.__qualname__, calls.get(where))


def test_the_parser_is_light() -> None:
    """Building the parser (and printing ``stealth --help``) imports the modules of names only:
    no pymunk, scipy or shapely, at most 12 modules of the project (a fresh interpreter)."""
    code = ("import json, sys\n"
            "from headless.cli import build_parser\n"
            "build_parser().format_help()\n"
            "print(json.dumps(sorted(sys.modules)))\n")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                            timeout=60)
    assert result.returncode == 0, result.stderr
    loaded = json.loads(result.stdout)
    assert not {"pymunk", "scipy", "shapely"} & set(loaded)
    project = [m for m in loaded if m.split(".")[0] in ("navmesh", "ai", "game", "headless")]
    assert "headless.cli" in project and len(project) <= 12, project


def test_the_lazy_choices_still_check_and_list_the_registered_names(
        capsys: pytest.CaptureFixture) -> None:
    from ai import GUARD_MODES, PLAYER_POLICIES
    from headless.cli import build_parser

    parser = build_parser()
    args = parser.parse_args(["sim", "maze", "--guards", "staleness", "--player", "safetygraph"])
    assert (args.guards, args.player) == ("staleness", "safetygraph")
    assert main(["sim", "maze", "--player", "sniper"]) == 2
    error = capsys.readouterr().err
    assert "invalid choice: 'sniper'" in error and all(p in error for p in PLAYER_POLICIES)
    with pytest.raises(SystemExit):
        main(["sim", "--help"])
    shown = " ".join(capsys.readouterr().out.split())
    assert "guard mode: " + ", ".join(GUARD_MODES) in shown
