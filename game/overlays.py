"""Field overlays: which of the guard AI's ``fields()`` a renderer draws, and how (the O key
of ``stealth play`` cycles through them, ``--overlay`` names one).

A registry of plain data, apart from :mod:`game.scene` which turns an overlay into a
:class:`~game.scene.FieldLayer`, so the command line can list the overlays without
importing numpy or shapely (numpy is imported when an overlay's values are computed).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    import numpy as np

__all__ = ["OVERLAYS", "OVERLAY_ALIASES", "Overlay", "overlay_key", "overlay_label",
           "register_overlay", "unregister_overlay"]


@dataclass(frozen=True)
class Overlay:
    """A field overlay: which of the guard AI's ``fields()`` it draws, and how.

    ``fields`` names the arrays it reads (the first is required: without it the overlay
    says "not available"); ``combine`` turns them into the drawn values and the legend
    title (default: the first array and ``label``); ``aliases`` are extra spellings for
    ``--overlay``. Register one with :func:`register_overlay`.
    """

    key: str
    label: str
    fields: tuple[str, ...]
    combine: Callable[..., tuple[np.ndarray, str]] | None = None
    aliases: tuple[str, ...] = ()

    def layer_values(self, sources: Sequence[Any]) -> tuple[np.ndarray, str]:
        """The values to draw and the legend title, from the arrays named by ``fields``."""
        import numpy as np

        if self.combine is not None:
            return self.combine(*sources)
        return np.asarray(sources[0], dtype=np.float64), self.label


def _information_plus_stimuli(info: Any, extra: Any) -> tuple[np.ndarray, str]:
    """``I`` shows the information field plus the stimuli layer (what enters P)."""
    import numpy as np

    values = np.asarray(info, dtype=np.float64)
    if extra is not None and np.any(np.asarray(extra) != 0):
        return values + np.asarray(extra, dtype=np.float64), "Information I + stimuli"
    return values, "Information I"


#: The overlay registry, in the order the overlay key cycles through it ("none" first).
OVERLAYS: dict[str, Overlay | None] = {"none": None}
#: Accepted spellings of overlay names on the command line.
OVERLAY_ALIASES: dict[str, str] = {"none": "none", "off": "none"}


def register_overlay(overlay: Overlay) -> None:
    """Add ``overlay`` to the cycle and to ``--overlay`` (its key and aliases)."""
    OVERLAYS[overlay.key] = overlay
    for name in (overlay.key, *overlay.aliases):
        OVERLAY_ALIASES[name.lower()] = overlay.key


def unregister_overlay(key: str) -> None:
    """Remove an overlay added by :func:`register_overlay` (tests, notebooks)."""
    OVERLAYS.pop(key, None)
    for name, target in list(OVERLAY_ALIASES.items()):
        if target == key:
            del OVERLAY_ALIASES[name]


def overlay_label(key: str) -> str:
    """The legend title of overlay ``key``."""
    overlay = OVERLAYS.get(key)
    return "no overlay" if overlay is None else overlay.label


register_overlay(Overlay("I", "Information I", ("I", "I_extra"), _information_plus_stimuli,
                         ("information", "info")))
register_overlay(Overlay("C", "Confidence C", ("C",), aliases=("confidence",)))
register_overlay(Overlay("N", "Connectivity N", ("N",), aliases=("connectivity",)))
register_overlay(Overlay("P", "Composite potential P", ("P",), aliases=("potential", "composite")))
register_overlay(Overlay("K", "Kernel K", ("K",), aliases=("kernel",)))


def overlay_key(name: str) -> str:
    """The overlay key (``none``, ``I``, ``C``, ``N``, ``P``, ``K``, ...) for a name or alias.

    >>> overlay_key("kernel"), overlay_key("I")
    ('K', 'I')
    """
    key = OVERLAY_ALIASES.get(name.strip().lower())
    if key is None:
        names = ", ".join(sorted(set(OVERLAY_ALIASES) - set(OVERLAYS), key=str.lower))
        raise ValueError(f"unknown overlay {name!r} (choose from {', '.join(OVERLAYS)}, "
                         f"or {names})")
    return key
