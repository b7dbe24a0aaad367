"""What a ``stealth tune`` spec file declares, validated: the design (a preset), the searched
config keys (:class:`Param`), the objective or target, the training and held-out seeds
(:class:`TuneSpec`, read by :func:`load_tune_spec`). The file's format is in
:mod:`headless.tune.study`'s docstring; running the study is there, its outputs in
:mod:`headless.tune.report`.
"""

from __future__ import annotations

import tomllib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

from game.errors import ConfigError
from game.trial import TrialSpec
from navmesh.files import FileRefused, read_regular

from ..errors import UserError
from ..presets import MAX_PRESET_BYTES, Preset, check_setting, parse_preset
from .expr import Expression, parse_constraint, parse_expression
from .objective import Target, check_names, load_target, lookup_for

__all__ = ["STUDIES_DIR", "Param", "TuneSpec", "load_tune_spec"]

STUDIES_DIR = Path(__file__).resolve().parent.parent / "studies"
"""Bundled tune specs (``stealth tune paper-calibrate``)."""
_TUNE_KEYS = ("search", "objective", "seeds_train", "seeds_test", "sampler_seed")


@dataclass(frozen=True)
class Param:
    """One searched config key: a float/int range (``log`` scale or not) or choices."""

    key: str
    low: float | int | None = None
    high: float | int | None = None
    log: bool = False
    choices: tuple[Any, ...] = ()

    def suggest(self, trial: Any) -> Any:
        """Optuna's suggestion for this key in ``trial``."""
        if self.choices:
            return trial.suggest_categorical(self.key, list(self.choices))
        if isinstance(self.low, int) and isinstance(self.high, int):
            return trial.suggest_int(self.key, self.low, self.high, log=self.log)
        return trial.suggest_float(self.key, float(self.low or 0), float(self.high or 0),
                                   log=self.log)


@dataclass(frozen=True)
class TuneSpec:
    """A validated tune spec (see the module docstring)."""

    path: Path
    text: str
    preset: Preset
    params: tuple[Param, ...]
    direction: Literal["maximize", "minimize"]
    objective: Expression | None
    constraints: tuple[Expression, ...]
    target: Target | None
    seeds_train: int
    seeds_test: int
    sampler_seed: int

    def specs(self, values: Mapping[str, Any], seeds: Sequence[int]) -> list[TrialSpec]:
        """The design's trials on ``seeds`` with ``values`` set (over the preset's [set])."""
        overrides = tuple(sorted({**dict(self.preset.overrides), **values}.items()))
        return [TrialSpec(level=s.level, abstraction=s.abstraction, guards=s.guards,
                          player=s.player, scenario=s.scenario, seed=seed, overrides=overrides,
                          root_seed=s.root_seed, factors=s.factors)
                for seed in seeds for s in self.preset.specs() if s.seed == self.preset.seeds[0]]

    def score(self, trials: Sequence[Mapping[str, Any]]) -> tuple[float, list[float], dict[str, Any]]:
        """``(objective value, constraint values (<= 0 holds), extra facts)`` of some trials."""
        lookup = lookup_for(trials)
        constraints = [c.evaluate(lookup) for c in self.constraints]
        if self.target is not None:
            distance, within = self.target.distance(trials)
            return distance, constraints, {"within_tolerance": within}
        assert self.objective is not None
        return self.objective.evaluate(lookup), constraints, {}


def _count(data: Mapping[str, Any], key: str, src: str, minimum: int) -> int:
    value = data.get(key)
    if isinstance(value, bool) or not isinstance(value, int) or value < minimum:
        raise UserError(f"{src}: {key}: expected a whole number >= {minimum}, got {value!r}")
    return value


def _param(key: str, table: Any, src: str, factors: set[str]) -> Param:
    where = f"{src}: search.{key}"
    if key in factors:
        raise UserError(f"{where}: is also a factor of the design")
    if not isinstance(table, Mapping):
        raise UserError(f"{where}: expected {{low=, high=, log=}} or {{choices=[...]}}")
    unknown = set(table) - {"low", "high", "log", "choices"}
    if unknown:
        raise UserError(f"{where}: unknown field {sorted(unknown)[0]!r}")
    try:
        if "choices" in table:
            choices = table["choices"]
            if set(table) != {"choices"} or not isinstance(choices, list) or not choices:
                raise UserError(f"{where}: choices must be a non-empty list, alone")
            return Param(key, choices=tuple(check_setting(key, c) for c in choices))
        if "low" not in table or "high" not in table:
            raise UserError(f"{where}: needs low and high (or choices)")
        low, high = check_setting(key, table["low"]), check_setting(key, table["high"])
    except ConfigError as error:
        raise UserError(f"{where}: {error}") from None
    log = table.get("log", False)
    if not isinstance(log, bool):
        raise UserError(f"{where}: log: expected true or false")
    if isinstance(low, bool) or not isinstance(low, (int, float)) or not low < high:
        raise UserError(f"{where}: expected numbers low < high, got {low!r}, {high!r}")
    if log and low <= 0:
        raise UserError(f"{where}: a log range needs low > 0")
    return Param(key, low=low, high=high, log=log)


def load_tune_spec(path: str | Path, extra: Mapping[str, Any] | None = None) -> TuneSpec:
    """Read and validate a tune spec; ``extra`` (a ``--config`` file) goes over its ``[set]``."""
    path = Path(path)
    if not path.is_file() and (STUDIES_DIR / f"{path}.toml").is_file():
        path = STUDIES_DIR / f"{path}.toml"  # a bundled study by name
    src = str(path)
    try:
        text = read_regular(path, MAX_PRESET_BYTES).decode("utf-8")
        data = tomllib.loads(text)
    except FileNotFoundError:
        raise UserError(f"{src}: no such tune spec") from None
    except FileRefused as error:
        raise UserError(f"{src}: {error}") from None
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError) as error:
        raise UserError(f"{src}: cannot read ({' '.join(str(error).split())})") from None
    seeds_train = _count(data, "seeds_train", src, 1)
    seeds_test = _count(data, "seeds_test", src, 0)
    sampler_seed = _count({"sampler_seed": data.get("sampler_seed", 0)}, "sampler_seed", src, 0)
    design = {k: v for k, v in data.items() if k not in _TUNE_KEYS}
    design["seeds"] = seeds_train
    preset = parse_preset(design, src, name=path.stem, text=text, base=path.resolve().parent,
                          extra=extra)
    search = data.get("search")
    if not isinstance(search, Mapping) or not search:
        raise UserError(f"{src}: search: expected a table of config keys to search")
    factors = {k for k, _ in preset.factors}
    flat: dict[str, Any] = {}
    for key, value in search.items():  # "a.b" = {...} and [search.a] b = {...} alike
        if isinstance(value, Mapping) and not set(value) & {"low", "high", "log", "choices"}:
            flat.update({f"{key}.{k}": v for k, v in value.items()})
        else:
            flat[key] = value
    params = tuple(_param(k, v, src, factors) for k, v in sorted(flat.items()))

    objective = data.get("objective")
    if not isinstance(objective, Mapping):
        raise UserError(f"{src}: objective: expected a table (maximize, minimize or target)")
    ways = [k for k in ("maximize", "minimize", "target") if k in objective]
    unknown = set(objective) - {"maximize", "minimize", "target", "constraints"}
    if len(ways) != 1 or unknown:
        raise UserError(f"{src}: objective: give exactly one of maximize, minimize, target "
                        "(and optional constraints)")
    selectors = {*preset.guards, *preset.players, *preset.abstractions, *preset.level_names}
    expression = target = None
    if ways[0] == "target":
        target = load_target(str(objective["target"]), path.resolve().parent, {
            "abstractions": preset.abstractions, "guards": preset.guards,
            "players": preset.players, "scenarios": preset.scenarios})
    else:
        expression = parse_expression(objective[ways[0]])
        check_names(expression, selectors, preset.scenarios, f"{src}: objective")
    texts = objective.get("constraints", [])
    if not isinstance(texts, list) or not all(isinstance(t, str) for t in texts):
        raise UserError(f"{src}: objective.constraints: expected a list of comparisons")
    constraints = tuple(parse_constraint(t) for t in texts)
    for c in constraints:
        check_names(c, selectors, preset.scenarios, f"{src}: objective.constraints")
    return TuneSpec(path=path, text=text, preset=preset, params=params,
                    direction="maximize" if ways[0] == "maximize" else "minimize",
                    objective=expression, constraints=constraints, target=target,
                    seeds_train=seeds_train, seeds_test=seeds_test, sampler_seed=sampler_seed)
