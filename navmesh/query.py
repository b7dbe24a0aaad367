"""Path queries on a :class:`~navmesh.mesh.NavMesh`: exact corridor + funnel, A* fallback.

The Detour ``dtNavMeshQuery`` side of the package: a :class:`PathQuery` is bound to one
mesh and owns everything a search needs — Python-level portal tables, the pinch points,
the lazily built corner-visibility tables (:class:`navmesh.sight.MeshSight`) and the
triangle fans used to re-route a corridor.  It is made from a built mesh, which knows
nothing of it (Detour's ``dtNavMeshQuery`` beside ``dtNavMesh``): :func:`path_query` gives
the one query of a mesh, and :func:`find_path` / :func:`corridor` ask it.

>>> from shapely import box
>>> from navmesh.mesh import NavMesh
>>> mesh = NavMesh.build(box(0, 0, 10, 10).difference(box(4, 0, 6, 8)))
>>> path = find_path(mesh, (1, 1), (9, 1))
>>> path.points.tolist(), round(path.length, 6)
([[1.0, 1.0], [4.0, 8.0], [6.0, 8.0], [9.0, 1.0]], 17.231546)
>>> path_query(mesh) is path_query(mesh)
True
"""

from __future__ import annotations

import heapq
import itertools
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from navmesh.errors import OutsideError
from navmesh.funnel import funnel
from navmesh.sight import MeshSight

if TYPE_CHECKING:
    from navmesh.mesh import NavMesh

__all__ = ["MAX_CORNERS", "NavPath", "OutsideError", "PathQuery", "corridor", "find_path", "path_query"]

#: Above this many wall corners the exact-path tables are not built (A* + funnel instead).
MAX_CORNERS = 1000


@dataclass
class NavPath:
    """A path: ``points`` (k, 2) from start to goal, both included; ``length`` of the polyline."""

    points: np.ndarray
    length: float


class PathQuery:
    """Shortest paths and corridors on one mesh, with the tables and caches the search uses.

    Built from a finished mesh (:func:`path_query` keeps one per mesh); the
    corner-visibility tables are built on the first exact query.
    """

    def __init__(self, mesh: NavMesh) -> None:
        # Python-level tables for the per-query search (lists beat numpy for scalar access)
        self.mesh = mesh
        self._tol = mesh.tol
        v, t, nb = mesh.vertices, mesh.triangles, mesh.neighbors
        self._nb = [tuple(r) for r in nb.tolist()]
        xs, ys = v[:, 0].tolist(), v[:, 1].tolist()
        tl = t.tolist()
        self._tri_list = tl
        # portal across edge k, seen leaving the triangle: right = v[k+1], left = v[k+2]
        self._portal = [
            tuple((xs[tr[(k + 1) % 3]], ys[tr[(k + 1) % 3]], xs[tr[(k + 2) % 3]], ys[tr[(k + 2) % 3]]) for k in range(3))
            for tr in tl
        ]
        self._portal_ids = [tuple((tr[(k + 1) % 3], tr[(k + 2) % 3]) for k in range(3)) for tr in tl]
        self._fans: dict[int, list[int]] | None = None
        self._pinch = self._pinch_points()
        self._sight: MeshSight | None = None
        self._sight_tried = False  # tables are built on the first exact query

    def _pinch_points(self) -> dict[int, list[int]]:
        """Vertices where walls touch (several walkable sectors): one triangle per sector."""
        tl, nb = self._tri_list, self._nb
        parent = list(range(3 * len(tl)))

        def find(i: int) -> int:
            while parent[i] != i:
                parent[i] = parent[parent[i]]
                i = parent[i]
            return i

        for t, tri in enumerate(tl):
            for k in range(3):
                u = nb[t][(k + 1) % 3]  # across edge (v[k+2], v[k]): also holds vertex v[k]
                if u >= 0:
                    a, b = find(3 * t + k), find(3 * u + tl[u].index(tri[k]))
                    if a != b:
                        parent[a] = b
        sectors: dict[int, dict[int, int]] = {}
        for t, tri in enumerate(tl):
            for k in range(3):
                sectors.setdefault(tri[k], {}).setdefault(find(3 * t + k), t)
        return {v: list(reps.values()) for v, reps in sectors.items() if len(reps) > 1}

    def _sectors_at(self, t: int, x: float, y: float) -> list[int]:
        """[t], or one triangle per sector if (x, y) is a pinch vertex of t."""
        if self._pinch:
            v = self.mesh.vertices
            for w in self._tri_list[t]:
                if w in self._pinch and abs(v[w, 0] - x) <= self._tol and abs(v[w, 1] - y) <= self._tol:
                    return self._pinch[w]
        return [t]

    def _sight_tables(self) -> MeshSight | None:
        """The exact-path tables, built on first use (None when the level has too many corners)."""
        if not self._sight_tried:
            self._sight_tried = True
            try:
                m = self.mesh
                self._sight = MeshSight(m.vertices, m.triangles, m.neighbors, self._tol, max_nodes=MAX_CORNERS)
            except OverflowError:
                self._sight = None
        return self._sight

    # ---------------------------------------------------------------- queries
    def _ends(
        self, start: tuple[float, float], goal: tuple[float, float]
    ) -> tuple[float, float, float, float, list[int], list[int]]:
        """Coordinates and the triangles holding start and goal (one per sector at a pinch)."""
        sx, sy = float(start[0]), float(start[1])
        gx, gy = float(goal[0]), float(goal[1])
        ts = self.mesh.locate(sx, sy)
        if ts < 0:
            raise OutsideError(f"point ({sx}, {sy}) is outside the walkable area")
        tg = self.mesh.locate(gx, gy)
        if tg < 0:
            raise OutsideError(f"point ({gx}, {gy}) is outside the walkable area")
        return sx, sy, gx, gy, self._sectors_at(ts, sx, sy), self._sectors_at(tg, gx, gy)

    def find_path(self, start: tuple[float, float], goal: tuple[float, float], *, exact: bool = True) -> NavPath:
        """Shortest walkable path from ``start`` to ``goal``, both included.

        ``exact=True`` (default): the corridor is the one the true Euclidean shortest path
        runs through, chosen with the precomputed corner-visibility tables (see
        ``docs/navmesh.md``); the path is the funnel path of that corridor.  ``exact=False``
        (also the fallback on levels with more than ``MAX_CORNERS`` wall corners): A* over
        the triangles with costs through the portal entry points, then the funnel.
        Raises :class:`OutsideError` if either point lies outside the walkable area.
        """
        sx, sy, gx, gy, ts, tg = self._ends(start, goal)
        if ts[0] == tg[0]:
            return _navpath([(sx, sy), (gx, gy)])
        sight = self._sight_tables() if exact else None
        if sight is not None:
            return _navpath(self._exact_points(sight, ts, sx, sy, tg, gx, gy))
        return _navpath(self._astar_path(ts, sx, sy, tg, gx, gy)[0])

    def corridor(self, start: tuple[float, float], goal: tuple[float, float], *, exact: bool = True) -> list[int]:
        """Triangles, from start's to goal's, of the corridor :meth:`find_path` pulls its path through.

        Pulling the funnel (:func:`navmesh.funnel.funnel`) through the portals of this
        corridor gives the :meth:`find_path` path.
        """
        sx, sy, gx, gy, ts, tg = self._ends(start, goal)
        if ts[0] == tg[0]:
            return [ts[0]]
        sight = self._sight_tables() if exact else None
        if sight is not None:
            pts = self._exact_points(sight, ts, sx, sy, tg, gx, gy)
            return sight.corridor_of(ts, pts)
        return self._astar_path(ts, sx, sy, tg, gx, gy)[1]

    def _astar_path(
        self, ts: list[int], sx: float, sy: float, tg: list[int], gx: float, gy: float
    ) -> tuple[list[tuple[float, float]], list[int]]:
        """A* corridor + funnel, searched from both ends when the path bends; the shorter wins.

        Each direction's entry-point costs are biased differently, so the two searches
        rarely pick the same wrong side of an obstacle.
        """
        corridor = self._astar(ts, tg, sx, sy, gx, gy)
        if corridor is None:
            raise ValueError(f"no path from ({sx}, {sy}) to ({gx}, {gy})")
        pts, corridor = self._pull(corridor, sx, sy, gx, gy)
        if len(pts) > 2:
            back = self._astar(tg, ts, gx, gy, sx, sy)
            if back is not None and back[::-1] != corridor:
                pts2, corridor2 = self._pull(back[::-1], sx, sy, gx, gy)
                if _polyline_length(pts2) < _polyline_length(pts):
                    pts, corridor = pts2, corridor2
        return pts, corridor

    def _exact_points(
        self, sight: MeshSight, ts: list[int], sx: float, sy: float, tg: list[int], gx: float, gy: float
    ) -> list[tuple[float, float]]:
        if any(sight.walk(t, sx, sy, gx, gy) >= 0 for t in ts):
            return [(sx, sy), (gx, gy)]
        chain, length = sight.corner_path(ts, sx, sy, tg, gx, gy)
        if not math.isfinite(length):
            raise ValueError(f"no path from ({sx}, {sy}) to ({gx}, {gy})")
        xs, ys = sight.nodes_x, sight.nodes_y
        return _drop_straight_points([(sx, sy)] + [(xs[c], ys[c]) for c in chain] + [(gx, gy)], self._tol)

    def _astar(self, ts: list[int], tg: list[int], sx: float, sy: float, gx: float, gy: float) -> list[int] | None:
        """A* over triangles; the cost runs through the actual entry point on each portal.

        Entering a triangle across portal (a, b) from point p, the entry point is the point
        of the portal minimising |p q| + |q goal| (where the straight line to the goal
        crosses the portal, else towards the goal's mirror image, clamped to the portal),
        so g is the length of a real polyline through the corridor.
        """
        nb, portal = self._nb, self._portal
        n = len(nb)
        hyp = math.hypot
        best = [math.inf] * n
        parent = [-1] * n
        closed = bytearray(n)
        h0 = hyp(gx - sx, gy - sy)
        heap = [(h0, t, sx, sy, 0.0) for t in ts]
        for t in ts:
            best[t] = 0.0
        goals = set(tg)
        pop, push = heapq.heappop, heapq.heappush
        while heap:
            _f, t, px, py, g = pop(heap)
            if closed[t]:
                continue
            if t in goals:
                out = [t]
                while parent[t] >= 0:
                    t = parent[t]
                    out.append(t)
                out.reverse()
                return out
            closed[t] = 1
            nbt, pt = nb[t], portal[t]
            for k in (0, 1, 2):
                u = nbt[k]
                if u < 0 or closed[u]:
                    continue
                ax, ay, bx, by = pt[k]
                ex, ey = bx - ax, by - ay
                ee = ex * ex + ey * ey
                cp = ex * (py - ay) - ey * (px - ax)
                cg = ex * (gy - ay) - ey * (gx - ax)
                if cp * cg > 0.0:  # goal on the near side: aim at its mirror image
                    f = 2.0 * cg / ee
                    hx, hy = gx + f * ey, gy - f * ex
                else:
                    hx, hy = gx, gy
                wx, wy = hx - px, hy - py
                den = wx * ey - wy * ex
                if den != 0.0 and cp != 0.0:
                    lam = (wx * (py - ay) - wy * (px - ax)) / den
                else:
                    lam = ((px - ax) * ex + (py - ay) * ey) / ee
                lam = 0.0 if lam < 0.0 else (min(lam, 1.0))
                qx, qy = ax + lam * ex, ay + lam * ey
                ng = g + hyp(qx - px, qy - py)
                if ng < best[u]:
                    best[u] = ng
                    parent[u] = t
                    push(heap, (ng + hyp(gx - qx, gy - qy), u, qx, qy, ng))
        return None

    def _portals(self, corridor: list[int]) -> tuple[list, list, list, list]:
        nb, portal, pid = self._nb, self._portal, self._portal_ids
        rights, lefts, rid, lid = [], [], [], []
        for t, u in itertools.pairwise(corridor):
            k = nb[t].index(u)
            ax, ay, bx, by = portal[t][k]
            rights.append((ax, ay))
            lefts.append((bx, by))
            r, lft = pid[t][k]
            rid.append(r)
            lid.append(lft)
        return rights, lefts, rid, lid

    def _pull(
        self, corridor: list[int], sx: float, sy: float, gx: float, gy: float
    ) -> tuple[list[tuple[float, float]], list[int]]:
        """Funnel through the corridor; re-route around interior (Steiner) corners.

        A taut path only bends at wall corners.  If the funnel bends at an interior vertex,
        the corridor passes it on the wrong side: swap that stretch for the other half of
        the vertex's triangle fan (same homotopy, strictly shorter) and pull again.
        """
        bv = self.mesh.boundary_vertex
        for _ in range(64):
            rights, lefts, rid, lid = self._portals(corridor)
            pts, corners = funnel((sx, sy), (gx, gy), rights, lefts, rid, lid)
            inner = next(((w, i) for w, i in corners if w >= 0 and not bv[w]), None)
            if inner is None:
                break
            corridor = self._reroute(corridor, inner[0], inner[1], rid, lid)
        return pts, corridor

    def _fan(self, w: int) -> list[int]:
        """Triangles around interior vertex w, in counter-clockwise order."""
        if self._fans is None:
            fans: dict[int, list[int]] = {}
            for t, tri in enumerate(self._tri_list):
                for v in tri:
                    fans.setdefault(v, []).append(t)
            self._fans = fans
        around = self._fans[w]
        order = [around[0]]
        while len(order) < len(around):
            t = order[-1]
            k = self._tri_list[t].index(w)
            nxt = self._nb[t][(k + 1) % 3]  # across edge (v[k+2], w): next counter-clockwise
            if nxt < 0 or nxt == order[0]:
                break
            order.append(nxt)
        return order

    def _reroute(self, corridor: list[int], w: int, portal_i: int, rid: list[int], lid: list[int]) -> list[int]:
        """Replace the corridor stretch around interior vertex w by the other side of w's fan."""
        side = rid if rid[portal_i] == w else lid
        i = j = portal_i
        while i > 0 and side[i - 1] == w:
            i -= 1
        while j + 1 < len(side) and side[j + 1] == w:
            j += 1
        first, last = corridor[i], corridor[j + 1]  # portal p joins corridor[p] and corridor[p+1]
        fan = self._fan(w)
        n = len(fan)
        a = fan.index(first)
        step = 1 if fan[(a + 1) % n] == corridor[i + 1] else -1
        arc = [fan[a]]
        pos = a
        while fan[pos] != last:
            pos = (pos - step) % n
            arc.append(fan[pos])
        return _drop_loops(corridor[:i] + arc + corridor[j + 2 :])


def path_query(mesh: NavMesh) -> PathQuery:
    """The path query of ``mesh``: built on first use and kept with the mesh (in
    ``mesh.derived``), so its tables and caches serve every later query."""
    query = mesh.derived.get(PathQuery)
    if not isinstance(query, PathQuery):
        query = mesh.derived[PathQuery] = PathQuery(mesh)
    return query


def find_path(mesh: NavMesh, start: tuple[float, float], goal: tuple[float, float], *,
              exact: bool = True) -> NavPath:
    """Shortest walkable path on ``mesh`` from ``start`` to ``goal``, both included
    (:meth:`PathQuery.find_path`); :class:`OutsideError` if either point is outside."""
    return path_query(mesh).find_path(start, goal, exact=exact)


def corridor(mesh: NavMesh, start: tuple[float, float], goal: tuple[float, float], *,
             exact: bool = True) -> list[int]:
    """Triangles of the corridor :func:`find_path` pulls its path through
    (:meth:`PathQuery.corridor`)."""
    return path_query(mesh).corridor(start, goal, exact=exact)


def _polyline_length(points: list[tuple[float, float]]) -> float:
    length = 0.0
    for (ax, ay), (bx, by) in itertools.pairwise(points):
        length += math.hypot(bx - ax, by - ay)
    return length


def _navpath(points: list[tuple[float, float]]) -> NavPath:
    return NavPath(np.array(points, dtype=np.float64), _polyline_length(points))


def _drop_straight_points(points: list[tuple[float, float]], tol: float) -> list[tuple[float, float]]:
    """Remove repeated points and inner points where the path goes straight on."""
    out = [points[0]]
    for i in range(1, len(points) - 1):
        (ax, ay), (bx, by), (cx, cy) = out[-1], points[i], points[i + 1]
        ux, uy, vx, vy = bx - ax, by - ay, cx - bx, cy - by
        lu, lv = math.hypot(ux, uy), math.hypot(vx, vy)
        if lu <= tol or lv <= tol:
            continue
        if abs(ux * vy - uy * vx) <= tol * max(lu, lv) and ux * vx + uy * vy > 0.0:
            continue
        out.append(points[i])
    out.append(points[-1])
    return out


def _drop_loops(corridor: list[int]) -> list[int]:
    """Cut out the loop between two visits of the same triangle."""
    seen: dict[int, int] = {}
    out: list[int] = []
    for t in corridor:
        if t in seen:
            del out[seen[t] + 1 :]
            seen = {u: k for k, u in enumerate(out)}
        else:
            seen[t] = len(out)
            out.append(t)
    return out
