"""Linear time-varying MPC on OSQP, in the manner of Autoware's lateral MPC (`mpc_lateral_controller`).

Each step the prediction model's error dynamics are linearised along the path, not along a previous solution:
at every interval k about steady cornering on the path's curvature kappa_k at the planned speed v_k
(`PredictionModel.reference_states`; for the kinematic model this is Autoware's linearisation
tan(delta) ~ tan(delta_r) + (delta - delta_r) / cos^2(delta_r), delta_r = atan(L kappa)), giving
x' = A_k x + B_k u + w_k, discretised with the bilinear (Tustin) transform as Autoware does:

    A_d = (I - h/2 A)^-1 (I + h/2 A),   B_d = (I - h/2 A)^-1 B h,   w_d = (I - h/2 A)^-1 w h.

The QP (`sparse_qp.py`) is sparse, states and inputs both variables, built once; each step only its dynamics
blocks, initial state and offsets are overwritten in place, and OSQP starts from the previous plan shifted to now.
The commanded road-wheel angle is a state and its rate the input, which is Autoware's steering-rate limit and
rate penalty written as bounds and a diagonal weight. The same prediction kinds as the NMPC are available
(`model`), so with a lag file the LTV-MPC predicts with the identified lag too. "auto" picks as the NMPC does:
kinematic-lag with a lag file, else the dynamic single track when the vehicle's mass and tyres are known, else
Autoware's kinematic model.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import ClassVar

import casadi as ca
import numpy as np

from controllers.config_checks import Number, Whole, option
from controllers.mpc.codegen import FastFunction, compile_function
from controllers.mpc.config import MPC_SEARCH_SPACE, MPCConfig
from controllers.mpc.controller import MPCController
from controllers.mpc.ocp import TrackingOCP
from controllers.mpc.sparse_qp import OsqpSettings
from controllers.mpc.status import SolveResult
from controllers.search_space import Tunable


class LtvSolver:
    """The LTV QP of a TrackingOCP's model (its ODE linearised along the path, Tustin-discretised)."""

    def __init__(self, ocp: TrackingOCP, settings: OsqpSettings | None = None, codegen: bool = True) -> None:
        self.ocp = ocp
        model, N, nx, nu, h = ocp.model, ocp.N, ocp.nx, ocp.nu, ocp.step_s
        # One function from the path parameters (kappa, v) of an interval to its discrete model, compiled.
        p = ca.SX.sym("p", 2)
        x_ref = model.reference(p)
        u_ref = ca.SX.zeros(nu)
        f = model.ode(x_ref, u_ref, p)
        x, u = ca.SX.sym("x", nx), ca.SX.sym("u", nu)
        jac = ca.Function(
            "ode_jacobian", [x, u, p], [ca.jacobian(model.ode(x, u, p), x), ca.jacobian(model.ode(x, u, p), u)]
        )
        Ac, Bc = jac(x_ref, u_ref, p)
        w = f - ca.mtimes(Ac, x_ref)
        eye = ca.SX.eye(nx)
        solved = ca.solve(eye - 0.5 * h * Ac, ca.horzcat(eye + 0.5 * h * Ac, h * Bc, h * w))
        stage = ca.Function("stage", [p], [ca.densify(solved)])
        mapped = stage.map(N)
        inputs = mapped.mx_in()
        name = f"lmpc_{model.kind.replace('-', '_')}_tustin"
        compiled = compile_function(ca.Function(name, inputs, mapped.call(inputs)), codegen)
        self.discretise = FastFunction(compiled.function)
        self.compiled, self.codegen_note = compiled.compiled, compiled.note
        self.qp = ocp.sparse_qp(settings)
        self._bounds_version = ocp.bounds_version

    def matrices(self, kappa: np.ndarray, speed: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The discrete LTV model (A_d (N, nx, nx), B_d (N, nx, nu), w_d (N, nx)) along the path."""
        ocp = self.ocp
        N, nx, nu = ocp.N, ocp.nx, ocp.nu
        (solved,) = self.discretise(np.vstack((kappa, speed)))
        blocks = solved.reshape(N, nx + nu + 1, nx).transpose(0, 2, 1)  # column-major (nx, nx+nu+1) per interval
        return blocks[:, :, :nx], blocks[:, :, nx : nx + nu], blocks[:, :, nx + nu]

    def solve(
        self,
        x0: np.ndarray,
        kappa: np.ndarray,
        speed: np.ndarray,
        guess_states: np.ndarray,
        guess_inputs: np.ndarray,
        guess_dual: tuple[np.ndarray, ...] = (),
        first: bool = False,
    ) -> SolveResult:
        """Solve from x0 along the path (kappa, speed per interval), warm-started from the guess (OSQP keeps the
        multipliers of its previous solve: shifting them to now measured no fewer iterations)."""
        ocp, qp = self.ocp, self.qp
        start = time.perf_counter()
        if ocp.bounds_version != self._bounds_version:
            qp.set_bounds(ocp.x_lower, ocp.x_upper, ocp.u_lower, ocp.u_upper)
            self._bounds_version = ocp.bounds_version
        A, B, c = self.matrices(kappa, speed)
        qp.update(x0, A, B, c)
        warm = qp.pack(guess_states, guess_inputs)
        solution = qp.solve(warm)
        elapsed = time.perf_counter() - start
        objective = solution.objective if solution.status.accepted else float("nan")  # OSQP's 1/2 z'Pz = the cost
        return SolveResult(solution.status, solution.states, solution.inputs, solution.iterations, elapsed, objective)

    def set_time_limit(self, seconds: float) -> None:
        self.qp.set_time_limit(seconds)

    def shift_dual(self, dual: tuple[np.ndarray, ...], positions: np.ndarray) -> tuple[np.ndarray, ...]:
        return ()


@dataclass(frozen=True)
class LMPCConfig(MPCConfig):
    """The common MPC options (`MPCConfig`, model "auto" as the NMPC's) and OSQP's; each field's unit, range and
    meaning are in its metadata (`config_checks.option`). The lateral-acceleration limit (max_lat_accel_mps2) is the
    NMPC's only: the LTV-MPC allows 0 alone."""

    max_lat_accel_mps2: float = option(
        0.0,
        "the NMPC's soft lateral-acceleration limit, which the LTV-MPC does not have",
        Number(0.0, 0.0, "m/s^2", note="the LTV-MPC has no lateral-acceleration limit; the NMPC has"),
    )
    qp_tolerance: float = option(1e-3, "OSQP's absolute and relative tolerance", Number(1e-10, 1e-1))
    qp_max_iterations: int = option(4000, "OSQP's iteration limit", Whole(1, 10**6, "iterations"))

    def __post_init__(self) -> None:
        super().__post_init__()  # every field's rule, this class's included (`check_options`)


class LMPCController(MPCController[LMPCConfig]):
    """Autoware-style LTV-MPC (module docstring). `vehicle` (optional): the vehicle model or its parameters."""

    name: ClassVar[str] = "lmpc"
    config_type: ClassVar[type] = LMPCConfig
    search_space: ClassVar[tuple[Tunable, ...]] = MPC_SEARCH_SPACE

    def _build_solver(self) -> None:
        cfg = self.config
        settings = OsqpSettings(
            eps_abs=cfg.qp_tolerance,
            eps_rel=cfg.qp_tolerance,
            max_iter=cfg.qp_max_iterations,
            time_limit_s=self._solve_budget_s(),
        )
        self.solver = LtvSolver(self.ocp, settings, codegen=cfg.codegen)
