"""Guard label placement (game.front.labels): pure geometry, no pygame."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from game.front.labels import overlaps, place_labels


def _boxes(anchors, sizes, avoid=()):
    spots = place_labels(anchors, sizes, avoid)
    return [(x, y, w, h) for (x, y), (w, h) in zip(spots, sizes)]


def test_a_lone_guard_has_its_label_centred_above_it() -> None:
    (x, y, w, h), = _boxes([(200.0, 150.0, 8.0)], [(60.0, 14.0)])
    assert x + w / 2 == pytest.approx(200.0)
    assert y + h <= 150.0 - 8.0  # entirely above the body


def test_far_apart_guards_all_keep_the_spot_above() -> None:
    anchors = [(100.0 * k, 100.0, 6.0) for k in range(1, 6)]
    boxes = _boxes(anchors, [(50.0, 14.0)] * 5)
    assert all(y + h <= 100.0 - 6.0 and x + w / 2 == pytest.approx(cx)
               for (x, y, w, h), (cx, _, _) in zip(boxes, anchors))


@pytest.mark.parametrize("spread", [0.0, 3.0, 12.0, 25.0])
def test_guards_standing_together_get_labels_that_overlap_nothing(spread: float) -> None:
    """Eight guards in a huddle (same point up to ``spread`` px), the player among them:
    no two labels overlap, and no label covers a guard's body or the player."""
    rng = np.random.default_rng(int(spread))
    anchors = [(300.0 + float(dx), 200.0 + float(dy), 7.0) for dx, dy in rng.uniform(-spread, spread, (8, 2))]
    sizes = [(float(w), 13.0) for w in rng.integers(30, 90, 8)]
    player = (296.0, 196.0, 12.0, 12.0)
    boxes = _boxes(anchors, sizes, avoid=[player])
    for a, b in itertools.combinations(boxes, 2):
        assert not overlaps(a, b), (a, b)
    bodies = [(cx - r, cy - r, 2 * r, 2 * r) for cx, cy, r in anchors] + [player]
    for box in boxes:
        assert not any(overlaps(box, body) for body in bodies), box


def test_labels_stay_close_to_their_guard() -> None:
    """A displaced label is still near its guard (within a few label heights)."""
    anchors = [(400.0, 300.0, 6.0)] * 6
    boxes = _boxes(anchors, [(48.0, 13.0)] * 6)
    for x, y, w, h in boxes:
        assert abs(y + h / 2 - 300.0) < 6 * (13.0 + 4.0)
        assert abs(x + w / 2 - 400.0) < 48.0 + 20.0


def test_overlap_is_interior_only() -> None:
    assert overlaps((0, 0, 10, 10), (5, 5, 10, 10))
    assert not overlaps((0, 0, 10, 10), (10, 0, 10, 10))  # touching edges
    assert not overlaps((0, 0, 10, 10), (0, 11, 10, 10))
