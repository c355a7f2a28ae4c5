"""CommonRoad multi-body adapter: reference-point conversion, agreement with our dynamic bicycle, cost."""

from __future__ import annotations

import math

import numpy as np
import pytest

from workbench.base.errors import WorkbenchInputError
from workbench.vehicles import CommonRoadMB, CommonRoadMBParams, DynamicBicycle

MB = CommonRoadMB()
OUT = {name: i for i, name in enumerate(MB.output_names)}


def test_outputs_are_at_the_rear_axle_centre() -> None:
    state = MB.initial_state(10.0, -5.0, 0.7, 12.0)
    b = MB._cr.b
    assert (state[0], state[1]) == pytest.approx((10.0 + b * math.cos(0.7), -5.0 + b * math.sin(0.7)))
    out = MB.outputs(state, 0.0, 0.0)
    assert out[OUT["x_m"]] == pytest.approx(10.0) and out[OUT["y_m"]] == pytest.approx(-5.0)
    assert out[OUT["yaw_rad"]] == 0.7 and out[OUT["vx_mps"]] == pytest.approx(12.0)
    assert len(out) == len(MB.output_names)


def test_straight_running_stays_straight() -> None:
    # CommonRoad's tyres have small offsets (p_hy1, p_vy1): measured 3 mm of drift over 50 m.
    state = MB.initial_state(0.0, 0.0, 0.0, 10.0)
    for _ in range(250):
        state = MB.advance(state, 0.0, 0.0, 0.02, 20)
    out = MB.outputs(state, 0.0, 0.0)
    assert out[OUT["x_m"]] == pytest.approx(50.0, abs=0.05)
    assert abs(out[OUT["y_m"]]) < 0.01


def test_step_steer_agrees_with_our_dynamic_bicycle() -> None:
    # Both built on CommonRoad vehicle 2. 10 m/s, 0.5 rad at the steering wheel (~0.13 g): measured steady yaw
    # rate 0.1295 (MB) vs 0.1293 rad/s (ours), rear-axle positions after 5 s within 0.13 m.
    car = DynamicBicycle()
    mb_state, car_state = MB.initial_state(0.0, 0.0, 0.0, 10.0), car.initial_state(0.0, 0.0, 0.0, 10.0)
    for _ in range(250):
        mb_state = MB.advance(mb_state, 0.5, 0.0, 0.02, 20)
        car_state = car.advance(car_state, 0.5, 0.0, 0.02, 20)
    mb_out, car_out = MB.outputs(mb_state, 0.5, 0.0), car.outputs(car_state, 0.5, 0.0)
    assert mb_out[OUT["yaw_rate_rad_s"]] == pytest.approx(car_out[5], rel=0.02)
    assert math.hypot(mb_out[0] - car_out[0], mb_out[1] - car_out[1]) < 0.3
    assert mb_out[OUT["path_curvature_1pm"]] == pytest.approx(car_out[-1], rel=0.03)


def test_from_rest_on_full_lock_is_finite() -> None:
    state = MB.initial_state(0.0, 0.0, 0.0, 0.0)
    for _ in range(100):
        state = MB.advance(state, 20.0, 1.0, 0.02, 20)
    assert np.all(np.isfinite(state)) and np.all(np.isfinite(MB.outputs(state, 20.0, 1.0)))
    assert 0.5 < state[3] < 2.5  # measured 1.22 m/s: full lock scrubs speed


def test_a_spin_out_ends_in_a_non_finite_state_not_an_exception() -> None:
    # 0.5 rad at the steering wheel at 30 m/s asks for 1.2 g: the car spins, a wheel stops and CommonRoad's
    # slip formula divides by zero. The simulator reports non-finite states as a diverged run.
    state = MB.initial_state(0.0, 0.0, 0.0, 30.0)
    for _ in range(100):
        state = MB.advance(state, 0.5, 0.0, 0.02, 20)
    assert not np.all(np.isfinite(state))


def test_bad_parameters_are_rejected() -> None:
    with pytest.raises(WorkbenchInputError, match="vehicle_id must be 1, 2 or 3"):
        CommonRoadMB(CommonRoadMBParams(vehicle_id=4))
    with pytest.raises(WorkbenchInputError, match=r"max_step_s must be a finite number in \[1e-05, 0.01\] s"):
        CommonRoadMB(CommonRoadMBParams(max_step_s=0.1))
