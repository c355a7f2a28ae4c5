"""The check of a path against the vehicle before a run (issue 20, item 13): steering lock (with understeer at the
planned speed), rollover and tyre grip, merged into spans along the path, and the warning that names them."""

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
    TYRE_GRIP,
    InfeasibleSpan,
    VehicleLimits,
    check_path,
    feasibility_warnings,
    infeasible_spans,
)
from workbench.simulation.run_config import SimulationConfig
from workbench.simulation.scenarios import make_scenario
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
    with pytest.raises(WorkbenchInputError, match=r"reason must be one of steering lock, rollover, tyre grip"):
        InfeasibleSpan(0.0, 1.0, 0.5, 6.5, 9.4, 15.0, "too tight")
    span = InfeasibleSpan(60.971, 79.456, 77.4712, 5.8234, 9.3012, 15.24, STEERING_LOCK)
    assert span.to_dict() == {
        "start_s_m": 60.97, "end_s_m": 79.46, "s_m": 77.47, "radius_m": 5.82, "min_radius_m": 9.3,
        "speed_kmh": 15.2, "reason": "steering lock",
    }  # fmt: skip
