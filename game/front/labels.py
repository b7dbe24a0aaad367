"""Where the guards' behaviour labels go: boxes that overlap neither each other nor a body.

A label sits above its guard when that spot is free. Guards standing together would put
their labels on top of each other (and on the neighbours' bodies), so each label, in turn,
takes the first free slot among: above, below (past the awareness meter), right, left,
then further up or down in a stack. The stack is long enough that a free slot always
exists, so no two labels ever overlap and no label covers a guard or the player. Pure
geometry on pixel boxes (no pygame), so it is tested directly.

>>> place_labels([(100, 100, 6), (100, 100, 6)], [(40, 12), (40, 12)])
[(80.0, 78.0), (80.0, 116.0)]
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence

__all__ = ["Box", "GAP", "overlaps", "place_labels"]

#: ``(x, y, w, h)`` in pixels, top-left corner and size.
Box = tuple[float, float, float, float]

#: Pixels between a body and its label, and between stacked labels.
GAP = 4.0
#: Extra room below a guard for its awareness meter.
BELOW = 6.0


def overlaps(a: Box, b: Box) -> bool:
    """Whether two boxes share interior (touching edges do not count)."""
    return a[0] < b[0] + b[2] and b[0] < a[0] + a[2] and a[1] < b[1] + b[3] and b[1] < a[1] + a[3]


def _slots(cx: float, cy: float, r: float, w: float, h: float, depth: int) -> Iterator[tuple[float, float]]:
    """Candidate corners, best first: above, below, right, left, then stacked up and down."""
    above = cy - r - GAP - h
    below = cy + r + GAP + BELOW
    yield from ((cx - w / 2, above), (cx - w / 2, below),
                (cx + r + GAP, cy - h / 2), (cx - r - GAP - w, cy - h / 2))
    for k in range(1, depth + 1):
        yield cx - w / 2, above - k * (h + GAP / 2)
        yield cx - w / 2, below + k * (h + GAP / 2)


def place_labels(anchors: Sequence[tuple[float, float, float]], sizes: Sequence[tuple[float, float]],
                 avoid: Sequence[Box] = ()) -> list[tuple[float, float]]:
    """Top-left corners for one label per anchor ``(cx, cy, radius)`` of size ``(w, h)``.

    Labels are placed in order; each avoids the labels placed before it, every anchor's
    body (its disc's bounding box) and the ``avoid`` boxes (e.g. the player).
    """
    bodies: list[Box] = [(cx - r, cy - r, 2 * r, 2 * r) for cx, cy, r in anchors]
    blockers = bodies + list(avoid)
    # A box of height H rules out at most H // step + 2 slots of a stack (step = the
    # smallest label height + GAP / 2), so this depth always leaves a free slot above.
    step = min((h for _, h in sizes), default=1.0) + GAP / 2
    tallest = max((h for _, h in sizes), default=0.0)
    depth = (sum(int(b[3] // step) + 2 for b in blockers)
             + len(anchors) * (int(tallest // step) + 2) + 1)
    placed: list[Box] = []
    out: list[tuple[float, float]] = []
    for (cx, cy, r), (w, h) in zip(anchors, sizes):
        chosen = None
        for x, y in _slots(cx, cy, r, w, h, depth):
            box = (x, y, w, h)
            if not any(overlaps(box, other) for other in placed) and \
                    not any(overlaps(box, other) for other in blockers):
                chosen = (float(x), float(y))
                break
        if chosen is None:  # pragma: no cover - the depth above rules this out
            chosen = (float(cx - w / 2), float(cy - r - GAP - h))
        placed.append((chosen[0], chosen[1], w, h))
        out.append(chosen)
    return out
