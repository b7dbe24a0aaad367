"""How robust are the paper's claims? Each main claim judged in every cell of a two-factor design.

``python -m headless.robustness DIR [--write docs/results.md] [--figure robustness.png]``
reads a store whose design crosses exactly two numeric factors (e.g. the
``paper-robustness`` preset: player speed x view range) and judges, per abstraction and
factor cell, each claim of :data:`CLAIMS`. A claim is a set of comparisons "mode A above
mode B" on one Table 3 measure; a comparison is the mean of the **paired** differences
A − B over the trials of one identity (level, player policy, scenario, seed: the same
spawns), with a 95 % percentile-bootstrap CI (:func:`headless.analysis.stats.bootstrap_ci`). A
comparison **holds** when its CI lies above 0, **fails** when it lies below 0 (the reverse
is shown) and is **undecided** otherwise; a claim holds when all its comparisons hold,
fails when any fails, and is undecided otherwise. No correction for the several
comparisons of a claim or the many cells is made: each verdict is at 95 % on its own.

``--write`` puts the Markdown tables between ``<!-- robustness -->`` markers of the file
(appending a ``## How robust are the paper's claims?`` section with them at its end when
the markers are missing); ``--figure`` draws one panel per claim and abstraction.
"""

from __future__ import annotations

import argparse
import math
import sys
import tomllib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ai import GUARD_MODES, Names

from .reproducible import save_figure
from ..commands.failure import GuardedParser, guarded, wants_debug
from ..outputs.clobber import refuse_inputs_all
from ..errors import UserError
from .markers import replace_marked
from .factor_report import numeric_factors
from .stats import bootstrap_ci
from ..store import STORE_NAME, ResultStore
from .tables import ABSTRACTION_NAMES, GUARD_NAMES, _Durations, label, metric_value, table_columns

__all__ = ["CLAIMS", "Axes", "Claim", "Judgement", "Verdict", "axes_of", "draw", "judge",
           "main", "markdown", "run", "write_between_markers"]

START, END = "<!-- robustness -->", "<!-- /robustness -->"
SECTION = "## How robust are the paper's claims?"


@dataclass(frozen=True)
class Claim:
    """One claim of the paper: on ``measure`` (a Table 3 column), ``a`` above ``b`` for each pair."""

    name: str
    title: str
    measure: str
    pairs: tuple[tuple[str, str], ...]


PAPER_CLAIMS = Path(__file__).resolve().parent.parent / "targets" / "paper-claims.toml"
"""The paper's main claims, transcribed as data (like its Table 3, they name guard modes)."""


def _load_claims(path: Path) -> tuple[Claim, ...]:
    with path.open("rb") as handle:
        claims = tomllib.load(handle)["claim"]
    return tuple(Claim(c["name"], c["title"], c["measure"],
                       tuple((a, b) for a, b in c["pairs"])) for c in claims)


CLAIMS: tuple[Claim, ...] = _load_claims(PAPER_CLAIMS)
"""The paper's main claims as comparisons (``(a, b)``: a's value exceeds b's)."""


@dataclass(frozen=True)
class Verdict:
    """One comparison in one cell: paired pairs, mean difference a − b and its 95 % CI."""

    a: str
    b: str
    pairs: int
    mean: float
    low: float
    high: float

    @property
    def outcome(self) -> str:
        """``holds`` (CI above 0), ``fails`` (below 0) or ``undecided``."""
        if self.pairs and self.low > 0:
            return "holds"
        if self.pairs and self.high < 0:
            return "fails"
        return "undecided"


@dataclass(frozen=True)
class Judgement:
    """One claim in one abstraction and factor cell: its comparisons and overall outcome."""

    claim: Claim
    abstraction: str
    cell: tuple[float, float]
    verdicts: tuple[Verdict, ...]

    @property
    def outcome(self) -> str:
        """``holds`` when every comparison holds, ``fails`` when any fails, else ``undecided``."""
        outcomes = [v.outcome for v in self.verdicts]
        if outcomes and all(o == "holds" for o in outcomes):
            return "holds"
        return "fails" if "fails" in outcomes else "undecided"

    @property
    def decisive(self) -> Verdict:
        """The comparison that decides the outcome: a failing one if any, else the weakest
        (lowest CI bound)."""
        failing = [v for v in self.verdicts if v.outcome == "fails"]
        return min(failing or self.verdicts, key=lambda v: (v.high if failing else v.low))


def _values(trials: Sequence[Mapping[str, Any]], measure: str,
            keys: tuple[str, str]) -> dict[tuple[Any, ...], float]:
    """``{(abstraction, factor cell, guards, level, player, seed): value}`` of ``measure``."""
    column = next((c for c in table_columns() if c.name == measure), None)
    if column is None:
        raise UserError(f"no Table 3 column {measure!r}")
    durations = _Durations()
    out: dict[tuple[Any, ...], float] = {}
    for trial in trials:
        if trial["scenario"] != column.scenario:
            continue
        factors = trial.get("factors", {})
        value = metric_value(trial, column, durations({**trial["overrides"], **factors}))
        if value is None:
            continue
        cell = (float(factors[keys[0]]), float(factors[keys[1]]))
        out[(trial["abstraction"], cell, trial["guards"], trial["level"], trial["player"],
             trial["seed"], trial.get("root_seed", 0))] = value
    return out


def judge(trials: Sequence[Mapping[str, Any]], claims: Sequence[Claim] = CLAIMS,
          ) -> tuple[tuple[str, str], list[Judgement]]:
    """The two numeric factors of ``trials`` and every claim judged per abstraction and cell.

    A comparison uses only the identities where both modes have a value (a partly run
    store is judged on its complete pairs). Raises :class:`UserError` unless the trials
    cross exactly two numeric factors.
    """
    factors = numeric_factors(trials)
    if len(factors) != 2:
        raise UserError("robustness needs a design of exactly two numeric factors, found "
                        + (", ".join(factors) or "none"))
    keys = (sorted(factors)[0], sorted(factors)[1])
    abstractions = list(dict.fromkeys(t["abstraction"] for t in trials))
    cells = [(x, y) for x in factors[keys[0]] for y in factors[keys[1]]]
    judgements = []
    for claim in claims:
        values = _values(trials, claim.measure, keys)
        by_group: dict[tuple[Any, ...], dict[tuple[Any, ...], float]] = {}
        for (abstraction, cell, guards, *identity), value in values.items():
            by_group.setdefault((abstraction, cell, guards), {})[tuple(identity)] = value
        for abstraction in abstractions:
            for cell in cells:
                verdicts = []
                for a, b in claim.pairs:
                    va = by_group.get((abstraction, cell, a), {})
                    vb = by_group.get((abstraction, cell, b), {})
                    common = sorted(set(va) & set(vb))
                    diff = np.array([va[k] - vb[k] for k in common], dtype=np.float64)
                    low, high = bootstrap_ci(diff, f"robustness/{claim.name}/{abstraction}/"
                                             f"{cell[0]}/{cell[1]}/{a}-{b}")
                    verdicts.append(Verdict(a, b, len(common),
                                            float(diff.mean()) if len(diff) else math.nan,
                                            low, high))
                judgements.append(Judgement(claim, abstraction, cell, tuple(verdicts)))
    return keys, judgements


#: a mode's name in a verdict: its registered ``abbrev`` (:mod:`ai`)
_SHORT = Names(GUARD_MODES, "abbrev")
_MARK = {"holds": "✓", "fails": "✗", "undecided": "?"}


def _short(guard: str) -> str:
    return _SHORT.get(guard, guard)


def _cell_text(j: Judgement) -> str:
    v = j.decisive
    return (f"{_MARK[j.outcome]} {_short(v.a)}−{_short(v.b)} {v.mean:+.2f} "
            f"[{v.low:+.2f}, {v.high:+.2f}]")


def markdown(judgements: Sequence[Judgement], axes: Axes) -> str:
    """One table per abstraction: a row per factor cell, a column per claim."""
    names = axes.names
    claims = list(dict.fromkeys(j.claim for j in judgements))
    lines = ["Each entry: ✓ holds / ✗ fails / ? undecided, then the deciding comparison "
             "(a failing one, else the one with the lowest CI bound): its mean paired "
             "difference and 95 % bootstrap CI. Claims: "
             + "; ".join(f"**{c.name}** {c.title}" for c in claims) + ".", ""]
    for abstraction in dict.fromkeys(j.abstraction for j in judgements):
        rows = [j for j in judgements if j.abstraction == abstraction]
        cells = list(dict.fromkeys(j.cell for j in rows))
        pairs = min(v.pairs for j in rows for v in j.verdicts)
        lines += [f"**{label(ABSTRACTION_NAMES, abstraction)}** (at least {pairs} pairs "
                  "per comparison)", "",
                  f"| {names[0]} | {names[1]} | " + " | ".join(c.name for c in claims) + " |",
                  "|---:|---:|" + "---|" * len(claims)]
        for cell in cells:
            found = {j.claim.name: j for j in rows if j.cell == cell}
            lines.append(f"| {axes.tick(0, cell[0])} | {axes.tick(1, cell[1])} | "
                         + " | ".join(_cell_text(found[c.name]) for c in claims) + " |")
        held = sum(j.outcome == "holds" for j in rows)
        failed = sum(j.outcome == "fails" for j in rows)
        lines += ["", f"{held} of {len(rows)} verdicts hold, {failed} fail, "
                  f"{len(rows) - held - failed} undecided.", ""]
    return "\n".join(lines)


_COLOURS = {"holds": "#4c9a52", "fails": "#c8453c", "undecided": "#c9c9c9"}


def draw(judgements: Sequence[Judgement], path: Path, axes: Axes) -> None:
    """A panel per claim (rows) and abstraction (columns): each factor cell coloured by its
    outcome and labelled with the deciding comparison's mean difference."""
    from matplotlib.figure import Figure
    from matplotlib.patches import Patch

    names = axes.names
    claims = list(dict.fromkeys(j.claim for j in judgements))
    abstractions = list(dict.fromkeys(j.abstraction for j in judgements))
    xs = sorted({j.cell[0] for j in judgements})
    ys = sorted({j.cell[1] for j in judgements})
    fig = Figure(figsize=(4.2 * len(abstractions), 3.0 * len(claims) + 0.8), dpi=100)
    for r, claim in enumerate(claims):
        for c, abstraction in enumerate(abstractions):
            ax = fig.add_subplot(len(claims), len(abstractions), r * len(abstractions) + c + 1)
            for j in judgements:
                if j.claim != claim or j.abstraction != abstraction:
                    continue
                i, k = xs.index(j.cell[0]), ys.index(j.cell[1])
                ax.add_patch(_rect(i, k, _COLOURS[j.outcome]))
                v = j.decisive
                ax.text(i, k, f"{_short(v.a)}−{_short(v.b)}\n{v.mean:+.2f}\n"
                        f"[{v.low:+.2f}, {v.high:+.2f}]", ha="center", va="center", fontsize=7)
            ax.set_xlim(-0.5, len(xs) - 0.5)
            ax.set_ylim(-0.5, len(ys) - 0.5)
            ax.set_xticks(range(len(xs)), [axes.tick(0, x) for x in xs], fontsize=7)
            ax.set_yticks(range(len(ys)), [axes.tick(1, y) for y in ys], fontsize=7)
            ax.set_xlabel(names[0], fontsize=7)
            ax.set_ylabel(names[1], fontsize=7)
            ax.set_title(f"{label(ABSTRACTION_NAMES, abstraction)}: {claim.title}", fontsize=7)
    fig.legend(handles=[Patch(color=colour, label=name) for name, colour in _COLOURS.items()],
               loc="lower center", ncol=3, fontsize=8)
    fig.suptitle("The paper's claims per factor cell. In each cell the deciding comparison "
                 "A−B:\nmean paired difference [95 % bootstrap CI]", fontsize=9)
    fig.tight_layout(rect=(0, 0.03, 1, 0.98))
    save_figure(fig, path)


def _rect(i: int, k: int, colour: str) -> Any:
    from matplotlib.patches import Rectangle

    return Rectangle((i - 0.5, k - 0.5), 1, 1, facecolor=colour, edgecolor="white")


@dataclass(frozen=True)
class Axes:
    """Titles of the two factors and how a level of each is written (tables, ticks)."""

    names: tuple[str, str]
    ticks: tuple[Mapping[float, str], Mapping[float, str]]

    def tick(self, axis: int, value: float) -> str:
        """A level as written on ``axis`` (its value when nothing else is known)."""
        return self.ticks[axis].get(value, f"{value:g}")


def axes_of(keys: tuple[str, str], trials: Sequence[Mapping[str, Any]]) -> Axes:
    """The factors' titles and tick labels: a ``world.player_speed`` level is written with
    the player/guard speed ratio it gives in the fixed-time scenario, ``1.6 (0.8)``."""
    from game.config import Config

    config = Config.load(dict(trials[0]["overrides"]) if trials else {})
    names: list[str] = []
    ticks: list[dict[float, str]] = []
    for key in keys:
        levels = sorted({float(t["factors"][key]) for t in trials if key in t.get("factors", {})})
        if key == "world.player_speed":
            unit = (float(config["scenario.fixed.player_speed_scale"])
                    / float(config["world.guard_speed"]))
            names.append(f"{key} (player/guard speed ratio)")
            ticks.append({v: f"{v:g} ({v * unit:.2g})" for v in levels})
        else:
            names.append(key)
            ticks.append({})
    return Axes((names[0], names[1]), (ticks[0], ticks[1]))


def write_between_markers(path: Path, text: str) -> None:
    """Replace what is between the markers of ``path`` with ``text``; without markers,
    append the section heading and the marked text at the end."""
    body = text.rstrip() + "\n"
    if path.exists() and replace_marked(path, START, END, body):
        return
    old = path.read_text(encoding="utf-8") if path.exists() else ""
    block = f"{START}\n{body}{END}"
    path.write_text(old.rstrip("\n") + ("\n\n" if old else "") + f"{SECTION}\n\n{block}\n",
                    encoding="utf-8")


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m headless.robustness``: its exit code; every failure one ``stealth: error:`` line
    (:func:`headless.commands.failure.guarded`, as for ``stealth``)."""
    words = list(sys.argv[1:] if argv is None else argv)
    return guarded(lambda: run(words), wants_debug(words))


def run(argv: Sequence[str], prog: str = "python -m headless.robustness") -> int:
    """The analysis of the command line ``argv``, unguarded: :func:`main` guards it, and so
    does ``stealth analyse`` (``prog`` names the command in the help)."""
    parser = GuardedParser(prog=prog, description=(__doc__ or "").split("\n\n")[0])
    parser.add_argument("store", type=Path, help="results directory of a two-factor design")
    parser.add_argument("--write", type=Path, default=None,
                        help="Markdown file to put the tables into (between the markers)")
    parser.add_argument("--figure", type=Path, default=None, help="PNG of the verdicts")
    args = parser.parse_args(argv)
    try:
        refuse_inputs_all("--figure/--write", [p for p in (args.figure, args.write) if p],
                          [args.store / STORE_NAME])
        if not (args.store / STORE_NAME).is_file():
            raise UserError(f"{args.store}: no {STORE_NAME} here")
        with ResultStore(args.store / STORE_NAME, readonly=True) as store:
            trials = list(store.trials())
        keys, judgements = judge(trials)
    except UserError as error:
        print(f"stealth: error: {error}", file=sys.stderr)
        return 2
    axes = axes_of(keys, trials)
    text = markdown(judgements, axes)
    if args.write is not None:
        write_between_markers(args.write, text)
    else:
        sys.stdout.write(text)
    if args.figure is not None:
        args.figure.parent.mkdir(parents=True, exist_ok=True)
        draw(judgements, args.figure, axes)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
