"""The contract every registered controller meets: finite, bounded commands in hard situations; runs end to end."""

from __future__ import annotations

import math

import numpy as np
import pytest

from controllers import CONTROLLERS, make_controller
from controllers.base import Measurement
from workbench.clothoid_chain import ClothoidChain
from workbench.errors import WorkbenchInputError
from workbench.scenarios import make_scenario
from workbench.simulator import Simulation, SimulationConfig
from workbench.vehicles import KinematicBicycle

NAMES = sorted(CONTROLLERS)
PATH = (
    ClothoidChain()
    .straight(30.0)
    .clothoid_to(1 / 25, 15.0)
    .arc(30.0)
    .clothoid_to(0.0, 15.0)
    .straight(30.0)
    .to_path("p")
)


def _measure(x: float, y: float, yaw: float, speed: float, t: float = 0.0) -> Measurement:
    return Measurement(t, x, y, speed, 0.0, yaw, 0.0, 0.0)


SITUATIONS = {
    "on the path": _measure(0.0, 0.0, 0.0, 8.0),
    "10 m off the path": _measure(5.0, 10.0, 0.0, 8.0),
    "turned 90 deg away": _measure(5.0, 0.0, math.pi / 2, 8.0),
    "facing backwards": _measure(5.0, 0.0, math.pi, 8.0),
    "standing still": _measure(5.0, 0.5, 0.1, 0.0),
    "at the end of the path": _measure(float(PATH.x_m[-1]), float(PATH.y_m[-1]), float(PATH.heading_rad[-1]), 8.0),
    "past the end of the path": _measure(float(PATH.x_m[-1]) + 3.0, float(PATH.y_m[-1]), 0.0, 8.0),
}


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("situation", sorted(SITUATIONS))
def test_command_is_finite_and_within_the_steering_limit(name: str, situation: str) -> None:
    vehicle = KinematicBicycle()
    controller = make_controller(name, vehicle.geometry, vehicle=vehicle)
    controller.reset(PATH, 0.02)
    command = controller.step(SITUATIONS[situation], PATH)
    assert math.isfinite(command)
    assert abs(command) <= vehicle.geometry.max_steer_wheel_angle_rad + 1e-12
    assert all(math.isfinite(v) for v in controller.diagnostics.values())


@pytest.mark.parametrize("name", NAMES)
def test_turns_toward_the_path(name: str) -> None:
    vehicle = KinematicBicycle()
    controller = make_controller(name, vehicle.geometry, vehicle=vehicle)
    controller.reset(PATH, 0.02)
    left_of_path = controller.step(_measure(5.0, 1.0, 0.0, 8.0), PATH)
    controller.reset(PATH, 0.02)
    right_of_path = controller.step(_measure(5.0, -1.0, 0.0, 8.0), PATH)
    assert left_of_path < 0 < right_of_path


@pytest.mark.parametrize("name", NAMES)
def test_completes_the_dlc_closely(name: str) -> None:
    vehicle = KinematicBicycle()
    scenario = make_scenario("dlc")
    result = Simulation(
        scenario, vehicle, make_controller(name, vehicle.geometry, vehicle=vehicle), SimulationConfig()
    ).run()
    assert result.completed, result.message
    assert result.metrics.max_abs_cte_m < 0.3
    assert np.isfinite(result.to_pandas().select_dtypes("number").to_numpy()).all()


def test_unknown_controller_names_the_choices() -> None:
    with pytest.raises(WorkbenchInputError, match=r"unknown controller 'mpc2'.*pure-pursuit"):
        make_controller("mpc2", KinematicBicycle().geometry)
