"""The keys of ``stealth play``, as plain data (no pygame), so ``stealth play --help`` can
list them without opening a window.

:mod:`game.front.play` binds the same keys; a test checks that every key listed here does
what it says. The number keys are the registered guard modes' (:data:`ai.GUARD_MODES`), in
registration order, so a mode registered later gets the next key.

>>> mode_order()[:2], key_help()[0]
(('pf', 'random'), ('W A S D / arrows', 'move the player'))
"""

from __future__ import annotations

from ai import GUARD_MODES

__all__ = ["key_help", "key_table", "mode_on_key", "mode_order"]

#: number keys 1 … 9
_NUMBER_KEYS = 9


def mode_order() -> tuple[str, ...]:
    """The guard modes on the number keys 1, 2, … (registration order, SPEC §9's first)."""
    return tuple(GUARD_MODES)[:_NUMBER_KEYS]


def mode_on_key(number: int) -> str | None:
    """The guard mode on number key ``number`` (1 … 9), or None when no mode is there."""
    modes = mode_order()
    return modes[number - 1] if 1 <= number <= len(modes) else None


def key_help() -> tuple[tuple[str, str], ...]:
    """``(keys, what they do)`` in the order the help shows them, the number keys' modes
    as registered now."""
    modes = mode_order()
    return tuple((f"1-{len(modes)}", "restart with guards " + "/".join(modes))
                 if keys == _MODES else (keys, what) for keys, what in _KEYS)


_MODES = "1-N"
#: ``(keys, what they do)``; the number keys' line (``1-N``) is filled in by :func:`key_help`.
_KEYS: tuple[tuple[str, str], ...] = (
    ("W A S D / arrows", "move the player"),
    ("Shift", "sprint (footstep noise)"),
    ("Ctrl / C", "slow walk (half speed, quieter, half as noticeable)"),
    ("left click", "throw a decoy at the pointer"),
    ("E", "activate the static decoy you stand next to"),
    ("F", "take down the guard in reach (leaves a corpse)"),
    ("R", "toggle rain"),
    ("Space", "pause"),
    ("V", "sound on / off"),
    ("[ ]", "volume down / up"),
    ("wheel / + -", "zoom (the camera follows you)"),
    ("O / Tab", "next field overlay (none, I, C, N, P, K, ...)"),
    ("M", "show the grid / navmesh"),
    ("G", "show the guards' plans"),
    (_MODES, ""),
    ("Enter", "restart"),
    ("N / B", "next / previous level"),
    ("Esc", "pause menu (resume, restart, volume, controls, quit)"),
    ("Q", "quit"),
)


def key_table() -> str:
    """The keys as an aligned two-column text (``stealth play --help``)."""
    rows = key_help()
    width = max(len(keys) for keys, _ in rows)
    return "\n".join(f"  {keys:<{width}}  {what}" for keys, what in rows)
