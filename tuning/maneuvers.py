"""Open-loop steering-wheel profiles used to identify the steering-to-curvature lag (paper, section 5.1).

Each maneuver is a function of time returning the steering-wheel angle (rad). `dlc` is a double-lane-change
steering profile (one sine period to the left lane, a hold, one opposite period back), `step` a single step,
`step-series` the series of alternating steps of the paper's Figure 8b, and `chirp` a sine sweep of the steering
wheel whose frequency rises exponentially from start_hz to end_hz (default 0.1 to 2 Hz) over the rest of the log.

Why the chirp: the step responses and the dlc have little energy above about 1 Hz, where a pure delay and the
damping of Eq. 5 differ (both add phase lag; only the damping also bends the magnitude), so a fit of Eq. 5 with a
delay to them alone trades one for the other (the loaded truck's zeta ran to 7-10 from 40 km/h, the delay jumping
with it). The sweep puts equal energy in every octave up to 2 Hz (12.6 rad/s), past the loop's crossover, so the
fit sees the frequency response there.

max_rate_deg_s limits the steering-wheel rate of any profile (slew-rate limiting: the steps become ramps), and the
chirp's amplitude falls as 1 / frequency where amplitude x 2 pi f would exceed it, so that the large amplitudes of
low speeds do not drive the actuator into its rate limit (a nonlinearity the linear lag cannot describe: the
kinematic bicycle, a 0.05 s first-order actuator, identified as omega_n 16.5 rad/s at 20 km/h against 139-154 at
higher speeds before; 80 rad/s, zeta 2 at every speed with the limit at half the actuator's).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from workbench.base.errors import WorkbenchInputError, require_in_range, require_positive

#: Time step (s) of the slew-rate limiter of max_rate_deg_s.
_SLEW_STEP_S = 1e-3


@dataclass(frozen=True)
class Maneuver:
    """A steering-wheel profile: amplitude_deg (steering-wheel degrees), duration_s, and the profile's kind.

    step: 0 until start_s, then amplitude. step-series: steps of +amplitude, 0, -amplitude, 0 ... each held
    hold_s. dlc: amplitude * sin(2 pi (t - start) / period) for one period, a hold of hold_s, then the opposite.
    chirp: amplitude * sin(phase(t)) from start_s to duration_s, the frequency rising exponentially from start_hz
    to end_hz, its amplitude at frequency f at most max_rate_deg_s / (2 pi f). max_rate_deg_s (deg/s, None: no
    limit): every profile is slew-rate limited to it.
    """

    kind: str
    amplitude_deg: float = 90.0
    start_s: float = 1.0
    hold_s: float = 4.0
    period_s: float = 4.0
    duration_s: float = 20.0
    start_hz: float = 0.1
    end_hz: float = 2.0
    max_rate_deg_s: float | None = None

    KINDS = ("step", "step-series", "dlc", "chirp")

    def __post_init__(self) -> None:
        if self.kind not in self.KINDS:
            raise WorkbenchInputError(f"unknown maneuver {self.kind!r}; choose one of {', '.join(self.KINDS)}")
        require_in_range("amplitude_deg", self.amplitude_deg, -1080.0, 1080.0, "deg")
        if self.amplitude_deg == 0:
            raise WorkbenchInputError("amplitude_deg must be non-zero: a zero profile cannot excite the vehicle")
        require_in_range("start_s", self.start_s, 0.0, 1e4, "s")
        require_positive("hold_s", self.hold_s)
        require_positive("period_s", self.period_s)
        require_positive("duration_s", self.duration_s)
        require_in_range("start_hz", self.start_hz, 1e-3, 50.0, "Hz")
        require_in_range("end_hz", self.end_hz, self.start_hz, 50.0, "Hz (at least start_hz)")
        if self.max_rate_deg_s is not None:
            require_positive("max_rate_deg_s", self.max_rate_deg_s)
        if self.kind == "chirp" and self.duration_s <= self.start_s:
            raise WorkbenchInputError(
                f"a chirp needs duration_s > start_s; got duration_s {self.duration_s!r}, start_s {self.start_s!r}"
            )

    def chirp_frequency_hz(self, t_s: np.ndarray) -> np.ndarray:
        """The chirp's instantaneous frequency (Hz) at t_s (start_hz before the sweep, end_hz after it)."""
        span = self.duration_s - self.start_s
        u = np.clip((np.asarray(t_s, dtype=float) - self.start_s) / span, 0.0, 1.0)
        return self.start_hz * (self.end_hz / self.start_hz) ** u

    def steer_wheel_rad(self, t_s: np.ndarray) -> np.ndarray:
        """The steering-wheel angle (rad) at times t_s (s); with max_rate_deg_s, slew-rate limited to it."""
        t = np.asarray(t_s, dtype=float)
        if self.max_rate_deg_s is None or t.size == 0:
            return self._profile(t)
        # the profile on a fine grid, its rate limited sample by sample, read at t
        fine = np.arange(0.0, max(float(t.max()), 0.0) + 2 * _SLEW_STEP_S, _SLEW_STEP_S)
        raw = self._profile(fine)
        limited = np.empty_like(raw)
        step = math.radians(self.max_rate_deg_s) * _SLEW_STEP_S
        value = 0.0
        for i, target in enumerate(raw.tolist()):
            value += min(max(target - value, -step), step)
            limited[i] = value
        return np.interp(t, fine, limited)

    def _profile(self, t_s: np.ndarray) -> np.ndarray:
        t = np.asarray(t_s, dtype=float) - self.start_s
        a = math.radians(self.amplitude_deg)
        if self.kind == "step":
            return np.where(t >= 0.0, a, 0.0)
        if self.kind == "step-series":
            phase = np.floor(np.maximum(t, 0.0) / self.hold_s).astype(int) % 4
            return np.where(t >= 0.0, np.choose(phase, [a, 0.0, -a, 0.0]), 0.0)
        if self.kind == "chirp":
            return self._chirp(t, a)
        # dlc: sine out, hold, sine back
        first = (t >= 0.0) & (t < self.period_s)
        t2 = t - self.period_s - self.hold_s
        second = (t2 >= 0.0) & (t2 < self.period_s)
        return a * (
            np.where(first, np.sin(2 * np.pi * t / self.period_s), 0.0)
            - np.where(second, np.sin(2 * np.pi * t2 / self.period_s), 0.0)
        )

    def _chirp(self, t: np.ndarray, a: float) -> np.ndarray:
        """a sin(2 pi integral of f) over [0, span) of t (time from start_s), f = start_hz ratio^(t / span)."""
        span = self.duration_s - self.start_s
        ratio = self.end_hz / self.start_hz
        inside = (t >= 0.0) & (t < span)
        u = np.clip(t / span, 0.0, 1.0)
        if ratio == 1.0:
            phase = 2 * np.pi * self.start_hz * span * u
        else:
            phase = 2 * np.pi * self.start_hz * span * (ratio**u - 1.0) / math.log(ratio)
        amplitude = np.full_like(t, abs(a))
        if self.max_rate_deg_s is not None:
            frequency = self.start_hz * ratio**u
            amplitude = np.minimum(amplitude, math.radians(self.max_rate_deg_s) / (2 * np.pi * frequency))
        return np.where(inside, math.copysign(1.0, a) * amplitude * np.sin(phase), 0.0)


@dataclass(frozen=True)
class Braking:
    """A braking pulse of the held speed: the speed reference falls at decel_mps2 (m/s^2, > 0) from start_s (s)
    for duration_s (s), then holds where it ended; the speed control feeds the fall's rate forward, so the
    vehicle brakes at about decel_mps2. The pulse of the sideslip-release identification (`tuning.release_fit`).
    """

    start_s: float  # s, >= 0: when the braking starts
    duration_s: float  # s, > 0: how long it lasts
    decel_mps2: float = 2.0  # m/s^2, in (0, 10]: the deceleration

    def __post_init__(self) -> None:
        require_in_range("start_s", self.start_s, 0.0, 1e4, "s")
        require_in_range("duration_s", self.duration_s, 0.0, 60.0, "s", low_open=True)
        require_in_range("decel_mps2", self.decel_mps2, 0.0, 10.0, "m/s^2", low_open=True)

    @property
    def end_s(self) -> float:
        """When the braking ends (s)."""
        return self.start_s + self.duration_s

    def speed_ref(self, t_s: float, speed_mps: float) -> tuple[float, float]:
        """(speed reference m/s, its rate m/s^2) at t_s of a run held at speed_mps before the pulse."""
        if t_s < self.start_s:
            return speed_mps, 0.0
        if t_s < self.end_s:
            return speed_mps - self.decel_mps2 * (t_s - self.start_s), -self.decel_mps2
        return speed_mps - self.decel_mps2 * self.duration_s, 0.0
