"""docs/results.md's tables: ours beside the paper's, written between markers."""

from __future__ import annotations

import csv
from pathlib import Path

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
