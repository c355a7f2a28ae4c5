"""The controller the NMPC and the LTV-MPC share (`MPCController`): the prediction model they are built with, and
the step: project onto the path, estimate the model state, sample the path along the planned progress, solve, and
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

An optional pose filter (`pose_filter_cutoff_hz`, `pose_filter.py`) goes before step 1. The options are
`MPCConfig` (`config.py`); the vehicle predicted with is resolved by `prediction_vehicle.py`.
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import TYPE_CHECKING, TypeVar

import casadi as ca
import numpy as np

from controllers.base import Controller, Measurement
from controllers.mpc.codegen import FastFunction, compile_function
from controllers.mpc.config import DEFAULT_PERIOD_S, MPCConfig
from controllers.mpc.delay_segments import chunked, delay_segments
from controllers.mpc.ocp import TrackingOCP
from controllers.mpc.plan import Plan, shift_rows
from controllers.mpc.pose_filter import INFORMED_POSE_FILTER_CUTOFF_HZ, PoseFilter
from controllers.mpc.prediction_model import PredictionModel
from controllers.mpc.prediction_vehicle import resolve_prediction_params
from controllers.mpc.preview import PathPreview
from controllers.mpc.solver import MPCSolver
from controllers.mpc.status import SolveStatus
from workbench.base.path import PathTracker, Projection, ReferencePath, wrap_angle
from workbench.vehicles.geometry import VehicleGeometry

if TYPE_CHECKING:
    from workbench.simulation.known_delays import KnownDelays
    from workbench.vehicles.base import VehicleModel

#: An MPC's config: `MPCConfig` or the subclass its controller's `config_type` names.
MPCConfigT = TypeVar("MPCConfigT", bound=MPCConfig)

#: Below this speed (m/s) yaw rate / speed and the course angle are not used (the yaw and the previous plan are).
MIN_MEASURED_SPEED_MPS = 0.5
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


class MPCController(Controller[MPCConfigT]):
    """Base of the two MPCs: subclasses build `self.solver` (an `MPCSolver`) in `_build_solver`."""

    @classmethod
    def informed_config(cls, config: MPCConfigT, delays: KnownDelays) -> MPCConfigT:
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

    def __init__(
        self, geometry: VehicleGeometry, config: MPCConfigT | None = None, vehicle: VehicleModel | None = None
    ) -> None:
        """`config`: an instance of the subclass's `config_type` (its defaults when None); `vehicle`: what to predict
        with when the config's vehicle is "auto" (`resolve_prediction_params`)."""
        super().__init__(geometry, config)
        cfg = self.config
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
        self._sample_time_s = DEFAULT_PERIOD_S  # until `reset` gives the run's
        self._build_solver()
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

    def _solve_budget_s(self) -> float:
        """The solver's wall-time budget (s): max_solve_time_s, or the controller period when it is 0."""
        return self.config.max_solve_time_s or self._sample_time_s

    # ------------------------------------------------------------------ Controller interface
    def _reset(self, path: ReferencePath, sample_time_s: float) -> None:
        self._sample_time_s = float(sample_time_s)
        self.solver.set_time_limit(self._solve_budget_s())
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
        if self._delay_s > 0.0:  # logged only when compensating, so a run without has the plain trace
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
        dual: tuple[np.ndarray, ...] = ()
        if shifted is None:
            guess_inputs = np.zeros((ocp.N, ocp.nu))
            guess_states = ocp.rollout(x0, guess_inputs, kappa, speed)
        else:
            guess_states, guess_inputs = shifted[0], shifted[1]
            # Only IPOPT returns multipliers; the QP solvers keep their own, so no positions are computed for them.
            if plan is not None and plan.dual:  # (a shifted plan is there exactly when a plan is)
                dual = self.solver.shift_dual(plan.dual, plan.positions(origin))
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
        dts, rates, command = delay_segments(
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
        profile from v0 as the preview does. Needs input_delay_s or measurement_latency_s > 0.

        Parameters
        ----------
        x0 : numpy.ndarray of float
            The prediction model's state at the start, shape (nx,) (`PredictionModel.state_names`).
        s0_m : float, m
            The arc length of the vehicle's foot point on the path at the start.
        v0_mps : float, m/s
            The speed at the start.
        durations_s : numpy.ndarray of float, s
            The segments' durations, each > 0 and at most the delay segment the controller was reset with.
        rates : numpy.ndarray of float, rad/s
            The commanded steering angle's rate over each segment, one per duration.

        Returns
        -------
        state : numpy.ndarray of float
            The model's state after the last segment, shape (nx,).
        s_m : float, m
            The foot point's arc length then, s0_m plus the model's progress.
        speed_mps : float, m/s
            The speed then, v0_mps changed as the path's speed profile changes over the progress.
        """
        integrate, chunk, nx = self._delay_integrator, self._delay_chunk, self.model.nx
        assert integrate is not None, "predict_ahead needs input_delay_s or measurement_latency_s > 0 and a reset"
        dt, u, nodes = chunked(durations_s, rates, chunk, max(v0_mps, self.ocp.min_speed_mps))
        path = self._preview.along(s0_m, nodes, v0_mps, self.ocp.min_speed_mps)
        z = np.empty(nx + 1)
        z[:nx], z[nx] = x0, 0.0
        for c in range(0, dt.shape[0], chunk):
            (out,) = integrate(z, u[c : c + chunk], path[c : c + chunk].T, dt[c : c + chunk])
            z = out[-(nx + 1) :].copy()
        progress = float(z[nx])
        planned_change = float(self._preview.along(s0_m, np.array([progress, progress]), 0.0, -math.inf)[0, 1])
        return z[:nx], s0_m + progress, v0_mps + planned_change


__all__ = ["MPCController"]
