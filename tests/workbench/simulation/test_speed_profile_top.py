"""The planned profile's top speed and what limited it (`SpeedProfile.top_speed`, `TopSpeedLimit`), against the
closed forms of each bound, and as a Simulation tells it (`plan_path_speed_and_top`, `Simulation.warnings`)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from controllers import PurePursuit
from workbench.base.clothoid_chain import ClothoidChain
from workbench.base.path import ReferencePath
from workbench.simulation.scenarios import Scenario, ScenarioOptions, make_scenario
from workbench.simulation.simulator import Simulation, SimulationConfig, plan_path_speed_and_top
from workbench.simulation.speed_profile import G_MPS2, SpeedLimits, TopSpeedLimit, plan_speed_profile
from workbench.vehicles import KinematicBicycle

LIMITS = SpeedLimits(max_speed_mps=30.0, max_lateral_accel_mps2=3.0, max_accel_mps2=1.0, max_decel_mps2=2.0)


def _line(length_m: float) -> tuple[np.ndarray, np.ndarray]:
    x = np.linspace(0.0, length_m, int(length_m) + 1)
    return x, np.zeros_like(x)


def test_a_long_straight_reaches_the_target() -> None:
    top = plan_speed_profile(*_line(100.0), LIMITS).top_speed()
    assert top.limit is TopSpeedLimit.TARGET and top.reached and top.top_mps == pytest.approx(30.0, rel=1e-12)
    assert top.reason() == "the target speed"


def test_a_circle_is_held_by_the_lateral_bound() -> None:
    radius = 40.0
    angles = np.linspace(0.0, 2 * math.pi, 252, endpoint=False)
    profile = plan_speed_profile(radius * np.cos(angles), radius * np.sin(angles), LIMITS, closed=True)
    top = profile.top_speed()
    assert top.limit is TopSpeedLimit.LATERAL_ACCELERATION and not top.reached
    assert top.top_mps == pytest.approx(math.sqrt(3.0 * radius), rel=2e-3)  # the quadratic fit's curvature error
    assert "lateral-acceleration bound of 0.306 g" in top.reason()


def test_a_short_straight_from_a_slow_start_is_held_by_the_acceleration() -> None:
    top = plan_speed_profile(*_line(100.0), LIMITS, initial_speed_mps=2.0).top_speed()
    assert top.limit is TopSpeedLimit.ACCELERATION
    assert top.top_mps == pytest.approx(math.sqrt(2.0**2 + 2 * 1.0 * 100.0), rel=1e-9)
    assert top.s_m == pytest.approx(100.0)


def test_a_short_straight_into_a_slow_end_is_held_by_the_braking() -> None:
    top = plan_speed_profile(*_line(100.0), LIMITS, final_speed_mps=2.0).top_speed()
    assert top.limit is TopSpeedLimit.BRAKING and top.s_m == 0.0
    assert top.top_mps == pytest.approx(math.sqrt(2.0**2 + 2 * 2.0 * 100.0), rel=1e-9)


def test_a_short_straight_between_slow_ends_is_held_by_both() -> None:
    top = plan_speed_profile(*_line(100.0), LIMITS, initial_speed_mps=2.0, final_speed_mps=2.0).top_speed()
    assert top.limit is TopSpeedLimit.ACCELERATION_AND_BRAKING
    # v^2 = 4 + 2 a s = 4 + 2 d (100 - s) meets at s = 2 d 100 / (2 a + 2 d) = 66.7 m (waypoints every 1 m)
    assert top.s_m == pytest.approx(200.0 / 3.0, abs=1.0)
    assert top.top_mps == pytest.approx(math.sqrt(4.0 + 2.0 * top.s_m), rel=1e-9)


def test_the_dlc_at_200_kmh_is_held_by_the_braking_into_the_lane_change() -> None:
    path = make_scenario("dlc", ScenarioOptions(vehicle_width_m=2.59)).path
    planned, top = plan_path_speed_and_top(path, SimulationConfig(speed_kmh=200.0))
    assert top.limit is TopSpeedLimit.BRAKING and not top.reached
    assert top.top_mps == pytest.approx(float(planned.speed_mps.max()), rel=1e-6)
    assert top.target_mps == pytest.approx(200.0 / 3.6)
    assert top.describe().startswith(f"target 200 km/h, planned top {top.top_mps * 3.6:.3g} km/h at s = 0 m")


def test_speeds_the_path_carries_that_lower_the_top_are_named() -> None:
    x, y = _line(100.0)
    path = ReferencePath.from_xy(x, y, speed_mps=np.full_like(x, 5.0), name="slow")
    planned, top = plan_path_speed_and_top(path, SimulationConfig(speed_kmh=50.0))
    assert top.limit is TopSpeedLimit.PATH_SPEED and top.top_mps == pytest.approx(5.0)
    assert float(planned.speed_mps.max()) == pytest.approx(5.0)
    assert top.reason() == "the speeds the path's waypoints carry"


def test_a_simulation_warns_of_a_top_short_of_the_target() -> None:
    vehicle = KinematicBicycle()
    straight = ClothoidChain().straight(60.0).to_path("short")
    config = SimulationConfig(speed_kmh=200.0, max_lateral_accel_g=3.0 / G_MPS2)
    reached = Simulation(Scenario("short", straight, "t"), vehicle, PurePursuit(vehicle.geometry), SimulationConfig())
    assert reached.top_speed.reached and reached.warnings() == []
    circle = ClothoidChain(curvature_1pm=1 / 40.0).arc(2 * math.pi * 40.0).to_path("circle", closed=True)
    short = Simulation(Scenario("circle", circle, "t"), vehicle, PurePursuit(vehicle.geometry), config)
    (warning,) = short.warnings("circle: pp")
    assert warning.startswith("circle: pp: target 200 km/h, planned top ") and "lateral-acceleration" in warning
