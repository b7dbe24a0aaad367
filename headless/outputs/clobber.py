"""An output is never an input of the same command, nor a results store: one guard for all.

Opening an output for writing truncates it, so ``stealth sim LEVEL --trace LEVEL`` would
destroy the level before the first tick, and ``sim --from DIR --trial KEY --trace
DIR/results.sqlite`` the store it reads. :func:`refuse_inputs` is called by every command
that writes a file (``sim --trace``, ``play``/``replay --screenshot``, ``report``,
``mechanics``, ``tune``, the analyses' ``--write``/``--figure``) before anything is opened,
and refuses a directory where a file is to be written.
It compares the output with the command's input files by identity
(:func:`os.path.samefile`: the same file under another name, a symlink or a hard link
included) and refuses any existing SQLite file (a results store or a study): no command
writes a store through a path the user typed as an output.
"""

from __future__ import annotations

import os
from collections.abc import Iterable
from pathlib import Path
from typing import IO

from ..errors import UserError

__all__ = ["is_store_file", "level_file", "open_output", "plugin_files", "refuse_inputs", "refuse_inputs_all"]

_SQLITE_HEADER = b"SQLite format 3\x00"


def is_store_file(path: str | Path) -> bool:
    """Whether ``path`` is an existing SQLite database (a results store, an Optuna study)."""
    try:
        with open(path, "rb") as handle:
            return handle.read(len(_SQLITE_HEADER)) == _SQLITE_HEADER
    except OSError:
        return False


def refuse_inputs(option: str, output: str | Path, inputs: Iterable[str | Path | None],
                  folder: bool = False) -> None:
    """Raise a one-line :class:`UserError` if ``output`` is one of ``inputs`` or a store,
    or an existing directory where a file is written (``folder``: the output is a folder,
    as ``play --record``'s), so a command refuses it before it writes any other output.

    >>> import tempfile
    >>> level = Path(tempfile.mkdtemp()) / "level.json"
    >>> _ = level.write_text("{}")
    >>> refuse_inputs("--trace", level, [level])  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    navmesh.errors.UserError: --trace ...level.json: is an input of this command; writing it would destroy it
    """
    target = Path(output)
    if not target.exists():
        return
    if target.is_dir() and not folder:
        raise UserError(f"{option} {output}: is a directory; it names a file")
    for source in inputs:
        if source is None:
            continue
        try:
            same = os.path.samefile(target, source)
        except OSError:  # an input that is not a file (a bundled name, a vanished file)
            continue
        if same:
            raise UserError(f"{option} {output}: is an input of this command; writing it "
                            "would destroy it")
    if target.is_file() and is_store_file(target):
        raise UserError(f"{option} {output}: is a results store (an SQLite file); writing it "
                        "would destroy it")


def refuse_inputs_all(option: str, outputs: Iterable[str | Path],
                      inputs: Iterable[str | Path | None]) -> None:
    """:func:`refuse_inputs` for each of several outputs of one command."""
    sources = list(inputs)
    for output in outputs:
        refuse_inputs(option, output, sources)


def plugin_files(stimuli: Iterable[str]) -> list[str]:
    """The files of ``FILE.py:NAME`` plugin references (entry-point names have none)."""
    return [p.rpartition(":")[0] for p in stimuli if ":" in p]


def open_output(option: str, output: str | Path, inputs: Iterable[str | Path | None]) -> IO[str]:
    """``output`` opened for writing text, after :func:`refuse_inputs`; one line if it cannot be."""
    refuse_inputs(option, output, inputs)
    try:
        return open(output, "w", encoding="utf-8")
    except OSError as error:
        raise UserError(f"{option} {output}: cannot write ({error.strerror or error})") from None


def level_file(level: str | Path | None) -> Path | None:
    """The file a level argument names (None: none given, or nothing it resolves to now)."""
    if level is None:
        return None
    from navmesh.errors import StealthError
    from navmesh.level import resolve_level_path

    try:
        return Path(resolve_level_path(level))
    except StealthError:
        return None
