"""Parameters of the guard modes and player policies (paper Table 2, SPEC §3–§4).

Every controller receives its parameters as a plain dict (from the config file's section of
its mode) and turns it into one of these frozen dataclasses with ``from_mapping``, so a typo
or an out-of-range value fails when the controller is built, not silently in a sweep. Each
class declares the allowed values of every field once, in ``bounds`` (:mod:`ai.bounds`);
the config schema (``game.schema``) checks the config keys against the same declarations.

>>> PFParams.from_mapping({"rho": 0.9}).rho
0.9
>>> PFParams.from_mapping({"roh": 0.9})
Traceback (most recent call last):
...
ValueError: PFParams: unknown parameter 'roh' (known: I0, C0, gamma_I, gamma_C, rho, ...)
>>> PFParams.from_mapping({"rho": 1.5})
Traceback (most recent call last):
...
ValueError: PFParams: rho must be in (0, 1], got 1.5
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, fields
from types import MappingProxyType
from typing import Any, ClassVar, TypeVar

from .bounds import ANY_NUMBER, COUNT, FLAG, FRACTION, NON_NEGATIVE, POSITIVE, UNIT, Bound, OneOf, Range

_P = TypeVar("_P", bound="Params")

#: per parameter class, its config keys' defaults (:meth:`Params.config_defaults`)
_CONFIG_DEFAULTS: dict[type, Mapping[str, Any]] = {}


class Params:
    """The base of every parameter dataclass (a guard mode's, a player policy's, a plugin
    stimulus's: subclass it, frozen, with a ``bounds`` entry per field): ``from_mapping`` and
    the bound checks."""

    #: field name -> its allowed values (:mod:`ai.bounds`), one declaration per field; the
    #: config schema (``game.schema``) reads these for the keys of the section
    bounds: ClassVar[Mapping[str, Bound]] = {}
    #: fields the trial fills in from ``[world]`` and the scenario (``game.trial.player_params``),
    #: so they are no config keys of the class's own section
    from_world: ClassVar[tuple[str, ...]] = ()

    @classmethod
    def config_defaults(cls) -> Mapping[str, Any]:
        """Field -> default of the fields that are config keys (all but :attr:`from_world`):
        the one source of their section's defaults (``game.schema.parameter_defaults``)."""
        if cls not in _CONFIG_DEFAULTS:
            _CONFIG_DEFAULTS[cls] = MappingProxyType({
                f.name: f.default for f in fields(cls)  # type: ignore[arg-type]
                if f.name not in cls.from_world})
        return _CONFIG_DEFAULTS[cls]

    @classmethod
    def declaration_problem(cls, params: Any) -> str | None:
        """Why ``params`` cannot be a registration's parameter class, or None: it must be a
        dataclass subclass of ``Params`` whose ``bounds`` gives every field a :mod:`ai.bounds`
        bound and names no other, and whose defaults lie within them (checked when a mode or
        stimulus is registered, not when a trial first builds it)."""
        from dataclasses import is_dataclass

        if not (isinstance(params, type) and issubclass(params, cls) and is_dataclass(params)):
            return f"must be a dataclass subclass of ai.params.Params, got {params!r:.80}"
        names = [f.name for f in fields(params)]
        if not isinstance(params.bounds, Mapping):
            return f"{params.__name__}.bounds must map each field to its bound"
        for key, bound in params.bounds.items():
            if key not in names:
                return f"{params.__name__}.bounds names {key!r}, which is no field"
            if not isinstance(bound, (Range, OneOf)):
                return (f"{params.__name__}.bounds[{key!r}] must be an ai.bounds bound "
                        f"(Range, OneOf), got {bound!r:.80}")
        unbounded = [k for k in names if k not in params.bounds]
        if unbounded:
            return (f"{params.__name__}.{unbounded[0]} declares no bound (its bounds maps each "
                    "field to its allowed values)")
        try:
            params()
        except (TypeError, ValueError) as error:
            return f"{params.__name__}: {error}"
        return None

    @classmethod
    def from_mapping(cls: type[_P], params: Mapping[str, Any] | None = None) -> _P:
        """Defaults overridden by ``params``; an unknown key or a bad value raises ValueError."""
        known = [f.name for f in fields(cls)]  # type: ignore[arg-type]
        values: dict[str, Any] = {}
        for key, value in dict(params or {}).items():
            if key not in known:
                shown = ", ".join(known[:5]) + (", ..." if len(known) > 5 else "")
                raise ValueError(f"{cls.__name__}: unknown parameter {key!r} (known: {shown})")
            values[key] = value
        return cls(**values)

    def __post_init__(self) -> None:
        for f in fields(self):  # type: ignore[arg-type]
            value = getattr(self, f.name)
            bound = self.bounds.get(f.name)
            if bound is None:
                raise TypeError(f"{type(self).__name__}: {f.name} declares no bound")
            problem = bound.problem(value)
            if problem is not None:
                raise ValueError(f"{type(self).__name__}: {f.name} {problem}, got {value!r}")
            if isinstance(bound, Range):
                object.__setattr__(self, f.name, int(value) if bound.integer else float(value))


@dataclass(frozen=True)
class PFParams(Params):
    """Composite potential field guards (paper Table 2, SPEC §3)."""

    I0: float = 5.0  # noqa: N815 — the paper's symbol
    C0: float = 1.0  # noqa: N815
    gamma_I: float = 0.9  # noqa: N815 — spatial decay of the information field per hop
    gamma_C: float = 0.8  # noqa: N815 — spatial decay of a guard's confidence deposit per hop
    rho: float = 0.95  # temporal decay of I and C per second
    kernel_lambda: float = 0.8
    kernel_radius: int = 3  # hops
    w_I_base: float = 0.4  # noqa: N815
    w_C_patrol: float = 0.5  # noqa: N815
    w_N_patrol: float = 0.1  # noqa: N815
    w_I_max: float = 0.9  # noqa: N815
    weight_decay: float = 0.05  # of w_I, per second
    r_edge_factor: float = 2.5  # partition candidate horizon = factor × mean edge length
    tie_eps: float = 1e-9
    #: scale of the teammates' confidence deposit at their *current* nodes, added when a guard
    #: decides (docs/ai.md "Teammate presence"); 0 = the paper's field only
    teammate_presence: float = 1.0
    #: penalty, in units of w_C·C0, on a candidate among the guard's last 5 decided nodes
    #: (docs/ai.md "Revisit penalty"); 0 = the paper's field only
    revisit_penalty: float = 0.5

    bounds = {
        "teammate_presence": NON_NEGATIVE,
        "revisit_penalty": NON_NEGATIVE,
        "I0": NON_NEGATIVE,
        "C0": NON_NEGATIVE,
        "gamma_I": UNIT,
        "gamma_C": UNIT,
        "rho": UNIT,
        "kernel_lambda": UNIT,
        "kernel_radius": COUNT,
        "w_I_base": FRACTION,
        "w_C_patrol": NON_NEGATIVE,
        "w_N_patrol": NON_NEGATIVE,
        "w_I_max": FRACTION,
        "weight_decay": NON_NEGATIVE,
        "r_edge_factor": POSITIVE,
        "tie_eps": POSITIVE,  # ties are scores within tie_eps of the best: 0 ties nothing
    }

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.w_I_max < self.w_I_base:
            raise ValueError(
                f"PFParams: w_I_max ({self.w_I_max}) must be >= w_I_base ({self.w_I_base})"
            )
        if self.w_C_patrol + self.w_N_patrol <= 0:
            raise ValueError("PFParams: w_C_patrol + w_N_patrol must be > 0")


INVESTIGATE_RULES = ("team", "local")
"""``fsm.investigate`` / ``staleness.investigate`` (first: the rule before SPEC §11)."""

STALENESS_MODELS = ("node", "view", "alenezi")
"""``staleness.model``: ``node`` resets staleness only where a guard stands; ``view`` on every
node a guard sees (Al Enezi & Verbrugge 2020; docs/ai.md); ``alenezi`` resets as ``view`` and
scores targets as their simulator's code does (SPEC §12; ai/baselines.py, docs/ai.md)."""

SAFETYGRAPH_GOALS = ("escape", "paper", "local")
"""``player.safetygraph_goal``: ours, the paper's text only, and the paper's text with the goal
sought within ``safetygraph_hops`` hops (SPEC §12; ai/players.py)."""


@dataclass(frozen=True)
class FSMParams(Params):
    """FSM guards (paper Table 2; SPEC §4). Times in seconds."""

    info_threshold: float = 1.0  # information strength that triggers Investigate
    #: strength of a sighting reported by any guard (the PF's I0, so both modes get the same signal)
    sighting_information: float = 5.0
    t_investigate: float = 3.0  # time spent searching at the last known position
    t_lose_sight: float = 2.0  # Chase gives up after this long with no guard seeing the player
    chase_max: float = 10.0
    return_max: float = 5.0
    r_edge_factor: float = 2.5  # partition step horizon = factor × mean edge length
    #: who a sighting sends to Investigate (SPEC §11): "team" = every guard, whatever its
    #: distance; "local" = a guard where the sighting's information at its own node,
    #: sighting_information × information_falloff^hops, reaches info_threshold
    investigate: str = "team"
    #: "local" only: the sighting's information falls off by this factor per hop (the PF's gamma_I)
    information_falloff: float = 0.9

    bounds = {
        "info_threshold": NON_NEGATIVE,
        "sighting_information": NON_NEGATIVE,
        "t_investigate": NON_NEGATIVE,
        "t_lose_sight": NON_NEGATIVE,
        "chase_max": NON_NEGATIVE,
        "return_max": NON_NEGATIVE,
        "r_edge_factor": POSITIVE,
        "investigate": OneOf(INVESTIGATE_RULES),
        "information_falloff": FRACTION,
    }


@dataclass(frozen=True)
class StalenessParams(FSMParams):
    """Staleness guards: the FSM's parameters, the staleness growth per second of AI tick, and
    the patrol rule (``model``; ``distance_weight`` and ``spread_radius`` apply to ``view``)."""

    increment: float = 1.0
    model: str = "view"
    #: view: a patrol target scores staleness − distance_weight × path distance (seconds of
    #: staleness per world unit; 0.5 = one second of walking at the default guard speed)
    distance_weight: float = 0.5
    #: view: no target within this distance (world units) of another guard's target
    spread_radius: float = 4.0
    #: alenezi: weight of the normalised staleness (their ``StalenessWeight``; with
    #: ``distance_weight`` on the closeness 1 − d/L and ``separation_weight`` on the distance
    #: to the nearest other guard / L; their defaults 1, 0.5, 0.5)
    staleness_weight: float = 1.0
    separation_weight: float = 0.5

    bounds = {**FSMParams.bounds, "increment": NON_NEGATIVE,
              "model": OneOf(STALENESS_MODELS), "distance_weight": Range(0.0, 100.0),
              "spread_radius": NON_NEGATIVE, "staleness_weight": Range(0.0, 100.0),
              "separation_weight": Range(0.0, 100.0)}


@dataclass(frozen=True)
class PlayerParams(Params):
    """Scripted players (SPEC §4). Speeds in world units per second, margins in seconds."""

    maxmin_depth: int = 3  # steps simulated ahead (≤ 5^depth sequences on the grid)
    #: MaxMin assumes every guard closes in by one guard step per player step (pessimistic)
    maxmin_guards_advance: bool = True
    guard_speed: float = 2.0
    player_speed: float = 2.0
    #: SafetyGraph: a node is safe when the player gets there this many seconds before any guard
    safety_margin: float = 1.0
    #: SafetyGraph: edge cost factor 1 + safety_penalty × max(0, safety_margin − S) (per second)
    safety_penalty: float = 4.0
    r_edge_factor: float = 2.5  # partition step horizon of SafetyGraph
    tie_eps: float = 1e-9
    #: SafetyGraph's goal rule: "escape" (ours: the farthest node kept ``safety_margin`` safe,
    #: re-planned at every decision), "paper" (the paper's text only: the safest node, A*
    #: with a Euclidean heuristic, margin 0, re-planned once per decision tick) or "local"
    #: ("paper" with the safest node within ``safetygraph_hops`` hops); ai/players.py
    safetygraph_goal: str = "escape"
    #: SafetyGraph ``local``: the goal is the node of greatest S within this many hops
    safetygraph_hops: int = 3

    from_world = ("guard_speed", "player_speed")
    bounds = {
        "maxmin_depth": Range(1, 6, integer=True),
        "maxmin_guards_advance": FLAG,
        "guard_speed": POSITIVE,
        "player_speed": POSITIVE,
        "safety_margin": ANY_NUMBER,
        "safety_penalty": NON_NEGATIVE,
        "r_edge_factor": POSITIVE,
        "tie_eps": NON_NEGATIVE,
        "safetygraph_goal": OneOf(SAFETYGRAPH_GOALS),
        "safetygraph_hops": Range(1, 1000, integer=True),
    }


__all__ = ["Params", "PFParams", "FSMParams", "StalenessParams", "PlayerParams", "INVESTIGATE_RULES",
           "SAFETYGRAPH_GOALS", "STALENESS_MODELS"]
