"""The simulated world (pymunk bodies, vision, attack, scenarios, metrics) and the front end.

The core here runs with no display and never imports pygame; only ``game.front`` does.
"""
