"""QP data OSQP cannot use (non-finite, or so large that its KKT factorisation fails in rounding) is never handed
to it: the solve comes back as NUMERICAL_ERROR, OSQP's C code prints nothing, and the next good solve works."""

from __future__ import annotations

import math

import numpy as np
import pytest

from controllers.mpc import LMPCConfig, LMPCController, NMPCConfig, NMPCController, SolveStatus
from controllers.mpc.sparse_qp import MAX_MATRIX_ENTRY
from workbench.vehicles import make_vehicle

VARIANTS = {
    "nmpc-rti": (NMPCController, NMPCConfig(max_solve_time_s=0.5)),
    "lmpc": (LMPCController, LMPCConfig(max_solve_time_s=0.5)),
}


def _solve(controller, speed_mps: float):
    ocp = controller.ocp
    kappa, speed = np.full(ocp.N, 0.04), np.full(ocp.N, speed_mps)
    guess_states, guess_inputs = np.zeros((ocp.N + 1, ocp.nx)), np.zeros((ocp.N, ocp.nu))
    return controller.solver.solve(np.zeros(ocp.nx), kappa, speed, guess_states, guess_inputs, (), True)


@pytest.mark.parametrize("vehicle_name", ["kinematic-bicycle", "dynamic-bicycle"])
@pytest.mark.parametrize("variant", sorted(VARIANTS))
@pytest.mark.parametrize("speed_mps", [math.nan, math.inf, 1e300, 1e20, 1e10, 1e7])
def test_data_osqp_cannot_use_is_a_reported_failure(
    variant: str, vehicle_name: str, speed_mps: float, capfd: pytest.CaptureFixture
) -> None:
    cls, config = VARIANTS[variant]
    controller = cls(make_vehicle(vehicle_name).geometry, config)
    result = _solve(controller, speed_mps)
    out, err = capfd.readouterr()
    assert out + err == ""  # before the guard: "ERROR in osqp_update_data_mat: new KKT matrix is not quasidefinite"
    assert math.isfinite(result.states[1:].sum()) or not result.accepted
    if controller.solver.qp.refused:
        assert result.status is SolveStatus.NUMERICAL_ERROR and result.iterations == 0
    assert _solve(controller, 10.0).status.accepted  # OSQP kept its last good data
    assert capfd.readouterr() == ("", "")


def test_the_guard_leaves_plausible_problems_alone() -> None:
    """At the envelope's 150 m/s the dynamics blocks stay far below the guard's limit."""
    for cls, config in VARIANTS.values():
        controller = cls(make_vehicle("dynamic-bicycle").geometry, config)
        result = _solve(controller, 150.0)
        assert not controller.solver.qp.refused
        assert result.status is not SolveStatus.NUMERICAL_ERROR
        assert np.abs(controller.solver.qp._csc_values).max() < MAX_MATRIX_ENTRY * 1e-5


@pytest.mark.parametrize("variant", [*sorted(VARIANTS), "nmpc-ipopt"])
def test_every_mpc_solver_offers_the_one_solver_interface(variant: str) -> None:
    """MPCController steps its solver through `MPCSolver` only (no isinstance branches on the solver kind)."""
    from controllers.mpc.solver import MPCSolver

    cls, config = VARIANTS.get(variant, (NMPCController, NMPCConfig(solver="ipopt", max_solve_time_s=0.5)))
    solver = cls(make_vehicle("kinematic-bicycle").geometry, config).solver
    for name in ("solve", "set_time_limit", "shift_dual"):
        assert callable(getattr(solver, name, None)), name
    assert all(hasattr(solver, name) for name in MPCSolver.__dict__ if not name.startswith("_"))
