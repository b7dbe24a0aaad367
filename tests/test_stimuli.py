"""Stimuli and zones (SPEC §5): each mechanic's numbers, the hooks, the world's actions, plugins."""

from __future__ import annotations

import math
import subprocess
import sys
import textwrap

import numpy as np
import pytest

from ai import make_guard_ai
from ai.stimuli import (
    Corpse,
    FieldContext,
    Noise,
    Rain,
    StaticDecoy,
    Stimulus,
    StimulusError,
    StimulusParams,
    StimulusSet,
    Zone,
    apply_zones,
    load_stimulus,
    zone_view_scale,
    zones_from_config,
)
from ai.view import Event, GuardAI, WorldView
from game.action_params import ActionParams
from game.config import Config
from game.trace import trace_record
from game.trial import TrialSpec, make_world
from game.world import Refused, World
from navmesh.graph import NodeGraph
from navmesh.level import parse_level

# ---------------------------------------------------------------------------- fixtures


def corridor(n: int) -> NodeGraph:
    """1 × n cells: node k is k hops from node 0."""
    return NodeGraph.from_grid(np.ones((1, n), bool), 1.0)


def view(graph: NodeGraph, t: float, guards=(), events=(), active=None) -> WorldView:
    nodes = np.array(guards, dtype=np.int64)
    return WorldView(
        t=t, graph=graph, guard_nodes=nodes, guard_positions=graph.positions[nodes].reshape(-1, 2),
        guard_headings=np.zeros(len(nodes)), player_node=0, player_pos=graph.positions[0],
        events=tuple(events), guard_active=None if active is None else np.array(active, bool),
    )


class Hooks(GuardAI):
    """A stand-in guard AI hearing the stimuli, recording what the set assigns."""

    def __init__(self, n: int) -> None:
        super().__init__()
        self.extra_information = np.zeros(n)
        self.information_weight_floor = 0.0

    def reset(self, graph, rng, n_guards) -> None:
        pass

    def decide(self, i, view) -> int:
        return 0

    def hears_stimuli(self) -> bool:
        return True

    def set_extra_information(self, layer) -> None:
        self.extra_information = layer

    def set_information_weight_floor(self, floor) -> None:
        self.information_weight_floor = floor


class StayGuards(GuardAI):
    """Guards that never move."""

    mode = "stay"

    def reset(self, graph, rng, n_guards) -> None:
        pass

    def decide(self, i, view) -> int:
        return int(view.guard_nodes[i])


def room(**extra):
    """An open 9 × 9 room (cells 1..9) in a wall ring, with a wall block at row 5, cols 4..6."""
    grid = ["#" * 11] + ["#" + "." * 9 + "#" for _ in range(9)] + ["#" * 11]
    grid[5] = "#..." + "###" + "...#"
    data = {"format": "stealth-level/1", "name": "room", "grid": grid,
            "guards": [[1.5, 1.5]], **extra}
    return parse_level(data, "room.json")


def world(level, guard_ai=None, overrides=(), **kw) -> World:
    config = Config.load(["world.spawns=level", "world.player_hp=1000", *overrides])
    return World(level, "grid", guard_ai or StayGuards(), None, config=config,
                 scenario="fixed", seed=0, **kw)


def put(agent, w: World, xy) -> None:
    agent.place(xy)
    agent.node = w.graph.node_at(*xy)


def tick(w: World, ticks: int = 1) -> None:
    for _ in range(ticks * w.steps_per_tick):
        w.step()


# ---------------------------------------------------------------------------- footstep noise


def test_footstep_injection_spatial_factor_and_cutoff():
    graph = corridor(8)
    stimuli = StimulusSet(graph)
    stimuli.add(Noise(0, 3.0, 0.6, max_hops=5))
    expected = [-3.0, -1.8, -1.08, -0.648, -0.3888, -0.23328, 0.0, 0.0]
    np.testing.assert_allclose(stimuli.layer(), expected, atol=1e-12)


def test_footstep_decays_by_0_8_per_second_and_is_dropped_below_0_1():
    graph = corridor(8)
    stimuli = StimulusSet(graph)
    noise = stimuli.add(Noise(0, 3.0, 0.6))
    stimuli.tick(view(graph, 1.0), 1.0)
    assert noise.level == pytest.approx(2.4)
    np.testing.assert_allclose(stimuli.layer()[:2], [-2.4, -1.44])
    # 3·0.8^15 = 0.1056 stays, 3·0.8^16 = 0.0845 < 0.1 is dropped
    for k in range(2, 16):
        stimuli.tick(view(graph, float(k)), 1.0)
    assert stimuli.active == (noise,) and noise.level == pytest.approx(3 * 0.8**15)
    stimuli.tick(view(graph, 16.0), 1.0)
    assert stimuli.active == ()
    assert not stimuli.layer().any()


def test_decay_scales_with_tick_length():
    noise = Noise(0, 3.0, 0.6)
    noise.decay(0.5)
    noise.decay(0.5)
    assert noise.level == pytest.approx(2.4)


def test_sprint_event_makes_a_footstep_and_impulses_add_up():
    graph = corridor(8)
    stimuli = StimulusSet(graph)
    stimuli.tick(view(graph, 1.0, events=[Event("sprint", 0, 1.0)]), 1.0)
    stimuli.tick(view(graph, 2.0, events=[Event("sprint", 1, 2.0)]), 1.0)
    assert [s.name for s in stimuli.active] == ["footstep", "footstep"]
    layer = stimuli.layer()
    assert layer[0] == pytest.approx(-2.4 - 3.0 * 0.6)  # the older one decayed once
    assert layer[1] == pytest.approx(-2.4 * 0.6 - 3.0)


def test_rain_changes_new_footsteps_to_amplitude_1_5_and_falloff_0_7():
    graph = corridor(8)
    stimuli = StimulusSet(graph)
    rain_on = Event("weather", -1, 1.0, {"rain": True})
    stimuli.tick(view(graph, 1.0, events=[rain_on, Event("sprint", 0, 1.0)]), 1.0)
    (rain, step) = stimuli.active
    assert isinstance(rain, Rain) and step.level == pytest.approx(1.5)
    expected = [-1.5 * 0.7**d for d in range(6)] + [0.0, 0.0]
    np.testing.assert_allclose(stimuli.layer(), expected, atol=1e-12)
    # the rain stops: new footsteps are back to 3.0 / 0.6
    stimuli.tick(view(graph, 2.0, events=[Event("weather", -1, 2.0, {"rain": False})]), 1.0)
    assert not any(isinstance(s, Rain) for s in stimuli.active)
    stimuli.tick(view(graph, 3.0, events=[Event("sprint", 7, 3.0)]), 1.0)
    assert stimuli.active[-1].level == pytest.approx(3.0)
    assert stimuli.active[-1].inject(stimuli.ctx)[6] == pytest.approx(-1.8)


# ---------------------------------------------------------------------------- thrown decoy


def test_thrown_decoy_is_one_footstep_impulse_aged_from_the_landing_time():
    graph = corridor(8)
    stimuli = StimulusSet(graph)
    stimuli.tick(view(graph, 5.0, events=[Event("throw_landed", 3, 4.4)]), 1.0)
    (decoy,) = stimuli.active
    assert decoy.name == "thrown_decoy" and decoy.marker and decoy.node == 3
    assert decoy.level == pytest.approx(3.0 * 0.8**0.6)  # landed 0.6 s before the tick
    np.testing.assert_allclose(stimuli.layer()[[3, 4, 8 - 1]], [-decoy.level, -decoy.level * 0.6,
                                                               -decoy.level * 0.6**4])


# ---------------------------------------------------------------------------- static decoy


def test_static_decoy_covers_the_whole_map_and_does_not_decay():
    graph = corridor(12)
    stimuli = StimulusSet(graph)
    stimuli.tick(view(graph, 1.0, events=[Event("decoy_activated", 0, 1.0, {"decoy": 0})]), 1.0)
    expected = [-5.0 * 0.8**d for d in range(12)]
    np.testing.assert_allclose(stimuli.layer(), expected)
    assert stimuli.layer()[11] == pytest.approx(-0.4294967296)  # 11 hops: no cut-off
    for t in range(2, 30):
        stimuli.tick(view(graph, float(t), guards=[11]), 1.0)
    np.testing.assert_allclose(stimuli.layer(), expected)


def test_static_decoy_is_removed_after_a_guard_stood_on_it_for_3_s():
    graph = corridor(12)
    stimuli = StimulusSet(graph)
    decoy = stimuli.add(StaticDecoy(5, disarm_time=3.0, radius=1))
    stimuli.tick(view(graph, 1.0, guards=[7]), 1.0)  # 2 hops: not standing on it
    stimuli.tick(view(graph, 2.0, guards=[5]), 1.0)
    stimuli.tick(view(graph, 3.0, guards=[6]), 1.0)  # next to it counts
    assert decoy.presence.seconds == 2.0 and stimuli.active == (decoy,)
    stimuli.tick(view(graph, 4.0, guards=[5, 0], active=[False, True]), 1.0)  # a body does not
    assert stimuli.active == (decoy,)
    stimuli.tick(view(graph, 5.0, guards=[5]), 1.0)
    assert stimuli.active == ()


# ---------------------------------------------------------------------------- corpse


def test_corpse_layer_decays_0_95_per_second_with_0_7_per_hop():
    graph = corridor(10)
    stimuli = StimulusSet(graph)
    stimuli.tick(view(graph, 1.0, events=[Event("guard_down", 2, 1.0, {"guard": 0})]), 1.0)
    (corpse,) = stimuli.active
    assert isinstance(corpse, Corpse) and corpse.level == pytest.approx(4.0)
    np.testing.assert_allclose(stimuli.layer()[[2, 3, 5, 9]], [-4.0, -2.8, -4 * 0.343, -4 * 0.7**7])
    stimuli.tick(view(graph, 2.0), 1.0)
    stimuli.tick(view(graph, 3.0), 1.0)
    assert corpse.level == pytest.approx(4.0 * 0.95**2)
    np.testing.assert_allclose(stimuli.layer()[0], -4.0 * 0.95**2 * 0.49)


def test_corpse_removed_after_10_s_of_inspection_and_alerts_while_found():
    graph = corridor(10)
    hooks = Hooks(graph.n)
    stimuli = StimulusSet(graph, guard_ai=hooks)
    corpse = stimuli.add(Corpse(2, inspect_time=10.0, radius=1, alert=0.9))
    stimuli.tick(view(graph, 1.0, guards=[9]), 1.0)
    assert corpse.information_weight_floor is None and hooks.information_weight_floor == 0.0
    assert hooks.extra_information[2] == pytest.approx(-4.0 * 0.95)
    for t in range(2, 8):  # 6 s next to it
        stimuli.tick(view(graph, float(t), guards=[3]), 1.0)
    assert hooks.information_weight_floor == 0.9
    for t in range(8, 12):  # 4 s away: the count pauses, the team stays alert
        stimuli.tick(view(graph, float(t), guards=[9]), 1.0)
    assert corpse.presence.seconds == 6.0 and hooks.information_weight_floor == 0.9
    for t in range(12, 16):
        stimuli.tick(view(graph, float(t), guards=[1]), 1.0)
    assert stimuli.active == ()
    assert hooks.information_weight_floor == 0.0
    assert not hooks.extra_information.any()


# ---------------------------------------------------------------------------- hooks


def test_pf_guards_read_the_layer_and_the_weight_floor():
    graph = corridor(9)
    guards = make_guard_ai("pf")
    guards.reset(graph, np.random.default_rng(0), 1)
    stimuli = StimulusSet(graph, guard_ai=guards)

    class Alarm(Stimulus):
        information_weight_floor = 0.9

        def inject(self, ctx):
            return -6.0 * ctx.falloff(8, 0.85)

    alarm = stimuli.add(Alarm())
    stimuli.refresh()
    assert guards.field.w_I == 0.9
    assert guards.fields()["I_extra"][8] == pytest.approx(-6.0)
    v = view(graph, 0.0, guards=[4])
    assert guards.decide(0, v) == 5  # towards the alarm
    guards.tick(v, 1.0)
    assert guards.field.w_I == 0.9  # the floor holds against eq. 8's decay
    alarm.done = True
    stimuli.tick(view(graph, 1.0, guards=[4]), 1.0)
    assert guards.information_weight_floor == 0.0
    guards.tick(v, 1.0)
    assert guards.field.w_I == pytest.approx(0.85)  # decays again at 0.05 per second


def test_fsm_guards_investigate_a_footstep_heard_at_their_node():
    graph = corridor(9)
    guards = make_guard_ai("fsm")
    guards.reset(graph, np.random.default_rng(0), 1)
    stimuli = StimulusSet(graph, guard_ai=guards)
    v = view(graph, 1.0, guards=[2], events=[Event("sprint", 0, 1.0)])
    stimuli.tick(v, 1.0)  # 3·0.6^2 = 1.08 ≥ info_threshold 1 at the guard's node
    guards.tick(v, 1.0)
    assert guards.state_name(0) == "investigate" and guards.guards[0].spot == 0


def test_modes_without_hooks_are_left_alone():
    graph = corridor(5)
    guards = make_guard_ai("random")
    guards.reset(graph, np.random.default_rng(0), 1)
    stimuli = StimulusSet(graph, guard_ai=guards)
    stimuli.tick(view(graph, 1.0, events=[Event("sprint", 0, 1.0)]), 1.0)
    assert len(stimuli) == 1 and not guards.hears_stimuli() and guards.fields() == {}


def test_a_layer_of_the_wrong_shape_is_a_clear_error():
    graph = corridor(5)

    class Bad(Stimulus):
        name = "bad"

        def inject(self, ctx):
            return np.zeros(3)

    stimuli = StimulusSet(graph, guard_ai=Hooks(5))
    stimuli.add(Bad())
    with pytest.raises(ValueError, match="'bad'.*shape"):
        stimuli.refresh()


def test_registry_register_and_disable():
    graph = corridor(5)
    stimuli = StimulusSet(graph)
    stimuli.disable("guard_down")
    stimuli.register("bell", lambda e, ctx: Noise(e.node, 1.0, 0.5, name="bell"))
    stimuli.tick(view(graph, 1.0, events=[Event("guard_down", 1, 1.0), Event("bell", 2, 1.0)]), 1.0)
    assert [s.name for s in stimuli.active] == ["bell"]


def test_falloff_helper():
    ctx = FieldContext(corridor(6))
    np.testing.assert_allclose(ctx.falloff(2, 0.5, max_hops=2), [0.25, 0.5, 1, 0.5, 0.25, 0])
    np.testing.assert_allclose(ctx.falloff(0, 0.5), 0.5 ** np.arange(6))


def test_parameters_default_to_the_paper_and_validate():
    p = StimulusParams.from_mapping(ActionParams.split(Config.load().section("stimuli"))[1])
    assert (p.noise_amplitude, p.noise_falloff, p.noise_max_hops, p.noise_decay,
            p.noise_threshold) == (3.0, 0.6, 5, 0.8, 0.1)
    assert (p.decoy_amplitude, p.decoy_falloff, p.decoy_disarm_time) == (5.0, 0.8, 3.0)
    assert (p.corpse_amplitude, p.corpse_decay, p.corpse_falloff, p.corpse_inspect_time) == (
        4.0, 0.95, 0.7, 10.0)
    actions = ActionParams.split(Config.load().section("stimuli"))[0]
    assert (actions.throw_cooldown, actions.throw_radius) == (10.0, 4)
    assert 3.0 * p.rain_amplitude_scale == 1.5 and p.rain_falloff == 0.7
    with pytest.raises(ValueError, match="noise_falloff"):
        StimulusParams.from_mapping({"noise_falloff": 1.5})


# ---------------------------------------------------------------------------- zones


def test_zones_from_config_and_their_effects():
    zones = zones_from_config(Config.load().section("zones"))
    assert zones["dark"] == Zone("dark", 0.80, 1.0)
    assert zones["concealment"] == Zone("concealment", 0.80, 0.7)
    graph = corridor(6)
    masks = {"dark": np.array([1, 1, 0, 0, 0, 0], bool),
             "concealment": np.array([0, 1, 1, 0, 0, 0], bool)}
    np.testing.assert_allclose(zone_view_scale(zones, masks, 6), [1, 0.7, 0.7, 1, 1, 1])
    guards = make_guard_ai("pf")
    guards.reset(graph, np.random.default_rng(0), 1)
    apply_zones(guards, {"dark": Zone("dark", 0.8), "concealment": Zone("concealment", 0.9)},
                masks)
    # overlap (node 1): the faster decay wins
    np.testing.assert_allclose(guards.field.confidence_decay, [0.8, 0.8, 0.9, 0.95, 0.95, 0.95])
    apply_zones(make_guard_ai("random"), zones, masks)  # no hook: nothing to do, no error


def test_dark_zone_decay_is_applied_by_the_world():
    level = room(zones={"dark": [[[1, 1], [4, 1], [4, 4], [1, 4]]]})
    w = world(level, make_guard_ai("pf"))
    dark = w.zones["dark"]
    assert dark.sum() == 9
    np.testing.assert_allclose(w.guard_ai.field.confidence_decay[dark], 0.80)
    np.testing.assert_allclose(w.guard_ai.field.confidence_decay[~dark], 0.95)
    # one tick: C decays at 0.80 in the dark cells, 0.95 elsewhere
    tick(w)
    before = w.guard_ai.field.confidence.copy()
    tick(w)
    deposit = w.guard_ai.field.matrices.deposit([g.node for g in w.guards])
    expected = np.where(dark, 0.80, 0.95) * before + deposit
    np.testing.assert_allclose(w.guard_ai.field.confidence, expected)
    w2 = world(level, make_guard_ai("pf"), ["zones.dark_confidence_decay=0.5"])
    np.testing.assert_allclose(w2.guard_ai.field.confidence_decay[dark], 0.5)


# ---------------------------------------------------------------------------- world actions


def test_a_sprint_makes_footsteps_at_the_player_and_standing_still_does_not():
    w = world(room())
    put(w.player, w, (8.5, 8.5))
    w.sprinting = True
    tick(w)  # standing still
    assert not [e for e in w.tick_events if e.kind == "sprint"] and len(w.stimuli) == 0
    w.player_input = (-1.0, 0.0)
    tick(w)
    (event,) = [e for e in w.tick_events if e.kind == "sprint"]
    assert event.node == w.player.node and event.t == pytest.approx(2.0)
    (step,) = w.stimuli.active
    assert step.name == "footstep" and step.node == w.player.node and step.level == 3.0
    tick(w, 2)
    assert [s.name for s in w.stimuli.active] == ["footstep"] * 3
    w.sprinting = False
    tick(w)
    assert len(w.stimuli) == 3  # no new ones; the old ones decay


def test_rain_toggle_changes_the_footstep_parameters():
    w = world(room())
    assert w.raining is False and w.toggle_rain() == "on" and w.raining
    put(w.player, w, (8.5, 8.5))
    w.sprinting, w.player_input = True, (-1.0, 0.0)
    tick(w)
    steps = [s for s in w.stimuli.active if s.name == "footstep"]
    assert steps[0].level == 1.5 and steps[0].falloff == 0.7
    assert w.toggle_rain() == "off"
    tick(w)
    assert [s.level for s in w.stimuli.active if s.name == "footstep"][-1] == 3.0
    assert world(room(), overrides=["stimuli.raining=true"]).raining
    w.toggle_rain(), w.toggle_rain(), w.toggle_rain()  # off-on-off-on within one tick: on
    tick(w)
    assert w.raining and [s.name for s in w.stimuli.active].count("rain") == 1


def manhattan_cells(a, b) -> int:
    return abs(math.floor(a[0]) - math.floor(b[0])) + abs(math.floor(a[1]) - math.floor(b[1]))


def test_a_throw_lands_within_radius_4_never_in_a_wall_with_a_10_s_cooldown():
    w = world(room())
    put(w.player, w, (2.5, 2.5))
    assert w.throw_decoy(4.5, 3.5) is True  # valid: lands where aimed
    tick(w)
    (landed,) = w.stimuli.active
    assert landed.name == "thrown_decoy" and landed.node == w.graph.node_at(4.5, 3.5)
    assert w.stimulus_points().tolist() == [[4.5, 3.5]]
    refused = w.throw_decoy(3.5, 3.5)
    assert isinstance(refused, Refused) and not refused and "cooldown" in refused
    tick(w, 8)
    assert not w.throw_decoy(3.5, 3.5)  # 9 s after the throw
    tick(w)
    # too far: clamped to the nearest node within 4 cells (Manhattan) of the player's cell
    for target in [(9.5, 9.5), (5.5, 5.5), (0.2, 0.2), (-30.0, 4.0)]:
        w.next_throw = 0.0
        node = w.landing_node(*target)
        landed_at = tuple(w.graph.positions[node])
        assert manhattan_cells(landed_at, w.player.pos) <= 4
        assert w.level.occupancy[math.floor(landed_at[1]), math.floor(landed_at[0])]
    assert tuple(w.graph.positions[w.landing_node(5.5, 5.5)]) != (5.5, 5.5)  # (5, 5) is wall
    assert tuple(w.graph.positions[w.landing_node(9.5, 9.5)]) in {(6.5, 2.5), (5.5, 3.5),
                                                                  (4.5, 4.5), (3.5, 5.5),
                                                                  (2.5, 6.5)}
    assert w.throw_decoy(9.5, 9.5) is True


def test_decoy_activation_reach_and_removal_after_3_s_of_a_guard_on_it():
    level = room(decoys=[[7.5, 7.5]], guards=[[7.5, 7.5]])
    w = world(level)
    put(w.player, w, (2.5, 2.5))
    assert not w.activate_decoy()  # out of reach
    put(w.player, w, (8.5, 7.5))
    assert w.activate_decoy() is True
    assert w.activate_decoy() == "the decoy is already on"
    tick(w)
    (decoy,) = w.stimuli.active
    assert isinstance(decoy, StaticDecoy) and decoy.node == w.graph.node_at(7.5, 7.5)
    tick(w)
    assert len(w.stimuli) == 1
    tick(w)  # the guard has stood on it at three ticks
    assert len(w.stimuli) == 0
    assert w.activate_decoy() is True  # can be switched on again


def test_guard_on_event_when_a_guard_steps_onto_a_decoy():
    class Walk(GuardAI):
        def reset(self, graph, rng, n_guards):
            self.graph = graph

        def decide(self, i, view):
            return self.graph.node_at(7.5, 7.5)

    level = room(decoys=[[7.5, 7.5]], guards=[[1.5, 7.5]])
    w = world(level, Walk())
    put(w.player, w, (8.5, 7.5))
    w.guards[0].waypoints.clear()
    w.activate_decoy()
    seen = []
    for _ in range(4 * w.steps_per_tick):
        w.step()
        seen += [e for e in w.tick_events if e.kind == "guard_on" and e not in seen]
    assert seen and seen[0].node == w.graph.node_at(7.5, 7.5) and seen[0].data["guard"] == 0


def test_take_down_from_behind_makes_a_corpse():
    level = room(guards=[[5.5, 2.5]])
    w = world(level)
    guard = w.guards[0]
    guard.heading = 0.0  # facing +x
    put(w.player, w, (6.3, 2.5))  # in front, 0.8 away: it sees you coming
    assert not w.take_down()
    put(w.player, w, (7.5, 2.5))  # behind? no: in front and too far
    assert w.take_down() == "no guard within reach from behind"
    put(w.player, w, (4.7, 2.5))  # behind, 0.8 away
    assert w.take_down() is True
    assert guard.active is False
    assert not w.take_down()  # nobody left
    tick(w)
    (corpse,) = w.stimuli.active
    assert isinstance(corpse, Corpse) and corpse.node == guard.node and corpse.guard == 0
    assert w.stimulus_points().tolist() == [list(w.graph.positions[guard.node])]
    assert [e.kind for e in w.tick_events] == ["guard_down"]
    assert 0 not in w.seen_by
    with pytest.raises(ValueError):
        w.down_guard(0)


def test_trace_lists_active_stimuli():
    w = world(room())
    w.down_guard(0)
    tick(w)
    record = trace_record(w)
    assert record["stimuli"][0]["name"] == "corpse"
    assert "stimuli" not in trace_record(world(room()))


# ---------------------------------------------------------------------------- plugins


PLUGIN = textwrap.dedent("""
    from ai.stimuli import Noise, Stimulus

    class Beacon(Stimulus):
        name = "beacon"
        def start(self, ctx):
            self.node = 0
            self.layer = -2.0 * ctx.falloff(0, 0.5)
        def inject(self, ctx):
            return self.layer

    def make_noise():
        return Noise(0, 1.0, 0.5)

    def not_a_stimulus():
        return 42

    class Plain:
        pass

    VALUE = 3
""")


def test_load_stimulus_from_a_file(tmp_path):
    path = tmp_path / "plugin.py"
    path.write_text(PLUGIN)
    beacon = load_stimulus(f"{path}:Beacon")
    assert issubclass(beacon, Stimulus)
    assert isinstance(load_stimulus(f"{path}:make_noise")(), Noise)
    for name, message in [("Nope", "defines no 'Nope'"), ("Plain", "not a subclass"),
                          ("VALUE", "not a Stimulus subclass or a factory"),
                          ("not_a_stimulus", "returned int")]:
        with pytest.raises(StimulusError, match=message):
            load_stimulus(f"{path}:{name}")
    with pytest.raises(StimulusError, match="no such file"):
        load_stimulus(f"{tmp_path}/missing.py:Beacon")
    broken = tmp_path / "broken.py"
    broken.write_text("def (:\n")
    with pytest.raises(StimulusError, match="SyntaxError"):
        load_stimulus(f"{broken}:X")
    with pytest.raises(StimulusError, match="entry point"):
        load_stimulus("no-such-installed-stimulus")


def test_trial_spec_stimuli_reach_the_world_and_the_key(tmp_path):
    path = tmp_path / "plugin.py"
    path.write_text(PLUGIN)
    plain = TrialSpec("maze", seed=1)
    assert "stimuli" not in plain.key
    spec = TrialSpec("maze", seed=1, stimuli=(f"{path}:Beacon",))
    assert spec.key.startswith(plain.key) and spec.key.endswith(f"stimuli={path}:Beacon")
    w = make_world(spec)
    assert [s.name for s in w.stimuli.active] == ["beacon"]
    assert w.guard_ai.extra_information[0] == -2.0


def test_cli_stimulus_errors_are_one_line_exit_2(tmp_path):
    path = tmp_path / "plugin.py"
    path.write_text(PLUGIN)
    result = subprocess.run(
        [sys.executable, "-m", "headless.cli", "sim", "maze", "--stimulus", f"{path}:Plain"],
        capture_output=True, text=True, check=False,
    )
    assert result.returncode == 2
    assert result.stderr.strip().count("\n") == 0 and "not a subclass" in result.stderr
