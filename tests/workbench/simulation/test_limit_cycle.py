"""The steering limit-cycle detector on synthetic steering traces whose oscillation is known."""

from __future__ import annotations

import math

import numpy as np
import pytest

from workbench.base.errors import WorkbenchInputError
from workbench.simulation.limit_cycle import (
    AMPLITUDE_TOLERANCE,
    HALF_PERIOD_TOLERANCE,
    LIMIT_CYCLE_MIN_AMPLITUDE_DEG,
    LimitCycle,
    _longest_cycle,
    _regular,
    detect_limit_cycle,
    oscillation,
    residual_gain,
    turning_points,
    window_samples,
)

DT = 0.02  # the default 50 Hz controller rate
T = np.arange(0.0, 80.0, DT)


def _manoeuvre_deg(t: np.ndarray) -> np.ndarray:
    """A slow manoeuvre: ±200° at 0.05 Hz, a truck's steering through long corners."""
    return 200.0 * np.sin(2 * np.pi * 0.05 * t)


def _burst_deg(t: np.ndarray, freq_hz: float, amp_deg: float, start_s: float, stop_s: float) -> np.ndarray:
    """A sinusoid of freq_hz and amp_deg between start_s and stop_s (whole half-cycles, so it starts and ends at 0)."""
    on = (t >= start_s) & (t < stop_s)
    return np.where(on, amp_deg * np.sin(2 * np.pi * freq_hz * (t - start_s)), 0.0)


def _detect(sw_deg: np.ndarray, t: np.ndarray = T) -> LimitCycle:
    return detect_limit_cycle(t, np.radians(sw_deg))


@pytest.mark.parametrize(("freq_hz", "amp_deg"), [(1.0, 150.0), (2.0, 40.0), (0.5, 60.0), (5.0, 20.0)])
def test_an_oscillation_on_a_slow_manoeuvre_is_detected_with_its_frequency_amplitude_and_span(
    freq_hz: float, amp_deg: float
) -> None:
    # 0.5 Hz checks the amplitude correction: about the 1 s average only 36 % of it is left
    cycle = _detect(_manoeuvre_deg(T) + _burst_deg(T, freq_hz, amp_deg, 20.0, 60.0))
    assert cycle.detected
    assert cycle.frequency_hz == pytest.approx(freq_hz, rel=0.02)
    assert cycle.amplitude_deg == pytest.approx(amp_deg, rel=0.05)
    assert cycle.start_s == pytest.approx(20.0, abs=1.0 / freq_hz)
    assert cycle.duration_s == pytest.approx(40.0, abs=1.5 / freq_hz)


@pytest.mark.parametrize(
    "sw_deg",
    [
        # a double lane change: two full-sine steering pulses of 13° and 2.5 s, 3 s apart
        _burst_deg(T, 0.4, 13.0, 10.0, 12.5) - _burst_deg(T, 0.4, 13.0, 15.5, 18.0),
        # the same at a truck's steering ratio: ±250°
        _burst_deg(T, 0.4, 250.0, 10.0, 12.5) - _burst_deg(T, 0.4, 250.0, 15.5, 18.0),
        np.where(T >= 30.0, 90.0, 0.0),  # a step
        _manoeuvre_deg(T),
        _burst_deg(T, 1.0, 0.8 * LIMIT_CYCLE_MIN_AMPLITUDE_DEG, 10.0, 70.0),  # below the threshold
        _burst_deg(T, 0.1, 200.0, 10.0, 70.0),  # below 0.2 Hz: a manoeuvre's pace
        _burst_deg(T, 15.0, 40.0, 10.0, 70.0),  # above 10 Hz
    ],
    ids=["dlc-car", "dlc-truck", "step", "slow-manoeuvre", "small", "slow", "fast"],
)
def test_manoeuvres_and_oscillations_outside_the_limits_are_not_limit_cycles(sw_deg: np.ndarray) -> None:
    assert _detect(sw_deg) == LimitCycle(False)


def test_it_must_last_3_s() -> None:
    assert not _detect(_burst_deg(T, 2.0, 40.0, 20.0, 22.0)).detected  # 4 cycles in 2 s
    cycle = _detect(_burst_deg(T, 2.0, 40.0, 20.0, 24.0))
    assert cycle.detected and cycle.duration_s == pytest.approx(4.0, abs=0.5)


def test_it_must_repeat_3_cycles() -> None:
    assert not _detect(_burst_deg(T, 0.4, 100.0, 20.0, 25.0)).detected  # 2 cycles in 5 s
    assert _detect(_burst_deg(T, 0.4, 100.0, 20.0, 30.0)).detected  # 4 cycles


def test_swings_of_different_sizes_are_not_a_limit_cycle() -> None:
    # regular timing, but every other cycle 4 times the size: a manoeuvre's residue, not a sustained cycle
    amp = np.where(np.floor(T) % 2 == 0, 10.0, 40.0)
    assert not _detect(amp * np.sin(2 * np.pi * T)).detected
    assert _detect(np.where(np.floor(T) % 2 == 0, 20.0, 30.0) * np.sin(2 * np.pi * T)).detected  # within ±50 %


def test_small_rate_wiggles_do_not_split_the_cycles() -> None:
    ripple = 2.0 * np.sin(2 * np.pi * 12.0 * T)  # 12 Hz, ±2°: turns the rate's sign 24 times a second
    cycle = _detect(_burst_deg(T, 1.0, 30.0, 10.0, 70.0) + ripple)
    assert cycle.detected and cycle.frequency_hz == pytest.approx(1.0, rel=0.02)


def test_turning_points_ignore_reversals_within_the_deadband() -> None:
    x = np.array([0.0, 10.0, 8.0, 12.0, -5.0, -3.0, -8.0, 6.0])
    assert turning_points(x, 5.0).tolist() == [0, 3, 6]  # the reversals of 2 are not turning points


@pytest.mark.parametrize("freq_hz", [0.3, 0.5, 1.0, 1.43, 2.0, 7.0])
def test_residual_gain_is_the_discrete_moving_average_s_effect_on_a_sinusoid(freq_hz: float) -> None:
    t = np.arange(0.0, 60.0, DT)
    k = window_samples(t)
    _, deviation = oscillation(t, np.sin(2 * np.pi * freq_hz * t))
    assert np.max(np.abs(deviation)) == pytest.approx(residual_gain(freq_hz, k, DT), rel=0.01)


def test_the_window_is_1_s_odd_and_at_least_3_samples() -> None:
    assert window_samples(np.arange(0.0, 10.0, 0.02)) == 51
    assert window_samples(np.arange(0.0, 10.0, 0.01)) == 101
    assert window_samples(np.arange(0.0, 10.0, 0.1)) == 11
    assert window_samples(np.arange(0.0, 10.0, 0.5)) == 3


def test_a_trace_too_short_for_the_moving_average_has_none() -> None:
    t = np.arange(101) * DT  # 2k + 1 = 103 samples needed at 50 Hz
    sw = np.radians(100.0) * np.sin(2 * np.pi * 2.0 * t)
    assert oscillation(t, sw) is None and detect_limit_cycle(t, sw) == LimitCycle(False)
    assert oscillation(t[:1], sw[:1]) is None and oscillation(t[:0], sw[:0]) is None
    assert oscillation(np.arange(103) * DT, sw[:1].repeat(103))[1].size == 1


@pytest.mark.parametrize(
    ("column", "needle"), [("steer_wheel_rad", "steer_wheel_rad must be finite"), ("t_s", "t_s must be finite")]
)
def test_non_finite_input_is_refused_naming_the_column(column: str, needle: str) -> None:
    trace = {"t_s": T.copy(), "steer_wheel_rad": np.radians(_burst_deg(T, 1.0, 30.0, 10.0, 70.0))}
    trace[column][500] = math.nan
    with pytest.raises(WorkbenchInputError, match=needle):
        detect_limit_cycle(trace["t_s"], trace["steer_wheel_rad"])


def test_time_must_increase() -> None:
    t = T.copy()
    t[10] = t[9]
    with pytest.raises(WorkbenchInputError, match="t_s must be strictly increasing; it is not at entry 9"):
        detect_limit_cycle(t, np.zeros_like(t))


def test_the_cycle_in_words() -> None:
    cycle = LimitCycle(True, frequency_hz=1.02, amplitude_deg=149.6, start_s=113.04, duration_s=40.0)
    assert cycle.brief() == "1.0 Hz, ±150°"
    assert cycle.describe() == "1.0 Hz, ±150° steering wheel for 40.0 s from t = 113.0 s"
    assert LimitCycle(True, 0.384, 12.0, 1.0, 8.0).brief() == "0.38 Hz, ±12°"
    assert LimitCycle(False).brief() == "no" and LimitCycle(False).describe() == "no limit cycle"


# ------------------------------------------------------------------ each threshold just inside and just outside
def _sine(freq_hz: float, amp_deg: float, dt_s: float, duration_s: float) -> tuple[np.ndarray, np.ndarray]:
    """A whole trace of one sinusoid (t, steering wheel in rad)."""
    t = np.arange(0.0, duration_s, dt_s)
    return t, np.radians(amp_deg * np.sin(2 * np.pi * freq_hz * t))


@pytest.mark.parametrize(("scale", "detected"), [(1.01, True), (0.99, False)])
def test_the_amplitude_threshold_is_5_deg_about_the_moving_average(scale: float, detected: bool) -> None:
    """2 Hz sampled at 200 Hz (the peaks are samples): the half amplitude about the moving average is the
    amplitude times the average's residual gain, set 1 % above and below LIMIT_CYCLE_MIN_AMPLITUDE_DEG = 5."""
    dt = 0.005
    t = np.arange(0.0, 20.0, dt)
    gain = residual_gain(2.0, window_samples(t), dt)
    t, sw = _sine(2.0, scale * 5.0 / gain, dt, 20.0)
    assert LIMIT_CYCLE_MIN_AMPLITUDE_DEG == 5.0
    assert detect_limit_cycle(t, sw).detected is detected


@pytest.mark.parametrize(("freq_hz", "detected"), [(9.5, True), (10.5, False)])
def test_the_frequency_range_ends_at_10_hz(freq_hz: float, detected: bool) -> None:
    """At 1 kHz the half-periods of 9.5 Hz are 52-53 samples (>= 0.05 s), those of 10.5 Hz 47-48 (< 0.05 s)."""
    t, sw = _sine(freq_hz, 20.0, 0.001, 10.0)
    assert detect_limit_cycle(t, sw).detected is detected


@pytest.mark.parametrize(("freq_hz", "detected"), [(0.21, True), (0.19, False)])
def test_the_frequency_range_starts_at_0_2_hz(freq_hz: float, detected: bool) -> None:
    """Half-periods of 2.38 s (<= 2.5 s) and 2.63 s; the 1 s average leaves ~7 % of the swing, hence 300°."""
    t, sw = _sine(freq_hz, 300.0, 0.02, 80.0)
    assert detect_limit_cycle(t, sw).detected is detected


def test_the_least_duration_is_inclusive() -> None:
    """A cycle exactly as long as min_duration_s is one; a hair longer asked for, it is not."""
    t, sw = _sine(2.0, 40.0, 0.02, 12.0)
    duration = detect_limit_cycle(t, sw).duration_s
    assert detect_limit_cycle(t, sw, min_duration_s=duration).detected
    assert not detect_limit_cycle(t, sw, min_duration_s=math.nextafter(duration, math.inf)).detected


@pytest.mark.parametrize(
    ("values", "tolerance", "regular"),
    [
        ([2.0, 2.0, 3.0], 0.5, True),  # exactly at the tolerance: regular
        ([2.0, 2.0, 3.0000001], 0.5, False),
        ([1.0, 1.0, 1.0, 1.34], HALF_PERIOD_TOLERANCE, True),
        ([1.0, 1.0, 1.0, 1.36], HALF_PERIOD_TOLERANCE, False),
        ([1.0, 1.0, 1.0, 0.66], HALF_PERIOD_TOLERANCE, True),
        ([1.0, 1.0, 1.0, 0.64], HALF_PERIOD_TOLERANCE, False),
        ([1.0, 1.0, 1.0, 1.49], AMPLITUDE_TOLERANCE, True),
        ([1.0, 1.0, 1.0, 1.51], AMPLITUDE_TOLERANCE, False),
        ([1.0, 1.0, 1.0, 0.51], AMPLITUDE_TOLERANCE, True),
        ([1.0, 1.0, 1.0, 0.49], AMPLITUDE_TOLERANCE, False),
    ],
)
def test_regularity_is_within_the_tolerance_of_the_median(values: list, tolerance: float, regular: bool) -> None:
    """HALF_PERIOD_TOLERANCE = 0.35 and AMPLITUDE_TOLERANCE = 0.5, each just inside and just outside."""
    assert _regular(np.array(values), tolerance) is regular


def _runs(*runs: tuple[int, float, float]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(eligible, half_periods, half_amplitudes) of stretches (count, half-period, half amplitude); a count of 0
    is one ineligible half-cycle of 1 s."""
    eligible, periods, amplitudes = [], [], []
    for count, period, amplitude in runs:
        eligible += [count > 0] * max(count, 1)
        periods += [period if count else 1.0] * max(count, 1)
        amplitudes += [amplitude if count else 1.0] * max(count, 1)
    return np.array(eligible), np.array(periods), np.array(amplitudes)


@pytest.mark.parametrize(
    ("runs", "expected"),
    [
        (((6, 1.0, 10.0),), (0, 6)),  # LIMIT_CYCLE_MIN_CYCLES = 3: 6 half-cycles are enough
        (((5, 1.0, 10.0),), (0, 0)),  # 5 are not
        (((6, 0.1, 10.0),), (0, 6)),  # however short in time
        (((8, 1.0, 10.0),), (0, 8)),
        (((6, 1.1, 10.0), (0, 0, 0), (6, 1.0, 10.0)), (0, 6)),  # the longer in time: 6.6 s against 6 s
        (((0, 0, 0), (6, 1.0, 10.0), (0, 0, 0), (6, 1.1, 10.0)), (8, 14)),  # 6.6 s after 6 s
        (((6, 1.0, 10.0), (0, 0, 0), (6, 1.0, 10.0)), (0, 6)),  # a tie: the first
        (((8, 1.0, 10.0), (0, 0, 0), (10, 1.0, 10.0)), (9, 19)),  # a longer stretch after a long one
        (((7, 1.0, 10.0), (1, 3.0, 10.0)), (0, 7)),  # an eligible half-cycle too long ends the run
        (((7, 1.0, 10.0), (1, 1.0, 40.0)), (0, 7)),  # so does one too large
    ],
)
def test_the_longest_regular_run(runs: tuple, expected: tuple[int, int]) -> None:
    assert _longest_cycle(*_runs(*runs)) == expected


def test_a_flat_trace_has_no_turning_points() -> None:
    points = turning_points(np.zeros(10), 1.0)
    assert points.dtype == np.dtype(int) and points.size == 0


@pytest.mark.parametrize(
    ("x", "deadband", "expected"),
    [
        ([0.0, 5.0, 0.0, 5.0, 0.0], 5.0, []),  # reversals of exactly the deadband are not turning points
        ([0.0, 5.0, 0.0, 5.0, 0.0], 4.999, [0, 1, 2, 3]),
        ([0.0, 10.0, 0.0, 10.0], 1.0, [0, 1, 2]),  # an extremum at the second sample
        ([0.0, 10.0, 10.0, 0.0, 0.0, 10.0], 1.0, [0, 1, 3]),  # a plateau's first sample
    ],
)
def test_turning_points_at_the_deadband(x: list, deadband: float, expected: list) -> None:
    assert turning_points(np.array(x), deadband).tolist() == expected


def test_checks_name_what_is_wrong() -> None:
    with pytest.raises(WorkbenchInputError, match=r"must be 1-D and equally long; got \(2, 3\), \(2, 3\)"):
        detect_limit_cycle(np.ones((2, 3)), np.ones((2, 3)))
    with pytest.raises(WorkbenchInputError, match="strictly increasing; it is not at entry 0"):
        detect_limit_cycle(np.array([1.0, 0.0]), np.zeros(2))


def test_the_frequency_shows_one_decimal_from_1_hz() -> None:
    assert LimitCycle(True, 1.0, 12.0, 1.0, 8.0).brief() == "1.0 Hz, ±12°"
    assert LimitCycle(True, math.nextafter(1.0, 0.0), 12.0, 1.0, 8.0).brief() == "1.00 Hz, ±12°"
