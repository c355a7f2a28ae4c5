"""The MPCs' optional pose filter (`MPCConfig.pose_filter_cutoff_hz`, off by default): a complementary filter
that dead-reckons the pose with the measured velocity and yaw rate and pulls it toward the measured pose at a
first-order crossover (`PoseFilter`). Pose noise in the loop's own correction band (the NMPC corrects an offset with
an S-shaped steering pulse at 0.6-0.8 Hz on the loaded truck) then no longer drives the steering, where a low-pass on
the command would have to cut into that band; the motion the rates describe passes without lag, so the delay
compensation needs nothing more.
"""

from __future__ import annotations

import math

from controllers.base import Measurement
from workbench.base.path import wrap_angle

#: The largest crossover frequency of the pose filter (Hz): far above it the filter passes the measurement as it is.
MAX_POSE_FILTER_HZ = 100.0
#: The pose filter's crossover (Hz) an MPC told a noisy pose switches on (`MPCController.informed_config`): below
#: the loop's own offset correction (an S-shaped steering pulse at 0.6-0.8 Hz on the loaded truck), so that pose
#: noise in that band no longer drives the steering, while the motion the rates describe passes without lag.
INFORMED_POSE_FILTER_CUTOFF_HZ = 0.3


class PoseFilter:
    """Complementary filter on the measured pose (x, y, yaw) at crossover frequency `cutoff_hz`.

    Each step it dead-reckons its estimate over the time dt since the last step with the measured body velocity and
    yaw rate (the velocities' mean and the yaw rate at the interval's middle, held: an arc, integrated exactly), then
    moves it toward the measured pose by k = 1 - exp(-2 pi cutoff_hz dt): the measured pose through a first-order
    low-pass at the cutoff, plus the dead-reckoned motion through the complementary high-pass. With exact signals the
    estimate is the measured pose (exactly on an arc; to the change of the rates within a step otherwise); white pose
    noise keeps k / (2 - k) of its variance per axis. The yaw rate is taken where the pose is: `yaw_rate_lead_s` (the
    yaw rate's latency minus the pose's) shifts it along the line through its last two samples. The first
    measurement after a reset is taken as it is; a pose held by a slower localisation (or, with a latency, before the
    run's start) counts as measured again, as it does without the filter, and the estimate runs ahead of it until
    the hold ends."""

    def __init__(self, cutoff_hz: float, yaw_rate_lead_s: float = 0.0) -> None:
        self.cutoff_hz, self.yaw_rate_lead_s = float(cutoff_hz), float(yaw_rate_lead_s)
        self.reset()

    def reset(self) -> None:
        """Forget the estimate: the next measurement starts it."""
        self._previous: Measurement | None = None
        self._x = self._y = self._yaw = 0.0

    def gain(self, elapsed_s: float) -> float:
        """The correction gain k after `elapsed_s` seconds without one."""
        return 1.0 - math.exp(-2.0 * math.pi * self.cutoff_hz * elapsed_s)

    def __call__(self, m: Measurement) -> Measurement:
        """The measurement with its pose replaced by the filter's estimate."""
        previous = self._previous
        self._previous = m
        if previous is None:
            self._x, self._y, self._yaw = m.x_m, m.y_m, m.yaw_rad
            return m
        dt = m.t_s - previous.t_s
        if dt > 0.0:  # (a repeated time stamp adds nothing)
            # The yaw rate at the middle of the interval the pose moved over: samples dt apart, the newer describing
            # yaw_rate_lead_s before the pose's time (-1/2: their mean when the latencies agree).
            c = self.yaw_rate_lead_s / dt - 0.5
            rate = m.yaw_rate_rad_s + c * (m.yaw_rate_rad_s - previous.yaw_rate_rad_s)
            vx, vy = 0.5 * (m.vx_mps + previous.vx_mps), 0.5 * (m.vy_mps + previous.vy_mps)
            half = 0.5 * rate * dt  # the arc's chord: exact for constant body velocity and yaw rate
            chord = dt * (math.sin(half) / half if abs(half) > 1e-4 else 1.0 - half * half / 6.0)
            cos_m, sin_m = math.cos(self._yaw + half), math.sin(self._yaw + half)
            k = self.gain(dt)
            self._x += chord * (cos_m * vx - sin_m * vy)
            self._x += k * (m.x_m - self._x)
            self._y += chord * (sin_m * vx + cos_m * vy)
            self._y += k * (m.y_m - self._y)
            self._yaw += rate * dt
            self._yaw += k * float(wrap_angle(m.yaw_rad - self._yaw))
        yaw = m.yaw_rad - float(wrap_angle(m.yaw_rad - self._yaw))  # the estimate, on the measurement's branch
        return Measurement(m.t_s, self._x, self._y, m.vx_mps, m.vy_mps, yaw, m.yaw_rate_rad_s, m.steer_wheel_rad)
