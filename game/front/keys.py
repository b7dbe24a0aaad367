"""The keys of ``stealth play``, as plain data (no pygame), so ``stealth play --help`` can
list them without opening a window.

:mod:`game.front.play` binds the same keys; a test checks that every key listed here does
what it says.

>>> MODE_ORDER[0], KEY_HELP[0]
('pf', ('W A S D / arrows', 'move the player'))
"""

from __future__ import annotations

__all__ = ["KEY_HELP", "MODE_ORDER", "key_table"]

#: Guard modes on the number keys 1, 2, … (SPEC §9 order).
MODE_ORDER: tuple[str, ...] = ("pf", "random", "fsm", "staleness", "cheat")

#: ``(keys, what they do)`` in the order the help shows them.
KEY_HELP: tuple[tuple[str, str], ...] = (
    ("W A S D / arrows", "move the player"),
    ("Shift", "sprint (footstep noise)"),
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
    (f"1-{len(MODE_ORDER)}", "restart with guards " + "/".join(MODE_ORDER)),
    ("Enter", "restart"),
    ("N / B", "next / previous level"),
    ("Esc", "quit"),
)


def key_table() -> str:
    """The keys as an aligned two-column text (``stealth play --help``)."""
    width = max(len(keys) for keys, _ in KEY_HELP)
    return "\n".join(f"  {keys:<{width}}  {what}" for keys, what in KEY_HELP)
