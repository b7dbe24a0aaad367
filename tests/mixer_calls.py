"""Counting the game's mixer calls per sound kind (tests of sounds): a stand-in Sound object
replaces each of a SoundBoard's sounds, so nothing is heard or timed."""

from __future__ import annotations

from collections import Counter

from game.front.sound import KINDS, SoundBoard


class CountingSound:
    """Stands in for a mixer Sound: counts the mixer calls made for one kind."""

    def __init__(self, kind: str, calls: Counter[str]) -> None:
        self.kind, self.calls = kind, calls

    def play(self, loops: int = 0) -> None:
        self.calls[self.kind] += 1

    def set_volume(self, volume: float) -> None:
        pass


def count_mixer_calls(board: SoundBoard) -> Counter[str]:
    """Replace ``board``'s sounds by counters; the counts, per kind, as they come."""
    assert board.available, "the dummy audio driver opens a mixer"
    calls: Counter[str] = Counter()
    board._sounds = {kind: CountingSound(kind, calls) for kind in KINDS}  # type: ignore[misc]
    return calls
