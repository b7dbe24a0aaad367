"""Reading an input file safely: a regular file of bounded size, or a one-line refusal.

Every file the user names (a level, a preset, a trace) is read through :func:`read_regular`:
a FIFO, a device (``/dev/zero``), a socket or a directory is refused before a byte is read
— a FIFO is opened without blocking, so a path nobody writes to cannot hang the command —
and a file larger than the caller's limit is refused instead of read into memory; the read
itself is bounded too, so a file that grows while it is read cannot exhaust memory either.

>>> import os, tempfile
>>> folder = tempfile.mkdtemp()
>>> fifo = os.path.join(folder, "pipe")
>>> os.mkfifo(fifo)
>>> read_regular(fifo, 1024)
Traceback (most recent call last):
...
navmesh.files.FileRefused: is a FIFO (named pipe), not a regular file
"""

from __future__ import annotations

import os
import stat
import zlib
from pathlib import Path

from .errors import UserError

__all__ = ["FileRefused", "inflate_bounded", "read_regular", "zstd_size_bound"]

_KINDS = ((stat.S_ISDIR, "a directory"), (stat.S_ISFIFO, "a FIFO (named pipe)"),
          (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"),
          (stat.S_ISSOCK, "a socket"))


# never wait for a FIFO's writer, never adopt a terminal as controlling tty
_FLAGS = os.O_RDONLY | (os.O_NONBLOCK | os.O_NOCTTY if os.name == "posix" else 0)


class FileRefused(UserError):
    """An input that is not a regular file or is too large; the message is the problem only
    (callers prefix the file and the field in their own error type)."""


def _mebibytes(n: int) -> str:
    return f"{n / 2**20:.0f} MiB" if n >= 2**20 else f"{n} bytes"


def read_regular(path: str | Path, limit: int) -> bytes:
    """The bytes of ``path``, a regular file of at most ``limit`` bytes.

    Raises :class:`FileRefused` for another kind of file or a larger one; ``OSError``
    (``FileNotFoundError``, ``PermissionError``, ...) as :func:`open` does.
    """
    fd = os.open(path, _FLAGS)
    try:
        info = os.fstat(fd)
        for test, kind in _KINDS:
            if test(info.st_mode):
                raise FileRefused(f"is {kind}, not a regular file")
        if not stat.S_ISREG(info.st_mode):  # pragma: no cover - doors, whiteouts
            raise FileRefused("is not a regular file")
        if info.st_size > limit:
            raise FileRefused(f"is {_mebibytes(info.st_size)}, larger than the limit of "
                              f"{_mebibytes(limit)}")
        chunks: list[bytes] = []
        total = 0
        while total <= limit:
            chunk = os.read(fd, min(1 << 20, limit + 1 - total))
            if not chunk:
                break
            chunks.append(chunk)
            total += len(chunk)
        if total > limit:
            raise FileRefused(f"grew past the limit of {_mebibytes(limit)} while it was read")
        return b"".join(chunks)
    finally:
        os.close(fd)


_ZSTD_MAGIC = 0xFD2FB528
_ZSTD_BLOCK_MAX = 128 * 1024  # a zstd block never regenerates more than this


def inflate_bounded(data: bytes, compression: str, limit: int) -> bytes:
    """``data`` decompressed (``"zlib"``, ``"gzip"`` or ``"zstd"``), refused past ``limit`` bytes.

    zlib and gzip are inflated with a bounded ``decompressobj``, so a bomb stops at
    ``limit + 1`` bytes; zstd frames are measured from their headers (the declared content
    size, else the number of blocks times the largest block) before a byte is inflated. Raises
    :class:`FileRefused` for a stream that is too large or corrupt.
    """
    if compression == "zstd":
        declared = zstd_size_bound(data)
        if declared > limit:
            raise FileRefused(f"decompresses to up to {_mebibytes(declared)}, more than "
                              f"the limit of {_mebibytes(limit)}")
        try:
            import zstd  # type: ignore[import-untyped]  # pytiled-parser's optional extra
        except ImportError as exc:
            raise FileRefused("is zstd-compressed, but the zstd module is not installed "
                              "(pip install pytiled-parser[zstd])") from exc
        try:
            out: bytes = zstd.decompress(data)
        except zstd.Error as exc:
            raise FileRefused(f"is not valid zstd data ({exc})") from None
        if len(out) > limit:  # pragma: no cover - the header bound above is exact or larger
            raise FileRefused(f"decompresses to more than {_mebibytes(limit)}")
        return out
    if limit < 0:
        raise ValueError("limit must be >= 0")  # zlib reads max_length 0 as "no limit"
    if compression not in ("zlib", "gzip"):
        raise FileRefused(f"unknown compression {compression!r} (zlib, gzip or zstd)")
    wbits = 31 if compression == "gzip" else 15
    chunks: list[bytes] = []
    total = 0
    rest = data
    while True:
        inflater = zlib.decompressobj(wbits)
        try:
            chunk = inflater.decompress(rest, limit + 1 - total)
        except zlib.error as exc:
            raise FileRefused(f"is not valid {compression} data ({exc})") from None
        chunks.append(chunk)
        total += len(chunk)
        if total > limit:
            raise FileRefused(f"decompresses to more than the limit of {_mebibytes(limit)}")
        if not inflater.eof:
            raise FileRefused(f"is not valid {compression} data (truncated stream)")
        rest = inflater.unused_data
        if compression == "zlib" or not rest:  # gzip may hold several members
            return b"".join(chunks)


def zstd_size_bound(data: bytes) -> int:
    """An upper bound of what the zstd frames in ``data`` decompress to, from headers only.

    A frame that declares its content size counts that (the decoder refuses a frame whose
    output differs); one that does not counts its raw and RLE blocks' sizes and the largest
    block its window allows (at most 128 KiB) per compressed block. Raises :class:`FileRefused`
    for bytes that are not zstd frames.
    """
    total, at = 0, 0
    while at < len(data):
        if len(data) - at < 8:
            raise FileRefused("is not valid zstd data (truncated frame)")
        magic = int.from_bytes(data[at:at + 4], "little")
        if magic & 0xFFFFFFF0 == 0x184D2A50:  # skippable frame: its size, then its bytes
            at += 8 + int.from_bytes(data[at + 4:at + 8], "little")
            continue
        if magic != _ZSTD_MAGIC:
            raise FileRefused("is not valid zstd data (bad frame magic)")
        descriptor = data[at + 4]
        single = bool(descriptor & 0x20)
        fcs_bytes = (1 if single else 0, 2, 4, 8)[descriptor >> 6]
        block_max = _ZSTD_BLOCK_MAX
        if not single:  # the window descriptor caps a block further
            window = data[at + 5]
            base = 1 << (10 + (window >> 3))
            block_max = min(block_max, base + base // 8 * (window & 7))
        at += 5 + (0 if single else 1) + (0, 1, 2, 4)[descriptor & 3]
        declared = None
        if fcs_bytes:
            declared = int.from_bytes(data[at:at + fcs_bytes], "little")
            declared += 256 if fcs_bytes == 2 else 0
        at += fcs_bytes
        regenerated = 0
        while True:
            if len(data) - at < 3:
                raise FileRefused("is not valid zstd data (truncated block)")
            header = int.from_bytes(data[at:at + 3], "little")
            kind, size = (header >> 1) & 3, header >> 3
            if kind == 3:
                raise FileRefused("is not valid zstd data (reserved block type)")
            at += 3 + (1 if kind == 1 else size)  # an RLE block stores one byte
            # raw and RLE blocks regenerate their size, a compressed one at most a block
            regenerated += block_max if kind == 2 else size
            if header & 1:
                break
        at += 4 if descriptor & 0x04 else 0  # content checksum
        total += declared if declared is not None else regenerated
    return total
