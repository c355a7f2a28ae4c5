"""PI speed controller that follows the planned speed profile.

The paper's simulations (Shaju, Southward & Ahmadian 2024, section 6) run a speed controller next to the
lateral controller so the vehicle follows the smart velocity waypoints (`workbench.simulation.speed_profile`). This is
that controller: a PI law on the speed error plus a feed-forward of the reference's own rate of change, whose
output is a longitudinal acceleration command, saturated, with conditional-integration anti-windup.

Why the feed-forward: the plants realise the acceleration command directly (dv/dt = u), so a PI law alone tracks a
reference ramping at rate a with the transient error e(t) = a (exp(r2 t) - exp(r1 t)) / (r2 - r1), r1,2 the roots
of s^2 + kp s + ki: for the default gains it peaks at 0.76 a after 2.2 s (1.5 m/s behind a 2 m/s^2 braking
ramp), and the braking before a corner is often over sooner, so the vehicle enters the corner too fast. With the rate
fed forward the error obeys e'' + kp e' + ki e = 0 whatever the reference does (within the saturation): a
reference followed from zero error is followed exactly.

`pi_speed_step` is the same law compiled, its gains and integrator in an array (`pi_state`), for the simulator's
per-step kernel (`workbench.simulation.step_kernel`): the same arithmetic in the same order, so the same commands.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from workbench.base.errors import WorkbenchInputError, require_in_range, require_positive

#: Layout of `pi_state`'s array: the gains (kp 1/s, ki 1/s^2), the saturation (m/s^2, both positive) and the
#: integrated speed error (m).
PI_KP, PI_KI, PI_MAX_ACCEL, PI_MAX_DECEL, PI_INTEGRAL = 0, 1, 2, 3, 4
PI_STATE_SIZE = 5


@dataclass(frozen=True)
class PISpeedGains:
    """Gains and output limits of the PI speed controller.

    kp_per_s: proportional gain (1/s: m/s^2 of command per m/s of speed error); ki_per_s2: integral gain
    (1/s^2, >= 0; 0 gives a P controller); max_accel_mps2 / max_decel_mps2: command saturation (m/s^2, both
    positive).
    """

    kp_per_s: float = 1.0
    ki_per_s2: float = 0.2
    max_accel_mps2: float = 2.0
    max_decel_mps2: float = 4.0

    def __post_init__(self) -> None:
        require_positive("PISpeedGains.kp_per_s", self.kp_per_s)
        require_in_range("PISpeedGains.ki_per_s2", self.ki_per_s2, 0.0, math.inf, "1/s^2")
        require_positive("PISpeedGains.max_accel_mps2", self.max_accel_mps2)
        require_positive("PISpeedGains.max_decel_mps2", self.max_decel_mps2)
        for name in ("kp_per_s", "ki_per_s2", "max_accel_mps2", "max_decel_mps2"):
            object.__setattr__(self, name, float(getattr(self, name)))


class PISpeedController:
    """u = a_ff + kp e + ki * integral(e dt), e = speed_ref - speed, saturated to [-max_decel, max_accel] (m/s^2).

    a_ff is the reference's rate of change d(speed_ref)/dt (m/s^2) the caller feeds forward (0 for a held speed).

    Anti-windup by conditional integration: the error is not integrated on a step whose command is saturated
    and whose error would push it further into saturation, so the integrator holds its value during long
    saturated stretches (e.g. the acceleration from standstill to a high reference) and the overshoot after
    them stays that of the unsaturated loop.
    """

    def __init__(self, gains: PISpeedGains | None = None) -> None:
        if gains is None:
            gains = PISpeedGains()
        if not isinstance(gains, PISpeedGains):
            raise WorkbenchInputError(f"gains must be a PISpeedGains; got {gains!r}")
        self.gains = gains
        self._integral_m = 0.0

    @property
    def integral_m(self) -> float:
        """Integrated speed error (m)."""
        return self._integral_m

    def reset(self) -> None:
        """Clear the integrator (start of a new run)."""
        self._integral_m = 0.0

    def step(self, speed_ref_mps: float, speed_mps: float, dt_s: float, speed_ref_rate_mps2: float = 0.0) -> float:
        """Advance one control step of dt_s seconds and return the acceleration command (m/s^2).

        speed_ref_rate_mps2: the rate of change of speed_ref_mps (m/s^2), fed forward; along a planned profile
        v_ref(s) it is speed x dv_ref/ds.
        """
        if not (math.isfinite(speed_ref_mps) and math.isfinite(speed_mps)):
            raise WorkbenchInputError(
                f"speed_ref_mps and speed_mps must be finite; got {speed_ref_mps!r} and {speed_mps!r}"
            )
        if not (dt_s > 0.0 and math.isfinite(dt_s)):
            raise WorkbenchInputError(f"dt_s must be a finite number > 0; got {dt_s!r}")
        if not math.isfinite(speed_ref_rate_mps2):
            raise WorkbenchInputError(f"speed_ref_rate_mps2 must be finite; got {speed_ref_rate_mps2!r}")
        g = self.gains
        error = speed_ref_mps - speed_mps
        candidate = self._integral_m + error * dt_s
        command = speed_ref_rate_mps2 + g.kp_per_s * error + g.ki_per_s2 * candidate
        if command > g.max_accel_mps2:
            if error <= 0.0:  # the error is already pulling the command back inside: keep integrating
                self._integral_m = candidate
            return g.max_accel_mps2
        if command < -g.max_decel_mps2:
            if error >= 0.0:
                self._integral_m = candidate
            return -g.max_decel_mps2
        self._integral_m = candidate
        return command


def pi_state(gains: PISpeedGains | None = None) -> np.ndarray:
    """The array `pi_speed_step` runs on (layout PI_*): `gains` (the defaults when None), the integrator at zero."""
    if gains is None:
        gains = PISpeedGains()
    if not isinstance(gains, PISpeedGains):
        raise WorkbenchInputError(f"gains must be a PISpeedGains; got {gains!r}")
    state = np.zeros(PI_STATE_SIZE)
    state[PI_KP], state[PI_KI] = gains.kp_per_s, gains.ki_per_s2
    state[PI_MAX_ACCEL], state[PI_MAX_DECEL] = gains.max_accel_mps2, gains.max_decel_mps2
    return state


@njit(cache=True)
def pi_speed_step(
    state: np.ndarray, speed_ref_mps: float, speed_mps: float, dt_s: float, speed_ref_rate_mps2: float
) -> float:  # pragma: no cover - compiled
    """`PISpeedController.step` on `state` (`pi_state`): the acceleration command (m/s^2), the integrator advanced
    in place. The inputs are not checked: the caller passes finite speeds and rate and a finite dt_s > 0."""
    error = speed_ref_mps - speed_mps
    candidate = state[PI_INTEGRAL] + error * dt_s
    command = speed_ref_rate_mps2 + state[PI_KP] * error + state[PI_KI] * candidate
    if command > state[PI_MAX_ACCEL]:
        if error <= 0.0:  # the error is already pulling the command back inside: keep integrating
            state[PI_INTEGRAL] = candidate
        return state[PI_MAX_ACCEL]
    if command < -state[PI_MAX_DECEL]:
        if error >= 0.0:
            state[PI_INTEGRAL] = candidate
        return -state[PI_MAX_DECEL]
    state[PI_INTEGRAL] = candidate
    return command
