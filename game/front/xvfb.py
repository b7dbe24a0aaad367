"""A private X server (Xvfb) for real-window tests and benchmarks.

The server picks a free display number itself (``-displayfd``) and reports it once it
accepts connections, so parallel test workers, other users' servers and repeated runs
never clash and nobody waits a fixed time for it to start.
"""

from __future__ import annotations

import os
import select
import shutil
import subprocess
from collections.abc import Iterator
from contextlib import contextmanager

__all__ = ["XvfbError", "xvfb"]


class XvfbError(RuntimeError):
    """Xvfb is missing or did not start."""


@contextmanager
def xvfb(size: tuple[int, int] = (1280, 1024), timeout: float = 20.0) -> Iterator[str]:
    """Run an Xvfb server for the ``with`` block; yields its ``DISPLAY`` (``":N"``)."""
    binary = shutil.which("Xvfb")
    if binary is None:
        raise XvfbError("Xvfb is not installed (apt-get install xvfb)")
    read, write = os.pipe()
    proc = subprocess.Popen(
        [binary, "-displayfd", str(write), "-screen", "0", f"{size[0]}x{size[1]}x24",
         "-nolisten", "tcp"],
        pass_fds=(write,), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    os.close(write)
    try:
        text = b""
        while not text.endswith(b"\n"):
            ready, _, _ = select.select([read], [], [], timeout)
            chunk = os.read(read, 64) if ready else b""
            if not chunk:
                raise XvfbError(f"Xvfb did not start within {timeout:g} s")
            text += chunk
        yield f":{int(text)}"
    finally:
        os.close(read)
        proc.terminate()
        try:
            proc.wait(5)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()
