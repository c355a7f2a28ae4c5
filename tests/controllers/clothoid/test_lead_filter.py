"""The lead filter (Eq. 6) against python-control, and its Tustin discretisation against the continuous filter,
python-control's own Tustin discretisation and the properties every valid design must have."""

from __future__ import annotations

import math

import control
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import signal

from controllers.clothoid.lead_filter import DiscreteLeadFilter, LeadFilterParams
from workbench.base.errors import WorkbenchInputError

PAPER_LIKE = LeadFilterParams.from_lag(4.44, 0.80)  # wz = 4.44, psi = 0.8, wp = 13.32 rad/s
DESIGNS = [PAPER_LIKE, LeadFilterParams(2.0, 0.3, 9.0), LeadFilterParams(10.0, 2.0, 25.0), LeadFilterParams(1, 1, 1)]


def lag(omega_n: float, zeta: float) -> control.TransferFunction:
    """Eq. 5."""
    return control.tf([omega_n**2], [1.0, 2 * zeta * omega_n, omega_n**2])


def run(f: DiscreteLeadFilter, u: np.ndarray, u0: float = 0.0) -> np.ndarray:
    f.reset(u0)
    return np.array([f.step(float(x)) for x in u])


# ---- the continuous filter, Eq. 6 ----


@pytest.mark.parametrize("p", DESIGNS)
def test_transfer_function_dc_gain_poles_and_zeros(p: LeadFilterParams) -> None:
    tf = p.transfer_function()
    assert control.dcgain(tf) == pytest.approx(1.0, abs=1e-12)
    assert p.dc_gain == pytest.approx(1.0, abs=1e-12)
    wz, psi, wp = p.omega_z_rad_s, p.psi, p.omega_p_rad_s
    # Triple pole at -wp: the denominator is (s + wp)^3 coefficient by coefficient (1e-12 relative) ...
    den = tf.den[0][0] / tf.den[0][0][0]
    np.testing.assert_allclose(den, [1.0, 3 * wp, 3 * wp**2, wp**3], rtol=1e-12)
    # ... and the computed poles, whose error for a triple root is ~ eps^(1/3) ~ 6e-6 relative, are there too.
    np.testing.assert_allclose(tf.poles(), [-wp] * 3, rtol=1e-4)
    assert np.all(tf.poles().real < 0) and np.all(tf.zeros().real < 0)  # stable and minimum phase
    if abs(psi - 1.0) > 0.1:  # simple zeros (a double zero at psi = 1 is conditioned like sqrt(eps))
        expected = np.sort_complex(np.roots([1.0, 2 * psi * wz, wz**2]))
        np.testing.assert_allclose(np.sort_complex(tf.zeros()), expected, rtol=1e-9, atol=1e-9)


def test_zeros_cancel_the_lag_and_the_cascade_is_a_faster_triple_lag() -> None:
    wn, zeta = 4.44, 0.80
    p = LeadFilterParams.from_lag(wn, zeta)
    assert (p.omega_z_rad_s, p.psi, p.omega_p_rad_s) == (wn, zeta, pytest.approx(3 * wn, rel=1e-15))
    wp = p.omega_p_rad_s
    cascade = p.transfer_function() * lag(wn, zeta)
    target = control.tf([wp**3], [1.0, 3 * wp, 3 * wp**2, wp**3])
    w = np.logspace(-2, 3, 400)
    np.testing.assert_allclose(cascade(1j * w), target(1j * w), rtol=1e-9)
    lag_bw, cascade_bw = control.bandwidth(lag(wn, zeta)), control.bandwidth(cascade)
    assert cascade_bw > 1.7 * lag_bw  # 6.78 against 3.86 rad/s
    # control.bandwidth is where |G| falls 3 dB: (1 + (w / wp)^2)^3 = 10^0.3 for (wp / (s + wp))^3.
    assert cascade_bw == pytest.approx(wp * math.sqrt(10**0.1 - 1), rel=1e-6)


@pytest.mark.parametrize("p", DESIGNS)
def test_peak_gain_is_the_maximum_over_frequency(p: LeadFilterParams) -> None:
    w = np.logspace(-4, 5, 200_001)
    brute = np.abs(p.transfer_function()(1j * w)).max()
    assert brute <= p.peak_gain * (1 + 1e-12)
    assert p.peak_gain == pytest.approx(brute, rel=1e-6)
    assert p.high_frequency_gain == p.peak_gain
    assert p.peak_gain >= 1.0  # never below the DC gain


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        ((0.0, 0.8, 13.0), r"omega_z_rad_s must be .*\[0.01, 1000\].*got 0.0"),
        ((4.0, 0.8, 2000.0), r"omega_p_rad_s must be a finite number in \[0.01, 1000\] rad/s; got 2000.0"),
        ((4.0, 0.0, 13.0), r"psi must be a finite number in \(0, 5\]; got 0.0"),
        ((4.0, 6.0, 13.0), r"psi must be a finite number in \(0, 5\]; got 6.0"),
        ((4.0, math.nan, 13.0), r"psi must be a finite number in \(0, 5\]; got nan"),
        ((4.0, 0.8, "13"), r"omega_p_rad_s must be a finite number.*got '13'"),
        ((4.0, 0.8, 2.0), r"omega_p_rad_s / omega_z_rad_s must be in \[1.0, 100.0\].*= 0.5"),
        ((1.0, 0.8, 200.0), r"omega_p_rad_s / omega_z_rad_s must be in \[1.0, 100.0\].*= 200"),
    ],
)
def test_bad_parameters_are_rejected_naming_field_value_and_range(args: tuple, needle: str) -> None:
    with pytest.raises(WorkbenchInputError, match=needle):
        LeadFilterParams(*args)


def test_from_lag_validates_its_own_arguments() -> None:
    with pytest.raises(
        WorkbenchInputError, match=r"omega_n_rad_s must be a finite number in \[0.01, 1000\] rad/s; got -1"
    ):
        LeadFilterParams.from_lag(-1.0, 0.8)
    with pytest.raises(WorkbenchInputError, match=r"zeta must be a finite number in \(0, 5\]"):
        LeadFilterParams.from_lag(4.0, -0.1)
    with pytest.raises(WorkbenchInputError, match=r"pole_ratio must be a finite number in \[1, 100\]; got 0.5"):
        LeadFilterParams.from_lag(4.0, 0.8, pole_ratio=0.5)


# ---- the discrete filter ----


def continuous_reference(tf: control.TransferFunction, t: np.ndarray, u: np.ndarray) -> np.ndarray:
    """The continuous response to the samples u, interpolated linearly as Tustin's trapezoidal rule does, starting
    at rest one sample before t[0] with input 0 there (so a sampled step is a ramp over that sample)."""
    dt = t[1] - t[0]
    return control.forced_response(tf, np.r_[t[0] - dt, t], np.r_[0.0, u]).outputs[1:]


def test_step_and_sine_match_the_continuous_filter_with_second_order_error() -> None:
    errors = {}
    for dt in (0.02, 0.01):
        f = DiscreteLeadFilter(PAPER_LIKE, dt)
        t = np.arange(0.0, 3.0 + dt / 2, dt)
        step, sine = np.ones_like(t), np.sin(3.0 * t)
        tf = PAPER_LIKE.transfer_function()
        errors[dt] = (
            np.abs(run(f, step) - continuous_reference(tf, t, step)).max(),
            np.abs(run(f, sine) - continuous_reference(tf, t, sine)).max(),
        )
    # Measured: step 0.082 / 0.026 (peak of the step response 2.7), sine 5.6e-3 / 1.4e-3 (amplitude 1.2).
    assert errors[0.02][0] < 0.10 and errors[0.01][0] < 0.03
    assert errors[0.02][1] < 7e-3 and errors[0.01][1] < 1.7e-3
    assert errors[0.02][0] / errors[0.01][0] > 3.0  # O(dt^2): 3.2 (wp dt = 0.27 is not yet small)
    assert 3.6 < errors[0.02][1] / errors[0.01][1] < 4.4  # O(dt^2): 4.1


@pytest.mark.parametrize("dt", [0.02, 0.01])
@pytest.mark.parametrize("prewarp", [None, 5.0])
def test_equals_python_controls_tustin_discretisation(dt: float, prewarp: float | None) -> None:
    tf = PAPER_LIKE.transfer_function()
    tfd = control.sample_system(tf, dt, "tustin", prewarp_frequency=prewarp)
    t = np.arange(0.0, 4.0, dt)
    rng = np.random.default_rng(1)
    f = DiscreteLeadFilter(PAPER_LIKE, dt, prewarp_rad_s=prewarp)
    for u in (np.ones_like(t), np.sin(3.0 * t), rng.uniform(-1, 1, t.size)):
        np.testing.assert_allclose(run(f, u), control.forced_response(tfd, t, u).outputs, rtol=0, atol=1e-9)
    if prewarp is not None:  # exact match of the frequency response at the pre-warping frequency
        a, b, c, d = (np.asarray(m) for m in f.state_space)
        z = np.exp(1j * prewarp * dt)
        g = c @ np.linalg.solve(z * np.eye(3) - a, b) + d
        assert g == pytest.approx(complex(tf(1j * prewarp)), rel=1e-12)


@pytest.mark.parametrize("u0", [0.0, 0.35, -2.0, 540.0])
def test_reset_is_a_steady_state_for_a_constant_input(u0: float) -> None:
    f = DiscreteLeadFilter(PAPER_LIKE, 0.01)
    run(f, np.sin(np.arange(50.0)))  # a history that reset must forget
    y = run(f, np.full(20_000, u0), u0=u0)
    assert np.abs(y - u0).max() <= 1e-12 * max(1.0, abs(u0))


def test_steady_state_gain_is_one() -> None:
    f = DiscreteLeadFilter(PAPER_LIKE, 0.01)
    assert f.dc_gain == pytest.approx(1.0, abs=1e-12)
    assert run(f, np.full(2000, 0.7))[-1] == pytest.approx(0.7, abs=1e-12)  # converged from rest after 20 s


def test_step_and_state_are_plain_python_floats() -> None:
    f = DiscreteLeadFilter(PAPER_LIKE, 0.01)
    f.reset(0.1)
    assert type(f.step(0.2)) is float and all(type(v) is float for v in f.state)


@pytest.mark.parametrize(
    ("kwargs", "needle"),
    [
        ({"dt_s": 0.0}, r"dt_s must be a finite number > 0; got 0.0"),
        ({"dt_s": -0.01}, r"dt_s must be a finite number > 0; got -0.01"),
        ({"dt_s": math.inf}, r"dt_s must be a finite number > 0; got inf"),
        ({"dt_s": 0.01, "prewarp_rad_s": 400.0}, r"prewarp_rad_s must be in \[0, 314.159\) rad/s.*got 400.0"),
        ({"dt_s": 0.01, "prewarp_rad_s": -1.0}, r"prewarp_rad_s must be in \[0, 314.159\).*got -1.0"),
    ],
)
def test_bad_sample_time_or_prewarp_is_rejected(kwargs: dict, needle: str) -> None:
    with pytest.raises(WorkbenchInputError, match=needle):
        DiscreteLeadFilter(PAPER_LIKE, **kwargs)


def test_an_unstable_discretisation_is_rejected(monkeypatch: pytest.MonkeyPatch) -> None:
    original = signal.cont2discrete

    def unstable(system, dt, method):  # a broken discretisation: every pole scaled out of the unit circle
        a, b, c, d, dt = original(system, dt, method=method)
        return 1.5 * a, b, c, d, dt

    monkeypatch.setattr(signal, "cont2discrete", unstable)
    with pytest.raises(WorkbenchInputError, match=r"unstable: pole magnitudes .*all must be < 1"):
        DiscreteLeadFilter(PAPER_LIKE, 0.01)


# ---- properties of every valid design ----


@st.composite
def designs(draw: st.DrawFn, min_wp_dt: float = 0.0) -> tuple[LeadFilterParams, float]:
    """Random valid (wz, psi, wp) over the whole allowed range, log-uniform, and a sample time 0.1 ms - 0.1 s."""
    wz = math.exp(draw(st.floats(math.log(0.01), math.log(1000.0))))
    wp = math.exp(draw(st.floats(math.log(wz), math.log(min(100 * wz, 1000.0)))))
    psi = draw(st.floats(1e-3, 5.0))
    low = math.log(max(1e-4, min_wp_dt / wp))
    dt = math.exp(draw(st.floats(low, max(low, math.log(0.1)))))
    return LeadFilterParams(wz, psi, min(max(wp, wz), 1000.0)), dt


@settings(max_examples=200, deadline=None)
@given(designs())
def test_every_discretisation_is_stable_with_unit_dc_gain(design: tuple[LeadFilterParams, float]) -> None:
    p, dt = design
    f = DiscreteLeadFilter(p, dt)
    k = p.omega_p_rad_s * dt / 2  # Tustin maps the triple pole -wp to (1 - k) / (1 + k)
    np.testing.assert_allclose(f.poles.real, [(1 - k) / (1 + k)] * 3, rtol=0, atol=1e-9)
    assert np.all(np.abs(f.poles) < 1.0)
    assert f.dc_gain == pytest.approx(1.0, abs=1e-9)


@settings(max_examples=60, deadline=None)
@given(designs(min_wp_dt=1e-2), st.lists(st.floats(-1.0, 1.0), min_size=1, max_size=300))
def test_output_is_bounded_by_the_l1_norm_of_the_impulse_response(
    design: tuple[LeadFilterParams, float], u: list[float]
) -> None:
    p, dt = design
    tfd = control.sample_system(p.transfer_function(), dt, "tustin")  # independent of the filter's realisation
    pole = abs((1 - p.omega_p_rad_s * dt / 2) / (1 + p.omega_p_rad_s * dt / 2))
    n = math.ceil(80 / (1 - pole))  # the tail beyond n samples is below ~ n^2 e^-80
    impulse = signal.lfilter(tfd.num[0][0], tfd.den[0][0], np.r_[1.0, np.zeros(n)])
    bound = np.abs(impulse).sum() * max(abs(v) for v in u)
    y = run(DiscreteLeadFilter(p, dt), np.asarray(u))
    assert np.abs(y).max() <= bound * (1 + 1e-6) + 1e-12
