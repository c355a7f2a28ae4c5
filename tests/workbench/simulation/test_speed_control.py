"""PI speed controller: closed loop with a point-mass plant dv/dt = u - d, against analytic references."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from workbench.base.errors import WorkbenchInputError
from workbench.simulation.speed_control import (
    PI_INTEGRAL,
    PISpeedController,
    PISpeedGains,
    pi_speed_step,
    pi_state,
)

DT_S = 0.01


def simulate(
    controller: PISpeedController,
    speed_ref_mps: float,
    duration_s: float,
    v0_mps: float = 0.0,
    drag_mps2: float = 0.0,
) -> tuple[np.ndarray, np.ndarray]:
    """Forward-Euler closed loop; returns (speed after each step, command of each step)."""
    speed, speeds, commands = v0_mps, [], []
    for _ in range(round(duration_s / DT_S)):
        u = controller.step(speed_ref_mps, speed, DT_S)
        speed += (u - drag_mps2) * DT_S
        speeds.append(speed)
        commands.append(u)
    return np.array(speeds), np.array(commands)


def simulate_ramp(
    controller: PISpeedController,
    ref0_mps: float,
    rate_mps2: float,
    duration_s: float,
    v0_mps: float,
    feedforward: bool,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Forward-Euler closed loop on dv/dt = u following v_ref(t) = ref0 + rate t, the rate fed forward or not.

    Returns (time of each step, error v_ref - v at each step before its command, command of each step).
    """
    speed, times, errors, commands = v0_mps, [], [], []
    for k in range(round(duration_s / DT_S)):
        t = k * DT_S
        ref = ref0_mps + rate_mps2 * t
        u = controller.step(ref, speed, DT_S, rate_mps2 if feedforward else 0.0)
        times.append(t)
        errors.append(ref - speed)
        commands.append(u)
        speed += u * DT_S
    return np.array(times), np.array(errors), np.array(commands)


def pi_roots_per_s(gains: PISpeedGains) -> tuple[float, float]:
    """Roots r1 < r2 < 0 of s^2 + kp s + ki (real for the default gains)."""
    kp, ki = gains.kp_per_s, gains.ki_per_s2
    disc = math.sqrt(kp**2 - 4 * ki)
    return (-kp - disc) / 2, (-kp + disc) / 2


def linear_overshoot_mps(gains: PISpeedGains, e0_mps: float) -> float:
    """Overshoot of the unsaturated loop from error e0 with an empty integrator (analytic).

    With u = kp e + ki I on dv/dt = u the error obeys e'' + kp e' + ki e = 0, e(0) = e0, e'(0) = -kp e0.
    For the default gains the roots are real (overdamped), e = A exp(r1 t) + B exp(r2 t).
    """
    kp, ki = gains.kp_per_s, gains.ki_per_s2
    disc = math.sqrt(kp**2 - 4 * ki)
    r1, r2 = (-kp - disc) / 2, (-kp + disc) / 2
    b = (-kp * e0_mps - r1 * e0_mps) / (r2 - r1)
    a = e0_mps - b
    t = np.linspace(0.0, 60.0, 600_001)
    return float(-(a * np.exp(r1 * t) + b * np.exp(r2 * t)).min())


class WindupPI:
    """The same PI law without anti-windup (reference for the anti-windup test)."""

    def __init__(self, gains: PISpeedGains) -> None:
        self.gains, self.integral = gains, 0.0

    def step(self, speed_ref_mps: float, speed_mps: float, dt_s: float) -> float:
        error = speed_ref_mps - speed_mps
        self.integral += error * dt_s
        u = self.gains.kp_per_s * error + self.gains.ki_per_s2 * self.integral
        return min(self.gains.max_accel_mps2, max(-self.gains.max_decel_mps2, u))


@pytest.mark.parametrize("speed_ref_mps", [0.5, 5.0, 10.0])
def test_step_reference_reaches_zero_steady_state_error(speed_ref_mps: float) -> None:
    speeds, _ = simulate(PISpeedController(), speed_ref_mps, duration_s=60.0)
    after_30_s = speeds[round(30.0 / DT_S) :]
    assert np.abs(after_30_s - speed_ref_mps).max() < 1e-3


def test_integral_action_removes_constant_drag_offset() -> None:
    # A P controller would settle drag / kp = 0.5 m/s short; the integrator must hold u = drag instead.
    controller = PISpeedController()
    speeds, commands = simulate(controller, 8.0, duration_s=60.0, drag_mps2=0.5)
    assert abs(speeds[-1] - 8.0) < 1e-3
    assert commands[-1] == pytest.approx(0.5, abs=1e-3)
    assert controller.integral_m == pytest.approx(0.5 / controller.gains.ki_per_s2, rel=1e-2)


def test_command_is_saturated_to_the_limits() -> None:
    gains = PISpeedGains(max_accel_mps2=1.5, max_decel_mps2=3.0)
    _, accelerating = simulate(PISpeedController(gains), 30.0, duration_s=5.0)
    _, braking = simulate(PISpeedController(gains), 0.0, duration_s=5.0, v0_mps=30.0)
    assert accelerating.max() == 1.5
    assert braking.min() == -3.0
    assert np.all((accelerating <= 1.5) & (accelerating >= -3.0))
    assert np.all((braking <= 1.5) & (braking >= -3.0))
    # While saturated the speed ramps at exactly the limit.
    speeds, _ = simulate(PISpeedController(gains), 30.0, duration_s=5.0)
    assert speeds[-1] == pytest.approx(1.5 * 5.0, rel=1e-9)


@pytest.mark.parametrize("speed_ref_mps", [5.0, 20.0, 40.0])
def test_anti_windup_overshoot_matches_unsaturated_loop(speed_ref_mps: float) -> None:
    # With conditional integration the integrator is empty when the command leaves saturation at
    # e = amax / kp, so the overshoot is that of the linear loop from e0 = amax / kp whatever the step size
    # (0.232 m/s for the default gains).
    gains = PISpeedGains()
    bound = linear_overshoot_mps(gains, gains.max_accel_mps2 / gains.kp_per_s)
    speeds, _ = simulate(PISpeedController(gains), speed_ref_mps, duration_s=80.0)
    overshoot = speeds.max() - speed_ref_mps
    assert 0.0 < overshoot <= bound * 1.02  # 2 %: forward-Euler discretisation at dt = 10 ms
    assert overshoot == pytest.approx(bound, rel=0.02)
    windup_speeds, _ = simulate(WindupPI(gains), speed_ref_mps, duration_s=80.0)  # type: ignore[arg-type]
    assert windup_speeds.max() - speed_ref_mps > 4 * bound  # 0.96, 12 and 31 m/s with windup


def test_small_step_overshoot_scales_with_the_step() -> None:
    gains = PISpeedGains()
    speeds, commands = simulate(PISpeedController(gains), 1.0, duration_s=60.0)
    assert commands.max() < gains.max_accel_mps2  # never saturates: a purely linear response
    assert speeds.max() - 1.0 == pytest.approx(linear_overshoot_mps(gains, 1.0), rel=0.02)


def test_reset_clears_the_integrator() -> None:
    controller = PISpeedController()
    simulate(controller, 3.0, duration_s=10.0)
    assert controller.integral_m != 0.0
    controller.reset()
    assert controller.integral_m == 0.0
    assert controller.step(1.0, 1.0, DT_S) == 0.0


@pytest.mark.parametrize(
    ("field", "value", "match"),
    [
        ("kp_per_s", 0.0, r"kp_per_s must be a finite number > 0; got 0\.0"),
        ("kp_per_s", float("nan"), r"kp_per_s .*got nan"),
        ("ki_per_s2", -0.1, r"ki_per_s2 must be a finite number in \[0, inf\].*got -0\.1"),
        ("ki_per_s2", float("inf"), r"ki_per_s2 .*got inf"),
        ("max_accel_mps2", -1.0, r"max_accel_mps2 must be a finite number > 0; got -1\.0"),
        ("max_decel_mps2", "4", r"max_decel_mps2 must be a finite number > 0; got '4'"),
    ],
)
def test_gain_validation(field: str, value: object, match: str) -> None:
    with pytest.raises(WorkbenchInputError, match=match):
        PISpeedGains(**{field: value})


def test_zero_integral_gain_is_a_p_controller() -> None:
    controller = PISpeedController(PISpeedGains(ki_per_s2=0.0))
    assert controller.step(3.0, 2.5, DT_S) == pytest.approx(0.5)


@pytest.mark.parametrize(
    ("args", "match"),
    [
        ((float("nan"), 1.0, 0.01), r"got nan and 1\.0"),
        ((1.0, float("inf"), 0.01), r"got 1\.0 and inf"),
        ((1.0, 1.0, 0.0), r"dt_s must be a finite number > 0; got 0\.0"),
        ((1.0, 1.0, -0.01), r"dt_s .*got -0\.01"),
        ((1.0, 1.0, float("nan")), r"dt_s .*got nan"),
    ],
)
def test_step_rejects_bad_input(args: tuple[float, float, float], match: str) -> None:
    controller = PISpeedController()
    with pytest.raises(WorkbenchInputError, match=match):
        controller.step(*args)
    assert controller.integral_m == 0.0


def test_controller_rejects_non_gains() -> None:
    with pytest.raises(WorkbenchInputError, match=r"gains must be a PISpeedGains; got \{'kp_per_s': 1\.0\}"):
        PISpeedController({"kp_per_s": 1.0})  # type: ignore[arg-type]


@pytest.mark.parametrize("rate_mps2", [-2.0, -0.5, 1.0])
def test_without_feedforward_a_ramp_is_followed_with_the_analytic_pi_lag(rate_mps2: float) -> None:
    # From zero error, E(s) = R(s) s^2 / (s^2 + kp s + ki) with R = a / s^2: e(t) = a (e^{r2 t} - e^{r1 t}) / (r2 - r1),
    # peaking at 0.764 a after 2.16 s for the default gains: the lag that made the truck enter corners too fast.
    gains = PISpeedGains()
    r1, r2 = pi_roots_per_s(gains)
    t, errors, commands = simulate_ramp(PISpeedController(gains), 20.0, rate_mps2, 8.0, 20.0, feedforward=False)
    # unsaturated: the linear analysis holds
    assert np.all((commands < gains.max_accel_mps2) & (commands > -gains.max_decel_mps2))
    analytic = rate_mps2 * (np.exp(r2 * t) - np.exp(r1 * t)) / (r2 - r1)
    assert np.abs(errors - analytic).max() <= 0.01 * abs(rate_mps2)  # forward Euler at dt = 10 ms
    t_peak = math.log(r1 / r2) / (r2 - r1)
    assert t_peak == pytest.approx(2.16, abs=0.01)
    assert np.abs(errors).max() == pytest.approx(0.764 * abs(rate_mps2), rel=0.01)


@pytest.mark.parametrize("rate_mps2", [-2.0, -0.5, 1.0])
def test_feedforward_follows_a_ramp_without_lag(rate_mps2: float) -> None:
    # dv/dt = u = a + kp e + ki I with e(0) = 0: v steps exactly with the reference (up to rounding).
    _, errors, commands = simulate_ramp(PISpeedController(), 20.0, rate_mps2, 8.0, 20.0, feedforward=True)
    assert np.abs(errors).max() < 1e-9
    np.testing.assert_allclose(commands, rate_mps2, atol=1e-9)


def test_feedforward_error_decays_like_a_held_reference_whatever_the_ramp() -> None:
    # With the rate fed forward, e'' + kp e' + ki e = 0 for any reference: from e0 the error is that of a step,
    # e = A e^{r1 t} + B e^{r2 t} with A + B = e0 and r1 A + r2 B = -kp e0.
    gains = PISpeedGains()
    r1, r2 = pi_roots_per_s(gains)
    e0 = 0.8
    b = (-gains.kp_per_s * e0 - r1 * e0) / (r2 - r1)
    a = e0 - b
    for rate in (-1.5, 0.0, 0.7):
        t, errors, commands = simulate_ramp(PISpeedController(gains), 15.0, rate, 20.0, 15.0 - e0, feedforward=True)
        assert np.all((commands < gains.max_accel_mps2) & (commands > -gains.max_decel_mps2))
        analytic = a * np.exp(r1 * t) + b * np.exp(r2 * t)
        assert np.abs(errors - analytic).max() <= 0.01 * e0  # forward Euler at dt = 10 ms


def test_feedforward_is_saturated_with_the_feedback() -> None:
    gains = PISpeedGains(max_accel_mps2=1.5, max_decel_mps2=3.0)
    controller = PISpeedController(gains)
    assert controller.step(10.0, 10.0, DT_S, 5.0) == 1.5
    assert controller.step(10.0, 10.0, DT_S, -5.0) == -3.0
    assert controller.step(10.0, 10.0, DT_S, 0.25) == pytest.approx(0.25)


@pytest.mark.parametrize("rate", [float("nan"), float("inf"), -float("inf")])
def test_step_rejects_a_non_finite_reference_rate(rate: float) -> None:
    controller = PISpeedController()
    with pytest.raises(WorkbenchInputError, match=r"speed_ref_rate_mps2 must be finite; got -?(nan|inf)"):
        controller.step(1.0, 1.0, DT_S, rate)
    assert controller.integral_m == 0.0


_speeds = st.floats(0.0, 40.0)
_rates = st.floats(-6.0, 6.0)
#: (speed_ref, speed, dt, rate) of a step: references and speeds far apart drive the command into both saturations,
#: near ones keep it inside.
_steps = st.tuples(_speeds, _speeds, st.floats(1e-4, 0.2), _rates)


@settings(max_examples=150, deadline=None)
@given(
    gains=st.builds(
        PISpeedGains,
        kp_per_s=st.floats(0.05, 5.0),
        ki_per_s2=st.floats(0.0, 2.0),
        max_accel_mps2=st.floats(0.1, 6.0),
        max_decel_mps2=st.floats(0.1, 10.0),
    ),
    steps=st.lists(_steps, min_size=1, max_size=60),
)
def test_the_compiled_step_is_the_python_controller_bit_for_bit(gains: PISpeedGains, steps: list) -> None:
    """The simulator's kernel (`pi_speed_step` on `pi_state`) gives the Python controller's commands and integrator,
    equal to the last bit, along any sequence of steps, saturated or not."""
    python, compiled = PISpeedController(gains), pi_state(gains)
    for speed_ref, speed, dt, rate in steps:
        assert pi_speed_step(compiled, speed_ref, speed, dt, rate) == python.step(speed_ref, speed, dt, rate)
        assert compiled[PI_INTEGRAL] == python.integral_m


def test_pi_state_starts_from_the_gains_and_a_zero_integrator() -> None:
    gains = PISpeedGains(kp_per_s=0.5, ki_per_s2=0.1, max_accel_mps2=1.5, max_decel_mps2=3.0)
    assert pi_state(gains).tolist() == [0.5, 0.1, 1.5, 3.0, 0.0]
    assert pi_state().tolist() == pi_state(PISpeedGains()).tolist()
    with pytest.raises(WorkbenchInputError, match="gains must be a PISpeedGains"):
        pi_state({"kp_per_s": 1.0})  # type: ignore[arg-type]
