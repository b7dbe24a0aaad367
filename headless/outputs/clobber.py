"""An output file must never be one of the command's inputs (``--trace`` onto the level).

Opening an output for writing truncates it, so ``stealth sim LEVEL --trace LEVEL`` would
destroy the level before the first tick. :func:`refuse_inputs` compares the output with the
command's input files by identity (:func:`os.path.samefile`: the same file under another
name, a symlink or a hard link included) before anything is opened.
"""

from __future__ import annotations

import os
from collections.abc import Iterable
from pathlib import Path

from ..errors import UserError

__all__ = ["refuse_inputs"]


def refuse_inputs(option: str, output: str | Path, inputs: Iterable[str | Path]) -> None:
    """Raise a one-line :class:`UserError` if ``output`` is one of ``inputs``.

    >>> import tempfile
    >>> level = Path(tempfile.mkdtemp()) / "level.json"
    >>> _ = level.write_text("{}")
    >>> refuse_inputs("--trace", level, [level])  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    navmesh.errors.UserError: --trace ...level.json: is an input of this command (the level or a plugin); writing it would destroy it
    """
    target = Path(output)
    if not target.exists():
        return
    for source in inputs:
        try:
            same = os.path.samefile(target, source)
        except OSError:  # an input that is not a file (a bundled name, a vanished file)
            continue
        if same:
            raise UserError(f"{option} {output}: is an input of this command (the level or a "
                            "plugin); writing it would destroy it")
