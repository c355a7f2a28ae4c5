"""The MPC solvers reach known optimal solutions: Riccati (scipy's DARE), a bounded least-squares solve of the
condensed problem (scipy's lsq_linear), an independently written CasADi Opti single-shooting problem."""

from __future__ import annotations

import casadi as ca
import numpy as np
import pytest
import scipy.linalg
import scipy.optimize
import scipy.signal

from controllers.mpc.lmpc import LtvSolver
from controllers.mpc.nlp_solver import IpoptSolver
from controllers.mpc.ocp import TrackingOCP, TrackingWeights
from controllers.mpc.prediction_model import PredictionModel, prediction_params_for
from controllers.mpc.rti import RtiSolver
from controllers.mpc.sparse_qp import OsqpSettings, SparseMPCQP
from controllers.mpc.status import SolveStatus

TIGHT = OsqpSettings(eps_abs=1e-10, eps_rel=1e-10, max_iter=100_000, polish=True)
N = 30


def _lqr(A: np.ndarray, B: np.ndarray, Q: np.ndarray, R: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    P = scipy.linalg.solve_discrete_are(A, B, Q, R)
    return P, np.linalg.solve(R + B.T @ P @ B, B.T @ P @ A)


SYSTEMS = {
    "double integrator with actuator lag": (
        np.array([[1.0, 0.4, 0.0], [0.0, 1.0, 0.3], [0.0, 0.0, 0.6]]),
        np.array([[0.0], [0.0], [0.4]]),
    ),
    "unstable": (np.array([[1.1, 0.2], [0.0, 0.95]]), np.array([[0.0], [0.1]])),
}


@pytest.mark.parametrize("system", sorted(SYSTEMS))
def test_sparse_qp_with_riccati_terminal_cost_is_the_lqr(system: str) -> None:
    """Unconstrained, with the DARE solution as terminal weight, the finite-horizon optimum is the infinite-horizon
    LQR: u_k = -K x_k all along, and the cost is x0' P x0."""
    A, B = SYSTEMS[system]
    nx = A.shape[0]
    Q, R = np.diag(np.linspace(10.0, 0.1, nx)), np.array([[0.5]])
    P, K = _lqr(A, B, Q, R)
    free = np.full(nx, np.inf)
    qp = SparseMPCQP(N, nx, 1, Q, R, P, -free, free, np.array([-1e3]), np.array([1e3]), settings=TIGHT)
    x0 = np.linspace(0.1, -0.05, nx)
    qp.update(x0, np.repeat(A[None], N, 0), np.repeat(B[None], N, 0), np.zeros((N, nx)))
    solution = qp.solve()
    assert solution.status == SolveStatus.SOLVED
    x, expected = x0.copy(), []
    for _ in range(N):
        expected.append(-K @ x)
        x = A @ x + B @ expected[-1]
    np.testing.assert_allclose(solution.inputs, np.array(expected), atol=1e-8)
    assert solution.objective == pytest.approx(float(x0 @ P @ x0), rel=1e-8)


def test_sparse_qp_with_active_bounds_matches_bounded_least_squares() -> None:
    """Time-varying dynamics with offsets and active input bounds against the condensed problem solved as a
    bounded linear least-squares problem (scipy.optimize.lsq_linear), an independent formulation and solver."""
    rng = np.random.default_rng(4)
    nx, nu = 3, 1
    A = np.array([np.eye(nx) + 0.1 * rng.normal(size=(nx, nx)) for _ in range(N)])
    B = rng.normal(size=(N, nx, nu))
    c = 0.05 * rng.normal(size=(N, nx))
    Q, R, QN = np.diag([4.0, 1.0, 0.5]), np.array([[0.2]]), np.diag([20.0, 5.0, 1.0])
    x0 = np.array([1.0, -0.5, 0.3])
    bound = 0.2
    free = np.full(nx, np.inf)
    qp = SparseMPCQP(N, nx, nu, Q, R, QN, -free, free, np.array([-bound]), np.array([bound]), settings=TIGHT)
    qp.update(x0, A, B, c)
    solution = qp.solve()
    assert solution.status == SolveStatus.SOLVED
    # condensed: x_k = phi_k + G_k u, with cost sum |Q^1/2 x_k|^2 + |R^1/2 u_k|^2
    phi, G = [x0], [np.zeros((nx, N * nu))]
    for k in range(N):
        g_next = A[k] @ G[-1]
        g_next[:, k * nu : (k + 1) * nu] += B[k]
        G.append(g_next)
        phi.append(A[k] @ phi[-1] + c[k])
    rows, rhs = [], []
    for k in range(1, N + 1):
        root = np.linalg.cholesky(QN if k == N else Q).T
        rows.append(root @ G[k])
        rhs.append(-root @ phi[k])
    rows.append(np.sqrt(R[0, 0]) * np.eye(N * nu))
    rhs.append(np.zeros(N * nu))
    reference = scipy.optimize.lsq_linear(np.vstack(rows), np.concatenate(rhs), bounds=(-bound, bound), tol=1e-12)
    assert np.sum(np.isclose(np.abs(reference.x), bound)) >= 2  # the bounds are active
    np.testing.assert_allclose(solution.inputs.ravel(), reference.x, atol=1e-6)
    np.testing.assert_allclose(solution.states[-1], phi[-1] + G[-1] @ reference.x, atol=1e-6)


def _linearise(F: ca.Function, nx: int, speed: float) -> tuple[np.ndarray, np.ndarray]:
    """Jacobians of a discrete model at the origin by central differences (independent of CasADi's AD)."""

    def f(x: np.ndarray, u: float) -> np.ndarray:
        return np.asarray(F(x, u, [0.0, speed])).ravel()

    eps = 1e-6
    A = np.column_stack([(f(e * eps, 0.0) - f(-e * eps, 0.0)) / (2 * eps) for e in np.eye(nx)])
    B = ((f(np.zeros(nx), eps) - f(np.zeros(nx), -eps)) / (2 * eps))[:, None]
    return A, B


@pytest.mark.parametrize("solver", ["ipopt", "rti"])
def test_nmpc_near_the_path_is_the_lqr_of_its_linearisation(solver: str) -> None:
    """A small offset on a straight: the nonlinear problem with the DARE terminal weight of its linearisation has
    the LQR as its optimum (to the size of the nonlinear terms, ~1e-6 relative here)."""
    model = PredictionModel(prediction_params_for("dynamic-bicycle"))
    speed = 8.0
    probe = TrackingOCP(model, N, 0.05, TrackingWeights())
    A, B = _linearise(probe.F, model.nx, speed)
    P, K = _lqr(A, B, probe.Q, probe.R)
    ocp = TrackingOCP(model, N, 0.05, TrackingWeights(), terminal_weight=P)
    x0 = np.zeros(model.nx)
    x0[model.i_cte], x0[model.i_heading] = 0.002, -0.001
    kappa, v = np.zeros(N), np.full(N, speed)
    guess = ocp.rollout(x0, np.zeros((N, 1)), kappa, v)
    if solver == "ipopt":
        result = IpoptSolver(ocp, tolerance=1e-12, max_solve_time_s=30.0).solve(x0, kappa, v, guess, np.zeros((N, 1)))
    else:
        result = RtiSolver(ocp, TIGHT, codegen=False).solve(x0, kappa, v, guess, np.zeros((N, 1)), iterations=20)
    assert result.accepted
    assert result.inputs[0, 0] == pytest.approx(float((-K @ x0)[0]), rel=1e-4)
    x, expected = x0.copy(), []
    for _ in range(N):
        expected.append(float((-K @ x)[0]))
        x = A @ x + B[:, 0] * expected[-1]
    np.testing.assert_allclose(result.inputs[:, 0], expected, atol=1e-4 * np.max(np.abs(expected)))


def _opti_reference(model: PredictionModel, ocp: TrackingOCP, x0, kappa, speed) -> np.ndarray:
    """The same optimal control problem written independently: CasADi Opti, single shooting, RK4 with eight
    sub-steps per interval on the model's ODE, bounds as constraints."""
    opti = ca.Opti()
    u = opti.variable(N)
    x = ca.DM(x0)
    cost = 0
    h = ocp.step_s / 8
    for k in range(N):
        cost += ca.bilin(ca.DM(ocp.Q), x, x) + ocp.R[0, 0] * u[k] ** 2
        p = ca.vertcat(kappa[k], speed[k])
        for _ in range(8):
            k1 = model.ode(x, u[k], p)
            k2 = model.ode(x + h / 2 * k1, u[k], p)
            k3 = model.ode(x + h / 2 * k2, u[k], p)
            k4 = model.ode(x + h * k3, u[k], p)
            x = x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        opti.subject_to(opti.bounded(ocp.x_lower[model.i_cmd], x[model.i_cmd], ocp.x_upper[model.i_cmd]))
    cost += ca.bilin(ca.DM(ocp.QN), x, x)
    opti.subject_to(opti.bounded(ocp.u_lower[0], u, ocp.u_upper[0]))
    opti.minimize(cost)
    opti.solver("ipopt", {"print_time": False}, {"print_level": 0, "sb": "yes", "tol": 1e-10})
    return np.asarray(opti.solve().value(u)).ravel()


def test_nmpc_solvers_agree_with_an_independent_formulation() -> None:
    """On a curve with an offset (steering-rate bounds active): IPOPT on the multiple-shooting NLP, the RTI's
    Gauss-Newton SQP iterated to convergence, and an Opti single-shooting problem give the same inputs."""
    model = PredictionModel(prediction_params_for("dynamic-bicycle"))
    ocp = TrackingOCP(model, N, 0.05, TrackingWeights())
    x0 = np.zeros(model.nx)
    x0[model.i_cte], x0[model.i_heading] = 0.4, 0.05
    kappa = np.concatenate((np.zeros(10), np.full(20, 1 / 30)))
    speed = np.full(N, 8.33)
    guess = ocp.rollout(x0, np.zeros((N, 1)), kappa, speed)
    ipopt = IpoptSolver(ocp, tolerance=1e-10, max_solve_time_s=30.0).solve(x0, kappa, speed, guess, np.zeros((N, 1)))
    rti = RtiSolver(ocp, TIGHT, codegen=True).solve(x0, kappa, speed, guess, np.zeros((N, 1)), iterations=50)
    reference = _opti_reference(model, ocp, x0, kappa, speed)
    assert ipopt.status == SolveStatus.SOLVED and rti.accepted
    rate_limit = ocp.u_upper[0]
    assert np.any(np.isclose(np.abs(reference), rate_limit, atol=1e-6))  # the rate bound is active
    np.testing.assert_allclose(rti.inputs[:, 0], ipopt.inputs[:, 0], atol=1e-6)
    np.testing.assert_allclose(ipopt.inputs[:, 0], reference, atol=2e-3 * rate_limit)
    assert rti.objective == pytest.approx(ipopt.objective, rel=1e-6)


def test_ltv_discretisation_is_autowares_bilinear_transform() -> None:
    """The LTV-MPC's discrete model at a curvature is scipy's bilinear (Tustin) discretisation of the model's
    continuous Jacobians at steady cornering, and those are the model's by central differences."""
    model = PredictionModel(prediction_params_for("kinematic-bicycle"), "kinematic")
    ocp = TrackingOCP(model, N, 0.05, TrackingWeights())
    solver = LtvSolver(ocp, codegen=False)
    kappa, speed = np.full(N, 0.02), np.full(N, 8.0)
    Ad, Bd, wd = solver.matrices(kappa, speed)
    x_ref = model.reference_states(kappa[:1], speed[:1])[0]
    p = [kappa[0], speed[0]]

    def f(x: np.ndarray, u: float) -> np.ndarray:
        return np.asarray(model.ode(x, u, p)).ravel()

    eps = 1e-6
    Ac = np.column_stack([(f(x_ref + e * eps, 0.0) - f(x_ref - e * eps, 0.0)) / (2 * eps) for e in np.eye(model.nx)])
    Bc = ((f(x_ref, eps) - f(x_ref, -eps)) / (2 * eps))[:, None]
    w = f(x_ref, 0.0) - Ac @ x_ref
    expected = scipy.signal.cont2discrete(
        (Ac, np.hstack((Bc, w[:, None])), np.eye(model.nx), np.zeros((model.nx, 2))), 0.05, method="bilinear"
    )
    np.testing.assert_allclose(Ad[0], expected[0], atol=1e-8)
    # scipy's bilinear B is (I - hA/2)^-1 B h scaled differently for the output equation: compare the input map
    lhs = np.eye(model.nx) - 0.025 * Ac
    np.testing.assert_allclose(Bd[0], np.linalg.solve(lhs, 0.05 * Bc), atol=1e-8)
    np.testing.assert_allclose(wd[0], np.linalg.solve(lhs, 0.05 * w), atol=1e-8)


def test_ltv_mpc_on_a_straight_is_the_lqr_of_its_model() -> None:
    model = PredictionModel(prediction_params_for("dynamic-bicycle"), "dynamic")
    probe = TrackingOCP(model, N, 0.05, TrackingWeights())
    kappa, speed = np.zeros(N), np.full(N, 10.0)
    A, B, w = LtvSolver(probe, codegen=False).matrices(kappa, speed)
    assert np.allclose(w, 0.0)
    P, K = _lqr(A[0], B[0], probe.Q, probe.R)
    ocp = TrackingOCP(model, N, 0.05, TrackingWeights(), terminal_weight=P)
    solver = LtvSolver(ocp, TIGHT, codegen=False)
    x0 = np.zeros(model.nx)
    x0[model.i_cte] = 0.05
    result = solver.solve(x0, kappa, speed, np.zeros((N + 1, model.nx)), np.zeros((N, 1)))
    # |u| stays below the rate bound here, so the QP is unconstrained
    assert np.max(np.abs(result.inputs)) < ocp.u_upper[0]
    assert result.inputs[0, 0] == pytest.approx(float((-K @ x0)[0]), rel=1e-6)


def test_non_finite_dynamics_give_a_reported_failure_not_nan_plans() -> None:
    A, B = SYSTEMS["unstable"]
    free = np.full(2, np.inf)
    qp = SparseMPCQP(N, 2, 1, np.eye(2), np.eye(1), np.eye(2), -free, free, np.array([-1.0]), np.array([1.0]))
    A_k = np.repeat(A[None], N, 0)
    A_k[3, 0, 0] = np.nan
    qp.update(np.array([0.1, 0.0]), A_k, np.repeat(B[None], N, 0), np.zeros((N, 2)))
    solution = qp.solve()
    assert not solution.status.accepted
    assert np.isfinite(solution.states).all() and np.isfinite(solution.inputs).all()
