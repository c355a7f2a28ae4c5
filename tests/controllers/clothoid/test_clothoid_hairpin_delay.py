"""The loaded truck at a hairpin with a known delay (issue 18): the lookahead follows a falling floor, and a geometric
ceiling keeps the target within 60 deg of the path's turn.

With known_delay_s = 0.11 s (the automotive preset) compensated on the arc of kappa(0) (the delay left in the loop) the
truck's lookahead floor is 22 m at 30 km/h and 10.5 m at 20 km/h; compensated by the lags' model it is 9 m and 6.5 m
(the delay-free loop's 8.5 and 5.5 m, raised where the loop keeps half its margins over +-50 ms of the delay). Braking
into Zandvoort's hairpin (R 11.4 m) the floor fell within 10 m but the lookahead, shrinking at the search's 0.5 m per
metre, reached the apex at 16.7 m: the tractor's rear-axle sideslip, built up while braking, relaxes there as braking
turns into accelerating (0.077 -> 0.044 rad in 4 m, in ideal runs too), a heading step that the clothoid law corrects
over a distance that grows with the lookahead (max |CTE| 0.2 / 0.3 / 0.39 / 0.65 m with the lookahead fixed at 10.5 / 13
/ 16 / 22 m). The floor now takes the lookahead down with it at once (with a band hysteresis against speed noise).
Separately, a lateral offset shows at a target theta round a bend only as offset x cos(theta), so Eq. 3's gain on it
falls alike: the ceiling (max_target_turn_deg) bounds the search's range there, never below the floor."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from lookahead_follower import LookaheadFilter

from controllers.base import Measurement
from controllers.clothoid import ClothoidConfig
from controllers.clothoid.controller import FLOOR_SPEED_STEP_KMH
from controllers.clothoid.lookahead import turn_limited_lookahead
from controllers.clothoid.loop_analysis import MAX_CURVATURE_LOOKAHEAD, clothoid_law_gains, loop_margins
from tuning.own_tuning import tuned_controller
from workbench.base.clothoid_chain import ClothoidChain
from workbench.base.errors import WorkbenchInputError
from workbench.base.path import ReferencePath
from workbench.simulation.conditions import load_conditions
from workbench.simulation.scenarios import Scenario
from workbench.simulation.simulator import Simulation, SimulationConfig
from workbench.vehicles import make_vehicle

PERIOD = 0.02
#: A loop and an open path with a bend, for the ceiling's chord-bound check.
OPEN_BEND = ClothoidChain().straight(30.0).clothoid_to(1 / 15, 10.0).arc(40.0).to_path("open bend")
LOOP_BEND = ClothoidChain().straight(30.0).clothoid_to(1 / 15, 10.0).arc(40.0).clothoid_to(0.0, 10.0).straight(20.0)
LOOP_BEND = LOOP_BEND.to_path("bend")
TRUCK = make_vehicle("tractor-semitrailer")
#: A hairpin like Zandvoort's (radius 11.4 m, about 100 deg of turn): 12 m clothoids either side of a 7.5 m arc.
HAIRPIN_RADIUS_M = 11.4
HAIRPIN = (
    ClothoidChain()
    .straight(80.0)
    .clothoid_to(-1 / HAIRPIN_RADIUS_M, 12.0)
    .arc(7.5)
    .clothoid_to(0.0, 12.0)
    .straight(60.0)
    .to_path("hairpin")
)


def _circle(radius_m: float) -> ReferencePath:
    """A closed circle, counter-clockwise, its seam at angle 0."""
    angle = np.linspace(0.0, 2.0 * math.pi, 240, endpoint=False)
    return ReferencePath.from_xy(radius_m * np.cos(angle), radius_m * np.sin(angle), closed=True, name="circle")


@pytest.mark.parametrize("lookahead_m", [8.0, 12.0, 16.0])
@pytest.mark.parametrize("turn_product", [0.2, 0.6, 1.0, 1.2, 1.4, 1.6])
def test_the_offset_gain_falls_with_the_cosine_of_the_turn_to_the_target(
    lookahead_m: float, turn_product: float
) -> None:
    """Eq. 3 linearised on an arc of curvature kappa (`clothoid_law_gains`): its gain on the lateral offset, relative
    to a straight's -6 / L^3, is cos(theta) within 0.07, theta = 2 asin(L kappa / 2) the arc's turn to the target
    (a vehicle offset by y drives a circle shifted by y, which crosses the path's normal at the target at y
    cos(theta)); it depends on L kappa only. About 0.46 at 60 deg (the ceiling: L = R), none at 90 deg, reversed
    beyond."""
    kappa = turn_product / lookahead_m
    theta = 2.0 * math.asin(turn_product / 2.0)
    ratio = clothoid_law_gains(lookahead_m, kappa)[0] / (-6.0 / lookahead_m**3)
    assert ratio == pytest.approx(math.cos(theta), abs=0.07)
    if turn_product == 1.0:  # theta = 60 deg
        assert 0.4 < ratio < 0.5
    if turn_product == 1.6:  # theta = 106 deg: an offset now steers the wrong way
        assert ratio < -0.15


@pytest.mark.parametrize(
    ("turn_deg", "chord"), [(60.0, 1.0), (90.0, math.sqrt(2.0)), (30.0, 2.0 * math.sin(math.pi / 12))]
)
@pytest.mark.parametrize("start_angle", [0.5, 2.0 * math.pi - 0.2])
def test_the_ceiling_on_a_circle_is_the_chord_of_the_turn(turn_deg: float, chord: float, start_angle: float) -> None:
    """On a circle of radius R, from a point on it, the ceiling for a turn theta is the chord 2 R sin(theta / 2)
    (R at 60 deg), within 0.1 m (the path's 0.1 m samples), also across a closed path's seam (start at -0.2 rad)."""
    radius = 20.0
    path = _circle(radius)
    s = start_angle * radius
    x, y = path.position(s)
    compiled = path.compiled()
    ceiling = turn_limited_lookahead(
        compiled.table, compiled.record, s / path.spacing_m, float(x), float(y), math.radians(turn_deg), 100.0
    )
    assert ceiling == pytest.approx(chord * radius, abs=0.1)


def test_the_ceiling_is_the_most_on_a_straight_and_past_an_open_end() -> None:
    """No turn within reach: max_m, on a straight and beyond an open path's end (its straight extension)."""
    path = ClothoidChain().straight(30.0).to_path("straight")
    x, y = path.position(25.0)
    compiled = path.compiled()
    args = (compiled.table, compiled.record, 25.0 / path.spacing_m, float(x), float(y), math.pi / 3)
    assert turn_limited_lookahead(*args, 40.0) == 40.0
    assert turn_limited_lookahead(*args, 3.0) == 3.0


@settings(max_examples=60, deadline=None)
@given(
    s=st.floats(0.0, 90.0),
    offset=st.floats(-3.0, 3.0),
    turn_deg=st.floats(5.0, 180.0),
    max_m=st.floats(0.5, 60.0),
)
def test_the_ceiling_measures_only_where_it_must_and_finds_the_same(
    s: float, offset: float, turn_deg: float, max_m: float
) -> None:
    """turn_limited_lookahead with the path's longest chord gives the ceiling measured at every sample, bit for bit."""
    heading = float(LOOP_BEND.heading(s))
    x, y = LOOP_BEND.position(s)
    px, py = float(x) - offset * math.sin(heading), float(y) + offset * math.cos(heading)
    for path in (LOOP_BEND, OPEN_BEND):
        turn = math.radians(turn_deg)
        compiled = path.compiled()
        unbounded = compiled.record.copy()
        unbounded["max_segment"] = math.inf  # no bound known: every sample measured
        args = (s / path.spacing_m, px, py, turn, max_m)
        assert turn_limited_lookahead(compiled.table, compiled.record, *args) == turn_limited_lookahead(
            compiled.table, unbounded, *args
        )


def test_a_falling_floor_takes_the_lookahead_down_keeping_its_excess() -> None:
    """The floor is applied at once both ways: the lookahead falls with it by as much (22 -> 10.5 m: braking into
    the hairpin), keeping its excess over it (25 m over a 22 m floor -> 13.5 m); the search's own choices are still
    followed at the rate limits (0.5 m/m shorter: 0.1 m in a 0.2 m step)."""
    f = LookaheadFilter(ClothoidConfig())
    assert f.step(22.0, 22.0, 40.0, 0.2) == 22.0
    assert f.step(10.5, 10.5, 40.0, 0.2) == 10.5
    f.reset()
    f.step(25.0, 22.0, 40.0, 0.2)
    assert f.step(25.0, 10.5, 40.0, 0.2) == pytest.approx(13.5 + 0.3 * 0.2)  # 13.5, then towards 25 at 0.3 m/m
    assert f.step(12.0, 10.5, 40.0, 0.2) == pytest.approx(13.56 - 0.5 * 0.2)  # the search's 12 m at 0.5 m/m


def _floor_at(controller, path: ReferencePath, speeds_kmh: list[float]) -> list[float]:
    """The controller's floor diagnostic stepping on the straight's centre line at these speeds, one step each."""
    out = []
    for k, kmh in enumerate(speeds_kmh):
        s = 5.0 + 0.2 * k
        x, y = path.position(s)
        m = Measurement(PERIOD * k, float(x), float(y), kmh / 3.6, 0.0, float(path.heading(s)), 0.0, 0.0)
        controller.step(m, path)
        out.append(controller.diagnostics["lookahead_floor_m"])
    return out


def test_the_floor_is_linear_in_the_speed_between_its_nodes() -> None:
    """Speed nodes 2.5 km/h apart: at a node its floor, between two the line between theirs, as the step reads it
    (its diagnostic) and as `lookahead_floor_m` says; the same speed the same floor, whichever way the speed came (no
    band held: a floor continuous in the speed moves the loop gain with it, not in steps)."""
    controller = tuned_controller("clothoid", TRUCK, ClothoidConfig(known_delay_s=0.11))
    path = ClothoidChain().straight(200.0).to_path("straight")
    controller.reset(path, PERIOD)
    speeds = [30.0, 27.0, 26.0, 22.6, 22.4, 21.6, 21.4, 22.4, 22.6, 22.4, 20.0]
    floors = _floor_at(controller, path, speeds)
    for kmh, floor in zip(speeds, floors, strict=True):
        low = math.floor(kmh / FLOOR_SPEED_STEP_KMH + 1e-9)
        weight = kmh / FLOOR_SPEED_STEP_KMH - low
        below, above = controller._node_floor_m(low), controller._node_floor_m(low + 1)
        assert floor == pytest.approx(below + weight * (above - below), abs=1e-9), kmh
        assert floor == pytest.approx(controller.lookahead_floor_m(kmh / 3.6), abs=1e-12), kmh
    assert floors[4] == floors[7] == floors[9] and floors[3] == floors[8]
    assert floors[-1] < floors[5] < floors[3] < floors[2] < floors[0]  # rising with the speed: 5.5 m to 8.5 m
    assert len(set(floors)) == 8  # not stepped per band: 21.4, 21.6, 22.4 and 22.6 km/h each their own


def _worst_margins(controller, speed_kmh: float, floor_m: float) -> tuple[float, float]:
    """(phase margin deg, gain margin dB): the least of the loop at this speed (its lags, the lead filter the step
    uses there, one per whole km/h) with this lookahead, about the straight and the floor's arc."""
    v = speed_kmh / 3.6
    settings = controller.loop_settings(float(round(speed_kmh)))
    lags = controller.plant_lags(speed_kmh)
    found = [
        loop_margins(lags, settings, v, floor_m, kr)
        for kr in (0.0, controller._floor_arc_1pm(v))
        if abs(kr) * floor_m < MAX_CURVATURE_LOOKAHEAD
    ]
    return min(m.phase_margin_deg for m in found), min(m.gain_margin_db for m in found)


@pytest.mark.parametrize("vehicle_name", ["tractor-semitrailer", "dynamic-bicycle"])
def test_the_floor_keeps_the_margins_at_the_speed_driven(vehicle_name: str) -> None:
    """At every quarter km/h from 15 to 35 km/h the floor keeps 45 deg and 6 dB at the speed driven: at its nodes
    exactly, between them within 3 deg and 1 dB (a node's floor is searched on a 0.5 m grid, and beside an
    identified speed the lags change form: measured 43.1 deg and 5.55 dB at worst, the truck at 19.75 km/h and the
    car at 33.25 km/h); a 5 km/h band's floor held from its centre to its edge loses 7 deg (the truck at 22.4 km/h
    on the 20 km/h floor, 5.5 m: 37.4 deg, 4.3 dB)."""
    controller = tuned_controller("clothoid", make_vehicle(vehicle_name))
    controller.reset(ReferencePath.from_xy(np.linspace(0.0, 100.0, 11), np.zeros(11), name="straight"), PERIOD)
    for kmh in np.arange(15.0, 35.0 + 1e-9, 0.25):
        phase, gain = _worst_margins(controller, kmh, controller.lookahead_floor_m(kmh / 3.6))
        assert phase >= 42.0 and gain >= 5.0, kmh
        if kmh / FLOOR_SPEED_STEP_KMH == round(kmh / FLOOR_SPEED_STEP_KMH):  # a node: the floor searched there
            assert phase >= 45.0 - 1e-9 and gain >= 6.0 - 1e-9, kmh
    if vehicle_name == "tractor-semitrailer":
        phase, gain = _worst_margins(controller, 22.4, controller.lookahead_floor_m(20.0 / 3.6))
        assert phase < 38.0 and gain < 4.5


def test_the_ceiling_acts_only_where_the_path_turns_more_than_it_allows(weaving) -> None:
    """On a 30 m bend no target within the 20 m range lies 60 deg round it: the ceiling changes nothing, bit for bit.
    On a 12 m arc driven at 6 m/s the lookahead keeps within the chord of 60 deg, R (+0.3 m: the start pose is
    predicted 0.2 s ahead, off the foot point), and never below the floor."""
    car = make_vehicle("dynamic-bicycle")
    with_ceiling = tuned_controller("clothoid", car)
    without = tuned_controller("clothoid", car, ClothoidConfig(max_target_turn_deg=0.0))
    bend = ClothoidChain().straight(20.0).clothoid_to(1 / 30, 15.0).arc(30.0).clothoid_to(0.0, 15.0).to_path("bend")
    measurements = weaving(bend, 80, 7, 30.0)  # along the 30 m arc: targets up to 38 deg round it
    with_ceiling.reset(bend, PERIOD)
    without.reset(bend, PERIOD)
    for m in measurements:
        assert with_ceiling.step(m, bend) == without.step(m, bend)

    radius = 12.0
    arc = ClothoidChain().straight(10.0).clothoid_to(1 / radius, 6.0).arc(60.0).to_path("arc")
    with_ceiling.reset(arc, PERIOD)
    for k in range(100):
        s = 20.0 + 6.0 * PERIOD * k
        x, y = arc.position(s)
        heading = float(arc.heading(s))
        with_ceiling.step(Measurement(PERIOD * k, float(x), float(y), 6.0, 0.0, heading, 6.0 / radius, 0.0), arc)
        d = with_ceiling.diagnostics
        assert d["lookahead_floor_m"] <= d["lookahead_m"] <= max(d["lookahead_floor_m"], radius + 0.3)
    assert d["lookahead_ceiling_m"] == pytest.approx(radius, abs=0.3)


@pytest.mark.parametrize("value", [-1.0, 181.0, math.nan])
def test_the_turn_limit_is_checked(value: float) -> None:
    with pytest.raises(WorkbenchInputError, match="max_target_turn_deg"):
        ClothoidConfig(max_target_turn_deg=value)


@pytest.mark.parametrize(("compensation", "max_cte_m"), [("model", 0.15), ("arc", 0.43)])
def test_the_loaded_truck_keeps_to_a_hairpin_with_the_automotive_delay(compensation: str, max_cte_m: float) -> None:
    """Loaded truck, automotive conditions (pose 10 ms late, steering 0.1 s dead time), known_delay_s = 0.11, 30 km/h
    planned (5.75 m/s at the apex, the profile's 0.3 g), no limit cycle; at the apex the lookahead is within 1 m of
    the floor (0.47 m compensated by the model, 0.42 m on the arc). Compensated by the lags' model
    (`delay_predictor.py`) the floor is the delay-free loop's, 5.8 m at the apex's 20.7 km/h (5.5 m at 20 km/h,
    6.5 m at 22.5; kept for +-50 ms of the delay), and
    max |CTE| <= 0.15 m (issue 18's goal; measured 0.121 m, the delay-free controller under `ideal` 0.121 m: the
    prediction leaves the delay-free loop, so this corner's error is the controller's own). On the arc of kappa(0)
    the delay stays in the loop, the floor is 11.1 m and max |CTE| <= 0.43 m (measured 0.388 m; 0.47 m before the
    floor took the lookahead down at once: the sideslip relaxing at the apex, a heading step of ~0.03 rad, leaves
    about 0.02 m per metre of lookahead). The truck's feed-forward and reference come from its preview responses
    (`feedforward_model` auto), their taps read where the planned speed takes the vehicle: identified at a held
    speed, they hold this braking-and-accelerating 0.3 g corner less well than its lags do (with
    `feedforward_model = "lag"`: 0.106 m and 0.215 m). Their handling gain (the steering per curvature growing with
    lateral acceleration in steady turns) asks more steering at the apex, which the truck, turning tighter at a held
    steering while it brakes, does not need (without it, `handling_gain = false`: 0.122 m and 0.354 m); with the
    delay left in the loop (the arc) the feedback corrects it late."""
    config = ClothoidConfig(known_delay_s=0.11, delay_compensation=compensation)
    controller = tuned_controller("clothoid", TRUCK, config)
    sim = SimulationConfig(conditions=load_conditions("automotive"))
    result = Simulation(Scenario("hairpin", HAIRPIN, "test"), TRUCK, controller, sim).run()
    assert result.completed, result.message
    trace = result.trace
    apex = int(np.argmin(trace["speed_mps"]))
    assert trace["speed_mps"][apex] == pytest.approx(5.75, abs=0.1)
    assert trace["ctrl_lookahead_m"][apex] <= trace["ctrl_lookahead_floor_m"][apex] + 1.0
    assert trace["ctrl_lookahead_floor_m"][apex] == pytest.approx(5.78 if compensation == "model" else 11.10, abs=0.02)
    assert result.metrics.max_abs_cte_m <= max_cte_m
    assert not result.metrics.limit_cycle
