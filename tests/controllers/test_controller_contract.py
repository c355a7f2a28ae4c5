"""The contract every registered controller meets: finite, bounded commands in hard situations; an implausible
measurement holds the last command and says so (`controllers/base.py`); runs end to end."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from controllers import CONTROLLERS, make_controller
from controllers.base import Measurement
from tuning.own_tuning import tuned_controller
from workbench.base.clothoid_chain import ClothoidChain
from workbench.base.errors import WorkbenchInputError
from workbench.simulation.scenarios import ScenarioOptions, make_scenario
from workbench.simulation.simulator import Simulation, SimulationConfig
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
    # plausible but extreme: the controller sees them and must stay finite and bounded
    "at 140 m/s": _measure(5.0, 0.5, 0.0, 140.0),
    "10 m off the path facing backwards": _measure(5.0, 10.0, math.pi, 8.0),
    "a yaw of 1e300 rad": _measure(5.0, 0.5, 1e300, 8.0),
    "a yaw of -1e5 rad": _measure(5.0, 0.5, -1e5, 8.0),
    "far away (1e7 m)": _measure(1e7, -1e7, 0.3, 8.0),
    "spinning at 10 rad/s": Measurement(0.0, 5.0, 0.5, 8.0, 3.0, 0.0, 10.0, 0.0),
    "sliding sideways at 30 m/s": Measurement(0.0, 5.0, 0.5, 0.0, 30.0, 0.0, 0.0, 0.0),
    "reversing": _measure(5.0, 0.5, 0.0, -5.0),
}
#: The last plausible measurement before each implausible one (0.5 m left of the path, so the command is not 0).
BEFORE = _measure(5.0, 0.5, 0.0, 8.0, t=1.0)
#: Measurements outside the plausible envelope (`controllers/base.py`): each is refused, the last command held.
IMPLAUSIBLE = {
    "NaN yaw": dataclasses.replace(BEFORE, t_s=1.02, yaw_rad=math.nan),
    "inf yaw": dataclasses.replace(BEFORE, t_s=1.02, yaw_rad=math.inf),
    "NaN vx": dataclasses.replace(BEFORE, t_s=1.02, vx_mps=math.nan),
    "NaN vy": dataclasses.replace(BEFORE, t_s=1.02, vy_mps=math.nan),
    "NaN steering": dataclasses.replace(BEFORE, t_s=1.02, steer_wheel_rad=math.nan),
    "NaN yaw rate": dataclasses.replace(BEFORE, t_s=1.02, yaw_rate_rad_s=math.nan),
    "NaN time": dataclasses.replace(BEFORE, t_s=math.nan),
    "-inf x": dataclasses.replace(BEFORE, t_s=1.02, x_m=-math.inf),
    "steering 50 rad": dataclasses.replace(BEFORE, t_s=1.02, steer_wheel_rad=50.0),
    "position 1e300": dataclasses.replace(BEFORE, t_s=1.02, x_m=1e300, y_m=-1e300),
    "speed 1e3 m/s": dataclasses.replace(BEFORE, t_s=1.02, vx_mps=1e3),
    "yaw rate 100 rad/s": dataclasses.replace(BEFORE, t_s=1.02, yaw_rate_rad_s=100.0),
    "time going backwards": dataclasses.replace(BEFORE, t_s=0.98),
    "time 1e300 s": dataclasses.replace(BEFORE, t_s=1e300),
}


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("situation", sorted(SITUATIONS))
def test_command_is_finite_and_within_the_steering_limit(name: str, situation: str) -> None:
    vehicle = KinematicBicycle()
    controller = tuned_controller(name, vehicle)
    controller.reset(PATH, 0.02)
    command = controller.step(SITUATIONS[situation], PATH)
    assert math.isfinite(command)
    assert abs(command) <= vehicle.geometry.max_steer_wheel_angle_rad + 1e-12
    assert all(math.isfinite(v) for v in controller.diagnostics.values())
    assert controller.diagnostics["measurement_rejected"] == 0.0, controller.rejection
    assert controller.diagnostics["command_rejected"] == 0.0


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("situation", sorted(IMPLAUSIBLE))
def test_an_implausible_measurement_holds_the_last_command_and_says_so(name: str, situation: str) -> None:
    vehicle = KinematicBicycle()
    controller = tuned_controller(name, vehicle)
    controller.reset(PATH, 0.02)
    last = controller.step(BEFORE, PATH)
    assert last != 0.0 and controller.diagnostics["measurement_rejected"] == 0.0
    before = dict(controller.diagnostics)
    assert controller.step(IMPLAUSIBLE[situation], PATH) == last
    diagnostics = dict(controller.diagnostics)
    assert diagnostics.pop("measurement_rejected") == 1.0
    assert diagnostics.pop("command_rejected") == 0.0
    assert diagnostics == {k: v for k, v in before.items() if not k.endswith("_rejected")}  # the controller's own
    assert controller.rejection
    # the next plausible measurement is used again
    command = controller.step(dataclasses.replace(BEFORE, t_s=1.04), PATH)
    assert math.isfinite(command) and controller.diagnostics["measurement_rejected"] == 0.0
    # after a reset, before any command: 0 (and any time is the first)
    controller.reset(PATH, 0.02)
    if situation == "time going backwards":
        assert controller.step(IMPLAUSIBLE[situation], PATH) != 0.0
        return
    assert controller.step(IMPLAUSIBLE[situation], PATH) == 0.0
    assert controller.diagnostics["measurement_rejected"] == 1.0
    assert set(controller.diagnostics) == set(before)
    assert all(math.isfinite(v) for v in controller.diagnostics.values())


@pytest.mark.parametrize("name", NAMES)
def test_turns_toward_the_path(name: str) -> None:
    vehicle = KinematicBicycle()
    controller = tuned_controller(name, vehicle)
    controller.reset(PATH, 0.02)
    left_of_path = controller.step(_measure(5.0, 1.0, 0.0, 8.0), PATH)
    controller.reset(PATH, 0.02)
    right_of_path = controller.step(_measure(5.0, -1.0, 0.0, 8.0), PATH)
    assert left_of_path < 0 < right_of_path


@pytest.mark.parametrize("name", NAMES)
def test_completes_the_dlc_closely(name: str) -> None:
    vehicle = KinematicBicycle()
    scenario = make_scenario("dlc", ScenarioOptions(vehicle_width_m=vehicle.geometry.width_m))
    result = Simulation(scenario, vehicle, tuned_controller(name, vehicle), SimulationConfig()).run()
    assert result.completed, result.message
    assert result.metrics.max_abs_cte_m < 0.3
    assert np.isfinite(result.to_pandas().select_dtypes("number").to_numpy()).all()


def test_unknown_controller_names_the_choices() -> None:
    with pytest.raises(WorkbenchInputError, match=r"unknown controller 'mpc2'.*pure-pursuit"):
        make_controller("mpc2", KinematicBicycle().geometry)
