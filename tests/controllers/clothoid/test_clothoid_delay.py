"""The clothoid controller's known dead time (`ClothoidConfig.known_delay_s`, measurement latency plus actuation dead
time): off it changes nothing; on, the pose is predicted over it, the loop analysis has it as a pure delay (the phase
margin falls by omega_c x T), the lookahead floor rises with it, and on a plant whose steering arrives late the
controller keeps tracking without the limit cycle it falls into unaware of the delay."""

from __future__ import annotations

import dataclasses
import math

import control
import numpy as np
import pytest

from controllers.base import Measurement
from controllers.clothoid import ClothoidConfig, ClothoidController, LeadFilterParams
from controllers.clothoid.loop_analysis import (
    DelayRobustness,
    LoopSettings,
    PlantLags,
    lookahead_floor,
    loop_margins,
    loop_transfer,
    margins,
)
from tuning.own_tuning import tuned_controller, tuning_for
from workbench.base.clothoid_chain import ClothoidChain
from workbench.base.errors import WorkbenchInputError
from workbench.simulation.conditions import Actuation, Conditions, Inertial, load_conditions
from workbench.simulation.scenarios import ScenarioOptions, make_scenario
from workbench.simulation.simulator import Simulation, SimulationConfig
from workbench.vehicles import make_vehicle
from workbench.vehicles.steering_lag import SteeringLag

PERIOD = 0.02


def _late(delay_s: float) -> Conditions:
    """The steering command reaching the plant delay_s late (the simulator's actuation dead time)."""
    return Conditions(name="late", actuation=Actuation(dead_time_s=delay_s))


CAR = make_vehicle("dynamic-bicycle")
CAR_TUNING = tuning_for(CAR)
BEND = ClothoidChain().straight(20.0).clothoid_to(1 / 30, 15.0).arc(30.0).clothoid_to(0.0, 15.0).straight(40.0)
BEND_PATH = BEND.to_path("bend")
#: The loaded truck's lags at 30 km/h and a lead filter (as in test_loop_analysis.py).
TRUCK_LAGS = PlantLags(
    SteeringLag(28.0, 2.0, 0.24, steady_state_gain=0.935), SteeringLag(9.42, 0.94, 0.062, steady_state_gain=0.942)
)
TRUCK_LEAD = LeadFilterParams(6.0, 1.2, 24.0)
V = 30 / 3.6
#: The pose predicted over the known delay on kappa(0), the delay left in the loop.
ARC = {"delay_compensation": "arc"}


@pytest.mark.parametrize("vehicle_name", ["dynamic-bicycle", "tractor-semitrailer"])
def test_no_known_delay_changes_nothing(vehicle_name: str, weaving) -> None:
    """known_delay_s = 0: commands and diagnostics equal bit for bit those of a controller built without it, and
    so do the loop settings the floor is computed from."""
    vehicle = make_vehicle(vehicle_name)
    plain = tuned_controller("clothoid", vehicle)
    explicit = tuned_controller("clothoid", vehicle, ClothoidConfig(known_delay_s=0.0))
    plain.reset(BEND_PATH, PERIOD)
    explicit.reset(BEND_PATH, PERIOD)
    for m in weaving(BEND_PATH, 80, 3, 6.0):
        assert plain.step(m, BEND_PATH) == explicit.step(m, BEND_PATH)  # exactly
        assert dict(plain.diagnostics) == dict(explicit.diagnostics)
    assert plain.loop_settings(30.0) == explicit.loop_settings(30.0)
    assert plain.loop_settings(30.0).known_delay_s == 0.0
    assert plain._floors == explicit._floors


@pytest.mark.parametrize("value", [-0.01, 1.5, math.nan])
def test_known_delay_is_checked(value: float) -> None:
    with pytest.raises(WorkbenchInputError, match=r"known_delay_s must be a finite number in \[0, 1\] s"):
        ClothoidConfig(known_delay_s=value)


def test_the_pose_is_predicted_over_the_known_delay_too() -> None:
    """Figure 2, step 5, with delay_compensation "arc": the start pose moves ahead by (prediction_time_s +
    known_delay_s) x speed on kappa(0); the feed-forward point moves ahead by the delay; the loop settings carry
    it."""
    arc = {"delay_compensation": "arc"}
    controller = ClothoidController(CAR.geometry, ClothoidConfig(tuning=CAR_TUNING, known_delay_s=0.15, **arc))
    plain = ClothoidController(CAR.geometry, ClothoidConfig(tuning=CAR_TUNING))
    controller.reset(BEND_PATH, PERIOD)
    plain.reset(BEND_PATH, PERIOD)
    # the clothoid starts where a controller predicting over prediction_time_s + known_delay_s puts it
    fixed = {"tuning": CAR_TUNING, "lookahead_mode": "fixed", "path_feedforward": False, **arc}
    delayed = ClothoidController(CAR.geometry, ClothoidConfig(known_delay_s=0.15, **fixed))
    longer = ClothoidController(CAR.geometry, ClothoidConfig(prediction_time_s=0.35, **fixed))
    m = Measurement(0.0, 3.0, 0.4, 8.0, 0.0, 0.1, 0.2, 0.0)
    for c in (delayed, longer):
        c.reset(BEND_PATH, PERIOD)
        c.step(m, BEND_PATH)
    assert delayed.diagnostics["clothoid_curvature_rate_1pm2"] != 0.0
    floors = ("lookahead_floor_m", "lookahead_ceiling_m")  # the delayed loop's floor is longer
    assert {k: v for k, v in delayed.diagnostics.items() if k not in floors} == {
        k: v for k, v in longer.diagnostics.items() if k not in floors
    }
    timing, plain_timing = controller.feedforward_timing(8.0), plain.feedforward_timing(8.0)
    assert timing.feedforward_time_s == pytest.approx(plain_timing.feedforward_time_s + 0.15, abs=1e-12)
    assert controller.loop_settings(30.0).known_delay_s == 0.15


@pytest.mark.parametrize("lookahead_m", [10.0, 15.0, 20.0])
@pytest.mark.parametrize("delay_s", [0.04, 0.1])
def test_a_known_delay_costs_the_phase_margin_omega_c_times_the_delay(lookahead_m: float, delay_s: float) -> None:
    """Compensated on the arc: with the pose prediction's total horizon kept (prediction_time_s lowered by the delay), a
    known delay is a pure delay of the loop: the crossover stays, the phase margin falls by omega_c T (in degrees,
    within 0.05 deg), the gain margin falls; and it is the same loop as an unknown (measurement) delay with the same
    prediction."""
    base = loop_margins(TRUCK_LAGS, LoopSettings(lead=TRUCK_LEAD), V, lookahead_m)
    known = loop_margins(
        TRUCK_LAGS,
        LoopSettings(lead=TRUCK_LEAD, prediction_time_s=0.2 - delay_s, known_delay_s=delay_s, **ARC),
        V,
        lookahead_m,
    )
    assert known.crossover_rad_s == pytest.approx(base.crossover_rad_s, rel=1e-9)
    drop = base.phase_margin_deg - known.phase_margin_deg
    assert drop == pytest.approx(math.degrees(base.crossover_rad_s * delay_s), abs=0.05)
    assert known.gain_margin_db < base.gain_margin_db
    unknown = loop_margins(TRUCK_LAGS, LoopSettings(lead=TRUCK_LEAD, measurement_delay_s=delay_s), V, lookahead_m)
    assert unknown.phase_margin_deg == pytest.approx(known.phase_margin_deg, abs=1e-9)
    assert unknown.gain_margin_db == pytest.approx(known.gain_margin_db, abs=1e-9)


@pytest.mark.parametrize("lookahead_m", [10.0, 12.0])
def test_margins_with_a_known_delay_are_lower(lookahead_m: float) -> None:
    """As the controller runs with it (0.2 s prediction plus a known 0.1 s), both compensations: lower phase and gain
    margins than without the delay (no prediction buys back all the delay costs at the steering sent); the model's
    keeps more of them than the arc's."""
    base = loop_margins(TRUCK_LAGS, LoopSettings(lead=TRUCK_LEAD), V, lookahead_m)
    delayed = loop_margins(TRUCK_LAGS, LoopSettings(lead=TRUCK_LEAD, known_delay_s=0.1, **ARC), V, lookahead_m)
    model = loop_margins(TRUCK_LAGS, LoopSettings(lead=TRUCK_LEAD, known_delay_s=0.1), V, lookahead_m)
    for compensated in (delayed, model):
        assert compensated.phase_margin_deg < base.phase_margin_deg
        assert compensated.gain_margin_db < base.gain_margin_db
    assert model.phase_margin_deg > delayed.phase_margin_deg
    assert model.gain_margin_db > delayed.gain_margin_db


def test_the_floor_rises_with_the_known_delay() -> None:
    """Compensated on the arc: truck lags at 30 km/h: 9 m without delay, longer with 0.1 s and 0.2 s; and the
    controller's own floors (car, truck, 30 and 60 km/h) with known_delay_s = 0.1 are at least those without."""
    floors = [
        lookahead_floor(TRUCK_LAGS, LoopSettings(lead=TRUCK_LEAD, known_delay_s=d, **ARC), V, 5.0, 40.0, 0.5, (0.0,))
        for d in (0.0, 0.1, 0.2)
    ]
    assert floors[0] < floors[1] < floors[2]
    for vehicle in (CAR, make_vehicle("tractor-semitrailer")):
        config = ClothoidConfig(tuning=tuning_for(vehicle), **ARC)
        plain = ClothoidController(vehicle.geometry, config)
        delayed = ClothoidController(vehicle.geometry, dataclasses.replace(config, known_delay_s=0.1))
        for controller in (plain, delayed):
            controller.reset(BEND_PATH, PERIOD)
        for speed_kmh in (30.0, 60.0):
            assert delayed.lookahead_floor_m(speed_kmh / 3.6) >= plain.lookahead_floor_m(speed_kmh / 3.6)
        assert delayed.lookahead_floor_m(30 / 3.6) > plain.lookahead_floor_m(30 / 3.6)


def _dlc_metrics(speed_kmh: float, delay_s: float, known_delay_s: float):
    vehicle = make_vehicle("dynamic-bicycle")
    controller = tuned_controller("clothoid", vehicle, ClothoidConfig(known_delay_s=known_delay_s))
    assert controller.tuning is not None
    scenario = make_scenario("dlc", ScenarioOptions(vehicle_width_m=vehicle.geometry.width_m))
    result = Simulation(
        scenario, vehicle, controller, SimulationConfig(speed_kmh=speed_kmh, conditions=_late(delay_s))
    ).run()
    assert result.completed, result.message
    return result.metrics


@pytest.mark.parametrize(("speed_kmh", "delay_s"), [(30.0, 0.1), (30.0, 0.2), (60.0, 0.1)])
def test_knowing_the_dead_time_keeps_tracking_without_a_limit_cycle(speed_kmh: float, delay_s: float) -> None:
    """Measured (dynamic bicycle, dlc, steering late by delay_s), unaware / knowing the delay: 30 km/h 0.1 s:
    0.060 / 0.058 m, 9.8 / 3.6 deg; 0.2 s: 0.47 m, 31 deg, a limit cycle / 0.061 m, 3.4 deg; 60 km/h 0.1 s: 0.26 m,
    34 deg, a limit cycle / 0.10 m, 6.0 deg. Knowing it is no worse in |CTE| (within 5 %), oscillates less, and
    never limit-cycles."""
    unaware = _dlc_metrics(speed_kmh, delay_s, 0.0)
    knowing = _dlc_metrics(speed_kmh, delay_s, delay_s)
    assert knowing.max_abs_cte_m <= 1.05 * unaware.max_abs_cte_m
    assert knowing.steer_oscillation_deg < 0.7 * unaware.steer_oscillation_deg
    assert not knowing.limit_cycle


def test_a_yaw_rate_older_than_the_pose_is_predicted_from_its_own_time() -> None:
    """The dynamic bicycle on the dlc at 30 km/h, its yaw rate 20 ms late and nothing else (a vehicle bus's latency):
    the controller told its age (yaw_rate_age_s 0.02 s) tracks within 20 % of the ideal run's max |CTE|, the one not
    told at over three times it (measured 0.0055 m ideal, 0.0061 told, 0.024 not told): read as the pose's, the
    older yaw rate lags the curvature the feedback compares the path with."""
    late_yaw_rate = Conditions(name="late yaw rate", inertial=Inertial(latency_s=0.02))
    told = ClothoidConfig(yaw_rate_age_s=0.02)
    scenario = make_scenario("dlc", ScenarioOptions(vehicle_width_m=CAR.geometry.width_m))
    cte = {}
    for name, conditions, config in (
        ("ideal", Conditions(name="ideal"), ClothoidConfig()),
        ("told", late_yaw_rate, told),
        ("not told", late_yaw_rate, ClothoidConfig()),
    ):
        controller = tuned_controller("clothoid", CAR, config)
        result = Simulation(scenario, CAR, controller, SimulationConfig(conditions=conditions)).run()
        assert result.completed, result.message
        cte[name] = result.metrics.max_abs_cte_m
    assert cte["told"] <= 1.2 * cte["ideal"]
    assert cte["not told"] > 3.0 * cte["ideal"]


#: The truck's two lags on one gain (the path lag's): a sideslip whose rate the lags' difference is.
TRUCK_LAGS_ONE_GAIN = PlantLags(
    TRUCK_LAGS.path, dataclasses.replace(TRUCK_LAGS.measured, steady_state_gain=TRUCK_LAGS.path.steady_state_gain)
)


@pytest.mark.parametrize("lookahead_m", [6.0, 9.0, 14.0])
@pytest.mark.parametrize("delay_s", [0.04, 0.1, 0.2])
@pytest.mark.parametrize(
    ("lags", "tolerance"),
    [(PlantLags(TRUCK_LAGS.path), 1e-5), (TRUCK_LAGS_ONE_GAIN, 5e-4)],
    ids=["one lag", "two lags"],
)
def test_the_model_compensation_leaves_the_delay_free_loop(
    lookahead_m: float, delay_s: float, lags: PlantLags, tolerance: float
) -> None:
    """Smith's property (Smith 1957), on the analysis's own loop: with the lags' model the plant's (one lag, the
    measured curvature the path's; or the truck's path and yaw-rate lags on one gain, the course then turning
    with the path lag and kappa(0) with the yaw-rate lag), every closed-loop pole of the delay-free loop is a
    closed-loop pole of the loop with the known delay and the predictor (within 1e-5 with one lag: repeated poles;
    5e-4 with two, whose longer delay line makes the eigenvalues more sensitive to rounding: measured 1.3e-4 at
    0.2 s; a course turned with the path lag's own change misses by 0.14-0.28); the others are the model's (the
    lags' own) and the delay line's (at 0). So the loop is as stable as the delay-free one (at 6 m, 30 km/h,
    neither is). The arc's compensation keeps none of them."""
    free = control.feedback(loop_transfer(lags, LoopSettings(lead=TRUCK_LEAD), V, lookahead_m), 1).poles()
    settings = LoopSettings(lead=TRUCK_LEAD, known_delay_s=delay_s)
    delayed = control.feedback(loop_transfer(lags, settings, V, lookahead_m), 1).poles()
    rest = list(delayed)
    for pole in free:
        nearest = int(np.argmin(np.abs(np.array(rest) - pole)))
        assert abs(rest.pop(nearest) - pole) < tolerance, pole
    assert max(abs(pole) for pole in rest) < 0.87  # the lag's (0.86, 0.12) and the line's (0, spread by rounding)
    arc = LoopSettings(lead=TRUCK_LEAD, known_delay_s=delay_s, **ARC)
    arc_poles = control.feedback(loop_transfer(lags, arc, V, lookahead_m), 1).poles()
    assert max(np.min(np.abs(arc_poles - pole)) for pole in free) > 1e-3


def test_with_the_model_the_floor_keeps_the_nominal_loop_and_the_delayed_one_robust() -> None:
    """Truck lags at 30 km/h, 0.1 s known. With the delay exactly known (no uncertainty) the model's floor is the
    delay-free loop's (9 m) wherever the loop with its delay keeps 30 deg / 3 dB; asking it 6 dB raises the floor to
    where it has them. With the delay uncertain by +-50 ms (the default) the floor is where the loop also keeps half
    those margins over that band (here the same 9 m), below the arc's (16 m). The controller's own floors (loaded
    truck, 0.11 s): exactly known and uncertain, those without a delay at 20 and 30 km/h (5.5 and 8.5 m: its
    course predicted with the path lag, the loop with the delay is the delay-free one), shorter than the arc's."""

    def floor(settings: LoopSettings, delayed: DelayRobustness) -> float:
        return lookahead_floor(TRUCK_LAGS, settings, V, 5.0, 40.0, 0.5, (0.0,), delayed=delayed)

    exact = DelayRobustness(delay_uncertainty_s=0.0)
    model = LoopSettings(lead=TRUCK_LEAD, known_delay_s=0.1)
    free = floor(LoopSettings(lead=TRUCK_LEAD), exact)
    assert floor(model, exact) == free == 9.0
    stricter = floor(model, DelayRobustness(gain_margin_db=6.0, delay_uncertainty_s=0.0))
    assert stricter > free
    assert loop_margins(TRUCK_LAGS, model, V, stricter).meets(30.0, 6.0)
    uncertain = floor(model, DelayRobustness())
    arc = floor(LoopSettings(lead=TRUCK_LEAD, known_delay_s=0.1, **ARC), DelayRobustness())
    assert free <= uncertain < arc
    for error in (-0.05, -0.025, 0.025, 0.05):
        late = dataclasses.replace(model, measurement_delay_s=error)
        assert loop_margins(TRUCK_LAGS, late, V, uncertain).meets(15.0, 1.5)
    truck = make_vehicle("tractor-semitrailer")
    plain = tuned_controller("clothoid", truck)
    known = tuned_controller("clothoid", truck, ClothoidConfig(known_delay_s=0.11, known_delay_uncertainty_s=0.0))
    default = tuned_controller("clothoid", truck, ClothoidConfig(known_delay_s=0.11))
    on_arc = tuned_controller("clothoid", truck, ClothoidConfig(known_delay_s=0.11, **ARC))
    for controller in (plain, known, default, on_arc):
        controller.reset(BEND_PATH, PERIOD)
    for speed_kmh in (20.0, 30.0):
        assert known.lookahead_floor_m(speed_kmh / 3.6) == plain.lookahead_floor_m(speed_kmh / 3.6)
        assert known.lookahead_floor_m(speed_kmh / 3.6) <= default.lookahead_floor_m(speed_kmh / 3.6)
        assert default.lookahead_floor_m(speed_kmh / 3.6) == plain.lookahead_floor_m(speed_kmh / 3.6)
        assert default.lookahead_floor_m(speed_kmh / 3.6) < on_arc.lookahead_floor_m(speed_kmh / 3.6)


def test_the_delay_errors_checked_span_the_uncertainty_both_ways() -> None:
    assert DelayRobustness(delay_uncertainty_s=0.04).delay_errors_s(0.11) == (-0.04, -0.02, 0.02, 0.04)
    assert DelayRobustness(delay_uncertainty_s=0.04).delay_errors_s(0.03) == (-0.03, -0.02, 0.02, 0.04)
    assert DelayRobustness(delay_uncertainty_s=0.0).delay_errors_s(0.1) == ()
    with pytest.raises(
        WorkbenchInputError, match=r"delay_uncertainty_s must be a finite number in \[0, 1\] s; got -0.01"
    ):
        DelayRobustness(delay_uncertainty_s=-0.01)


@pytest.mark.parametrize("vehicle_name", ["dynamic-bicycle", "tractor-semitrailer"])
@pytest.mark.parametrize("dead_time_s", [0.05, 0.15])
def test_a_delay_within_its_uncertainty_does_not_limit_cycle(vehicle_name: str, dead_time_s: float) -> None:
    """The dlc under automotive conditions, the controller told 0.11 s (0.01 s pose latency, 0.1 s dead time) while
    the steering's dead time is 50 ms shorter or longer, the default uncertainty: completed, no limit cycle, within
    0.15 m (measured: car 0.038 / 0.079 m, truck 0.097 / 0.137 m). Beyond it the model's compensation may
    limit-cycle (the dynamic bicycle with 0.2 s: 0.77 Hz)."""
    vehicle = make_vehicle(vehicle_name)
    controller = tuned_controller("clothoid", vehicle, ClothoidConfig(known_delay_s=0.11))
    automotive = load_conditions("automotive")
    conditions = dataclasses.replace(
        automotive, actuation=dataclasses.replace(automotive.actuation, dead_time_s=dead_time_s)
    )
    scenario = make_scenario("dlc", ScenarioOptions(vehicle_width_m=vehicle.geometry.width_m))
    result = Simulation(scenario, vehicle, controller, SimulationConfig(conditions=conditions)).run()
    assert result.completed, result.message
    assert not result.metrics.limit_cycle
    assert result.metrics.max_abs_cte_m <= 0.15


def test_the_model_compensation_is_checked() -> None:
    """An unknown compensation, the model without the measured kappa(0) it predicts, or without the lags it predicts
    with, is refused with what is allowed."""
    with pytest.raises(WorkbenchInputError, match=r"delay_compensation must be one of model, arc; got 'smith'"):
        ClothoidConfig(delay_compensation="smith")
    with pytest.raises(WorkbenchInputError, match="initial_curvature = 'yaw-rate'"):
        ClothoidConfig(known_delay_s=0.1, initial_curvature="command")
    ClothoidConfig(known_delay_s=0.1, initial_curvature="command", **ARC)  # the arc needs neither
    ClothoidConfig(initial_curvature="command")  # nor does the model without a delay
    with pytest.raises(WorkbenchInputError, match="has no tuning"):
        ClothoidController(CAR.geometry, ClothoidConfig(known_delay_s=0.1))
    with pytest.raises(WorkbenchInputError, match="delay_compensation must be one of"):
        LoopSettings(delay_compensation="smith")


@pytest.mark.parametrize("lookahead_m", [6.0, 9.0, 14.0])
@pytest.mark.parametrize("error_s", [-0.05, 0.0, 0.05])
def test_the_floor_search_margins_are_those_of_the_whole_loop(lookahead_m: float, error_s: float) -> None:
    """With the model's compensation the floor search composes the loop's response from cached parts (the plant
    without its delays, the controller by block elimination of its line of commands sent): the same margins and
    stability as `margins` of the whole loop transfer, built with python-control, within 1e-6."""
    settings = LoopSettings(lead=TRUCK_LEAD, known_delay_s=0.1, measurement_delay_s=error_s)
    fast = loop_margins(TRUCK_LAGS, settings, V, lookahead_m)
    whole = margins(loop_transfer(TRUCK_LAGS, settings, V, lookahead_m))
    assert fast.stable == whole.stable
    for name in ("phase_margin_deg", "gain_margin_db", "gain_reduction_margin_db", "crossover_rad_s"):
        assert getattr(fast, name) == pytest.approx(getattr(whole, name), abs=1e-6), name
