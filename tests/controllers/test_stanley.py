"""Stanley (`controllers/stanley.py`) against its law, worked out by hand: the cross-track term's gain and softening,
the heading term, the steering limit, and the curvature feed-forward, whose steady command on a circle is the one
that holds the rear axle (the workbench's reference point) on it, on each of the four vehicle models; and on the
figure8 the feed-forward makes tracking better, not worse; the reference form's yaw-rate and steering damping terms
act as their equations say, and at 0 (their defaults) leave a run bit for bit the plain law's."""

from __future__ import annotations

import math
from typing import ClassVar

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from controllers.base import Controller
from controllers.stanley import Stanley, StanleyConfig
from workbench.base.errors import WorkbenchInputError
from workbench.base.path import ReferencePath, wrap_angle
from workbench.simulation.control_interface import Measurement
from workbench.simulation.scenarios import Scenario, ScenarioOptions, make_scenario
from workbench.simulation.simulator import Simulation, SimulationConfig
from workbench.vehicles import make_vehicle
from workbench.vehicles.geometry import VehicleGeometry

GEOMETRY = VehicleGeometry(
    wheelbase_m=3.0, steering_ratio=16.0, max_road_wheel_angle_rad=0.6, max_steer_wheel_rate_rad_s=10.0, width_m=2.0
)
STRAIGHT = ReferencePath.from_xy(np.linspace(-50.0, 500.0, 12), np.zeros(12))
VEHICLES = ("kinematic-bicycle", "dynamic-bicycle", "tractor-semitrailer", "commonroad-mb")


def _circle(radius_m: float, turn: float = 1.0, samples: int = 4000) -> ReferencePath:
    """A closed circle starting at the origin heading along +x, turning left (turn = 1) or right (-1)."""
    angle = np.linspace(0.0, 2.0 * math.pi, samples, endpoint=False)
    return ReferencePath.from_xy(radius_m * np.sin(angle), turn * radius_m * (1.0 - np.cos(angle)), closed=True)


def _command(controller: Stanley, path: ReferencePath, x: float, y: float, yaw: float, speed: float, vy: float = 0.0):
    controller.reset(path, 0.02)
    return controller.step(Measurement(0.0, x, y, speed, vy, yaw, 0.0, 0.0), path)


# ---------------------------------------------------------------------------------------------- the law's terms
@settings(max_examples=40, deadline=None)
@given(
    offset=st.floats(-1.5, 1.5),
    speed=st.floats(0.0, 30.0),
    gain=st.floats(0.1, 10.0),
    softening=st.floats(0.1, 5.0),
)
def test_beside_a_straight_line_the_command_is_the_cross_track_term(
    offset: float, speed: float, gain: float, softening: float
) -> None:
    """Aligned with the line, the front axle is as far off it as the rear: delta = atan(-k e / (k_soft + v))."""
    controller = Stanley(GEOMETRY, StanleyConfig(gain_per_s=gain, softening_mps=softening))
    command = _command(controller, STRAIGHT, 0.0, offset, 0.0, speed)
    expected = math.atan(-gain * offset / (softening + speed))
    expected = min(max(expected, -GEOMETRY.max_road_wheel_angle_rad), GEOMETRY.max_road_wheel_angle_rad)
    assert command == pytest.approx(GEOMETRY.steering_ratio * expected, abs=1e-9)
    diagnostics = controller.diagnostics
    assert diagnostics["front_cte_m"] == pytest.approx(offset, abs=1e-9)
    assert diagnostics["heading_term_rad"] == pytest.approx(0.0, abs=1e-12)
    assert diagnostics["feedforward_term_rad"] == 0.0


@pytest.mark.parametrize(("gain", "softening", "speed"), [(1.5, 1.0, 0.0), (3.0, 1.0, 0.0), (1.5, 2.0, 0.0)])
def test_standing_still_the_softening_alone_bounds_the_cross_track_term(
    gain: float, softening: float, speed: float
) -> None:
    """At v = 0 the term is atan(-k e / k_soft): twice the gain is twice the softening's inverse."""
    controller = Stanley(GEOMETRY, StanleyConfig(gain_per_s=gain, softening_mps=softening))
    command = _command(controller, STRAIGHT, 0.0, 0.2, 0.0, speed)
    assert command / GEOMETRY.steering_ratio == pytest.approx(math.atan(-gain * 0.2 / softening), abs=1e-12)


@settings(max_examples=40, deadline=None)
@given(yaw=st.floats(-0.5, 0.5), speed=st.floats(0.5, 30.0))
def test_a_heading_error_is_steered_out_and_moves_the_front_axle_off_the_line(yaw: float, speed: float) -> None:
    """Rear axle on the line, heading yaw: the front axle lies L sin(yaw) off it, the line's heading is 0."""
    cfg = StanleyConfig()
    controller = Stanley(GEOMETRY, cfg)
    command = _command(controller, STRAIGHT, 0.0, 0.0, yaw, speed)
    front_cte = GEOMETRY.wheelbase_m * math.sin(yaw)
    expected = -yaw + math.atan(-cfg.gain_per_s * front_cte / (cfg.softening_mps + speed))
    limit = GEOMETRY.max_road_wheel_angle_rad
    assert command == pytest.approx(GEOMETRY.steering_ratio * min(max(expected, -limit), limit), abs=1e-9)
    assert controller.diagnostics["front_cte_m"] == pytest.approx(front_cte, abs=1e-9)


@pytest.mark.parametrize("side", [1.0, -1.0])
def test_the_command_stops_at_the_road_wheels_lock(side: float) -> None:
    """The road-wheel angle is clipped at max_road_wheel_angle_rad, then geared: just inside it, it is not."""
    cfg = StanleyConfig()
    controller = Stanley(GEOMETRY, cfg)
    lock = GEOMETRY.max_road_wheel_angle_rad
    assert _command(controller, STRAIGHT, 0.0, -side * 20.0, 0.0, 5.0) == side * lock * GEOMETRY.steering_ratio
    offset = math.tan(lock * 0.999) * (cfg.softening_mps + 5.0) / cfg.gain_per_s  # the term 0.1 % inside the lock
    command = _command(controller, STRAIGHT, 0.0, -side * offset, 0.0, 5.0)
    assert command == pytest.approx(side * 0.999 * lock * GEOMETRY.steering_ratio, rel=1e-9)


# ---------------------------------------------------------------------------------------- the curvature feed-forward
@settings(max_examples=40, deadline=None)
@given(
    radius=st.floats(12.0, 300.0),
    turn=st.sampled_from([1.0, -1.0]),
    speed=st.floats(1.0, 30.0),
    gain=st.floats(0.3, 5.0),
)
def test_kinematic_on_a_circle_the_command_is_ackermanns_with_the_feedforward(
    radius: float, turn: float, speed: float, gain: float
) -> None:
    """Rear axle on the circle, heading along it (no slip): the front axle lies sqrt(R^2 + L^2) - R outside it
    and the heading term is atan(L / R), the Ackermann angle that holds the circle. With the feed-forward the
    command is that angle; without it the law adds atan(k (sqrt(R^2 + L^2) - R) / (k_soft + v)) more."""
    path = _circle(radius, turn)
    wheelbase, ratio = GEOMETRY.wheelbase_m, GEOMETRY.steering_ratio
    ackermann = turn * math.atan(wheelbase / radius)
    outside = math.hypot(radius, wheelbase) - radius
    on = Stanley(GEOMETRY, StanleyConfig(gain_per_s=gain, curvature_feedforward=True))
    off = Stanley(GEOMETRY, StanleyConfig(gain_per_s=gain))
    # the path's samples, 0.1 m apart, are joined by chords: a foot point lies up to 0.1^2 / (8 R) m inside the
    # circle and its heading up to ~3e-4 / R rad off the circle's
    cte_tol, heading_tol = 0.1**2 / (8.0 * radius) * 1.05, 5e-4 / radius
    command_tol = heading_tol + gain * cte_tol / (1.0 + speed)
    assert _command(on, path, 0.0, 0.0, 0.0, speed) / ratio == pytest.approx(ackermann, abs=command_tol)
    assert on.diagnostics["front_cte_m"] == pytest.approx(-turn * outside, abs=cte_tol)
    assert on.diagnostics["heading_term_rad"] == pytest.approx(ackermann, abs=heading_tol)
    lock = GEOMETRY.max_road_wheel_angle_rad
    without = min(max(ackermann + turn * math.atan(gain * outside / (1.0 + speed)), -lock), lock)
    assert _command(off, path, 0.0, 0.0, 0.0, speed) / ratio == pytest.approx(without, abs=command_tol)
    assert abs(without - ackermann) > 10.0 * command_tol  # the two are told apart


@pytest.mark.parametrize("name", ["dynamic-bicycle", "tractor-semitrailer", "commonroad-mb"])
@pytest.mark.parametrize("turn", [1.0, -1.0])
def test_in_the_single_tracks_steady_turn_the_command_is_its_steady_steer(name: str, turn: float) -> None:
    """The vehicle's single track in its steady turn on the circle (rear axle on it, body yawed into the turn by
    the rear axle's slip alpha_r, a_y = v^2 / R): the command is that turn's road-wheel angle, the direction of
    the front axle's velocity atan2(L / R - sin(alpha_r), cos(alpha_r)) plus the front axle's slip alpha_f."""
    vehicle = make_vehicle(name)
    track = vehicle.single_track().single_track
    radius, speed = 40.0, 10.0
    alpha_f, alpha_r = track.steady_slip_angles_rad(turn * speed**2 / radius)
    assert abs(alpha_f) > 0.005 and abs(alpha_r) > 0.002  # the tyres matter here
    wheelbase, ratio = vehicle.geometry.wheelbase_m, vehicle.geometry.steering_ratio
    controller = Stanley(vehicle.geometry, StanleyConfig(curvature_feedforward=True), vehicle=vehicle)
    command = _command(
        controller, _circle(radius, turn), 0.0, 0.0, alpha_r, speed * math.cos(alpha_r), -speed * math.sin(alpha_r)
    )
    steady = alpha_f + math.atan2(turn * wheelbase / radius - math.sin(alpha_r), math.cos(alpha_r))
    assert command / ratio == pytest.approx(steady, abs=5e-5)  # R = 40 m: the chords' error (above) is ~1e-5
    assert controller.diagnostics["heading_term_rad"] == pytest.approx(steady - alpha_f, abs=5e-5)


def test_without_a_vehicle_the_feedforward_has_no_slip() -> None:
    """Built from the geometry alone (no tyres known), the feed-forward is the kinematic one."""
    vehicle = make_vehicle("dynamic-bicycle")
    path = _circle(40.0)
    with_tyres = Stanley(vehicle.geometry, StanleyConfig(curvature_feedforward=True), vehicle=vehicle)
    geometry_only = Stanley(vehicle.geometry, StanleyConfig(curvature_feedforward=True))
    alpha_f, alpha_r = vehicle.single_track().single_track.steady_slip_angles_rad(100.0 / 40.0)
    assert with_tyres.feedforward_rad(1 / 40.0, 10.0) != pytest.approx(geometry_only.feedforward_rad(1 / 40.0, 10.0))
    no_tyres = make_vehicle("kinematic-bicycle")
    kinematic = Stanley(vehicle.geometry, StanleyConfig(curvature_feedforward=True), vehicle=no_tyres)
    assert kinematic.feedforward_rad(1 / 40.0, 10.0) == geometry_only.feedforward_rad(1 / 40.0, 10.0)
    assert _command(geometry_only, path, 0.0, 0.0, 0.0, 10.0) / vehicle.geometry.steering_ratio == pytest.approx(
        math.atan(vehicle.geometry.wheelbase_m / 40.0), abs=5e-5
    )
    assert alpha_f > 0.0 and alpha_r > 0.0


# ------------------------------------------------------------------------------------- closed loop, each vehicle
class _Constant(Controller):
    """Holds one steering-wheel command: the open-loop vehicle."""

    name: ClassVar[str] = "constant"
    config_type: ClassVar[type] = float

    def _reset(self, path: ReferencePath, sample_time_s: float) -> None:
        pass

    def _command(self, measurement: Measurement, path: ReferencePath) -> float:
        return self.config


#: Per vehicle: the circle's radius (m), the speed (km/h), and the tolerance on the steady rear-axle CTE and on
#: the open-loop circle's radius (m). The single tracks of the tractor-semitrailer and of the CommonRoad multi-body
#: car are equivalents (the trailer as a point load at the fifth wheel; no roll or load transfer, on which the
#: multi-body car's tyres lose stiffness): their feed-forward's slip is that close to the model's.
CIRCLES = {
    "kinematic-bicycle": (30.0, 40.0, 0.005),
    "dynamic-bicycle": (30.0, 40.0, 0.01),
    "tractor-semitrailer": (30.0, 30.0, 0.01),
    "commonroad-mb": (30.0, 40.0, 0.05),
}


def _steady(result):  # a SimulationResult in, its trace's settled part out
    frame = result.to_pandas()
    return frame.iloc[len(frame) // 2 :]  # the second half of the lap: the start's transient has died out


def _fitted_radius(x: np.ndarray, y: np.ndarray) -> float:
    """The least-squares circle through the points (x^2 + y^2 = 2 a x + 2 b y + c)."""
    design = np.column_stack((2.0 * x, 2.0 * y, np.ones_like(x)))
    (a, b, c), *_ = np.linalg.lstsq(design, x * x + y * y, rcond=None)
    return float(math.sqrt(c + a * a + b * b))


@pytest.mark.parametrize("name", VEHICLES)
def test_on_a_circle_the_feedforward_holds_the_rear_axle_on_it(name: str) -> None:
    """Closed loop on a circle to steady state: with the feed-forward the rear axle's CTE settles at ~0 (and far
    below the law's own offset without it), and the steady command, held open loop, drives the vehicle round a
    circle of the same radius: it is the steer that holds the circle."""
    radius, speed_kmh, tolerance = CIRCLES[name]
    vehicle = make_vehicle(name)
    scenario = Scenario("circle", _circle(radius), "circle")
    config = SimulationConfig(speed_kmh=speed_kmh, max_lateral_accel_g=0.5)
    steady_cte = {}
    for feedforward in (False, True):
        controller = Stanley(vehicle.geometry, StanleyConfig(curvature_feedforward=feedforward), vehicle=vehicle)
        result = Simulation(scenario, vehicle, controller, config).run()
        assert result.status.value == "completed", result.message
        late = _steady(result)
        assert late["speed_mps"].min() > 0.98 * speed_kmh / 3.6
        steady_cte[feedforward] = float(late["cte_m"].mean())
        assert float(late["cte_m"].max() - late["cte_m"].min()) < tolerance  # settled
    command = float(late["steer_wheel_cmd_rad"].mean())
    assert abs(steady_cte[True]) < tolerance, steady_cte
    assert abs(steady_cte[False]) > 1.4 * abs(steady_cte[True]) + 0.02, steady_cte
    open_loop = Simulation(scenario, vehicle, _Constant(vehicle.geometry, command), config).run()
    late = _steady(open_loop)
    assert _fitted_radius(late["x_m"].to_numpy(), late["y_m"].to_numpy()) == pytest.approx(radius, abs=tolerance)


@pytest.mark.parametrize("name", VEHICLES)
def test_on_the_figure8_the_feedforward_makes_tracking_better(name: str) -> None:
    """figure8 at 30 km/h: max |CTE| with the feed-forward at most that without it (measured: kinematic car 0.152
    -> 0.018 m, dynamic car 0.029 -> 0.008 m, loaded truck 0.057 -> 0.023 m, multi-body car 0.054 -> 0.027 m)."""
    vehicle = make_vehicle(name)
    scenario = make_scenario("figure8", ScenarioOptions(vehicle_width_m=vehicle.geometry.width_m))
    worst = {}
    for feedforward in (False, True):
        controller = Stanley(vehicle.geometry, StanleyConfig(curvature_feedforward=feedforward), vehicle=vehicle)
        result = Simulation(scenario, vehicle, controller, SimulationConfig(speed_kmh=30.0)).run()
        assert result.status.value == "completed", result.message
        worst[feedforward] = result.metrics.max_abs_cte_m
    assert worst[True] <= 0.7 * worst[False], worst


# ------------------------------------------------------------------------------ the reference form's damping terms
class _PlainLaw(Stanley):
    """The law without the damping terms, written out as the module docstring's first equation: the reference a
    Stanley with both damping terms at 0 must match bit for bit."""

    def _command(self, measurement: Measurement, path: ReferencePath) -> float:
        cfg, m, wheelbase = self.config, measurement, self.geometry.wheelbase_m
        foot = self._tracker.update(m.x_m + wheelbase * math.cos(m.yaw_rad), m.y_m + wheelbase * math.sin(m.yaw_rad))
        heading_term = wrap_angle(foot.heading_rad - m.yaw_rad)
        cross_track_term = math.atan2(-cfg.gain_per_s * foot.cte_m, cfg.softening_mps + m.speed_mps)
        feedforward = self.feedforward_rad(foot.curvature_1pm, m.speed_mps) if cfg.curvature_feedforward else 0.0
        self._diag[:] = (foot.cte_m, heading_term, cross_track_term, feedforward)
        limit = self.geometry.max_road_wheel_angle_rad
        road_wheel = heading_term + cross_track_term + feedforward
        return self.saturate(min(max(road_wheel, -limit), limit) * self.geometry.steering_ratio)


@pytest.mark.parametrize("feedforward", [False, True])
def test_with_the_damping_terms_off_a_run_is_bit_for_bit_the_plain_law(feedforward: bool) -> None:
    """Both damping terms at 0 (their defaults): every logged signal of a run on the fig17 S-bend (but the step's
    wall-clock time) equals the plain law's, exactly."""
    vehicle = make_vehicle("dynamic-bicycle")
    scenario = make_scenario("fig17", ScenarioOptions(vehicle_width_m=vehicle.geometry.width_m))
    config = StanleyConfig(curvature_feedforward=feedforward, yaw_rate_damping_s=0.0, steering_damping=0.0)
    assert StanleyConfig(curvature_feedforward=feedforward) == config  # off by default
    traces = []
    for cls in (Stanley, _PlainLaw):
        result = Simulation(scenario, vehicle, cls(vehicle.geometry, config, vehicle=vehicle), SimulationConfig()).run()
        assert result.status.value == "completed", result.message
        traces.append(result.to_pandas())
    assert list(traces[0].columns) == list(traces[1].columns)
    for column in (c for c in traces[0].columns if c != "step_time_s"):  # all but the wall-clock time of a step
        assert np.array_equal(traces[0][column].to_numpy(), traces[1][column].to_numpy(), equal_nan=True), column


@pytest.mark.parametrize(("yaw_rate", "speed", "damping"), [(0.2, 10.0, 0.3), (-0.1, 5.0, 0.05), (0.05, 20.0, 1.0)])
def test_the_yaw_rate_term_is_minus_k_yaw_times_the_yaw_rate_the_path_does_not_ask_for(
    yaw_rate: float, speed: float, damping: float
) -> None:
    """Beside a straight line (trajectory yaw rate 0), aligned, 0.3 m left of it, yawing at r: delta = atan(-k e /
    (k_soft + v)) - k_yaw r. On a circle of radius R, rear axle on it and yawing at v / R (the trajectory's yaw
    rate), the term vanishes: the command is that without damping."""
    cfg = StanleyConfig(yaw_rate_damping_s=damping)
    controller = Stanley(GEOMETRY, cfg)
    controller.reset(STRAIGHT, 0.02)
    command = controller.step(Measurement(0.0, 0.0, 0.3, speed, 0.0, 0.0, yaw_rate, 0.0), STRAIGHT)
    expected = math.atan(-cfg.gain_per_s * 0.3 / (cfg.softening_mps + speed)) - damping * yaw_rate
    assert command / GEOMETRY.steering_ratio == pytest.approx(expected, abs=1e-12)
    radius = 40.0
    circle = _circle(radius)
    on_circle = Measurement(0.0, 0.0, 0.0, speed, 0.0, 0.0, speed / radius, 0.0)
    damped, plain = Stanley(GEOMETRY, cfg), Stanley(GEOMETRY, StanleyConfig())
    for controller in (damped, plain):
        controller.reset(circle, 0.02)
    # the path's curvature at the front axle's foot point is 1 / R to the chords' error (~1e-5 of it)
    assert damped.step(on_circle, circle) == pytest.approx(plain.step(on_circle, circle), abs=damping * speed * 1e-6)


@pytest.mark.parametrize("damping", [0.5, 3.0])
def test_the_steering_damping_opposes_a_change_of_the_command(damping: float) -> None:
    """delta = u + k_steer (delta_prev - delta), delta_prev the last command (0 after a reset): the first step
    gives u / (1 + k), the next (u' + k delta_1) / (1 + k), with u, u' the undamped law's commands (hand-computed
    beside a straight line, aligned)."""
    cfg = StanleyConfig(steering_damping=damping)
    controller = Stanley(GEOMETRY, cfg)
    controller.reset(STRAIGHT, 0.02)

    def law(offset: float, speed: float) -> float:
        return math.atan(-cfg.gain_per_s * offset / (cfg.softening_mps + speed))

    ratio = GEOMETRY.steering_ratio
    first = controller.step(Measurement(0.0, 0.0, 0.5, 8.0, 0.0, 0.0, 0.0, 0.0), STRAIGHT) / ratio
    assert first == pytest.approx(law(0.5, 8.0) / (1.0 + damping), abs=1e-12)
    second = controller.step(Measurement(0.02, 0.16, -0.2, 8.0, 0.0, 0.0, 0.0, 0.0), STRAIGHT) / ratio
    assert second == pytest.approx((law(-0.2, 8.0) + damping * first) / (1.0 + damping), abs=1e-12)
    controller.reset(STRAIGHT, 0.02)  # a reset forgets the last command
    again = controller.step(Measurement(0.0, 0.0, 0.5, 8.0, 0.0, 0.0, 0.0, 0.0), STRAIGHT) / ratio
    assert again == pytest.approx(first, abs=1e-15)


@pytest.mark.parametrize(
    ("option", "value"), [("yaw_rate_damping_s", -0.1), ("steering_damping", -1.0), ("steering_damping", math.nan)]
)
def test_a_damping_term_outside_its_range_is_refused_naming_it(option: str, value: float) -> None:
    with pytest.raises(WorkbenchInputError, match=rf"{option} must be a finite number in \[0, "):
        StanleyConfig(**{option: value})
