"""PI speed controller: closed loop with a point-mass plant dv/dt = u - d, against analytic references."""

from __future__ import annotations

import math

import numpy as np
import pytest

from workbench.errors import WorkbenchInputError
from workbench.speed_control import PISpeedController, PISpeedGains

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
        ("ki_per_s2", -0.1, r"ki_per_s2 must be in \[0\.0, inf\].*got -0\.1"),
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
