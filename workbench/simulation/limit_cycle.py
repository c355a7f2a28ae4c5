"""Steering limit cycles: a sustained, regular oscillation of the steering wheel, which max |CTE| need not show.

The signal is the measured steering-wheel angle minus its centred 1 s moving average (`oscillation`): the average
follows the manoeuvre (lane changes and corners, mostly below 0.5 Hz), so what is left is the fast part.
`detect_limit_cycle` finds that signal's turning points (where its rate changes sign), ignoring reversals smaller
than the amplitude threshold so that small rate wiggles do not split a cycle. Consecutive turning points are
half-cycles, each with a half amplitude (peak-to-peak / 2) and a half-period. A limit cycle is a run of consecutive
half-cycles, each with a half amplitude over LIMIT_CYCLE_MIN_AMPLITUDE_DEG and a frequency 1 / (2 x half-period)
in LIMIT_CYCLE_FREQUENCY_RANGE_HZ, their half-periods within ±35 % and their half amplitudes within ±50 % of the
run's medians, of at least LIMIT_CYCLE_MIN_CYCLES cycles and LIMIT_CYCLE_MIN_DURATION_S; the longest is reported.

Non-finite input is refused (WorkbenchInputError naming the column), not dropped: the simulator never logs one, so a
NaN means a broken trace, and dropping samples would fake the timing a frequency is measured from.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from workbench.base.errors import WorkbenchInputError, require_finite

#: Length of the centred moving average the oscillation is measured about (s).
MOVING_AVERAGE_S = 1.0
#: Least half amplitude (steering-wheel deg, about the moving average) of a limit cycle's half-cycles, and the least
#: reversal counted as a turning point. 5° at the rim is 0.33° at the cars' road wheels (steering ratio 15) and 0.23°
#: at the truck's (22), under 0.02 g of lateral acceleration at 30 km/h: the size of a driver's small corrections.
#: A smaller cycle is ripple, not worth a flag.
LIMIT_CYCLE_MIN_AMPLITUDE_DEG = 5.0
#: Least duration of a limit cycle (s).
LIMIT_CYCLE_MIN_DURATION_S = 3.0
#: Least number of full cycles of a limit cycle: it repeats. A manoeuvre's own steering (a lane change and its
#: settling) leaves up to 2 regular cycles about the moving average in the shipped scenarios (the
#: tractor-semitrailer's ±10-60° at 0.3-0.7 Hz); a limit cycle keeps going.
LIMIT_CYCLE_MIN_CYCLES = 3
#: Frequencies a limit cycle may have (Hz): below 0.2 Hz the 1 s moving average follows the oscillation (under 7 %
#: of it is left) and it is a manoeuvre's pace; above 10 Hz a cycle has under 5 samples at the default 50 Hz
#: controller rate and the steering actuator's lag passes little of it.
LIMIT_CYCLE_FREQUENCY_RANGE_HZ = (0.2, 10.0)
#: How far (fraction of the run's median) each half-period of a limit cycle may stray: it is periodic.
HALF_PERIOD_TOLERANCE = 0.35
#: How far (fraction of the run's median) each half amplitude of a limit cycle may stray: it is sustained, unlike the
#: swings of different sizes a manoeuvre leaves.
AMPLITUDE_TOLERANCE = 0.5


@dataclass(frozen=True)
class LimitCycle:
    """A detected limit cycle (detected True; the other fields None otherwise): frequency_hz = 1 / (2 x the mean
    half-period); amplitude_deg = the steering-wheel amplitude (half peak-to-peak) of a sinusoid at that frequency
    giving the median half amplitude about the moving average (`residual_gain`; 2 % from the raw half amplitude at
    1 and 2 Hz, a factor 2.7 at 0.5 Hz); start_s: time of the run's first turning point; duration_s: the run's
    length."""

    detected: bool
    frequency_hz: float | None = None
    amplitude_deg: float | None = None
    start_s: float | None = None
    duration_s: float | None = None

    def brief(self) -> str:
        """Frequency and amplitude, e.g. "1.0 Hz, ±150°"; "no" when not detected."""
        frequency = self.frequency_hz
        if not self.detected or frequency is None:
            return "no"
        digits = 1 if frequency >= 1.0 else 2
        return f"{frequency:.{digits}f} Hz, ±{self.amplitude_deg:.0f}°"

    def describe(self) -> str:
        """In words, e.g. "1.0 Hz, ±150° steering wheel for 40.0 s from t = 113.0 s"; "no limit cycle" when not
        detected."""
        if not self.detected:
            return "no limit cycle"
        return f"{self.brief()} steering wheel for {self.duration_s:.1f} s from t = {self.start_s:.1f} s"


def window_samples(t_s: np.ndarray) -> int:
    """Samples k of the centred moving average: 1 s at the median step, at least 3, odd (so it is centred)."""
    return max(3, round(MOVING_AVERAGE_S / float(np.median(np.diff(t_s))))) | 1


def residual_gain(frequency_hz: float, k: int, dt_s: float) -> float:
    """Amplitude of a sinusoid at frequency_hz after subtracting its k-sample centred moving average, over its
    amplitude: |1 - sin(pi f k dt) / (k sin(pi f dt))| (the discrete boxcar's gain is real: it is symmetric)."""
    x = math.pi * frequency_hz * dt_s
    return abs(1.0 - math.sin(k * x) / (k * math.sin(x)))


def _checked(t_s: np.ndarray, steer_wheel_rad: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    t, sw = np.asarray(t_s, dtype=float), np.asarray(steer_wheel_rad, dtype=float)
    if t.ndim != 1 or t.shape != sw.shape:
        raise WorkbenchInputError(f"t_s and steer_wheel_rad must be 1-D and equally long; got {t.shape}, {sw.shape}")
    require_finite("t_s", t)
    require_finite("steer_wheel_rad", sw)
    if t.size > 1 and not np.all(np.diff(t) > 0):
        raise WorkbenchInputError(f"t_s must be strictly increasing; it is not at entry {np.argmax(np.diff(t) <= 0)}")
    return t, sw


def oscillation(t_s: np.ndarray, steer_wheel_rad: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """(t_s, deviation in rad) away from the edges: the steering-wheel angle minus its centred moving average over
    k = `window_samples` samples (np.convolve, mode "same"), the first and last k samples dropped (there the
    average runs off the trace); None when there are fewer than 2k + 1 samples. Raises WorkbenchInputError on
    non-finite values or non-increasing time."""
    t, sw = _checked(t_s, steer_wheel_rad)
    if t.size < 2:
        return None
    k = window_samples(t)
    if t.size < 2 * k + 1:
        return None
    deviation = sw - np.convolve(sw, np.ones(k) / k, mode="same")
    return t[k:-k], deviation[k:-k]


def turning_points(x: np.ndarray, deadband: float) -> np.ndarray:
    """Indices of the local extrema of x, alternately minima and maxima, where x reverses by more than deadband
    before the next one (smaller reversals are not turning points). The last extremum is reported once x has
    left it by the deadband."""
    points: list[int] = []
    low = high = 0  # the lowest and highest samples since the last turning point
    rising: bool | None = None
    for i in range(1, x.size):
        if x[i] > x[high]:
            high = i
        if x[i] < x[low]:
            low = i
        if rising is not False and x[high] - x[i] > deadband:  # a maximum, left downwards
            points.append(high)
            rising, low = False, i
        elif rising is not True and x[i] - x[low] > deadband:  # a minimum, left upwards
            points.append(low)
            rising, high = True, i
    return np.array(points, dtype=int)


def _regular(values: np.ndarray, tolerance: float) -> bool:
    """Whether every value is within tolerance (a fraction) of their median."""
    median = np.median(values)
    return bool(np.all(np.abs(values - median) <= tolerance * median))


def _longest_cycle(eligible: np.ndarray, half_periods: np.ndarray, half_amplitudes: np.ndarray) -> tuple[int, int]:
    """[i, j) of the longest (in time) run of consecutive eligible half-cycles with regular half-periods and half
    amplitudes (HALF_PERIOD_TOLERANCE, AMPLITUDE_TOLERANCE), of at least LIMIT_CYCLE_MIN_CYCLES cycles; (0, 0)
    if none. Each run starts at an eligible half-cycle and grows while it stays regular."""
    elapsed = np.concatenate(([0.0], np.cumsum(half_periods)))
    best, best_s = (0, 0), 0.0
    segment_end = 0  # end of the stretch of eligible half-cycles the run starts in
    for i in np.flatnonzero(eligible):
        segment_end = max(segment_end, int(i))
        while segment_end < eligible.size and eligible[segment_end]:
            segment_end += 1
        if elapsed[segment_end] - elapsed[i] <= best_s:  # cannot beat the best
            continue
        j = i + 1
        while (
            j < segment_end
            and _regular(half_periods[i : j + 1], HALF_PERIOD_TOLERANCE)
            and _regular(half_amplitudes[i : j + 1], AMPLITUDE_TOLERANCE)
        ):
            j += 1
        if j - i >= 2 * LIMIT_CYCLE_MIN_CYCLES and elapsed[j] - elapsed[i] > best_s:
            best, best_s = (int(i), int(j)), float(elapsed[j] - elapsed[i])
    return best


def detect_limit_cycle(
    t_s: np.ndarray,
    steer_wheel_rad: np.ndarray,
    *,
    min_amplitude_deg: float = LIMIT_CYCLE_MIN_AMPLITUDE_DEG,
    min_duration_s: float = LIMIT_CYCLE_MIN_DURATION_S,
) -> LimitCycle:
    """The longest limit cycle of the measured steering wheel (see the module docstring), or LimitCycle(False)
    (also for a trace too short for the moving average). Raises WorkbenchInputError on non-finite values or
    non-increasing time."""
    found = oscillation(t_s, steer_wheel_rad)
    if found is None:
        return LimitCycle(False)
    t, deviation_deg = found[0], np.degrees(found[1])
    points = turning_points(deviation_deg, min_amplitude_deg)
    if points.size < 2:
        return LimitCycle(False)
    half_amplitudes = np.abs(np.diff(deviation_deg[points])) / 2.0
    half_periods = np.diff(t[points])
    low_hz, high_hz = LIMIT_CYCLE_FREQUENCY_RANGE_HZ
    eligible = (half_amplitudes > min_amplitude_deg) & (half_periods >= 0.5 / high_hz) & (half_periods <= 0.5 / low_hz)
    i, j = _longest_cycle(eligible, half_periods, half_amplitudes)
    duration = float(np.sum(half_periods[i:j]))
    if j == i or duration < min_duration_s:
        return LimitCycle(False)
    frequency = (j - i) / (2.0 * duration)  # the mean half-period: a half-period is a whole number of samples
    t_all = np.asarray(t_s, dtype=float)
    gain = residual_gain(frequency, window_samples(t_all), float(np.median(np.diff(t_all))))
    return LimitCycle(
        detected=True,
        frequency_hz=frequency,
        amplitude_deg=float(np.median(half_amplitudes[i:j])) / gain,
        start_s=float(t[points[i]]),
        duration_s=duration,
    )


__all__ = [
    "AMPLITUDE_TOLERANCE",
    "HALF_PERIOD_TOLERANCE",
    "LIMIT_CYCLE_FREQUENCY_RANGE_HZ",
    "LIMIT_CYCLE_MIN_AMPLITUDE_DEG",
    "LIMIT_CYCLE_MIN_CYCLES",
    "LIMIT_CYCLE_MIN_DURATION_S",
    "MOVING_AVERAGE_S",
    "LimitCycle",
    "detect_limit_cycle",
    "oscillation",
    "residual_gain",
    "turning_points",
    "window_samples",
]
