"""The one colour of each guard mode, the same in every figure of every report.

A mode's colour is the ``tab10`` colour of its place in the guard-mode registry
(:data:`ai.GUARD_MODES`, SPEC §9 order), not of its place among the modes one report
happens to hold, so PotentialField is blue in the aggregate figure, the heatmap panels and
any other report, whichever modes they show. A mode registered later (a plugin, a test)
gets the next colour.

>>> guard_colour("pf"), guard_colour("cheat")
('#1f77b4', '#9467bd')
"""

from __future__ import annotations

from ai import GUARD_MODES

__all__ = ["TAB10", "guard_colour"]

TAB10 = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2",
         "#7f7f7f", "#bcbd22", "#17becf")
"""matplotlib's ``tab10``, written out so the palette needs no matplotlib."""


def guard_colour(mode: str) -> str:
    """The colour of guard mode ``mode`` (grey for a mode that is not registered)."""
    order = list(GUARD_MODES)
    if mode not in order:
        return TAB10[7]
    return TAB10[order.index(mode) % len(TAB10)]
