"""Searching spreads ahead in a frame's spare time: the frame-budget scheduler of the guards.

The PF guards say which balls they will soon read (:meth:`Prefetch.expect`: a guard's next
node, the player's node while seen); the game hands over the spare time at the end of a
quick frame (:meth:`~ai.view.GuardAI.prepare`), and :meth:`Prefetch.run` searches those
balls a ring at a time within it. Values never depend on it: a ball read before its search
ends finishes that search. On a graph whose spreads are rows nothing is ever queued.
"""

from __future__ import annotations

import time
from collections import deque

from navmesh.distances import SlicedSearch

from .spreads import Spreads


class Prefetch:
    """The queue of balls a controller will read soon, and the one being searched."""

    def __init__(self, spreads: Spreads) -> None:
        self.spreads = spreads
        #: the balls that will soon be read, as (field, node)
        self.ahead: deque[tuple[str, int]] = deque()
        #: what :attr:`ahead` holds, so a ball is queued once however often it is expected
        self._queued: set[tuple[str, int]] = set()
        #: the one being searched, as (field, node, search)
        self.searching: tuple[str, int, SlicedSearch] | None = None

    def expect(self, node: int, which: str = "C", urgent: bool = False) -> None:
        """``node``'s ball of field ``which`` ("C": a guard heads there, "I": the player is
        seen there) will be read soon: queue it if it would be searched then and is not
        queued yet; ``urgent`` puts it first (a guard stands there: the next tick reads it)."""
        key = (which, int(node))
        searching = self.searching
        if key in self._queued or (searching is not None and searching[:2] == key):
            if urgent and key in self._queued and self.ahead[0] != key:
                self.ahead.remove(key)
                self.ahead.appendleft(key)
            return
        if self.spreads.wanted(*key):
            self._queued.add(key)
            if urgent:
                self.ahead.appendleft(key)
            else:
                self.ahead.append(key)

    def run(self, budget: float) -> bool:
        """Search the queued balls not yet kept for about ``budget`` seconds, a ring at a
        time, at least one (a search left unfinished goes on at the next call); whether
        work is left."""
        deadline = time.perf_counter() + budget
        first = True  # at least one ring per call, whatever the budget
        while first or time.perf_counter() < deadline:
            first = False
            if self.searching is None:
                while self.ahead and not self.spreads.wanted(*self.ahead[0]):
                    self._queued.discard(self.ahead.popleft())
                if not self.ahead:
                    return False
                which, node = self.ahead.popleft()
                self._queued.discard((which, node))
                self.searching = (which, node, self.spreads.begin(which, node))
            which, node, search = self.searching
            if search.update(1):
                self.searching = None
                self.spreads.keep(which, node, search)
        return self.searching is not None or bool(self.ahead)
