"""The screens over the map in ``stealth play`` (ready, questions, game over), apart from its loop."""

from __future__ import annotations

from typing import TYPE_CHECKING

from game.front.palette import BAD, GOOD, WARN
from game.front.screens import Panel
from game.record import QUESTIONS

if TYPE_CHECKING:
    from game.front.play import PlayGame

__all__ = ["over_panel", "play_panel"]


def play_panel(game: PlayGame) -> Panel | None:
    """The screen over the map now (ready, questionnaire, game over), if any."""
    goal = game.goal
    if game.state == "ready":
        if goal.has_goal:
            task = (f"Pick up the {len(goal.collected)} stars, then reach" if len(goal.collected)
                    else "Reach") + " the green exit without being caught"
        else:
            task = f"Survive {game.world.total_steps * game.world.dt:g} s without being caught"
        return Panel(f"{game.level.name}: ready", (task, "The clock starts on your first move (WASD / arrows)"),
                     GOOD, hint="N next level · B previous · Esc quit")
    if game.state == "questions":
        k = len(game.answers)
        return Panel("Your view (1-5)", [q for _, q in QUESTIONS], WARN, choice=k,
                     hint="press 1-5 for the marked question · Enter skip")
    if game.state == "over":
        return over_panel(game)
    return None


def over_panel(game: PlayGame) -> Panel:
    """The game-over screen: the outcome and the session's metrics (once they are ready)."""
    titles = {"won": ("ESCAPED", GOOD), "caught": ("CAUGHT", BAD),
              "survived": ("SURVIVED", GOOD), "time up": ("TIME UP", WARN)}
    title, color = titles.get(game.outcome, (game.outcome.upper(), WARN))
    hint = "Enter restart · N next level · 1-5 other guards · Esc quit"
    pending = game.world.m.distances_pending()
    if pending:  # a large level: the metrics wait for the worker; the window does not
        return Panel(title, [f"time {game.world.t:.1f} s · the metrics follow in a moment "
                             f"({pending} distance searches to go)"], color, hint=hint)
    m = game.world.metrics()
    seen = m["first_detect_time"]
    lines = [f"time {game.world.t:.1f} s · captures {m['captures']} · first seen "
             + ("never" if seen is None else f"at {seen:.1f} s")]
    lines.append(f"mean guard distance {m['avg_guard_player_dist']:.1f} · guard coverage "
                 f"{100 * m['coverage']:.0f} %"
                 + (f" · stars {int(game.goal.collected.sum())}/{len(game.goal.collected)}"
                    if len(game.goal.collected) else ""))
    return Panel(title, lines, color, hint=hint)
