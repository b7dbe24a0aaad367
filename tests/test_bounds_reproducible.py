"""Issue 24 class 6: ``stealth report`` on the same store twice writes byte-identical files.

Every figure goes through :func:`headless.analysis.reproducible.save_figure` (a fixed ``svg.hashsalt``,
no dates): the SVGs, PNGs and every other report file are the same bytes on a second run.
"""

from __future__ import annotations

import shutil
from pathlib import Path

from headless.presets import load_preset
from headless.analysis.report import write_report
from headless.sweep import run_sweep

PRESET = """
levels = ["maze"]
abstractions = ["grid"]
guards = ["random", "pf"]
players = ["maxmin"]
scenarios = ["fixed", "capture"]
seeds = 2

[set]
"world.duration" = 1.0
"""


def _files(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*"))
            if p.is_file() and p.name not in ("results.sqlite", "results.lock")
            and not p.name.startswith("results.sqlite-")}


def test_a_report_twice_is_byte_identical(tmp_path: Path) -> None:
    (tmp_path / "p.toml").write_text(PRESET)
    out = tmp_path / "out"
    run_sweep(load_preset(str(tmp_path / "p.toml")), out, workers=1, progress=False)
    written = write_report(out)
    first = _files(out)
    assert any(p.suffix == ".svg" for p in written) and any(p.suffix == ".png" for p in written)
    copy = tmp_path / "copy"
    shutil.copytree(out, copy)  # another directory too: no path inside a file
    for path in out.rglob("*"):
        if path.is_file() and path.suffix in (".svg", ".png", ".csv", ".md"):
            path.unlink()
    write_report(out)
    write_report(copy)
    second, third = _files(out), _files(copy)
    assert set(first) == set(second) == set(third)
    differ = [name for name in first if first[name] != second[name]]
    assert not differ, differ
    assert b"<dc:date>" not in b"".join(v for k, v in first.items() if k.endswith(".svg"))
