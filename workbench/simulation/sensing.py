"""The conditions' models (`workbench.simulation.conditions`): what the controller sees (`SensorModel`) and how
its steering command reaches the plant (`ActuatorModel`). Both are seeded or deterministic, cheap (a few
microseconds a call in plain Python, no array allocated per step) and pass their input through unchanged under
ideal conditions.

SensorModel.measure(true) is called once per controller step with the plant's true Measurement and returns the
one the controller sees:

- Latency: a signal seen at time t is the true one at t - latency, linearly interpolated between the controller
  steps in a short buffer of past true measurements (the yaw unwrapped between two steps first), so a latency
  that is not a whole number of steps is honoured exactly for a signal linear in time; before the run's first
  measurement (t - latency < its time) the first one is used. The pose (x, y, yaw) and the velocity (vx, vy)
  have the localisation's latency, the yaw rate the inertial one, the steering-wheel angle the steering
  sensor's.
- Update rate: with one, the pose and the velocity are refreshed only at the multiples k / update_rate_hz of the
  run's clock (at the first controller step at or after each) and held in between; a refresh at epoch time
  T_k shows the true pose at T_k - latency. Without one they are refreshed every controller step.
- Noise: white noise, and on x and y a first-order Gauss-Markov drift by its exact discretisation
  d_{k+1} = a d_k + sigma sqrt(1 - a^2) w_k, a = exp(-Delta / tau), Delta the time between refreshes, started
  from its stationary distribution (d_0 = sigma w_0); the pose's and the speed's noise is drawn with each refresh
  (a held pose keeps its noise), the yaw rate's and the steering angle's every step; then the yaw-rate bias and
  the steering angle's quantisation (rounding to the nearest multiple, after the noise).
- Time: the seen Measurement's t_s is the current time, the time the controller steps at, not the time its
  (stale) data describe: a controller sees no timestamp of its data, as with a real sensor it would have to be
  told the latency.

Seeds: each noise source draws from its own numpy Generator, a child spawned from `SeedSequence(seed)` in the
order of NOISE_SOURCES, so the same seed gives the same sequences, and changing one source's setting (its sigma,
or the update rate that sets how often it draws) leaves every other source's draws unchanged.

ActuatorModel.segments(cmd) is called once per controller step with the command the controller computed and
returns the (number of plant substeps, steering-wheel command) segments to apply in order over that step: the
command applied from time t is the one computed at t - dead_time (the dead time rounded to the nearest plant
step), the command before the first is the steering measured at `reset`; a tighter rate limit then acts on the
delayed command, segment by segment: each segment's command differs from the one before by at most
max_steer_wheel_rate_rad_s x the segment's duration (the value a ramp at the limit reaches by the segment's end).
"""

from __future__ import annotations

import math

import numpy as np

from workbench.base.errors import WorkbenchInputError, require_positive, value_text
from workbench.simulation.conditions import Conditions
from workbench.simulation.control_interface import Measurement

#: The noise sources, each drawing from its own stream, spawned from the seed in this order (append a new source
#: at the end, so that the existing sources keep their draws).
NOISE_SOURCES = ("position_noise", "position_drift", "heading_noise", "speed_noise", "yaw_rate_noise", "steering_noise")
#: Normal draws taken from a stream at a time (the values do not depend on it: a Generator's block of n draws is
#: its next n single draws).
_BLOCK = 512
#: Tolerance (in update periods) when finding the update epoch of a time that is a sum of controller steps.
_EPOCH_TOLERANCE = 1e-6
_TWO_PI = 2.0 * math.pi


def _check_seed(seed: object) -> int:
    if isinstance(seed, bool) or not isinstance(seed, int | np.integer) or seed < 0:
        raise WorkbenchInputError(f"seed must be a whole number >= 0; got {value_text(seed)}")
    return int(seed)


class _Normals:
    """Standard normal draws from one stream, taken in blocks (a call returns the stream's next draw)."""

    __slots__ = ("_block", "_i", "_rng")

    def __init__(self, seed_sequence: np.random.SeedSequence) -> None:
        self._rng = np.random.Generator(np.random.PCG64(seed_sequence))
        self._block: list[float] = []
        self._i = 0

    def __call__(self) -> float:
        i = self._i
        if i == len(self._block):
            self._block = self._rng.standard_normal(_BLOCK).tolist()
            i = 0
        self._i = i + 1
        return self._block[i]


class SensorModel:
    """What the controller sees of the plant under `conditions` (see the module docstring).

    seed: the noise's seed (a whole number >= 0); sample_time_s: the controller's step (s), which sizes the buffer
    of past measurements and times the drift without an update rate.
    """

    def __init__(self, conditions: Conditions, seed: int = 0, sample_time_s: float = 0.02) -> None:
        require_positive("sample_time_s", sample_time_s)
        if not isinstance(conditions, Conditions):
            raise WorkbenchInputError(f"conditions must be a Conditions; got {value_text(conditions)}")
        self.conditions = conditions
        self.sample_time_s = float(sample_time_s)
        self.seed = _check_seed(seed)
        loc, ine, ste = conditions.localisation, conditions.inertial, conditions.steering_sensor
        dt = self.sample_time_s
        #: Nothing to do: measure returns its input.
        self.is_ideal = conditions.sensing_is_ideal
        self._pose_active = not loc.is_ideal or ine.speed_noise_mps > 0.0
        self._rate = loc.update_rate_hz
        self._pose_latency = loc.latency_s
        self._yaw_rate_latency = ine.latency_s
        self._steer_latency = ste.latency_s
        self._buffered = loc.latency_s > 0.0 or loc.update_rate_hz is not None or ine.latency_s > 0.0
        self._buffered = self._buffered or ste.latency_s > 0.0
        lookback = max(loc.latency_s, ine.latency_s, ste.latency_s) + dt
        self._capacity = math.ceil(lookback / dt) + 3
        self._sigma_position = loc.position_noise_m
        self._sigma_drift = loc.position_drift_m
        self._drift_time = loc.position_drift_time_s
        self._sigma_heading = loc.heading_noise_rad
        self._sigma_speed = ine.speed_noise_mps
        self._sigma_yaw_rate = ine.yaw_rate_noise_rad_s
        self._yaw_rate_bias = ine.yaw_rate_bias_rad_s
        self._sigma_steer = ste.noise_rad
        self._quantum = ste.quantisation_rad
        #: The drift's refresh interval (s) and, by the number of intervals a refresh spans (more than 1 when
        #: the update rate is above the controller's), its (a, sqrt(1 - a^2)).
        self._refresh_interval = dt if self._rate is None else 1.0 / self._rate
        self._drift_factors: dict[int, tuple[float, float]] = {}
        self.reset()

    def _gauss_markov(self, interval_s: float) -> tuple[float, float]:
        a = math.exp(-interval_s / self._drift_time)
        return a, math.sqrt(max(0.0, 1.0 - a * a))

    def reset(self, seed: int | None = None) -> None:
        """Start again: the noise from the seed (the given one, which becomes this model's, or the model's own),
        no past measurements, no pose held."""
        if seed is not None:
            self.seed = _check_seed(seed)
        streams = [_Normals(child) for child in np.random.SeedSequence(self.seed).spawn(len(NOISE_SOURCES))]
        (
            self._n_position,
            self._n_drift,
            self._n_heading,
            self._n_speed,
            self._n_yaw_rate,
            self._n_steer,
        ) = streams
        #: The last true measurements, a ring of `_capacity` once full (it fills by appending).
        self._buffer: list[Measurement] = []
        self._count = 0
        self._epoch: int | None = None
        #: The pose the controller is shown (x, y, yaw, vx, vy); NaN until the first step refreshes it.
        self._held: tuple[float, float, float, float, float] = (math.nan,) * 5
        self._drift_x = self._drift_y = 0.0
        self._drift_started = False

    # ----------------------------------------------------------------------------------------------- measuring
    def measure(self, true: Measurement) -> Measurement:
        """What the controller sees at this step, given the plant's true measurement (called once per controller
        step, in time order; t_s of the result is true.t_s)."""
        if self.is_ideal:
            return true
        t = true.t_s
        if self._buffered:
            if self._count < self._capacity:
                self._buffer.append(true)
            else:
                self._buffer[self._count % self._capacity] = true
            self._count += 1
        if self._pose_active:
            rate = self._rate
            if rate is None:
                self._refresh_pose(true, t - self._pose_latency, 1)
            else:
                epoch = math.floor(t * rate + _EPOCH_TOLERANCE)
                if epoch != self._epoch:
                    skipped = 1 if self._epoch is None else epoch - self._epoch
                    self._epoch = epoch
                    self._refresh_pose(true, epoch / rate - self._pose_latency, skipped)
            x, y, yaw, vx, vy = self._held
        else:
            x, y, yaw, vx, vy = true.x_m, true.y_m, true.yaw_rad, true.vx_mps, true.vy_mps

        yaw_rate = true.yaw_rate_rad_s
        if self._yaw_rate_latency > 0.0:
            a, b, f = self._bracket(t - self._yaw_rate_latency)
            yaw_rate = a.yaw_rate_rad_s + f * (b.yaw_rate_rad_s - a.yaw_rate_rad_s)
        if self._sigma_yaw_rate > 0.0:
            yaw_rate += self._sigma_yaw_rate * self._n_yaw_rate()
        yaw_rate += self._yaw_rate_bias

        steer = true.steer_wheel_rad
        if self._steer_latency > 0.0:
            a, b, f = self._bracket(t - self._steer_latency)
            steer = a.steer_wheel_rad + f * (b.steer_wheel_rad - a.steer_wheel_rad)
        if self._sigma_steer > 0.0:
            steer += self._sigma_steer * self._n_steer()
        if self._quantum > 0.0:
            steer = self._quantum * round(steer / self._quantum)
        return Measurement(t, x, y, vx, vy, yaw, yaw_rate, steer)

    def _refresh_pose(self, true: Measurement, when_s: float, intervals: int) -> None:
        """A new pose and velocity: the true ones at `when_s` (interpolated), their noise drawn, the drift advanced
        by `intervals` refresh intervals."""
        if self._buffered:
            a, b, f = self._bracket(when_s)
            if f == 0.0:
                x, y, yaw, vx, vy = a.x_m, a.y_m, a.yaw_rad, a.vx_mps, a.vy_mps
            else:
                x = a.x_m + f * (b.x_m - a.x_m)
                y = a.y_m + f * (b.y_m - a.y_m)
                yaw = a.yaw_rad + f * math.remainder(b.yaw_rad - a.yaw_rad, _TWO_PI)
                vx = a.vx_mps + f * (b.vx_mps - a.vx_mps)
                vy = a.vy_mps + f * (b.vy_mps - a.vy_mps)
        else:
            x, y, yaw, vx, vy = true.x_m, true.y_m, true.yaw_rad, true.vx_mps, true.vy_mps
        sigma = self._sigma_position
        if sigma > 0.0:
            x += sigma * self._n_position()
            y += sigma * self._n_position()
        sigma = self._sigma_drift
        if sigma > 0.0:
            draw = self._n_drift
            if not self._drift_started:  # from the stationary distribution
                self._drift_x, self._drift_y = sigma * draw(), sigma * draw()
                self._drift_started = True
            else:
                factors = self._drift_factors.get(intervals)
                if factors is None:
                    factors = self._drift_factors[intervals] = self._gauss_markov(intervals * self._refresh_interval)
                a_k, b_k = factors
                self._drift_x = a_k * self._drift_x + sigma * b_k * draw()
                self._drift_y = a_k * self._drift_y + sigma * b_k * draw()
            x += self._drift_x
            y += self._drift_y
        if self._sigma_heading > 0.0:
            yaw += self._sigma_heading * self._n_heading()
        sigma = self._sigma_speed
        if sigma > 0.0:
            speed = math.hypot(vx, vy)
            noise = sigma * self._n_speed()
            if speed > 1e-9:  # on the magnitude: the direction of travel is kept
                scale = (speed + noise) / speed
                vx, vy = vx * scale, vy * scale
            else:
                vx += noise
        self._held = (x, y, yaw, vx, vy)

    def _bracket(self, when_s: float) -> tuple[Measurement, Measurement, float]:
        """(a, b, f): the buffered true measurements around time `when_s` and the fraction of the way from a to b
        (f = 0 and b = a at or beyond either end of the buffer: its last, or the run's first measurement)."""
        buf, cap, count = self._buffer, self._capacity, self._count
        last = buf[(count - 1) % cap]
        if when_s >= last.t_s:
            return last, last, 0.0
        oldest = count - cap if count > cap else 0
        j = count - 1 - math.ceil((last.t_s - when_s) / self.sample_time_s - 1e-9)
        j = max(j, oldest)
        a = buf[j % cap]
        while a.t_s > when_s and j > oldest:
            j -= 1
            a = buf[j % cap]
        if a.t_s > when_s:  # before the first measurement: hold it
            return a, a, 0.0
        b = buf[(j + 1) % cap]
        while b.t_s <= when_s:  # ends: b is at most `last`, later than when_s
            j += 1
            a, b = b, buf[(j + 1) % cap]
        return a, b, (when_s - a.t_s) / (b.t_s - a.t_s)


class ActuatorModel:
    """How the steering-wheel command reaches the plant under `conditions` (see the module docstring).

    sample_time_s: the controller's step (s); plant_substeps: the plant's steps per controller step (the plant
    integrates them with each segment's command held).
    """

    def __init__(self, conditions: Conditions, sample_time_s: float, plant_substeps: int) -> None:
        require_positive("sample_time_s", sample_time_s)
        if not isinstance(conditions, Conditions):
            raise WorkbenchInputError(f"conditions must be a Conditions; got {value_text(conditions)}")
        if isinstance(plant_substeps, bool) or not isinstance(plant_substeps, int | np.integer) or plant_substeps < 1:
            raise WorkbenchInputError(f"plant_substeps must be a whole number >= 1; got {value_text(plant_substeps)}")
        act = conditions.actuation
        self.conditions = conditions
        self.sample_time_s = float(sample_time_s)
        self.plant_substeps = int(plant_substeps)
        self.plant_step_s = self.sample_time_s / self.plant_substeps
        #: The dead time in plant steps (rounded to the nearest).
        self.dead_time_substeps = round(act.dead_time_s / self.plant_step_s)
        self._whole, self._part = divmod(self.dead_time_substeps, self.plant_substeps)
        rate = act.max_steer_wheel_rate_rad_s
        self._max_change_per_substep = None if rate is None else rate * self.plant_step_s
        #: Nothing to do: segments returns [(plant_substeps, the command)].
        self.is_ideal = act.is_ideal
        self.reset()

    def reset(self, initial_steer_wheel_rad: float = 0.0) -> None:
        """Start again, the command before the controller's first being `initial_steer_wheel_rad` (the steering
        measured at the start)."""
        initial = float(initial_steer_wheel_rad)
        if not math.isfinite(initial):
            raise WorkbenchInputError(f"initial_steer_wheel_rad must be finite; got {value_text(initial)}")
        self._history = [initial] * (self._whole + 2)  # the commands of steps k - whole - 1 ... k
        self._step = 0
        self._applied = initial

    def segments(self, steer_wheel_cmd_rad: float) -> list[tuple[int, float]]:
        """The (plant substeps, steering-wheel command) segments to apply, in order, over this controller step,
        given the command the controller computed at its start; their substeps add up to plant_substeps."""
        substeps = self.plant_substeps
        if self.is_ideal:
            return [(substeps, steer_wheel_cmd_rad)]
        k = self._step
        self._history[k % len(self._history)] = steer_wheel_cmd_rad
        self._step = k + 1
        out, self._applied = self._limited(self._delayed(k, substeps), self._applied)
        return out

    def segments_ahead(self) -> list[tuple[int, float]]:
        """The (plant substeps, steering-wheel command) segments the plant will apply over the next dead time, from
        the commands already sent (the dead time's worth of them decides it): what a perfect delay compensation
        knows before this step's command is sent. Changes nothing; their substeps add up to the dead time's.

        Returns
        -------
        list of (int, float)
            The segments, in order; none without a dead time.
        """
        out: list[tuple[int, float]] = []
        applied, k = self._applied, self._step
        for j in range(self._whole + 1):  # the whole steps of the dead time, then its part of the next
            n = self.plant_substeps if j < self._whole else self._part
            if n == 0:
                break
            segments, applied = self._limited(self._delayed(k + j, n), applied)
            out += segments
        return out

    def _delayed(self, k: int, substeps: int) -> tuple[tuple[int, float], ...]:
        """The commands that reach the plant over the first `substeps` (at least the dead time's part of a step)
        plant steps of controller step k, before the rate limit: those sent dead_time_substeps earlier (the dead
        time honoured to the plant's step)."""
        history, whole, part = self._history, self._whole, self._part
        size = len(history)
        late = history[(k - whole) % size]
        if not part:
            return ((substeps, late),)
        early = (part, history[(k - whole - 1) % size])
        return (early, (substeps - part, late)) if substeps > part else (early,)

    def _limited(
        self, raw: tuple[tuple[int, float], ...], applied: float
    ) -> tuple[list[tuple[int, float]], float]:
        """The segments `raw` under the rate limit from the command applied before them, merging equal
        neighbours; and the command applied after them."""
        limit = self._max_change_per_substep
        out: list[tuple[int, float]] = []
        for n, command in raw:
            if limit is not None:
                change = limit * n
                if command - applied > change:
                    command = applied + change
                elif applied - command > change:
                    command = applied - change
            applied = command
            if out and out[-1][1] == command:
                out[-1] = (out[-1][0] + n, command)
            else:
                out.append((n, command))
        return out, applied


__all__ = ["NOISE_SOURCES", "ActuatorModel", "SensorModel"]
