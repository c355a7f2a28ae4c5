"""The loop analysis against independent references: the analytic law about a straight, python-control's own margin
computation, simulations of the linear loop at and around its margins, the saturation's describing function by
Fourier analysis, and the nonlinear closed loop's limit cycle."""

from __future__ import annotations

import math
import warnings

import control
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from controllers.clothoid.lead_filter import LeadFilterParams
from controllers.clothoid.loop_analysis import (
    LoopSettings,
    PlantLags,
    clothoid_law_gains,
    lookahead_floor,
    loop_transfer,
    margins,
    plant,
    predicted_limit_cycle,
    saturation_describing_function,
)
from workbench.base.errors import WorkbenchInputError
from workbench.vehicles.steering_lag import SteeringLag

#: The loaded truck's lags at 30 km/h as `tuning fit-lag --delay` identifies them (path curvature and yaw rate).
TRUCK = PlantLags(
    SteeringLag(28.0, 2.0, 0.24, steady_state_gain=0.935), SteeringLag(9.42, 0.94, 0.062, steady_state_gain=0.942)
)
TRUCK_LEAD = LeadFilterParams(6.0, 1.2, 24.0)
V = 30 / 3.6


@pytest.mark.parametrize("lookahead", [3.0, 5.0, 10.0, 20.0])
def test_law_about_a_straight_is_the_small_angle_clothoid(lookahead: float) -> None:
    """kappa' = -(6 / L^3) (y + psi L + kappa L^2 / 2) for a hyper-clothoid to a point L ahead on a straight."""
    g = clothoid_law_gains(lookahead)
    expected = (-6 / lookahead**3, -6 / lookahead**2, -3 / lookahead)
    assert g == pytest.approx(expected, rel=1e-5)


def test_law_about_an_arc_differs_by_the_arc_geometry() -> None:
    """On an arc the gains change by O((kappa L)^2): a few percent at kappa L = 1/3, and they are finite."""
    straight, arc = clothoid_law_gains(10.0), clothoid_law_gains(10.0, 1 / 30)
    assert all(math.isfinite(v) for v in arc)
    assert arc == pytest.approx(straight, rel=0.08)
    assert arc != pytest.approx(straight, rel=1e-4)
    with pytest.raises(WorkbenchInputError, match="lookahead_m x"):
        clothoid_law_gains(20.0, 0.1)


def test_plant_steady_state_follows_the_lag_gain() -> None:
    """A held kinematic curvature u gives the path curvature K u (Eq. 5's steady state) in the plant's output."""
    p = plant(TRUCK, V, 0.0, LoopSettings())
    t = np.arange(0.0, 10.0, p.dt)
    y = np.asarray(control.forced_response(p, t, np.ones_like(t)).outputs)
    assert y[2, -1] == pytest.approx(TRUCK.measured.steady_state_gain, rel=1e-6)  # the measured (yaw-rate) curvature
    heading_rate = (y[1, -1] - y[1, -2]) / p.dt
    assert heading_rate == pytest.approx(V * TRUCK.path.steady_state_gain, rel=1e-6)  # psi' = V K u


@pytest.mark.parametrize(("lookahead", "lead"), [(9.0, TRUCK_LEAD), (15.0, TRUCK_LEAD), (12.0, None)])
def test_margins_agree_with_python_control(lookahead: float, lead: LeadFilterParams | None) -> None:
    loop = loop_transfer(TRUCK, LoopSettings(lead=lead), V, lookahead)
    ours = margins(loop)
    assert ours.stable
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        gm, pm, _, _, wgc, _ = control.stability_margins(loop, returnall=True)
    pm = np.asarray(pm)[np.asarray(wgc) > 0]
    assert ours.phase_margin_deg == pytest.approx(np.min(np.abs(pm)), abs=0.3)
    gm = np.asarray(gm)
    assert ours.gain_margin_db == pytest.approx(20 * np.log10(np.min(gm[gm > 1])), abs=0.1)
    assert ours.gain_reduction_margin_db == pytest.approx(20 * np.log10(np.max(gm[gm < 1])), abs=0.1)


def _simulated_growth(loop: control.StateSpace, gain: float) -> tuple[float, float]:
    """Closed loop of gain x L after a short pulse: (envelope late / envelope early, dominant frequency in rad/s)."""
    closed = control.feedback(gain * loop, 1)
    t = np.arange(0.0, 60.0, loop.dt)
    pulse = np.where(t < 0.1, 1e-3, 0.0)
    y = np.asarray(control.forced_response(closed, t, pulse).outputs).ravel()
    n = t.size // 3
    early, late = np.max(np.abs(y[n : 2 * n])), np.max(np.abs(y[2 * n :]))
    spectrum = np.abs(np.fft.rfft(y[n:] - np.mean(y[n:])))
    freqs = np.fft.rfftfreq(y[n:].size, loop.dt) * 2 * np.pi
    return late / early, float(freqs[np.argmax(spectrum)])


def test_linear_loop_oscillates_where_the_gain_margin_vanishes() -> None:
    """Raised by its gain margin, the loop oscillates undamped at the phase-crossover frequency; 2 dB less and it
    settles, 2 dB more and it grows."""
    loop = loop_transfer(TRUCK, LoopSettings(lead=TRUCK_LEAD), V, 12.0)
    m = margins(loop)
    at_margin = 10 ** (m.gain_margin_db / 20)
    ratio, omega = _simulated_growth(loop, at_margin)
    assert ratio == pytest.approx(1.0, abs=0.15)
    assert omega == pytest.approx(m.phase_crossover_rad_s, rel=0.03)
    assert _simulated_growth(loop, at_margin * 10 ** (-2 / 20))[0] < 0.2
    assert _simulated_growth(loop, at_margin * 10 ** (2 / 20))[0] > 5.0


def test_linear_loop_settles_where_the_margins_hold_and_grows_where_unstable() -> None:
    held = loop_transfer(TRUCK, LoopSettings(lead=TRUCK_LEAD), V, 15.0)
    assert margins(held).meets() and _simulated_growth(held, 1.0)[0] < 0.05
    gone = loop_transfer(TRUCK, LoopSettings(lead=TRUCK_LEAD), V, 4.0)
    assert not margins(gone).stable and _simulated_growth(gone, 1.0)[0] > 10.0


def test_floor_is_the_shortest_lookahead_keeping_the_margins() -> None:
    s = LoopSettings(lead=TRUCK_LEAD)
    floor = lookahead_floor(TRUCK, s, V, 3.0, 30.0, 0.5)
    assert 5.0 < floor < 20.0
    assert margins(loop_transfer(TRUCK, s, V, floor)).meets()
    assert not margins(loop_transfer(TRUCK, s, V, floor - 0.5)).meets()
    for lookahead in np.arange(floor, 30.0, 2.5):
        assert margins(loop_transfer(TRUCK, s, V, float(lookahead))).meets()


def _clipped_sine_fundamental(a: float) -> float:
    """The fundamental of sin clipped at +-1/a, over its input amplitude 1/a (numerically, by Fourier)."""
    theta = np.linspace(0.0, 2 * np.pi, 20001)[:-1]
    out = np.clip(a * np.sin(theta), -1.0, 1.0)
    return float(2 * np.mean(out * np.sin(theta)) / a)


@given(st.floats(min_value=1.0, max_value=50.0))
@settings(max_examples=60, deadline=None)
def test_saturation_describing_function_is_the_fundamental(a: float) -> None:
    assert float(saturation_describing_function(a)) == pytest.approx(_clipped_sine_fundamental(a), abs=1e-6)
    assert 0 < float(saturation_describing_function(a)) <= 1.0
    assert saturation_describing_function(a * 1.1) < saturation_describing_function(a) or a * 1.1 <= 1.0


def test_no_limit_cycle_is_predicted_where_the_loop_is_stable() -> None:
    loop = loop_transfer(TRUCK, LoopSettings(lead=TRUCK_LEAD), V, 15.0)
    assert predicted_limit_cycle(loop, 0.12) is None


def test_predicted_limit_cycle_sits_at_a_phase_crossover_python_control_finds() -> None:
    """Where the loop is unstable the describing function puts the cycle at the fastest phase crossover with |L| > 1
    (python-control's), at the amplitude whose saturation gain N is 1 / |L| there."""
    settings_ = LoopSettings(lead=LeadFilterParams(4.44, 0.8, 13.32))
    lags = PlantLags(SteeringLag(4.28, 0.775, steady_state_gain=0.942))
    loop = loop_transfer(lags, settings_, V, 5.0)
    assert not margins(loop).stable
    cycle = predicted_limit_cycle(loop, 0.05, settings_.lead, 22.0 * 5.9)
    assert cycle is not None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        gm, _, _, wpc, _, _ = control.stability_margins(loop, returnall=True)
    gm, wpc = np.asarray(gm), np.asarray(wpc)
    w = np.max(wpc[(gm < 1) & (wpc > 0)])
    assert 2 * np.pi * cycle.frequency_hz == pytest.approx(w, rel=0.01)
    n = float(saturation_describing_function(cycle.rate_amplitude_1pm_s / 0.05))
    assert n == pytest.approx(np.min(gm[np.isclose(wpc, w, rtol=0.01)]), rel=0.02)
    assert cycle.steer_wheel_amplitude_deg > 0
