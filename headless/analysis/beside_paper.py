"""Our Table 3 beside the paper's: the Markdown tables of docs/results.md, made from reports.

``python -m headless.beside_paper DIR [--literal DIR2]`` reads ``DIR/table.csv`` (and, with
``--literal``, the PF rows of a ``paper-pf-literal`` report) and prints, per abstraction, one
table whose cells are "ours (paper)", the paper's values from
:data:`headless.analysis.paper.PAPER_TABLE3`, followed by ``DIR/table.md``'s full tables. docs/results.md
holds its output between the markers ``<!-- beside-paper -->`` and ``<!-- /beside-paper -->``;
``--write FILE`` replaces that part of FILE in place.
"""

from __future__ import annotations

import argparse
import csv
import io
import sys
from collections.abc import Mapping, Sequence
from pathlib import Path

from ..commands.failure import GuardedParser, guarded, wants_debug
from ..errors import UserError
from ..outputs.clobber import refuse_inputs_all
from .markers import replace_marked
from .paper import paper_table3

__all__ = ["COLUMNS", "beside_paper", "main", "run"]

#: (Table 3 column, the paper table's metric) in the paper's order
COLUMNS: tuple[tuple[str, str], ...] = (
    ("CaptureRate", "captured"), ("CaptureTime", "capture_time"),
    ("CapturesInTime", "captures"), ("CoverageRate", "coverage"),
    ("AvgGuardPlayerDist", "avg_guard_player_dist"), ("FirstDetectTime", "first_detect_time"),
    ("BacktrackCount", "backtracks"),
)
_BEGIN, _END = "<!-- beside-paper -->", "<!-- /beside-paper -->"
_TITLES = {"grid": "Grid", "partition": "Partition"}


#: the columns of a ``stealth report`` table.csv read here (besides each column's ``_mean``)
_KEYS = ("abstraction", "guards", "player", "GuardMode", "PlayerMode")


def _text(path: Path) -> str:
    """``path``'s text; a file that is not UTF-8 is one line naming it."""
    data = path.read_bytes()
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as error:
        raise UserError(f"{path}: not UTF-8 text (byte {error.start}): not a report of "
                        "stealth report") from None


def _rows(path: Path) -> list[dict[str, str]]:
    """The rows of a ``stealth report`` table.csv; another table (missing columns, a mean
    that is not a number) is one line naming the file and what is wrong."""
    rows = list(csv.DictReader(io.StringIO(_text(path), newline="")))
    header = set(rows[0]) if rows else set()
    missing = [c for c in (*_KEYS, *(f"{c}_mean" for c, _ in COLUMNS)) if c not in header]
    if not rows or missing:
        what = "no rows" if not rows else "no column " + ", ".join(missing[:3]) + (
            f" (and {len(missing) - 3} more)" if len(missing) > 3 else "")
        raise UserError(f"{path}: {what}: not a table.csv of stealth report")
    for line, row in enumerate(rows, start=2):
        for column, _ in COLUMNS:
            value = row[f"{column}_mean"]
            try:
                float(value)
            except (TypeError, ValueError):
                raise UserError(f"{path}: line {line}: {column}_mean = {value!r} is not a "
                                "number") from None
    return rows


def _table(abstraction: str, ours: Sequence[Mapping[str, str]],
           literal: Sequence[Mapping[str, str]]) -> list[str]:
    paper = paper_table3()
    head = "| GuardMode | PlayerMode | " + " | ".join(c for c, _ in COLUMNS) + " |"
    lines = [f"**{_TITLES.get(abstraction, abstraction)}** — each cell: ours (paper)", "",
             head, "|---|---|" + "---:|" * len(COLUMNS)]
    for row in ours:
        if row["abstraction"] != abstraction:
            continue
        key = (abstraction, row["guards"], row["player"])
        cells = []
        for column, metric in COLUMNS:
            value = f"{float(row[f'{column}_mean']):.2f}"
            if key in paper and metric in paper[key]:
                value += f" ({paper[key][metric]:.2f})"
            cells.append(value)
        lines.append(f"| {row['GuardMode']} | {row['PlayerMode']} | " + " | ".join(cells) + " |")
        for lit in literal:
            if (lit["abstraction"], lit["guards"], lit["player"]) == key and key[1] == "pf":
                values = " | ".join(f"{float(lit[f'{c}_mean']):.2f}" for c, _ in COLUMNS)
                lines.append(f"| PF, paper-literal | {lit['PlayerMode']} | {values} |")
    return lines


def beside_paper(directory: Path, literal: Path | None = None) -> str:
    """The Markdown of docs/results.md's tables for the report in ``directory``."""
    ours = _rows(directory / "table.csv")
    lit = _rows(literal / "table.csv") if literal is not None else []
    out: list[str] = []
    for abstraction in dict.fromkeys(r["abstraction"] for r in ours):
        out += _table(abstraction, ours, lit) + [""]
    full = _text(directory / "table.md")
    body = full.split("\n## ", 1)[1] if "\n## " in full else full
    out += ["Our full table, with sample standard deviations and 95 % bootstrap confidence "
            "intervals of", "the mean:", "", "## " + body.strip()]
    return "\n".join(out) + "\n"


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m headless.beside_paper``: its exit code; every failure one ``stealth: error:`` line
    (:func:`headless.commands.failure.guarded`, as for ``stealth``)."""
    words = list(sys.argv[1:] if argv is None else argv)
    return guarded(lambda: run(words), wants_debug(words))


def run(argv: Sequence[str], prog: str = "python -m headless.beside_paper") -> int:
    """The analysis of the command line ``argv``, unguarded: :func:`main` guards it, and so
    does ``stealth analyse`` (``prog`` names the command in the help)."""
    parser = GuardedParser(prog=prog, description=__doc__.split("\n\n")[0])
    parser.add_argument("dir", type=Path, help="a report of the paper preset")
    parser.add_argument("--literal", type=Path, default=None,
                        help="a report of the paper-pf-literal preset (its PF rows are added)")
    parser.add_argument("--write", type=Path, default=None,
                        help="replace the marked part of this Markdown file instead of printing")
    args = parser.parse_args(argv)
    if args.write is not None:
        refuse_inputs_all("--write", [args.write], [args.dir / n for n in ("table.csv", "table.md")]
                          + ([args.literal / "table.csv", args.literal / "table.md"]
                             if args.literal else []))
    text = beside_paper(args.dir, args.literal)
    if args.write is None:
        sys.stdout.write(text)
        return 0
    if not replace_marked(args.write, _BEGIN, _END, text):
        print(f"stealth: error: {args.write}: no {_BEGIN} ... {_END} markers", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
