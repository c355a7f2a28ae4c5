"""A sparse MPC quadratic program on OSQP: built once, its matrices updated in place each step, warm-started.

Variables z = [u_0, x_1, u_1, x_2, ..., u_{N-1}, x_N, eps_1, ..., eps_N] (the slacks only when soft constraints
are on; x_0 = x_hat is known and not a variable). The problem is

    min  x_hat' Q x_hat + sum_{k<N} u_k' R u_k + sum_{0<k<N} x_k' Q x_k + x_N' Q_N x_N - 2 sum_k x_ref,k' Q_k x_k
         + sum_k (rho2 eps_k^2 + rho1 eps_k)
    s.t. x_1 = A_0 x_hat + B_0 u_0 + c_0,   x_{k+1} = A_k x_k + B_k u_k + c_k,
         u_lower <= u_k <= u_upper,   x_lower <= x_k <= x_upper (k >= 1, bounded states only),
         lo_k <= G_k x_k + eps_k,   G_k x_k - eps_k <= hi_k,   eps_k >= 0      (k = 1..N, soft constraints)

(OSQP's 1/2 z'Pz convention: P holds 2Q, 2R, 2 rho2.) The sparsity pattern is fixed when it is built, with A_k,
B_k and G_k stored as dense blocks, so each step only overwrites the values (OSQP `update(Ax=...)`, plus the
vectors l, u, q) and OSQP re-factors without a new symbolic analysis. The previous solution is the default warm
start; `solve` accepts a better one (the previous plan shifted to the current time).

The per-step calls go to the compiled solver that `osqp.OSQP` wraps (`OSQP._solver`, osqp 1.x): the wrapper's
`update` and `solve` spend about 60 us a step in Python (a module lookup for OSQP_INFTY on every update, an info
namespace built on every solve), a tenth of the LTV-MPC's whole step. Setup and settings go through the wrapper.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Any

import numpy as np
import osqp
import scipy.sparse as sp
from numba import njit

from controllers.mpc.status import SolveStatus, osqp_status

#: OSQP's infinity: bounds beyond it are treated as absent.
OSQP_INFINITY = float(osqp.constant("OSQP_INFTY"))
#: Largest |entry| of the constraint matrix handed to OSQP. Its LDL' factorisation of the KKT matrix loses the
#: quasi-definiteness it relies on in rounding when the dynamics blocks hold entries far beyond the O(1) weights and
#: penalty (measured: from about 1e15, when OSQP prints "ERROR in osqp_update_data_mat: new KKT matrix is not
#: quasidefinite" and its next solve fails); the plausible problems stay below 1e3 (speeds up to 150 m/s).
MAX_MATRIX_ENTRY = 1e9
#: Largest |value| of the vectors handed to OSQP (the dynamics rows' right sides, the linear cost, the soft bounds):
#: well inside OSQP_INFINITY, beyond which a bound silently counts as absent.
MAX_VECTOR_ENTRY = 1e20
#: OSQP's adaptive_rho mode that adapts the ADMM step rho every ADAPTIVE_RHO_INTERVAL iterations
#: (OSQP_ADAPTIVE_RHO_UPDATE_ITERATIONS). Its other automatic rule adapts when the iterations have taken a fraction
#: of the setup's wall time (osqp 0.6's adaptive_rho_interval = 0; osqp 1.x's mode 2): a rule on the clock makes
#: two identical solves differ on a loaded machine. On the iteration count, the same run gives the same result bit
#: for bit, as long as no solve is cut short by its time limit (`max_solve_time_s`).
ADAPTIVE_RHO_ITERATIONS = 1
#: Iterations between two adaptations of rho: osqp 1.x's default interval, set here so that no version's default
#: can move it, and so that every run is the same as with that default.
ADAPTIVE_RHO_INTERVAL = 50


@dataclass(frozen=True)
class OsqpSettings:
    """eps_abs, eps_rel: OSQP's tolerances; max_iter: ADMM iteration limit; time_limit_s: wall-time limit (0: none);
    polish: refine the active set after ADMM (more accurate, a little slower); check_termination: iterations
    between convergence checks; scaling: OSQP's Ruiz equilibration passes (rho adapts on the iteration count,
    ADAPTIVE_RHO_INTERVAL, never on the clock). Scaling is off by default: OSQP re-runs the
    equilibration on every matrix update, which took 3/4 of the update (130 of 170 us at N = 30, nx = 6), while
    these well-scaled MPC problems converged in as few or fewer ADMM iterations without it."""

    eps_abs: float = 1e-5
    eps_rel: float = 1e-5
    max_iter: int = 4000
    time_limit_s: float = 0.0
    polish: bool = False
    check_termination: int = 5
    scaling: int = 0

    def as_kwargs(self) -> dict:
        out = {
            "eps_abs": self.eps_abs,
            "eps_rel": self.eps_rel,
            "max_iter": self.max_iter,
            "verbose": False,
            "check_termination": self.check_termination,
            "scaling": self.scaling,
            "adaptive_rho": ADAPTIVE_RHO_ITERATIONS,
            "adaptive_rho_interval": ADAPTIVE_RHO_INTERVAL,
        }
        out.update(polishing=self.polish, warm_starting=True)  # OSQP >= 1.0 names
        if self.time_limit_s > 0.0:
            out["time_limit"] = self.time_limit_s
        return out


@dataclass
class QPSolution:
    status: SolveStatus
    states: np.ndarray  # (N+1, nx)
    inputs: np.ndarray  # (N, nu)
    slacks: np.ndarray  # (N,) or (0,)
    iterations: int
    solve_time_s: float
    objective: float
    z: np.ndarray
    y: np.ndarray


class SparseMPCQP:
    """The QP above for fixed N, nx, nu, weights and bounds."""

    def __init__(
        self,
        horizon_steps: int,
        nx: int,
        nu: int,
        Q: np.ndarray,
        R: np.ndarray,
        QN: np.ndarray,
        x_lower: np.ndarray,
        x_upper: np.ndarray,
        u_lower: np.ndarray,
        u_upper: np.ndarray,
        soft: bool = False,
        soft_weights: tuple[float, float] = (0.0, 0.0),
        settings: OsqpSettings | None = None,
    ) -> None:
        N = horizon_steps
        self.N, self.nx, self.nu, self.soft = N, nx, nu, soft
        self.settings = settings or OsqpSettings()
        stage = nx + nu
        ns = N if soft else 0
        self.n = N * stage + ns
        self.iu = np.array([[k * stage + i for i in range(nu)] for k in range(N)])
        self.ix = np.array([[k * stage + nu + i for i in range(nx)] for k in range(N)])  # nodes 1..N
        self.ie = N * stage + np.arange(ns)
        self.Q, self.QN = np.asarray(Q, float), np.asarray(QN, float)
        self.x_lower, self.x_upper = np.asarray(x_lower, float).copy(), np.asarray(x_upper, float).copy()
        self.u_lower, self.u_upper = np.asarray(u_lower, float).copy(), np.asarray(u_upper, float).copy()
        self.x0 = np.zeros(nx)
        self._x0_cost = 0.0

        # ---- cost
        blocks = []
        for k in range(N):
            blocks += [2.0 * np.asarray(R, float), 2.0 * (self.QN if k == N - 1 else self.Q)]
        if soft:
            blocks.append(2.0 * soft_weights[0] * np.eye(ns))
        P = sp.triu(sp.block_diag(blocks, format="csc"), format="csc")
        self.q = np.zeros(self.n)
        if soft:
            self.q[self.ie] = soft_weights[1]

        # ---- constraints, in COO with an id per entry so that blocks can be updated in CSC order
        rows: list[np.ndarray] = []
        cols: list[np.ndarray] = []
        vals: list[np.ndarray] = []
        count = [0]

        def add(r: np.ndarray, c: np.ndarray, v: np.ndarray) -> slice:
            r, c, v = np.ravel(r), np.ravel(c), np.ravel(v).astype(float)
            rows.append(r)
            cols.append(c)
            vals.append(v)
            start = count[0]
            count[0] += r.size
            return slice(start, count[0])

        eye_x = np.arange(nx)
        # dynamics rows r = k nx + i: x_{k+1} - A_k x_k - B_k u_k = c_k (no A block for k = 0: x_0 is known)
        self._a_slices, self._b_slices = [], []
        ii, jj = np.meshgrid(eye_x, np.arange(nx), indexing="ij")
        iu_, ju_ = np.meshgrid(eye_x, np.arange(nu), indexing="ij")
        for k in range(N):
            base = k * nx
            add(base + eye_x, self.ix[k], np.ones(nx))
            if k > 0:
                self._a_slices.append(add(base + ii, self.ix[k - 1][jj], np.zeros(ii.shape)))
            self._b_slices.append(add(base + iu_, self.iu[k][ju_], np.zeros(iu_.shape)))
        row = N * nx
        self.n_eq = row
        # input bounds
        add(row + np.arange(N * nu), self.iu.ravel(), np.ones(N * nu))
        self._u_rows = slice(row, row + N * nu)
        row += N * nu
        # state bounds on nodes 1..N
        self.bounded = np.flatnonzero(np.isfinite(self.x_lower) | np.isfinite(self.x_upper))
        nb = self.bounded.size
        add(row + np.arange(N * nb), self.ix[:, self.bounded].ravel(), np.ones(N * nb))
        self._x_rows = slice(row, row + N * nb)
        row += N * nb
        # soft constraints on nodes 1..N
        self._g_slices = []
        if soft:
            self._soft_hi = row + 2 * np.arange(N)
            self._soft_lo = self._soft_hi + 1
            for k in range(N):
                r_hi, r_lo = row + 2 * k, row + 2 * k + 1
                g_hi = add(np.full(nx, r_hi), self.ix[k], np.zeros(nx))
                g_lo = add(np.full(nx, r_lo), self.ix[k], np.zeros(nx))
                self._g_slices.append((g_hi, g_lo))
                add(np.array([r_hi, r_lo]), np.array([self.ie[k], self.ie[k]]), np.array([-1.0, 1.0]))
            row += 2 * N
            add(row + np.arange(N), self.ie, np.ones(N))
            self._eps_rows = slice(row, row + N)
            row += N
        self.m = row
        r_all, c_all, v_all = np.concatenate(rows), np.concatenate(cols), np.concatenate(vals)
        ids = sp.csc_matrix((np.arange(1, r_all.size + 1, dtype=float), (r_all, c_all)), shape=(self.m, self.n))
        ids.sort_indices()
        order = ids.data.astype(int) - 1  # CSC position p holds entry id order[p]
        a_idx = np.array([np.arange(sl.start, sl.stop).reshape(nx, nx) for sl in self._a_slices]).reshape(N - 1, nx, nx)
        b_idx = np.array([np.arange(sl.start, sl.stop).reshape(nx, nu) for sl in self._b_slices])
        if soft:
            g_idx = np.array(
                [[np.arange(hi.start, hi.stop), np.arange(lo.start, lo.stop)] for hi, lo in self._g_slices]
            )
        # Where each updated entry sits in the CSC data array, so that a step writes there directly.
        position = np.empty_like(order)
        position[order] = np.arange(order.size)
        self._a_pos, self._b_pos = position[a_idx], position[b_idx]
        if soft:
            self._g_pos = position[g_idx]
        self._csc_values = v_all[order]
        A = sp.csc_matrix((self._csc_values.copy(), ids.indices.copy(), ids.indptr.copy()), shape=(self.m, self.n))

        self.lower = np.zeros(self.m)
        self.upper = np.zeros(self.m)
        self._set_box_bounds()
        if soft:
            self.lower[self._soft_hi], self.upper[self._soft_hi] = -OSQP_INFINITY, 0.0
            self.lower[self._soft_lo], self.upper[self._soft_lo] = 0.0, OSQP_INFINITY
            self.lower[self._eps_rows], self.upper[self._eps_rows] = 0.0, OSQP_INFINITY
        self._P = P
        self.solver = osqp.OSQP()
        self.solver.setup(
            P=P, q=self.q.copy(), A=A, l=self.lower.copy(), u=self.upper.copy(), **self.settings.as_kwargs()
        )
        self._native: Any = getattr(self.solver, "_solver", None)  # osqp 1.x's own object (checked below)
        #: Whether the last `update` held data OSQP cannot use (then `solve` reports NUMERICAL_ERROR).
        self.refused = False
        if not all(hasattr(self._native, name) for name in ("update_data_vec", "update_data_mat", "solve", "info")):
            raise RuntimeError(
                f"osqp {osqp.__version__} is not supported: the MPC needs osqp >= 1.0, < 2 (pip install 'osqp>=1,<2')"
            )

    def set_time_limit(self, seconds: float) -> None:
        """OSQP's wall-time limit (s; 0: none)."""
        self.solver.update_settings(time_limit=float(seconds))

    def _set_box_bounds(self) -> None:
        """Box bounds into l and u, infinite ones as OSQP's infinity (as its wrapper would on every update)."""
        N = self.N
        self.lower[self._u_rows] = np.tile(self.u_lower, N)
        self.upper[self._u_rows] = np.tile(self.u_upper, N)
        self.lower[self._x_rows] = np.tile(self.x_lower[self.bounded], N)
        self.upper[self._x_rows] = np.tile(self.x_upper[self.bounded], N)
        np.clip(self.lower, -OSQP_INFINITY, OSQP_INFINITY, out=self.lower)
        np.clip(self.upper, -OSQP_INFINITY, OSQP_INFINITY, out=self.upper)

    def set_bounds(self, x_lower: np.ndarray, x_upper: np.ndarray, u_lower: np.ndarray, u_upper: np.ndarray) -> None:
        """New box bounds (same bounded states as at construction; +-inf elsewhere is ignored)."""
        self.x_lower[:], self.x_upper[:] = x_lower, x_upper
        self.u_lower[:], self.u_upper[:] = u_lower, u_upper
        self._set_box_bounds()

    # ------------------------------------------------------------------ per step
    def update(
        self,
        x0: np.ndarray,
        A: np.ndarray,
        B: np.ndarray,
        c: np.ndarray,
        G: np.ndarray | None = None,
        soft_lo: np.ndarray | None = None,
        soft_hi: np.ndarray | None = None,
        x_ref: np.ndarray | None = None,
    ) -> None:
        """Dynamics blocks A (N, nx, nx), B (N, nx, nu), c (N, nx); initial state; soft-constraint rows G (N, nx)
        with bounds soft_lo, soft_hi (N,); state references x_ref (N+1, nx) for the linear cost term.

        Data OSQP cannot use (non-finite, or beyond MAX_MATRIX_ENTRY / MAX_VECTOR_ENTRY) is not handed to it: the
        next `solve` then reports NUMERICAL_ERROR without calling OSQP, whose C code would print its failure to
        the console instead. OSQP keeps the last data it accepted, and the next good update overwrites every
        block this one wrote."""
        vals = self._csc_values
        self.x0 = np.array(x0, dtype=float)
        self._x0_cost = _quadratic_form(self.Q, self.x0)  # x_0' Q x_0: the cost's constant term
        _write_dynamics(vals, self._a_pos, self._b_pos, A, B, c, self.x0, self.lower, self.upper)
        if self.soft and G is not None:
            vals[self._g_pos] = G[:, None, :]
            self.lower[self._soft_lo] = soft_lo
            self.upper[self._soft_hi] = soft_hi
        q = None
        if x_ref is not None:
            q = self.q.copy()
            q[self.ix[:-1]] = -2.0 * x_ref[1:-1] @ self.Q
            q[self.ix[-1]] = -2.0 * x_ref[-1] @ self.QN
        self.refused = not (
            _bounded(vals, MAX_MATRIX_ENTRY)
            and _bounded(self.lower[: self.n_eq], MAX_VECTOR_ENTRY)  # the dynamics rows: l = u = their right side
            and _bounded(self.lower, OSQP_INFINITY)
            and _bounded(self.upper, OSQP_INFINITY)
            and (q is None or _bounded(q, MAX_VECTOR_ENTRY))
            and np.isfinite(self._x0_cost)
        )
        if self.refused:
            return
        self._native.update_data_vec(q=q, l=self.lower, u=self.upper)
        self._native.update_data_mat(P_x=None, P_i=None, A_x=vals, A_i=None)

    def pack(self, states: np.ndarray, inputs: np.ndarray, slacks: np.ndarray | None = None) -> np.ndarray:
        """z from states (N+1, nx; node 0 is not a variable), inputs (N, nu) and slacks (N,)."""
        z = np.zeros(self.n)
        z[self.ix] = states[1:]
        z[self.iu] = inputs
        if self.soft and slacks is not None:
            z[self.ie] = slacks
        return z

    def solve(self, warm_start: np.ndarray | None = None) -> QPSolution:
        """Solve; warm_start (z) replaces the primal part of OSQP's own warm start (its previous solution)."""
        native = self._native
        if self.refused:  # `update` kept data OSQP cannot use from it
            z = np.zeros(self.n)
            states, inputs, _ = _unpack(z, self.x0, self.N, self.u_lower, self.u_upper)
            return QPSolution(
                SolveStatus.NUMERICAL_ERROR, states, inputs, z[self.ie], 0, 0.0, math.nan, z, np.zeros(self.m)
            )
        if warm_start is not None and _bounded(warm_start, MAX_VECTOR_ENTRY):
            native.warm_start(warm_start, None)
        start = time.perf_counter()
        native.solve()
        elapsed = time.perf_counter() - start
        info, solution = native.info, native.solution
        status = osqp_status(info.status)
        z = solution.x
        states, inputs, finite = _unpack(z, self.x0, self.N, self.u_lower, self.u_upper)
        if not finite:
            status = SolveStatus.NOT_FINITE if status.accepted else status
            z = np.zeros(self.n)
            states, inputs, _ = _unpack(z, self.x0, self.N, self.u_lower, self.u_upper)
        objective = float(info.obj_val) + self._x0_cost
        return QPSolution(status, states, inputs, z[self.ie], int(info.iter), elapsed, objective, z, solution.y)


# ---------------------------------------------------------------------------------------------- compiled kernels
# The per-step array work around OSQP's calls: a dozen small numpy operations each, which cost 20-30 us a step
# (far more inside the control loop than in isolation), against a few us as one compiled call.


@njit(cache=True)
def _write_dynamics(
    values: np.ndarray,
    a_pos: np.ndarray,
    b_pos: np.ndarray,
    A: np.ndarray,
    B: np.ndarray,
    c: np.ndarray,
    x0: np.ndarray,
    lower: np.ndarray,
    upper: np.ndarray,
) -> None:  # pragma: no cover - compiled
    """values[a_pos] = -A[1:] and values[b_pos] = -B (CSC positions of the dynamics blocks); the equality rows'
    bounds (the first N nx rows of l and u) = c_k, plus A_0 x0 for k = 0 (x_0 is not a variable)."""
    N, nx, nu = B.shape
    for k in range(N):
        for i in range(nx):
            for j in range(nu):
                values[b_pos[k, i, j]] = -B[k, i, j]
            rhs = c[k, i]
            if k == 0:
                for j in range(nx):
                    rhs += A[0, i, j] * x0[j]
            else:
                for j in range(nx):
                    values[a_pos[k - 1, i, j]] = -A[k, i, j]
            lower[k * nx + i] = rhs
            upper[k * nx + i] = rhs


@njit(cache=True)
def _unpack(
    z: np.ndarray, x0: np.ndarray, N: int, u_lower: np.ndarray, u_upper: np.ndarray
) -> tuple[np.ndarray, np.ndarray, bool]:  # pragma: no cover - compiled
    """States (N+1, nx; node 0 = x0) and inputs (N, nu) from z = [u_0, x_1, ..., u_{N-1}, x_N, ...], and whether
    all of z is finite. OSQP meets bounds to its tolerance only; the inputs are projected so that the plan never
    asks for more than the actuator's rate (the state bounds are enforced where the command is saturated)."""
    finite = np.isfinite(z).all()
    nx, nu = x0.shape[0], u_lower.shape[0]
    states = np.empty((N + 1, nx))
    inputs = np.empty((N, nu))
    states[0] = x0
    for k in range(N):
        base = k * (nu + nx)
        for j in range(nu):
            inputs[k, j] = min(max(z[base + j], u_lower[j]), u_upper[j])
        for i in range(nx):
            states[k + 1, i] = z[base + nu + i]
    return states, inputs, finite


@njit(cache=True)
def _bounded(values: np.ndarray, limit: float) -> bool:  # pragma: no cover - compiled
    """Whether every entry of the 1-D array is finite and within +-limit."""
    for v in values:
        if not abs(v) <= limit:  # NaN fails too
            return False
    return True


@njit(cache=True)
def _quadratic_form(Q: np.ndarray, x: np.ndarray) -> float:  # pragma: no cover - compiled
    """x' Q x (numpy's @ would call BLAS for these few numbers)."""
    total = 0.0
    for i in range(x.shape[0]):
        for j in range(x.shape[0]):
            total += x[i] * Q[i, j] * x[j]
    return total
