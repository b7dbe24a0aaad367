"""Issue 11, class 4: file names made from user data stay inside the output directory.

Level names such as ``../../x``, ``a/b``, ``NUL``, a NUL character or non-ASCII text used to
be pasted into the report's heatmap names: ``..`` wrote outside the results directory, ``/``
and NUL crashed the report. Every writer now asks :func:`headless.outputs.filenames.output_path`.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from headless.cli import main
from headless.presets import load_preset
from headless.analysis.report import write_report
from headless.sweep import run_sweep

ROOT = Path(__file__).resolve().parent.parent
HOSTILE = ["../../x", "a/b", "a-b", "A-B", "a_b", "NUL", "\x00", "Münster", "..", "ok"]
SAFE = re.compile(r"[a-z0-9.-]+(_[a-z0-9.-]+)*\.(csv|png|svg)")

PRESET = """
levels = {levels}
abstractions = ["grid"]
guards = ["random"]
players = ["evade"]
scenarios = ["capture"]
seeds = 1

[set]
"world.duration" = 1.0
"""


def level_named(folder: Path, index: int, name: str) -> Path:
    data = json.loads((ROOT / "assets" / "levels" / "maze.json").read_text(encoding="utf-8"))
    data["name"] = name
    path = folder / f"level{index}.json"
    path.write_text(json.dumps(data), encoding="utf-8")
    return path


def test_a_report_of_hostile_level_names_stays_inside_and_keeps_every_level(tmp_path: Path) -> None:
    inputs = tmp_path / "inputs"
    inputs.mkdir()
    levels = [str(level_named(inputs, i, name)) for i, name in enumerate(HOSTILE)]
    preset = inputs / "hostile.toml"
    preset.write_text(PRESET.format(levels=json.dumps(levels)), encoding="utf-8")
    out = tmp_path / "a" / "b" / "results"
    run_sweep(load_preset(str(preset)), out, workers=1, progress=False)
    before = {p for p in tmp_path.rglob("*") if not p.is_relative_to(out)}

    written = write_report(out, figures=True)

    after = {p for p in tmp_path.rglob("*") if not p.is_relative_to(out)}
    assert after == before  # nothing outside the results directory
    heat = sorted(p.name for p in (out / "heatmaps").iterdir())
    # per level: a visit and an attack CSV of its one mode, and the two figures as PNG + SVG
    assert len(heat) == len(HOSTILE) * (2 + 2 * 2)
    assert all(SAFE.fullmatch(name) for name in heat), heat
    assert all(p.resolve().is_relative_to(out.resolve()) for p in written)
    assert "ok_grid_random_visit.csv" in heat  # a plain name keeps its file name


@pytest.mark.parametrize("name", HOSTILE + ["con", "x" * 300, "\ud800", "a\nb", "\u202egnp.exe"])
def test_every_name_is_a_safe_part_inside_the_directory(tmp_path: Path, name: str) -> None:
    from headless.outputs.filenames import output_path, safe_part

    part = safe_part(name)
    assert re.fullmatch(r"[a-z0-9.-]+", part) and not part.startswith((".", "-")), part
    assert len(part) <= 64
    path = output_path(tmp_path, name, "grid", suffix=".csv")
    assert path.parent == tmp_path
    path.write_text("x", encoding="utf-8")  # the file system takes it


def test_names_whose_slugs_collide_get_distinct_files() -> None:
    from headless.outputs.filenames import output_path, safe_part

    names = ["a/b", "a-b", "A-B", "a_b", "a?b", "a b", "a--b"]
    parts = {safe_part(n) for n in names}
    assert len(parts) == len(names)
    stems = {output_path("out", level, mode).name for level, mode in
             [("a_b", "c"), ("a", "b_c"), ("a-b", "c"), ("a", "b-c")]}
    assert len(stems) == 4  # "_" joins parts and never occurs inside one


def test_the_default_results_directory_of_a_dotted_preset_name_stays_in_results(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.chdir(tmp_path)
    (tmp_path / "...toml").write_text(PRESET.format(levels='["maze"]'), encoding="utf-8")
    assert main(["run", "--preset", "...toml", "--workers", "1"]) == 0, capsys.readouterr().err
    assert not (tmp_path / "results.sqlite").exists()  # results/.. is the working directory
    (folder,) = (tmp_path / "results").iterdir()
    assert (folder / "results.sqlite").is_file() and folder.name.startswith("name--")
