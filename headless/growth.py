"""Growing a design in its store: more seeds or new factor levels, never another design.

A results store remembers the design it holds (``meta.design``, :meth:`Preset.design`). A
later ``stealth run`` into the same directory may ask for the same design with other seeds
(``--seeds N``) or other levels of the same factors; the sweep then runs only the trials
that are missing, and the store's design becomes the union of both. Anything else — other
levels, modes, policies, scenarios, root seed, ``[set]``, or another set of factor keys —
is a different experiment and is refused.

>>> old = {"guards": ["pf"], "seeds": [0, 1], "set": {}, "factors": {"pf.rho": [0.9]}}
>>> new = {"guards": ["pf"], "seeds": [0, 1, 2], "set": {}, "factors": {"pf.rho": [0.95]}}
>>> design_change(old, new) is None
True
>>> grown_design(old, new)["factors"], grown_design(old, new)["seeds"]
({'pf.rho': [0.9, 0.95]}, [0, 1, 2])
>>> design_change(old, {**new, "guards": ["cheat"]})
'guards'
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

__all__ = ["design_change", "design_trials", "grown_design"]

_GROWABLE = ("seeds", "factors")


def design_change(old: Mapping[str, Any], new: Mapping[str, Any]) -> str | None:
    """The first field in which ``new`` is not ``old`` grown, or None (a growth or equal)."""
    for name in sorted(set(old) | set(new)):
        if name not in _GROWABLE and old.get(name) != new.get(name):
            return name
    if set(old.get("factors", {})) != set(new.get("factors", {})):
        return "factors"
    return None


def _union(first: list[Any], second: list[Any]) -> list[Any]:
    seen = {repr(v) for v in first}
    return [*first, *(v for v in second if repr(v) not in seen)]


def grown_design(old: Mapping[str, Any], new: Mapping[str, Any]) -> dict[str, Any]:
    """The design a store holds after ``new`` ran into it: seeds and factor levels united."""
    grown = dict(new)
    grown["seeds"] = sorted(set(old.get("seeds", [])) | set(new.get("seeds", [])))
    if new.get("factors"):
        old_factors = old.get("factors", {})
        grown["factors"] = {key: _union(old_factors.get(key, []), values)
                            for key, values in new["factors"].items()}
    return grown


def design_trials(design: Mapping[str, Any]) -> int:
    """Number of trials of a stored design."""
    lists = ("levels", "abstractions", "guards", "players", "scenarios", "seeds")
    sizes = [len(design.get(name, [])) for name in lists]
    sizes += [len(values) for values in design.get("factors", {}).values()]
    return math.prod(sizes)
