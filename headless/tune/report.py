"""The outputs of a ``stealth tune`` study: ``best.toml``, ``study.csv``, ``report.md``,
``history.png`` (the objective of every trial and the best so far) and ``params.png`` (the
objective against each searched parameter; with a target table also the share of cells
within tolerance, which the squared objective can rank differently).

``report.md`` gives the best value on the training seeds and on the held-out seeds, the
best parameters and Optuna's parameter importances (:mod:`optuna.importance`, its default evaluator; when
the study is too small to estimate them that is said instead).
"""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

from game.config_file import write_config_file

from ..analysis.reproducible import save_figure

if TYPE_CHECKING:
    from .spec import TuneSpec

__all__ = ["write_study_outputs"]


def _importances(study: Any) -> dict[str, float] | str:
    import warnings

    import optuna

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return dict(optuna.importance.get_param_importances(study))
    except Exception as error:  # too few trials, a single distinct value, ...
        return f"not available ({type(error).__name__}: {' '.join(str(error).split())})"


def _history(study: Any, direction: str, path: Path) -> None:
    from matplotlib.figure import Figure

    points = [(t.number, t.value) for t in study.trials if t.value is not None]
    fig = Figure(figsize=(6.4, 3.6), dpi=100)
    ax = fig.add_subplot(1, 1, 1)
    if points:
        xs, ys = zip(*points)
        best, running = [], math.inf if direction == "minimize" else -math.inf
        for y in ys:
            running = min(running, y) if direction == "minimize" else max(running, y)
            best.append(running)
        ax.plot(xs, ys, "o", alpha=0.6, label="trial")
        ax.step(xs, best, where="post", label="best so far")
        ax.legend()
    ax.set_xlabel("trial")
    ax.set_ylabel("objective")
    ax.set_title(f"stealth tune: history ({direction})")
    fig.tight_layout()
    save_figure(fig, path)


def _params(study: Any, path: Path) -> None:
    from matplotlib.figure import Figure

    done = [t for t in study.trials if t.value is not None]
    keys = sorted({k for t in done for k in t.params})
    share = any("within_tolerance" in t.user_attrs for t in done)
    rows = 2 if share else 1
    fig = Figure(figsize=(max(6.4, 2.6 * len(keys)), 2.8 * rows), dpi=100)
    for j, key in enumerate(keys):
        points = [t for t in done if key in t.params]
        xs = [t.params[key] if not isinstance(t.params[key], str) else str(t.params[key])
              for t in points]
        for i in range(rows):
            ax = fig.add_subplot(rows, max(1, len(keys)), i * len(keys) + j + 1)
            ys = ([t.value for t in points] if i == 0
                  else [100 * float(t.user_attrs.get("within_tolerance", math.nan))
                        for t in points])
            ax.plot(xs, ys, "o", alpha=0.7)
            if i == 0:
                ax.set_yscale("log" if min(ys, default=1) > 0 else "linear")
            ax.set_xlabel(key.split(".")[-1], fontsize=8)
            ax.tick_params(labelsize=7)
            if j == 0:
                ax.set_ylabel("objective" if i == 0 else "% cells within tol.", fontsize=8)
    fig.suptitle("stealth tune: each trial against each searched parameter", fontsize=9)
    fig.tight_layout()
    save_figure(fig, path)


def _study_csv(study: Any, path: Path) -> None:
    keys = sorted({k for t in study.trials for k in t.params})
    with path.open("w", newline="", encoding="utf-8") as handle:
        writer = csv.writer(handle)
        writer.writerow(["number", "state", "value", *keys, "constraints", "within_tolerance"])
        for t in study.trials:
            writer.writerow([t.number, t.state.name, "" if t.value is None else repr(t.value),
                             *(repr(t.params[k]) if k in t.params else "" for k in keys),
                             json.dumps(t.user_attrs.get("constraints", [])),
                             t.user_attrs.get("within_tolerance", "")])


def write_study_outputs(spec: TuneSpec, study: Any, best: Any, test: dict[str, Any] | None,
                        out: Path) -> None:
    """Write the five files of the module docstring into ``out``."""
    _study_csv(study, out / "study.csv")
    _history(study, spec.direction, out / "history.png")
    _params(study, out / "params.png")
    objective = (f"distance to {spec.target.path.name}" if spec.target is not None
                 else f"{spec.direction} {spec.objective.text if spec.objective else ''}")
    lines = [f"# stealth tune: {spec.path.name}", "",
             f"Objective: {objective}"
             + (f"; constraints: {', '.join(c.text for c in spec.constraints)}"
                if spec.constraints else "") + ".",
             f"Design: {spec.preset.n_trials // max(1, len(spec.preset.seeds))} trials per seed; "
             f"training seeds 0…{spec.seeds_train - 1}, held-out seeds {spec.seeds_train}…"
             f"{spec.seeds_train + spec.seeds_test - 1}; TPE sampler seed {spec.sampler_seed}.",
             f"Trials: {len(study.trials)} ({sum(t.state.name == 'COMPLETE' for t in study.trials)}"
             " complete).", ""]
    if best is None:
        lines += ["No feasible finished trial yet: no best.toml.", ""]
        (out / "best.toml").unlink(missing_ok=True)
    else:
        write_config_file(out / "best.toml", best.params,
                          f"best of stealth tune {spec.path.name}, trial {best.number}\n"
                          f"objective on training seeds: {best.value!r}")
        lines += ["## Best", "", f"Trial {best.number}.", "",
                  "| | training seeds | held-out seeds |", "|---|---:|---:|",
                  f"| objective | {best.value:.6g} | "
                  + (f"{test['value']:.6g}" if test else "–") + " |"]
        if "within_tolerance" in best.user_attrs:
            lines.append(f"| cells within tolerance | {best.user_attrs['within_tolerance']:.0%} | "
                         + (f"{test['within_tolerance']:.0%}" if test else "–") + " |")
        lines += ["", "| parameter | value |", "|---|---:|"]
        lines += [f"| `{k}` | {v!r} |" for k, v in sorted(best.params.items())]
        lines += ["", "`best.toml` holds these as a `--config` file.", ""]
    importances = _importances(study)
    lines += ["## Parameter importances (optuna.importance, its default evaluator)", ""]
    if isinstance(importances, str):
        lines.append(importances)
    else:
        lines += ["| parameter | importance |", "|---|---:|"]
        lines += [f"| `{k}` | {v:.3f} |" for k, v in importances.items()]
    lines += ["", "## History", "", "![history](history.png)", "",
              "## Each trial against each parameter", "", "![parameters](params.png)", ""]
    (out / "report.md").write_text("\n".join(lines), encoding="utf-8")
