"""The simulator under sensing, actuation and road conditions (issue 18): ideal is today's run bit for bit; the
controller sees the conditions' measurements while the trace and the metrics keep the true state; the actuator's
dead time delays what reaches the plant, and a perfect prediction of it hands the controller the state past it; the
road's friction is set on the vehicle; a seed reproduces a run."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from controllers import PurePursuit
from controllers.base import Controller, Measurement
from workbench.base.errors import WorkbenchInputError
from workbench.base.path import ReferencePath
from workbench.simulation.conditions import CONDITIONS, Actuation, Conditions, Localisation, Road
from workbench.simulation.scenarios import ScenarioOptions, make_scenario
from workbench.simulation.simulator import Simulation, SimulationConfig
from workbench.vehicles import KinematicBicycle, make_vehicle


def _run(conditions: Conditions | None = None, seed: int = 0, vehicle_name: str = "dynamic-bicycle", **config):
    vehicle = make_vehicle(vehicle_name)
    dlc = make_scenario("dlc", ScenarioOptions(vehicle_width_m=vehicle.geometry.width_m))
    fields = {"speed_kmh": 40.0, **config}
    if conditions is not None:
        fields |= {"conditions": conditions, "seed": seed}
    return Simulation(dlc, vehicle, PurePursuit(vehicle.geometry), SimulationConfig(**fields)).run()


def _same(a: dict[str, np.ndarray], b: dict[str, np.ndarray]) -> bool:
    timing = ("step_time_s",)
    return a.keys() == b.keys() and all(np.array_equal(a[k], b[k], equal_nan=True) for k in a if k not in timing)


def test_ideal_conditions_are_todays_run_bit_for_bit() -> None:
    default = _run()
    explicit = _run(CONDITIONS["ideal"], seed=123)
    assert default.completed and _same(default.trace, explicit.trace)
    assert not any(k.startswith("seen_") for k in default.trace)


def test_the_controller_sees_the_conditions_and_the_metrics_keep_the_true_state() -> None:
    noisy = Conditions(name="noise", localisation=Localisation(position_noise_m=0.05))
    result = _run(noisy, seed=1)
    trace = result.trace
    assert result.completed
    error = trace["seen_y_m"] - trace["y_m"]
    assert np.std(error) == pytest.approx(0.05, rel=0.15)  # what the controller saw: the true y plus the noise
    assert abs(np.mean(error)) < 0.01
    # the trace's position is the plant's, from which the CTE and the metrics come
    assert result.metrics.max_abs_cte_m == pytest.approx(np.max(np.abs(trace["cte_m"])))


def test_the_same_seed_gives_the_same_run_and_another_seed_another() -> None:
    noisy = CONDITIONS["rtk"]
    first, again, other = _run(noisy, seed=7), _run(noisy, seed=7), _run(noisy, seed=8)
    assert _same(first.trace, again.trace)
    assert not np.array_equal(first.trace["seen_x_m"], other.trace["seen_x_m"])


def test_a_pose_latency_shifts_what_the_controller_sees_by_exactly_that_time() -> None:
    """On the dlc's straight start the true x grows about linearly: the seen x is the true x of 60 ms before."""
    late = Conditions(name="late", localisation=Localisation(latency_s=0.06))
    trace = _run(late).trace
    t, x, seen = trace["t_s"], trace["x_m"], trace["seen_x_m"]
    k = 3  # 0.06 s at 50 Hz
    assert np.allclose(seen[k + 10 : k + 60], x[10:60], rtol=0, atol=1e-9)
    assert t[1] - t[0] == pytest.approx(0.02)


def test_the_actuators_dead_time_delays_the_command_reaching_the_plant() -> None:
    class Step(Controller):
        """Steers 0 until 0.5 s, then 30 degrees of steering wheel."""

        name = "step"
        config_type = dict

        def _reset(self, path: ReferencePath, sample_time_s: float) -> None:
            pass

        def _command(self, measurement: Measurement, path: ReferencePath) -> float:
            return 0.0 if measurement.t_s < 0.5 - 1e-9 else np.radians(30.0)

    vehicle = KinematicBicycle()
    straight = make_scenario("dlc", ScenarioOptions(vehicle_width_m=vehicle.geometry.width_m))
    delayed = Conditions(name="delay", actuation=Actuation(dead_time_s=0.1))
    config = SimulationConfig(speed_kmh=20.0, conditions=delayed, max_time_s=1.5)
    trace = Simulation(straight, vehicle, Step(vehicle.geometry, {}), config).run().trace
    t, applied = trace["t_s"], trace["applied_steer_wheel_cmd_rad"]
    first_sent = t[np.argmax(trace["steer_wheel_cmd_rad"] > 0.1)]
    first_applied = t[np.argmax(applied > 0.1)]
    assert first_sent == pytest.approx(0.5)
    assert first_applied - first_sent == pytest.approx(0.1, abs=1e-9)


def test_the_roads_friction_is_set_on_the_vehicle_and_refused_without_tyres() -> None:
    profile = Conditions(name="patch", road=Road(friction_profile=((0.0, 1.0), (60.0, 1.0), (61.0, 0.5))))
    trace = _run(profile, speed_kmh=30.0).trace
    friction = trace["road_friction"]
    s = trace["path_s_m"]
    assert friction[s < 59.0].max() == 1.0 and friction[s > 62.0].min() == 0.5
    slippery = dataclasses.replace(CONDITIONS["ideal"], name="wet", road=Road(friction_scale=0.5))
    with pytest.raises(WorkbenchInputError, match="tyres"):
        _run(slippery, vehicle_name="kinematic-bicycle")


def test_a_bad_conditions_or_seed_is_refused_naming_it() -> None:
    with pytest.raises(WorkbenchInputError, match="conditions must be a Conditions"):
        SimulationConfig(conditions="automotive")  # type: ignore[arg-type]
    for seed in (-1, 1.5, True, 2**63):
        with pytest.raises(WorkbenchInputError, match="seed must be a whole number"):
            SimulationConfig(seed=seed)  # type: ignore[arg-type]


DEAD = Conditions(name="dead time", actuation=Actuation(dead_time_s=0.1))


def test_perfect_prediction_hands_the_controller_the_true_state_one_dead_time_on() -> None:
    """On the dlc at a held speed (the lateral bound lifted: no braking, so the acceleration command held over the
    dead time is the one that comes) what the controller saw at a step is the plant's true state 0.1 s (5 steps at
    50 Hz) later, steering included: the commands already sent decide it."""
    trace = _run(DEAD, perfect_prediction=True, max_lateral_accel_g=2.0).trace
    k = 5
    for signal in ("x_m", "y_m", "yaw_rad", "vy_mps", "yaw_rate_rad_s", "steer_wheel_rad"):
        seen, true = trace[f"seen_{signal}"][:-k], trace[signal][k:]
        assert np.max(np.abs(seen - true)) < 1e-5, signal  # m, rad, m/s, rad/s: the integration's rounding
    assert np.ptp(trace["yaw_rate_rad_s"]) > 0.1  # the check is on a run that steers


def test_perfect_prediction_leaves_the_speed_loop_and_the_trace_on_the_true_state() -> None:
    """Braking for the lane change (the profile's 0.3 g), the speed the trace logs and the speed controller holds
    is the plant's now, not the one a dead time ahead the steering controller is handed."""
    trace = _run(DEAD, perfect_prediction=True).trace
    assert np.ptp(trace["accel_cmd_mps2"]) > 1.0  # it brakes and accelerates
    assert np.allclose(trace["speed_mps"], np.hypot(trace["vx_mps"], trace["vy_mps"]), rtol=0, atol=1e-12)
    seen = np.hypot(trace["seen_vx_mps"], trace["seen_vy_mps"])
    assert np.max(np.abs(seen - trace["speed_mps"])) > 0.05  # what the controller saw was ahead


def test_perfect_prediction_takes_the_dead_time_out_of_the_loop() -> None:
    """With the dead time perfectly predicted the loop is the delay-free one: pure pursuit's max |CTE| on the dlc
    (at a held speed, the lateral bound lifted) is the ideal run's to a millimetre, where the same dead time
    unpredicted moves it by centimetres."""
    held = {"max_lateral_accel_g": 2.0}
    ideal, late = _run(**held).metrics.max_abs_cte_m, _run(DEAD, **held).metrics.max_abs_cte_m
    predicted = _run(DEAD, perfect_prediction=True, **held).metrics.max_abs_cte_m
    assert abs(late - ideal) > 0.02
    assert predicted == pytest.approx(ideal, abs=1e-3)


def test_perfect_prediction_is_not_told_the_dead_time_and_needs_one() -> None:
    automotive = CONDITIONS["automotive"]
    told = SimulationConfig(conditions=automotive, inform_delays=True, perfect_prediction=True).known_delays
    assert told is not None and told.dead_time_s == 0.0
    assert told.pose_latency_s == automotive.localisation.latency_s > 0.0
    assert SimulationConfig(conditions=automotive, inform_delays=True).known_delays.dead_time_s == 0.1
    assert SimulationConfig(conditions=automotive).known_delays is None
    with pytest.raises(WorkbenchInputError, match=r"perfect_prediction .* 'rtk' have no dead time"):
        SimulationConfig(conditions=CONDITIONS["rtk"], perfect_prediction=True)
    with pytest.raises(WorkbenchInputError, match="perfect_prediction must be True or False; got 'yes'"):
        SimulationConfig(conditions=DEAD, perfect_prediction="yes")  # type: ignore[arg-type]
