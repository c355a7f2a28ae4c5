"""What the NMPC and the LTV-MPC share: their common options, the prediction model they are built with, and the
step: project onto the path, estimate the model state, sample the path along the planned progress, solve, and
fall back to the previous plan when a solve is not accepted.

Each step (section 6.6 of the paper compares the clothoid controller with an MPC; this is that baseline):
  1. the foot point on the path (the progress-following `PathTracker`), the Frenet errors e_y, e_psi;
  2. the model's initial state: measured where the sensors give it (lateral velocity, yaw rate, road-wheel angle,
     path curvature as yaw rate / speed), the commanded angle being the last command sent, and states no sensor
     gives (the lag's curvature rate, the delay state) taken from the previous plan shifted to now;
  3. per interval k the path curvature at the planned progress s_k (from the previous plan: the vehicle's own
     predicted progress, so an offset or a heading error moves the curvature samples as it should) and the speed
     v_k = measured speed + (planned speed at s_k - planned speed at s_0), at least min_model_speed_mps
     (`preview.py`);
  4. the solve, warm-started from the previous plan shifted to now;
  5. the command: the plan's commanded road-wheel angle one controller period ahead (its rate is the input),
     times the steering ratio, saturated. A solve that is not accepted (failed, iteration limit, late, infeasible,
     non-finite) is not used: the previous plan, shifted, is replayed (hold of the current command if there is
     none), and the trace says so (`ctrl_fallback` = 1, `ctrl_solver_status`, `ctrl_plan_age_s`).

A known measurement latency L and actuation dead time D (`measurement_latency_s`, `input_delay_s`) are compensated
as Autoware's lateral MPC does: the state of step 2, which describes t - L, is predicted to t + D with the commands
already sent (`MPCController.predict_ahead`), and the plan starts there (`ctrl_delay_compensation_s` = L + D,
logged when it is not 0).

An optional pose filter (`pose_filter_cutoff_hz`, off by default) goes before step 1: a complementary filter that
dead-reckons the pose with the measured velocity and yaw rate and pulls it toward the measured pose at a first-order
crossover (`PoseFilter`). Pose noise in the loop's own correction band (the NMPC corrects an offset with
an S-shaped steering pulse at 0.6-0.8 Hz on the loaded truck) then no longer drives the steering, where a low-pass on
the command would have to cut into that band; the motion the rates describe passes without lag, so the delay
compensation needs nothing more.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

import casadi as ca
import numpy as np
from numba import njit

from controllers.base import Controller, Measurement
from controllers.config_checks import Choice, Flag, Instance, Number, Whole, check_options, option
from controllers.mpc.codegen import FastFunction, compile_function
from controllers.mpc.ocp import TrackingOCP, TrackingWeights
from controllers.mpc.plan import Plan, shift_rows
from controllers.mpc.prediction_model import (
    MODEL_KINDS,
    PredictionModel,
    PredictionParams,
    matching_preset,
    params_from_geometry,
    prediction_params_for,
)
from controllers.mpc.preview import PathPreview
from controllers.mpc.solver import MPCSolver
from controllers.mpc.status import SolveStatus
from controllers.search_space import Tunable
from workbench.base.errors import WorkbenchInputError, value_text
from workbench.base.path import PathTracker, Projection, ReferencePath, wrap_angle
from workbench.vehicles.geometry import VehicleGeometry
from workbench.vehicles.steering_lag import SteeringLag

if TYPE_CHECKING:
    from workbench.simulation.known_delays import KnownDelays

#: Below this speed (m/s) yaw rate / speed and the course angle are not used (the yaw and the previous plan are).
MIN_MEASURED_SPEED_MPS = 0.5
#: Relative mismatch of wheelbase or steering ratio between the prediction vehicle and the steered vehicle that is
#: rejected as a configuration error (a car's model predicting a truck).
GEOMETRY_TOLERANCE = 0.02
#: The objective logged when a solve returned none.
NO_OBJECTIVE = -1.0
#: The signals every MPC logs each step, in the order `_command` writes them (then, when on, delay_compensation_s
#: and the pose filter's pose_filter_offset_m and pose_filter_heading_offset_rad).
SOLVE_DIAGNOSTICS = (
    "solver_status",
    "solve_time_s",
    "solver_iterations",
    "fallback",
    "plan_age_s",
    "failed_solves",
    "objective",
    "predicted_cte_end_m",
    "road_wheel_rate_cmd_rad_s",
    "model_speed_mps",
)
#: The largest cost weight the options allow (larger ones only make the QPs ill-conditioned).
MAX_WEIGHT = 1e9
#: Command knots closer than this (s) to an end of the prediction window start no segment of their own.
_KNOT_MERGE_S = 1e-9
#: The largest crossover frequency of the pose filter (Hz): far above it the filter passes the measurement as it is.
MAX_POSE_FILTER_HZ = 100.0
#: The pose filter's crossover (Hz) an MPC told a noisy pose switches on (`MPCController.informed_config`): below
#: the loop's own offset correction (an S-shaped steering pulse at 0.6-0.8 Hz on the loaded truck), so that pose
#: noise in that band no longer drives the steering, while the motion the rates describe passes without lag.
INFORMED_POSE_FILTER_CUTOFF_HZ = 0.3


class PoseFilter:
    """Complementary filter on the measured pose (x, y, yaw) at crossover frequency `cutoff_hz`.

    Each step it dead-reckons its estimate over the time dt since the last step with the measured body velocity and
    yaw rate (the velocities' mean and the yaw rate at the interval's middle, held: an arc, integrated exactly), then
    moves it toward the measured pose by k = 1 - exp(-2 pi cutoff_hz dt): the measured pose through a first-order
    low-pass at the cutoff, plus the dead-reckoned motion through the complementary high-pass. With exact signals the
    estimate is the measured pose (exactly on an arc; to the change of the rates within a step otherwise); white pose
    noise keeps k / (2 - k) of its variance per axis. The yaw rate is taken where the pose is: `yaw_rate_lead_s` (the
    yaw rate's latency minus the pose's) shifts it along the line through its last two samples. The first
    measurement after a reset is taken as it is; a pose held by a slower localisation (or, with a latency, before the
    run's start) counts as measured again, as it does without the filter, and the estimate runs ahead of it until
    the hold ends."""

    def __init__(self, cutoff_hz: float, yaw_rate_lead_s: float = 0.0) -> None:
        self.cutoff_hz, self.yaw_rate_lead_s = float(cutoff_hz), float(yaw_rate_lead_s)
        self.reset()

    def reset(self) -> None:
        """Forget the estimate: the next measurement starts it."""
        self._previous: Measurement | None = None
        self._x = self._y = self._yaw = 0.0

    def gain(self, elapsed_s: float) -> float:
        """The correction gain k after `elapsed_s` seconds without one."""
        return 1.0 - math.exp(-2.0 * math.pi * self.cutoff_hz * elapsed_s)

    def __call__(self, m: Measurement) -> Measurement:
        """The measurement with its pose replaced by the filter's estimate."""
        previous = self._previous
        self._previous = m
        if previous is None:
            self._x, self._y, self._yaw = m.x_m, m.y_m, m.yaw_rad
            return m
        dt = m.t_s - previous.t_s
        if dt > 0.0:  # (a repeated time stamp adds nothing)
            # The yaw rate at the middle of the interval the pose moved over: samples dt apart, the newer describing
            # yaw_rate_lead_s before the pose's time (-1/2: their mean when the latencies agree).
            c = self.yaw_rate_lead_s / dt - 0.5
            rate = m.yaw_rate_rad_s + c * (m.yaw_rate_rad_s - previous.yaw_rate_rad_s)
            vx, vy = 0.5 * (m.vx_mps + previous.vx_mps), 0.5 * (m.vy_mps + previous.vy_mps)
            half = 0.5 * rate * dt  # the arc's chord: exact for constant body velocity and yaw rate
            chord = dt * (math.sin(half) / half if abs(half) > 1e-4 else 1.0 - half * half / 6.0)
            cos_m, sin_m = math.cos(self._yaw + half), math.sin(self._yaw + half)
            k = self.gain(dt)
            self._x += chord * (cos_m * vx - sin_m * vy)
            self._x += k * (m.x_m - self._x)
            self._y += chord * (sin_m * vx + cos_m * vy)
            self._y += k * (m.y_m - self._y)
            self._yaw += rate * dt
            self._yaw += k * float(wrap_angle(m.yaw_rad - self._yaw))
        yaw = m.yaw_rad - float(wrap_angle(m.yaw_rad - self._yaw))  # the estimate, on the measurement's branch
        return Measurement(m.t_s, self._x, self._y, m.vx_mps, m.vy_mps, yaw, m.yaw_rate_rad_s, m.steer_wheel_rad)


def _vehicle_choices() -> tuple[str, ...]:
    """What MPCConfig.vehicle may name: "auto", "geometry" or a shipped preset (`workbench vehicles`)."""
    from workbench.vehicles import VEHICLES

    return ("auto", "geometry", *VEHICLES)


@dataclass(frozen=True)
class MPCConfig:
    """Options common to both MPCs (module docstring). Each field's unit, allowed range and meaning are in its
    metadata (`config_checks.option`): `check_options` checks them and `workbench controllers --show nmpc` prints
    them. The objects a file is read into (`prediction_vehicle`, `lag`) are given in a config file or `--set` by
    their file options (`vehicle_file`, `lag_file`), read when the config is loaded."""

    vehicle: str = option(
        "auto",
        'where the prediction model\'s parameters come from: "auto" (the steered vehicle\'s own when the caller passes '
        "its model, else the shipped preset of the same geometry, else the geometry alone), \"geometry\" (kinematic "
        "single track from the geometry), or a preset name",
        Choice(_vehicle_choices),
    )
    prediction_vehicle: PredictionParams | None = option(  # noqa: RUF009  (option is a dataclasses.field)
        None,
        "a vehicle's single-track equivalent to predict with instead of `vehicle` (in a file, vehicle_file names a "
        "vehicle TOML file)",
        Instance(PredictionParams, "as `vehicle` says"),
    )
    lag: SteeringLag | None = option(  # noqa: RUF009  (option is a dataclasses.field)
        None,
        'an identified steering lag the prediction uses (in a file, lag_file names a "steering-lag/1" JSON from '
        "`tuning fit-lag`)",
        Instance(SteeringLag, "no identified lag"),
    )
    model: str = option(
        "auto",
        'the prediction model (`prediction_model.py`): "auto" (kinematic-lag with a lag, else dynamic when mass and '
        'tyres are known, else kinematic), "dynamic", "kinematic" or "kinematic-lag"',
        Choice(("auto", *MODEL_KINDS)),
    )
    horizon_steps: int = option(30, "N, the prediction horizon in steps of step_s", Whole(2, 500, "steps"))
    step_s: float = option(0.05, "h, the prediction step", Number(1e-3, 1.0, "s"))
    weight_cte: float = option(200.0, "the stage weight on the cross-track error", Number(0.0, MAX_WEIGHT, "1/m^2"))
    weight_heading: float = option(
        10.0, "the stage weight on the heading error", Number(0.0, MAX_WEIGHT, "1/rad^2")
    )
    weight_steer_rate: float = option(
        5.0,
        "the stage weight on the road-wheel angle's rate (the input): larger is smoother and slower",
        Number(0.0, MAX_WEIGHT, "s^2/rad^2", low_open=True),
    )
    terminal_weight_cte: float = option(
        2000.0, "the terminal weight on the cross-track error", Number(0.0, MAX_WEIGHT, "1/m^2")
    )
    terminal_weight_heading: float = option(
        100.0, "the terminal weight on the heading error", Number(0.0, MAX_WEIGHT, "1/rad^2")
    )
    max_lat_accel_mps2: float = option(
        0.0,
        "a soft limit on the predicted lateral acceleration (its slack weighted by weight_lat_accel_slack)",
        Number(0.0, 50.0, "m/s^2", note="0: no limit"),
    )
    weight_lat_accel_slack: float = option(
        100.0,
        "the weight on the lateral-acceleration limit's slack",
        Number(0.0, MAX_WEIGHT, "s^4/m^2"),
    )
    min_model_speed_mps: float = option(
        3.0, "the prediction never runs slower than this", Number(0.5, 50.0, "m/s")
    )
    max_solve_time_s: float = option(
        0.0,
        "the solver's wall-time budget; a solve cut short by it is late and not used (a machine-dependent result: "
        "raise it for reproducible runs)",
        Number(0.0, 10.0, "s", note="0: the sample time"),
    )
    codegen: bool = option(
        True,
        "compile the model's derivatives with the system C compiler where that pays (cached; ignored without a "
        "compiler)",
        Flag(),
    )
    input_delay_s: float = option(
        0.0,
        "D, the known actuation dead time (a command sent at t reaches the steering at t + D), compensated by "
        "predicting the measured state to t + D with the commands already sent",
        Number(0.0, 1.0, "s", note="0: none"),
    )
    measurement_latency_s: float = option(
        0.0,
        "L, the known measurement latency (the measurement stamped t describes t - L), compensated as input_delay_s",
        Number(0.0, 1.0, "s", note="0: none"),
    )
    pose_filter_cutoff_hz: float = option(
        0.0,
        "the crossover frequency of the complementary filter on the measured pose (`PoseFilter`): pose noise in the "
        "loop's correction band then no longer drives the steering",
        Number(0.0, MAX_POSE_FILTER_HZ, "Hz", note="0: off"),
    )
    yaw_rate_latency_s: float | None = option(
        None,
        "the known latency of the measured yaw rate when it differs from measurement_latency_s, by which the pose "
        "filter aligns the yaw rate with the pose (only with the pose filter)",
        Number(0.0, 1.0, "s", none_means="measurement_latency_s"),
    )

    def __post_init__(self) -> None:
        check_options(self)
        if self.yaw_rate_latency_s is not None and self.pose_filter_cutoff_hz == 0.0:
            raise WorkbenchInputError(
                "yaw_rate_latency_s is used by the pose filter only: set pose_filter_cutoff_hz > 0 or leave "
                f"yaw_rate_latency_s unset (none); got {value_text(self.yaw_rate_latency_s)}"
            )

    @property
    def yaw_rate_lead_s(self) -> float:
        """How much older the measured yaw rate is than the measured pose (s): yaw_rate_latency_s - L."""
        latency = self.measurement_latency_s if self.yaw_rate_latency_s is None else self.yaw_rate_latency_s
        return latency - self.measurement_latency_s

    @property
    def weights(self) -> TrackingWeights:
        return TrackingWeights(
            cte=self.weight_cte,
            heading=self.weight_heading,
            steer_rate=self.weight_steer_rate,
            terminal_cte=self.terminal_weight_cte,
            terminal_heading=self.terminal_weight_heading,
            lat_accel_slack=self.weight_lat_accel_slack,
        )


#: The search space of both MPCs (`NMPCController`, `LMPCController`): the cost weights and the horizon. The
#: weights act through their ratios, over decades: a log scale each. The horizon is at least 20 steps of 0.04 s
#: (0.8 s): on the loaded truck's dlc at 30 km/h a 0.5-0.6 s horizon leaves the path.
MPC_SEARCH_SPACE = (
    Tunable("weight_cte", "log", 10.0, 5000.0, reason="a heavier cross-track weight tracks tighter for more "
            "steering effort and less damping"),
    Tunable("weight_heading", "log", 0.5, 500.0, reason="a heavier heading weight damps the approach to the path, "
            "and slows the correction of an offset"),
    Tunable("weight_steer_rate", "log", 0.1, 100.0, reason="a heavier steering-rate weight is smoother and slower: "
            "less steering effort, more cross-track error"),
    Tunable("terminal_weight_cte", "log", 100.0, 50000.0, reason="the horizon end's cross-track weight: heavier "
            "settles on the path sooner, a short horizon stabler"),
    Tunable("terminal_weight_heading", "log", 5.0, 2000.0, reason="the horizon end's heading weight: heavier "
            "arrives aligned with the path, at the cost of effort"),
    Tunable("horizon_steps", "integer", 20, 60, reason="a longer horizon sees bends earlier and is stabler, for "
            "solve time growing with the steps"),
    Tunable("step_s", "linear", 0.04, 0.1, reason="a longer prediction step sees further for the same solve time, "
            "with a coarser model of fast motion"),
)  # fmt: skip


def resolve_prediction_params(geometry: VehicleGeometry, config: MPCConfig, vehicle: object | None) -> PredictionParams:
    """The prediction parameters for a controller, in this order: the config's prediction_vehicle; its vehicle when not
    "auto"; the `vehicle` the caller passes (a VehicleModel, its params, ...: the steered vehicle itself); the
    shipped preset with the same geometry; the geometry alone. The config's lag file goes on top. The steering
    limits are always the steered vehicle's (`geometry`)."""
    from workbench.vehicles import VEHICLES

    if config.prediction_vehicle is not None:
        params = config.prediction_vehicle
    elif config.vehicle == "auto" and vehicle is not None:
        params = prediction_params_for(vehicle)
    elif config.vehicle == "auto":
        preset = matching_preset(geometry)
        params = prediction_params_for(preset) if preset else params_from_geometry(geometry)
    elif config.vehicle == "geometry":
        params = params_from_geometry(geometry)
    elif config.vehicle in VEHICLES:
        params = prediction_params_for(config.vehicle)
    else:
        raise WorkbenchInputError(
            f"vehicle must be 'auto', 'geometry' or one of the presets {', '.join(VEHICLES)}; got {config.vehicle!r}"
        )
    for name, mine, theirs in (
        ("wheelbase_m", params.wheelbase_m, geometry.wheelbase_m),
        ("steering_ratio", params.steering_ratio, geometry.steering_ratio),
    ):
        if abs(mine - theirs) > GEOMETRY_TOLERANCE * theirs:
            raise WorkbenchInputError(
                f"the prediction model ({params.source}) has {name} = {mine:g} but the steered vehicle has "
                f"{theirs:g}; choose the matching vehicle or vehicle_file (or vehicle = 'auto')"
            )
    params = PredictionParams(
        wheelbase_m=params.wheelbase_m,
        steering_ratio=geometry.steering_ratio,
        max_road_wheel_angle_rad=geometry.max_road_wheel_angle_rad,
        max_road_wheel_rate_rad_s=geometry.max_steer_wheel_rate_rad_s / geometry.steering_ratio,
        steering_time_constant_s=params.steering_time_constant_s,
        single_track=params.single_track,
        lag=params.lag,
        source=params.source,
    )
    if config.lag is not None:
        params = params.with_lag(config.lag)
    return params


class MPCController(Controller):
    """Base of the two MPCs: subclasses build `self.solver` (an `MPCSolver`) in `_build_solver`."""

    @classmethod
    def informed_config(cls, config: MPCConfig, delays: KnownDelays) -> MPCConfig:
        """`config` told the conditions' nominal delays, as a vehicle's state estimator and delay compensation
        would be configured; both MPCs (`NMPCConfig`, `LMPCConfig`) have every option set here (`MPCConfig`).

        Parameters
        ----------
        config : MPCConfig
            The controller's options.
        delays : KnownDelays
            The conditions' nominal delays and pose noise.

        Returns
        -------
        MPCConfig
            `config` with input_delay_s = the actuation dead time and measurement_latency_s = the pose latency
            (the state predicted over both with the commands already sent); when the pose is noisy
            (`KnownDelays.pose_is_noisy`) and the pose filter is off, pose_filter_cutoff_hz =
            INFORMED_POSE_FILTER_CUTOFF_HZ (a cutoff already set is kept); with the pose filter on,
            yaw_rate_latency_s = the yaw rate's own latency, by which the filter aligns the yaw rate with the
            pose. A delay beyond an option's range is refused naming the option."""
        cutoff = config.pose_filter_cutoff_hz
        if delays.pose_is_noisy and cutoff == 0.0:
            cutoff = INFORMED_POSE_FILTER_CUTOFF_HZ
        yaw_rate_latency = delays.yaw_rate_latency_s if cutoff > 0.0 else config.yaw_rate_latency_s
        return replace(
            config,
            input_delay_s=delays.dead_time_s,
            measurement_latency_s=delays.pose_latency_s,
            pose_filter_cutoff_hz=cutoff,
            yaw_rate_latency_s=yaw_rate_latency,
        )

    def __init__(self, geometry: VehicleGeometry, config: Any | None = None, vehicle: object | None = None) -> None:
        super().__init__(geometry, config)
        cfg: MPCConfig = self.config
        self.prediction = resolve_prediction_params(geometry, cfg, vehicle)
        kind = cfg.model if cfg.model != "auto" else self._auto_kind()
        self.model = PredictionModel(self.prediction, kind)
        self.ocp = TrackingOCP(
            self.model,
            cfg.horizon_steps,
            cfg.step_s,
            cfg.weights,
            max_lat_accel_mps2=cfg.max_lat_accel_mps2,
            min_speed_mps=cfg.min_model_speed_mps,
        )
        self._build_solver()
        self._sample_time_s = 0.02
        self._delay_s = cfg.measurement_latency_s + cfg.input_delay_s
        self._delay_integrators: dict[tuple[int, int], FastFunction] = {}
        self._delay_integrator: FastFunction | None = None
        self._delay_chunk = 0
        self._pose_filter = (
            PoseFilter(cfg.pose_filter_cutoff_hz, cfg.yaw_rate_lead_s) if cfg.pose_filter_cutoff_hz > 0.0 else None
        )
        self._reset_state()

    # ------------------------------------------------------------------ subclass hooks
    def _auto_kind(self) -> str:
        """The model kind for model = "auto"."""
        return self.prediction.default_kind()

    solver: MPCSolver

    def _build_solver(self) -> None:  # pragma: no cover - abstract
        """Set `self.solver` from `self.ocp` and the config."""
        raise NotImplementedError

    # ------------------------------------------------------------------ Controller interface
    def _reset(self, path: ReferencePath, sample_time_s: float) -> None:
        self._sample_time_s = float(sample_time_s)
        self.solver.set_time_limit(self.config.max_solve_time_s or self._sample_time_s)
        self._reset_state()
        self._tracker: PathTracker = path.tracker(0.0)
        self._preview = PathPreview(path)
        if self._delay_s > 0.0:
            self._prepare_delay_integrator()

    def _reset_state(self) -> None:
        self._plan: Plan | None = None
        self._last_command: float | None = None
        self._failures = 0
        # The road-wheel commands sent (and their times), oldest first, the newest at the end: what the plant
        # receives over the delays (`_delayed_state`). Room for the window L + D + one period, twice over.
        capacity = 2 * math.ceil((self._delay_s + self._sample_time_s) / self._sample_time_s) + 8
        self._sent_times = np.zeros(capacity)
        self._sent_commands = np.zeros(capacity)
        self._sent_count = 0
        names = list(SOLVE_DIAGNOSTICS)
        if self._delay_s > 0.0:  # logged only when compensating, so a run without is today's trace bit for bit
            names.append("delay_compensation_s")
        if self._pose_filter is not None:  # logged only with the filter on, as the delay compensation
            self._pose_filter.reset()
            names += ["pose_filter_offset_m", "pose_filter_heading_offset_rad"]
        self._diag = self._declare_diagnostics(names)
        self._diag[: len(SOLVE_DIAGNOSTICS)] = (float(SolveStatus.SOLVED), *[0.0] * 5, NO_OBJECTIVE, 0.0, 0.0, 0.0)
        if self._delay_s > 0.0:
            self._diag[len(SOLVE_DIAGNOSTICS)] = self._delay_s

    def _command(self, measurement: Measurement, path: ReferencePath) -> float:
        m, ocp, model = measurement, self.ocp, self.model
        if self._pose_filter is not None:
            m = self._pose_filter(measurement)
        foot = self._tracker.update(m.x_m, m.y_m)
        plan = self._plan
        # The plan's time origin: now, or with a known actuation dead time D the time the command sent now starts
        # to reach the steering (t + D); warm start and fallback are taken at the same origin.
        origin = m.t_s + self.config.input_delay_s
        shifted = plan.shifted(origin) if plan is not None else None
        v0 = max(m.vx_mps if model.kind == "dynamic" else m.speed_mps, 0.0)
        if self._delay_s > 0.0:  # the measured state (at t - L) predicted to t + D with the commands sent
            x0, s0, v0 = self._delayed_state(m, foot, plan, v0)
        else:
            x0, s0 = self._initial_state(m, foot, shifted[0][0] if shifted else None), foot.s_m
        h = ocp.step_s
        if shifted is not None:
            progress = shifted[2]
        else:
            progress = max(v0, ocp.min_speed_mps) * h * np.arange(ocp.N + 1)
        along = self._preview.along(s0, progress, v0, ocp.min_speed_mps)
        kappa, speed = along[:, 0], along[:, 1]
        first = shifted is None
        if first:
            guess_inputs = np.zeros((ocp.N, ocp.nu))
            guess_states = ocp.rollout(x0, guess_inputs, kappa, speed)
            dual: tuple[np.ndarray, ...] = ()
        else:
            guess_states, guess_inputs = shifted[0], shifted[1]
            # Only IPOPT returns multipliers; the QP solvers keep their own, so no positions are computed for them.
            dual = self.solver.shift_dual(plan.dual, plan.positions(origin)) if plan.dual else ()
        result = self.solver.solve(x0, kappa, speed, guess_states, guess_inputs, dual, first)

        t_next = origin + self._sample_time_s
        if result.accepted:
            progress = ocp.progress(result.states, kappa, speed)
            self._plan = plan = Plan(origin, h, result.states, result.inputs, progress, model.i_cmd, result.dual)
        else:
            self._failures += 1
        if plan is not None:
            command = plan.command_at(t_next)
            rate = plan.rate_at(origin)
        else:  # no plan yet: hold the current command
            command, rate = float(x0[model.i_cmd]), 0.0
        limit = self.prediction.max_road_wheel_angle_rad
        command = min(max(command, -limit), limit)
        if math.isfinite(command):  # else the base class holds the last command and says so
            self._last_command = command
        if self._delay_s > 0.0 and self._last_command is not None:
            self._record_sent(m.t_s, self._last_command)
        self._diag[: len(SOLVE_DIAGNOSTICS)] = (  # in the order of SOLVE_DIAGNOSTICS
            float(result.status),
            float(result.solve_time_s),
            float(result.iterations),
            0.0 if result.accepted else 1.0,
            0.0 if plan is None else origin - plan.t_s,
            float(self._failures),
            float(result.objective) if math.isfinite(result.objective) else NO_OBJECTIVE,
            0.0 if plan is None else float(plan.states[-1, model.i_cte]),
            rate,
            float(speed[0]),
        )
        if self._pose_filter is not None:  # what the filter took off the measured pose (the last two signals)
            self._diag[-2] = math.hypot(measurement.x_m - m.x_m, measurement.y_m - m.y_m)
            self._diag[-1] = measurement.yaw_rad - m.yaw_rad
        return self.saturate(command * self.prediction.steering_ratio)

    @property
    def last_plan(self) -> Plan | None:
        """The plan the last command came from (None before the first accepted solve)."""
        return self._plan

    # ------------------------------------------------------------------ state estimate
    def _initial_state(
        self, m: Measurement, foot: Projection, predicted: np.ndarray | None, command: float | None = None
    ) -> np.ndarray:
        """The model state the measurement describes: measured components, the commanded angle (`command`; None:
        the last command sent, the measured angle on a run's first step), and the previous plan for the rest."""
        model, prm = self.model, self.prediction
        names = model.state_names
        x = np.zeros(model.nx) if predicted is None else np.array(predicted, dtype=float)
        speed = m.speed_mps
        moving = speed > MIN_MEASURED_SPEED_MPS
        road_wheel = m.steer_wheel_rad / prm.steering_ratio
        heading = m.yaw_rad
        if model.kind != "dynamic" and moving:  # kinematic kinds: the rear axle's course
            heading += math.atan2(m.vy_mps, m.vx_mps)
        x[model.i_cte] = foot.cte_m
        x[model.i_heading] = float(wrap_angle(heading - foot.heading_rad))
        if command is not None:
            pass
        elif self._last_command is None:  # the first step: the commanded angle is the measured one, within its bounds
            command = self._measured_command(m)
        else:
            command = self._last_command
        x[model.i_cmd] = command
        if model.kind == "dynamic":
            st = prm.single_track
            assert st is not None
            x[names.index("vy_cg_mps")] = m.vy_mps + st.cg_to_rear_axle_m * m.yaw_rate_rad_s
            x[names.index("yaw_rate_rad_s")] = m.yaw_rate_rad_s
            x[names.index("road_wheel_rad")] = road_wheel
        elif model.kind == "kinematic":
            x[names.index("road_wheel_rad")] = road_wheel
        else:
            assert prm.lag is not None  # the kinematic-lag kind is built only with a lag
            kinematic = prm.lag.steady_state_gain * math.tan(command)  # wheelbase x the curvature it settles at
            x[names.index("wheelbase_x_curvature")] = (
                prm.wheelbase_m * m.yaw_rate_rad_s / speed if moving else kinematic
            )
            if predicted is None:
                x[names.index("wheelbase_x_curvature_rate_1ps")] = 0.0
                if "delayed_wheelbase_x_curvature" in names:
                    x[names.index("delayed_wheelbase_x_curvature")] = kinematic
        return x

    def _measured_command(self, m: Measurement) -> float:
        """The measured road-wheel angle within its bounds: the commanded angle assumed before any command."""
        limit = self.prediction.max_road_wheel_angle_rad
        return min(max(m.steer_wheel_rad / self.prediction.steering_ratio, -limit), limit)

    # ------------------------------------------------------------------ known delays
    def _delay_segment_s(self) -> float:
        """The longest segment of the prediction over the delays (s): a controller period, at most a prediction step."""
        return min(self._sample_time_s, self.ocp.step_s)

    def _prepare_delay_integrator(self) -> None:
        """The compiled integrator of `predict_ahead` for this sample time, built once per (chunk, sub-steps) and
        kept. One call integrates a chunk of segments, as many as the window L + D has with one per controller
        period (padded with empty ones; more segments take more calls), each by RK4 over its own duration dt with
        its rate u and path (kappa, v) held, in enough sub-steps for the fastest mode at the longest segment
        (`substeps_for`); the state is augmented by the progress along the path s (s' = `progress_rate`)."""
        model, ocp = self.model, self.ocp
        longest = self._delay_segment_s()
        chunk = math.ceil(self._delay_s / longest - 1e-9) + 2
        substeps = model.substeps_for(longest, ocp.min_speed_mps)
        key = (chunk, substeps)
        if key not in self._delay_integrators:
            nx = model.nx
            z, u, p, dt = ca.SX.sym("z", nx + 1), ca.SX.sym("u", 1), ca.SX.sym("p", 2), ca.SX.sym("dt", 1)

            def rate(zk: ca.SX) -> ca.SX:
                return ca.vertcat(model.ode(zk[:nx], u, p), model.progress_rate(zk[:nx], p))

            h = dt / substeps
            zk = z
            for _ in range(substeps):
                k1 = rate(zk)
                k2 = rate(zk + 0.5 * h * k1)
                k3 = rate(zk + 0.5 * h * k2)
                k4 = rate(zk + h * k3)
                zk = zk + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
            mapped = ca.Function("delay_step", [z, u, p, dt], [zk]).mapaccum(chunk)
            inputs = mapped.mx_in()
            name = f"mpc_{model.kind.replace('-', '_')}_delay_{chunk}x{substeps}"
            compiled = compile_function(ca.Function(name, inputs, mapped.call(inputs)), self.config.codegen)
            self._delay_integrators[key] = FastFunction(compiled.function)
        self._delay_integrator, self._delay_chunk = self._delay_integrators[key], chunk

    def _record_sent(self, t_s: float, command: float) -> None:
        """Buffer a road-wheel command sent at t_s (the oldest falls out when full). The first one is preceded by the
        commanded angle assumed before any command, one period earlier (`_delayed_state`)."""
        times, commands = self._sent_times, self._sent_commands
        if self._sent_count < times.size:
            times[self._sent_count], commands[self._sent_count] = t_s, command
            self._sent_count += 1
        else:
            times[:-1], commands[:-1] = times[1:], commands[1:]
            times[-1], commands[-1] = t_s, command

    def _delayed_state(
        self, m: Measurement, foot: Projection, plan: Plan | None, v0_mps: float
    ) -> tuple[np.ndarray, float, float]:
        """(model state at t + D, arc length of its foot point, speed there) from a measurement stamped t that
        describes t - L (MPCConfig's input_delay_s D, measurement_latency_s L).

        As Autoware's lateral MPC (`autoware_mpc_lateral_controller`, `MPC::updateStateForDelayCompensation`, which
        rolls the initial state over `input_delay` with the commands kept in `m_input_buffer` and resamples the
        reference from `nearest_time + input_delay`): the plant receives at tau the command sent at tau - D, so over
        [t - L, t + D] it receives the buffered commands sent over [t - L - D, t - D]. In the model's convention,
        where the command sent at t_j is the commanded angle reached one period T later (the plan's command at
        t + T is sent at t), the commanded angle at tau is the buffered commands, linearly interpolated, at
        tau - D - T: so it starts at the command being received at t - L and the input rates are the slopes between
        buffered commands; before the first command it is the measured angle of the first step, after the last
        the last held. States no sensor gives are the previous plan's at t - L (its start if t - L is earlier)."""
        cfg, T = self.config, self._sample_time_s
        if self._sent_count == 0:  # a run's first step: the angle measured now has been commanded all along
            self._record_sent(m.t_s - T, self._measured_command(m))
        n = self._sent_count
        start = m.t_s - cfg.measurement_latency_s - cfg.input_delay_s - T  # t - L, in the buffer's time (tau - D - T)
        dts, rates, command = _delay_segments(
            self._sent_times[:n], self._sent_commands[:n], start, self._delay_s, self._delay_segment_s()
        )
        unmeasured = None
        if plan is not None:
            unmeasured = shift_rows(
                plan.states, max((m.t_s - cfg.measurement_latency_s - plan.t_s) / plan.step_s, 0.0), 1
            )[0]
        x = self._initial_state(m, foot, unmeasured, command)
        return self.predict_ahead(x, foot.s_m, v0_mps, dts, rates)

    def predict_ahead(
        self, x0: np.ndarray, s0_m: float, v0_mps: float, durations_s: np.ndarray, rates: np.ndarray
    ) -> tuple[np.ndarray, float, float]:
        """(state, foot arc length s0 + progress (m), speed (m/s)) after the segments `durations_s` (s, each at most
        `_delay_segment_s`) with the input rates `rates` (rad/s, the commanded angle's), from state x0 at foot arc
        length s0_m and speed v0_mps: the model integrated along the path (reset first), each segment on the path's
        curvature and speed at its middle (`PathPreview.along`, at progress estimated at the model's speed; the
        Frenet errors and the progress are the model's own), RK4. The speed at the end follows the path's speed
        profile from v0 as the preview does. Needs input_delay_s or measurement_latency_s > 0."""
        integrate, chunk, nx = self._delay_integrator, self._delay_chunk, self.model.nx
        assert integrate is not None, "predict_ahead needs input_delay_s or measurement_latency_s > 0 and a reset"
        dt, u, nodes = _chunked(durations_s, rates, chunk, max(v0_mps, self.ocp.min_speed_mps))
        path = self._preview.along(s0_m, nodes, v0_mps, self.ocp.min_speed_mps)
        z = np.empty(nx + 1)
        z[:nx], z[nx] = x0, 0.0
        for c in range(0, dt.shape[0], chunk):
            (out,) = integrate(z, u[c : c + chunk], path[c : c + chunk].T, dt[c : c + chunk])
            z = out[-(nx + 1) :].copy()
        progress = float(z[nx])
        planned_change = float(self._preview.along(s0_m, np.array([progress, progress]), 0.0, -math.inf)[0, 1])
        return z[:nx], s0_m + progress, v0_mps + planned_change


@njit(cache=True)
def _chunked(
    durations: np.ndarray, rates: np.ndarray, chunk: int, speed_mps: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:  # pragma: no cover - compiled
    """Segments padded with empty ones (duration and rate 0) to whole chunks: (durations, rates, progress at
    each node estimated at speed_mps, the padding's at the last). Compiled: it runs every step."""
    k = durations.shape[0]
    size = max(1, -(-k // chunk)) * chunk
    dt, u, nodes = np.zeros(size), np.zeros(size), np.zeros(size + 1)
    for i in range(k):
        dt[i], u[i] = durations[i], rates[i]
    for i in range(size):
        nodes[i + 1] = nodes[i] + speed_mps * dt[i]
    return dt, u, nodes


@njit(cache=True)
def _delay_segments(
    times: np.ndarray, commands: np.ndarray, start: float, horizon: float, max_step: float
) -> tuple[np.ndarray, np.ndarray, float]:  # pragma: no cover - compiled
    """The commanded angle over [start, start + horizon] as segments: (durations (s), rates (rad/s), the angle at
    start). The angle is the buffered commands linearly interpolated in time, held before the first and after the
    last; segments break at the buffered times and are at most max_step long. Compiled: it runs every step."""
    end = start + horizon
    breaks = np.empty(times.shape[0] + 2)
    breaks[0] = start
    count = 1
    for t in times:
        if start + _KNOT_MERGE_S < t < end - _KNOT_MERGE_S:
            breaks[count] = t
            count += 1
    breaks[count] = end
    count += 1
    pieces = np.empty(count - 1, dtype=np.int64)
    for i in range(count - 1):
        pieces[i] = max(1, math.ceil((breaks[i + 1] - breaks[i]) / max_step - 1e-9))
    durations = np.empty(pieces.sum())
    rates = np.empty(durations.shape[0])
    first = np.interp(start, times, commands)
    before, j = first, 0
    for i in range(count - 1):
        after = np.interp(breaks[i + 1], times, commands)
        length = breaks[i + 1] - breaks[i]
        for _ in range(pieces[i]):
            durations[j] = length / pieces[i]
            rates[j] = (after - before) / length if length > 0.0 else 0.0
            j += 1
        before = after
    return durations, rates, first
