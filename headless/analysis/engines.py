"""Two results stores of one design, run on the two engines, compared trial by trial.

``stealth analyse engines PYMUNK_DIR BATCH_DIR [--write docs/results.md]`` pairs the
trials of two stores by key (the engine is not part of it, SPEC §12) and counts the pairs
equal in every stored metric and in both heatmaps, per guard mode and abstraction, with
the first differing trials named. The engines are meant to agree exactly: a difference is
a rule one of them reads differently, never noise. With ``--write`` the table replaces the
``<!-- engines -->`` part of the Markdown file.
"""

from __future__ import annotations

import sys
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from game.metrics import metric_names

from ..commands.failure import GuardedParser, guarded, wants_debug
from ..errors import UserError
from ..store import STORE_NAME, ResultStore
from .markers import replace_marked

__all__ = ["agreement", "agreement_table", "main", "run"]

BEGIN, END = "<!-- engines -->", "<!-- /engines -->"


def _load(directory: Path) -> dict[str, Mapping[str, Any]]:
    if not (directory / STORE_NAME).is_file():
        raise UserError(f"{directory}: no {STORE_NAME} here")
    with ResultStore(directory / STORE_NAME, readonly=True) as store:
        return {str(t["key"]): t for t in store.trials(heatmaps=True)}


def _differs(a: Mapping[str, Any], b: Mapping[str, Any]) -> list[str]:
    """The stored values two trials do not share (metrics, then heatmaps)."""
    names = [m for m in metric_names() if m in a or m in b]
    out = [m for m in names if a.get(m) != b.get(m)]
    out += [h for h in ("visits", "attacks") if list(a.get(h) or []) != list(b.get(h) or [])]
    return out


def agreement(reference: Path, batch: Path) -> dict[str, Any]:
    """Pairs, equal pairs per (guard mode, abstraction), and the first differences."""
    a, b = _load(reference), _load(batch)
    keys = sorted(set(a) & set(b))
    if not keys:
        raise UserError(f"{reference} and {batch}: no trial with the same key in both")
    cells: dict[tuple[str, str], list[int]] = {}
    differences: list[tuple[str, list[str]]] = []
    for key in keys:
        cell = cells.setdefault((str(a[key]["guards"]), str(a[key]["abstraction"])), [0, 0])
        cell[0] += 1
        differs = _differs(a[key], b[key])
        if differs:
            differences.append((key, differs))
        else:
            cell[1] += 1
    return {"pairs": len(keys), "equal": len(keys) - len(differences), "cells": cells,
            "differences": differences, "only_reference": len(set(a) - set(b)),
            "only_batch": len(set(b) - set(a))}


def agreement_table(result: Mapping[str, Any], reference: str, batch: str) -> str:
    """The result of :func:`agreement` as Markdown."""
    lines = [f"Trials paired by key: **{result['pairs']}**; equal in every stored metric and "
             f"both heatmaps: **{result['equal']}** "
             f"(`{reference}` on the pymunk engine, `{batch}` on the batch engine; "
             f"{result['only_reference']} only in the first, {result['only_batch']} only in "
             "the second).", "",
             "| guard mode | abstraction | pairs | equal |", "|---|---|---|---|"]
    for (guards, abstraction), (pairs, equal) in sorted(result["cells"].items()):
        lines.append(f"| {guards} | {abstraction} | {pairs} | {equal} |")
    for key, differs in result["differences"][:10]:
        lines.append(f"\n* differs: `{key[:90]}`: {', '.join(differs)}")
    return "\n".join(lines) + "\n"


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m headless.analysis.engines``: its exit code (1 when a pair differs)."""
    words = list(sys.argv[1:] if argv is None else argv)
    return guarded(lambda: run(words), wants_debug(words))


def run(argv: Sequence[str], prog: str = "python -m headless.analysis.engines") -> int:
    """The analysis of the command line ``argv``, unguarded (:func:`main` and ``stealth
    analyse engines`` guard it)."""
    parser = GuardedParser(prog=prog, description=(__doc__ or "").split("\n\n")[0])
    parser.add_argument("reference", type=Path, help="results directory run on the pymunk engine")
    parser.add_argument("batch", type=Path, help="results directory run on the batch engine")
    parser.add_argument("--write", type=Path, default=None,
                        help="replace the <!-- engines --> part of this Markdown file")
    args = parser.parse_args(argv)
    result = agreement(args.reference, args.batch)
    text = agreement_table(result, args.reference.name, args.batch.name)
    if args.write is not None and not replace_marked(args.write, BEGIN, END, text):
        raise UserError(f"{args.write}: no {BEGIN} ... {END} markers")
    sys.stdout.write(text)
    return 0 if result["equal"] == result["pairs"] else 1


if __name__ == "__main__":
    raise SystemExit(main())
