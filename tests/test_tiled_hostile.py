"""Issue 35, Tiled maps: every file the loader opens goes through one guarded reader, and
hostile map content ends in one line naming the file, layer or object (round 4).

Each map here is written by the test (a 20 × 20 maze, TMX or JSON, a few lines of XML for
templates and tilesets); ``docs/hostile-inputs.md`` lists the cases with their results.
"""

from __future__ import annotations

import builtins
import io
import json
import os
import sys
import time
import types
import warnings
from pathlib import Path

import pytest

import navmesh.files
import navmesh.level
from headless.cli import main
from navmesh.errors import LevelError
from navmesh.level import load_level

ROOT = Path(__file__).resolve().parent.parent
MAZE = json.loads((ROOT / "assets" / "levels" / "maze.tmj").read_text())
GIDS = MAZE["layers"][0]["data"]
GUARD = '<object id="3" type="guard" x="48" y="48"><point/></object>'
POSIX = pytest.mark.skipif(sys.platform == "win32", reason="POSIX special files")


def _csv(gids: list[int]) -> str:
    return ",\n".join(",".join(map(str, gids[i:i + 20])) for i in range(0, len(gids), 20))


def tmx(folder: Path, *, data: str | None = None, objects: str = GUARD, extra: str = "",
        tileset: str = "walls.tsx", infinite: bool = False) -> Path:
    """A TMX maze (what Tiled writes) with an external tileset and the given objects."""
    data = data or f'<data encoding="csv">\n{_csv(GIDS)}\n</data>'
    if tileset == "walls.tsx" and not (folder / tileset).exists():
        tsx(folder)
    path = folder / "map.tmx"
    path.write_text(
        '<?xml version="1.0" encoding="UTF-8"?>\n<map version="1.10" tiledversion="1.10.2" '
        'orientation="orthogonal" renderorder="right-down" width="20" height="20" '
        f'tilewidth="32" tileheight="32" infinite="{int(infinite)}" nextlayerid="4" '
        f'nextobjectid="9">\n <tileset firstgid="1" source="{tileset}"/>\n{extra}'
        f' <layer id="1" name="walls" width="20" height="20">\n  {data}\n </layer>\n'
        f' <objectgroup id="2" name="things">{objects}</objectgroup>\n</map>\n')
    return path


def tmj(folder: Path, objects: list[dict] | None = None, **changes: object) -> Path:
    doc = json.loads(json.dumps(MAZE))
    doc["tilesets"] = [{"firstgid": 1, "source": "walls.tsj"}]
    if not (folder / "walls.tsj").exists():
        tsj(folder)
    if objects is not None:
        doc["layers"][1]["objects"] = objects
    doc.update(changes)
    path = folder / "map.tmj"
    path.write_text(json.dumps(doc))
    return path


def tsx(folder: Path, name: str = "walls.tsx") -> None:
    (folder / name).write_text(
        '<?xml version="1.0"?><tileset name="w" tilewidth="32" tileheight="32" tilecount="1" '
        'columns="1"><image source="walls.png" width="32" height="32"/></tileset>')


def tsj(folder: Path, name: str = "walls.tsj") -> None:
    (folder / name).write_text(json.dumps({
        "columns": 1, "image": "walls.png", "imageheight": 32, "imagewidth": 32, "margin": 0,
        "name": "w", "spacing": 0, "tilecount": 1, "tileheight": 32, "tilewidth": 32,
        "type": "tileset"}))


def tx(folder: Path, tileset: str | None = None, name: str = "guard.tx",
       obj: str = '<object type="guard" name="sentry"><point/></object>') -> None:
    named = f'<tileset firstgid="1" source="{tileset}"/>' if tileset else ""
    (folder / name).write_text(f'<?xml version="1.0"?><template>{named}{obj}</template>')


def tj(folder: Path, tileset: str | None = None, name: str = "guard.tj") -> None:
    doc: dict = {"type": "template", "object": {"type": "guard", "name": "sentry",
                                                "point": True}}
    if tileset:
        doc["tileset"] = {"firstgid": 1, "source": tileset}
    (folder / name).write_text(json.dumps(doc))


def placed(template: str, object_id: int = 4, x: float = 304, y: float = 48) -> str:
    return f'<object id="{object_id}" template="{template}" x="{x}" y="{y}"/>'


def placed_json(template: str, object_id: int = 4, x: float = 304, y: float = 48) -> dict:
    return {"id": object_id, "template": template, "x": x, "y": y}


def refused(path: Path, match: str, capsys: pytest.CaptureFixture[str],
            command: tuple[str, ...] = ("validate",)) -> str:
    """One ``stealth: error:`` line holding ``match``, exit 2, within 30 s."""
    start = time.monotonic()
    assert main([*command, str(path)]) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("stealth: error: "), lines
    assert match in lines[0], lines[0]
    assert time.monotonic() - start < 30
    return lines[0]


# --------------------------------------------------------------------------- one reader


class _Recorder:
    """Stands in for every way Python opens or looks at a file, noting who asked."""

    NAMES = (("builtins", builtins, "open"), ("io", io, "open"), ("os", os, "open"),
             ("os", os, "stat"), ("os", os, "lstat"))

    def __init__(self, monkeypatch: pytest.MonkeyPatch) -> None:
        self.calls: list[tuple[str, str, list[str]]] = []
        for module_name, module, name in self.NAMES:
            monkeypatch.setattr(module, name, self._wrap(f"{module_name}.{name}",
                                                         getattr(module, name)))

    def _wrap(self, label: str, real):  # noqa: ANN001, ANN202 - any signature
        def recorded(target, *args, **kwargs):  # noqa: ANN001, ANN202
            frame: types.FrameType | None = sys._getframe(1)
            stack: list[str] = []
            while frame is not None:
                stack.append(frame.f_code.co_qualname)
                if frame.f_code is navmesh.files.read_regular.__code__:
                    stack.append("<guarded>")
                frame = frame.f_back
            self.calls.append((label, os.fspath(target) if not isinstance(target, int)
                               else str(target), stack))
            return real(target, *args, **kwargs)
        return recorded


def _every_feature(folder: Path, kind: str) -> tuple[Path, set[str]]:
    """A map using external tilesets, templates with tilesets, an image layer and a tile
    object; the files the loader must read."""
    image = (' <imagelayer id="3" name="sky"><image source="sky.png" width="9" height="9"/>'
             '</imagelayer>\n')
    if kind == "tmx":
        tsx(folder)
        tsx(folder, "props.tsx")
        tx(folder, tileset="props.tsx")
        tx(folder, name="crate.tx", obj='<object gid="1" width="32" height="32"/>')
        path = tmx(folder, extra=image, objects=GUARD + placed("guard.tx")
                   + placed("crate.tx", 5, 64, 64))
        named = {"map.tmx", "walls.tsx", "guard.tx", "props.tsx", "crate.tx"}
    else:
        tsj(folder)
        tsj(folder, "props.tsj")
        tj(folder, tileset="props.tsj")
        doc = json.loads(json.dumps(MAZE))
        sky = {"id": 3, "image": "sky.png", "name": "sky", "opacity": 1, "type": "imagelayer",
               "visible": True, "x": 0, "y": 0}
        doc["layers"].append(sky)
        doc["layers"][1]["objects"].append(placed_json("guard.tj"))
        path = tmj(folder, layers=doc["layers"])
        named = {"map.tmj", "walls.tsj", "guard.tj", "props.tsj"}
    return path, {str(folder / name) for name in named}


@pytest.mark.parametrize("kind", ["tmx", "tmj"])
def test_every_file_the_loader_opens_goes_through_the_guarded_reader(tmp_path, monkeypatch,
                                                                     kind):
    path, named = _every_feature(tmp_path, kind)
    import navmesh.tiled  # noqa: F401 - imported before recording: the walk, not the import

    recorder = _Recorder(monkeypatch)
    with warnings.catch_warnings(record=True):
        level = load_level(path)
    monkeypatch.undo()
    assert (9.5, 1.5) in level.guards  # the template's guard
    opened = set()
    for label, target, stack in recorder.calls:
        if "<guarded>" in stack:
            opened.add(os.path.normpath(target))
            continue
        # the one exception: level.py tells a file from a bundled level's name, looking at
        # (never opening) the path the user gave
        assert label in ("os.stat", "os.lstat"), (label, target, stack)
        assert "resolve_level_path" in stack or "_read_level_file" in stack, (target, stack)
        assert str(path).startswith(target), target
    assert opened == named


# --------------------------------------------------------------------------- templates


@POSIX
@pytest.mark.parametrize("kind", ["tmx", "tmj"])
@pytest.mark.parametrize("special", ["fifo", "/dev/zero"])
@pytest.mark.parametrize("command", [("validate",), ("sim", "--guards", "pf", "--player",
                                                     "maxmin")])
def test_a_template_s_tileset_that_is_a_fifo_or_a_device_is_refused(tmp_path, capsys, kind,
                                                                     special, command):
    named = special
    if special == "fifo":
        os.mkfifo(tmp_path / "pipe.tsx")
        named = "pipe.tsx"
    if kind == "tmx":
        tx(tmp_path, tileset=named)
        path = tmx(tmp_path, objects=GUARD + placed("guard.tx"))
    else:
        tj(tmp_path, tileset=named)
        path = tmj(tmp_path, [placed_json("guard.tj", 3, 48, 48)])
    line = refused(path, "object 4 template's tileset: " if kind == "tmx" else
                   "object 3 template's tileset: ", capsys, command)
    assert ("is a FIFO" if special == "fifo" else "/dev/zero is a character device") in line


@POSIX
def test_a_template_that_is_a_fifo_a_directory_or_empty_is_refused(tmp_path, capsys):
    os.mkfifo(tmp_path / "pipe.tx")
    (tmp_path / "dir.tx").mkdir()
    (tmp_path / "empty.tx").write_text("")
    for name, problem in (("pipe.tx", "is a FIFO"), ("dir.tx", "is a directory"),
                          ("empty.tx", "is empty"), ("/dev/stdin", "character device")):
        refused(tmx(tmp_path, objects=GUARD + placed(name)),
                f"layer 'things' object 4 template: ", capsys)
        assert problem in str(_error(tmp_path / "map.tmx"))


def test_templates_are_merged_as_tiled_does(tmp_path):
    """The object's own attributes and properties win; the template's shape is kept."""
    tsx(tmp_path)
    tx(tmp_path, obj='<object type="dark" width="64" height="64"><properties>'
                     '<property name="a" value="1"/><property name="b" value="2"/>'
                     '</properties></object>')
    override = ('<object id="4" template="guard.tx" x="64" y="288" width="96">'
                '<properties><property name="b" value="3"/></properties></object>')
    level = load_level(tmx(tmp_path, objects=GUARD + override))
    (zone,) = level.zones["dark"]
    assert zone.bounds == (2.0, 9.0, 5.0, 11.0)  # width from the object, height from the template
    tj(tmp_path)
    doc_objects = [placed_json("guard.tj", 3, 48, 48),
                   {**placed_json("guard.tj", 5, 304, 48), "type": "decoy"}]
    level = load_level(tmj(tmp_path, doc_objects))
    assert level.guards == ((1.5, 1.5),) and level.decoys == ((9.5, 1.5),)


def test_a_template_of_the_other_format_is_converted(tmp_path, capsys):
    """As in Tiled, a TMX map may place ``.tj`` templates and a JSON map ``.tx`` ones."""
    tj(tmp_path)
    tx(tmp_path, obj='<object type="dark" width="64" height="32" rotation="90"><properties>'
                     '<property name="n" type="int" value="3"/></properties></object>')
    level = load_level(tmx(tmp_path, objects=GUARD + placed("guard.tj")))
    assert level.guards == ((1.5, 1.5), (9.5, 1.5))
    level = load_level(tmj(tmp_path, [placed_json("guard.tj", 3, 48, 48),
                                      placed_json("guard.tx", 5, 96, 288)]))
    (zone,) = level.zones["dark"]
    assert zone.bounds == pytest.approx((2.0, 9.0, 3.0, 11.0))  # turned 90° about (3, 9)
    tx(tmp_path, name="bad.tx", obj='<object type="dark"><polygon points="1,2,3"/></object>')
    refused(tmj(tmp_path, [placed_json("guard.tj", 3, 48, 48), placed_json("bad.tx")]),
            "object 4 template: ", capsys)
    assert "bad.tx cannot be converted to the map's format" in str(_error(tmp_path / "map.tmj"))


def test_the_files_a_map_names_are_bounded_together(tmp_path, capsys, monkeypatch):
    import navmesh.tiled_guard as guard

    tsx(tmp_path)
    for i in range(4):
        tx(tmp_path, name=f"g{i}.tx")
    monkeypatch.setattr(guard, "MAX_NAMED_FILES", 3)
    objects = "".join(placed(f"g{i}.tx", 4 + i) for i in range(4))
    refused(tmx(tmp_path, objects=objects), "the map names more than 3 files", capsys)


# --------------------------------------------------------------------------- content


@pytest.mark.parametrize("attributes,message", [
    ('x="nan" y="48"', "object 3 (guard): position must be finite numbers, got nan"),
    ('x="48" y="48" width="32" height="32" rotation="nan"',
     "size and rotation must be finite numbers, got nan"),
    ('x="1e308" y="48" width="1e308" height="32"',
     "corners (position + size) must be finite numbers, got inf"),
])
def test_non_finite_object_numbers_are_one_line(tmp_path, capsys, attributes, message):
    tsx(tmp_path)
    kind = "guard" if "rotation" not in attributes else "dark"
    objects = f'<object id="3" type="{kind}" {attributes}/>'
    if kind == "dark":
        objects = GUARD.replace('id="3"', 'id="9"') + objects
    refused(tmx(tmp_path, objects=objects), message.replace("(guard)", f"({kind})"), capsys)


def test_a_tmj_object_at_nan_and_a_polygon_point_at_nan(tmp_path, capsys):
    tsj(tmp_path)
    guard = {"id": 3, "type": "guard", "x": float("nan"), "y": 48, "point": True}
    refused(tmj(tmp_path, [guard]), "object 3 (guard): position must be finite numbers",
            capsys)
    tsx(tmp_path)
    polygon = ('<object id="4" type="dark" x="48" y="48">'
               '<polygon points="0,0 nan,0 0,32"/></object>')
    refused(tmx(tmp_path, objects=GUARD + polygon), "points must be finite numbers", capsys)


@pytest.mark.parametrize("key,message", [
    ('"x": 48', "object 3 (guard): position must be finite numbers, got inf"),
    ('"rotation": 0', "object 3 (guard): size and rotation must be finite numbers, got inf"),
    ('"tilewidth": 32', "pixels wide are not supported; tiles are at most 65536 pixels wide"),
    ('"value": 7', "map property cell_size: must be a finite number > 0"),
])
def test_integers_beyond_a_float_are_one_line(tmp_path, capsys, key, message):
    """JSON integers have no limit: 10^400 where a number is read ends in one line."""
    guard = {"id": 3, "type": "guard", "x": 48, "y": 48, "width": 4, "height": 4, "rotation": 0}
    path = tmj(tmp_path, [guard], properties=[{"name": "cell_size", "type": "int", "value": 7}])
    text = path.read_text()
    huge = key.split(": ")[0] + ": 1" + "0" * 400
    if key.startswith('"tilewidth"'):
        text = text.replace('"tileheight": 32', huge.replace("width", "height"))
    assert key in text
    path.write_text(text.replace(key, huge))
    refused(path, message, capsys)


@pytest.mark.parametrize("kind", ["tmx", "tmj"])
@pytest.mark.parametrize("pixels", [10**30, 2**31, 2**16 + 1])
def test_a_tile_too_wide_is_refused_naming_its_size(tmp_path, capsys, kind, pixels):
    """Wider tiles made the maze's objects zero-area specks: the line named a zone, not the
    tile size; 65536-pixel tiles load (objects scaled with them: the same level)."""
    def scaled(tile: int) -> Path:
        if kind == "tmj":
            return tmj(tmp_path, [{"id": 3, "type": "guard", "x": 1.5 * tile, "y": 1.5 * tile,
                                   "point": True}], tilewidth=tile, tileheight=tile)
        path = tmx(tmp_path, objects=f'<object id="3" type="guard" x="{1.5 * tile}" '
                                     f'y="{1.5 * tile}"><point/></object>')
        path.write_text(path.read_text().replace('tilewidth="32" tileheight="32"',
                                                 f'tilewidth="{tile}" tileheight="{tile}"'))
        return path

    refused(scaled(pixels), f"map: tiles {pixels} pixels wide are not supported; tiles are at "
                            "most 65536 pixels wide", capsys)
    wide, usual = load_level(scaled(2**16)), load_level(scaled(32))
    assert (wide.occupancy == usual.occupancy).all() and wide.guards == usual.guards == (
        (1.5, 1.5),)


@pytest.mark.parametrize("name,encoding", [("map.tmx", "utf-16"), ("map.tmj", "utf-16"),
                                           ("map.tmj", "utf-16-be")])
def test_a_map_that_is_not_utf8_is_one_clear_line(tmp_path, capsys, name, encoding):
    """Tiled writes UTF-8: a UTF-16 map (with a byte order mark, or JSON without one) is
    refused as such, not with a UnicodeDecodeError or a JSON syntax error."""
    path = tmx(tmp_path) if name == "map.tmx" else tmj(tmp_path)
    text = path.read_text(encoding="utf-8").replace('encoding="UTF-8"', 'encoding="UTF-16"')
    path.write_bytes(text.encode(encoding))
    refused(path, f"{name}: map: not UTF-8 text (invalid byte at offset 0); Tiled writes maps "
                  "in UTF-8", capsys)


@pytest.mark.parametrize("width", ["abc", "1.5", 1.5, True, "²"])
def test_a_map_size_that_is_not_a_whole_number_is_one_line(tmp_path, capsys, width):
    refused(tmj(tmp_path, width=width), f"map: width must be a whole number, got {width!r}",
            capsys)


def test_a_chunk_or_an_offset_far_out_is_one_line(tmp_path, capsys):
    tsx(tmp_path)
    far = ('<data encoding="csv"><chunk x="1000000000000000000000000000000" y="0" width="2" '
           'height="2">1,0,0,1</chunk></data>')
    refused(tmx(tmp_path, data=far, infinite=True), "layer 'walls': chunk position must be "
            "whole numbers within ±2147483648", capsys)
    tsj(tmp_path)
    doc = json.loads(json.dumps(MAZE))
    doc["layers"][1].update(offsetx=float("nan"), offsety=0)
    refused(tmj(tmp_path, layers=doc["layers"]), "layer 'objects': offset must be finite",
            capsys)


def test_the_old_tile_gid_layer_format_is_read(tmp_path):
    """``<data>`` holding one ``<tile gid="…"/>`` per tile (no encoding): the same level."""
    tsx(tmp_path)
    data = "<data>" + "".join(f'<tile gid="{g}"/>' if g else "<tile/>" for g in GIDS) + "</data>"
    old = load_level(tmx(tmp_path, data=data))
    csv = load_level(tmx(tmp_path))
    assert (old.occupancy == csv.occupancy).all()


@pytest.mark.parametrize("kind,gids,message", [
    ("tmx", GIDS[:380], "layer 'walls': tile data holds 380 gids, expected 400 (one per tile "
                        "of 20x20)"),
    ("tmx", GIDS + [0] * 20, "tile data holds 420 gids, expected 400"),
    ("tmx", [-1] + GIDS[1:], "the gid of the tile at row 0, column 0 is -1, not a whole number "
                             "in [0, 2^32)"),
    ("tmj", GIDS[:50], "layer 'walls': tile data holds 50 gids, expected 400"),
    ("tmj", GIDS[:21] + [2**32] + GIDS[22:], "the gid of the tile at row 1, column 1 is "
                                             "4294967296"),
    ("tmj", GIDS[:21] + [1.5] + GIDS[22:], "row 1, column 1 is 1.5"),
])
def test_layer_data_of_the_wrong_length_or_values_is_refused(tmp_path, capsys, kind, gids,
                                                             message):
    if kind == "tmx":
        tsx(tmp_path)
        path = tmx(tmp_path, data=f'<data encoding="csv">{_csv(gids)}</data>')
    else:
        tsj(tmp_path)
        doc = json.loads(json.dumps(MAZE))
        doc["layers"][0]["data"] = gids
        path = tmj(tmp_path, layers=doc["layers"])
    refused(path, message, capsys)


def test_a_layer_or_chunk_of_no_tiles_is_read_as_empty(tmp_path):
    """The maze's 206 walkable cells, whatever empty layers and chunks lie beside it."""
    empty = '<layer id="7" name="empty" width="0" height="0"><data encoding="csv"></data></layer>'
    assert load_level(tmx(tmp_path, extra=empty)).occupancy.sum() == 206
    chunks = ('<data encoding="csv"><chunk x="0" y="0" width="0" height="3"></chunk>'
              f'<chunk x="0" y="0" width="20" height="20">{_csv(GIDS)}</chunk></data>')
    assert load_level(tmx(tmp_path, data=chunks, infinite=True)).occupancy.sum() == 206


def test_a_tile_of_100000_collision_shapes_is_refused_quickly(tmp_path):
    """100,000 collision shapes on one tileset tile are one line, counted before the tileset
    is parsed (issue 41: the loader hung for minutes on it)."""
    shapes = "".join(f'<object id="{i}" x="0" y="0" width="1" height="1"/>'
                     for i in range(1, 100_001))
    (tmp_path / "walls.tsx").write_text(
        '<?xml version="1.0"?><tileset name="w" tilewidth="32" tileheight="32" tilecount="1" '
        f'columns="1"><tile id="0"><objectgroup>{shapes}</objectgroup></tile></tileset>')
    start = time.monotonic()
    with pytest.raises(LevelError, match=r"tilesets\[0\] 'walls.tsx' tile 0: 100000 collision "
                                         r"shapes on one tile, more than the limit of 256"):
        load_level(tmx(tmp_path))
    assert time.monotonic() - start < 5


@pytest.mark.parametrize("data,message", [
    ('<data encoding="hex">1</data>', "unknown encoding 'hex'"),
    ('<data encoding="csv" compression="zlib">1</data>', "compression 'zlib' needs base64"),
    ('<data encoding="base64" compression="lzma">AAAA</data>', "unknown compression 'lzma'"),
])
def test_odd_encodings_are_one_line(tmp_path, capsys, data, message):
    tsx(tmp_path)
    refused(tmx(tmp_path, data=data), f"layer 'walls': ", capsys)
    assert message in str(_error(tmp_path / "map.tmx"))


def test_odd_paths_and_nesting_are_one_line(tmp_path, capsys):
    os.symlink("b.tsx", tmp_path / "a.tsx")
    os.symlink("a.tsx", tmp_path / "b.tsx")
    refused(tmx(tmp_path, tileset="a.tsx"), "tilesets[0].source: cannot read", capsys)
    refused(tmj(tmp_path, tilesets=[{"firstgid": 1, "source": "a\0b.tsj"}]),
            "tilesets[0].source: cannot read", capsys)
    tsx(tmp_path)
    groups = "<group>" * 5000 + "</group>" * 5000
    refused(tmx(tmp_path, extra=groups), "map: not a Tiled map Stealthfield can read: nested "
                                         "too deeply", capsys)


def test_a_template_that_names_itself_is_read_once(tmp_path):
    tsx(tmp_path)
    tx(tmp_path, tileset="guard.tx",
       obj='<object template="guard.tx" type="guard"><point/></object>')
    level = load_level(tmx(tmp_path, objects=GUARD + placed("guard.tx")))
    assert len(level.guards) == 2


def _error(path: Path) -> LevelError:
    with pytest.raises(LevelError) as info:
        navmesh.level.load_level(path)
    return info.value
