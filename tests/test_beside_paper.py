"""docs/results.md's tables: ours beside the paper's, written between markers."""

from __future__ import annotations

import csv
import subprocess
import sys
from pathlib import Path

import pytest

from headless.analysis.beside_paper import COLUMNS, main


def _report(directory: Path, capture_rate: float) -> Path:
    directory.mkdir()
    fields = ["abstraction", "guards", "player", "GuardMode", "PlayerMode"]
    fields += [f"{c}_mean" for c, _ in COLUMNS]
    with (directory / "table.csv").open("w", newline="", encoding="utf-8") as handle:
        writer = csv.DictWriter(handle, fieldnames=fields)
        writer.writeheader()
        row = {"abstraction": "grid", "guards": "pf", "player": "maxmin",
               "GuardMode": "PotentialField", "PlayerMode": "MaxMin"}
        row.update({f"{c}_mean": 1.0 for c, _ in COLUMNS})
        row["CaptureRate_mean"] = capture_rate
        writer.writerow(row)
    (directory / "table.md").write_text("# Table 3\n\nintro\n\n## Grid environment\n\n| x |\n",
                                        encoding="utf-8")
    return directory


def test_cells_are_ours_with_the_papers_in_brackets_between_the_markers(tmp_path: Path) -> None:
    ours = _report(tmp_path / "paper", 0.314)
    literal = _report(tmp_path / "literal", 0.25)
    doc = tmp_path / "results.md"
    doc.write_text("before\n<!-- beside-paper -->\nold\n<!-- /beside-paper -->\nafter\n",
                   encoding="utf-8")
    assert main([str(ours), "--literal", str(literal), "--write", str(doc)]) == 0
    text = doc.read_text(encoding="utf-8")
    assert text.startswith("before\n<!-- beside-paper -->\n") and text.endswith("after\n")
    assert "old" not in text
    assert "| PotentialField | MaxMin | 0.31 (0.80) | 1.00 (31.70) |" in text  # paper Table 3
    assert "| PF, paper-literal | MaxMin | 0.25 | 1.00 |" in text
    assert "## Grid environment" in text


def test_a_document_without_markers_is_refused(tmp_path: Path) -> None:
    doc = tmp_path / "results.md"
    doc.write_text("no markers\n", encoding="utf-8")
    assert main([str(_report(tmp_path / "paper", 0.5)), "--write", str(doc)]) == 2
    assert doc.read_text(encoding="utf-8") == "no markers\n"


def _stealth(*args: str) -> subprocess.CompletedProcess[bytes]:
    return subprocess.run([sys.executable, "-m", *args], capture_output=True, timeout=120)


def test_analyse_beside_paper_writes_what_python_m_writes(tmp_path: Path) -> None:
    """``stealth analyse beside-paper`` takes the arguments of ``python -m
    headless.beside_paper`` and writes the same bytes, printed or into a marked file."""
    ours = str(_report(tmp_path / "paper", 0.314))
    literal = str(_report(tmp_path / "literal", 0.25))
    printed = [_stealth("headless.beside_paper", ours, "--literal", literal),
               _stealth("headless.cli", "analyse", "beside-paper", ours, "--literal", literal)]
    assert [p.returncode for p in printed] == [0, 0], [p.stderr for p in printed]
    assert printed[0].stdout == printed[1].stdout and b"0.31 (0.80)" in printed[0].stdout
    written = []
    for name, command in (("m", ["headless.beside_paper"]),
                          ("cli", ["headless.cli", "analyse", "beside-paper"])):
        doc = tmp_path / f"results-{name}.md"
        doc.write_text("before\n<!-- beside-paper -->\nold\n<!-- /beside-paper -->\nafter\n",
                       encoding="utf-8")
        done = _stealth(*command, ours, "--write", str(doc))
        assert done.returncode == 0 and done.stdout == b"", done.stderr
        written.append(doc.read_bytes())
    assert written[0] == written[1] and b"old" not in written[0]


@pytest.mark.parametrize(("name", "module", "args"), [
    ("beside-paper", "beside_paper", ["no-such-report"]),
    ("held-out", "held_out", ["no-such-store", "--seeds-from", "-1"]),
    ("robustness", "robustness", ["no-such-store"]),
    ("paired", "paired", ["no-such-arm", "no-such-control"]),
    ("paired", "paired", ["--no-such-option"]),
])
def test_analyse_errors_are_the_same_one_line(tmp_path: Path, name: str, module: str,
                                              args: list[str]) -> None:
    via_m = _stealth(f"headless.{module}", *args)
    via_cli = _stealth("headless.cli", "analyse", name, *args)
    assert via_m.returncode == via_cli.returncode == 2
    assert via_m.stderr == via_cli.stderr and via_cli.stdout == b""
    lines = via_cli.stderr.decode().splitlines()
    assert len(lines) == 1 and lines[0].startswith("stealth: error: "), lines


@pytest.mark.parametrize("table,what", [
    ("a,b\n1,2\n", "no column abstraction, guards, player (and 9 more): not a table.csv"),
    ("", "no rows: not a table.csv of stealth report"),
    (None, "line 2: CaptureTime_mean = 'abc' is not a number"),
    (b"abstraction,guards\n\xff\xfe,1\n", "not UTF-8 text (byte 19)"),
])
def test_a_table_that_is_not_ours_is_one_line_naming_the_file(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], table: str | bytes | None,
        what: str) -> None:
    report = _report(tmp_path / "other", 0.5)
    path = report / "table.csv"
    if table is None:  # our columns, a mean that is not a number
        text = path.read_text(encoding="utf-8").splitlines()
        head = text[0].split(",")
        row = text[1].split(",")
        row[head.index("CaptureTime_mean")] = "abc"
        path.write_text("\n".join([text[0], ",".join(row)]) + "\n", encoding="utf-8")
    elif isinstance(table, bytes):
        path.write_bytes(table)
    else:
        path.write_text(table, encoding="utf-8")
    assert main([str(report)]) == 2
    captured = capsys.readouterr()
    lines = captured.err.splitlines()
    assert captured.out == "" and len(lines) == 1, lines
    assert lines[0] == f"stealth: error: {path}: {what}" or (
        lines[0].startswith(f"stealth: error: {path}: ") and what in lines[0]), lines[0]


def test_a_table_md_that_is_not_utf8_is_one_line(tmp_path: Path,
                                                 capsys: pytest.CaptureFixture[str]) -> None:
    report = _report(tmp_path / "paper", 0.5)
    (report / "table.md").write_bytes(b"# Table\n\xff\n")
    assert main([str(report)]) == 2
    lines = capsys.readouterr().err.splitlines()
    assert lines == [f"stealth: error: {report / 'table.md'}: not UTF-8 text (byte 8): not a "
                     "report of stealth report"]
