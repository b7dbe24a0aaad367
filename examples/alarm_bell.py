"""An alarm bell: rings from t = 5 s to t = 35 s, draws the guards and puts them on alert.

    stealth sim miami --stimulus examples/alarm_bell.py:AlarmBell
"""
from ai.stimuli import Stimulus


class AlarmBell(Stimulus):
    name = "alarm_bell"
    marker = True                    # drawn in the game; guards stepping on it raise "guard_on"
    position = (10.5, 23.5)          # where it hangs (world units; the nearest walkable node)
    amplitude, falloff = 6.0, 0.85   # a whole-map pull −6·0.85^d, stronger than a decoy's
    rings_from, rings_until = 5.0, 35.0
    alert = 0.9                      # w_I floor while it rings (the paper's w_I_max)

    def start(self, ctx):
        self.node = ctx.node_at(*self.position)
        self.pull = -self.amplitude * ctx.falloff(self.node, self.falloff)
        self.t = 0.0

    def on_tick(self, view, dt):
        self.t = view.t

    @property
    def ringing(self):
        return self.rings_from <= self.t < self.rings_until

    def inject(self, ctx):
        return self.pull if self.ringing else None

    @property
    def information_weight_floor(self):
        return self.alert if self.ringing else None

    @property
    def done(self):
        return self.t >= self.rings_until
