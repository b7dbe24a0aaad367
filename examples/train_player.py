"""Tabular Q-learning of a player on a small level, compared with the MaxMin policy.

    python examples/train_player.py                # maze, grid, capture, PF guards
    python examples/train_player.py --episodes 300 --out /tmp/train.png

The learner plays ``StealthEnv`` (game.env) on training seeds 1000, 1001, ...; the greedy
policy is then played on held-out seeds 0 … N−1 and its capture rate is compared with
MaxMin's, run by the project's own ``run_trial`` on the same level, abstraction, scenario,
guard mode and seeds. Episode ``s`` of the env and trial ``s`` share the spawn generator,
so each held-out seed starts both players at the same node against guards at the same
nodes and headings; the guards' own generator (tie-breaking only) differs between the
two, as it does between any two player policies in a sweep.

The state is a tabulation of the player's observation: which of its 4 neighbouring
cells are walkable (from the occupancy window), the nearest guard it perceives, if any,
as one of 4 directions × 3 distance bands, and whether a guard sees it now (416 states;
no position, so what it learns carries over between seeds). Writes a figure (learning curve, capture-rate bars).
"""

from __future__ import annotations

import argparse
import json
import math
import time
from pathlib import Path

import numpy as np

from game.env import PLAYER_CHANNELS, PLAYER_FEATURES, PLAYER_GUARD, StealthEnv
from game.trial import TrialSpec, run_trial

BANDS = (2.0, 4.0, 8.0)  # distance bands of the nearest perceived guard (world units)


class Tabulator:
    """Maps a player observation to a small integer state (see the module docstring)."""

    def __init__(self, env: StealthEnv) -> None:
        m = env.unwrapped.match
        self.scale = m.view_range  # the player's guard offsets are in view-range units
        r = m.observer.radius
        side = 2 * r + 1
        self.base = len(PLAYER_CHANNELS) * side ** 2
        # the window's centre cell is the player's; N, E, S, W of it:
        self.around = [(r - 1) * side + r, r * side + r + 1, (r + 1) * side + r, r * side + r - 1]
        self.n_guards = m.n_guards
        self.n_states = 16 * (1 + 4 * len(BANDS)) * 2

    def __call__(self, obs: np.ndarray) -> int:
        f = obs[self.base:]
        walls = sum(1 << k for k, i in enumerate(self.around) if obs[i] > 0.5)
        detected = int(f[PLAYER_FEATURES.index("detected")] > 0.5)
        slots = f[len(PLAYER_FEATURES):len(PLAYER_FEATURES) + len(PLAYER_GUARD) * self.n_guards]
        guards = slots.reshape(self.n_guards, len(PLAYER_GUARD))
        code = 0
        seen = guards[:, 0] > 0.5
        if seen.any():
            d = guards[seen, 1:3] * self.scale
            k = int(np.argmin(np.hypot(d[:, 0], d[:, 1])))
            dx, dy = d[k]
            direction = (0 if dy < 0 else 2) if abs(dy) >= abs(dx) else (1 if dx > 0 else 3)
            band = next((b for b, r in enumerate(BANDS) if math.hypot(dx, dy) <= r), len(BANDS) - 1)
            code = 1 + direction * len(BANDS) + band
        return (walls * (1 + 4 * len(BANDS)) + code) * 2 + detected


def episode(env: StealthEnv, tab: Tabulator, q: np.ndarray, seed: int, rng: np.random.Generator,
            eps: float, alpha: float, gamma: float, learn: bool) -> tuple[float, bool]:
    """One episode (ε-greedy, Q-learning updates when ``learn``): return, captured."""
    obs, _ = env.reset(seed=seed)
    s = tab(obs)
    total, term, trunc, info = 0.0, False, False, {}
    while not (term or trunc):
        a = int(rng.integers(q.shape[1])) if rng.random() < eps else int(np.argmax(q[s]))
        obs, r, term, trunc, info = env.step(a)
        s2 = tab(obs)
        if learn:
            target = r if term else r + gamma * q[s2].max()
            q[s, a] += alpha * (target - q[s, a])
        s, total = s2, total + r
    return total, info["captures"] > 0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--level", default="maze")
    parser.add_argument("--abstraction", default="grid")
    parser.add_argument("--guards", default="pf")
    parser.add_argument("--scenario", default="capture")
    parser.add_argument("--episodes", type=int, default=1500)
    parser.add_argument("--test-seeds", type=int, default=50)
    parser.add_argument("--seed", type=int, default=0, help="the learner's own generator")
    parser.add_argument("--out", default="docs/img/train-player-maze.png")
    args = parser.parse_args()

    # the reward it was tuned and measured with: the game's terms as they were then
    # (0.1 per second, 1 per HP, 10 per capture), no shaping
    env = StealthEnv(args.level, guards=args.guards, abstraction=args.abstraction,
                     scenario=args.scenario, rewards={"survival": 0.1, "hp": 1.0, "capture": 10.0,
                                                      "seen": 0.0, "proximity": 0.0})
    tab = Tabulator(env)
    q = np.zeros((tab.n_states, env.action_space.n))
    rng = np.random.default_rng(np.random.SeedSequence([args.seed, 1]))
    started = time.perf_counter()
    returns, captured = [], []
    for k in range(args.episodes):
        eps = max(0.05, 1.0 - k / (0.6 * args.episodes))
        r, c = episode(env, tab, q, 1000 + k, rng, eps, alpha=0.2, gamma=0.97, learn=True)
        returns.append(r)
        captured.append(c)
        if (k + 1) % 100 == 0:
            print(f"episode {k + 1}: capture rate of the last 100 {np.mean(captured[-100:]):.2f}, "
                  f"eps {eps:.2f}, {time.perf_counter() - started:.0f} s", flush=True)
    train_time = time.perf_counter() - started

    seeds = range(args.test_seeds)
    greedy = [episode(env, tab, q, s, rng, 0.0, 0, 0, learn=False)[1] for s in seeds]
    random_player = [episode(env, tab, q, s, rng, 1.0, 0, 0, learn=False)[1] for s in seeds]
    maxmin = [run_trial(TrialSpec(args.level, args.abstraction, args.guards, "maxmin",
                                  args.scenario, s))["metrics"]["captured"] for s in seeds]
    rates = {"random": float(np.mean(random_player)), "Q-learning": float(np.mean(greedy)),
             "MaxMin": float(np.mean(maxmin))}
    summary = {"level": args.level, "abstraction": args.abstraction, "guards": args.guards,
               "scenario": args.scenario, "episodes": args.episodes,
               "train_seconds": round(train_time, 1), "held_out_seeds": args.test_seeds,
               "capture_rate": rates,
               "states_visited": int((np.abs(q).sum(axis=1) > 0).sum())}
    print(json.dumps(summary, indent=2))

    import matplotlib  # noqa: PLC0415 — only for the figure

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # noqa: PLC0415

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 3.8), gridspec_kw={"width_ratios": [2, 1]})
    window = 100
    smooth = np.convolve(np.asarray(captured, float), np.ones(window) / window, mode="valid")
    ax1.plot(np.arange(window, len(captured) + 1), smooth, label="capture rate (last 100)")
    ax1.axhline(rates["MaxMin"], color="tab:green", ls="--", label="MaxMin, held-out seeds")
    ax1.set_xlabel("training episode")
    ax1.set_ylabel("capture rate")
    ax1.set_ylim(0, 1)
    ax1.legend(loc="upper right")
    ax1.set_title(f"Q-learning player, {args.level} / {args.abstraction} / {args.guards} guards")
    names = list(rates)
    ax2.bar(names, [rates[n] for n in names], color=["tab:gray", "tab:blue", "tab:green"])
    for x, n in enumerate(names):
        ax2.text(x, rates[n] + 0.02, f"{rates[n]:.2f}", ha="center")
    ax2.set_ylim(0, 1)
    ax2.set_title(f"capture rate, seeds 0–{args.test_seeds - 1}")
    fig.tight_layout()
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.out, dpi=110)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
