"""Zones (SPEC §5): the static counterpart of stimuli, lighting and concealment of level cells.

A :class:`Zone` says what it does to the confidence decay of its cells and to the guards'
view range when the player stands in it.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from .bounds import NON_NEGATIVE, UNIT, Bound
from .view import GuardAI


@dataclass(frozen=True)
class Zone:
    """What a kind of level zone does (SPEC §5): lighting and concealment.

    ``confidence_decay``: per-second decay of C in the zone's cells instead of ρ (``None``:
    unchanged); ``view_scale``: factor on every guard's view range while the player stands
    in the zone. Where zones overlap, the fastest decay and the smallest scale apply.
    """

    kind: str
    confidence_decay: float | None = None
    view_scale: float = 1.0

    #: allowed values of the two settings; config keys ``zones.<kind>_<setting>`` (game.schema)
    bounds: ClassVar[Mapping[str, Bound]] = {"confidence_decay": UNIT, "view_scale": NON_NEGATIVE}

    def __post_init__(self) -> None:
        for name, bound in self.bounds.items():
            value = getattr(self, name)
            problem = None if value is None else bound.problem(value)
            if problem is not None:
                raise ValueError(f"zone {self.kind}: {name} {problem}, got {value!r}")


def zones_from_config(section: Mapping[str, Any]) -> dict[str, Zone]:
    """Zones from the ``[zones]`` config section: ``<kind>_confidence_decay``, ``<kind>_view_scale``."""
    kinds: dict[str, dict[str, float]] = {}
    for key, value in section.items():
        for suffix in ("_confidence_decay", "_view_scale"):
            if key.endswith(suffix):
                kinds.setdefault(key[: -len(suffix)], {})[suffix[1:]] = float(value)
    return {kind: Zone(kind, **values) for kind, values in kinds.items()}


def zone_view_scale(zones: Mapping[str, Zone], masks: Mapping[str, np.ndarray], n: int) -> np.ndarray:
    """Per node, the factor on the guards' view range while the player stands there."""
    scale = np.ones(n)
    for kind, mask in masks.items():
        zone = zones.get(kind)
        if zone is not None:
            scale = np.where(mask, np.minimum(scale, zone.view_scale), scale)
    return scale


def apply_zones(guard_ai: GuardAI, zones: Mapping[str, Zone], masks: Mapping[str, np.ndarray]) -> None:
    """Give every zone's cells its confidence decay, on a guard AI with that hook (PF).

    Slowest rates first, so where zones overlap the fastest decay wins.
    """
    rules: list[tuple[float, np.ndarray]] = []
    for kind, mask in masks.items():
        rate = zones[kind].confidence_decay if kind in zones else None
        if rate is not None and np.any(mask):
            rules.append((rate, mask))
    for rate, mask in sorted(rules, key=lambda item: -item[0]):
        guard_ai.set_confidence_decay(np.asarray(mask, dtype=bool), rate)
