"""The optimal control problem the NMPC solves each step, shared by its IPOPT and real-time-iteration solvers.

Multiple shooting over N intervals of step h with the prediction model discretised by RK4:

    min   sum_{k<N} (x_k' Q x_k + u_k' R u_k) + x_N' Q_N x_N + sum_{k=1..N} (rho2 eps_k^2 + rho1 eps_k)
    s.t.  x_0 = x_hat,  x_{k+1} = F(x_k, u_k; kappa_k, v_k),
          |delta_c,k| <= delta_max,  |u_k| <= rate_max,
          |a_y(x_k)| <= a_y,max + eps_k, eps_k >= 0        (only when a lateral-acceleration limit is set)

Q penalises the cross-track and heading errors (the path-following cost in Frenet errors), R the steering rate;
Q_N is the terminal weight. The lateral-acceleration limit is soft (slack eps) so that it can never make the
problem infeasible. The per-interval parameters (path curvature kappa_k and speed v_k at the planned progress)
are solver parameters: the problem is built once and solved many times.
"""

from __future__ import annotations

from dataclasses import dataclass

import casadi as ca
import numpy as np

from controllers.mpc.codegen import CompiledFunction, FastFunction, compile_function
from controllers.mpc.prediction_model import PredictionModel
from controllers.mpc.sparse_qp import OsqpSettings, SparseMPCQP
from workbench.base.errors import WorkbenchInputError, require_in_range, require_positive, require_whole


@dataclass(frozen=True)
class TrackingWeights:
    """cte (1/m^2), heading (1/rad^2), steer_rate (s^2/rad^2, on the road-wheel rate), terminal_cte (1/m^2),
    terminal_heading (1/rad^2), lat_accel_slack (s^4/m^2, quadratic; the linear part is the same number in s^2/m)."""

    cte: float = 200.0
    heading: float = 10.0
    steer_rate: float = 5.0
    terminal_cte: float = 2000.0
    terminal_heading: float = 100.0
    lat_accel_slack: float = 100.0

    def __post_init__(self) -> None:
        for name in ("cte", "heading", "steer_rate", "terminal_cte", "terminal_heading", "lat_accel_slack"):
            require_in_range(name, getattr(self, name), 0.0, 1e9)
        require_positive("steer_rate", self.steer_rate)


class TrackingOCP:
    """Dimensions, weights, bounds and the discrete model of the NMPC problem (built once)."""

    def __init__(
        self,
        model: PredictionModel,
        horizon_steps: int,
        step_s: float,
        weights: TrackingWeights,
        max_lat_accel_mps2: float = 0.0,
        min_speed_mps: float = 3.0,
        terminal_weight: np.ndarray | None = None,
    ) -> None:
        require_whole("horizon_steps", horizon_steps, 2, 500)
        horizon_steps = int(horizon_steps)
        require_in_range("step_s", step_s, 1e-3, 1.0, "s")
        require_in_range("max_lat_accel_mps2", max_lat_accel_mps2, 0.0, 50.0, "m/s^2 (0: no limit)")
        require_in_range("min_speed_mps", min_speed_mps, 0.5, 50.0, "m/s")
        self.model, self.N, self.step_s, self.weights = model, horizon_steps, float(step_s), weights
        self.nx, self.nu = model.nx, model.nu
        self.max_lat_accel_mps2 = float(max_lat_accel_mps2)
        self.soft = self.max_lat_accel_mps2 > 0.0
        self.min_speed_mps = float(min_speed_mps)
        self.substeps = model.substeps_for(step_s, min_speed_mps)
        self.F = model.discrete(step_s, self.substeps)
        self._rollout = FastFunction(self.F.mapaccum(self.N))
        self._linearisation: dict[bool, CompiledFunction] = {}
        q = np.zeros(self.nx)
        q[model.i_cte], q[model.i_heading] = weights.cte, weights.heading
        self.Q = np.diag(q)
        self.R = np.array([[weights.steer_rate]])
        if terminal_weight is None:
            qn = np.zeros(self.nx)
            qn[model.i_cte], qn[model.i_heading] = weights.terminal_cte, weights.terminal_heading
            terminal_weight = np.diag(qn)
        terminal_weight = np.asarray(terminal_weight, dtype=float)
        if terminal_weight.shape != (self.nx, self.nx) or not np.allclose(terminal_weight, terminal_weight.T):
            raise WorkbenchInputError(f"terminal_weight must be a symmetric {self.nx}x{self.nx} matrix")
        self.QN = terminal_weight
        params = model.params
        self.x_lower = np.full(self.nx, -np.inf)
        self.x_upper = np.full(self.nx, np.inf)
        self.x_lower[model.i_cmd], self.x_upper[model.i_cmd] = (
            -params.max_road_wheel_angle_rad,
            params.max_road_wheel_angle_rad,
        )
        self.u_lower = np.array([-params.max_road_wheel_rate_rad_s])
        self.u_upper = np.array([params.max_road_wheel_rate_rad_s])
        self.bounds_version = 0  # incremented whenever the bounds change, so solvers update only then

    def sparse_qp(self, settings: OsqpSettings | None) -> SparseMPCQP:
        """The OSQP problem of this OCP's weights and bounds (with the soft lateral-acceleration rows when the
        limit is set), built once; the solvers overwrite its dynamics each step."""
        slack = self.weights.lat_accel_slack
        return SparseMPCQP(
            self.N,
            self.nx,
            self.nu,
            self.Q,
            self.R,
            self.QN,
            self.x_lower,
            self.x_upper,
            self.u_lower,
            self.u_upper,
            soft=self.soft,
            soft_weights=(slack, slack),
            settings=settings,
        )

    def linearisation(self, codegen: bool = True) -> CompiledFunction:
        """The discrete model and its Jacobians on all N intervals in one call: (X (nx, N), U (nu, N), P (2, N)) ->
        (F (nx, N), dF/dx (nx, nx N), dF/du (nx, nu N)), dense, compiled to C when `codegen` (`codegen.py`).
        Built once per OCP and shared by the RTI and the IPOPT solvers."""
        if codegen not in self._linearisation:
            x, u, p = ca.SX.sym("x", self.nx), ca.SX.sym("u", self.nu), ca.SX.sym("p", 2)
            x_next = self.F(x, u, p)
            jac_x, jac_u = ca.densify(ca.jacobian(x_next, x)), ca.densify(ca.jacobian(x_next, u))
            mapped = ca.Function("stage", [x, u, p], [x_next, jac_x, jac_u]).map(self.N)
            inputs = mapped.mx_in()
            name = f"nmpc_{self.model.kind.replace('-', '_')}_lin"
            self._linearisation[codegen] = compile_function(ca.Function(name, inputs, mapped.call(inputs)), codegen)
        return self._linearisation[codegen]

    def rollout(self, x0: np.ndarray, inputs: np.ndarray, kappa: np.ndarray, speed: np.ndarray) -> np.ndarray:
        """States (N+1, nx) of the nonlinear discrete model from x0 under `inputs` (N, nu)."""
        (out,) = self._rollout(x0, inputs.T, np.vstack((kappa, speed)))
        return np.vstack((x0, out.reshape(self.N, self.nx)))

    def progress(self, states: np.ndarray, kappa: np.ndarray, speed: np.ndarray) -> np.ndarray:
        """Predicted arc length travelled along the path (m) at each node: the trapezoidal integral of s'."""
        return self.model.progress(states, kappa, speed, self.step_s)

    def set_steer_bounds(self, lower_rad: float, upper_rad: float) -> None:
        """Bounds on the commanded road-wheel angle (rad). Solvers read them at every solve, so this also serves to
        inject an infeasible problem (lower above the current command) in tests."""
        i = self.model.i_cmd
        self.x_lower[i], self.x_upper[i] = float(lower_rad), float(upper_rad)
        self.bounds_version += 1

    def stage_cost(self, x: ca.SX, u: ca.SX) -> ca.SX:
        return ca.bilin(ca.DM(self.Q), x, x) + ca.bilin(ca.DM(self.R), u, u)

    def terminal_cost(self, x: ca.SX) -> ca.SX:
        return ca.bilin(ca.DM(self.QN), x, x)
