"""The sensing and actuation models (issue 18): noise statistics against their settings, the Gauss-Markov drift's
variance and correlation, update rate and hold, latency exact for signals linear in time, seeds, the actuator's
dead time to the plant step and its rate limit (with hypothesis properties), and the cost per call."""

from __future__ import annotations

import math
import statistics
import time
from collections.abc import Callable

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from workbench.base.errors import WorkbenchInputError
from workbench.simulation.conditions import (
    CONDITIONS,
    Actuation,
    Conditions,
    Inertial,
    Localisation,
    SteeringSensor,
)
from workbench.simulation.control_interface import Measurement
from workbench.simulation.sensing import ActuatorModel, SensorModel

DT = 0.02
SUBSTEPS = 20


def _times(n: int, dt: float = DT) -> list[float]:
    """The controller's clock as the simulator keeps it (t += dt: not exact multiples)."""
    out, t = [], 0.0
    for _ in range(n):
        out.append(t)
        t += dt
    return out


def _cruise(n: int) -> list[Measurement]:
    """A vehicle at 10 m/s on a gentle weave (true values that move every step)."""
    return [
        Measurement(
            t, 10.0 * t, 0.5 * math.sin(t), 10.0, 0.3, 0.05 * math.sin(t), 0.05 * math.cos(t), 0.4 * math.sin(t)
        )
        for t in _times(n)
    ]


def _seen(conditions: Conditions, truth: list[Measurement], seed: int = 7) -> list[Measurement]:
    model = SensorModel(conditions, seed=seed, sample_time_s=DT)
    return [model.measure(m) for m in truth]


def _errors(seen: list[Measurement], truth: list[Measurement], signal: Callable[[Measurement], float]) -> np.ndarray:
    return np.array([signal(s) - signal(m) for s, m in zip(seen, truth, strict=True)])


# ------------------------------------------------------------------------------------------ ideal, arguments
def test_ideal_conditions_pass_everything_through_unchanged() -> None:
    truth = _cruise(50)
    for conditions in (CONDITIONS["ideal"], Conditions(actuation=Actuation(dead_time_s=0.1))):
        model = SensorModel(conditions, seed=3, sample_time_s=DT)
        assert model.is_ideal
        assert all(model.measure(m) is m for m in truth)
    for conditions in (CONDITIONS["ideal"], Conditions(localisation=Localisation(latency_s=0.1))):
        actuator = ActuatorModel(conditions, DT, SUBSTEPS)
        assert actuator.is_ideal
        for command in (0.0, -1.25, 3.5e-7):
            ((n, applied),) = actuator.segments(command)
            assert n == SUBSTEPS and applied is command


@pytest.mark.parametrize(
    ("build", "words"),
    [
        (lambda: SensorModel(CONDITIONS["rtk"], seed=-1), ["seed", ">= 0", "-1"]),
        (lambda: SensorModel(CONDITIONS["rtk"], seed=True), ["seed", "True"]),
        (lambda: SensorModel(CONDITIONS["rtk"], seed=1.5), ["seed", "1.5"]),
        (lambda: SensorModel(CONDITIONS["rtk"], sample_time_s=0.0), ["sample_time_s", "> 0"]),
        (lambda: SensorModel("rtk"), ["conditions", "Conditions"]),
        (lambda: ActuatorModel(CONDITIONS["rtk"], DT, 0), ["plant_substeps", ">= 1", "0"]),
        (lambda: ActuatorModel(CONDITIONS["rtk"], math.nan, 20), ["sample_time_s", "nan"]),
        (lambda: ActuatorModel(CONDITIONS["automotive"], DT, 20).reset(math.nan), ["initial_steer_wheel_rad"]),
    ],
)
def test_bad_arguments_are_refused(build, words: list[str]) -> None:
    with pytest.raises(WorkbenchInputError) as info:
        build()
    for word in words:
        assert word in str(info.value), (word, str(info.value))


# ------------------------------------------------------------------------------------------------- white noise
N_WHITE = 40_000

WHITE = [
    ("x", Conditions(localisation=Localisation(position_noise_m=0.05)), lambda m: m.x_m, 0.05),
    ("y", Conditions(localisation=Localisation(position_noise_m=0.05)), lambda m: m.y_m, 0.05),
    ("yaw", Conditions(localisation=Localisation(heading_noise_rad=0.003)), lambda m: m.yaw_rad, 0.003),
    ("yaw rate", Conditions(inertial=Inertial(yaw_rate_noise_rad_s=0.002)), lambda m: m.yaw_rate_rad_s, 0.002),
    ("speed", Conditions(inertial=Inertial(speed_noise_mps=0.1)), lambda m: m.speed_mps, 0.1),
    ("steering", Conditions(steering_sensor=SteeringSensor(noise_rad=0.004)), lambda m: m.steer_wheel_rad, 0.004),
]


@pytest.mark.parametrize(("label", "conditions", "signal", "sigma"), WHITE, ids=[w[0] for w in WHITE])
def test_white_noise_has_its_sigma_and_zero_mean(label, conditions, signal, sigma) -> None:
    truth = _cruise(N_WHITE)
    seen = _seen(conditions, truth)
    errors = _errors(seen, truth, signal)
    assert abs(np.std(errors) / sigma - 1.0) < 0.03, label  # the estimate's own spread: 0.35 %
    assert abs(np.mean(errors)) < 5.0 * sigma / math.sqrt(N_WHITE), label
    assert abs(np.corrcoef(errors[1:], errors[:-1])[0, 1]) < 5.0 / math.sqrt(N_WHITE), label  # white


def test_speed_noise_keeps_the_direction_of_travel() -> None:
    truth = _cruise(200)
    seen = _seen(Conditions(inertial=Inertial(speed_noise_mps=0.5)), truth)
    for s, m in zip(seen, truth, strict=True):
        assert math.atan2(s.vy_mps, s.vx_mps) == pytest.approx(math.atan2(m.vy_mps, m.vx_mps), abs=1e-12)
    assert np.std([s.speed_mps - m.speed_mps for s, m in zip(seen, truth, strict=True)]) > 0.3


def test_the_yaw_rate_bias_shifts_its_mean() -> None:
    truth = _cruise(N_WHITE)
    bias, sigma = 0.004, 0.002
    seen = _seen(Conditions(inertial=Inertial(yaw_rate_noise_rad_s=sigma, yaw_rate_bias_rad_s=bias)), truth)
    errors = _errors(seen, truth, lambda m: m.yaw_rate_rad_s)
    assert abs(np.mean(errors) - bias) < 5.0 * sigma / math.sqrt(N_WHITE)
    only_bias = _seen(Conditions(inertial=Inertial(yaw_rate_bias_rad_s=-bias)), truth[:100])
    assert np.allclose(_errors(only_bias, truth[:100], lambda m: m.yaw_rate_rad_s), -bias, rtol=0, atol=1e-15)


def test_quantisation_rounds_to_its_steps() -> None:
    quantum = 0.01
    truth = [Measurement(t, 0, 0, 5, 0, 0, 0, -1.0 + 0.01234 * k) for k, t in enumerate(_times(200))]
    for noise in (0.0, 0.003):
        sensor = SteeringSensor(noise_rad=noise, quantisation_rad=quantum)
        steer = np.array([s.steer_wheel_rad for s in _seen(Conditions(steering_sensor=sensor), truth)])
        steps = steer / quantum
        assert np.max(np.abs(steps - np.round(steps))) < 1e-9
        if noise == 0.0:
            true_steer = np.array([m.steer_wheel_rad for m in truth])
            assert np.max(np.abs(steer - true_steer)) <= quantum / 2 + 1e-12
            assert len(set(np.round(steps).astype(int))) > 150  # a fine sweep keeps its steps


# ------------------------------------------------------------------------------------------- Gauss-Markov drift
@pytest.mark.parametrize(
    ("rate_hz", "tau_s", "interval_s", "steps"),
    [(None, 0.2, DT, 100_000), (100.0, 0.2, DT, 100_000), (10.0, 0.5, 0.1, 100_000)],
    ids=["every-step", "rate-above-the-controllers", "10-Hz"],
)
def test_the_drift_has_its_sigma_and_correlation(rate_hz, tau_s, interval_s, steps) -> None:
    sigma = 0.5
    loc = Localisation(position_drift_m=sigma, position_drift_time_s=tau_s, update_rate_hz=rate_hz)
    truth = [Measurement(t, 0.0, 0.0, 5.0, 0.0, 0.0, 0.0, 0.0) for t in _times(steps)]
    seen = _seen(Conditions(localisation=loc), truth)
    stride = round(interval_s / DT)  # one sample per refresh
    a = math.exp(-interval_s / tau_s)
    r1, sigmas = [], []
    for signal in (lambda m: m.x_m, lambda m: m.y_m):
        drift = np.array([signal(m) for m in seen[::stride]])
        sigmas.append(np.sqrt(np.mean(drift**2)))
        r1.append(np.sum(drift[1:] * drift[:-1]) / np.sum(drift**2))
        n = drift.size
    # The estimates' spread: var(sigma^2 estimate) ~ 2 sigma^4 (1 + a^2) / ((1 - a^2) n), var(r1) ~ (1 - a^2) / n.
    sigma_spread = math.sqrt(2.0 * (1 + a * a) / ((1 - a * a) * 2 * n)) / 2.0
    assert 5.0 * sigma_spread < 0.05
    assert abs(np.mean(sigmas) / sigma - 1.0) < 0.05
    r1_tolerance = 5.0 * math.sqrt((1.0 - a * a) / (2 * n))
    assert abs(np.mean(r1) - a) < r1_tolerance, (np.mean(r1), a, r1_tolerance)


def test_the_drift_starts_from_its_stationary_distribution() -> None:
    sigma = 0.75
    model = SensorModel(Conditions(localisation=Localisation(position_drift_m=sigma)), seed=0, sample_time_s=DT)
    start = Measurement(0.0, 0.0, 0.0, 5.0, 0.0, 0.0, 0.0, 0.0)
    first = []
    for seed in range(2000):
        model.reset(seed)
        seen = model.measure(start)
        first += [seen.x_m, seen.y_m]
    assert abs(np.std(first) / sigma - 1.0) < 0.06  # spread of the estimate over 4000 draws: 1.1 %
    assert abs(np.mean(first)) < 5.0 * sigma / math.sqrt(len(first))


# --------------------------------------------------------------------------------------------- update rate
@pytest.mark.parametrize("rate_hz", [10.0, 15.0, 3.0])
def test_the_pose_is_refreshed_only_at_the_update_rate_and_held(rate_hz: float) -> None:
    truth = _cruise(1000)  # 20 s
    loc = Localisation(update_rate_hz=rate_hz, position_noise_m=0.01, heading_noise_rad=0.001)
    seen = _seen(Conditions(localisation=loc, inertial=Inertial(speed_noise_mps=0.01)), truth)
    changed = [k for k in range(1, len(seen)) if seen[k].x_m != seen[k - 1].x_m]
    # The first controller step at or after each epoch k / rate.
    expected = sorted({math.ceil(round(e / rate_hz / DT, 9)) for e in range(1, math.ceil(truth[-1].t_s * rate_hz) + 1)})
    expected = [k for k in expected if k < len(seen)]
    assert changed == expected
    for k in range(1, len(seen)):
        same_pose = seen[k].x_m == seen[k - 1].x_m
        pose_k = (seen[k].y_m, seen[k].yaw_rad, seen[k].vx_mps, seen[k].vy_mps)
        pose_before = (seen[k - 1].y_m, seen[k - 1].yaw_rad, seen[k - 1].vx_mps, seen[k - 1].vy_mps)
        assert (pose_k == pose_before) == same_pose  # the whole pose and the velocity refresh together
        assert seen[k].yaw_rate_rad_s != seen[k - 1].yaw_rate_rad_s  # not held
        assert seen[k].t_s == truth[k].t_s


# -------------------------------------------------------------------------------------------------- latency
def _linear(t: float) -> tuple[float, ...]:
    """Signals linear in time (x, y, yaw unwrapped, vx, vy, yaw rate, steering); the yaw crosses +-pi."""
    return (
        3.0 + 2.0 * t,
        -1.0 + 0.5 * t,
        3.0 + 0.9 * t,
        10.0 + 0.1 * t,
        0.2 - 0.01 * t,
        0.2 + 0.01 * t,
        -0.3 + 0.05 * t,
    )


def _linear_truth(n: int) -> list[Measurement]:
    out = []
    for t in _times(n):
        x, y, yaw, vx, vy, yaw_rate, steer = _linear(t)
        wrapped = (yaw + math.pi) % (2.0 * math.pi) - math.pi  # as a plant may give it
        out.append(Measurement(t, x, y, vx, vy, wrapped, yaw_rate, steer))
    return out


def _assert_seen_at(seen: Measurement, pose_t: float, rate_t: float, steer_t: float) -> None:
    x, y, yaw, vx, vy, _, _ = _linear(max(pose_t, 0.0))
    yaw_rate = _linear(max(rate_t, 0.0))[5]
    steer = _linear(max(steer_t, 0.0))[6]
    assert seen.x_m == pytest.approx(x, abs=1e-12)
    assert seen.y_m == pytest.approx(y, abs=1e-12)
    assert math.remainder(seen.yaw_rad - yaw, 2.0 * math.pi) == pytest.approx(0.0, abs=1e-12)
    assert seen.vx_mps == pytest.approx(vx, abs=1e-12)
    assert seen.vy_mps == pytest.approx(vy, abs=1e-12)
    assert seen.yaw_rate_rad_s == pytest.approx(yaw_rate, abs=1e-12)
    assert seen.steer_wheel_rad == pytest.approx(steer, abs=1e-12)


@pytest.mark.parametrize("latency_s", [0.0, 0.02, 0.013, 0.05, 0.1234, 0.3])
def test_latency_shifts_signals_linear_in_time_by_exactly_the_latency(latency_s: float) -> None:
    truth = _linear_truth(300)  # 6 s, the yaw wraps at about 0.16 s
    rate_latency, steer_latency = 0.7 * latency_s + 0.003, 0.5 * latency_s
    conditions = Conditions(
        localisation=Localisation(latency_s=latency_s),
        inertial=Inertial(latency_s=rate_latency),
        steering_sensor=SteeringSensor(latency_s=steer_latency),
    )
    for seen, m in zip(_seen(conditions, truth), truth, strict=True):
        assert seen.t_s == m.t_s  # stamped now, with stale data
        _assert_seen_at(seen, m.t_s - latency_s, m.t_s - rate_latency, m.t_s - steer_latency)


@pytest.mark.parametrize(("rate_hz", "latency_s"), [(8.0, 0.037), (10.0, 0.1), (100.0, 0.013), (7.0, 0.0)])
def test_latency_and_hold_together(rate_hz: float, latency_s: float) -> None:
    truth = _linear_truth(300)
    conditions = Conditions(localisation=Localisation(update_rate_hz=rate_hz, latency_s=latency_s))
    for seen, m in zip(_seen(conditions, truth), truth, strict=True):
        epoch_t = math.floor(m.t_s * rate_hz + 1e-6) / rate_hz
        _assert_seen_at(seen, epoch_t - latency_s, m.t_s, m.t_s)


# ------------------------------------------------------------------------------------------------------ seeds
NOISY = Conditions(
    localisation=Localisation(
        position_noise_m=0.1, position_drift_m=0.2, heading_noise_rad=0.01, update_rate_hz=25.0, latency_s=0.03
    ),
    inertial=Inertial(yaw_rate_noise_rad_s=0.01, yaw_rate_bias_rad_s=0.001, speed_noise_mps=0.1, latency_s=0.01),
    steering_sensor=SteeringSensor(noise_rad=0.01, quantisation_rad=1e-4),
)


def _signals(seen: list[Measurement]) -> dict[str, list[float]]:
    return {
        "x": [m.x_m for m in seen],
        "y": [m.y_m for m in seen],
        "yaw": [m.yaw_rad for m in seen],
        "speed": [m.speed_mps for m in seen],
        "yaw_rate": [m.yaw_rate_rad_s for m in seen],
        "steering": [m.steer_wheel_rad for m in seen],
    }


def test_the_same_seed_repeats_and_another_differs() -> None:
    truth = _cruise(500)
    first = _signals(_seen(NOISY, truth, seed=11))
    assert _signals(_seen(NOISY, truth, seed=11)) == first
    other = _signals(_seen(NOISY, truth, seed=12))
    for name in first:
        assert other[name] != first[name], name
    model = SensorModel(NOISY, seed=11, sample_time_s=DT)
    [model.measure(m) for m in truth[:123]]
    model.reset()
    assert _signals([model.measure(m) for m in truth]) == first
    model.reset(12)
    assert _signals([model.measure(m) for m in truth]) == other


@pytest.mark.parametrize(
    ("changed", "unchanged"),
    [
        (Localisation(position_noise_m=0.1, position_drift_m=0.2, heading_noise_rad=0.02), ["x", "y", "speed"]),
        (Localisation(position_noise_m=0.3, position_drift_m=0.2, heading_noise_rad=0.01), ["yaw", "speed"]),
        (Localisation(position_noise_m=0.1, position_drift_m=0.0, heading_noise_rad=0.01), ["yaw", "speed"]),
    ],
)
def test_changing_one_source_leaves_the_others_draws(changed: Localisation, unchanged: list[str]) -> None:
    truth = _cruise(500)
    loc = NOISY.localisation
    base = Conditions(localisation=Localisation(**{**vars(loc), "update_rate_hz": None, "latency_s": 0.0}))
    variant = Conditions(localisation=changed)
    first, second = _signals(_seen(base, truth)), _signals(_seen(variant, truth))
    for name in unchanged:
        assert second[name] == first[name], name


def test_changing_the_pose_leaves_the_inertial_and_steering_draws() -> None:
    truth = _cruise(500)
    quiet = Conditions(inertial=NOISY.inertial, steering_sensor=NOISY.steering_sensor)
    first, second = _signals(_seen(NOISY, truth)), _signals(_seen(quiet, truth))
    assert second["yaw_rate"] == first["yaw_rate"]
    assert second["steering"] == first["steering"]
    assert second["x"] != first["x"]
    no_speed_noise = Conditions(localisation=NOISY.localisation, steering_sensor=NOISY.steering_sensor)
    third = _signals(_seen(no_speed_noise, truth))
    for name in ("x", "y", "yaw", "steering"):
        assert third[name] == first[name], name


# --------------------------------------------------------------------------------------------------- actuator
def _expand(segments: list[tuple[int, float]]) -> list[float]:
    return [value for n, value in segments for _ in range(n)]


def _drive(actuator: ActuatorModel, commands: list[float]) -> list[list[tuple[int, float]]]:
    return [actuator.segments(c) for c in commands]


@pytest.mark.parametrize("dead_time_s", [0.05, 0.0137, 0.02, 0.0996, 0.001, 0.25])
def test_a_step_command_arrives_after_exactly_the_dead_time(dead_time_s: float) -> None:
    actuator = ActuatorModel(Conditions(actuation=Actuation(dead_time_s=dead_time_s)), DT, SUBSTEPS)
    delay = round(dead_time_s / (DT / SUBSTEPS))
    assert actuator.dead_time_substeps == delay
    actuator.reset(0.3)
    commands = [0.0] * 10 + [1.0] * 20
    calls = _drive(actuator, commands)
    assert all(sum(n for n, _ in segments) == SUBSTEPS and all(n > 0 for n, _ in segments) for segments in calls)
    assert all(len(segments) <= 2 for segments in calls)
    applied = [value for segments in calls for value in _expand(segments)]
    expected = ([0.3] * delay + [c for c in commands for _ in range(SUBSTEPS)])[: len(applied)]
    assert applied == expected
    assert applied.index(1.0) == 10 * SUBSTEPS + delay


def test_the_rate_limit_ramps_the_delayed_command() -> None:
    rate = 2.0  # rad/s: 0.04 rad per controller step
    actuator = ActuatorModel(Conditions(actuation=Actuation(max_steer_wheel_rate_rad_s=rate)), DT, SUBSTEPS)
    actuator.reset(0.0)
    values = [actuator.segments(1.0) for _ in range(40)]
    for k, segments in enumerate(values):
        ((n, value),) = segments
        assert n == SUBSTEPS
        assert value == pytest.approx(min(rate * DT * (k + 1), 1.0), abs=1e-12)
    assert values[-1][0][1] == 1.0  # reached exactly
    down = actuator.segments(-1.0)
    assert down == [(SUBSTEPS, pytest.approx(1.0 - rate * DT, abs=1e-12))]


#: An actuator's dead time (s), plant substeps per controller step, controller step (s), rate limit (rad/s; None:
#: the plant's own) and the steering before the first command (rad), for the property tests.
ACTUATORS = {
    "dead_time_s": st.floats(0.0, 0.2),
    "substeps": st.integers(1, 25),
    "sample_time_s": st.sampled_from([0.01, 0.02, 0.05]),
    "rate": st.one_of(st.none(), st.floats(0.1, 50.0)),
    "initial": st.floats(-5.0, 5.0),
}


@settings(max_examples=150, deadline=None)
@given(
    commands=st.lists(st.floats(-10.0, 10.0), min_size=1, max_size=40),
    **ACTUATORS,
)
def test_the_actuator_keeps_the_order_and_never_exceeds_its_rate(
    commands, dead_time_s, substeps, sample_time_s, rate, initial
) -> None:
    conditions = Conditions(actuation=Actuation(dead_time_s=dead_time_s, max_steer_wheel_rate_rad_s=rate))
    actuator = ActuatorModel(conditions, sample_time_s, substeps)
    unlimited = ActuatorModel(Conditions(actuation=Actuation(dead_time_s=dead_time_s)), sample_time_s, substeps)
    plant_step = sample_time_s / substeps
    hold = math.ceil(20.0 / ((rate or 1e9) * sample_time_s)) + math.ceil(dead_time_s / sample_time_s) + 2
    commands = commands + [commands[-1]] * hold  # held long enough to be reached
    actuator.reset(initial)
    unlimited.reset(initial)
    limited_calls, unlimited_calls = _drive(actuator, commands), _drive(unlimited, commands)
    delay = round(dead_time_s / plant_step)
    targets = [v for segments in unlimited_calls for v in _expand(segments)]
    # Without a rate limit: the commands in order, shifted by the dead time, the initial steering before.
    assert targets == ([initial] * delay + [c for c in commands for _ in range(substeps)])[: len(targets)]
    previous = initial
    position = 0
    for segments in limited_calls:
        assert sum(n for n, _ in segments) == substeps and all(n > 0 for n, _ in segments)
        for n, value in segments:
            change = value - previous
            if rate is not None:
                assert abs(change) <= rate * n * plant_step * (1 + 1e-12) + 1e-12
            target = targets[position]  # it moves towards the delayed command, never past it
            assert change == 0.0 or (change > 0) == (target > previous)
            assert abs(change) <= abs(target - previous) + 1e-12
            previous, position = value, position + n
    assert previous == commands[-1]
    if rate is None:
        assert limited_calls == unlimited_calls


@settings(max_examples=150, deadline=None)
@given(
    sent=st.lists(st.floats(-10.0, 10.0), min_size=0, max_size=30),
    later=st.lists(st.floats(-10.0, 10.0), min_size=22, max_size=22),  # 0.2 s at 0.01 s and two more
    **ACTUATORS,
)
def test_the_segments_ahead_are_what_the_plant_gets_over_the_next_dead_time(
    sent, later, dead_time_s, substeps, sample_time_s, rate, initial
) -> None:
    """Whatever is sent from now on, the plant's next dead time of commands is the look-ahead taken before it."""
    conditions = Conditions(actuation=Actuation(dead_time_s=dead_time_s, max_steer_wheel_rate_rad_s=rate))
    actuator = ActuatorModel(conditions, sample_time_s, substeps)
    actuator.reset(initial)
    _drive(actuator, sent)
    ahead = actuator.segments_ahead()
    assert actuator.segments_ahead() == ahead  # it changes nothing
    assert sum(n for n, _ in ahead) == actuator.dead_time_substeps and all(n > 0 for n, _ in ahead)
    then = [value for segments in _drive(actuator, later) for value in _expand(segments)]
    assert _expand(ahead) == then[: actuator.dead_time_substeps]


# ------------------------------------------------------------------------------------------------------- cost
def test_a_call_costs_a_few_microseconds() -> None:
    truth = _cruise(2000)
    for name in ("rtk", "automotive", "degraded"):
        sensor = SensorModel(CONDITIONS[name], seed=1, sample_time_s=DT)
        actuator = ActuatorModel(CONDITIONS[name], DT, SUBSTEPS)
        sensor_times, actuator_times = [], []
        for _ in range(5):
            start = time.perf_counter()
            for m in truth:
                sensor.measure(m)
            middle = time.perf_counter()
            for m in truth:
                actuator.segments(m.steer_wheel_rad)
            sensor_times.append((middle - start) / len(truth))
            actuator_times.append((time.perf_counter() - middle) / len(truth))
        # Measured about 3-7 us and 0.1-0.6 us; the bound leaves room for a loaded machine.
        assert statistics.median(sensor_times) < 50e-6, name
        assert statistics.median(actuator_times) < 20e-6, name
