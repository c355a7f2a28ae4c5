"""Real-time iteration (RTI) of the NMPC problem: one Gauss-Newton SQP step, i.e. one sparse QP, per control step.

Each step linearises the discrete prediction model along the previous solution shifted to the current time
(one call of a compiled CasADi function that returns x_{k+1} = F(x_k, u_k) and its Jacobians for all N
intervals at once), updates the QP's matrices in place and solves it with OSQP, warm-started. The cost is a sum
of squares of states and inputs, so its Gauss-Newton Hessian is constant and the QP's P never changes; only the
dynamics blocks A_k, B_k, the offsets c_k = F(x_k, u_k) - A_k x_k - B_k u_k, the initial state and (with a
lateral-acceleration limit) the linearised soft constraint change. This is the scheme of Diehl, Bock & Schloeder
(2005) and acados, with the QP built by hand instead of by casadi's `sqpmethod` so that nothing is rebuilt or
re-analysed per step. Iterated to convergence (`solve(iterations=...)`) it is a full-step Gauss-Newton SQP that
reaches the same optimum as IPOPT (tested); the controller iterates on its first step only, when no previous
solution exists to linearise along.
"""

from __future__ import annotations

import time

import casadi as ca
import numpy as np

from controllers.mpc.codegen import FastFunction
from controllers.mpc.ocp import TrackingOCP
from controllers.mpc.sparse_qp import OsqpSettings
from controllers.mpc.status import SolveResult, SolveStatus

#: An SQP iteration whose largest input change is below this (rad/s) counts as converged.
STEP_TOLERANCE = 1e-7


class RtiSolver:
    """Gauss-Newton SQP on a TrackingOCP with an OSQP sparse QP (an `MPCSolver`); `codegen` compiles the
    linearisation; `first_iterations`: SQP iterations of a run's first solve (one after it: the real-time
    iteration)."""

    def __init__(
        self, ocp: TrackingOCP, settings: OsqpSettings | None = None, codegen: bool = True, first_iterations: int = 1
    ) -> None:
        self.ocp = ocp
        self.first_iterations = first_iterations
        N, nx = ocp.N, ocp.nx
        compiled = ocp.linearisation(codegen)
        self.linearise = FastFunction(compiled.function)
        self.compiled, self.codegen_note = compiled.compiled, compiled.note
        x, p = ca.SX.sym("x", nx), ca.SX.sym("p", 2)
        if ocp.soft:
            ay = ocp.model.lateral_accel(x, p)
            soft = ca.Function("soft", [x, p], [ay, ca.densify(ca.jacobian(ay, x))]).map(N)
            soft_in = soft.mx_in()
            self.soft_fn = FastFunction(ca.Function("soft_map", soft_in, soft.call(soft_in)).expand())
        self.qp = ocp.sparse_qp(settings)
        self._bounds_version = ocp.bounds_version

    def solve(
        self,
        x0: np.ndarray,
        kappa: np.ndarray,
        speed: np.ndarray,
        guess_states: np.ndarray,
        guess_inputs: np.ndarray,
        guess_dual: tuple[np.ndarray, ...] = (),
        first: bool = False,
        iterations: int | None = None,
    ) -> SolveResult:
        """`iterations` Gauss-Newton SQP steps from the guess (None: `first_iterations` on a run's first solve, one
        after it, the real-time iteration). The multipliers are not used: OSQP keeps its own."""
        if iterations is None:
            iterations = self.first_iterations if first else 1
        ocp, qp = self.ocp, self.qp
        N, nx = ocp.N, ocp.nx
        if ocp.bounds_version != self._bounds_version:
            qp.set_bounds(ocp.x_lower, ocp.x_upper, ocp.u_lower, ocp.u_upper)
            self._bounds_version = ocp.bounds_version
        params = np.vstack((kappa, speed))
        states = np.array(guess_states, dtype=float)
        inputs = np.array(guess_inputs, dtype=float)
        states[0] = x0
        start = time.perf_counter()
        status, qp_iterations, solution = SolveStatus.ERROR, 0, None
        warm = qp.pack(states, inputs)
        for _ in range(max(1, iterations)):
            f_next, jac_x, jac_u = self.linearise(states[:-1].T, inputs.T, params)
            # column-major (nx, N nx) -> A[k, i, j]; views, no copies
            A = jac_x.reshape(N, nx, nx).transpose(0, 2, 1)
            B = jac_u.reshape(N, ocp.nu, nx).transpose(0, 2, 1)
            c = f_next.reshape(N, nx) - np.einsum("kij,kj->ki", A, states[:-1]) - np.einsum("kij,kj->ki", B, inputs)
            G = soft_lo = soft_hi = None
            if ocp.soft:
                ay, jac_ay = self.soft_fn(states[1:].T, params)
                G = jac_ay.reshape(N, nx)
                offset = ay - np.einsum("ki,ki->k", G, states[1:])
                soft_hi = ocp.max_lat_accel_mps2 - offset
                soft_lo = -ocp.max_lat_accel_mps2 - offset
            if not (np.all(np.isfinite(A)) and np.all(np.isfinite(B)) and np.all(np.isfinite(c))):
                status = SolveStatus.NUMERICAL_ERROR
                break
            qp.update(x0, A, B, c, G, soft_lo, soft_hi)
            solution = qp.solve(warm)
            status, qp_iterations = solution.status, qp_iterations + solution.iterations
            if not status.accepted:
                break
            step = float(np.max(np.abs(solution.inputs - inputs)))
            states, inputs, warm = solution.states, solution.inputs, solution.z
            if step < STEP_TOLERANCE:
                break
        elapsed = time.perf_counter() - start
        objective = solution.objective if (status.accepted and solution is not None) else float("nan")
        return SolveResult(status, states, inputs, qp_iterations, elapsed, objective)

    def set_time_limit(self, seconds: float) -> None:
        self.qp.set_time_limit(seconds)

    def shift_dual(self, dual: tuple[np.ndarray, ...], positions: np.ndarray) -> tuple[np.ndarray, ...]:
        return ()
