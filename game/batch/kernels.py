"""The batch engine's per-physics-step loops, compiled with numba.

Each kernel runs one phase of :meth:`game.world.World.step` for every agent of every live
trial of a batch, repeating the reference's float operations in the reference's order so
the results are the same bits. What a kernel cannot finish the way the reference would —
a new waypoint, an arrival, a stuck body, a node entered, a sighting — it leaves alone and
flags, and the engine hands that agent or trial to the world's own Python rules
(:mod:`game.batch.engine`). Arrays are indexed ``[trial, agent]``: the guards, then the
player last.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .. import exact
from ..exact import clear_line, py_hypot, touches_wall


exact.forget_stale_cache(__file__)

#: the reference's tolerances (game.agents.ARRIVE_EPS, game.senses.RANGE_EPS)
ARRIVE_EPS = 1e-3
RANGE_EPS = 1e-9


@njit(cache=True)
def drive(live, active, has_wp, wp, pos, cruise_ok, cruise_speed, cruise_rem, on_track, speed,
          cmd, vel, heading, dt):
    """``Locomotion.drive`` for every agent: the velocity towards its next waypoint, landing
    on it exactly; on a straight stretch the velocity stays and the distance left goes down
    by a step. ``cmd`` is the velocity last set (``Agent.velocity``), ``vel`` the body's:
    a velocity equal to the one set is not written again, as ``Agent.set_velocity`` skips it."""
    n_trials, n_agents = active.shape
    for b in range(n_trials):
        if not live[b]:
            continue
        for a in range(n_agents):
            vx, vy = 0.0, 0.0
            if active[b, a] and has_wp[b, a]:
                step = speed[b, a] * dt
                if (cruise_ok[b, a] and cruise_speed[b, a] == speed[b, a] and on_track[b, a]
                        and cruise_rem[b, a] > step):
                    cruise_rem[b, a] = cruise_rem[b, a] - step
                    continue
                dx, dy = wp[b, a, 0] - pos[b, a, 0], wp[b, a, 1] - pos[b, a, 1]
                d = py_hypot(dx, dy)
                cruise_ok[b, a] = False
                if d >= 1e-12:
                    if d <= step:
                        vx, vy = dx / dt, dy / dt
                    else:
                        cruise_ok[b, a] = True
                        cruise_speed[b, a] = speed[b, a]
                        cruise_rem[b, a] = d - step
                        vx, vy = dx / d * speed[b, a], dy / d * speed[b, a]
                    heading[b, a] = math.atan2(dy, dx)
            else:
                cruise_ok[b, a] = False
            if vx != cmd[b, a, 0] or vy != cmd[b, a, 1]:
                cmd[b, a, 0], cmd[b, a, 1] = vx, vy
                vel[b, a, 0], vel[b, a, 1] = vx, vy


@njit(cache=True)
def move(live, pos, vel, dt):
    """Chipmunk's position update without contacts: ``p + v·dt`` (the same bits as
    ``cpBodyUpdatePosition`` with a zero bias velocity; checked against pymunk)."""
    n_trials, n_agents = live.shape[0], pos.shape[1]
    for b in range(n_trials):
        if not live[b]:
            continue
        for a in range(n_agents):
            pos[b, a, 0] = pos[b, a, 0] + vel[b, a, 0] * dt
            pos[b, a, 1] = pos[b, a, 1] + vel[b, a, 1] * dt


@njit(cache=True)
def touching(live, pos, radius, segs, cell_start, cell_items, geom, out):
    """Per trial: whether some body is within reach of a wall after the move (pymunk would
    make a contact, which only pymunk's solver resolves the reference's way)."""
    n_trials, n_agents = live.shape[0], pos.shape[1]
    for b in range(n_trials):
        out[b] = False
        if not live[b]:
            continue
        for a in range(n_agents):
            if touches_wall(segs, cell_start, cell_items, geom, pos[b, a, 0], pos[b, a, 1],
                            radius):
                out[b] = True
                break


#: what :func:`settle` made of an agent's step
QUIET, ENTERED, ARRIVED, SLOW = 0, 1, 2, 3


@njit(cache=True)
def settle(live, pos, before, has_wp, n_wp, wp, cruise_ok, speed, dt, since, on_track, node,
           stuck_timeout, radius, cell_node, cell_size, tri_eqs, tri_tol, locate_geom,
           locate_start, locate_items, kind, new_node):
    """``World.settle_agent`` for every agent, as far as it runs without Python: ``kind``
    says what it made of each agent's step — QUIET (time passed), ENTERED (a node entered
    by walking, ``new_node``), ARRIVED (its last waypoint reached: the target) — those three
    with ``on_track`` and ``since`` committed; SLOW (a waypoint passed, a stall, stuck, a
    point off the graph's cells) with its state untouched, for the world's rule to run."""
    n_trials, n_agents = live.shape[0], pos.shape[1]
    grid = cell_node.shape[0] > 0
    for b in range(n_trials):
        if not live[b]:
            continue
        for a in range(n_agents):
            x, y = pos[b, a, 0], pos[b, a, 1]
            bx, by = before[b, a, 0], before[b, a, 1]
            moved = py_hypot(x - bx, y - by)
            expected = speed[b, a] * dt
            waiting = since[b, a] + dt
            result = QUIET
            if has_wp[b, a]:
                d = py_hypot(wp[b, a, 0] - x, wp[b, a, 1] - y)
                stalled = moved < 0.25 * expected
                if d <= ARRIVE_EPS or (stalled and d <= radius + 0.05):
                    if n_wp[b, a] != 1:
                        kind[b, a] = SLOW
                        continue
                    result = ARRIVED  # Locomotion.advance: the target reached, no stuck test
                elif waiting > stuck_timeout:
                    kind[b, a] = SLOW
                    continue
            if result == QUIET and (x != bx or y != by):
                n = node[b, a]
                if grid:
                    row = math.floor(y / cell_size)
                    col = math.floor(x / cell_size)
                    if (row < 0 or row >= cell_node.shape[0] or col < 0
                            or col >= cell_node.shape[1] or cell_node[row, col] < 0):
                        kind[b, a] = SLOW  # off the cells: the nearest node, in Python
                        continue
                    m = cell_node[row, col]
                else:
                    m = n
                    if not _in_triangle(tri_eqs, tri_tol, n, x, y):
                        m = _locate(tri_eqs, tri_tol, locate_geom, locate_start, locate_items,
                                    x, y)
                        if m < 0:
                            kind[b, a] = SLOW
                            continue
                if m != n:
                    result = ENTERED
                    new_node[b, a] = m
            kind[b, a] = result
            on_track[b, a] = abs(moved - expected) < 1e-9
            since[b, a] = waiting
            if result == ARRIVED:
                has_wp[b, a] = False
                n_wp[b, a] = 0
                cruise_ok[b, a] = False


@njit(cache=True, inline="always")
def _in_triangle(tri_eqs, tri_tol, t, x, y):
    """``NavMesh.triangle_contains``: the same three edge tests, boundary included."""
    e = tri_eqs[t]
    eps = -tri_tol
    return (e[0] * x + e[1] * y + e[2] >= eps and e[3] * x + e[4] * y + e[5] >= eps
            and e[6] * x + e[7] * y + e[8] >= eps)


@njit(cache=True)
def _locate(tri_eqs, tri_tol, geom, cell_start, cell_items, x, y):
    """``NavMesh.locate``: the first triangle of (x, y)'s bucket that contains it, or -1."""
    x0, y0, sx, sy, nx, ny = geom[0], geom[1], geom[2], geom[3], int(geom[4]), int(geom[5])
    fx = (x - x0) * sx
    fy = (y - y0) * sy
    if not (-0.5 <= fx <= nx + 0.5 and -0.5 <= fy <= ny + 0.5):
        return -1
    i = min(max(int(fx), 0), nx - 1)
    j = min(max(int(fy), 0), ny - 1)
    c = j * nx + i
    for k in range(cell_start[c], cell_start[c + 1]):
        t = cell_items[k]
        if _in_triangle(tri_eqs, tri_tol, t, x, y):
            return t
    return -1


@njit(cache=True)
def _perceives(ox, oy, heading, use_cone, tx, ty, reach, cos_half_fov, line_of_sight,
               segs, cell_start, cell_items, geom):
    """``Senses.perceives``: range (with ``RANGE_EPS``), the cone, then the line of sight."""
    dx, dy = tx - ox, ty - oy
    d2 = dx * dx + dy * dy
    limit = reach + RANGE_EPS
    if d2 > limit * limit:
        return False
    if use_cone:
        d = math.sqrt(d2)
        if not (d <= 1e-9 or dx * math.cos(heading) + dy * math.sin(heading) >= cos_half_fov * d):
            return False
    return (not line_of_sight) or clear_line(segs, cell_start, cell_items, geom, ox, oy, tx, ty)


@njit(cache=True)
def sense(live, pos, heading, active, node, view_range, view_scale_at, attack_range,
          attack_los, cos_half_fov, segs, cell_start, cell_items, geom, key, dist_now,
          has_dist, dist_sum, dist_n, euc_sum, euc_n, seeing, attackers, key_changed):
    """``World._sense`` for every live trial: which guards see the player (a bit each in
    ``seeing``), how many are in attack range, and the step's distance samples. The path
    distance is summed here while the nodes stay those of the last sample (``key``); a
    trial whose nodes changed is flagged in ``key_changed`` for the graph to be asked."""
    n_trials, n_agents = live.shape[0], pos.shape[1]
    p = n_agents - 1
    for b in range(n_trials):
        if not live[b]:
            continue
        px, py = pos[b, p, 0], pos[b, p, 1]
        reach = view_range[b] * view_scale_at[node[b, p]]
        bits = 0
        count = 0
        nearest = 0.0
        any_guard = False
        changed = key[b, p] != node[b, p]
        for g in range(p):
            if not active[b, g]:
                if key[b, g] != -1:
                    changed = True
                continue
            gx, gy = pos[b, g, 0], pos[b, g, 1]
            if _perceives(gx, gy, heading[b, g], True, px, py, reach, cos_half_fov, True,
                          segs, cell_start, cell_items, geom):
                bits |= 1 << g
            if _perceives(gx, gy, 0.0, False, px, py, attack_range, cos_half_fov, attack_los,
                          segs, cell_start, cell_items, geom):
                count += 1
            if key[b, g] != node[b, g]:
                changed = True
            h = py_hypot(gx - px, gy - py)
            if not any_guard or h < nearest:
                nearest = h
            any_guard = True
        seeing[b] = bits
        attackers[b] = count
        if any_guard:
            euc_sum[b] = euc_sum[b] + nearest
            euc_n[b] += 1
        key_changed[b] = changed
        if not changed and has_dist[b]:
            dist_sum[b] = dist_sum[b] + dist_now[b]
            dist_n[b] += 1


def empty_cells() -> np.ndarray:
    """The grid lookup of a partition level: none."""
    return np.zeros((0, 0), dtype=np.int64)


__all__ = ["drive", "empty_cells", "move", "sense", "settle", "touching"]
