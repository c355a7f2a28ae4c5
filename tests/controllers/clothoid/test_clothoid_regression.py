"""Regression of the clothoid controller on every vehicle model (issue 15): a tight corner (radius 15 m) followed by a
150 m straight, and the ISO double lane change, each at 30 km/h asked.

On each run the controller, with the vehicle's own tuning (`tuned_controller(name, vehicle, config)`):
  - completes the run and tracks (max |CTE| under MAX_ABS_CTE_M, a generous bound: the reference controllers stay
    well under 0.1 m on both courses);
  - does not limit-cycle (`workbench.simulation.limit_cycle.detect_limit_cycle` on the steering wheel, the metric
    `limit_cycle`);
  - steers no more restlessly than a reference controller on the same run: the steering oscillation
    (`steer_oscillation_deg`, the RMS of the steering wheel about its 1 s moving average) at most
    OSCILLATION_RATIO x the reference's, or OSCILLATION_FLOOR_DEG, whichever is larger.

The reference is the NMPC (the issue's), with a relaxed solve-time budget so that a loaded machine does not drop
solves. On the CommonRoad multi-body car the plant dominates the run time (about 6x real time), so the NMPC costs
little more than Stanley there (about 11 against 9 s for both courses, measured): it is the reference on every
vehicle.
"""

from __future__ import annotations

import functools
import math

import pytest

from controllers.mpc import NMPCConfig
from tuning.own_tuning import tuned_controller
from workbench.base.clothoid_chain import ClothoidChain
from workbench.simulation.metrics import Metrics
from workbench.simulation.scenarios import Scenario, ScenarioOptions, make_scenario
from workbench.simulation.simulator import Simulation, SimulationConfig
from workbench.vehicles import make_vehicle

VEHICLES = ("kinematic-bicycle", "dynamic-bicycle", "tractor-semitrailer", "commonroad-mb")
SCENARIOS = ("corner", "dlc")
#: The reference controller of each vehicle, and its options.
REFERENCE = {name: "nmpc" for name in VEHICLES}
REFERENCE_CONFIG = {"nmpc": NMPCConfig(max_solve_time_s=0.5)}
SPEED_KMH = 30.0
MAX_ABS_CTE_M = 0.5
OSCILLATION_RATIO = 1.5
OSCILLATION_FLOOR_DEG = 3.0
#: The corner course: run-in, clothoid into the arc, 90 degrees of arc, clothoid out, straight (m, 1/m).
RUN_IN_M, TRANSITION_M, RADIUS_M, RUN_OUT_M = 40.0, 10.0, 15.0, 150.0


def corner_course() -> Scenario:
    """A tight left corner between straights, curvature-continuous (`ClothoidChain`): 40 m straight, 10 m clothoid
    to radius 15 m, 90 degrees of arc (23.6 m), 10 m clothoid back to straight, 150 m straight (the transitions
    turn 19 degrees each, 128 in all). The speed profile (0.3 g) slows the vehicle to 24 km/h in the arc."""
    kappa = 1.0 / RADIUS_M
    chain = (
        ClothoidChain()
        .straight(RUN_IN_M)
        .clothoid_to(kappa, TRANSITION_M)
        .arc(RADIUS_M * math.pi / 2)
        .clothoid_to(0.0, TRANSITION_M)
        .straight(RUN_OUT_M)
    )
    return Scenario(
        "corner", chain.to_path("corner"), "tight corner (radius 15 m, 90 degrees of arc) then a 150 m straight"
    )


def _scenario(name: str, vehicle_name: str) -> Scenario:
    if name == "corner":
        return corner_course()
    width = make_vehicle(vehicle_name).geometry.width_m
    return make_scenario(name, ScenarioOptions(vehicle_width_m=width))


@functools.cache
def _run(vehicle_name: str, scenario_name: str, controller_name: str) -> Metrics:
    """The metrics of one run (each run once per session: the clothoid's and the reference's serve several tests)."""
    vehicle = make_vehicle(vehicle_name)
    config = REFERENCE_CONFIG.get(controller_name)
    controller = tuned_controller(controller_name, vehicle, config)
    result = Simulation(
        _scenario(scenario_name, vehicle_name), vehicle, controller, SimulationConfig(speed_kmh=SPEED_KMH)
    ).run()
    return result.metrics


CASES = [pytest.param(v, s, id=f"{v}-{s}") for v in VEHICLES for s in SCENARIOS]


@pytest.mark.parametrize(("vehicle_name", "scenario_name"), CASES)
def test_clothoid_completes_and_tracks(vehicle_name: str, scenario_name: str) -> None:
    m = _run(vehicle_name, scenario_name, "clothoid")
    assert m.completed, f"the run stopped at {m.distance_m:.0f} of {m.path_length_m:.0f} m"
    assert m.max_abs_cte_m < MAX_ABS_CTE_M, f"max |CTE| {m.max_abs_cte_m:.3f} m"


@pytest.mark.parametrize(("vehicle_name", "scenario_name"), CASES)
def test_clothoid_has_no_limit_cycle(vehicle_name: str, scenario_name: str) -> None:
    m = _run(vehicle_name, scenario_name, "clothoid")
    assert not m.limit_cycle, (
        f"steering limit cycle at {m.limit_cycle_hz:.2f} Hz, +-{m.limit_cycle_amplitude_deg:.0f} deg steering wheel"
    )


@pytest.mark.parametrize(("vehicle_name", "scenario_name"), CASES)
def test_steering_oscillation_within_the_goal_against_the_reference(vehicle_name: str, scenario_name: str) -> None:
    reference_name = REFERENCE[vehicle_name]
    reference = _run(vehicle_name, scenario_name, reference_name)
    assert reference.completed and reference.max_abs_cte_m < MAX_ABS_CTE_M  # the yardstick itself tracks
    m = _run(vehicle_name, scenario_name, "clothoid")
    assert m.steer_oscillation_deg is not None and reference.steer_oscillation_deg is not None
    goal = max(OSCILLATION_RATIO * reference.steer_oscillation_deg, OSCILLATION_FLOOR_DEG)
    assert m.steer_oscillation_deg <= goal, (
        f"steering oscillation {m.steer_oscillation_deg:.2f} deg against the goal {goal:.2f} deg "
        f"({OSCILLATION_RATIO:g} x {reference_name}'s {reference.steer_oscillation_deg:.2f} deg, at least "
        f"{OSCILLATION_FLOOR_DEG:g})"
    )
