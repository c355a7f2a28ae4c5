"""The MPCs' runs repeat bit for bit: OSQP adapts its step rho on the iteration count, never on the clock, so two
identical runs whose solves are never cut short by max_solve_time_s steer identically."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from controllers import CONTROLLERS, make_controller
from controllers.mpc.sparse_qp import ADAPTIVE_RHO_INTERVAL, ADAPTIVE_RHO_ITERATIONS, OsqpSettings
from workbench.simulation.conditions import CONDITIONS
from workbench.simulation.scenarios import ScenarioOptions, make_scenario
from workbench.simulation.simulator import Simulation, SimulationConfig
from workbench.vehicles import make_vehicle


def test_osqp_is_given_an_iteration_based_rho_adaptation() -> None:
    kwargs = OsqpSettings().as_kwargs()
    assert kwargs["adaptive_rho"] == ADAPTIVE_RHO_ITERATIONS == 1  # OSQP_ADAPTIVE_RHO_UPDATE_ITERATIONS
    assert kwargs["adaptive_rho_interval"] == ADAPTIVE_RHO_INTERVAL > 0  # 0 would leave the choice to OSQP


@pytest.mark.parametrize("name", ["lmpc", "nmpc"])
def test_the_solver_osqp_runs_adapts_on_iterations(name: str) -> None:
    vehicle = make_vehicle("dynamic-bicycle")
    controller = make_controller(name, vehicle.geometry, vehicle=vehicle)
    settings = controller.solver.qp.solver.settings
    assert settings.adaptive_rho == ADAPTIVE_RHO_ITERATIONS
    assert settings.adaptive_rho_interval == ADAPTIVE_RHO_INTERVAL


@pytest.mark.parametrize("name", ["lmpc", "nmpc"])
def test_two_identical_runs_steer_bit_for_bit_alike(name: str) -> None:
    """Under noisy conditions (the noise seeded) and with a budget no solve reaches."""
    traces = []
    for _ in range(2):
        vehicle = make_vehicle("dynamic-bicycle")
        config = dataclasses.replace(CONTROLLERS[name].config_type(), max_solve_time_s=10.0)
        controller = make_controller(name, vehicle.geometry, config, vehicle=vehicle)
        scenario = make_scenario("dlc", ScenarioOptions(vehicle.geometry.width_m))
        run = SimulationConfig(speed_kmh=40.0, conditions=CONDITIONS["automotive"], seed=3, max_time_s=8.0)
        result = Simulation(scenario, vehicle, controller, run).run()
        traces.append((result.trace["steer_wheel_cmd_rad"], result.trace["ctrl_solver_iterations"]))
    (steer_a, iterations_a), (steer_b, iterations_b) = traces
    assert steer_a.size > 300 and np.array_equal(steer_a, steer_b)
    assert np.array_equal(iterations_a, iterations_b)
