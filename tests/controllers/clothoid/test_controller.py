"""The clothoid controller (Figure 2): robustness in hard situations, the command chain, options and files."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from controllers.base import Measurement
from controllers.clothoid import (
    DEFAULT_FILTER,
    ClothoidConfig,
    ClothoidController,
    CurvatureLimits,
    DiscreteLeadFilter,
    FilterSchedule,
    LeadFilterParams,
)
from tuning.filter_file import write_filter_file
from tuning.own_tuning import tuned_controller, tuning_for
from tuning.tuning_dirs import shipped_tuning_root
from workbench.apps.controller_config import build_config
from workbench.base.clothoid_chain import ClothoidChain
from workbench.base.errors import WorkbenchInputError
from workbench.base.path import ReferencePath
from workbench.vehicles import KinematicBicycle, make_vehicle

TRUCK = make_vehicle("tractor-semitrailer")
GEOMETRY = TRUCK.geometry
TRUCK_TUNING = tuning_for(TRUCK)
BEND = ClothoidChain().straight(30.0).clothoid_to(1 / 30, 20.0).arc(60.0).to_path("bend")
STRAIGHT = ReferencePath.from_xy(np.linspace(0.0, 100.0, 11), np.zeros(11), name="straight")


def _m(x: float, y: float, yaw: float, speed: float, yaw_rate: float = 0.0, steer: float = 0.0) -> Measurement:
    return Measurement(0.0, x, y, speed, 0.0, yaw, yaw_rate, steer)


def _step(measurement: Measurement, path: ReferencePath = BEND, **options) -> tuple[float, ClothoidController]:
    controller = ClothoidController(GEOMETRY, ClothoidConfig(**options))
    controller.reset(path, 0.02)
    return controller.step(measurement, path), controller


HARD = {
    "10 m off the path": _m(10.0, 10.0, 0.0, 8.0),
    "10 m off, the other side": _m(10.0, -10.0, 0.0, 8.0),
    "turned 90 deg away": _m(10.0, 0.0, math.pi / 2, 8.0),
    "target behind (facing backwards)": _m(10.0, 0.5, math.pi, 8.0),
    "at the end of the path": _m(float(BEND.x_m[-1]), float(BEND.y_m[-1]), float(BEND.heading_rad[-1]), 8.0),
    "beyond the end of the path": _m(float(BEND.x_m[-1]) + 5.0, float(BEND.y_m[-1]) + 5.0, 0.0, 8.0),
    "standing still": _m(10.0, 0.5, 0.1, 0.0),
    "curvature beyond the limits": _m(60.0, 2.0, 0.5, 25.0, yaw_rate=25.0 * 0.2, steer=8.0),
}


@pytest.mark.parametrize("mode", ["adaptive", "fixed", "speed"])
@pytest.mark.parametrize("situation", sorted(HARD))
def test_never_nan_nor_unbounded(situation: str, mode: str) -> None:
    controller = ClothoidController(GEOMETRY, ClothoidConfig(lookahead_mode=mode))
    controller.reset(BEND, 0.02)
    for _ in range(50):  # the integrator and the filter have state: keep stepping
        command = controller.step(HARD[situation], BEND)
        assert math.isfinite(command)
        assert abs(command) <= GEOMETRY.max_steer_wheel_angle_rad
        assert all(math.isfinite(v) for v in controller.diagnostics.values()), controller.diagnostics
    kappa_max, _ = controller.limits.at_speed(HARD[situation].speed_mps)
    assert abs(controller.diagnostics["curvature_cmd_1pm"]) <= kappa_max + 1e-12


def test_standing_still_holds_the_steering() -> None:
    """Eq. 3's kappa' times V = 0: the integrator does not move at speed 0, whatever the error."""
    command, controller = _step(_m(10.0, 3.0, 0.3, 0.0, steer=1.0), use_lead_filter=False)
    ratio, wheelbase = GEOMETRY.steering_ratio, GEOMETRY.wheelbase_m
    assert command == pytest.approx(ratio * math.atan(wheelbase * math.tan(1.0 / ratio) / wheelbase), abs=1e-12)
    assert controller.step(_m(10.0, 3.0, 0.3, 0.0, steer=1.0), BEND) == pytest.approx(command, abs=1e-12)


@pytest.mark.parametrize("mode", ["adaptive", "fixed", "speed"])
def test_on_an_exactly_straight_path_the_command_stays_zero(mode: str) -> None:
    """On the path, aligned, straight: the hyper-clothoid is a straight line, kappa' = 0 exactly."""
    controller = ClothoidController(GEOMETRY, ClothoidConfig(lookahead_mode=mode))
    controller.reset(STRAIGHT, 0.02)
    for k in range(100):
        command = controller.step(_m(1.0 + 0.16 * k, 0.0, 0.0, 8.0), STRAIGHT)
        assert command == 0.0
        assert controller.diagnostics["curvature_rate_1pm2"] == 0.0


@pytest.mark.parametrize(("y", "sign"), [(1.0, -1.0), (-1.0, 1.0)])
def test_an_offset_turns_toward_the_path_and_more_for_a_larger_offset(y: float, sign: float) -> None:
    small, _ = _step(_m(10.0, 0.5 * y, 0.0, 8.0), STRAIGHT, use_lead_filter=False, lookahead_mode="fixed")
    large, _ = _step(_m(10.0, y, 0.0, 8.0), STRAIGHT, use_lead_filter=False, lookahead_mode="fixed")
    assert sign * small > 0.0
    assert sign * large > sign * small


def test_command_chain_of_figure_2() -> None:
    """One step from straight running: kappa = kappa' V dt (the integrator), phi = atan(L kappa) (Ackermann),
    steering wheel = ratio phi; the filter off, the command is that steering-wheel angle."""
    dt, speed = 0.02, 8.0
    controller = ClothoidController(GEOMETRY, ClothoidConfig(use_lead_filter=False, lookahead_mode="fixed"))
    controller.reset(STRAIGHT, dt)
    command = controller.step(_m(10.0, 1.0, 0.0, speed), STRAIGHT)
    d = controller.diagnostics
    kappa = d["curvature_rate_1pm2"] * speed * dt
    assert d["curvature_cmd_1pm"] == pytest.approx(kappa, rel=1e-12)
    assert command == pytest.approx(GEOMETRY.steering_ratio * math.atan(GEOMETRY.wheelbase_m * kappa), rel=1e-12)


def test_curvature_rate_limit_bounds_the_integrator() -> None:
    """Section 4: |d kappa / dt| never exceeds the limit of the table, however large the fitted kappa'."""
    limits_rate = 0.01
    limits = CurvatureLimits((0.0, 100.0), (0.05, 0.05), (limits_rate, limits_rate), source="test")
    config = ClothoidConfig(use_lead_filter=False, prediction_time_s=0.0, curvature_limits=limits)
    controller = ClothoidController(GEOMETRY, config)
    controller.reset(BEND, 0.02)
    previous = 0.0
    for k in range(30):
        controller.step(_m(10.0 + 0.16 * k, 4.0, 0.0, 8.0), BEND)
        kappa = controller.diagnostics["curvature_cmd_1pm"]
        assert abs(kappa - previous) <= limits_rate * 0.02 + 1e-15
        previous = kappa
    assert abs(previous) == pytest.approx(30 * limits_rate * 0.02)  # it was at the limit throughout


def test_lead_filter_leads_and_can_be_switched_off() -> None:
    """The same measurements, so the integrator ramps the steering: off, the command is the ramp itself; with
    Eq. 6 (DC gain 1, phase lead) it runs ahead of the ramp once the filter has settled."""
    commands = {}
    for use in (False, True):
        config = ClothoidConfig(
            use_lead_filter=use, lookahead_mode="fixed", path_feedforward=False, tuning=TRUCK_TUNING
        )
        controller = ClothoidController(GEOMETRY, config, vehicle=TRUCK)
        controller.reset(STRAIGHT, 0.02)
        commands[use] = [controller.step(_m(10.0, 1.0, 0.0, 8.0), STRAIGHT) for _ in range(25)]
        raw = controller.diagnostics["steer_unfiltered_rad"]
    assert commands[False][-1] == pytest.approx(raw, rel=1e-12)
    assert commands[True][-1] < commands[False][-1] < 0.0


def test_filter_file_is_read_and_a_schedule_follows_speed(tmp_path: Path) -> None:
    slow, fast = LeadFilterParams.from_lag(4.0, 0.8), LeadFilterParams.from_lag(2.5, 1.2)
    schedule = FilterSchedule((20.0, 80.0), (slow, fast))
    path = write_filter_file(tmp_path / "lead.toml", schedule, source="test")
    controller = ClothoidController(GEOMETRY, build_config(ClothoidConfig, {"filter_file": str(path)}))
    assert controller.filter_schedule.params == (slow, fast)
    controller.reset(STRAIGHT, 0.02)
    controller.step(_m(10.0, 0.0, 0.0, 50.0 / 3.6), STRAIGHT)
    # the step runs the schedule's filter of its whole km/h, discretised at the period
    made = DiscreteLeadFilter(schedule.at_speed(50.0), 0.02).coefficients
    filters = controller._state["filters"][0]  # the step's state record (step_kernel.STATE)
    assert np.array_equal(filters[50], made) and np.isnan(filters[49, 0])
    # Without a file: the tuning's (the truck's shipped schedule), none without a tuning, and never DEFAULT_FILTER,
    # the truck's old filter, for another vehicle.
    own = tuned_controller("clothoid", TRUCK).filter_schedule
    assert own is not None and len(own.speeds_kmh) > 1 and own.params != (DEFAULT_FILTER,)
    assert own == TRUCK_TUNING.filter_schedule
    assert ClothoidController(GEOMETRY).filter_schedule is None
    car = make_vehicle("dynamic-bicycle")
    assert tuned_controller("clothoid", car).filter_schedule.params != own.params


def test_a_vehicle_without_its_tuning_is_refused_and_a_tuning_directory_is_read() -> None:
    """A controller built for a vehicle never runs untuned by mistake: the error names how to build it tuned. A
    config file's `tuning_dir` is read at the boundary into the config's tuning."""
    with pytest.raises(WorkbenchInputError, match=r"tractor-semitrailer.*tuned_controller"):
        ClothoidController(GEOMETRY, ClothoidConfig(), vehicle=TRUCK)
    assert tuned_controller("clothoid", TRUCK).tuning == TRUCK_TUNING
    explicit = ClothoidConfig(tuning=tuning_for(make_vehicle("kinematic-bicycle")))
    assert tuned_controller("clothoid", TRUCK, explicit).tuning == explicit.tuning  # a given tuning is kept
    config = build_config(ClothoidConfig, {"tuning_dir": str(shipped_tuning_root() / "tractor-semitrailer")})
    assert config.tuning == TRUCK_TUNING


@pytest.mark.parametrize(
    ("options", "needle"),
    [
        ({"lookahead_mode": "greedy"}, "lookahead_mode must be one of adaptive, fixed, speed; got 'greedy'"),
        ({"min_lookahead_m": 30.0}, "max_lookahead_m must be >= min_lookahead_m = 30.0 m; got 20.0"),
        ({"frechet_threshold_m": float("nan")}, "frechet_threshold_m must be a finite number in (0, 100] m; got nan"),
        ({"frechet_point_spacing_m": 0.1}, "frechet_point_spacing_m must be > max_lookahead_m / 64 = 0.3125 m"),
        ({"frechet_point_spacing_m": 0}, "frechet_point_spacing_m must be a finite number in (0, 50] m; got 0"),
        ({"initial_curvature": "lut"}, "initial_curvature must be one of"),
        ({"heading": "north"}, "heading must be one of course, yaw"),
        ({"prediction_time_s": -1.0}, "prediction_time_s"),
        ({"min_preview_time_s": -0.1}, "min_preview_time_s must be a finite number in [0, 10] s; got -0.1"),
        (
            {"max_lookahead_growth_m_per_m": 0.0},
            "max_lookahead_growth_m_per_m must be a finite number in (0, 100] m per m (or None: unlimited); got 0.0",
        ),
        ({"max_lookahead_shrink_m_per_m": -1.0}, "max_lookahead_shrink_m_per_m must be a finite number in (0, 100]"),
        ({"lookahead_hysteresis_m": -0.5}, "lookahead_hysteresis_m must be a finite number in [0, 50] m; got -0.5"),
        ({"min_phase_margin_deg": 95.0}, "min_phase_margin_deg must be a finite number in [0, 89] deg; got 95.0"),
        (
            {"feedforward_time_s": -0.1},
            "feedforward_time_s must be a finite number in [0, 5] s (or None: from the vehicle's lags); got -0.1",
        ),
        ({"feedforward_window_m": 0.0}, "feedforward_window_m must be a finite number in [0.1, 100] m; got 0.0"),
        (
            {"max_lookahead_growth_m_per_m": True},
            "max_lookahead_growth_m_per_m must be a finite number in (0, 100] m per m (or None: unlimited); got True",
        ),
        ({"max_lookahead_growth_m_per_m": "fast"}, "got 'fast'"),
    ],
)
def test_bad_options_are_refused_with_the_value_and_what_is_allowed(options: dict, needle: str) -> None:
    with pytest.raises(WorkbenchInputError, match=None) as info:
        ClothoidConfig(**options)
    assert needle in str(info.value)


def test_the_lookahead_floor_is_a_preview_time_when_asked() -> None:
    """In the bend's entry the search picks the bottom of the range: 5 m at 8 m/s without a vehicle (no analysis
    floor); at 25 m/s min_preview_time_s = 0.6 makes the floor 0.6 s x 25 m/s = 15 m."""
    entry = _m(40.0, 0.0, 0.0, 8.0)
    fast = _m(40.0, 0.0, 0.0, 25.0)
    assert _step(entry)[1].diagnostics["lookahead_m"] == 5.0
    assert _step(fast, min_preview_time_s=0.6)[1].diagnostics["lookahead_m"] == pytest.approx(15.0, abs=1e-12)
    assert _step(fast)[1].diagnostics["lookahead_m"] == 6.5


def test_the_analysis_floor_keeps_the_margins_at_every_lookahead_the_controller_may_pick() -> None:
    """With the truck's tuning the controller never picks a lookahead below the floor the loop analysis gives, and
    at that floor (at a speed node: 27.5 km/h) the loop keeps 45 deg and 6 dB; with the margins set to 0 there is
    no floor."""
    from controllers.clothoid.loop_analysis import loop_margins

    speed_kmh = 27.5
    controller = ClothoidController(GEOMETRY, ClothoidConfig(tuning=TRUCK_TUNING))
    controller.reset(BEND, 0.02)
    controller.step(_m(40.0, 0.0, 0.0, speed_kmh / 3.6), BEND)
    floor = controller.diagnostics["lookahead_floor_m"]
    assert controller.diagnostics["lookahead_m"] >= floor > 5.0
    assert floor <= 20.0  # the tuned lead filter leaves a range with margins
    lags, settings = controller.plant_lags(speed_kmh), controller.loop_settings(speed_kmh)
    for lookahead in np.arange(floor, 20.0 + 1e-9, 1.0):
        assert loop_margins(lags, settings, speed_kmh / 3.6, float(lookahead)).meets(45.0, 6.0)
    free = ClothoidController(
        GEOMETRY, ClothoidConfig(min_phase_margin_deg=0.0, min_gain_margin_db=0.0, tuning=TRUCK_TUNING)
    )
    free.reset(BEND, 0.02)
    free.step(_m(40.0, 0.0, 0.0, 8.0), BEND)
    assert free.diagnostics["lookahead_floor_m"] == 5.0


def test_missing_filter_file_names_it(tmp_path: Path) -> None:
    with pytest.raises(WorkbenchInputError, match=r"nowhere\.json"):
        build_config(ClothoidConfig, {"filter_file": str(tmp_path / "nowhere.json")})


def test_runs_on_the_kinematic_car_with_every_lookahead_mode() -> None:
    from workbench.simulation.scenarios import make_scenario
    from workbench.simulation.simulator import Simulation, SimulationConfig

    vehicle = KinematicBicycle()
    for mode in ("adaptive", "fixed", "speed"):
        controller = ClothoidController(vehicle.geometry, ClothoidConfig(lookahead_mode=mode, use_lead_filter=False))
        result = Simulation(make_scenario("fig17"), vehicle, controller, SimulationConfig()).run()
        assert result.completed, result.message
        trace = result.to_pandas()
        # fig17 starts 1 m left of the path: the controller brings it back and keeps it near.
        assert abs(trace["cte_m"].iloc[0]) == pytest.approx(1.0, abs=0.05)
        assert trace["cte_m"].iloc[-50:].abs().max() < 0.1
