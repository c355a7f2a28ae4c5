"""Curvature limits: defaults from the vehicle's geometry, the CSV table format, interpolation, bad files."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from controllers.clothoid.curvature_limits import G_MPS2, CurvatureLimits
from workbench.vehicles import make_vehicle

TRUCK = make_vehicle("tractor-semitrailer").geometry


def test_default_limits_follow_lock_lateral_accel_and_steering_rate() -> None:
    limits = CurvatureLimits.default_for(TRUCK, max_lateral_accel_g=0.4)
    lock = math.tan(TRUCK.max_road_wheel_angle_rad) / TRUCK.wheelbase_m
    kappa, rate = limits.at_speed(0.0)
    assert kappa == pytest.approx(lock, rel=1e-12)  # at standstill only the steering lock limits
    for kmh in (30.0, 60.0, 90.0):
        v = kmh / 3.6
        kappa, rate = limits.at_speed(v)
        assert kappa == pytest.approx(min(lock, 0.4 * G_MPS2 / v**2), rel=1e-9)
        assert rate == pytest.approx(TRUCK.max_steer_wheel_rate_rad_s / TRUCK.steering_ratio / TRUCK.wheelbase_m)
    # Limits fall with speed, as Figure 6's rollover limits do.
    kappas = [limits.at_speed(kmh / 3.6)[0] for kmh in range(20, 150, 10)]
    assert all(b < a for a, b in itertools.pairwise(kappas))


@settings(max_examples=300, deadline=None)
@given(
    st.lists(st.floats(0.01, 1.0), min_size=1, max_size=8),
    st.floats(-10.0, 200.0),
)
def test_interpolation_is_numpys_clamped_linear_one(values: list[float], speed_kmh: float) -> None:
    speeds = tuple(10.0 * (i + 1) for i in range(len(values)))
    rates = tuple(2.0 * v for v in values)
    limits = CurvatureLimits(speeds, tuple(values), rates)
    kappa, rate = limits.at_speed(speed_kmh / 3.6)
    assert kappa == pytest.approx(float(np.interp(speed_kmh, speeds, values)), rel=1e-12, abs=1e-15)
    assert rate == pytest.approx(float(np.interp(speed_kmh, speeds, rates)), rel=1e-12, abs=1e-15)
