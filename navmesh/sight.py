"""Corner-visibility tables on a triangle mesh: the exact-path engine of the path query.

A Euclidean shortest path in a polygon with holes bends only at reflex wall corners.
:class:`MeshSight` precomputes, per triangle, which corners see into it (by triangular
expansion from every corner) and all-pairs corner distances, so
:class:`navmesh.query.PathQuery` answers an exact query with a few cross products and one
small matrix.  Visibility is *closed*: a segment may touch and run along walls, but may not
enter an obstacle, nor slip through a pinch point where two obstacles touch corner to corner.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["MeshSight"]


class MeshSight:
    """Exact shortest paths on a triangle mesh, from tables precomputed per triangle.

    * The *corners* a shortest path can bend at are reflex wall vertices.  A vertex
      where several walls meet (a pinch) has one corner per walkable sector ("group":
      the triangles around the vertex connected through non-wall edges).
    * A triangular expansion from every corner records, for every triangle it reaches,
      the angular window (right ray, left ray) through which the corner sees into it;
      a triangle seen in full is stored as "fully visible".  So "which corners does a
      point see" is a few cross products on the tables of the point's triangle.
    * The same expansions give the corner visibility graph, and all-pairs corner
      distances with next hops (scipy's Dijkstra).
    * A query: straight line if s sees g (the segment is walked through the mesh),
      else ``min |s a| + D[a, b] + |b g|`` over the corners a seen from s, b seen from g.

    Built from mesh arrays (``vertices``, counter-clockwise ``triangles``, ``neighbors``);
    raises ``OverflowError`` when there are more than ``max_nodes`` corners.
    """

    def __init__(
        self, vertices: np.ndarray, triangles: np.ndarray, neighbors: np.ndarray, tol: float, *, max_nodes: int = 1500
    ) -> None:
        self.tol = tol
        self._xs: list[float] = vertices[:, 0].tolist()
        self._ys: list[float] = vertices[:, 1].tolist()
        self._tri: list[list[int]] = triangles.tolist()
        self._nb: list[list[int]] = neighbors.tolist()
        self._build_groups()
        if len(self.node_vertex) > max_nodes:
            raise OverflowError(f"{len(self.node_vertex)} corners (more than {max_nodes})")
        self._expand_all()
        self._all_pairs()

    # ------------------------------------------------------------------ groups
    def _build_groups(self) -> None:
        """Group the (triangle, corner slot) pairs around each vertex into walkable sectors."""
        tri, nb = self._tri, self._nb
        n = len(tri)
        parent = list(range(3 * n))

        def find(i: int) -> int:
            while parent[i] != i:
                parent[i] = parent[parent[i]]
                i = parent[i]
            return i

        for t in range(n):
            for k in range(3):
                u = nb[t][(k + 1) % 3]  # across edge (v[k+2], v[k]): also holds vertex v[k]
                if u >= 0:
                    ra, rb = find(3 * t + k), find(3 * u + tri[u].index(tri[t][k]))
                    if ra != rb:
                        parent[ra] = rb
        gid: dict[int, int] = {}
        group = [gid.setdefault(find(i), len(gid)) for i in range(3 * n)]
        ng = len(gid)
        angle = [0.0] * ng
        walled = [False] * ng  # a group without a wall edge is the full fan of an inner vertex
        members: list[list[int]] = [[] for _ in range(ng)]
        vertex = [0] * ng
        xs, ys = self._xs, self._ys
        for t in range(n):
            for k in range(3):
                w, a, b = tri[t][k], tri[t][(k + 1) % 3], tri[t][(k + 2) % 3]
                g = group[3 * t + k]
                angle[g] += _angle_at(xs[w], ys[w], xs[a], ys[a], xs[b], ys[b])
                members[g].append(t)
                vertex[g] = w
                if nb[t][(k + 1) % 3] < 0 or nb[t][(k + 2) % 3] < 0:
                    walled[g] = True
        self._slot_group = group  # 3 t + k -> group of vertex v[k] of t
        self._group_members = members
        node_of_group = [-1] * ng
        node_group: list[int] = []
        for g in range(ng):
            if walled[g] and angle[g] > math.pi + 1e-9:
                node_of_group[g] = len(node_group)
                node_group.append(g)
        self._node_of_group = node_of_group
        self._node_group = node_group
        self.node_vertex = np.asarray([vertex[g] for g in node_group], dtype=np.int64)
        self.nodes_x = [xs[vertex[g]] for g in node_group]
        self.nodes_y = [ys[vertex[g]] for g in node_group]
        self.nodes = np.column_stack([self.nodes_x, self.nodes_y]) if node_group else np.zeros((0, 2))

    # --------------------------------------------------------------- expansion
    def _expand_all(self) -> None:
        """Triangular expansion from every corner: visibility windows and corner edges."""
        n_tri = len(self._tri)
        fv: list[list[int]] = [[] for _ in range(n_tri)]
        pv: list[list[tuple]] = [[] for _ in range(n_tri)]
        edges: dict[tuple[int, int], float] = {}
        tri, nb, xs, ys = self._tri, self._nb, self._xs, self._ys
        slot_group, node_of_group = self._slot_group, self._node_of_group
        hyp, eps = math.hypot, 1e-12

        def node_at(t: int, w: int) -> int:
            return node_of_group[slot_group[3 * t + tri[t].index(w)]]

        for node, g in enumerate(self._node_group):
            v = int(self.node_vertex[node])
            vx, vy = xs[v], ys[v]
            stack = []
            for f in self._group_members[g]:
                k = tri[f].index(v)
                a, b = tri[f][(k + 1) % 3], tri[f][(k + 2) % 3]
                fv[f].append(node)
                for w in (a, b):
                    other = node_at(f, w)
                    if other >= 0:
                        edges[(node, other)] = hyp(xs[w] - vx, ys[w] - vy)
                u = nb[f][k]
                if u >= 0:
                    ax, ay, bx, by = xs[a] - vx, ys[a] - vy, xs[b] - vx, ys[b] - vy
                    la, lb = hyp(ax, ay), hyp(bx, by)
                    stack.append((u, a, b, ax / la, ay / la, bx / lb, by / lb, True))
            while stack:
                u, p, q, rx, ry, lx, ly, full = stack.pop()
                tu = tri[u]
                ip, iq = tu.index(p), tu.index(q)
                w = tu[3 - ip - iq]
                wx, wy = xs[w] - vx, ys[w] - vy
                lw = hyp(wx, wy)
                wx, wy = wx / lw, wy / lw
                w_in = rx * wy - ry * wx >= -eps and wx * ly - wy * lx >= -eps
                if full and w_in:
                    fv[u].append(node)
                else:
                    pv[u].append((node, vx, vy, rx, ry, lx, ly))
                if w_in:
                    other = node_at(u, w)
                    if other >= 0:
                        edges[(node, other)] = lw
                # through edge (p, w), opposite q: the left ray may swing in to w
                l1x, l1y = (wx, wy) if wx * ly - wy * lx > 0 else (lx, ly)
                if rx * l1y - ry * l1x > eps and nb[u][iq] >= 0:
                    stack.append((nb[u][iq], p, w, rx, ry, l1x, l1y, full and w_in))
                # through edge (w, q), opposite p: the right ray may swing in to w
                r2x, r2y = (wx, wy) if rx * wy - ry * wx > 0 else (rx, ry)
                if r2x * ly - r2y * lx > eps and nb[u][ip] >= 0:
                    stack.append((nb[u][ip], w, q, r2x, r2y, lx, ly, full and w_in))
        self._fv = [np.unique(np.asarray(f, dtype=np.int64)) for f in fv]
        self._pv: list[tuple[np.ndarray, ...] | None] = []
        for entries in pv:
            if entries:
                arr = np.asarray(entries, dtype=np.float64)
                self._pv.append((arr[:, 0].astype(np.int64), arr[:, 1], arr[:, 2], arr[:, 3], arr[:, 4], arr[:, 5], arr[:, 6]))
            else:
                self._pv.append(None)
        self._edges = {key: d for key, d in edges.items() if key[0] != key[1]}

    def _all_pairs(self) -> None:
        """Corner-to-corner geodesic distances and next hops."""
        n = len(self.node_vertex)
        w = np.full((n, n), np.inf)
        for (a, b), d in self._edges.items():
            w[a, b] = w[b, a] = min(w[a, b], d)
        from scipy.sparse import csr_matrix  # a project dependency; imported on first use
        from scipy.sparse.csgraph import shortest_path

        if n > 0:
            finite = np.isfinite(w)
            graph = csr_matrix((w[finite], np.nonzero(finite)), shape=(n, n))
            dist, pred = shortest_path(graph, method="D", directed=False, return_predecessors=True)
            # next hop from a towards b = predecessor of a on the tree rooted at b
            nxt = pred.T.copy()
            np.fill_diagonal(nxt, np.arange(n))
        else:
            dist, nxt = w.copy(), np.zeros((0, 0), dtype=np.int64)
        self.dist = np.ascontiguousarray(dist)
        self._next = nxt

    # ----------------------------------------------------------------- queries
    def visible_nodes(self, t: int, px: float, py: float) -> tuple[np.ndarray, np.ndarray]:
        """Corner nodes seen from point p in triangle t, and their distances from p."""
        nodes = self._fv[t]
        pv = self._pv[t]
        if pv is not None:
            ids, vx, vy, rx, ry, lx, ly = pv
            dx, dy = px - vx, py - vy
            tol = -self.tol
            ok = (rx * dy - ry * dx >= tol) & (dx * ly - dy * lx >= tol)
            if ok.any():
                nodes = np.concatenate([nodes, ids[ok]])
        pos = self.nodes[nodes]
        return nodes, np.hypot(pos[:, 0] - px, pos[:, 1] - py)

    def corner_path(
        self, ts: list[int], sx: float, sy: float, tg: list[int], gx: float, gy: float
    ) -> tuple[list[int], float]:
        """Best corner chain from s to g for an s that does not see g: (nodes, length).

        ``ts`` / ``tg``: triangles holding s / g (several only at a pinch vertex).
        """
        a_nodes, a_dist = self._visible_from(ts, sx, sy)
        b_nodes, b_dist = self._visible_from(tg, gx, gy)
        if a_nodes.size == 0 or b_nodes.size == 0:
            return [], math.inf
        total = self.dist[a_nodes[:, None], b_nodes]
        total += a_dist[:, None]
        total += b_dist
        i = int(np.argmin(total))
        ia, ib = divmod(i, total.shape[1])
        best = float(total[ia, ib])
        a, b = int(a_nodes[ia]), int(b_nodes[ib])
        chain = [a]
        nxt = self._next
        for _ in range(len(self.nodes_x)):
            if a == b:
                break
            a = int(nxt[a, b])
            chain.append(a)
        return chain, best

    def _visible_from(self, ts: list[int], px: float, py: float) -> tuple[np.ndarray, np.ndarray]:
        if len(ts) == 1:
            return self.visible_nodes(ts[0], px, py)
        parts = [self.visible_nodes(t, px, py) for t in ts]
        return np.concatenate([p[0] for p in parts]), np.concatenate([p[1] for p in parts])

    def fan_towards(self, t: int, w: int, dx: float, dy: float) -> int:
        """Triangle of w's sector (the one holding t) that direction d leaves w into.

        t itself only if nothing else fits; -1 if d points into a wall.
        """
        g = self._slot_group[3 * t + self._tri[t].index(w)]
        xs, ys = self._xs, self._ys
        wx, wy = xs[w], ys[w]
        tol = 1e-12 * math.hypot(dx, dy)
        found = -1
        for f in self._group_members[g]:
            tf = self._tri[f]
            k = tf.index(w)
            a, b = tf[(k + 1) % 3], tf[(k + 2) % 3]
            ax, ay = _unit(xs[a] - wx, ys[a] - wy)
            bx, by = _unit(xs[b] - wx, ys[b] - wy)
            if ax * dy - ay * dx >= -tol and dx * by - dy * bx >= -tol:
                if f != t:
                    return f
                found = f
        return found

    def walk(self, t: int, sx: float, sy: float, gx: float, gy: float, trail: list[int] | None = None) -> int:
        """Follow the segment s→g from s's triangle t: the triangle reached holding g, or -1 if blocked.

        Rays through vertices continue within the vertex's walkable sector, so grazing a
        corner is allowed but slipping through a pinch point is not.  Visited triangles
        are appended to ``trail`` if given.
        """
        tri, nb, xs, ys = self._tri, self._nb, self._xs, self._ys
        dx, dy = gx - sx, gy - sy
        l2 = dx * dx + dy * dy
        if l2 == 0.0:
            if trail is not None:
                trail.append(t)
            return t
        tol = self.tol * math.sqrt(l2)
        etol = self.tol
        for k in range(3):  # starting on a vertex: start in the triangle the ray leaves into
            v = tri[t][k]
            if abs(xs[v] - sx) <= etol and abs(ys[v] - sy) <= etol:
                t = self.fan_towards(t, v, dx, dy)
                if t < 0:
                    return -1
                break
        cur = 0.0
        for _ in range(4 * len(tri) + 8):
            if trail is not None:
                trail.append(t)
            t0, t1, t2 = tt = tri[t]
            x0, y0, x1, y1, x2, y2 = xs[t0], ys[t0], xs[t1], ys[t1], xs[t2], ys[t2]
            # is g in t?  (edge functions, tolerance in world units)
            if (
                (x2 - x1) * (gy - y1) - (y2 - y1) * (gx - x1) >= -etol * math.hypot(x2 - x1, y2 - y1)
                and (x0 - x2) * (gy - y2) - (y0 - y2) * (gx - x2) >= -etol * math.hypot(x0 - x2, y0 - y2)
                and (x1 - x0) * (gy - y0) - (y1 - y0) * (gx - x0) >= -etol * math.hypot(x1 - x0, y1 - y0)
            ):
                return t
            side = []
            tau = []
            for vx, vy in ((x0, y0), (x1, y1), (x2, y2)):
                ex, ey = vx - sx, vy - sy
                s_ = dx * ey - dy * ex
                side.append(0.0 if -tol <= s_ <= tol else s_)
                tau.append((ex * dx + ey * dy) / l2)
            # leaving through a vertex on the line, ahead of us?
            best_k, best_tau = -1, math.inf
            for k in range(3):
                if side[k] == 0.0 and cur + 1e-12 < tau[k] < best_tau:
                    best_k, best_tau = k, tau[k]
            if best_k >= 0:
                cur = best_tau
                nxt = self.fan_towards(t, tt[best_k], dx, dy)
                if nxt < 0 or nxt == t:
                    return -1
                t = nxt
                continue
            for k in range(3):
                sp, sq = side[(k + 1) % 3], side[(k + 2) % 3]
                if sp < 0.0 < sq:
                    break
            else:
                return -1
            u = nb[t][k]
            if u < 0:
                return -1
            tp, tq = tau[(k + 1) % 3], tau[(k + 2) % 3]
            cur = max(cur, tp + (tq - tp) * (sp / (sp - sq)))
            t = u
        return -1

    def corridor_of(self, ts: list[int], points: list[tuple[float, float]]) -> list[int]:
        """Triangles a polyline of mutually visible points (wall corners inside) passes through.

        ``ts``: triangles holding the first point (several only at a pinch vertex).
        """
        out: list[int] = []
        (ax, ay), (bx, by) = points[0], points[1]
        t = next((u for u in ts if self.walk(u, ax, ay, bx, by) >= 0), ts[0])
        for i in range(len(points) - 1):
            (ax, ay), (bx, by) = points[i], points[i + 1]
            if i > 0:  # at a corner: go round it inside its sector to where the next leg starts
                w = self._vertex_at(t, ax, ay)
                t_out = self.fan_towards(t, w, bx - ax, by - ay) if w >= 0 else t
                out += self._around(t, t_out, w)[1:-1]
                t = t_out
            trail: list[int] = []
            end = self.walk(t, ax, ay, bx, by, trail)
            if end < 0:
                raise ValueError("polyline leaves the walkable area")
            for u in trail:
                if out and out[-1] != u and u not in self._nb[out[-1]]:
                    # the walk went through a vertex: go round it to stay edge-connected
                    shared = [v for v in self._tri[u] if v in self._tri[out[-1]]]
                    out += self._around(out[-1], u, shared[0] if shared else -1)[1:-1]
                if not out or out[-1] != u:
                    out.append(u)
            t = end
        return out

    def _vertex_at(self, t: int, x: float, y: float) -> int:
        for v in self._tri[t]:
            if abs(self._xs[v] - x) <= self.tol and abs(self._ys[v] - y) <= self.tol:
                return v
        return -1

    def _around(self, t: int, target: int, w: int) -> list[int]:
        """Triangles from t to target turning around vertex w without crossing a wall."""
        if t == target or w < 0:
            return [t]
        for turn in (1, 2):  # 1: counter-clockwise (across edge opposite v[k+1]), 2: clockwise
            path = [t]
            cur = t
            for _ in range(len(self._tri)):
                k = self._tri[cur].index(w)
                cur = self._nb[cur][(k + turn) % 3]
                if cur < 0 or cur == t:
                    break
                path.append(cur)
                if cur == target:
                    return path
        return [t, target]


def _unit(x: float, y: float) -> tuple[float, float]:
    n = math.hypot(x, y)
    return (x / n, y / n) if n > 0 else (0.0, 0.0)


def _angle_at(wx: float, wy: float, ax: float, ay: float, bx: float, by: float) -> float:
    ux, uy, vx, vy = ax - wx, ay - wy, bx - wx, by - wy
    return abs(math.atan2(ux * vy - uy * vx, ux * vx + uy * vy))
