"""What a controller may be told about a run's conditions: their nominal latencies, dead time and pose noise
(`KnownDelays`).

A real vehicle's controller is configured knowing its sensors' and actuator's nominal delays (a data sheet, a
bench measurement); it does not know the noise that is drawn in a run. `KnownDelays.from_conditions` takes those
nominal values from a run's `Conditions`, and each controller turns them into its own options
(`controllers.base.Controller.informed_config`: the clothoid controller's `known_delay_s`, the MPCs' delay
compensation and pose filter; Stanley and pure pursuit have nothing to set). Whether a run's controllers are told
is the run's choice (`SimulationConfig.inform_delays`, `workbench run --inform-delays`), never implied by the
conditions themselves.

What is not told: the localisation's update rate (a held pose is on average half a period older than its
latency says), the steering sensor's latency and quantisation, the road's friction, and every bias: the nominal
latencies and dead time are what the controllers here can compensate.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from workbench.base.errors import require_in_range
from workbench.simulation.conditions import MAX_ANGLE_SIGMA_RAD, MAX_LATENCY_S, MAX_POSITION_SIGMA_M, Conditions

#: The largest pose_noise_m (m): white noise and drift, each at the conditions' largest sigma, together.
MAX_POSE_NOISE_M = math.hypot(MAX_POSITION_SIGMA_M, MAX_POSITION_SIGMA_M)


@dataclass(frozen=True)
class KnownDelays:
    """The nominal delays and pose noise of a run's conditions, as a controller may be told them.

    Parameters
    ----------
    pose_latency_s : float
        The localisation's latency (s): the pose and velocity stamped t describe t - pose_latency_s.
    yaw_rate_latency_s : float
        The measured yaw rate's own latency (s), e.g. over a vehicle bus.
    dead_time_s : float
        The actuation dead time (s): a steering command sent at t reaches the steering at t + dead_time_s.
    pose_noise_m : float
        The sigma of the measured position's error on x and on y (m): white noise and Gauss-Markov drift
        together, sqrt(noise^2 + drift^2). Greater than 0: the pose is noisy.
    heading_noise_rad : float
        The sigma of the white noise on the measured yaw (rad). Greater than 0: the pose is noisy.

    Every value is refused outside the range the conditions allow, naming the field and the range.
    """

    pose_latency_s: float = 0.0
    yaw_rate_latency_s: float = 0.0
    dead_time_s: float = 0.0
    pose_noise_m: float = 0.0
    heading_noise_rad: float = 0.0

    def __post_init__(self) -> None:
        require_in_range("pose_latency_s", self.pose_latency_s, 0.0, MAX_LATENCY_S, "s")
        require_in_range("yaw_rate_latency_s", self.yaw_rate_latency_s, 0.0, MAX_LATENCY_S, "s")
        require_in_range("dead_time_s", self.dead_time_s, 0.0, MAX_LATENCY_S, "s")
        require_in_range("pose_noise_m", self.pose_noise_m, 0.0, MAX_POSE_NOISE_M, "m")
        require_in_range("heading_noise_rad", self.heading_noise_rad, 0.0, MAX_ANGLE_SIGMA_RAD, "rad")

    @classmethod
    def from_conditions(cls, conditions: Conditions) -> KnownDelays:
        """The nominal values of `conditions`: the localisation's latency and the yaw rate's, the actuation dead
        time, the position's white noise and drift combined, and the heading noise."""
        loc = conditions.localisation
        return cls(
            pose_latency_s=loc.latency_s,
            yaw_rate_latency_s=conditions.inertial.latency_s,
            dead_time_s=conditions.actuation.dead_time_s,
            pose_noise_m=math.hypot(loc.position_noise_m, loc.position_drift_m),
            heading_noise_rad=loc.heading_noise_rad,
        )

    @property
    def loop_delay_s(self) -> float:
        """The dead time in the steering loop (s): the pose's latency plus the actuation dead time."""
        return self.pose_latency_s + self.dead_time_s

    @property
    def pose_is_noisy(self) -> bool:
        """Whether the measured pose (position or heading) carries noise or drift."""
        return self.pose_noise_m > 0.0 or self.heading_noise_rad > 0.0

    def describe(self) -> str:
        """One line in words, for a report."""
        noise = f"pose sigma {self.pose_noise_m:g} m, heading sigma {math.degrees(self.heading_noise_rad):.3g} deg"
        return (
            f"pose latency {self.pose_latency_s * 1e3:g} ms, yaw-rate latency {self.yaw_rate_latency_s * 1e3:g} ms, "
            f"steering dead time {self.dead_time_s * 1e3:g} ms, {noise if self.pose_is_noisy else 'pose not noisy'}"
        )


__all__ = ["MAX_POSE_NOISE_M", "KnownDelays"]
