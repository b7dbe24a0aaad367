"""Hostile cases against this session's additions (issue 35, docs/hostile-inputs.md "Round 4:
this session's additions"): registrations are checked when they are made, built-in names
stay built in, plugin code cannot break a command's output, and ``stealth analyse``'s
outputs and inputs are one line each."""

from __future__ import annotations

import dataclasses
import json
import os
import sqlite3
from pathlib import Path

import pytest
from test_paired import _sweep
from test_registry import _install, _stealth

import ai
from ai.baselines import RandomWalkGuards
from ai.bounds import NON_NEGATIVE
from ai.errors import PluginError, StimulusError
from ai.params import Params
from ai.stimuli import STIMULUS_TYPES, Stimulus, register_stimulus, unregister_stimulus
from headless.analysis.markers import replace_marked
from headless.analysis.paired import main as paired_main
from headless.analysis.reproducible import save_figure
from headless.errors import UserError
from navmesh.level import register_zone_kind
from navmesh.level_fields import zone_kinds


@dataclasses.dataclass(frozen=True)
class SpeedParams(Params):
    speed: float = 1.0
    bounds = {"speed": NON_NEGATIVE}


@pytest.mark.parametrize("name", ["", "a b", "x=y", "a/b", "a.b", "a\nb", " pf", 5, "x" * 65])
def test_a_mode_or_policy_name_that_is_no_word_is_refused(name: object) -> None:
    """A trial's key joins names with '/', --set splits at '.' and '=': such a name would be
    accepted and break a store or a config later."""
    with pytest.raises(ValueError, match="name must be"):
        ai.register_guard_mode(name, RandomWalkGuards)  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="name must be"):
        ai.register_player_policy(name, "ai.players:EvadePlayer")  # type: ignore[arg-type]
    assert name not in ai.GUARD_MODES and name not in ai.PLAYER_POLICIES


@pytest.mark.parametrize(("option", "value", "message"), [
    ("display", "a\nb", "display must be one line"),
    ("display", "", "display must be a non-empty"),
    ("short", "x" * 10**6, "short must be at most 64"), ("abbrev", 5, "abbrev must be a string"),
    ("section", "a.b", "section must be a word"),
    ("params", {"speed": 1}, "params must be a dataclass"),
    ("params", SpeedParams(), "params must be a dataclass"),
    ("factory", 42, "factory must be callable"),
])
def test_a_bad_declaration_is_refused_naming_it(option: str, value: object, message: str) -> None:
    kwargs = {"factory": RandomWalkGuards, option: value}
    with pytest.raises(ValueError, match=message):
        ai.register_guard_mode("odd", **kwargs)  # type: ignore[arg-type]
    assert "odd" not in ai.GUARD_MODES


def test_built_in_modes_and_policies_stay_built_in() -> None:
    """An installed package or a notebook replacing pf would change the paper preset's
    results without a word."""
    before = ai.GUARD_MODES["pf"]
    with pytest.raises(ValueError, match="pf: a built-in guard mode"):
        ai.register_guard_mode("pf", RandomWalkGuards)
    with pytest.raises(ValueError, match="maxmin: a built-in player policy"):
        ai.register_player_policy("maxmin", "ai.players:EvadePlayer")
    ai.unregister_guard_mode("pf")
    with pytest.raises(ValueError, match="stays registered"):
        del ai.GUARD_MODES["pf"]
    assert ai.GUARD_MODES["pf"] is before
    ai.register_guard_mode("sentry2", RandomWalkGuards)  # another name: fine, and replaceable
    ai.register_guard_mode("sentry2", RandomWalkGuards, display="Sentry")
    ai.unregister_guard_mode("sentry2")


def test_a_lazy_reference_that_names_nothing_and_a_factory_of_nothing_are_plugin_errors() -> None:
    ai.register_guard_mode("lazy", "no_such_module_xyz:Guards")
    ai.register_guard_mode("nothing", lambda params: None)
    try:
        with pytest.raises(PluginError, match="lazy: cannot import 'no_such_module_xyz:Guards'"):
            ai.make_guard_ai("lazy")
        with pytest.raises(PluginError, match="nothing: its factory returned NoneType"):
            ai.make_guard_ai("nothing")
    finally:
        ai.unregister_guard_mode("lazy")
        ai.unregister_guard_mode("nothing")


def test_a_plugin_stimulus_cannot_take_a_built_in_name() -> None:
    built_in = STIMULUS_TYPES["corpse"]

    class FakeCorpse(Stimulus):
        name = "corpse"

    with pytest.raises(StimulusError, match="corpse: a built-in stimulus"):
        register_stimulus(FakeCorpse)
    unregister_stimulus("corpse")
    assert STIMULUS_TYPES["corpse"] is built_in


@pytest.mark.parametrize(("bounds", "message"), [
    ({"amplitude": NON_NEGATIVE, "ghost": NON_NEGATIVE}, "bounds names 'ghost', which is no field"),
    ({"amplitude": (0, 1)}, r"bounds\['amplitude'\] must be an ai.bounds bound"),
])
def test_a_stimulus_parameter_class_declares_bounds_of_its_fields(bounds, message) -> None:
    """A tuple for a bound was an AttributeError traceback at the first trial."""
    params = dataclasses.make_dataclass("BellParams", [("amplitude", float, 1.0)],
                                        bases=(Params,), frozen=True)
    params.bounds = bounds  # type: ignore[attr-defined]

    class Bell(Stimulus):
        name, parameters = "bell4", params

    with pytest.raises(StimulusError, match=message):
        register_stimulus(Bell)
    assert "bell4" not in STIMULUS_TYPES


@pytest.mark.parametrize(("attr", "value"), [("section", "a.b"), ("section", "x=y"),
                                             ("display", "a\nb"), ("short", "x" * 10**6)])
def test_a_stimulus_section_is_a_word_and_its_labels_one_short_line(attr, value) -> None:
    cls = type("Bell", (Stimulus,), {"name": "bell5", attr: value})
    with pytest.raises(StimulusError, match=f"bell5: {attr} must be"):
        register_stimulus(cls)


@pytest.mark.parametrize("kind", ["guard", "Walls", "player", "OUTLINE", "Dark", "a b", ""])
def test_a_zone_kind_named_like_a_tiled_class_or_no_word_is_refused(kind: str) -> None:
    """A map's guard spawns would have become zones of kind 'guard' without a word."""
    before = zone_kinds()
    with pytest.raises(ValueError, match="zone kind"):
        register_zone_kind(kind)
    assert zone_kinds() == before


def test_installed_code_cannot_replace_pf_nor_break_json(tmp_path: Path) -> None:
    head = "import ai\nfrom ai.baselines import RandomWalkGuards\n"
    (tmp_path / "a").mkdir()
    site = _install(tmp_path / "a", "hpkg",
                    head + "ai.register_guard_mode('pf', RandomWalkGuards)\n", "m = hpkg")
    done = _stealth(site, "sim", "maze", "--set", "world.duration=2", "--json")
    assert done.returncode == 2 and done.stdout == ""
    assert done.stderr.splitlines() == [
        "stealth: error: m: cannot load entry point 'hpkg' (stealthfield.guard_modes): "
        "ValueError: pf: a built-in guard mode; register yours under a name of its own"]
    (tmp_path / "b").mkdir()
    site = _install(tmp_path / "b", "hpkg", head + "print('hello')\n"
                    "ai.register_guard_mode('hp', RandomWalkGuards)\n", "m = hpkg")
    done = _stealth(site, "sim", "maze", "--guards", "hp", "--set", "world.duration=2", "--json")
    assert done.returncode == 0 and json.loads(done.stdout)["guards"] == "hp"
    assert "hello" in done.stderr
    (tmp_path / "c").mkdir()
    site = _install(tmp_path / "c", "hpkg", "class Boom(BaseException):\n    pass\n"
                    "raise Boom('x')\n", "m = hpkg")
    done = _stealth(site, "sim", "maze")
    assert done.returncode == 2 and "Traceback" not in done.stderr
    assert done.stderr.splitlines()[-1].endswith("Boom: x") and len(done.stderr.splitlines()) == 1


def test_write_and_figure_outputs_that_are_no_file_are_one_line(tmp_path: Path) -> None:
    """--write to a FIFO waited for ever; --figure to a folder wrote folder.png beside it."""
    fifo = tmp_path / "pipe.md"
    os.mkfifo(fifo)
    with pytest.raises(UserError, match="is a FIFO"):
        replace_marked(fifo, "<!-- a -->", "<!-- b -->", "x")
    with pytest.raises(UserError, match="is a directory"):
        replace_marked(tmp_path, "<!-- a -->", "<!-- b -->", "x")
    with pytest.raises(UserError, match="cannot read"):
        replace_marked(tmp_path / "missing.md", "<!-- a -->", "<!-- b -->", "x")
    with pytest.raises(UserError, match="is a directory; a figure is written to a file"):
        save_figure(object(), tmp_path)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["pipe.md"]


def test_paired_refuses_no_pairs_and_a_store_without_the_metric(tmp_path: Path, capsys) -> None:
    """--guards of a mode neither store ran printed an empty table with exit 0; a store of
    another version (no backtracks column) was a ValueError traceback."""
    control = _sweep(tmp_path, "control")
    assert paired_main([str(control), str(control), "--guards", "nosuch"]) == 2
    assert "no trial of guard mode 'nosuch'" in capsys.readouterr().err
    with sqlite3.connect(control / "results.sqlite") as db:
        db.execute("UPDATE trials SET backtracks = NULL")
    assert paired_main([str(control), str(control)]) == 2
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and "for backtracks (a store of another version" in err[0]


@pytest.mark.parametrize("analysis", ["held-out", "robustness"])
def test_an_analysis_refuses_a_directory_as_its_figure_before_writing_anything(
        analysis: str, tmp_path: Path, capsys) -> None:
    """held-out drew --figure DIR as DIR.png beside it; a refusal after --write had
    already been rewritten would leave half the outputs."""
    from headless.cli import main

    doc = tmp_path / "doc.md"
    doc.write_text("<!-- a -->\n<!-- b -->\n", encoding="utf-8")
    folder = tmp_path / "figures"
    folder.mkdir()
    assert main(["analyse", analysis, str(tmp_path), "--figure", str(folder),
                 "--write", str(doc)]) == 2
    err = capsys.readouterr().err.splitlines()
    assert err == [f"stealth: error: --figure/--write {folder}: is a directory; it names a file"]
    assert doc.read_text(encoding="utf-8") == "<!-- a -->\n<!-- b -->\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["doc.md", "figures"]


def test_two_installed_packages_cannot_register_one_name(tmp_path: Path) -> None:
    """Which one won depended on the order the packages were found in, without a word."""
    for package, guards in (("pkga", "RandomWalkGuards"), ("pkgb", "CheatGuards")):
        _install(tmp_path, package, "import ai\nfrom ai.baselines import RandomWalkGuards, "
                 f"CheatGuards\nai.register_guard_mode('patrol', {guards})\n",
                 f"{package} = {package}")
    done = _stealth(tmp_path, "sim", "maze", "--guards", "patrol")
    assert done.returncode == 2 and len(done.stderr.splitlines()) == 1
    assert "registers guard mode 'patrol' again, which another package" in done.stderr
