"""What a solve returns, and the status codes the MPCs log (as `ctrl_solver_status`) in the trace.

A solve that is not accepted (anything but SOLVED or SOLVED_INACCURATE) is never used: the controller falls back
to its previous plan, shifted to the current time, and says so in its diagnostics (`ctrl_fallback` = 1 and the
status code), so no failure is hidden.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import IntEnum

import numpy as np


class SolveStatus(IntEnum):
    """Outcome of one MPC solve; the integer is what the trace records."""

    SOLVED = 0  # converged to the requested tolerance
    SOLVED_INACCURATE = 1  # converged to a looser tolerance (accepted, flagged)
    MAX_ITERATIONS = 2  # iteration limit reached before convergence
    LATE = 3  # the solver's wall-time limit (max_solve_time_s) cut it short
    INFEASIBLE = 4  # the constraints cannot be met (e.g. inconsistent bounds)
    NUMERICAL_ERROR = 5  # NaN/Inf in the functions, failed step computation, restoration failure, QP data OSQP
    #                      cannot factorise (non-finite or huge: refused before the call, `sparse_qp.py`)
    NOT_FINITE = 6  # the solver claimed success but returned non-finite numbers
    ERROR = 7  # any other failure (the solver raised, unknown status)

    @property
    def accepted(self) -> bool:
        return self in (SolveStatus.SOLVED, SolveStatus.SOLVED_INACCURATE)


#: IPOPT return_status (CasADi stats) -> SolveStatus.
IPOPT_STATUS: dict[str, SolveStatus] = {
    "Solve_Succeeded": SolveStatus.SOLVED,
    "Solved_To_Acceptable_Level": SolveStatus.SOLVED_INACCURATE,
    "Feasible_Point_Found": SolveStatus.SOLVED_INACCURATE,
    "Maximum_Iterations_Exceeded": SolveStatus.MAX_ITERATIONS,
    "Maximum_CpuTime_Exceeded": SolveStatus.LATE,
    "Maximum_WallTime_Exceeded": SolveStatus.LATE,
    "Infeasible_Problem_Detected": SolveStatus.INFEASIBLE,
    "Not_Enough_Degrees_Of_Freedom": SolveStatus.INFEASIBLE,
    "Invalid_Problem_Definition": SolveStatus.INFEASIBLE,
    "Restoration_Failed": SolveStatus.NUMERICAL_ERROR,
    "Error_In_Step_Computation": SolveStatus.NUMERICAL_ERROR,
    "Invalid_Number_Detected": SolveStatus.NUMERICAL_ERROR,
    "Search_Direction_Becomes_Too_Small": SolveStatus.NUMERICAL_ERROR,
    "Diverging_Iterates": SolveStatus.NUMERICAL_ERROR,
}


def osqp_status(text: str) -> SolveStatus:
    """OSQP's status string (`info.status`, the same in OSQP 0.6 and 1.x) as a SolveStatus."""
    text = text.lower()
    if text == "solved":
        return SolveStatus.SOLVED
    if text == "solved inaccurate":
        return SolveStatus.SOLVED_INACCURATE
    if "infeasible" in text:
        return SolveStatus.INFEASIBLE
    if "maximum iterations" in text:
        return SolveStatus.MAX_ITERATIONS
    if "time limit" in text:
        return SolveStatus.LATE
    if "non convex" in text or "non-convex" in text:
        return SolveStatus.NUMERICAL_ERROR
    return SolveStatus.ERROR


@dataclass
class SolveResult:
    """One solve: status, the optimal (or last) trajectory, and what it cost.

    states: (N+1, nx); inputs: (N, nu); iterations: solver iterations (QP iterations for OSQP, SQP/IPOPT
    iterations otherwise); solve_time_s: wall time of the solver call as timed from Python; objective: optimal
    cost (NaN when unknown); dual: solver-specific multipliers kept for warm starts.
    """

    status: SolveStatus
    states: np.ndarray
    inputs: np.ndarray
    iterations: int
    solve_time_s: float
    objective: float = float("nan")
    dual: tuple[np.ndarray, ...] = ()

    @property
    def accepted(self) -> bool:
        return self.status.accepted
