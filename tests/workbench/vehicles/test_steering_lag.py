"""The steering lag of Eq. 5 and its file, shared by the tuning CLI, the clothoid controller and the MPC: the
bounds, and each form of the lag (transfer function, frequency response, state space, discrete simulation, ODE)
against independent references (python-control, the textbook step responses)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import control
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tuning import lag_fit
from workbench.base.errors import WorkbenchInputError, range_text
from workbench.vehicles.steering_lag import (
    DELAY_BOUNDS,
    GAIN_BOUNDS,
    OMEGA_N_BOUNDS,
    ZETA_BOUNDS,
    SteeringLag,
    discrete_coefficients,
    read_lag_file,
    simulate_lag,
    write_lag_file,
)


@given(
    wn=st.floats(0.05, 200.0),
    zeta=st.floats(0.05, 10.0),
    delay=st.floats(0.0, 2.0),
    gain=st.floats(0.05, 20.0),
    nrmse=st.one_of(st.just(math.nan), st.floats(0.0, 1.0)),
)
def test_round_trip(wn: float, zeta: float, delay: float, gain: float, nrmse: float, tmp_path_factory) -> None:
    lag = SteeringLag(wn, zeta, delay, steady_state_gain=gain, nrmse=nrmse, speed_range_mps=(5.0, 9.0), source="t")
    back = read_lag_file(write_lag_file(lag, tmp_path_factory.mktemp("lag") / "lag.json"))
    assert back.omega_n_rad_s == wn and back.zeta == zeta and back.delay_s == delay and back.steady_state_gain == gain
    assert back.speed_range_mps == (5.0, 9.0) and back.source == "t"
    assert (math.isnan(back.nrmse) and math.isnan(nrmse)) or back.nrmse == nrmse


@pytest.mark.parametrize(
    ("content", "needle"),
    [
        ("{", "not valid JSON"),
        ("[1, 2]", "must hold a JSON object"),
        ('{"format": "steering-lag/1", "zeta": 0.8}', "missing keys ['omega_n_rad_s']"),
        ('{"format": "steering-lag/1", "omega_n_rad_s": 4, "zeta": 0.8, "wn": 3}', "unknown keys ['wn']"),
        ('{"format": "lead-filter/1", "omega_n_rad_s": 4, "zeta": 0.8}', "format must be 'steering-lag/1'"),
        ('{"format": "steering-lag/1", "omega_n_rad_s": -4, "zeta": 0.8}', "omega_n_rad_s must be a finite number in"),
        ('{"format": "steering-lag/1", "omega_n_rad_s": 4, "zeta": 0.8, "speed_range_mps": [9]}', "[low, high]"),
        ('{"format": "steering-lag/1", "omega_n_rad_s": 4, "zeta": 0.8, "steady_state_gain": 0}', "steady_state_gain"),
    ],
)
def test_bad_files_get_a_clear_error(content: str, needle: str, tmp_path: Path) -> None:
    path = tmp_path / "lag.json"
    path.write_text(content)
    with pytest.raises(WorkbenchInputError) as info:
        read_lag_file(path)
    assert needle in str(info.value) and "lag.json" in str(info.value)


def test_missing_file_and_nan_values() -> None:
    with pytest.raises(WorkbenchInputError, match=r"lag\.json': no such file"):
        read_lag_file("/nonexistent/lag.json")
    with pytest.raises(WorkbenchInputError, match="zeta"):
        SteeringLag(4.0, float("nan"))
    assert json.loads(json.dumps(SteeringLag(4.0, 0.8).to_dict()))["format"] == "steering-lag/1"


def test_a_folder_or_a_deeply_nested_file_is_refused(tmp_path: Path) -> None:
    with pytest.raises(WorkbenchInputError, match="a folder, not a file"):
        read_lag_file(tmp_path)
    deep = tmp_path / "deep.json"
    deep.write_text("[" * 5000 + "]" * 5000)
    with pytest.raises(WorkbenchInputError, match=r"deep\.json': nested deeper than 64 levels"):
        read_lag_file(deep)


# ---- the lag's one home: bounds, transfer function, frequency response, simulation, ODE ------------------------

LAGS = [
    SteeringLag(4.3, 0.3, steady_state_gain=0.94),  # underdamped
    SteeringLag(3.0, 1.0),  # critically damped
    SteeringLag(9.3, 2.0, 0.2, steady_state_gain=0.79),  # overdamped, with a delay
    SteeringLag(0.5, 6.0, 0.05, steady_state_gain=1.5),
]


def analytic_step(wn: float, zeta: float, t: np.ndarray) -> np.ndarray:
    """Unit step response of wn^2 / (s^2 + 2 zeta wn s + wn^2) from rest, textbook closed forms."""
    t = np.asarray(t, dtype=float)
    if zeta < 1.0:
        wd = wn * math.sqrt(1.0 - zeta**2)
        return 1.0 - np.exp(-zeta * wn * t) * (np.cos(wd * t) + zeta / math.sqrt(1.0 - zeta**2) * np.sin(wd * t))
    if zeta == 1.0:
        return 1.0 - np.exp(-wn * t) * (1.0 + wn * t)
    root = math.sqrt(zeta**2 - 1.0)
    p1, p2 = wn * (zeta - root), wn * (zeta + root)
    return 1.0 - (p2 * np.exp(-p1 * t) - p1 * np.exp(-p2 * t)) / (p2 - p1)


@pytest.mark.parametrize(
    ("name", "value", "bounds"),
    [
        ("omega_n_rad_s", 0.049, OMEGA_N_BOUNDS),
        ("omega_n_rad_s", 200.5, OMEGA_N_BOUNDS),
        ("zeta", 0.04, ZETA_BOUNDS),
        ("zeta", 10.5, ZETA_BOUNDS),
        ("delay_s", -0.01, DELAY_BOUNDS),
        ("delay_s", 2.5, DELAY_BOUNDS),
        ("steady_state_gain", 0.04, GAIN_BOUNDS),
        ("steady_state_gain", 21.0, GAIN_BOUNDS),
        ("zeta", math.inf, ZETA_BOUNDS),
    ],
)
def test_bounds_are_refused_naming_the_value_and_the_range(name: str, value: float, bounds: tuple) -> None:
    kwargs = {"omega_n_rad_s": 4.0, "zeta": 0.8, name: value}
    with pytest.raises(WorkbenchInputError) as info:
        SteeringLag(**kwargs)
    message = str(info.value)
    assert message.startswith(name) and range_text(*bounds) in message and repr(value) in message
    edge = {"omega_n_rad_s": 4.0, "zeta": 0.8, name: bounds[0 if value < bounds[0] else 1]}
    assert getattr(SteeringLag(**edge), name) == edge[name]  # the bounds themselves are accepted


def test_the_fit_searches_the_bounds_the_lag_accepts() -> None:
    assert (lag_fit.OMEGA_N_BOUNDS, lag_fit.ZETA_BOUNDS, lag_fit.GAIN_BOUNDS, lag_fit.DELAY_BOUNDS) == (
        OMEGA_N_BOUNDS,
        ZETA_BOUNDS,
        GAIN_BOUNDS,
        DELAY_BOUNDS,
    )
    assert lag_fit.simulate_lag is simulate_lag


@pytest.mark.parametrize("lag", LAGS, ids=str)
def test_discrete_simulation_follows_the_analytic_step_response(lag: SteeringLag) -> None:
    # A unit step at sample 1: under the first-order hold the input ramps over [0, dt], so the exact output at t_k
    # is the mean of the step response over [t_k - dt, t_k] (the trapezoid below is within dt^2 max|y''| / 12 of
    # it, max|y''| = wn^2 at the step).
    dt = 1e-3
    t = np.arange(0.0, 8.0, dt)
    u = np.ones_like(t)
    u[0] = 0.0
    ours = lag.simulate(u, dt, with_gain=False)
    shifted = np.clip(t - lag.delay_s, 0.0, None)
    step = analytic_step(lag.omega_n_rad_s, lag.zeta, shifted)
    previous = analytic_step(lag.omega_n_rad_s, lag.zeta, np.clip(shifted - dt, 0.0, None))
    np.testing.assert_allclose(ours, 0.5 * (step + previous), atol=dt**2 * lag.omega_n_rad_s**2 / 12.0 + 1e-9)
    np.testing.assert_allclose(lag.simulate(u, dt), lag.steady_state_gain * ours, rtol=1e-15, atol=0.0)


@pytest.mark.parametrize("lag", LAGS, ids=str)
def test_transfer_function_against_python_control_step_and_the_direct_frequency_response(lag: SteeringLag) -> None:
    wn, zeta, gain = lag.omega_n_rad_s, lag.zeta, lag.steady_state_gain
    tf = lag.transfer_function()
    assert control.dcgain(tf) == pytest.approx(gain, rel=1e-12)
    assert control.dcgain(lag.transfer_function(with_gain=False)) == pytest.approx(1.0, rel=1e-12)
    expected_poles = np.roots([1.0, 2.0 * zeta * wn, wn**2])
    # (a double root at zeta = 1 is found only to sqrt(eps) relative)
    np.testing.assert_allclose(np.sort_complex(tf.poles()), np.sort_complex(expected_poles), atol=1e-6 * wn)
    # python-control's simulation of the transfer function against the discrete one (no delay: python-control
    # has none in a continuous transfer function)
    no_delay = SteeringLag(wn, zeta, steady_state_gain=gain)
    dt = 0.01
    t = np.arange(0.0, 10.0, dt)
    u = np.where(t > 1.0, 1.0, 0.0) + 0.3 * np.sin(2.0 * t)
    response = np.asarray(control.forced_response(tf, t, u).outputs)
    np.testing.assert_allclose(no_delay.simulate(u, dt), response, atol=1e-9)
    # the direct evaluation against python-control, the delay as exp(-j omega delay)
    omega = wn * np.logspace(-2.0, 2.0, 200)
    direct = np.asarray(control.frequency_response(tf, omega).complex).ravel() * np.exp(-1j * omega * lag.delay_s)
    np.testing.assert_allclose(lag.frequency_response(omega), direct, rtol=1e-10)
    np.testing.assert_allclose(
        lag.frequency_response(omega, with_gain=False, with_delay=False),
        np.asarray(control.frequency_response(lag.transfer_function(with_gain=False), omega).complex).ravel(),
        rtol=1e-10,
    )


@pytest.mark.parametrize("order", [1, 3])
def test_the_delay_as_a_pade_approximant(order: int) -> None:
    lag = SteeringLag(4.0, 0.8, 0.3, steady_state_gain=0.9)
    tf = lag.transfer_function(pade_order=order)
    assert len(tf.poles()) == 2 + order
    omega = np.array([0.05, 0.2, 0.5])  # well below 1 / delay the approximant is the delay
    padded = np.asarray(control.frequency_response(tf, omega).complex).ravel()
    np.testing.assert_allclose(padded, lag.frequency_response(omega), rtol=1e-3)
    assert SteeringLag(4.0, 0.8).transfer_function(pade_order=order).poles().size == 2  # no delay, nothing added
    with pytest.raises(WorkbenchInputError, match="pade_order"):
        lag.transfer_function(pade_order=0)


@pytest.mark.parametrize("lag", LAGS, ids=str)
def test_companion_matrices_realise_the_transfer_function(lag: SteeringLag) -> None:
    a, b = lag.companion_matrices()
    ss = control.ss(a, b.reshape(2, 1), [[1.0, 0.0]], [[0.0]])
    omega = lag.omega_n_rad_s * np.logspace(-2.0, 2.0, 50)
    np.testing.assert_allclose(
        np.asarray(control.frequency_response(ss, omega).complex).ravel(),
        lag.frequency_response(omega, with_gain=False, with_delay=False),
        rtol=1e-10,
    )


def _ode_matrices(lag: SteeringLag) -> tuple[np.ndarray, np.ndarray]:
    """(A, B) of state_derivatives (it is linear), read off by unit probes."""
    n = lag.ode_state_count
    b = np.array(lag.state_derivatives([0.0] * n, 1.0))
    a = np.column_stack([np.array(lag.state_derivatives(list(np.eye(n)[j]), 0.0)) for j in range(n)])
    return a, b


@pytest.mark.parametrize("lag", LAGS, ids=str)
def test_ode_is_the_first_order_pade_transfer_function_and_its_fastest_decay(lag: SteeringLag) -> None:
    a, b = _ode_matrices(lag)
    ode = control.ss(a, b.reshape(-1, 1), np.eye(lag.ode_state_count)[:1], [[0.0]])
    omega = lag.omega_n_rad_s * np.logspace(-2.0, 2.0, 50)
    expected = lag.transfer_function(with_gain=False, pade_order=1)
    np.testing.assert_allclose(
        np.asarray(control.frequency_response(ode, omega).complex).ravel(),
        np.asarray(control.frequency_response(expected, omega).complex).ravel(),
        rtol=1e-9,
    )
    assert lag.fastest_rate_per_s == pytest.approx(float(-np.linalg.eigvals(a).real.min()), rel=1e-6)


def test_ode_takes_numpy_arrays_and_casadi_symbols() -> None:
    ca = pytest.importorskip("casadi")
    lag = SteeringLag(4.0, 0.8, 0.3)
    states = np.array([[0.1, -0.2], [0.3, 0.0], [0.05, 0.07]])
    lag_input = np.array([0.2, -0.1])
    vectorised = np.array(lag.state_derivatives(list(states), lag_input))
    x, u = ca.SX.sym("x", 3), ca.SX.sym("u")
    f = ca.Function("f", [x, u], [ca.vertcat(*lag.state_derivatives([x[0], x[1], x[2]], u))])
    for k in range(2):
        scalar = np.array(lag.state_derivatives(list(states[:, k]), float(lag_input[k])))
        np.testing.assert_array_equal(vectorised[:, k], scalar)
        np.testing.assert_allclose(np.asarray(f(states[:, k], lag_input[k])).ravel(), scalar, rtol=1e-15)


@settings(max_examples=60, deadline=None)
@given(
    wn=st.floats(*OMEGA_N_BOUNDS),
    zeta=st.floats(*ZETA_BOUNDS),
    # (a delay under about 1e-308 s overflows 2 / delay, the Pade pole: not a delay anyone identifies)
    delay=st.one_of(st.just(0.0), st.floats(1e-6, DELAY_BOUNDS[1])),
    gain=st.floats(*GAIN_BOUNDS),
    level=st.floats(-1.0, 1.0),
)
def test_unit_dc_gain_and_stability_everywhere_in_the_bounds(
    wn: float, zeta: float, delay: float, gain: float, level: float
) -> None:
    lag = SteeringLag(wn, zeta, delay, steady_state_gain=gain)
    assert abs(lag.frequency_response(np.array([0.0]), with_gain=False)[0] - 1.0) < 1e-12
    assert lag.frequency_response(np.array([0.0]))[0] == pytest.approx(gain, rel=1e-12)
    a, b = _ode_matrices(lag)
    assert np.linalg.eigvals(a).real.max() < 0.0  # zeta > 0: both poles (and the Pade pole) in the left half plane
    settled = np.linalg.solve(a, -b * level)  # the ODE's equilibrium: the output at the input, its rate 0
    assert settled[0] == pytest.approx(level, abs=1e-9 * max(1.0, wn)) and abs(settled[1]) <= 1e-9 * max(1.0, wn**2)
    # a constant input stays put in the discrete simulation (it starts from the input's steady state), within the
    # rounding of the discrete transfer function's DC gain sum(b) / sum(a): sum(a) = (1 - p1)(1 - p2), about
    # (wn dt)^2 for a slow lag, cancels the coefficients' (~1) digits, so the gain carries ~eps sum|a| / |sum(a)|
    # (about 4e-9 at wn = 0.05 rad/s and dt 0.01 s, measured 1e-9; the bound 16 times it); 1e-9 where that is less
    held = lag.simulate(np.full(50, level), 0.01)
    _, den = discrete_coefficients(wn, zeta, 0.01)
    rounding = 16.0 * np.finfo(float).eps * np.abs(den).sum() / abs(den.sum())
    np.testing.assert_allclose(held, gain * level, rtol=max(1e-9, rounding), atol=1e-12)
