"""Work the game on a large level does beside its frames gives exactly what it did inside them.

The distance metric's searches in a worker process, spreads searched ahead a ring at a
time, the field overlay on a thread, the static layer composed in stripes: each must give
the same metrics, balls and pixels as the synchronous path (docs/play.md, frame times).
"""

from __future__ import annotations

import os
import time
from concurrent.futures import Future

os.environ["SDL_VIDEODRIVER"] = "dummy"
os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")

import numpy as np
import pygame
from scipy.sparse.csgraph import dijkstra

from ai.decay_ahead import DecayAhead
from ai.fields import CompositeField, FieldMatrices
from ai.params import PFParams
from ai.prefetch import Prefetch
from game.large.distance_worker import DistanceWorker
from game.front.layers import StaticLayers
from game.front.render import init_pygame
from game.scene import FieldLayer, SceneBuilder, StaticScene
from game.trial import TrialSpec, make_world
from navmesh.graph import NodeGraph, graph_for
from navmesh.level import load_level


def _sparse_grid(seed: int) -> NodeGraph:
    occupancy = np.random.default_rng(seed).random((30, 40)) > 0.3  # several pieces
    return NodeGraph.from_grid(occupancy, 0.7, dense=False)


def test_ring_by_ring_balls_equal_the_scipy_search() -> None:
    for seed in range(3):
        graph = _sparse_grid(seed)
        unit = graph.adjacency.copy()
        unit.data[:] = 1.0
        for src in range(0, graph.n, 37):
            for max_hops in (0, 1, 4, 30, None):
                limit = np.inf if max_hops is None else max_hops
                found = dijkstra(unit, indices=src, limit=limit)
                inside, hops = graph.hop_ball(src, max_hops)
                assert np.array_equal(inside, np.flatnonzero(np.isfinite(found)))
                assert np.array_equal(hops, found[inside].astype(np.int32))
                assert np.array_equal(hops, graph.hops_from(src, max_hops)[inside])


def test_balls_searched_ahead_equal_the_ones_searched_when_needed() -> None:
    graph = _sparse_grid(1)
    ahead, now = FieldMatrices(graph, PFParams()), FieldMatrices(graph, PFParams())
    prefetch = Prefetch(ahead.spreads)
    nodes = [3, 40, 41, 300, 3]
    for node in nodes:
        prefetch.expect(node)
    prefetch.run(0.0)  # one ring: the first search is left half done
    assert prefetch.searching is not None
    half_done = prefetch.searching[1]
    # a decision that needs the half-done ball finishes that search, with the same result
    assert np.array_equal(ahead.conf_spread(half_done), now.conf_spread(half_done))
    prefetch.run(10.0)
    for node in nodes:
        assert not ahead.spreads.wanted("C", node)
        assert np.array_equal(ahead.conf_spread(node), now.conf_spread(node))
    assert np.array_equal(ahead.deposit(nodes), now.deposit(nodes))
    prefetch.expect(7, "I")  # a sighting's information ball, searched ahead as well
    assert prefetch.ahead
    prefetch.run(10.0)
    assert not ahead.spreads.wanted("I", 7) and not prefetch.ahead


def test_nothing_is_searched_ahead_on_a_graph_whose_spreads_are_rows() -> None:
    graph = NodeGraph.from_grid(np.ones((6, 6), dtype=bool), 1.0)
    prefetch = Prefetch(FieldMatrices(graph, PFParams()).spreads)
    prefetch.expect(3)
    prefetch.expect(4, "I")
    assert not prefetch.ahead and prefetch.searching is None


def test_a_field_snapshot_computes_the_fields_of_its_moment() -> None:
    field = CompositeField(_sparse_grid(2))
    field.tick(1.0, [5, 60], 200)
    snapshot = field.snapshot()
    expected = {k: v.copy() for k, v in field.fields().items()}
    field.tick(1.0, [6, 61], None)  # the live field moves on; the snapshot does not
    later = snapshot()
    assert set(later) == set(expected)
    assert all(np.array_equal(later[k], expected[k]) for k in expected)
    assert snapshot.identity != field.snapshot().identity


def test_fields_decayed_ahead_tick_to_the_same_bits(monkeypatch) -> None:  # type: ignore[no-untyped-def]
    """The next tick's I · ρ^dt and C · decay^dt computed ahead (whole, a slice at a time,
    or begun from arrays a tick has since replaced) give the fields of a tick that
    multiplies them itself, and the arrays handed out before stay as they were."""
    monkeypatch.setattr(DecayAhead, "SLICE", 97)  # a dozen slices on this graph
    graph = _sparse_grid(3)
    now, ahead = CompositeField(graph), CompositeField(graph)
    ahead_slices = ahead._ahead  # none before the first tick: no length to take
    assert ahead_slices is None and not ahead.work_ahead(time.perf_counter() + 10.0)
    script = [([5, 60], 200), ([6, 61], None), ([6, 62], None), ([7, 62], 90), ([8, 63], None),
              ([8, 64], None), ([9, 64], None)]
    for step, (guards, sighting) in enumerate(script):
        before = {k: v.copy() for k, v in ahead.fields().items()}
        handed_out = ahead.fields()
        if step % 3 == 1:
            assert not ahead.work_ahead(time.perf_counter() + 10.0)  # all of it
        elif step % 3 == 2:
            ahead.work_ahead(0.0)  # begun, nothing filled: the tick finishes it
            assert ahead._ahead is not None and ahead._ahead.done == 0
            ahead.work_ahead(time.perf_counter() + 1e-5)  # perhaps a slice or two
        now.tick(1.0, guards, sighting)
        ahead.tick(1.0, guards, sighting)
        assert all(np.array_equal(handed_out[k], before[k]) for k in before)
        for name, value in now.fields().items():
            assert np.array_equal(value, ahead.fields()[name]), (step, name)
    # begun from the fields before a tick that then did not use it: dropped, not read later
    ahead.work_ahead(time.perf_counter() + 10.0)
    stale = ahead._ahead
    ahead.tick(0.5, [9], None)  # another length: multiplied here, the work ahead dropped
    now.tick(0.5, [9], None)
    assert ahead._ahead is None and stale is not None
    assert np.array_equal(now.confidence, ahead.confidence)
    assert np.array_equal(now.information, ahead.information)


def _worlds(steps: int, worker: DistanceWorker | None, spec: TrialSpec) -> dict:
    world = make_world(spec)
    world.m.distance_worker = worker
    for _ in range(steps):
        world.step()
    return world.metrics()


def test_the_distance_metric_from_a_worker_process_is_the_same() -> None:
    spec = TrialSpec("miami", "grid", "pf", "maxmin", "fixed", seed=3)
    graph = make_world(spec).graph
    worker = DistanceWorker(graph)
    try:
        with_worker = _worlds(400, worker, spec)
        assert worker._pool is not None  # the searches did run in the worker
    finally:
        worker.close()
    assert with_worker == _worlds(400, None, spec)
    # a worker that is gone costs time, not the metric: the searches run here instead
    assert _worlds(400, worker, spec) == with_worker


def test_the_overlay_computed_on_a_thread_is_the_synchronous_one() -> None:
    spec = TrialSpec("tlou", "grid", "pf", "maxmin", "fixed", seed=1)
    world = make_world(spec)
    for _ in range(80):
        world.step()
    kwargs = {"view_range": world.view_range, "fov_deg": 90.0}
    now = SceneBuilder(world.level, world.graph, **kwargs).from_world(world, "K")
    later = SceneBuilder(world.level, world.graph, background_fields=True, **kwargs)
    scene = later.from_world(world, "K")
    deadline = time.monotonic() + 30
    while scene.layer is None and time.monotonic() < deadline:
        time.sleep(0.01)
        scene = later.from_world(world, "K")
    assert scene.layer is not None and now.layer is not None
    assert np.array_equal(scene.layer.values, now.layer.values)
    assert np.array_equal(scene.layer.norm, now.layer.norm)


def _arkham_layers(seed: int, count: int) -> tuple[StaticLayers, StaticLayers, list[FieldLayer]]:
    """Arkham's grid drawn once at once and once in 4 stripes, and ``count`` random K layers."""
    init_pygame()
    pygame.display.set_mode((320, 240))
    level = load_level("arkham")
    graph = graph_for(level, "grid")
    static = StaticScene.from_level(level, graph)
    rng = np.random.default_rng(seed)
    fields = [FieldLayer.from_values("K", rng.normal(size=graph.n)) for _ in range(count)]
    return StaticLayers(static), StaticLayers(static, stripes=4), fields


def test_a_layer_composed_in_stripes_has_the_pixels_of_one_composed_at_once() -> None:
    at_once, striped, (first, second) = _arkham_layers(4, 2)
    visible = (2.0, 2.0, 14.0, 11.0)
    for layers in (at_once, striped):
        layers.surface(visible, 20.0, first, False)
    want = pygame.surfarray.array3d(at_once.surface(visible, 20.0, second, False)[0])
    shown = [pygame.surfarray.array3d(striped.surface(visible, 20.0, second, False)[0])
             for _ in range(4)]
    before = pygame.surfarray.array3d(at_once.surface(visible, 20.0, first, False)[0])
    assert all(np.array_equal(s, before) for s in shown[:3])  # the old layer until complete
    assert np.array_equal(shown[3], want) and not np.array_equal(want, before)



def test_a_stripe_count_changed_between_layers_keeps_the_pixels() -> None:
    at_once, striped, layers_k = _arkham_layers(5, 3)
    visible = (2.0, 2.0, 14.0, 11.0)
    assert striped.striped and not at_once.striped
    for layers in (at_once, striped):
        layers.surface(visible, 20.0, layers_k[0], False)
    assert striped.compose_cost > 0
    for layer, count in ((layers_k[1], 2), (layers_k[2], 5)):
        striped.stripes = count
        want = pygame.surfarray.array3d(at_once.surface(visible, 20.0, layer, False)[0])
        shown = []
        for k in range(count):
            shown.append(pygame.surfarray.array3d(striped.surface(visible, 20.0, layer, False)[0]))
            striped.stripes = 3  # a change while composing applies to the next layer only
        assert all(not np.array_equal(s, want) for s in shown[:-1])
        assert np.array_equal(shown[-1], want)


class _SlowWorker:
    """A worker whose searches finish when the test says so."""

    def __init__(self, graph: NodeGraph) -> None:
        self.graph, self.searches = graph, []

    def submit(self, guard_nodes, player_node):  # type: ignore[no-untyped-def]
        search: Future[float] = Future()
        self.searches.append((search, guard_nodes, player_node))
        return search

    def value(self, search, guard_nodes, player_node):  # type: ignore[no-untyped-def]
        return float(search.result())

    def finish(self) -> None:
        for search, guards, player in self.searches:
            if not search.done():
                search.set_result(self.graph.nearest_dist_to(list(guards), player))


def test_the_game_over_screen_does_not_wait_for_the_worker() -> None:
    """While searches are pending the end screen says so (no frame blocks); once they are
    done it shows the trial's metrics."""
    from game.front.play import PlayGame, PlaySettings

    game = PlayGame(PlaySettings("miami", guards="pf", autopilot="maxmin",
                                 overrides=("world.duration=3",)), lockstep=True, size=(640, 480))
    worker = _SlowWorker(game.world.graph)
    game.world.m.distance_worker = worker  # type: ignore[assignment]
    try:
        game.run(200)  # 3 s of game: over
        assert game.state == "over" and game.world.m.distances_pending() > 0
        panel = game.panel()
        assert panel is not None and "follow in a moment" in " ".join(panel.lines)
        worker.finish()
        assert game.world.m.distances_ready()
        lines = " ".join(game.panel().lines)  # type: ignore[union-attr]
        assert "mean guard distance" in lines
        assert game.world.metrics()["avg_guard_player_dist"] > 0
    finally:
        game.close()


def test_without_room_for_the_worker_the_searches_run_here(monkeypatch) -> None:  # type: ignore[no-untyped-def]
    """No space for the graph's file (a full disk): no worker, the same distances."""
    import game.large.distance_worker as module

    def full_disk(*args, **kwargs):  # type: ignore[no-untyped-def]
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(module.tempfile, "mkdtemp", full_disk)
    graph = _sparse_grid(0)
    worker = DistanceWorker(graph)
    assert worker._pool is None
    found = worker.submit((3, 50), 200)
    assert worker.value(found, (3, 50), 200) == graph.nearest_dist_to([3, 50], 200)
    worker.close()
