"""Which SDL video driver a run gets when nobody chose one (a machine without a display).

On Linux without ``DISPLAY`` and ``WAYLAND_DISPLAY``, SDL probes Wayland and X11 before
falling back to an offscreen window, and libwayland prints ``error: XDG_RUNTIME_DIR is
invalid or not set in the environment`` on the way — a line that reads like a failure of
a run that then works. :func:`choose_video_driver` makes such a run headless from the start
(``SDL_VIDEODRIVER=dummy``) and says so in one line on stderr.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Mapping, MutableMapping
from typing import TextIO

__all__ = ["choose_video_driver", "headless_by_default"]

NOTE = ("stealth: no display (DISPLAY and WAYLAND_DISPLAY are unset): running headless, "
        "as with SDL_VIDEODRIVER=dummy")


def headless_by_default(environ: Mapping[str, str], platform: str = sys.platform) -> bool:
    """Whether a Linux machine has no display and nobody chose an SDL video driver.

    >>> headless_by_default({}, "linux"), headless_by_default({"DISPLAY": ":0"}, "linux")
    (True, False)
    >>> headless_by_default({"SDL_VIDEODRIVER": "x11"}, "linux"), headless_by_default({}, "darwin")
    (False, False)
    """
    if not platform.startswith("linux") or environ.get("SDL_VIDEODRIVER"):
        return False
    return not environ.get("DISPLAY") and not environ.get("WAYLAND_DISPLAY")


def choose_video_driver(environ: MutableMapping[str, str] = os.environ,
                        stream: TextIO | None = None) -> None:
    """Before ``pygame.display.init()``: the dummy driver, with :data:`NOTE`, when
    :func:`headless_by_default`; otherwise leave SDL's choice alone."""
    if headless_by_default(environ):
        environ["SDL_VIDEODRIVER"] = "dummy"
        print(NOTE, file=stream or sys.stderr)
