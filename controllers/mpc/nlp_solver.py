"""The NMPC problem as one CasADi NLP solved by IPOPT: built once, solved many times.

The NLP is built once from the `TrackingOCP` with the initial state and the per-interval curvature and speed as
parameters (never rebuilt per step), expanded to SX so that IPOPT's callbacks (gradient, Jacobian, exact Hessian
of the Lagrangian) are flat SX graphs, and warm-started each step from the previous solution shifted to the
current time, primal and dual (x0, lam_x0, lam_g0, with IPOPT's warm_start_init_point). Variables are interleaved
per stage, [x_0, u_0, x_1, u_1, ..., x_N, eps_1..eps_N], which keeps the KKT matrix banded.

The Hessian is by default the Gauss-Newton one (the cost's, constant: the cost is a sum of squares), which spares
the costly exact Hessian of the Lagrangian through N RK4 steps; IPOPT then converges to the same KKT point in a few
more iterations. `exact_hessian=True` restores it.

The constraint Jacobian, evaluated at every IPOPT iteration, comes from the OCP's compiled linearisation (the
same C code the RTI uses, `TrackingOCP.linearisation`) rather than CasADi's SX virtual machine. Compiling the whole
NLP with CasADi's JIT instead took far longer to build and saved less, so it is not offered. The real-time variant
is `rti.py`; benchmarks/run.py measures the step times.

IPOPT's own wall-time limit (max_wall_time) enforces the real-time budget: a solve it cuts short returns status
LATE and is not used.
"""

from __future__ import annotations

import time
from typing import Any

import casadi as ca
import numpy as np

from controllers.mpc.config import DEFAULT_PERIOD_S
from controllers.mpc.ocp import TrackingOCP
from controllers.mpc.plan import interp_rows
from controllers.mpc.status import IPOPT_STATUS, SolveResult, SolveStatus


class IpoptSolver:
    """IPOPT on the multiple-shooting NLP of a TrackingOCP."""

    def __init__(
        self,
        ocp: TrackingOCP,
        max_iterations: int = 100,
        tolerance: float = 1e-6,
        max_solve_time_s: float = DEFAULT_PERIOD_S,
        exact_hessian: bool = False,
        codegen: bool = True,
    ) -> None:
        self.ocp = ocp
        N, nx, nu = ocp.N, ocp.nx, ocp.nu
        ns = N if ocp.soft else 0
        stage = nx + nu
        self.n_var = N * stage + nx + ns
        self.ix = np.array([[k * stage + i for i in range(nx)] for k in range(N + 1)])
        self.iu = np.array([[k * stage + nx + i for i in range(nu)] for k in range(N)])
        self.ie = N * stage + nx + np.arange(ns)

        w = ca.SX.sym("w", self.n_var)
        x0 = ca.SX.sym("x0", nx)
        kappa = ca.SX.sym("kappa", N)
        speed = ca.SX.sym("v", N)
        p = ca.vertcat(x0, kappa, speed)
        X = [w[self.ix[k]] for k in range(N + 1)]
        U = [w[self.iu[k]] for k in range(N)]
        f: ca.SX | float = 0  # the cost, summed over the stages
        g = [X[0] - x0]
        for k in range(N):
            pk = ca.vertcat(kappa[k], speed[k])
            f += ocp.stage_cost(X[k], U[k])
            g.append(X[k + 1] - ocp.F(X[k], U[k], pk))
        f += ocp.terminal_cost(X[N])
        self.n_eq = (N + 1) * nx
        if ocp.soft:
            rho = ocp.weights.lat_accel_slack
            for k in range(N):
                eps = w[self.ie[k]]
                ay = ocp.model.lateral_accel(X[k + 1], ca.vertcat(kappa[k], speed[k]))
                g += [ay - eps, ay + eps]
                f += rho * eps * eps + rho * eps
        self.n_con = self.n_eq + 2 * ns
        self._nlp = {"x": w, "p": p, "f": f, "g": ca.vertcat(*g)}
        self._options: dict[str, Any] = {
            "expand": True,
            "print_time": False,
            "error_on_fail": False,
            "ipopt": {
                "print_level": 0,
                "sb": "yes",
                "max_iter": int(max_iterations),
                "tol": float(tolerance),
                "acceptable_tol": 100.0 * float(tolerance),
                "acceptable_iter": 5,
                "warm_start_init_point": "yes",
                "warm_start_bound_push": 1e-9,
                "warm_start_bound_frac": 1e-9,
                "warm_start_slack_bound_push": 1e-9,
                "warm_start_slack_bound_frac": 1e-9,
                "warm_start_mult_bound_push": 1e-9,
                "mu_init": 1e-2,
                "mu_strategy": "adaptive",
                "linear_solver": "mumps",
            },
        }
        self.exact_hessian = exact_hessian
        if not exact_hessian:
            # Gauss-Newton: the cost is a sum of squares, so drop the constraints' curvature; the Hessian is then
            # constant (IPOPT evaluates it once per solve) and IPOPT converges to the same KKT point.
            lam_f, lam_g = ca.SX.sym("lam_f"), ca.SX.sym("lam_g", self.n_con)
            hessian = ca.triu(lam_f * ca.hessian(f, w)[0])
            self._options["hess_lag"] = ca.Function(
                "nlp_hess_l", [w, p, lam_f, lam_g], [hessian], ["x", "p", "lam_f", "lam_g"], ["hess_gamma_x_x"]
            )
            self._options["ipopt"]["hessian_constant"] = "yes"
        self.compiled = False
        if not ocp.soft:
            compiled = ocp.linearisation(codegen)
            if compiled.compiled:
                self._options["jac_g"] = self._compiled_jacobian(compiled.function)
                self.compiled = True
        self.max_solve_time_s = -1.0
        self.set_time_limit(max_solve_time_s)
        self.lbg = np.zeros(self.n_con)
        self.ubg = np.zeros(self.n_con)
        if ocp.soft:
            self.lbg[self.n_eq :: 2] = -np.inf
            self.ubg[self.n_eq :: 2] = ocp.max_lat_accel_mps2
            self.lbg[self.n_eq + 1 :: 2] = -ocp.max_lat_accel_mps2
            self.ubg[self.n_eq + 1 :: 2] = np.inf

    def _compiled_jacobian(self, linearisation: ca.Function) -> ca.Function:
        """g and its Jacobian from the compiled linearisation of all N intervals, scattered into the Jacobian's
        sparsity (identity blocks for x_{k+1}, -A_k, -B_k), in place of CasADi's SX evaluation (0.75 ms a call at
        N = 30 for the dynamic bicycle, against 0.1 ms compiled)."""
        ocp = self.ocp
        N, nx, nu = ocp.N, ocp.nx, ocp.nu
        stage = nx + nu
        w, p = ca.MX.sym("w", self.n_var), ca.MX.sym("p", nx + 2 * N)
        body = ca.reshape(w[: N * stage], stage, N)
        states, inputs = body[:nx, :], body[nx:, :]
        x_next = ca.horzcat(states[:, 1:], w[N * stage : N * stage + nx])
        params = ca.horzcat(p[nx : nx + N], p[nx + N :]).T
        f_next, jac_x, jac_u = linearisation(states, inputs, params)
        g = ca.vertcat(states[:, 0] - p[:nx], ca.vec(x_next - f_next))
        # triplets: identity on every node, then -dF/dx and -dF/du in their column-major order
        k, i, j = np.meshgrid(np.arange(N), np.arange(nx), np.arange(nx), indexing="ij")  # jac_x[i, k nx + j]
        ku, iu_, ju = np.meshgrid(np.arange(N), np.arange(nx), np.arange(nu), indexing="ij")
        order_x = np.argsort(((k * nx + j) * nx + i).ravel())  # position of each triplet in vec(jac_x)
        order_u = np.argsort(((ku * nu + ju) * nx + iu_).ravel())
        rows = np.concatenate(
            (np.arange((N + 1) * nx), ((k + 1) * nx + i).ravel()[order_x], ((ku + 1) * nx + iu_).ravel()[order_u])
        )
        cols = np.concatenate((self.ix.ravel(), self.ix[k, j].ravel()[order_x], self.iu[ku, ju].ravel()[order_u]))
        values = ca.vertcat(ca.DM.ones((N + 1) * nx), -ca.vec(jac_x), -ca.vec(jac_u))
        csc = np.lexsort((rows, cols))
        sparsity = ca.Sparsity.triplet(self.n_con, self.n_var, rows[csc].tolist(), cols[csc].tolist())
        jacobian = ca.MX(sparsity, values[csc.tolist()])
        return ca.Function("nlp_jac_g", [w, p], [g, jacobian], ["x", "p"], ["g", "jac_g_x"])

    def set_time_limit(self, seconds: float) -> None:
        """IPOPT's max_wall_time (s); an option of the solver instance, so a new limit re-creates it (from the
        same expressions: no new graph is built)."""
        if seconds == self.max_solve_time_s:
            return
        self.max_solve_time_s = float(seconds)
        self._options["ipopt"]["max_wall_time"] = float(seconds)
        self.solver = ca.nlpsol("nmpc", "ipopt", self._nlp, self._options)

    def _bounds(self) -> tuple[np.ndarray, np.ndarray]:
        ocp = self.ocp
        lbx = np.full(self.n_var, -np.inf)
        ubx = np.full(self.n_var, np.inf)
        lbx[self.ix[1:]] = ocp.x_lower
        ubx[self.ix[1:]] = ocp.x_upper
        lbx[self.iu] = ocp.u_lower
        ubx[self.iu] = ocp.u_upper
        lbx[self.ie] = 0.0
        return lbx, ubx

    def pack(self, states: np.ndarray, inputs: np.ndarray) -> np.ndarray:
        w = np.zeros(self.n_var)
        w[self.ix] = states
        w[self.iu] = inputs
        return w  # slacks start at 0

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
        """Solve from x0 with the per-interval curvature and speed, warm-started from the guess (primal and, when
        given, the multipliers (lam_x, lam_g) of a previous solve); IPOPT iterates to convergence, first or not."""
        lbx, ubx = self._bounds()
        w0 = self.pack(guess_states, guess_inputs)
        w0[self.ix[0]] = x0
        args = {
            "x0": w0,
            "p": np.concatenate((x0, kappa, speed)),
            "lbx": lbx,
            "ubx": ubx,
            "lbg": self.lbg,
            "ubg": self.ubg,
        }
        if len(guess_dual) == 2:
            args["lam_x0"], args["lam_g0"] = guess_dual
        start = time.perf_counter()
        try:
            out = self.solver(**args)
        except RuntimeError:  # pragma: no cover - CasADi raises only on malformed input
            elapsed = time.perf_counter() - start
            return SolveResult(SolveStatus.ERROR, guess_states, guess_inputs, 0, elapsed)
        elapsed = time.perf_counter() - start
        stats = self.solver.stats()
        status = IPOPT_STATUS.get(str(stats.get("return_status", "")), SolveStatus.ERROR)
        w = np.asarray(out["x"]).ravel()
        states, inputs = w[self.ix], w[self.iu]
        objective = float(out["f"])
        if status.accepted and not (np.all(np.isfinite(w)) and np.isfinite(objective)):
            status = SolveStatus.NOT_FINITE
        dual = (np.asarray(out["lam_x"]).ravel(), np.asarray(out["lam_g"]).ravel())
        return SolveResult(status, states, inputs, int(stats.get("iter_count", 0)), elapsed, objective, dual)

    def shift_dual(self, dual: tuple[np.ndarray, ...], positions: np.ndarray) -> tuple[np.ndarray, ...]:
        """Multipliers of a previous solve moved to fractional stage `positions` (one per new stage, N+1 values):
        each block of per-stage entries is interpolated linearly between neighbouring stages."""
        if len(dual) != 2:
            return ()
        lam_x, lam_g = dual
        N, nx = self.ocp.N, self.ocp.nx
        new_x = lam_x.copy()
        new_x[self.ix] = interp_rows(lam_x[self.ix], positions)
        new_x[self.iu] = interp_rows(lam_x[self.iu], positions[:-1])
        new_g = lam_g.copy()
        eq = lam_g[: self.n_eq].reshape(N + 1, nx)
        new_g[: self.n_eq] = interp_rows(eq, positions).ravel()
        return new_x, new_g
