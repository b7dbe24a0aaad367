"""The work budget: a trial's and a design's physics steps, bounded before anything runs.

Every value of ``world.physics_step`` and ``world.duration`` may be in range on its own and
still ask for an absurd amount of work together: ``duration = 1e15`` or
``physics_step = 1e-300`` would step for ever. :func:`check_trial_steps` is one of the
cross-key rules of :func:`game.schema.check_sections`, so it holds wherever a config is made
— ``--set``, ``--config``, a preset's ``[set]``, a store row re-run by ``sim --from``, ``play``
— and :func:`check_design_steps` bounds a preset's trials × steps over its ``[factors]``
before the first trial. (The smoothing kernel's size, ``pf.kernel_radius``, depends on the
level's graph; :func:`ai.fields.kernel_matrix` bounds it when the graph is known.)

>>> check_trial_steps({"world.duration": 60.0, "world.physics_step": 0.05,
...                    "world.physics_step_interactive": 1 / 60})
>>> check_trial_steps({"world.duration": 1e15, "world.physics_step": 0.05,
...                    "world.physics_step_interactive": 1 / 60})
Traceback (most recent call last):
...
game.errors.ConfigError: world.duration / world.physics_step = 1e+15 / 0.05 = 2e+16 physics steps per trial, more than the limit of 1000000
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

from .errors import ConfigError

__all__ = ["MAX_DESIGN_STEPS", "MAX_TRIAL_STEPS", "MIN_INTERACTIVE_STEP", "check_design_steps", "check_trial_steps",
           "trial_steps"]

MAX_TRIAL_STEPS = 1_000_000
"""Physics steps one headless trial may take (``world.duration / world.physics_step``):
50,000 s of game time at the default step; the bundled presets take 1,200 (60 s at 1/20 s)."""

MIN_INTERACTIVE_STEP = 0.001
"""The finest ``world.physics_step_interactive``: ``play`` steps in real time, 1,000 steps a
second at most (the default is 60)."""

MAX_DESIGN_STEPS = 2_000_000_000
"""Physics steps of all the trials of a design together: the largest design of default
trials (:data:`headless.presets.MAX_TRIALS` × 1,200 steps) fits; the ``paper`` preset takes
1.2 × 10^7."""


def trial_steps(duration: float, physics_step: float) -> float:
    """The physics steps of a trial, as :class:`game.world.World` counts them (a float, so
    that an absurd ratio does not become an absurd integer)."""
    return float(duration) / float(physics_step)


def check_trial_steps(values: Mapping[str, Any]) -> None:
    """Refuse a config whose headless trial would take more than :data:`MAX_TRIAL_STEPS`
    steps, or whose interactive step is finer than :data:`MIN_INTERACTIVE_STEP` (``play``
    runs in real time, so its work is steps per second); :class:`ConfigError` names the keys."""
    duration, step = float(values["world.duration"]), float(values["world.physics_step"])
    steps = trial_steps(duration, step)
    if not steps <= MAX_TRIAL_STEPS:
        raise ConfigError(
            f"world.duration / world.physics_step = {duration:g} / {step:g} = {steps:.3g} "
            f"physics steps per trial, more than the limit of {MAX_TRIAL_STEPS}")
    interactive = float(values["world.physics_step_interactive"])
    if not interactive >= MIN_INTERACTIVE_STEP:
        raise ConfigError(
            f"world.physics_step_interactive = {interactive:g}: {1 / interactive:.3g} physics "
            f"steps per second of play, more than the limit of {1 / MIN_INTERACTIVE_STEP:g} "
            f"(a step of at least {MIN_INTERACTIVE_STEP:g} s)")


def check_design_steps(trials_per_cell: int, fixed: Mapping[str, Any],
                       factors: Sequence[tuple[str, Sequence[Any]]]) -> None:
    """Refuse a design of more than :data:`MAX_DESIGN_STEPS` physics steps in all.

    ``fixed`` is the design's config (flat keys), ``factors`` its ``[factors]`` (key, levels);
    ``trials_per_cell`` the trials of one combination of factor levels. Every combination's
    own steps are checked too (:func:`check_trial_steps`), so a factor level that is absurd
    only with another factor's level is refused before the first trial.
    """
    levels = dict(factors)
    durations = levels.get("world.duration", [fixed["world.duration"]])
    step_levels = levels.get("world.physics_step", [fixed["world.physics_step"]])
    others = 1
    for key, values in factors:
        if key not in ("world.duration", "world.physics_step"):
            others *= len(values)
    total = 0.0
    for duration in durations:
        for step in step_levels:
            check_trial_steps({**fixed, "world.duration": duration, "world.physics_step": step})
            total += trial_steps(duration, step)
    total *= others * trials_per_cell
    if total > MAX_DESIGN_STEPS:
        raise ConfigError(f"the design's trials take {total:.3g} physics steps in all, more "
                          f"than the limit of {MAX_DESIGN_STEPS}; use fewer seeds, factor "
                          "levels or a shorter world.duration")
