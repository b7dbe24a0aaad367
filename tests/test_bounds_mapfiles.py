"""Issue 24 class 1: every file a Tiled map names, and every layer it inflates, is bounded.

An external tileset or template that is a FIFO or a device is refused before it is opened
for reading; a compressed layer is inflated against the size its tiles take (width × height
× 4 bytes) and refused past it; a map's own size meets the cell limit before anything of
that size is allocated. Each ends in one ``stealth: error:`` line, quickly.
"""

from __future__ import annotations

import base64
import copy
import gzip
import json
import os
import sys
import time
import zlib
from pathlib import Path

import pytest

from headless.cli import main
from navmesh.errors import LevelError
from navmesh.files import FileRefused, inflate_bounded, zstd_size_bound
from navmesh.level import load_level

ROOT = Path(__file__).resolve().parent.parent
LEVELS = ROOT / "assets" / "levels"
MAZE_TMJ = json.loads((LEVELS / "maze.tmj").read_text())
TILESET = str(LEVELS / "walls.tsj")

pytestmark = pytest.mark.skipif(sys.platform == "win32", reason="POSIX special files")


def _map(tmp_path: Path, name: str = "map.tmj", **changes: object) -> tuple[Path, dict]:
    doc = copy.deepcopy(MAZE_TMJ)
    doc["tilesets"] = [{"firstgid": 1, "source": TILESET}]
    doc.update(changes)
    return tmp_path / name, doc


def _write(path: Path, doc: dict) -> Path:
    path.write_text(json.dumps(doc))
    return path


def _refused(path: Path, match: str, capsys: pytest.CaptureFixture[str]) -> None:
    start = time.monotonic()
    assert main(["validate", str(path)]) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("stealth: error: "), lines
    assert match in lines[0], lines[0]
    assert time.monotonic() - start < 10


def _bomb_layer(doc: dict, compression: str, payload: bytes) -> None:
    layer = doc["layers"][0]
    layer.pop("data")
    layer.update(encoding="base64", compression=compression,
                 data=base64.b64encode(payload).decode("ascii"))


def _zstd(raw: bytes) -> bytes:
    import zstd  # pytiled-parser's zstd extra

    return bytes(zstd.compress(raw, 19))


def test_fifo_tileset_is_refused_without_blocking(tmp_path, capsys):
    os.mkfifo(tmp_path / "pipe.tsj")
    path, doc = _map(tmp_path)
    doc["tilesets"] = [{"firstgid": 1, "source": "pipe.tsj"}]
    _refused(_write(path, doc), "tilesets[0].source: ", capsys)
    assert "is a FIFO (named pipe)" in str(_error(path))


def test_device_tileset_is_refused(tmp_path, capsys):
    path, doc = _map(tmp_path)
    doc["tilesets"] = [{"firstgid": 1, "source": "/dev/zero"}]
    _refused(_write(path, doc), "/dev/zero is a character device", capsys)


def test_fifo_template_is_refused(tmp_path, capsys):
    os.mkfifo(tmp_path / "guard.tj")
    path, doc = _map(tmp_path)
    doc["layers"][1]["objects"][0]["template"] = "guard.tj"
    _refused(_write(path, doc), "template: ", capsys)


@pytest.mark.parametrize("compression", ["zstd", "zlib", "gzip"])
def test_compression_bomb_is_refused_quickly(tmp_path, capsys, compression):
    # 64 MiB of zeros: the 400 MiB of the issue behaves the same, only slower to build
    raw = bytes(64 * 2**20)
    payload = {"zstd": _zstd, "zlib": zlib.compress, "gzip": gzip.compress}[compression](raw)
    path, doc = _map(tmp_path)
    _bomb_layer(doc, compression, payload)
    _refused(_write(path, doc), "layer 'walls': tile data decompresses to", capsys)


def test_compressed_layer_of_the_right_size_still_loads(tmp_path):
    plain = load_level(LEVELS / "maze.tmj")
    gids = MAZE_TMJ["layers"][0]["data"]
    raw = b"".join(int(g).to_bytes(4, "little") for g in gids)
    for compression, pack in (("zstd", _zstd), ("zlib", zlib.compress), ("gzip", gzip.compress)):
        path, doc = _map(tmp_path, name=f"{compression}.tmj")
        _bomb_layer(doc, compression, pack(raw))
        level = load_level(_write(path, doc))
        assert (level.occupancy == plain.occupancy).all()


def test_layer_data_of_the_wrong_length_is_refused(tmp_path):
    path, doc = _map(tmp_path)
    _bomb_layer(doc, "zlib", zlib.compress(bytes(4 * 399)))
    with pytest.raises(LevelError, match="tile data is 1596 bytes, expected 1600"):
        load_level(_write(path, doc))


def test_map_size_meets_the_cell_limit_first(tmp_path, capsys):
    path, doc = _map(tmp_path, width=10**9, height=10**9)
    _refused(_write(path, doc), "map of 1000000000x1000000000", capsys)


def test_infinite_map_spanning_far_chunks_meets_the_cell_limit(tmp_path):
    path, doc = _map(tmp_path, infinite=True)
    layer = doc["layers"][0]
    layer.pop("data")
    one = [1] + [0] * 255
    layer["chunks"] = [{"x": 0, "y": 0, "width": 16, "height": 16, "data": one},
                       {"x": 10**8, "y": 10**8, "width": 16, "height": 16, "data": one}]
    with pytest.raises(LevelError, match="exceeds the limit of 1000000 cells"):
        load_level(_write(path, doc))


def test_zstd_frame_without_content_size_is_bounded_by_its_blocks():
    # no content size, a 1 KiB window, 3000 RLE blocks of 1 KiB: 12 KB that claims 3 MB
    header = (0xFD2FB528).to_bytes(4, "little") + bytes([0x00, 0x00])

    def block(last: int) -> bytes:
        return ((1024 << 3) | (1 << 1) | last).to_bytes(3, "little") + b"\0"

    frame = header + b"".join(block(0) for _ in range(2999)) + block(1)
    assert zstd_size_bound(frame) == 3000 * 1024
    with pytest.raises(FileRefused, match="decompresses to up to"):
        inflate_bounded(frame, "zstd", 1600)
    with pytest.raises(FileRefused, match="not valid zstd data"):
        inflate_bounded(b"not zstd at all", "zstd", 1600)
    assert zstd_size_bound(_zstd(bytes(1600))) == 1600


def test_gzip_members_and_corrupt_streams():
    two = gzip.compress(b"a" * 10) + gzip.compress(b"b" * 10)
    assert inflate_bounded(two, "gzip", 20) == b"a" * 10 + b"b" * 10
    with pytest.raises(FileRefused, match="more than the limit"):
        inflate_bounded(two, "gzip", 19)
    with pytest.raises(FileRefused, match="truncated"):
        inflate_bounded(zlib.compress(bytes(100))[:-3], "zlib", 1000)


def _error(path: Path) -> LevelError:
    with pytest.raises(LevelError) as info:
        load_level(path)
    return info.value
