"""The lag-inverting feed-forward (`ClothoidConfig.feedforward_inversion`, `path_feedforward.lag_inverse_curvature`):
the default, its place in the two-degree-of-freedom form, the inversion against hand-computed values on paths whose
curvature is linear and quadratic in arc length, its wiring into the step, and that it leaves the feedback loop
(and so the lookahead floor) alone."""

from __future__ import annotations

import math

import numpy as np
import pytest

from controllers.base import Measurement
from controllers.clothoid import ClothoidConfig, ClothoidController
from controllers.clothoid import step_kernel as sk
from controllers.clothoid.path_feedforward import lag_inverse_curvature
from tuning.own_tuning import tuning_for
from workbench.base.clothoid_chain import ClothoidChain
from workbench.base.errors import WorkbenchInputError
from workbench.base.path_search import CompiledPath
from workbench.vehicles import make_vehicle

TRUCK = make_vehicle("tractor-semitrailer")
TRUCK_TUNING = tuning_for(TRUCK)
SPACING_M = 0.25
S_GRID = np.arange(0.0, 200.0 + SPACING_M / 2, SPACING_M)
#: A clothoid's curvature rate (1/m^2).
RATE_1PM2 = 4e-4


def _compiled(curvature: np.ndarray) -> CompiledPath:
    """An open path of S_GRID's samples with this curvature, compiled (only its curvature is read here)."""
    zeros = np.zeros_like(curvature)
    return CompiledPath.of((zeros, zeros, zeros, curvature, None), SPACING_M, float(S_GRID[-1]), False, 0.0, 5.0)


def _inverse(curvature: np.ndarray, s_m: float, **lag: float) -> tuple[float, float]:
    timing = {"speed_mps": 8.0, "dead_time_s": 0.25, "omega_n_rad_s": 20.0, "zeta": 1.5, "gain": 0.9, "window_m": 2.0}
    timing |= lag
    compiled = _compiled(curvature)
    return lag_inverse_curvature(
        compiled.table, compiled.record, s_m, timing["speed_mps"], timing["dead_time_s"], timing["omega_n_rad_s"],
        timing["zeta"], timing["gain"], timing["window_m"],
    )  # fmt: skip


def test_on_by_default_and_the_form_of_the_path_feedforward() -> None:
    """Default on; without the two-degree-of-freedom form there is no feed-forward to invert: the step keeps no
    feed-forward and integrates Eq. 3's feedback from the steering measured."""
    assert ClothoidConfig().feedforward_inversion is True
    with pytest.raises(WorkbenchInputError, match="feedforward_inversion"):
        ClothoidConfig(feedforward_inversion="yes")  # type: ignore[arg-type]
    path = ClothoidChain().straight(20.0).clothoid_to(RATE_1PM2 * 150.0, 150.0).to_path("ramp")
    config = ClothoidConfig(tuning=TRUCK_TUNING, path_feedforward=False)
    controller = ClothoidController(TRUCK.geometry, config, vehicle=TRUCK)
    controller.reset(path, 0.02)
    i, speed, g = round(80.0 / path.spacing_m), 8.0, TRUCK.geometry
    kappa = float(path.curvature_1pm[i])
    steer = math.atan(g.wheelbase_m * kappa) * g.steering_ratio
    m = Measurement(
        0.0, float(path.x_m[i]), float(path.y_m[i]), speed, 0.0, float(path.heading_rad[i]), speed * kappa, steer
    )
    controller.step(m, path)
    assert math.isnan(controller._state["feedforward_kappa"][0])
    assert abs(controller._state["kappa_cmd"][0] - kappa) < 0.05 * kappa  # one step of Eq. 3 from the steering


def test_a_constant_curvature_rate_is_the_curvature_ahead_plus_the_lags_first_order_lead() -> None:
    # kappa = c s: kappa(s + V T) + 2 zeta / wn V c, over K (the second derivative is 0)
    kappa, rate = _inverse(RATE_1PM2 * S_GRID, 50.0)
    expected = (RATE_1PM2 * (50.0 + 8.0 * 0.25) + 2 * 1.5 / 20.0 * 8.0 * RATE_1PM2) / 0.9
    assert kappa == pytest.approx(expected, rel=1e-9)
    assert rate == pytest.approx(RATE_1PM2 / 0.9, rel=1e-9)


def test_a_quadratic_curvature_adds_the_second_order_term() -> None:
    # kappa = a s^2 (central differences are exact on it at grid points): + (V / wn)^2 2 a
    a, s_ahead = 1e-5, 40.0 + 8.0 * 0.25
    kappa, _ = _inverse(a * S_GRID**2, 40.0)
    expected = (a * s_ahead**2 + 2 * 1.5 / 20.0 * 8.0 * 2 * a * s_ahead + (8.0 / 20.0) ** 2 * 2 * a) / 0.9
    assert kappa == pytest.approx(expected, rel=1e-9)


def test_without_an_identified_lag_it_is_the_path_curvature_there() -> None:
    kappa, _ = _inverse(RATE_1PM2 * S_GRID, 50.0, omega_n_rad_s=math.nan, dead_time_s=0.0, gain=1.0)
    assert kappa == pytest.approx(RATE_1PM2 * 50.0, rel=1e-12)


def test_the_step_sends_the_inverted_lag_of_the_vehicles_own_tuning() -> None:
    """On a clothoid, the feed-forward the step keeps is the truck's lag at its speed inverted by hand, and the
    integrator holds the rest of the steering (bumpless: feedback + feed-forward = the steering measured)."""
    path = ClothoidChain().straight(20.0).clothoid_to(RATE_1PM2 * 150.0, 150.0).to_path("ramp")
    speed, s0 = 8.0, 80.0
    i = round(s0 / path.spacing_m)
    known = 0.1
    config = ClothoidConfig(
        tuning=TRUCK_TUNING, feedforward_inversion=True, known_delay_s=known, feedforward_model="lag"
    )
    controller = ClothoidController(TRUCK.geometry, config, vehicle=TRUCK)
    controller.reset(path, 0.02)
    g = TRUCK.geometry
    steer = math.atan(g.wheelbase_m * float(path.curvature_1pm[i])) * g.steering_ratio
    yaw_rate = speed * float(path.curvature_1pm[i])
    x, y, heading = float(path.x_m[i]), float(path.y_m[i]), float(path.heading_rad[i])
    m = Measurement(0.0, x, y, speed, 0.0, heading, yaw_rate, steer)
    controller.step(m, path)
    lag = TRUCK_TUNING.lag_at(speed * 3.6)
    s_ahead = float(path.s_m[i]) + speed * (lag.delay_s + known)
    kappa_ahead = float(np.interp(s_ahead, path.s_m, path.curvature_1pm))
    expected = (kappa_ahead + 2 * lag.zeta / lag.omega_n_rad_s * speed * RATE_1PM2) / lag.steady_state_gain
    state = controller._state[0]
    assert state["feedforward_kappa"] == pytest.approx(expected, rel=1e-3)
    kappa_measured = math.tan(steer / g.steering_ratio) / g.wheelbase_m
    feedback_step = abs(state["kappa_cmd"] - (kappa_measured - expected))
    assert feedback_step < 0.05 * abs(expected)  # one step's integrated feedback only


def test_the_feedback_loop_and_its_floor_are_unchanged() -> None:
    """The feed-forward depends on the path alone: the loop the floor is computed on is the same with it on."""
    off = ClothoidController(
        TRUCK.geometry, ClothoidConfig(tuning=TRUCK_TUNING, feedforward_inversion=False), vehicle=TRUCK
    )
    on = ClothoidController(
        TRUCK.geometry, ClothoidConfig(tuning=TRUCK_TUNING, feedforward_inversion=True), vehicle=TRUCK
    )
    path = ClothoidChain().straight(50.0).to_path("straight")
    for controller in (off, on):
        controller.reset(path, 0.02)
    assert on.loop_settings(30.0) == off.loop_settings(30.0)
    assert on.lookahead_floor_m(30.0 / 3.6) == off.lookahead_floor_m(30.0 / 3.6) > 5.0


def _one_step(**options: object) -> float:
    """The steering command of one step on a clothoid ramp, the truck on the path at 8 m/s."""
    path = ClothoidChain().straight(20.0).clothoid_to(RATE_1PM2 * 150.0, 150.0).to_path("ramp")
    config = ClothoidConfig(tuning=TRUCK_TUNING, **{"feedforward_model": "lag", **options})
    controller = ClothoidController(TRUCK.geometry, config, vehicle=TRUCK)
    controller.reset(path, 0.02)
    i, speed, g = round(80.0 / path.spacing_m), 8.0, TRUCK.geometry
    kappa = float(path.curvature_1pm[i])
    steer = math.atan(g.wheelbase_m * kappa) * g.steering_ratio
    x, y, heading = float(path.x_m[i]), float(path.y_m[i]), float(path.heading_rad[i])
    return controller.step(Measurement(0.0, x, y, speed, 0.0, heading, speed * kappa, steer), path)


def test_the_lag_model_reference_is_on_by_default_and_acts_only_with_the_inversion_and_the_lags() -> None:
    assert ClothoidConfig().lag_model_reference is True
    assert _one_step(lag_model_reference=True) != _one_step(lag_model_reference=False)
    for without in ({"feedforward_inversion": False}, {"feedforward_model": "preview"}):
        assert _one_step(lag_model_reference=True, **without) == _one_step(lag_model_reference=False, **without)


def _reference(curvature: np.ndarray, s_m: float, measured: np.ndarray) -> float:
    path_lag = np.array([[20.0, 1.5, 0.25, 0.9]])  # wn, zeta, delay, K
    compiled = _compiled(curvature)
    return sk.reference_curvature(
        compiled.table, compiled.record, s_m, 8.0, path_lag, measured, np.array([30.0]), 2.0, np.empty(8)
    )


def test_the_reference_curvature_is_the_measured_lag_of_the_inverted_path_lag() -> None:
    """kappa = a s^2: kappa + c1 dkappa/dt + c2 d2kappa/dt2, Tp - Tm ahead, c1 = a_p - a_m, c2 = b_p - b_m - a_m c1
    (a = 2 zeta / wn, b = 1 / wn^2); without a measured lag the path's curvature there."""
    a = 1e-5
    curvature = a * S_GRID**2
    measured = np.array([[10.0, 0.8, 0.05, 0.95]])
    a_p, b_p, a_m, b_m = 2 * 1.5 / 20.0, 1 / 20.0**2, 2 * 0.8 / 10.0, 1 / 10.0**2
    s = 40.4 + 8.0 * (0.25 - 0.05)  # 42 m: on the grid, where the interpolated quadratic is exact
    c1, c2 = a_p - a_m, b_p - b_m - a_m * (a_p - a_m)
    expected = a * s**2 + c1 * 8.0 * 2 * a * s + c2 * 8.0**2 * 2 * a
    assert _reference(curvature, 40.4, measured) == pytest.approx(expected, rel=1e-9)
    assert _reference(curvature, 40.0, np.zeros((0, 4))) == pytest.approx(a * 40.0**2, rel=1e-12)


def test_on_an_arc_the_reference_is_the_paths_curvature_whatever_the_two_fitted_gains() -> None:
    """Steady turning: yaw rate / speed is the path's curvature, so the reference holds no steady offset even where
    the measured lag's fitted gain differs from the path lag's (0.95 against 0.9 here)."""
    arc = np.full(S_GRID.size, 0.04)
    measured = np.array([[10.0, 0.8, 0.05, 0.95]])
    assert _reference(arc, 60.0, measured) == pytest.approx(0.04, rel=1e-12)
