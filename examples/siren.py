"""A siren: a whole-map pull towards one point, as loud as config section [siren] says.

    stealth sim miami --stimulus examples/siren.py:Siren --set siren.amplitude=2
"""
from dataclasses import dataclass

from ai.bounds import NON_NEGATIVE, UNIT
from ai.params import Params
from ai.stimuli import Stimulus


@dataclass(frozen=True)
class SirenParams(Params):
    amplitude: float = 6.0           # the keys siren.amplitude and siren.falloff,
    falloff: float = 0.85            # these their defaults
    bounds = {"amplitude": NON_NEGATIVE, "falloff": UNIT}


class Siren(Stimulus):
    name, display, short = "siren", "Siren", "S"
    parameters = SirenParams         # config section [siren]: section defaults to the name
    position = (10.5, 23.5)

    def start(self, ctx):
        p = ctx.params_of(self)      # a SirenParams with this trial's values
        self.node = ctx.node_at(*self.position)
        self.pull = -p.amplitude * ctx.falloff(self.node, p.falloff)

    def inject(self, ctx):
        return self.pull
