"""Work the game does beside its frames runs at the lowest priority.

The game on a large level computes its field overlay on a thread
(:class:`game.scene.SceneBuilder`) and the distance metric's searches in a process
(:mod:`game.large.distance_worker`). On a machine of two cores they would otherwise take a core
from the frame loop or from the display server just when a frame is due; at nice 19 they
use what is left. Their results are the same either way, only later.
"""

from __future__ import annotations

import os
import threading

__all__ = ["lowest_priority"]


def lowest_priority() -> None:
    """Run the calling thread (Linux: each thread has its own nice value) at nice 19."""
    try:
        os.setpriority(os.PRIO_PROCESS, threading.get_native_id(), 19)
    except (AttributeError, OSError):  # not Linux, or not allowed: only slower, never wrong
        pass
