"""The check of a path against the vehicle before a run (issue 20, item 13): steering lock (with understeer at the
planned speed), steering rate, rollover and tyre grip, merged into spans along the path, and the warning that names
them."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest
from stadium_tracks import stadium_file

from workbench.base.clothoid_chain import ClothoidChain
from workbench.base.errors import WorkbenchInputError
from workbench.base.path import ReferencePath
from workbench.simulation.feasibility import (
    ROLLOVER,
    STEERING_LOCK,
    STEERING_RATE,
    STEERING_RATE_WINDOW_S,
    TYRE_GRIP,
    InfeasibleSpan,
    VehicleLimits,
    _range_extremes,
    check_path,
    feasibility_warnings,
    infeasible_spans,
)
from workbench.simulation.run_config import SimulationConfig
from workbench.simulation.scenarios import ScenarioOptions, make_scenario
from workbench.simulation.simulator import plan_path_speed
from workbench.vehicles import make_vehicle

G = 9.80665


def _hairpin_file(folder: Path, radius_m: float = 6.5, straight_m: float = 80.0, first: int = 0) -> Path:
    """The hairpin track (`stadium_tracks.stadium_file`), 5 m of track each side."""
    return stadium_file(folder, "hairpins.csv", radius_m, straight_m=straight_m, first=first)


def _planned(path: ReferencePath, **config: float) -> ReferencePath:
    return plan_path_speed(path, SimulationConfig(**config))


def _circle(radius_m: float) -> ReferencePath:
    return ClothoidChain(curvature_1pm=1.0 / radius_m).arc(2 * math.pi * radius_m).to_path("circle", closed=True)


def test_a_6_5_m_hairpin_is_flagged_for_the_loaded_truck_and_not_for_the_car(tmp_path: Path) -> None:
    path = _planned(make_scenario(str(_hairpin_file(tmp_path))).path)
    truck = make_vehicle("tractor-semitrailer")
    spans = check_path(path, truck)
    assert [span.reason for span in spans] == [STEERING_LOCK, STEERING_LOCK]  # one span per hairpin
    half_lap = path.length_m / 2
    for span, hairpin_start in zip(spans, (40.0, 40.0 + half_lap), strict=True):
        # The hairpin's radius, and at its tightest, where the spline through the points overshoots the jump in
        # curvature from the straight, 10% less.
        inside = (path.s_m >= span.start_s_m) & (path.s_m <= span.end_s_m)
        assert np.median(1.0 / np.abs(path.curvature_1pm[inside])) == pytest.approx(6.5, abs=0.1)
        assert 5.7 < span.radius_m < 6.5
        # The truck's least radius at the planned speed: 9.19 m at full lock, more as it understeers at 0.3 g.
        assert 9.19 < span.min_radius_m < 9.5
        assert span.start_s_m == pytest.approx(hairpin_start, abs=1.5)
        assert span.end_s_m - span.start_s_m == pytest.approx(math.pi * 6.5, abs=2.0)
        assert span.start_s_m <= span.s_m <= span.end_s_m
        v = span.speed_kmh / 3.6
        # Planned for the 0.3 g bound on points 1 m apart, smoother than the spline at its tightest.
        assert 0.25 < v * v / (span.radius_m * G) < 0.4
    assert check_path(path, make_vehicle("dynamic-bicycle")) == ()  # the car turns 1.43 m at lock
    (warning,) = feasibility_warnings(path.name, VehicleLimits.of(truck), spans)
    assert warning.startswith(
        "hairpins curves tighter than the tractor-semitrailer can turn at full lock (32 deg road-wheel angle: a "
        "radius of 9.19 m at walking pace, more at speed as it understeers) at s = 4"
    )
    assert re.search(
        r"m \(peak 0\.1[5-7]\d 1/m\), a radius of [56]\.\d\d m against a minimum of 9\.[2-4]\d m at 1\d km/h; s = ",
        warning,
    )
    assert warning.endswith(": expect it to run wide there")


def test_the_truck_understeers_its_minimum_radius_up_with_speed() -> None:
    limits = VehicleLimits.of(make_vehicle("tractor-semitrailer"))
    assert limits.lock_radius_m == pytest.approx(5.635 / math.tan(0.55), rel=1e-12)
    assert limits.min_radius_m(STEERING_LOCK, 0.0) == pytest.approx(limits.lock_radius_m, rel=1e-9)
    at_speed = limits.min_radius_m(STEERING_LOCK, 5.0)
    # atan(L / R) + K v^2 / R = the lock, K the truck's understeer gradient
    assert math.atan(5.635 / at_speed) + limits.understeer_gradient_rad_per_mps2 * 25.0 / at_speed == pytest.approx(
        0.55, abs=1e-9
    )
    assert limits.lock_radius_m < at_speed < 9.5
    car = VehicleLimits.of(make_vehicle("dynamic-bicycle"))
    assert car.min_radius_m(STEERING_LOCK, 5.0) == pytest.approx(car.lock_radius_m, rel=1e-6)  # neutral steer


def test_rollover_is_flagged_for_the_truck_asked_for_0_6_g() -> None:
    path = _planned(_circle(30.0), speed_kmh=80.0, max_lateral_accel_g=0.6)
    truck = make_vehicle("tractor-semitrailer")
    (span,) = check_path(path, truck)  # the lock turns 9.4 m: only rollover
    threshold = truck.derived.rollover_threshold_g
    assert (span.reason, span.start_s_m, span.end_s_m) == (ROLLOVER, 0.0, pytest.approx(path.length_m))
    v = span.speed_kmh / 3.6
    assert v * v / (30.0 * G) == pytest.approx(0.6, rel=0.01)
    assert span.min_radius_m == pytest.approx(v * v / (threshold * G), rel=1e-9)  # ~40 m at 48 km/h
    (warning,) = feasibility_warnings(path.name, VehicleLimits.of(truck), (span,))
    assert f"static rollover threshold ({threshold:.2f} g)" in warning and "(peak 0.60 g)" in warning
    assert check_path(_planned(_circle(30.0), speed_kmh=80.0), truck) == ()  # at the default 0.3 g: fine


def test_tyre_grip_is_flagged_for_the_car_asked_for_1_2_g() -> None:
    path = _planned(_circle(30.0), speed_kmh=100.0, max_lateral_accel_g=1.2)
    car = make_vehicle("dynamic-bicycle")
    (span,) = check_path(path, car)
    assert span.reason == TYRE_GRIP
    assert span.min_radius_m == pytest.approx((span.speed_kmh / 3.6) ** 2 / (1.049 * G), rel=0.01)
    assert check_path(path, make_vehicle("kinematic-bicycle")) == ()  # no tyres: no grip limit


def test_spans_merge_across_a_closed_loops_start(tmp_path: Path) -> None:
    # The loop starts at the apex of its first hairpin: that hairpin's span runs from before the end to after the
    # start, one span, not two.
    path = _planned(make_scenario(str(_hairpin_file(tmp_path, first=32))).path)
    spans = check_path(path, make_vehicle("tractor-semitrailer"))
    assert len(spans) == 2
    across, inside = sorted(spans, key=lambda span: span.end_s_m < span.start_s_m, reverse=True)
    assert across.end_s_m < across.start_s_m  # through the start
    assert across.end_s_m + path.length_m - across.start_s_m == pytest.approx(inside.end_s_m - inside.start_s_m, abs=1)


def test_a_path_without_planned_speed_is_refused_and_spans_are_validated() -> None:
    with pytest.raises(WorkbenchInputError, match=r"circle: checking the path against a vehicle needs its planned"):
        infeasible_spans(_circle(30.0), VehicleLimits.of(make_vehicle("dynamic-bicycle")))
    with pytest.raises(WorkbenchInputError, match=r"must be one of steering lock, steering rate, rollover, tyre"):
        InfeasibleSpan(0.0, 1.0, 0.5, 6.5, 9.4, 15.0, "too tight")
    span = InfeasibleSpan(60.971, 79.456, 77.4712, 5.8234, 9.3012, 15.24, STEERING_LOCK)
    assert span.to_dict() == {
        "start_s_m": 60.97, "end_s_m": 79.46, "s_m": 77.47, "radius_m": 5.82, "min_radius_m": 9.3,
        "speed_kmh": 15.2, "reason": "steering lock", "demand_ratio": None,
    }  # fmt: skip


def _waypoint_file(folder: Path, name: str, points: list[tuple[float, float]]) -> Path:
    file = folder / name
    file.write_text("x,y\n" + "".join(f"{x!r},{y!r}\n" for x, y in points))
    return file


def test_a_curvature_ramp_asks_the_steering_what_the_road_wheel_angle_says() -> None:
    """Straight, a clothoid to kappa_1 over l, an arc; driven at a constant v by the kinematic car. Within any window
    W the asked road-wheel angle atan(L kappa) changes most from the clothoid's start: by atan(L kappa_1 min(v W, l)
    / l), over the rate limit times W."""
    car = VehicleLimits.of(make_vehicle("kinematic-bicycle"))
    assert car.max_road_wheel_rate_rad_s == pytest.approx(math.radians(22.9), abs=1e-3)
    v, wheelbase = 5.0, car.wheelbase_m
    window_m = v * STEERING_RATE_WINDOW_S
    for kappa_1, length in ((0.2, 20.0), (0.3, 6.0)):
        path = ClothoidChain().straight(20.0).clothoid_to(kappa_1, length).arc(30.0).to_path("ramp")
        path = path.with_speed(np.full(path.s_m.size, v))
        ratio, _ = car.steering_rate_ratios(path)
        change = math.atan(wheelbase * kappa_1 * min(window_m, length) / length)
        # The window holds whole samples: up to one 0.1 m spacing short of v W = 7.5 m (1.3%).
        expected = change / (car.max_road_wheel_rate_rad_s * STEERING_RATE_WINDOW_S)
        assert ratio.max() == pytest.approx(expected, rel=0.02)
        spans = infeasible_spans(path, car)
        if ratio.max() < 1.0:  # 0.32: 0.19 rad of wheel within 1.5 s, where the steering turns 0.6
            assert spans == ()
            continue
        (span,) = spans  # 1.10: the whole 0.66 rad within 1.2 s
        assert span.reason == STEERING_RATE and span.min_radius_m is None
        assert span.demand_ratio == pytest.approx(ratio.max(), rel=1e-12)
        assert 20.0 - window_m < span.start_s_m < 20.0 and span.end_s_m >= 26.0  # windows reaching past the ramp
        assert span.radius_m == pytest.approx(1 / kappa_1, rel=1e-6)


def test_unfollowable_turns_are_flagged_by_the_steering_rate(tmp_path: Path) -> None:
    """Two 90-degree turns 0.5 m apart, and a 3 m semicircle between straights: within the car's lock (1.43 m) but
    changing curvature faster than its steering follows at the planned speed; the loaded truck's lock rules out the
    turns too."""
    turns = _waypoint_file(tmp_path, "turns.csv", [(0.0, 0.0), (20.0, 0.0), (20.0, 0.5), (40.0, 0.5)])
    arc = [(3.0 * math.sin(a), 3.0 - 3.0 * math.cos(a)) for a in np.linspace(0.0, math.pi, 13)[1:-1]]
    semicircle = [(x, 0.0) for x in range(-20, 1)] + arc + [(x, 6.0) for x in range(0, -21, -1)]
    tight = _waypoint_file(tmp_path, "r3.csv", [(float(x), float(y)) for x, y in semicircle])
    car = make_vehicle("kinematic-bicycle")
    for file in (turns, tight):
        path = _planned(make_scenario(str(file)).path)
        spans = check_path(path, car)
        assert spans and {span.reason for span in spans} == {STEERING_RATE}, file.name
        assert max(span.demand_ratio for span in spans) > 1.1
        assert 1.0 / np.abs(path.curvature_1pm).max() > VehicleLimits.of(car).lock_radius_m  # within the lock
        (warning,) = feasibility_warnings(path.name, VehicleLimits.of(car), spans)
        assert warning.startswith(
            f"{file.stem} changes its curvature faster than the kinematic-bicycle's steering follows at the planned "
            "speed (its road wheels turn at most 23 deg/s: 34 deg in any 1.5 s) at s = "
        )
        assert re.search(r"s = \d+\.\d-\d+\.\d m \(the road-wheel angle asked for changes by 1\.\d\d times", warning)
    truck_spans = check_path(_planned(make_scenario(str(turns)).path), make_vehicle("tractor-semitrailer"))
    assert {span.reason for span in truck_spans} == {STEERING_LOCK}


def test_the_named_scenarios_ask_well_within_every_vehicles_steering_rate() -> None:
    for name in ("figure8", "dlc", "fig17"):
        for vehicle_name in ("kinematic-bicycle", "tractor-semitrailer"):
            vehicle = make_vehicle(vehicle_name)
            scenario = make_scenario(name, ScenarioOptions(vehicle_width_m=vehicle.geometry.width_m))
            for speed in (30.0, 100.0):
                path = _planned(scenario.path, speed_kmh=speed)
                ratio, _ = VehicleLimits.of(vehicle).steering_rate_ratios(path)
                assert ratio.max() < 0.4, (name, vehicle_name, speed)
                assert check_path(path, vehicle) == ()


def test_window_extremes_match_a_direct_search() -> None:
    rng = np.random.default_rng(3)
    values = rng.normal(size=500)
    first = np.arange(values.size)
    last = np.minimum(first + rng.integers(0, 40, size=values.size), values.size - 1)
    high, low = _range_extremes(values, first, last)
    assert np.array_equal(high, [values[a : b + 1].max() for a, b in zip(first, last, strict=True)])
    assert np.array_equal(low, [values[a : b + 1].min() for a, b in zip(first, last, strict=True)])


def test_a_steering_rate_span_is_written_with_its_ratio_and_no_minimum_radius() -> None:
    span = InfeasibleSpan(13.04, 24.11, 13.04, 2.7249, None, 15.04, STEERING_RATE, 1.3712)
    assert span.to_dict() == {
        "start_s_m": 13.04, "end_s_m": 24.11, "s_m": 13.04, "radius_m": 2.72, "min_radius_m": None,
        "speed_kmh": 15.0, "reason": "steering rate", "demand_ratio": 1.37,
    }  # fmt: skip
    with pytest.raises(WorkbenchInputError, match=r"demand_ratio must be a finite number > 0; got -1\.0"):
        InfeasibleSpan(13.0, 24.1, 13.0, 2.7, None, 15.0, STEERING_RATE, -1.0)


def test_a_path_starting_in_a_tight_curve_asks_the_straight_wheels_to_wind_in_at_once() -> None:
    """A 3 m circle: constant curvature, within the car's lock, but a run starts with the wheels straight and the
    0.71 rad the circle asks for take the car's steering 1.8 s (1.19 times what it turns in 1.5 s): flagged at the
    start only. A 30 m circle asks 0.086 rad: nothing."""
    car = make_vehicle("kinematic-bicycle")
    path = _planned(_circle(3.0))
    (span,) = check_path(path, car)
    limits = VehicleLimits.of(car)
    wind_in = math.atan(limits.wheelbase_m / 3.0) / (limits.max_road_wheel_rate_rad_s * STEERING_RATE_WINDOW_S)
    assert (span.reason, span.start_s_m) == (STEERING_RATE, 0.0)
    assert span.demand_ratio == pytest.approx(wind_in, rel=1e-6) and span.radius_m == pytest.approx(3.0, rel=1e-6)
    ratio, _ = limits.steering_rate_ratios(path)
    assert ratio[1:].max() < 1e-6  # elsewhere the angle asked for stays the same
    assert check_path(_planned(_circle(30.0)), car) == ()
