"""Closed-loop simulator: termination, laps, failures reported with partial traces, physics sanity."""

from __future__ import annotations

import math
import re
from dataclasses import replace
from typing import ClassVar

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from controllers import PurePursuit
from controllers.base import Controller, Measurement
from workbench.base.clothoid_chain import ClothoidChain
from workbench.base.errors import WorkbenchInputError
from workbench.base.path import ReferencePath, wrap_angle
from workbench.simulation.conditions import CONDITIONS
from workbench.simulation.result import Status
from workbench.simulation.scenarios import Scenario, make_scenario
from workbench.simulation.simulator import Simulation, SimulationConfig
from workbench.simulation.speed_control import PISpeedController, PISpeedGains
from workbench.simulation.speed_profile import G_MPS2
from workbench.simulation.step_kernel import SIGNALS
from workbench.vehicles import KinematicBicycle


def _scenario(path: ReferencePath, offset: float = 0.0, heading_error: float = 0.0) -> Scenario:
    return Scenario(path.name, path, "test", initial_offset_m=offset, initial_heading_error_rad=heading_error)


def _circle(radius: float = 25.0) -> ReferencePath:
    return ClothoidChain(curvature_1pm=1.0 / radius).arc(2 * math.pi * radius).to_path("circle", closed=True)


def _run(scenario: Scenario, config: SimulationConfig | None = None, controller: Controller | None = None):
    vehicle = KinematicBicycle()
    controller = controller or PurePursuit(vehicle.geometry)
    return Simulation(scenario, vehicle, controller, config or SimulationConfig()).run()


def test_straight_on_path_stays_on_path() -> None:
    result = _run(_scenario(ClothoidChain().straight(100.0).to_path("straight")))
    assert result.status is Status.COMPLETED
    assert result.metrics.max_abs_cte_m < 1e-9
    assert result.metrics.max_abs_steer_wheel_deg < 1e-6
    # The run ends at the end of the path, within one controller step of travel.
    assert result.trace["progress_m"][-1] == pytest.approx(100.0, abs=8.34 / 50 + 1e-6)


def test_ten_metres_off_the_path_still_runs_and_converges() -> None:
    result = _run(_scenario(ClothoidChain().straight(200.0).to_path("straight"), offset=10.0))
    assert result.status is Status.COMPLETED
    assert result.trace["cte_m"][0] == pytest.approx(10.0, abs=1e-9)
    assert abs(result.trace["cte_m"][-1]) < 0.05


def test_closed_loop_runs_the_requested_laps() -> None:
    path = _circle(30.0)
    result = _run(_scenario(path), SimulationConfig(speed_kmh=30.0, laps=2))
    assert result.status is Status.COMPLETED
    assert result.trace["progress_m"][-1] == pytest.approx(2 * path.length_m, abs=0.5)
    assert result.metrics.path_length_m == pytest.approx(2 * path.length_m)
    assert result.metrics.distance_m == pytest.approx(2 * path.length_m, rel=0.01)


def test_steady_cornering_matches_v2_over_r_and_the_speed_profile_bound() -> None:
    radius = 25.0
    result = _run(_scenario(_circle(radius)), SimulationConfig(speed_kmh=60.0))
    v_bound = math.sqrt(0.3 * G_MPS2 * radius)  # the profile's lateral limit, below 60 km/h
    trace = result.trace
    late = trace["t_s"] > trace["t_s"][-1] / 2
    assert np.all(trace["speed_ref_mps"] <= v_bound * 1.01)
    assert np.median(trace["speed_mps"][late]) == pytest.approx(v_bound, rel=0.02)
    lat = trace["lat_accel_mps2"][late]
    v = trace["speed_mps"][late]
    # Kinematic bicycle in steady cornering: a_y = v^2 kappa, with kappa the realised path curvature ~ 1/R.
    assert np.median(lat) == pytest.approx(np.median(v**2) / radius, rel=0.02)
    # Once the start-up transient (wheels straight on a curve) is over, the 0.3 g bound holds.
    assert np.max(np.abs(lat)) <= 0.3 * G_MPS2 * 1.03


def _braking_ramp(v0: float, v1: float, decel: float) -> Scenario:
    """A straight whose own speeds brake at a constant rate: v(s) = sqrt(v0^2 - 2 a s), then v1 for 30 m.

    Followed exactly, v(t) = v0 - a t: a ramp in time. The profile planned at v0 leaves these speeds alone.
    """
    brake_m = (v0**2 - v1**2) / (2 * decel)
    x = np.arange(0.0, brake_m + 30.0, 0.5)
    speed = np.sqrt(np.maximum(v0**2 - 2 * decel * x, v1**2))
    return _scenario(ReferencePath.from_xy(x, np.zeros_like(x), speed, name="braking"))


@pytest.mark.parametrize("decel", [1.0, 2.0])
def test_speed_follows_a_braking_ramp_on_time_with_the_feedforward(decel: float) -> None:
    v0, v1 = 15.0, 5.0
    config = SimulationConfig(speed_kmh=v0 * 3.6)
    result = _run(_braking_ramp(v0, v1, decel), config)
    trace = result.trace
    assert result.status is Status.COMPLETED
    assert trace["speed_ref_mps"].max() == pytest.approx(v0, abs=1e-9)
    assert trace["speed_ref_mps"].min() == pytest.approx(v1, abs=1e-9)
    # The rate is fed forward: the speed follows the ramp; what is left comes from the 50 Hz steps at the ramp's
    # start and end, where the rate jumps between steps and is applied at most one step (a dt) early or late.
    error = trace["speed_ref_mps"] - trace["speed_mps"]
    assert np.abs(error).max() <= 1.25 * decel / config.controller_rate_hz  # measured 0.015 and 0.039 m/s

    # PI alone the speed lags. Reference: the same loop in continuous time, integrated independently of the
    # simulator: s' = v, v' = kp e + ki I, I' = e, e = v_ref(s) - v. (Not the time-ramp formula
    # a (e^{r2 t} - e^{r1 t}) / (r2 - r1): lagging, the vehicle runs down the profile faster than v_ref, so the
    # reference falls faster than a in time.)
    pi_only = _run(_braking_ramp(v0, v1, decel), replace(config, speed_feedforward=False)).trace
    gains = PISpeedGains()

    def v_ref(s_m: float) -> float:
        return math.sqrt(max(v0**2 - 2 * decel * s_m, v1**2))

    def rhs(_t: float, z: np.ndarray) -> list[float]:
        s_m, v, integral = z
        e = v_ref(s_m) - v
        return [v, gains.kp_per_s * e + gains.ki_per_s2 * integral, e]

    t = pi_only["t_s"]
    sol = solve_ivp(rhs, (0.0, t[-1]), [0.0, v0, 0.0], t_eval=t, rtol=1e-10, atol=1e-10, max_step=0.05)
    assert np.abs(sol.y[1] - pi_only["speed_mps"]).max() < 0.01 * decel  # 50 Hz ZOH; measured 0.0035, 0.014 m/s
    lag = pi_only["speed_mps"] - pi_only["speed_ref_mps"]
    assert lag.max() > 0.764 * decel  # at least the time-ramp lag's peak: 0.76 and 1.5 m/s too fast


def test_plant_rate_convergence() -> None:
    """RK4 at 1 kHz and 4 kHz give the same closed-loop trace (integration error far below the CTE)."""
    scenario = make_scenario("fig17")
    a = _run(scenario, SimulationConfig(plant_rate_hz=1000.0))
    b = _run(scenario, SimulationConfig(plant_rate_hz=4000.0))
    n = min(a.trace["t_s"].size, b.trace["t_s"].size)
    assert np.max(np.abs(a.trace["cte_m"][:n] - b.trace["cte_m"][:n])) < 1e-6


def test_every_step_is_timed() -> None:
    result = _run(make_scenario("fig17"))
    assert np.all(result.trace["step_time_s"] > 0)
    assert 0 < result.metrics.step_time_median_us <= result.metrics.step_time_p99_us


class _Failing(Controller):
    name: ClassVar[str] = "failing"
    config_type: ClassVar[type] = dict

    def __init__(self, geometry, mode: str, after: int = 20) -> None:
        super().__init__(geometry, {})
        self.mode, self.after = mode, after

    def _reset(self, path: ReferencePath, sample_time_s: float) -> None:
        self.n = 0

    def _command(self, measurement: Measurement, path: ReferencePath) -> float:
        self.n += 1
        if self.n > self.after:
            if self.mode == "nan":
                return float("nan")
            if self.mode == "full-lock":
                return self.geometry.max_steer_wheel_angle_rad
            raise RuntimeError("solver exploded")
        return 0.0


@pytest.mark.parametrize(
    ("mode", "needle"), [("nan", "computed a non-finite steering command"), ("raise", "RuntimeError: solver exploded")]
)
def test_controller_failure_is_reported_and_the_partial_trace_kept(mode: str, needle: str) -> None:
    vehicle = KinematicBicycle()
    scenario = _scenario(ClothoidChain().straight(100.0).to_path("straight"))
    result = Simulation(scenario, vehicle, _Failing(vehicle.geometry, mode)).run()
    assert result.status is Status.CONTROLLER_FAILED
    assert needle in result.message
    assert result.trace["t_s"].size == 20
    assert result.metrics.completed is False


class _Diverging(KinematicBicycle):
    def advance(self, state, steer, accel, dt, substeps):
        new = super().advance(state, steer, accel, dt, substeps)
        if new[0] > 30.0:
            new[2] = np.nan
        return new


def test_diverging_plant_stops_with_a_clear_message_and_keeps_the_trace() -> None:
    vehicle = _Diverging()
    scenario = _scenario(ClothoidChain().straight(100.0).to_path("straight"))
    result = Simulation(scenario, vehicle, PurePursuit(vehicle.geometry)).run()
    assert result.status is Status.DIVERGED
    assert "yaw_rad" in result.message
    assert result.trace["x_m"][-1] == pytest.approx(30.0, abs=0.2)
    assert np.all(np.isfinite(result.to_pandas().drop(columns=["ctrl_lookahead_m"]).to_numpy()))



class _BadOutputs(KinematicBicycle):
    """A plant whose outputs turn non-finite past x = 10 m: `column` (0 x, 3 vx) becomes `value`."""

    def __init__(self, column: int, value: float) -> None:
        super().__init__()
        self.column, self.value = column, value

    def outputs(self, state, steer, accel):
        out = super().outputs(state, steer, accel)
        if out[0] > 10.0:
            out = np.array(out, dtype=float)
            out[self.column] = self.value
        return out


@pytest.mark.parametrize(
    ("column", "value", "needle"),
    [
        (0, math.nan, r"position must be finite to project onto straight; got \(nan, 0\.0\)"),
        (3, math.inf, r"the speed reference, the speed and the reference's rate .* entry 1 is inf"),
    ],
)
def test_a_non_finite_position_or_speed_is_refused_naming_the_value(column: int, value: float, needle: str) -> None:
    vehicle = _BadOutputs(column, value)
    scenario = _scenario(ClothoidChain().straight(100.0).to_path("straight"))
    with pytest.raises(WorkbenchInputError, match=needle):
        Simulation(scenario, vehicle, _Failing(vehicle.geometry, "nan", after=10**9)).run()

def test_going_past_the_start_of_an_open_path_is_leaving_it() -> None:
    """A vehicle circling at full lock from the start passes behind it: before, the CTE was measured sideways from
    the start's tangent only and the run went on to its time-out, reported on the path."""
    vehicle = KinematicBicycle()
    scenario = _scenario(ClothoidChain().straight(100.0).to_path("straight"), heading_error=math.radians(80))
    controller = _Failing(vehicle.geometry, "full-lock", after=0)
    result = Simulation(scenario, vehicle, controller, SimulationConfig(max_past_end_m=1.0)).run()
    assert result.status is Status.LEFT_PATH
    assert re.search(r"went 1\.\d m past the start of the path \(max_past_end_m = 1 m\)", result.message)
    assert result.metrics.max_abs_cte_m > 1.0  # the distance from the path counts beyond its start
    assert result.metrics.to_dict()["completed"] is False


def test_a_measurement_the_controller_rejects_is_counted_in_the_message() -> None:
    class _Spinning(KinematicBicycle):
        def outputs(self, state, steer, accel):
            out = np.array(super().outputs(state, steer, accel))
            out[5] = 50.0  # yaw rate, rad/s: far beyond the plausible envelope
            return out

    vehicle = _Spinning()
    scenario = _scenario(ClothoidChain().straight(30.0).to_path("straight"))
    result = Simulation(scenario, vehicle, PurePursuit(vehicle.geometry)).run()
    assert "measurements as implausible and held its command" in result.message and "yaw_rate" in result.message
    assert result.trace["ctrl_measurement_rejected"].min() == 1.0


def test_leaving_the_path_stops_the_run() -> None:
    vehicle = KinematicBicycle()
    scenario = _scenario(ClothoidChain().straight(300.0).to_path("straight"), heading_error=math.radians(60))
    result = Simulation(
        scenario, vehicle, _Failing(vehicle.geometry, "nan", after=10**9), SimulationConfig(max_abs_cte_m=5.0)
    ).run()
    assert result.status is Status.LEFT_PATH
    assert "max_abs_cte_m = 5 m" in result.message


@pytest.mark.parametrize(
    ("kwargs", "needle"),
    [
        ({"speed_kmh": 0.0}, "speed_kmh"),
        ({"speed_kmh": -5.0}, "speed_kmh"),
        ({"speed_kmh": float("nan")}, "speed_kmh"),
        ({"plant_rate_hz": 1010.0}, "whole multiple"),
        ({"laps": 0}, "laps"),
        ({"max_lateral_accel_g": 0.0}, "max_lateral_accel_g"),
        ({"speed_feedforward": 1}, r"speed_feedforward must be True or False; got 1"),
    ],
)
def test_bad_configuration_is_rejected(kwargs: dict, needle: str) -> None:
    with pytest.raises(WorkbenchInputError, match=needle):
        SimulationConfig(**kwargs)


def test_a_path_tighter_than_the_vehicle_turns_is_named_before_the_run() -> None:
    vehicle = KinematicBicycle()
    reach = math.tan(vehicle.geometry.max_road_wheel_angle_rad) / vehicle.geometry.wheelbase_m
    chain = ClothoidChain().straight(20.0).clothoid_to(1.5 * reach, 2.0).arc(5.0).clothoid_to(0.0, 2.0)
    tight = chain.straight(20.0).to_path("hairpin")
    simulation = Simulation(_scenario(tight), vehicle, PurePursuit(vehicle.geometry))
    warning, rate = simulation.path_warnings()  # and its 2 m transitions change the curvature faster than it steers
    assert "hairpin curves tighter than the kinematic-bicycle can turn" in warning
    assert rate.startswith("hairpin changes its curvature faster than the kinematic-bicycle's steering follows")
    assert re.search(r"at s = 21\.[34]-27\.[67] m \(peak 1\.05 1/m\)", warning), warning
    assert Simulation(_scenario(_circle()), vehicle, PurePursuit(vehicle.geometry)).path_warnings() == []


@pytest.mark.parametrize("first_only", [True, False])
def test_a_path_speed_of_zero_is_refused_before_the_run(first_only: bool) -> None:
    """All speeds 0 divided by zero; a first speed of 0 left every controller standing until the time-out."""
    path = ClothoidChain().straight(50.0).to_path("straight")
    speed = np.full(path.s_m.size, 5.0)
    if first_only:
        speed[0] = 0.0
    else:
        speed[:] = 0.0
    vehicle = KinematicBicycle()
    with pytest.raises(WorkbenchInputError, match=r"straight: the path's speed must be > 0 m/s .* 0 m/s at s = 0\.0 m"):
        Simulation(_scenario(path.with_speed(speed)), vehicle, PurePursuit(vehicle.geometry))


def test_the_logged_signals_are_the_ones_recomputed_from_the_trace() -> None:
    """Every signal the compiled per-step work logs, recomputed in Python from the trace's own columns, equal to the
    last bit: the projection of the logged position by a fresh tracker, the planned speed and the Python PI
    controller's command, the wrapped heading error; the command and diagnostics are the controller's for the
    logged measurement. The run is long enough (18 850 steps) for the trace's table to grow."""
    path = _circle(25.0)
    config = SimulationConfig(controller_rate_hz=200.0, laps=5)
    result = _run(_scenario(path, offset=0.4), config)
    assert result.status is Status.COMPLETED
    trace, planned = result.trace, result.path
    n = trace["t_s"].size
    assert n > 1 << 14
    dt = 1.0 / config.controller_rate_hz
    tracker, speed_control = planned.tracker(0.0), PISpeedController(PISpeedGains())
    controller = PurePursuit(KinematicBicycle().geometry)
    controller.reset(planned, dt)
    t = 0.0
    for i in range(n):
        x, y, yaw, vx, vy = (trace[k][i] for k in ("x_m", "y_m", "yaw_rad", "vx_mps", "vy_mps"))
        foot = tracker.update(x, y)
        speed = math.hypot(vx, vy)
        speed_ref = planned.speed(foot.s_m)
        accel = speed_control.step(speed_ref, speed, dt, speed * planned.speed_gradient(foot.s_m))
        measurement = Measurement(t, x, y, vx, vy, yaw, trace["yaw_rate_rad_s"][i], trace["steer_wheel_rad"][i])
        expected = {
            "t_s": t,
            "steer_wheel_cmd_rad": controller.step(measurement, planned),
            "accel_cmd_mps2": accel,
            "speed_mps": speed,
            "speed_ref_mps": speed_ref,
            "path_s_m": foot.s_m,
            "progress_m": foot.progress_m,
            "cte_m": foot.signed_distance_m,
            "heading_error_rad": float(wrap_angle(yaw - foot.heading_rad)),
            "path_curvature_1pm": foot.curvature_1pm,
            **{f"ctrl_{k}": v for k, v in controller.diagnostics.items()},
        }
        logged = {key: float(trace[key][i]) for key in expected}
        assert logged == expected, i
        t += dt


def test_the_trace_holds_the_time_the_outputs_the_signals_the_diagnostics_and_what_was_seen() -> None:
    """In that order; a signal named like an output (`path_curvature_1pm`) in the output's place; the seen columns
    only under conditions that are not ideal, and only once a step was logged."""
    vehicle = KinematicBicycle()
    straight = ClothoidChain().straight(40.0).to_path("straight")
    controller = PurePursuit(vehicle.geometry)
    columns = [
        "t_s",
        *dict.fromkeys((*vehicle.output_names, *SIGNALS)),
        *(f"ctrl_{name}" for name in ("lookahead_m", "target_s_m", "curvature_cmd_1pm")),
        "ctrl_measurement_rejected",
        "ctrl_command_rejected",
    ]
    seen = [
        "seen_x_m", "seen_y_m", "seen_yaw_rad", "seen_vx_mps", "seen_vy_mps", "seen_yaw_rate_rad_s",
        "seen_steer_wheel_rad", "applied_steer_wheel_cmd_rad", "road_friction",
    ]  # fmt: skip
    ideal = Simulation(_scenario(straight), vehicle, controller).run()
    assert list(ideal.trace) == columns
    automotive = SimulationConfig(conditions=CONDITIONS["automotive"])
    noisy = Simulation(_scenario(straight), vehicle, controller, automotive).run()
    assert list(noisy.trace) == columns + seen
    assert np.isfinite(noisy.to_pandas()[seen].to_numpy()).all()
    off = Simulation(_scenario(straight, offset=10.0), vehicle, controller, replace(automotive, max_abs_cte_m=5.0))
    left = off.run()
    assert left.status is Status.LEFT_PATH and list(left.trace) == columns and left.trace["t_s"].size == 0
