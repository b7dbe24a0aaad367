"""Digests of the navmeshes trials build, to prove a faster mesh build changes no triangle.

For every bundled level and a few generated buildings (navmesh/buildings.py) it builds the
two meshes a trial uses — the partition mesh of the walkable area (``NavMesh.build``) and
the body's path mesh (``Clearance.path_mesh`` at the default agent radius) — and prints one
JSON object: per mesh the vertex, triangle and edge-neighbour counts and the SHA-256 of the
three arrays' bytes (same triangles in the same order, same vertex coordinates to the bit).
``tests/test_mesh_identity.py`` checks the small cases against ``tests/mesh_digests.json``;
this script also covers the large buildings the test suite cannot afford.

Run: ``python benchmarks/mesh_digest.py [--large] > /tmp/digests.json`` on two checkouts,
then ``diff`` the outputs (or ``--check FILE`` to compare with a saved run).
"""

from __future__ import annotations

import argparse
import hashlib
import json
import sys
import time
from typing import Any

import _paths  # noqa: F401  (project importable, this folder unshadowed)

#: (rows, cols, seed, form) of the generated buildings always digested
SMALL = [(40, 60, 1, "grid"), (40, 60, 1, "polygon"), (100, 100, 0, "grid"), (100, 100, 0, "polygon")]
#: and with ``--large``
LARGE = [(316, 316, 0, "grid"), (316, 316, 0, "polygon"), (1000, 1000, 0, "grid"), (1000, 1000, 0, "polygon")]


def mesh_digest(mesh: Any) -> dict[str, Any]:
    """Counts and SHA-256 of a mesh's vertices, triangles and neighbours (bit-exact identity)."""
    h = hashlib.sha256()
    for array in (mesh.vertices, mesh.triangles, mesh.neighbors):
        h.update(array.tobytes())
    return {"vertices": len(mesh.vertices), "triangles": len(mesh.triangles), "sha256": h.hexdigest()}


#: the other ``NavMesh.build`` options, digested on the bundled levels
VARIANTS: dict[str, dict[str, Any]] = {
    "cdt": {"method": "cdt"},
    "earcut": {"method": "earcut"},
    "earcut-refined": {"method": "earcut", "min_angle": 20.0},
    "refined-30deg": {"min_angle": 30.0},
    "max-area-2": {"max_area": 2.0},
}


def level_digests(level: Any, variants: bool = False) -> dict[str, Any]:
    """The partition mesh and the default body's path mesh of one level (and the variants)."""
    from navmesh.clearance import DEFAULT_AGENT_RADIUS, Clearance
    from navmesh.mesh import NavMesh

    out = {"partition": mesh_digest(NavMesh.build(level.walkable))}
    path_mesh = Clearance(level, DEFAULT_AGENT_RADIUS).path_mesh
    out["path"] = mesh_digest(path_mesh) if path_mesh is not None else None
    if variants:
        for name, options in VARIANTS.items():
            out[name] = mesh_digest(NavMesh.build(level.walkable, **options))
    return out


def cases(large: bool) -> list[tuple[str, Any, bool]]:
    """(name, level, with variants) of every bundled level and the generated buildings."""
    from navmesh.buildings import building_level
    from navmesh.level import bundled_level_names, load_level, parse_level

    out = [(name, load_level(name), True) for name in bundled_level_names()]
    for rows, cols, seed, form in SMALL + (LARGE if large else []):
        name = f"building-{rows}x{cols}-{seed}-{form}"
        out.append((name, parse_level(building_level(rows, cols, seed, form=form), name), rows <= 40))
    return out


def digests(large: bool = False, verbose: bool = False) -> dict[str, Any]:
    """Every case's digests, keyed by case name."""
    result = {}
    for name, level, variants in cases(large):
        t = time.process_time()
        result[name] = level_digests(level, variants)
        if verbose:
            print(f"{name}: {time.process_time() - t:.2f} s CPU", file=sys.stderr, flush=True)
    return result


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--large", action="store_true", help="also the 316² and 1000² buildings")
    parser.add_argument("--check", metavar="FILE", help="compare with a saved run; exit 1 on a difference")
    args = parser.parse_args()
    found = digests(args.large, verbose=True)
    if args.check:
        with open(args.check, encoding="utf-8") as fh:
            saved = json.load(fh)
        # a saved run may predate some digests: compare the meshes both runs have
        bad = [k for k in found if k in saved and any(saved[k][m] != found[k][m] for m in saved[k] if m in found[k])]
        missing = [k for k in found if k not in saved]
        for k in bad:
            print(f"DIFFERENT {k}: {saved[k]} != {found[k]}")
        print(f"{len(found) - len(bad) - len(missing)} identical, {len(bad)} different, {len(missing)} not in {args.check}")
        return 1 if bad else 0
    json.dump(found, sys.stdout, indent=1, sort_keys=True)
    sys.stdout.write("\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
