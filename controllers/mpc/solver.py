"""The one interface an MPC's solver offers its controller: the problem is described once (a `TrackingOCP`), the
solver built once from it, then solved every step (acados' split of description and solver).

`RtiSolver` (real-time iteration on OSQP), `IpoptSolver` (the full NLP) and `LtvSolver` (the LTV-MPC's QP) each
implement it, so `MPCController` steps any of them without knowing which.
"""

from __future__ import annotations

from typing import Protocol

import numpy as np

from controllers.mpc.status import SolveResult


class MPCSolver(Protocol):
    """What `MPCController` asks of its solver each step."""

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
        """Solve from state x0 along the path (curvature and speed per interval), warm-started from the guess
        (states (N+1, nx), inputs (N, nu), and the multipliers of a previous solve where the solver uses them);
        `first`: the first solve of a run, from a cold guess. Failures come back as the result's status."""
        ...

    def set_time_limit(self, seconds: float) -> None:
        """The wall-time budget of one solve (s; 0: none)."""
        ...

    def shift_dual(self, dual: tuple[np.ndarray, ...], positions: np.ndarray) -> tuple[np.ndarray, ...]:
        """A previous solve's multipliers moved to fractional stage `positions` (N+1 values); () when unused."""
        ...
