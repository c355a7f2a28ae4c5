"""Pure pursuit (`controllers/pure_pursuit.py`, compiled step) against its geometry: on a circle the arc through
the rear axle and the target is the circle itself; beside a straight line the curvature is -2 e / l_d^2."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from controllers.pure_pursuit import PurePursuit, PurePursuitConfig
from workbench.base.path import ReferencePath
from workbench.simulation.control_interface import Measurement
from workbench.vehicles.geometry import VehicleGeometry

GEOMETRY = VehicleGeometry(
    wheelbase_m=3.0, steering_ratio=16.0, max_road_wheel_angle_rad=0.6, max_steer_wheel_rate_rad_s=10.0, width_m=2.0
)


def _curvature(controller: PurePursuit) -> float:
    return controller.diagnostics["curvature_cmd_1pm"]


def _step(path: ReferencePath, x: float, y: float, yaw: float, speed: float, config: PurePursuitConfig) -> PurePursuit:
    controller = PurePursuit(GEOMETRY, config)
    controller.reset(path, 0.02)
    controller.step(Measurement(0.0, x, y, speed, 0.0, yaw, 0.0, 0.0), path)
    return controller


@settings(max_examples=40, deadline=None)
@given(radius=st.floats(15.0, 200.0), start=st.floats(0.0, 2.0 * math.pi), speed=st.floats(2.0, 25.0))
def test_on_a_circle_the_command_is_the_circles_curvature(radius: float, start: float, speed: float) -> None:
    angle = np.linspace(0.0, 2.0 * math.pi, 2000, endpoint=False)
    path = ReferencePath.from_xy(radius * np.cos(angle), radius * np.sin(angle), closed=True)
    x, y = radius * math.cos(start), radius * math.sin(start)
    controller = _step(path, x, y, start + math.pi / 2.0, speed, PurePursuitConfig())
    # the path's samples (0.1 m apart) are joined by chords: the target sits up to 0.1^2 / (8 R) m inside the circle,
    # which moves 2 sin(alpha) / l_d by up to ~2e-4 of 1 / R at R = 15 m and l_d = 4 m
    assert _curvature(controller) == pytest.approx(1.0 / radius, rel=5e-4)


@settings(max_examples=40, deadline=None)
@given(offset=st.floats(-2.0, 2.0), speed=st.floats(1.0, 40.0))
def test_beside_a_straight_line_the_curvature_is_minus_two_e_over_ld_squared(offset: float, speed: float) -> None:
    config = PurePursuitConfig()
    path = ReferencePath.from_xy(np.linspace(-50.0, 500.0, 12), np.zeros(12))
    controller = _step(path, 0.0, offset, 0.0, speed, config)
    lookahead = min(max(config.lookahead_gain_s * speed, config.min_lookahead_m), config.max_lookahead_m)
    lookahead = max(lookahead, abs(offset) + config.min_lookahead_m)
    diagnostics = controller.diagnostics
    assert diagnostics["lookahead_m"] == pytest.approx(lookahead, rel=1e-12)
    assert diagnostics["target_s_m"] == pytest.approx(50.0 + math.sqrt(lookahead**2 - offset**2), abs=1e-6)
    assert _curvature(controller) == pytest.approx(-2.0 * offset / lookahead**2, abs=1e-9)


def test_far_from_the_path_the_lookahead_reaches_past_the_offset() -> None:
    config = PurePursuitConfig(lookahead_gain_s=0.5, min_lookahead_m=4.0, max_lookahead_m=10.0)
    path = ReferencePath.from_xy(np.linspace(0.0, 500.0, 11), np.zeros(11))
    controller = _step(path, 100.0, 12.0, 0.0, 10.0, config)
    assert controller.diagnostics["lookahead_m"] == pytest.approx(16.0)
    # the target 16 m away on the line: (100 + sqrt(16^2 - 12^2), 0); the approach is within 45 degrees
    assert controller.diagnostics["target_s_m"] == pytest.approx(100.0 + math.sqrt(16.0**2 - 12.0**2), abs=1e-6)


def test_at_the_end_of_an_open_path_it_holds_the_paths_curvature() -> None:
    angle = np.linspace(0.0, math.pi / 2.0, 200)
    path = ReferencePath.from_xy(30.0 * np.cos(angle), 30.0 * np.sin(angle))
    controller = _step(path, 0.0, 30.0, math.pi, 5.0, PurePursuitConfig())
    assert controller.diagnostics["target_s_m"] == pytest.approx(path.length_m)
    assert _curvature(controller) == pytest.approx(1.0 / 30.0, rel=1e-3)
