"""Closed-loop simulation: a controller steering a plant along a scenario's path at a planned speed.

Fixed steps: the controller (and the speed controller) run at `controller_rate_hz`; between two controller
steps the plant integrates `plant_rate_hz / controller_rate_hz` RK4 steps with the commands held (zero-order
hold). One row of the trace is logged per controller step. The run ends when the vehicle reaches the end of an
open path or completes the requested laps of a closed one; it stops early, keeping its partial trace and saying
why, on a time-out, when the vehicle leaves the path (further than `max_abs_cte_m` from it, or beyond either end
of an open path by more than `max_past_end_m`), when the plant state stops being finite, when the plant fails a
step (`PlantStepError`: an FMU plant's doStep), or when the controller fails. The logged CTE is the signed
distance from the path, so beyond an open path's ends it is the distance to the end point, never the sideways
offset from the end's tangent alone.
"""

from __future__ import annotations

import math
import operator
import time

import numpy as np
from tqdm import tqdm

from workbench.base.errors import WorkbenchInputError, require_finite
from workbench.base.path import ReferencePath
from workbench.simulation.control_interface import (
    COMMAND_REJECTED,
    MEASUREMENT_REJECTED,
    Measurement,
    SteeringController,
)
from workbench.simulation.feasibility import VehicleLimits, check_path, feasibility_warnings
from workbench.simulation.result import SimulationResult, Status
from workbench.simulation.run_config import SimulationConfig
from workbench.simulation.run_size import RunSize
from workbench.simulation.scenarios import Scenario
from workbench.simulation.sensing import ActuatorModel, SensorModel
from workbench.simulation.speed_control import PISpeedGains
from workbench.simulation.speed_profile import G_MPS2, SpeedLimits, TopSpeed, TopSpeedLimit, plan_speed_profile
from workbench.simulation.step_kernel import (
    FOOT_AT_END,
    FOOT_DISTANCE,
    FOOT_PAST_END,
    FOOT_PROGRESS,
    FOOT_S,
    PROJECTED_NOT_FINITE,
    PROJECTED_OFF_PATH,
    PROJECTED_PAST_END,
    SIGNALS,
    compiled_path,
    finish_step,
    project_pose,
    run_settings,
)
from workbench.simulation.track_margin import VehicleOutline
from workbench.vehicles.base import PlantStepError, VehicleModel

#: Spacing (m) of the points the speed profile is planned on (the paper plans on its waypoints).
SPEED_PLAN_SPACING_M = 1.0
#: The first seven of a vehicle's outputs (`STANDARD_OUTPUTS`: x, y, yaw, vx, vy, yaw rate, steering-wheel angle),
#: what the measurement holds: indexed, as numpy scalars, at half the cost of unpacking a slice.
_MEASURED = operator.itemgetter(0, 1, 2, 3, 4, 5, 6)


def plan_path_speed(path: ReferencePath, config: SimulationConfig) -> ReferencePath:
    """The path carrying the planned speed: the paper's smart velocity waypoints (section 6), capped by any speed
    the path's waypoints already carry (`plan_path_speed_and_top`).

    Parameters
    ----------
    path : ReferencePath
        The path to plan along; a speed its waypoints carry (m/s, > 0 everywhere) caps the planned one.
    config : SimulationConfig
        The speed asked for (`speed_kmh`), the lateral-acceleration bound (`max_lateral_accel_g`) and the
        acceleration and braking bounds (`max_accel_mps2`, `max_decel_mps2`) the profile is planned within.

    Returns
    -------
    ReferencePath
        `path` with its planned speed (m/s) at each of its samples.

    Raises
    ------
    WorkbenchInputError
        When the path's own speed is not > 0 m/s somewhere (the message names the first such place).
    """
    return plan_path_speed_and_top(path, config)[0]


def plan_path_speed_and_top(path: ReferencePath, config: SimulationConfig) -> tuple[ReferencePath, TopSpeed]:
    """The path carrying the planned speed (`plan_path_speed`) and its top speed with what limited it: the speed
    profile's (`SpeedProfile.top_speed`), or the path's own speeds where they lower the top.

    Parameters
    ----------
    path : ReferencePath
        The path to plan along; a speed its waypoints carry (m/s, > 0 everywhere) caps the planned one.
    config : SimulationConfig
        The speed asked for and the lateral, acceleration and braking bounds the profile is planned within.

    Returns
    -------
    tuple of (ReferencePath, TopSpeed)
        `path` with its planned speed (m/s), and the planned top speed (m/s), where along the path it is (m) and
        what limited it (the speed asked for, the lateral-acceleration, acceleration or braking bound, or the
        path's own speeds).

    Raises
    ------
    WorkbenchInputError
        When the path's own speed is not > 0 m/s somewhere (the message names the first such place).
    """
    n = max(3, math.ceil(path.length_m / SPEED_PLAN_SPACING_M))
    s_plan = np.linspace(0.0, path.length_m, n + 1)
    if path.closed:
        s_plan = s_plan[:-1]
    x, y = path.position(s_plan)
    limits = SpeedLimits(
        max_speed_mps=config.speed_mps,
        max_lateral_accel_mps2=config.max_lateral_accel_g * G_MPS2,
        max_accel_mps2=config.max_accel_mps2,
        max_decel_mps2=config.max_decel_mps2,
        min_speed_mps=min(1.0, config.speed_mps),
    )
    profile = plan_speed_profile(x, y, limits, closed=path.closed)
    planned = profile.speed_mps
    if path.closed:  # close the loop for interpolation
        s_plan, planned = np.append(s_plan, path.length_m), np.append(planned, planned[0])
    speed = np.interp(path.s_m, s_plan, planned)
    if path.speed_mps is not None:
        stopped = np.flatnonzero(~(path.speed_mps > 0.0))
        if stopped.size:
            i = int(stopped[0])
            raise WorkbenchInputError(
                f"{path.name}: the path's speed must be > 0 m/s everywhere (a run follows it without stopping); "
                f"it is {float(path.speed_mps[i]):g} m/s at s = {float(path.s_m[i]):.1f} m"
            )
        capped = np.minimum(speed, path.speed_mps)
        if capped.max() < speed.max() * (1.0 - 1e-9):
            i = int(np.argmax(capped))
            top = TopSpeed(limits.max_speed_mps, float(capped[i]), float(path.s_m[i]), TopSpeedLimit.PATH_SPEED, limits)
            return path.with_speed(capped), top
        speed = capped
    return path.with_speed(speed), profile.top_speed()


class Simulation:
    """A scenario, a vehicle and a controller, wired once; `run()` simulates and returns a SimulationResult.

    The path's speed is planned when the simulation is built (`plan_path_speed_and_top`), and where the vehicle
    cannot follow it at that speed is found then (`path_warnings`), so that both can be told before the run.

    Parameters
    ----------
    scenario : Scenario
        The reference path, where the vehicle starts on it and what to draw around it (`make_scenario`).
    vehicle : VehicleModel
        The plant (`make_vehicle`); its road friction is set for the run from the conditions.
    controller : Controller
        The steering controller (`controllers.make_controller`); it is reset at the start of `run`.
    config : SimulationConfig, optional
        Speed, rates, laps, limits and conditions of the run (None: the defaults, 30 km/h and ideal conditions).

    Raises
    ------
    WorkbenchInputError
        When more than one lap is asked of an open path, or the path's own speed is not > 0 m/s somewhere.

    Examples
    --------
    >>> from controllers import make_controller
    >>> from workbench.simulation.run_config import SimulationConfig
    >>> from workbench.simulation.scenarios import make_scenario
    >>> from workbench.simulation.simulator import Simulation
    >>> from workbench.vehicles import make_vehicle
    >>> vehicle = make_vehicle("kinematic-bicycle")
    >>> controller = make_controller("stanley", vehicle.geometry)
    >>> simulation = Simulation(make_scenario("fig17"), vehicle, controller, SimulationConfig(speed_kmh=30.0))
    >>> result = simulation.run()
    >>> result.status.value
    'completed'
    """

    def __init__(
        self,
        scenario: Scenario,
        vehicle: VehicleModel,
        controller: SteeringController,
        config: SimulationConfig | None = None,
    ) -> None:
        self.scenario = scenario
        self.vehicle = vehicle
        self.controller = controller
        self.config = config or SimulationConfig()
        if self.config.laps > 1 and not scenario.path.closed:
            raise WorkbenchInputError(
                f"laps = {self.config.laps}: {scenario.path.name} is an open path (it has two ends); laps apply to "
                "closed paths only, so give 1"
            )
        self.path, self.top_speed = plan_path_speed_and_top(scenario.path, self.config)
        #: The most this run may simulate before it times out (`run_size.RunSize`: time, steps, trace size).
        self.size = RunSize.of(self.path, self.config, len(vehicle.output_names))
        #: Where the vehicle cannot follow the path at its planned speed (`feasibility.py`), said before the run
        #: and written to metrics.json.
        self.infeasible_curvature = check_path(self.path, vehicle)

    def warnings(self, label: str = "the run") -> list[str]:
        """What to tell a person before this run: `path_warnings`, the planned top speed when it falls short of
        the speed asked for (`top_speed_warning`), and the controller's own (`controller_warnings`).

        Parameters
        ----------
        label : str
            What each of the top-speed and controller warnings starts with, naming the run (e.g. its folder).

        Returns
        -------
        list of str
            One line per warning, in that order; empty when there is nothing to tell.
        """
        top = self.top_speed_warning(label)
        return self.path_warnings() + ([top] if top is not None else []) + self.controller_warnings(label)

    def controller_warnings(self, label: str = "the run") -> list[str]:
        """What the controller says about this run before it starts (`SteeringController.run_warnings` on the
        planned path at the controller rate: e.g. the clothoid controller's lookahead floor above its range), each
        after `label`; none from a controller without that method.

        Parameters
        ----------
        label : str
            What each warning starts with, naming the run.

        Returns
        -------
        list of str
            One line per warning, each ``"<label>: <warning>"``; empty when the controller has none.
        """
        run_warnings = getattr(self.controller, "run_warnings", None)
        if run_warnings is None:
            return []
        return [f"{label}: {w}" for w in run_warnings(self.path, 1.0 / self.config.controller_rate_hz)]

    def top_speed_warning(self, label: str = "the run") -> str | None:
        """The planned top speed and what limited it, when it falls short of the speed asked for (`TopSpeed`);
        None when the profile reaches it.

        Parameters
        ----------
        label : str
            What the warning starts with, naming the run.

        Returns
        -------
        str or None
            ``"<label>: <planned top and its limit>"``, or None when the planned top reaches the speed asked for.
        """
        if self.top_speed.reached:
            return None
        return f"{label}: {self.top_speed.describe()}"

    def path_warnings(self) -> list[str]:
        """What about the path this vehicle cannot do, to say before the run: stretches curving tighter than its
        steering lock turns it (understeer included), or asking more lateral acceleration than its rollover threshold
        or tyres allow at the planned speed (`feasibility.py`).

        Returns
        -------
        list of str
            One line per kind of infeasible stretch, naming the path, the places and the limit; empty when the
            vehicle can follow the whole path at its planned speed.
        """
        return feasibility_warnings(self.path.name, VehicleLimits.of(self.vehicle), self.infeasible_curvature)

    @property
    def total_length_m(self) -> float:
        """The distance the run is asked to cover: the path, times the laps of a closed one."""
        return self.path.length_m * (self.config.laps if self.path.closed else 1)

    @property
    def max_time_s(self) -> float:
        """Simulated time before the run times out: the config's, or three times the planned time plus 30 s
        (`RunSize`)."""
        return self.size.max_time_s

    @property
    def max_steps(self) -> int:
        """Controller steps the run may take before its time-out: the trace's row capacity."""
        return self.size.steps

    def run(self, progress: bool = False) -> SimulationResult:
        """Simulate until the run ends (the module docstring says how); `progress` shows the metres covered on a bar.
        The simulator's own work at each step is compiled (`step_kernel`): Python calls the plant, the conditions'
        models and the controller, and builds the measurement.

        A run that ends early (time-out, left the path, diverged, plant or controller failed) is not an error: the
        result keeps the partial trace, and its `status` and `message` say why.

        Parameters
        ----------
        progress : bool
            Show the metres covered on a progress bar on stderr (it appears once the run has taken 2 s).

        Returns
        -------
        SimulationResult
            The trace (one row per controller step), how the run ended, and what it was run with.

        Raises
        ------
        WorkbenchInputError
            When the vehicle's position or the speed reference stops being finite (a plant or path that cannot be
            simulated), rather than a trace of NaN.
        """
        cfg, path, vehicle, controller = self.config, self.path, self.vehicle, self.controller
        dt = 1.0 / cfg.controller_rate_hz
        total_length = self.total_length_m
        max_time, max_steps = self.max_time_s, self.max_steps

        x0, y0, yaw0 = self.scenario.initial_pose()
        state = vehicle.initial_state(x0, y0, yaw0, float(path.planned_speed_mps[0]))
        tracker = path.tracker(0.0)
        controller.reset(path, dt)
        # The conditions between plant and controller (`conditions.py`): each model is left out when ideal, so an
        # ideal run is the plain closed loop, bit for bit; what the controller saw is logged beside the true state.
        conditions = cfg.conditions
        sensors = None if conditions.sensing_is_ideal else SensorModel(conditions, cfg.seed, dt)
        actuator = None if conditions.actuation.is_ideal else ActuatorModel(conditions, dt, cfg.substeps)
        road = conditions.road
        road_varies = not road.is_constant
        friction = road.friction_at(0.0)
        if getattr(vehicle, "road_friction", 1.0) != friction:
            vehicle.set_road_friction(friction)
        seen = not conditions.is_ideal
        ahead = actuator if cfg.perfect_prediction else None  # the actuator whose pending commands it applies
        speed_gains = PISpeedGains()
        settings = run_settings(  # the kernels' constants and the PI speed controller's state
            cfg.max_past_end_m, cfg.max_abs_cte_m, total_length, dt, cfg.speed_feedforward, speed_gains
        )

        log = _TraceLog(vehicle.output_names, controller.diagnostic_names, max_steps, seen)
        diagnostics = controller.diagnostic_values  # the controller's own array, rewritten by each step
        measurement_rejected = controller.diagnostic_names.index(MEASUREMENT_REJECTED)
        command_rejected = controller.diagnostic_names.index(COMMAND_REJECTED)
        status, message = Status.TIMEOUT, f"did not finish within {max_time:.1f} s"
        steer_cmd = accel_cmd = applied_cmd = 0.0
        held, first_held = 0, ""  # steps whose measurement the controller's screen rejected (it held its command)
        bar = tqdm(total=round(total_length), unit="m", delay=2.0, disable=not progress, leave=False)
        # The hot loop's names, looked up once; the compiled per-step work (`step_kernel`) reads the path's samples
        # from one table and writes the tracker's arrays and the trace's table in place.
        outputs, advance, step_controller = vehicle.outputs, vehicle.advance, controller.step
        clock, hypot, isfinite, measured = time.perf_counter, math.hypot, math.isfinite, _MEASURED
        compiled, track_state, foot = compiled_path(tracker), tracker.state, tracker.out
        samples, shape = compiled.table, compiled.record
        substeps = cfg.substeps
        table = log.table
        t = 0.0
        for step in range(max_steps):
            out = outputs(state, applied_cmd, accel_cmd)
            x, y, yaw, vx, vy, yaw_rate, steer_wheel = measured(out)
            if step == 0 and actuator is not None:
                actuator.reset(float(steer_wheel))
            where = project_pose(x, y, samples, shape, track_state, foot, settings)
            if where == PROJECTED_NOT_FINITE:
                raise WorkbenchInputError(f"position must be finite to project onto {path.name}; got ({x}, {y})")
            if road_varies:  # the foot point's arc length on the path, within a lap on a closed one
                friction = road.friction_at(float(foot[FOOT_S]))
                vehicle.set_road_friction(friction)
            if where:
                status, message = _projection_end(where, foot.tolist(), t, cfg)
                break
            measurement = Measurement(t, x, y, vx, vy, yaw, yaw_rate, steer_wheel)
            if ahead is not None:  # the true state one dead time on, the commands already sent applied
                future = state
                for segment_substeps, command in ahead.segments_ahead():
                    segment_s = dt * segment_substeps / substeps
                    future = advance(future, command, accel_cmd, segment_s, segment_substeps)
                fx, fy, fyaw, fvx, fvy, fyaw_rate, fsteer = measured(outputs(future, command, accel_cmd))
                measurement = Measurement(t, fx, fy, fvx, fvy, fyaw, fyaw_rate, fsteer)  # the speed loop keeps vx, vy
            if sensors is not None:
                measurement = sensors.measure(measurement)
            start = clock()
            try:
                steer_cmd = step_controller(measurement, path)
            except Exception as exc:  # reported in the result, never hidden
                status, message = Status.CONTROLLER_FAILED, f"{controller.name} raised {type(exc).__name__}: {exc}"
                break
            step_time = clock() - start
            if diagnostics[command_rejected] or not isfinite(steer_cmd):
                status = Status.CONTROLLER_FAILED
                message = f"{controller.name} computed a non-finite steering command at t = {t:.2f} s"
                break
            if diagnostics[measurement_rejected]:
                if not held:
                    first_held = f"first at t = {t:.2f} s: {controller.rejection}"
                held += 1
            speed = hypot(vx, vy)
            if step == log.capacity:
                table = log.grow()
            # The speed reference and its rate fed forward (d(v_ref)/dt = dv_ref/ds * ds/dt, so braking for a
            # corner is on time; without it a PI lags a braking ramp by ~0.76 x the deceleration in m/s), the PI
            # speed command and the trace's row.
            accel_cmd = finish_step(
                table, step, t, out, steer_cmd, speed, step_time, diagnostics, foot, samples, shape, settings
            )
            if accel_cmd != accel_cmd:  # NaN: the speed, its reference or the reference's rate is not finite
                s_m = float(foot[FOOT_S])
                reference, slope = path.speed(s_m), path.speed_gradient(s_m)  # the run's path has its planned speed
                rate = speed * slope if cfg.speed_feedforward and slope is not None else 0.0
                speeds = (reference, speed, rate)
                require_finite("the speed reference, the speed and the reference's rate (m/s, m/s, m/s^2)", speeds)
            log.n = step + 1
            try:
                if actuator is None:
                    state = advance(state, steer_cmd, accel_cmd, dt, substeps)
                    applied_cmd = steer_cmd
                else:
                    for segment_substeps, applied_cmd in actuator.segments(steer_cmd):
                        segment_s = dt * segment_substeps / substeps
                        state = advance(state, applied_cmd, accel_cmd, segment_s, segment_substeps)
            except PlantStepError as exc:  # a plant that cannot go on (an FMU's failed doStep) says why
                status, message = Status.PLANT_FAILED, str(exc)
                break
            if seen:
                log.seen(measurement, applied_cmd, friction)
            t += dt
            if not isfinite(sum(state.tolist())):  # a NaN or an infinity in any state makes the sum one
                bad = [n for n, v in zip(vehicle.state_names, state, strict=False) if not isfinite(v)]
                status = Status.DIVERGED
                message = f"the {vehicle.name} state diverged at t = {t:.2f} s (non-finite: {', '.join(bad)})"
                break
            if progress:
                bar.update(round(float(foot[FOOT_PROGRESS])) - bar.n)
        bar.close()
        if held:
            message += (
                f"; the controller rejected {held} measurements as implausible and held its command ({first_held})"
            )
        return SimulationResult(
            trace=log.to_dict(),
            status=status,
            message=message,
            scenario=self.scenario,
            path=path,
            controller=controller.name,
            vehicle=vehicle.name,
            config=cfg,
            outline=VehicleOutline.of(vehicle),
            infeasible_curvature=self.infeasible_curvature,
        )


def _projection_end(where: int, foot: list[float], t: float, cfg: SimulationConfig) -> tuple[Status, str]:
    """How the run ends at a projection that ends it (`step_kernel.project_pose`'s code, the tracker's output as
    a list): the status and the message."""
    distance = foot[FOOT_DISTANCE]
    if where == PROJECTED_PAST_END:
        end = "end" if foot[FOOT_AT_END] == 1.0 else "start"
        return Status.LEFT_PATH, (
            f"went {foot[FOOT_PAST_END]:.1f} m past the {end} of the path (max_past_end_m = "
            f"{cfg.max_past_end_m:g} m) at t = {t:.2f} s, {distance:.1f} m from it"
        )
    if where == PROJECTED_OFF_PATH:
        return Status.LEFT_PATH, (
            f"|CTE| = {distance:.1f} m exceeds max_abs_cte_m = {cfg.max_abs_cte_m:g} m at t = {t:.2f} s"
        )
    return Status.COMPLETED, "completed"


class _TraceLog:
    """The trace as one table, one row per controller step (`step_kernel.finish_step` writes a row's time, the
    plant's outputs, the simulator's signals and the controller's diagnostics; `seen` the columns after them); it
    doubles when full, so memory follows the steps actually run, not the time-out's capacity. `n` rows are kept."""

    #: What the controller saw and what reached the plant, logged when the conditions are not ideal: the
    #: measurement's fields (seen_*), the steering command applied at the end of the step (after the actuator's
    #: dead time and rate limit) and the road's friction scale.
    SEEN = (
        "seen_x_m",
        "seen_y_m",
        "seen_yaw_rad",
        "seen_vx_mps",
        "seen_vy_mps",
        "seen_yaw_rate_rad_s",
        "seen_steer_wheel_rad",
        "applied_steer_wheel_cmd_rad",
        "road_friction",
    )

    def __init__(
        self, output_names: tuple[str, ...], diagnostic_names: tuple[str, ...], capacity: int, seen: bool = False
    ) -> None:
        #: The table's columns, in the trace's order (a signal named like an output, `path_curvature_1pm`, takes
        #: the output's place in the trace: `to_dict`).
        self.columns = (
            "t_s",
            *output_names,
            *SIGNALS,
            *(f"ctrl_{name}" for name in diagnostic_names),
            *(self.SEEN if seen else ()),
        )
        self.seen_offset = len(self.columns) - (len(self.SEEN) if seen else 0)
        self.capacity = min(capacity, 1 << 14)
        self.table = np.empty((self.capacity, len(self.columns)))
        self.n = 0

    def grow(self) -> np.ndarray:
        """Double the capacity (the new rows NaN); the new table."""
        self.table = np.concatenate((self.table, np.full_like(self.table, np.nan)))
        self.capacity *= 2
        return self.table

    def seen(self, m: Measurement, applied_cmd: float, friction: float) -> None:
        """The seen columns of the last row kept."""
        self.table[self.n - 1, self.seen_offset :] = (
            m.x_m,
            m.y_m,
            m.yaw_rad,
            m.vx_mps,
            m.vy_mps,
            m.yaw_rate_rad_s,
            m.steer_wheel_rad,
            applied_cmd,
            friction,
        )

    def to_dict(self) -> dict[str, np.ndarray]:
        """One array per column (a column named like an earlier one replaces it, in its place); the seen columns
        only once a row has them."""
        n = self.n
        columns = self.columns if n else self.columns[: self.seen_offset]
        return {name: self.table[:n, k].copy() for k, name in enumerate(columns)}


__all__ = ["Simulation", "plan_path_speed", "plan_path_speed_and_top"]
