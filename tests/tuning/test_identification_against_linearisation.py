"""The lags `tuning schedule` identifies (Eq. 5 with a delay, fitted to the dlc, step-series and chirp logs at
0.1 g), checked against the vehicle model itself: its linearisation about straight driving, by finite differences
of `vehicle.advance` over one 20 ms step, turned into a continuous-time model (the matrix logarithm of the step
with its zero-order-hold input) and evaluated at 0.5-8 rad/s.

Outputs (`vehicle.outputs`): the rear-axle course heading yaw + atan2(vy, vx), whose rate over the speed is the
path curvature (what `fit-lag --curvature-from path` measures from x, y), and yaw rate / speed, the measured
curvature (`--curvature-from yaw-rate`); each per kinematic curvature of the steering wheel, 1 / (steering ratio x
wheelbase) per rad. Measured at 30 km/h, largest errors over 0.5-8 rad/s (gain ratio - 1, phase difference):

    tractor-semitrailer  path 5.9 %, 1.9 deg (at 8 rad/s 0.70 at -159 deg against the truck's 0.74 at -157 deg;
                         Eq. 5 without a delay, fitted to the dlc and steps, gave 0.25 at -131 deg)
                         measured 2.4 %, 2.0 deg
    dynamic-bicycle      path 0.4 %, 0.3 deg; measured 0.4 %, 0.3 deg

The shipped lags (all speeds, `python -m tuning.preset_tuning`) against the same linearisation: the truck's path lag
15 / 6 / 20 / 32 % at 10 / 30 / 60 / 100 km/h (at speed the truck's response has a bump near 3-4 rad/s, its
trailer's yaw mode presumably, which Eq. 5 cannot follow), its measured lag 5 / 2 / 9 / 23 %; both cars within 2 %
and 1 deg at every speed.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from scipy import linalg

from tuning.lag_fit import LagFitOptions, fit_lag
from tuning.schedule import identification_logs
from workbench.vehicles import make_vehicle
from workbench.vehicles.base import VehicleModel
from workbench.vehicles.steering_lag import SteeringLag

STEP_S = 0.02
OMEGA_RAD_S = np.geomspace(0.5, 8.0, 13)
#: (gain, phase deg) tolerances per vehicle: a quarter to a half of what is measured would be too tight for a
#: change of the fit's start grid; a tenth of the brief's 20 % / 20 deg for the car, a half for the truck.
TOLERANCES = {"tractor-semitrailer": (0.10, 5.0), "dynamic-bicycle": (0.02, 2.0)}


def linearised_responses(vehicle: VehicleModel, speed_kmh: float, omega: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(path curvature, yaw rate / speed) per kinematic curvature, complex, at omega (rad/s), of the vehicle
    linearised about straight driving at speed_kmh."""
    v = speed_kmh / 3.6
    x0 = vehicle.initial_state(0.0, 0.0, 0.0, v)
    n = x0.size
    substeps = round(STEP_S / 1e-3)

    def step(x: np.ndarray, steer: float) -> np.ndarray:
        return vehicle.advance(x, steer, 0.0, STEP_S, substeps)

    def measure(x: np.ndarray, steer: float) -> np.ndarray:
        out = vehicle.outputs(x, steer, 0.0)
        _, _, yaw, vx, vy, yaw_rate = out[:6]
        return np.array([yaw + math.atan2(vy, vx), yaw_rate / math.hypot(vx, vy)])

    a, b = np.zeros((n, n)), np.zeros((n, 1))
    c, d = np.zeros((2, n)), np.zeros((2, 1))
    for i in range(n):
        e = np.zeros(n)
        e[i] = 1e-6 * max(1.0, abs(x0[i]))
        a[:, i] = (step(x0 + e, 0.0) - step(x0 - e, 0.0)) / (2 * e[i])
        c[:, i] = (measure(x0 + e, 0.0) - measure(x0 - e, 0.0)) / (2 * e[i])
    h = 1e-6
    b[:, 0] = (step(x0, h) - step(x0, -h)) / (2 * h)
    d[:, 0] = (measure(x0, h) - measure(x0, -h)) / (2 * h)
    # x+ = A x + B u with u held over the step: [[A, B], [0, 1]] = expm([[Ac, Bc], [0, 0]] T)
    m = np.zeros((n + 1, n + 1))
    m[:n, :n], m[:n, n:], m[n, n] = a, b, 1.0
    with warnings.catch_warnings():  # scipy warns of an error estimate over 1000 eps (it is ~1e-11): checked below
        warnings.filterwarnings("ignore", "logm result may be inaccurate", RuntimeWarning)
        log = linalg.logm(m).real
    assert np.max(np.abs(linalg.expm(log) - m)) < 1e-9 * np.max(np.abs(m))
    log /= STEP_S
    ac, bc = log[:n, :n], log[:n, n:]
    response = np.array([(c @ np.linalg.solve(1j * w * np.eye(n) - ac, bc))[:, 0] + d[:, 0] for w in omega])
    g = vehicle.geometry
    per_kinematic = g.steering_ratio * g.wheelbase_m  # steering-wheel rad per 1/m of kinematic curvature
    path = 1j * omega * response[:, 0] / v * per_kinematic
    measured = response[:, 1] * per_kinematic
    return path, measured


def lag_response(lag: SteeringLag, omega: np.ndarray) -> np.ndarray:
    s = 1j * omega
    wn, zeta = lag.omega_n_rad_s, lag.zeta
    return lag.steady_state_gain * wn**2 / (s * s + 2 * zeta * wn * s + wn**2) * np.exp(-s * lag.delay_s)


def errors(model: np.ndarray, truth: np.ndarray) -> tuple[float, float]:
    """Largest |gain ratio - 1| and |phase difference| (deg)."""
    ratio = model / truth
    return float(np.max(np.abs(np.abs(ratio) - 1.0))), float(np.max(np.abs(np.degrees(np.angle(ratio)))))


@pytest.fixture(scope="module", params=sorted(TOLERANCES))
def identified(request):
    vehicle = make_vehicle(request.param)
    logs = identification_logs(vehicle, 30.0)
    path = fit_lag(logs, vehicle.geometry, LagFitOptions(fit_delay=True)).lag
    measured = fit_lag(logs, vehicle.geometry, LagFitOptions(fit_delay=True, curvature_from="yaw-rate")).lag
    truth = linearised_responses(vehicle, 30.0, OMEGA_RAD_S)
    return request.param, path, measured, truth


def test_the_identified_path_lag_is_the_vehicles_own_response(identified) -> None:
    name, path, _, (truth, _) = identified
    gain_error, phase_error = errors(lag_response(path, OMEGA_RAD_S), truth)
    gain_tol, phase_tol = TOLERANCES[name]
    assert gain_error < gain_tol and phase_error < phase_tol, (name, path, gain_error, phase_error)
    assert path.zeta <= 2.0 and path.delay_s > 0.0


def test_the_identified_measured_lag_is_the_vehicles_own_yaw_rate_response(identified) -> None:
    name, _, measured, (_, truth) = identified
    gain_error, phase_error = errors(lag_response(measured, OMEGA_RAD_S), truth)
    gain_tol, phase_tol = TOLERANCES[name]
    assert gain_error < gain_tol and phase_error < phase_tol, (name, measured, gain_error, phase_error)


def test_the_trucks_path_lag_needs_its_delay() -> None:
    """At 30 km/h and 8 rad/s the loaded truck's steering-to-path-curvature response is 0.74 at -157 deg, which
    Eq. 5 without a delay cannot follow (0.25 at -131 deg fitted to the dlc and step-series logs)."""
    truck = make_vehicle("tractor-semitrailer")
    truth, _ = linearised_responses(truck, 30.0, np.array([8.0]))
    assert abs(truth[0]) == pytest.approx(0.74, abs=0.02)
    assert math.degrees(np.angle(truth[0])) == pytest.approx(-157.0, abs=2.0)
