"""Nonlinear MPC (CasADi): a nonlinear single-track prediction, path-following cost, real-time iteration on OSQP.

The baseline of the paper's section 6.6 / Figure 17 (an MPC lateral controller). The prediction model
(`prediction_model.py`) is a nonlinear dynamic bicycle with the steering angle as a state and its rate as the
input (or the paper's kinematic-with-lag model when an identified lag file is given); the cost penalises the
rear axle's cross-track and heading errors (Frenet errors) and the steering rate; steering angle and rate are
bounded and the lateral acceleration optionally (softly) limited (`ocp.py`). Built once, solved every step:
everything that changes per step (initial state, path curvature and speed along the horizon) is a parameter, and
each solve is warm-started from the previous plan shifted to the current time.

Two solvers:
  "rti"   (default) the real-time iteration: one Gauss-Newton QP per step on OSQP, the model's Jacobians
          compiled to C (`rti.py`, `codegen.py`); iterates to convergence on the first step only.
  "ipopt" the full NLP to convergence with IPOPT (expanded SX graphs, warm start of primal and dual variables),
          a converged reference that is slower (`nlp_solver.py`).
A failed or late solve is never used nor hidden: the controller replays its previous plan (`controller.py`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from controllers.config_checks import Choice, Flag, Number, Whole, option
from controllers.mpc.config import MPC_SEARCH_SPACE, MPCConfig
from controllers.mpc.controller import MPCController
from controllers.mpc.nlp_solver import IpoptSolver
from controllers.mpc.rti import RtiSolver
from controllers.mpc.sparse_qp import OsqpSettings
from controllers.search_space import Tunable

SOLVERS = ("rti", "ipopt")


@dataclass(frozen=True)
class NMPCConfig(MPCConfig):
    """The common MPC options (`MPCConfig`) and the NMPC's solver options; each field's unit, range and meaning are
    in its metadata (`config_checks.option`)."""

    solver: str = option(
        "rti",
        '"rti" (one SQP iteration per step on OSQP, real-time iteration) or "ipopt" (solved to convergence)',
        Choice(SOLVERS),
    )
    first_iterations: int = option(
        10,
        "SQP iterations of the RTI on its first step after a reset (no previous solution to linearise along)",
        Whole(1, 100, "iterations"),
    )
    max_iterations: int = option(100, "IPOPT's iteration limit", Whole(1, 10000, "iterations"))
    tolerance: float = option(1e-6, "IPOPT's convergence tolerance", Number(1e-12, 1e-1))
    exact_hessian: bool = option(
        False, "IPOPT with the exact Hessian of the Lagrangian instead of the Gauss-Newton one", Flag()
    )
    qp_tolerance: float = option(1e-3, "OSQP's absolute and relative tolerance (RTI)", Number(1e-10, 1e-1))
    qp_max_iterations: int = option(4000, "OSQP's iteration limit (RTI)", Whole(1, 10**6, "iterations"))

    def __post_init__(self) -> None:
        super().__post_init__()  # every field's rule, this class's included (`check_options`)


class NMPCController(MPCController[NMPCConfig]):
    """CasADi NMPC (module docstring). `vehicle` (optional): the vehicle model or its parameters to predict with;
    without it the config's `vehicle`/`vehicle_file` decide."""

    name: ClassVar[str] = "nmpc"
    config_type: ClassVar[type] = NMPCConfig
    search_space: ClassVar[tuple[Tunable, ...]] = MPC_SEARCH_SPACE

    def _build_solver(self) -> None:
        cfg = self.config
        budget = self._solve_budget_s()
        if cfg.solver == "ipopt":
            self.solver = IpoptSolver(
                self.ocp, cfg.max_iterations, cfg.tolerance, budget, cfg.exact_hessian, cfg.codegen
            )
        else:
            settings = OsqpSettings(
                eps_abs=cfg.qp_tolerance, eps_rel=cfg.qp_tolerance, max_iter=cfg.qp_max_iterations, time_limit_s=budget
            )
            self.solver = RtiSolver(self.ocp, settings, codegen=cfg.codegen, first_iterations=cfg.first_iterations)
