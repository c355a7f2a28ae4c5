"""The single track's steady-state slip angles (`SingleTrackParams.steady_slip_angles_rad`) against the magic
formula they invert and the linear tyre they start from."""

from __future__ import annotations

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from workbench.vehicles import make_vehicle
from workbench.vehicles.single_track import PredictionParams, SingleTrackParams

TRACK = make_vehicle("dynamic-bicycle").single_track().single_track


def _force(alpha: float, peak: float, stiffness: float, shape: float) -> float:
    """The magic formula with E = 0: D sin(C atan(B alpha)), B = stiffness / (C D)."""
    return peak * math.sin(shape * math.atan(stiffness / (shape * peak) * alpha))


@settings(max_examples=50, deadline=None)
@given(lateral_accel=st.floats(-6.0, 6.0))
def test_the_slips_give_the_axle_forces_that_hold_the_turn(lateral_accel: float) -> None:
    """Each axle's force at its slip is its share of m a_y: b / L at the front, a / L at the rear."""
    alpha_f, alpha_r = TRACK.steady_slip_angles_rad(lateral_accel)
    mass, a, b = TRACK.mass_kg, TRACK.cg_to_front_axle_m, TRACK.cg_to_rear_axle_m
    shape = TRACK.tyre_shape_factor
    front = _force(alpha_f, TRACK.front_peak_force_n, TRACK.front_cornering_stiffness_n_per_rad, shape)
    rear = _force(alpha_r, TRACK.rear_peak_force_n, TRACK.rear_cornering_stiffness_n_per_rad, shape)
    assert front == pytest.approx(mass * lateral_accel * b / (a + b), rel=1e-9, abs=1e-6)
    assert rear == pytest.approx(mass * lateral_accel * a / (a + b), rel=1e-9, abs=1e-6)


def test_small_slips_are_the_linear_tyres_and_their_difference_the_understeer() -> None:
    alpha_f, alpha_r = TRACK.steady_slip_angles_rad(0.01)
    assert (alpha_f - alpha_r) / 0.01 == pytest.approx(TRACK.understeer_gradient_rad_per_mps2(), rel=1e-4)
    assert TRACK.steady_slip_angles_rad(0.0) == (0.0, 0.0)


def test_beyond_the_peak_the_slip_is_that_of_99_percent_of_it() -> None:
    track = SingleTrackParams(1500.0, 2500.0, 1.2, 1.4, 80_000.0, 90_000.0, 7000.0, 8000.0)
    alpha_f, alpha_r = track.steady_slip_angles_rad(50.0)  # 5 g: far beyond either axle's peak
    shape = track.tyre_shape_factor
    assert _force(alpha_f, 7000.0, 80_000.0, shape) == pytest.approx(0.99 * 7000.0, rel=1e-9)
    assert _force(alpha_r, 8000.0, 90_000.0, shape) == pytest.approx(0.99 * 8000.0, rel=1e-9)
    assert track.steady_slip_angles_rad(-50.0) == (-alpha_f, -alpha_r)


@pytest.mark.parametrize("name", ["kinematic-bicycle", "dynamic-bicycle", "tractor-semitrailer"])
def test_a_models_prediction_carries_its_actuator_from_its_params(name: str) -> None:
    model = make_vehicle(name)
    prediction, p = model.single_track(), model.params
    assert prediction == PredictionParams.from_actuator(
        p, prediction.wheelbase_m, prediction.source, prediction.single_track, prediction.lag
    )
    assert (prediction.steering_ratio, prediction.max_road_wheel_angle_rad) == (
        p.steering_ratio,
        p.max_road_wheel_angle_rad,
    )
    assert (prediction.max_road_wheel_rate_rad_s, prediction.steering_time_constant_s) == (
        p.max_road_wheel_rate_rad_s,
        p.steering_time_constant_s,
    )
