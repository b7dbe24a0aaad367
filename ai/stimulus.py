"""The stimulus API (SPEC §5): what one mechanic is to the information field.

A :class:`Stimulus` knows how it injects into the information field, how it decays and when
it ends; it sees the trial through a :class:`FieldContext` and declares how
``stealth mechanics --stimulus`` measures it (:class:`Measure`). Its class declares its
names and its own config parameters, and :data:`STIMULUS_TYPES` holds the classes known by
name (the built-ins, the plugins loaded). The built-in mechanics are in
:mod:`ai.builtin_stimuli`, the set that drives them in :mod:`ai.stimuli`.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from typing import Any, ClassVar, NamedTuple

import numpy as np

from navmesh.graph import UNREACHABLE_HOPS, NodeGraph
from navmesh.names import label_problem, name_problem

from . import plugin_call, registrations
from .errors import StimulusError
from .bounds import COUNT, FLAG, FRACTION, NON_NEGATIVE, UNIT
from .params import Params
from .view import Event, WorldView


# ---------------------------------------------------------------------------- parameters


@dataclass(frozen=True)
class StimulusParams(Params):
    """The ``[stimuli]`` section of the config: the paper's values (SPEC §5) are the defaults.

    The section's player-action keys (``throw_cooldown``, ``throw_radius``, ``decoy_reach``,
    ``takedown_range``) are the world's (``game.action_params.ActionParams``), not these.
    """

    #: footstep noise while sprinting (and a thrown decoy's landing): −A·α^d up to max_hops
    noise_amplitude: float = 3.0
    noise_falloff: float = 0.6
    noise_max_hops: int = 5
    #: a noise layer is multiplied by this per second and dropped when its peak is below threshold
    noise_decay: float = 0.8
    noise_threshold: float = 0.1
    #: rain: every new noise's amplitude × this (3.0 → 1.5) and its falloff set to this
    rain_amplitude_scale: float = 0.5
    rain_falloff: float = 0.7
    #: weather at the start of a trial
    raining: bool = False
    #: static decoy: −A·β^d over the whole map, removed after guards stood on it this long
    decoy_amplitude: float = 5.0
    decoy_falloff: float = 0.8
    decoy_disarm_time: float = 3.0
    #: corpse: −A·γ^t·δ^d, removed after guards inspected it this long
    corpse_amplitude: float = 4.0
    corpse_decay: float = 0.95
    corpse_falloff: float = 0.7
    corpse_inspect_time: float = 10.0
    #: once a guard has found the body, the team's w_I stays at least this high until it is
    #: removed (our addition: the finder raises the alarm; 0 = the paper's layer alone)
    corpse_alert_weight: float = 0.9
    #: a guard within this many hops of a decoy or corpse counts as standing on / inspecting it
    inspect_hops: int = 1

    bounds = {
        "noise_amplitude": NON_NEGATIVE,
        "noise_falloff": UNIT,
        "noise_max_hops": COUNT,
        "noise_decay": UNIT,
        "noise_threshold": NON_NEGATIVE,
        "rain_amplitude_scale": NON_NEGATIVE,
        "rain_falloff": UNIT,
        "raining": FLAG,
        "decoy_amplitude": NON_NEGATIVE,
        "decoy_falloff": UNIT,
        "decoy_disarm_time": NON_NEGATIVE,
        "corpse_amplitude": NON_NEGATIVE,
        "corpse_decay": UNIT,
        "corpse_falloff": UNIT,
        "corpse_inspect_time": NON_NEGATIVE,
        "corpse_alert_weight": FRACTION,
        "inspect_hops": COUNT,
    }


class Sound(NamedTuple):
    """How loud a new noise is at its source and how much of it is left per hop."""

    amplitude: float
    falloff: float


# ---------------------------------------------------------------------------- context


@dataclass
class FieldContext:
    """What a stimulus may read about its trial: the graph, the parameters, the time.

    ``active`` is the set's current stimuli (weather consults it for :meth:`sound`); ``rng``
    is a generator derived from the trial's seed, for stimuli that need randomness;
    ``config`` the trial's config values by dotted key, from which :meth:`params_of` builds
    a plugin's own parameters.
    """

    graph: NodeGraph
    params: StimulusParams = field(default_factory=StimulusParams)
    rng: np.random.Generator = field(default_factory=lambda: np.random.default_rng(0))
    zones: Mapping[str, np.ndarray] = field(default_factory=dict)
    t: float = 0.0
    active: tuple[Stimulus, ...] = ()
    config: Mapping[str, Any] = field(default_factory=dict)

    @property
    def n(self) -> int:
        return self.graph.n

    def params_of(self, stimulus: Stimulus) -> Any:
        """``stimulus``'s parameters (an instance of its :attr:`Stimulus.parameters`) with this
        trial's values of its config section (``--set SECTION.KEY=V``, a preset's ``[set]``);
        the class's defaults where the config has none.

        >>> from dataclasses import dataclass
        >>> from ai.bounds import NON_NEGATIVE
        >>> @dataclass(frozen=True)
        ... class BellParams(Params):
        ...     amplitude: float = 6.0
        ...     bounds = {"amplitude": NON_NEGATIVE}
        >>> class Bell(Stimulus):
        ...     name, parameters = "bell", BellParams
        >>> ctx = FieldContext(NodeGraph.from_grid(np.ones((1, 2), bool), 1.0),
        ...                    config={"bell.amplitude": 2.5})
        >>> ctx.params_of(Bell()).amplitude, Bell.section, Bell.display
        (2.5, 'bell', 'bell')
        """
        cls = stimulus.parameters
        if cls is None:
            raise StimulusError(f"{plugin_call.describe(stimulus)}: declares no parameters")
        prefix = stimulus.section + "."
        given = {k[len(prefix):]: v for k, v in self.config.items()
                 if k.startswith(prefix) and "." not in k[len(prefix):]}
        try:
            return cls.from_mapping(given)
        except (TypeError, ValueError) as error:
            raise StimulusError(f"{plugin_call.describe(stimulus)}: [{stimulus.section}]: "
                                f"{error}") from None

    def hops_from(self, node: int, max_hops: int | None = None) -> np.ndarray:
        """Hop distance (BFS) from ``node`` to every node (a huge number where unreachable or,
        with ``max_hops``, farther: a large graph then only searches that far)."""
        return self.graph.hops_from(int(node), max_hops)

    def falloff(self, node: int, base: float, max_hops: int | None = None) -> np.ndarray:
        """``base ** d(node, ·)`` for every node; 0 where unreachable or beyond ``max_hops``.

        Multiply by ``−amplitude`` for an attractive layer, e.g. ``−3 · ctx.falloff(p, 0.6, 5)``.
        """
        hops = self.hops_from(node, max_hops)
        limit = UNREACHABLE_HOPS if max_hops is None else min(int(max_hops) + 1, UNREACHABLE_HOPS)
        inside = hops < limit
        return np.where(inside, float(base) ** np.where(inside, hops, 0).astype(np.float64), 0.0)

    def sound(self, base: Sound | None = None) -> Sound:
        """How a new noise sounds now: ``base`` (the configured noise) after every active
        stimulus's :meth:`Stimulus.affect_sound` (rain dampens it)."""
        sound = base or Sound(self.params.noise_amplitude, self.params.noise_falloff)
        for stimulus in self.active:
            if not plugin_call.is_done(stimulus):
                sound = plugin_call.call(stimulus, stimulus.affect_sound, sound)
                if not isinstance(sound, Sound):
                    raise StimulusError(f"{plugin_call.describe(stimulus)}: affect_sound() "
                                        f"returned {type(sound).__name__}, not a Sound")
        return sound

    def node_at(self, x: float, y: float) -> int:
        """The node at world point (x, y) (the nearest node for a point in a wall)."""
        return self.graph.node_at(float(x), float(y))


# ---------------------------------------------------------------------------- the API


#: the directions a :class:`Measure` may intend for a metric: up, down, or none declared
DIRECTIONS = (+1, -1, 0)


@dataclass(frozen=True)
class Measure:
    """How ``stealth mechanics --stimulus`` measures a mechanic against a paired control.

    Both arms run the same trials — same level, seed, guard spawns and generators — with
    the stimulus (arm ``on``) and without it (``control``): ``guards`` against ``player`` in
    ``scenario``, with the config ``overrides`` in both arms. Each of ``metrics`` is
    ``(trial metric name, intended direction)``: a name of the trial metrics
    (``game.metrics``: ``captured``, ``capture_time``, ``first_detect_time``, ``coverage``,
    ...; times of events that did not happen count as the trial's duration), and ``+1`` if
    the mechanic should raise it, ``-1`` lower it, ``0`` for no intended direction (the
    verdict then only says whether it changed). The default asks the question any new
    mechanic raises first: are the player's captures and detections different with it?

    >>> Measure(metrics=(("captured", +1),)).metrics
    (('captured', 1),)
    >>> Measure(metrics=(("captured", 2),))
    Traceback (most recent call last):
    ...
    ai.errors.StimulusError: measure: captured: the direction must be +1, -1 or 0, got 2
    """

    metrics: tuple[tuple[str, int], ...] = (
        ("first_detect_time", 0), ("captured", 0), ("capture_time", 0))
    guards: str = "pf"
    player: str = "maxmin"
    scenario: str = "capture"
    overrides: tuple[tuple[str, Any], ...] = ()

    def __post_init__(self) -> None:
        if not self.metrics:
            raise StimulusError("measure: no metrics to measure")
        for metric, direction in self.metrics:
            if direction not in DIRECTIONS:
                raise StimulusError(f"measure: {metric}: the direction must be +1, -1 or 0, "
                                    f"got {direction!r}")


class Stimulus:
    """One mechanic instance: how it injects, how it decays, when it ends.

    Override what you need; every method has a harmless default.

    * :meth:`start` — called once when the stimulus joins a trial (precompute the layer).
    * :meth:`inject` — its layer now, shape ``(n,)``; ``≤ 0`` attracts guards, ``> 0``
      repels them; ``None`` for no layer (e.g. weather).
    * :meth:`decay` — advance its own clock by ``dt`` seconds (once per AI tick).
    * :attr:`done` — true when it should be removed (checked after every tick).
    * :meth:`on_event` / :meth:`on_tick` — react to world events and to the guards (e.g.
      "a guard stood on me for 3 s").
    * :attr:`information_weight_floor` — ask the guard AI to keep ``w_I`` at least this high
      while active (``None``: no request).
    * :meth:`affect_sound` — change how *new* noises sound while active (rain).

    ``node`` is where it is (``-1``: nowhere in particular); stimuli with ``marker`` set are
    drawn by the game and raise ``"guard_on"`` events when a guard steps onto their node.

    What the rest of the house reads of a mechanic is declared on its class:

    * :attr:`name` — its name in traces; :attr:`display` the name tables print and
      :attr:`short` the one dense text prints (default: the name, then the display name).
    * :attr:`parameters` — its parameter dataclass (an :class:`ai.params.Params` with
      ``bounds``; ``None``: none) whose fields are the keys of config section
      :attr:`section` (default: the name). Loading a plugin registers them
      (:func:`register_stimulus`), so ``--set SECTION.KEY=V`` and presets set them and the
      stimulus reads them with :meth:`FieldContext.params_of`.

    Two more declarations concern a plugin as a whole:

    * :attr:`zone_kinds` — the level zone kinds the mechanic gives meaning to (e.g.
      ``("alarm",)``). Loading the plugin (:func:`load_stimulus`) registers each with
      :func:`navmesh.level.register_zone_kind`, so JSON and Tiled levels loaded afterwards
      may draw such zones; the stimulus finds their nodes in ``ctx.zones[kind]`` and its own
      hooks are what the zone does.
    * :attr:`measure` — how ``stealth mechanics --stimulus`` measures it (:class:`Measure`).
    """

    name: str = "stimulus"
    display: ClassVar[str] = "stimulus"
    short: ClassVar[str] = "stimulus"
    parameters: ClassVar[type[Params] | None] = None
    section: ClassVar[str] = "stimulus"
    node: int = -1
    marker: bool = False
    zone_kinds: tuple[str, ...] = ()
    measure: Measure = Measure()
    #: the index of the level decoy this stimulus is (``-1``: none); the world asks it to
    #: tell whether that decoy is already on
    decoy: int = -1
    done: bool = False
    information_weight_floor: float | None = None

    def __init_subclass__(cls, **kwargs: Any) -> None:
        """A subclass that names itself but not its display name, short name or section
        takes its name for each (the short name: its display name)."""
        super().__init_subclass__(**kwargs)
        own = vars(cls)
        if "display" not in own:
            cls.display = str(cls.name)
        if "short" not in own:
            cls.short = cls.display
        if "section" not in own:
            cls.section = str(cls.name)

    def start(self, ctx: FieldContext) -> None:
        """Join a trial (default: nothing)."""

    def inject(self, ctx: FieldContext) -> np.ndarray | None:
        """The stimulus's contribution to the information field now (default: none)."""
        return None

    def decay(self, dt: float) -> None:
        """Let ``dt`` seconds pass (default: nothing)."""

    def on_event(self, event: Event) -> None:
        """A world event of this AI tick (default: ignored)."""

    def on_tick(self, view: WorldView, dt: float) -> None:
        """The world after this AI tick's events (default: ignored)."""

    def affect_sound(self, sound: Sound) -> Sound:
        """How a new noise sounds while this stimulus is active (default: unchanged)."""
        return sound

    def guard_layers(self, ctx: FieldContext) -> Mapping[int, tuple[np.ndarray, Mapping[str, Any]]]:
        """Field terms for single guards: guard index → (layer (n,), why) (default: none).

        Coordinated roles (:mod:`ai.roles`) give each guard its own pull this way; the set
        hands them to ``guard_ai.set_guard_information``.
        """
        return {}

    def describe(self) -> dict[str, Any]:
        """A JSON-able summary for traces."""
        return {"name": self.name, "node": int(self.node)}


# ---------------------------------------------------------------------------- the registry

#: Every stimulus class known by its :attr:`~Stimulus.name`: the built-in mechanics
#: (:mod:`ai.builtin_stimuli`), then each plugin as :func:`ai.plugins.load_stimulus` loads
#: it. The config's sections of their :attr:`~Stimulus.parameters` (``game.schema``) and
#: the trace reader's markers (``game.trace``) read it.
STIMULUS_TYPES: dict[str, type[Stimulus]] = {}


def register_stimulus(cls: type[Stimulus]) -> type[Stimulus]:
    """Make stimulus class ``cls`` known by its name and return it. Refuses
    (:class:`StimulusError`) a name or section that is no word and a display or short name
    that is no short line (:mod:`navmesh.names`); the name of a built-in stimulus (a plugin
    named ``corpse`` would change the built-in corpse's markers; a plugin loaded again
    replaces its older self); parameters that are no
    :class:`~ai.params.Params` dataclass with a bound for every field and defaults within
    them (:meth:`~ai.params.Params.declaration_problem`); or a section that holds a guard
    mode's, a player policy's or another stimulus's parameters.
    """
    name = cls.name
    problem = name_problem(name)
    if problem is not None:
        raise StimulusError(f"{cls.__name__}: name {problem}")
    for attr, check in (("section", name_problem), ("display", label_problem),
                        ("short", label_problem)):
        problem = check(getattr(cls, attr))
        if problem is not None:
            raise StimulusError(f"{name}: {attr} {problem}")
    held = STIMULUS_TYPES.get(name)
    if held is not None and held is not cls and name in _BUILT_IN:
        raise StimulusError(f"{name}: a built-in stimulus ({held.__module__}."
                            f"{held.__qualname__}); give the stimulus a name of its own")
    params = cls.parameters
    if params is not None:
        _check_parameters(cls, params)
    STIMULUS_TYPES[name] = cls
    return cls


#: the names of the built-in mechanics (:func:`seal_built_in`): no plugin takes them
_BUILT_IN: set[str] = set()


def seal_built_in() -> None:
    """Fix the names registered so far as the built-in mechanics' (:mod:`ai.builtin_stimuli`
    calls it once they are registered)."""
    _BUILT_IN.update(STIMULUS_TYPES)


def _check_parameters(cls: type[Stimulus], params: Any) -> None:
    name, section = cls.name, cls.section
    problem = Params.declaration_problem(params)
    if problem is not None:
        raise StimulusError(f"{name}: parameters {problem}")
    taken = [f"{r.name!r}" for r in registrations() if r.section == section]
    taken += [f"stimulus {other.name!r}" for other in STIMULUS_TYPES.values()
              if other.section == section and other.parameters is not None
              and other.name != name]
    if taken:
        raise StimulusError(f"{name}: config section [{section}] already holds the parameters "
                            f"of {taken[0]}; declare a section of its own")


def unregister_stimulus(name: str) -> None:
    """Forget the stimulus class registered as ``name`` (tests, notebooks): its config
    section is gone from configs made afterwards. A built-in one stays."""
    if name not in _BUILT_IN:
        STIMULUS_TYPES.pop(name, None)


# ---------------------------------------------------------------------------- event rules

#: A rule turns one world event into new stimuli (or none).
Rule = Callable[[Event, FieldContext], "Stimulus | Iterable[Stimulus] | None"]
