"""Alarm zones: a player who steps into an ``alarm`` zone trips a bell that calls the guards.

The plugin declares the zone kind ``alarm`` (``zone_kinds``), so once it is loaded a JSON or
Tiled level may draw ``alarm`` zones (``examples/alarm_maze.tmj`` does); what such a zone
does is this stimulus: while the bell rings (20 s after the player tripped it) every guard
is drawn towards the spot (−6·0.85^d over the whole map) and on alert (w_I ≥ 0.9). Leaving
and re-entering an alarm zone while it rings does not restart it; after it stops, the next
step into a zone trips it again.

    stealth sim examples/alarm_maze.tmj --stimulus examples/tripwire.py:Tripwire
    stealth play examples/alarm_maze.tmj --stimulus examples/tripwire.py:Tripwire
    stealth mechanics --level examples/alarm_maze.tmj --stimulus examples/tripwire.py:Tripwire
"""
import numpy as np

from ai.stimuli import Measure, Stimulus


class Tripwire(Stimulus):
    name = "tripwire"
    zone_kinds = ("alarm",)          # levels may now draw "alarm" zones
    marker = True                    # the game draws the bell where it was tripped
    amplitude, falloff = 6.0, 0.85   # the bell's whole-map pull, −6·0.85^d
    ring_seconds = 20.0
    alert = 0.9                      # w_I floor while it rings (the paper's w_I_max)
    # stealth mechanics: the bell should get the player seen sooner and caught more often
    measure = Measure(metrics=(("first_detect_time", -1), ("captured", +1),
                               ("capture_time", -1)))

    def start(self, ctx):
        wired = ctx.zones.get("alarm")  # None on a level parsed without alarm zones
        self.wired = np.zeros(ctx.n, bool) if wired is None else np.asarray(wired, bool)
        self.ctx, self.pull, self.until, self.t = ctx, None, -1.0, 0.0

    def on_tick(self, view, dt):
        self.t = view.t
        if self.ringing:
            return
        self.node = -1  # silent: nothing to draw
        if self.wired[view.player_node]:
            self.node = int(view.player_node)
            self.pull = -self.amplitude * self.ctx.falloff(self.node, self.falloff)
            self.until = view.t + self.ring_seconds

    @property
    def ringing(self):
        return self.t < self.until

    def inject(self, ctx):
        return self.pull if self.ringing else None

    @property
    def information_weight_floor(self):
        return self.alert if self.ringing else None
