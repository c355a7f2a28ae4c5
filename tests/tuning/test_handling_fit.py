"""The handling gain from steady turns (`tuning/handling_fit.py`): steady_turn against logs whose steady turn is known
exactly, the unsteady ones refused; fit_handling's gain against np.interp of the ratios (held beyond), ones with
fewer than two turns, its refusals; and on the truck, steady turns against the preview taps identified
independently from the dlc, step-series and chirp logs (their sum is the steady-state steering per curvature)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.constants import g as G_MPS2

from controllers.clothoid.preview_model import HANDLING_GRID_G
from tuning.handling_fit import STEADY_TOLERANCE, STEADY_WINDOW_S, fit_handling, steady_turn
from tuning.lag_fit import SteeringGeometry
from tuning.log_file import VehicleLog
from tuning.own_tuning import tuning_for
from tuning.preview_fit import PreviewFitOptions
from tuning.schedule import handling_logs
from workbench.base.errors import WorkbenchInputError
from workbench.vehicles import make_vehicle

GEOMETRY = SteeringGeometry(wheelbase_m=3.0, steering_ratio=16.0)
SPEED_MPS = 8.0


def _turn_log(lat_accel_g: float, ratio: float, wobble: float = 0.0, duration_s: float = 10.0) -> VehicleLog:
    """A held steering whose yaw rate / speed gives lat_accel_g at SPEED_MPS, the steering's kinematic curvature
    ratio times it; wobble: a relative 1 Hz oscillation of the yaw rate."""
    t = np.arange(0.0, duration_s + 1e-9, 0.01)
    kappa = lat_accel_g * G_MPS2 / SPEED_MPS**2
    steer = GEOMETRY.steering_ratio * math.atan(GEOMETRY.wheelbase_m * ratio * kappa)
    yaw_rate = SPEED_MPS * kappa * (1.0 + wobble * np.sin(2 * math.pi * t))
    return VehicleLog(
        f"turn {lat_accel_g:g} g", t, np.full(t.size, steer), np.full(t.size, SPEED_MPS), yaw_rate_rad_s=yaw_rate
    )


def test_a_steady_turn_gives_its_lateral_acceleration_and_steering_ratio() -> None:
    turn = steady_turn(_turn_log(0.2, 1.05), GEOMETRY)
    assert turn is not None
    assert turn.lat_accel_g == pytest.approx(0.2, rel=1e-12)
    assert turn.steering_ratio == pytest.approx(1.05, rel=1e-12)


def test_an_oscillating_or_short_turn_is_not_steady() -> None:
    assert steady_turn(_turn_log(0.2, 1.05, wobble=0.6 * STEADY_TOLERANCE), GEOMETRY) is None  # peak-to-peak 1.2 x
    assert steady_turn(_turn_log(0.2, 1.05, wobble=0.4 * STEADY_TOLERANCE), GEOMETRY) is not None
    with pytest.raises(WorkbenchInputError, match=f"last {STEADY_WINDOW_S:g} s; the log lasts 2 s"):
        steady_turn(_turn_log(0.2, 1.05, duration_s=2.0), GEOMETRY)


def test_the_gain_is_the_ratios_interpolated_over_the_one_at_the_reference() -> None:
    accel, ratio = (0.05, 0.1, 0.2, 0.3), (1.0, 1.01, 1.04, 1.1)
    logs = [_turn_log(a, r) for a, r in zip(accel, ratio, strict=True)]
    logs.append(_turn_log(0.2, 1.0, wobble=0.1))  # unsteady: left out
    fit = fit_handling(logs[::-1], GEOMETRY, 0.1)
    assert [t.lat_accel_g for t in fit.turns] == pytest.approx(accel, rel=1e-12)
    expected = np.interp(HANDLING_GRID_G, accel, ratio) / 1.01
    assert fit.gain == pytest.approx(tuple(expected), rel=1e-12)
    assert fit.gain[HANDLING_GRID_G.index(0.4)] == pytest.approx(1.1 / 1.01, rel=1e-12)  # held beyond 0.3 g
    assert "4 steady turns 0.05-0.3 g" in fit.summary()


def test_fewer_than_two_steady_turns_give_ones() -> None:
    fit = fit_handling([_turn_log(0.1, 1.2), _turn_log(0.3, 1.0, wobble=0.1)], GEOMETRY, 0.1)
    assert fit.gain == (1.0,) * len(HANDLING_GRID_G)
    assert len(fit.turns) == 1


def test_a_gain_out_of_range_and_a_bad_reference_are_refused() -> None:
    logs = [_turn_log(0.05, 1.0), _turn_log(0.3, 2.5)]
    with pytest.raises(WorkbenchInputError, match=r"reaches 1-2.5 .* allowed 0.5-2"):
        fit_handling(logs, GEOMETRY, 0.05)
    with pytest.raises(WorkbenchInputError, match="reference_g"):
        fit_handling(logs, GEOMETRY, math.nan)


def test_the_trucks_steady_turns_agree_with_its_preview_taps_and_grow_with_lateral_acceleration() -> None:
    """At 30 km/h, the steady turn at the preview taps' identification amplitude (0.2 g) takes the steering per
    curvature the taps sum to (fitted to other maneuvers: dlc, step-series, chirp), within 1 %; understeer grows
    with lateral acceleration (the gain rises monotonically, to a few percent at 0.35 g) and the shipped tuning holds
    this gain."""
    truck = make_vehicle("tractor-semitrailer")
    amplitude = PreviewFitOptions().lat_accel_g
    fit = fit_handling(handling_logs(truck, 30.0), truck.geometry, amplitude)
    tuning = tuning_for(truck)
    speeds = tuning.lag_speeds_kmh
    _, _, steering, _ = tuning.preview_tables
    taps_sum = float(steering[speeds.index(30.0)].sum())
    near = min(fit.turns, key=lambda t: abs(t.lat_accel_g - amplitude))
    assert near.steering_ratio == pytest.approx(taps_sum, rel=0.01)
    assert len(fit.turns) >= 6
    assert np.all(np.diff(fit.gain) >= -1e-12)
    assert 1.01 < fit.gain[HANDLING_GRID_G.index(0.35)] < 1.2
    assert fit.gain[HANDLING_GRID_G.index(0.05)] < 1.0
    assert tuning.handling_table[speeds.index(30.0)] == pytest.approx(fit.gain, rel=1e-6)
