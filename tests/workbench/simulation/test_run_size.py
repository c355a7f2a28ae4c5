"""The planned size of a run (`run_size.RunSize`): its time-out, steps and trace, the bounds it is refused beyond, and
the laps a Simulation refuses on an open path."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

from controllers import PurePursuit
from workbench.base.clothoid_chain import ClothoidChain
from workbench.base.errors import WorkbenchInputError
from workbench.simulation.run_size import (
    BYTES_PER_VALUE,
    EXTRA_TRACE_COLUMNS,
    MAX_RUN_STEPS,
    MAX_TRACE_BYTES,
    TIMEOUT_FACTOR,
    TIMEOUT_MARGIN_S,
    RunSize,
    check_run_size,
)
from workbench.simulation.scenarios import Scenario
from workbench.simulation.simulator import Simulation, SimulationConfig, plan_path_speed
from workbench.vehicles import KinematicBicycle


def _straight(length_m: float = 200.0):
    return ClothoidChain().straight(length_m).to_path("straight")


def _circle(radius_m: float = 50.0):
    return ClothoidChain(curvature_1pm=1.0 / radius_m).arc(2 * math.pi * radius_m).to_path("circle", closed=True)


def test_the_default_time_out_is_three_times_the_planned_time_plus_the_margin() -> None:
    config = SimulationConfig(speed_kmh=36.0)
    path = plan_path_speed(_straight(200.0), config)
    size = RunSize.of(path, config, output_count=10)
    expected_s = TIMEOUT_FACTOR * 200.0 / float(np.mean(path.speed_mps)) + TIMEOUT_MARGIN_S
    assert size.max_time_s == pytest.approx(expected_s, rel=1e-12)
    assert size.steps == math.ceil(expected_s * 50.0) + 1
    assert size.columns == 10 + EXTRA_TRACE_COLUMNS
    assert size.trace_bytes == size.steps * size.columns * BYTES_PER_VALUE


def test_laps_multiply_a_closed_path_and_a_given_time_out_replaces_the_default() -> None:
    one, three = SimulationConfig(speed_kmh=30.0), SimulationConfig(speed_kmh=30.0, laps=3)
    path = plan_path_speed(_circle(), one)
    mean = float(np.mean(path.speed_mps))
    assert RunSize.of(path, three, 10).max_time_s == pytest.approx(
        TIMEOUT_FACTOR * 3 * path.length_m / mean + TIMEOUT_MARGIN_S, rel=1e-12
    )
    given = SimulationConfig(speed_kmh=30.0, max_time_s=12.5, controller_rate_hz=100.0, plant_rate_hz=1000.0)
    size = RunSize.of(path, given, 10)
    assert (size.max_time_s, size.steps) == (12.5, 1251)


@pytest.mark.parametrize(
    ("steps", "columns", "too_large"),
    [
        (MAX_RUN_STEPS, 1, False),
        (MAX_RUN_STEPS + 1, 1, True),
        (1000, MAX_TRACE_BYTES // (1000 * BYTES_PER_VALUE), False),
        (1000, MAX_TRACE_BYTES // (1000 * BYTES_PER_VALUE) + 1, True),
    ],
)
def test_the_bounds_are_inclusive(steps: int, columns: int, too_large: bool) -> None:
    size = RunSize(max_time_s=steps / 50.0, steps=steps, columns=columns, controller_rate_hz=50.0)
    assert size.too_large is too_large
    if too_large:
        with pytest.raises(WorkbenchInputError, match=r"^the run may simulate .*: fewer laps shortens it, or allow"):
            check_run_size(size, "the run", "fewer laps shortens it", "--allow-long-run")
    else:
        check_run_size(size, "the run", "fewer laps shortens it", "--allow-long-run")


def test_a_very_slow_run_is_sized_in_days_and_gigabytes() -> None:
    vehicle = KinematicBicycle()
    simulation = Simulation(
        Scenario("straight", _straight(200.0), "test"), vehicle, PurePursuit(vehicle.geometry), SimulationConfig(1e-3)
    )
    # 200 m at 1e-3 km/h: 3 x 720 000 s + 30 s, 25 days
    assert simulation.size.max_time_s == pytest.approx(3 * 200.0 / (1e-3 / 3.6) + 30.0, rel=1e-9)
    assert simulation.max_steps == simulation.size.steps and simulation.size.too_large
    with pytest.raises(WorkbenchInputError) as refused:
        check_run_size(simulation.size, "slow", "faster", "--allow-long-run")
    message = str(refused.value)
    assert "up to 25 days (108,001,501 controller steps at 50 Hz)" in message
    assert re.search(r"about \d+\.\d GB\)", message) and message.endswith("or allow it with --allow-long-run")


@pytest.mark.parametrize("laps", [2, 1_000_000_000])
def test_laps_on_an_open_path_are_refused(laps: int) -> None:
    vehicle, config = KinematicBicycle(), SimulationConfig(laps=laps)
    with pytest.raises(WorkbenchInputError, match=rf"^laps = {laps}: straight is an open path .*closed paths only"):
        Simulation(Scenario("straight", _straight(), "test"), vehicle, PurePursuit(vehicle.geometry), config)


def test_laps_on_a_closed_path_are_accepted() -> None:
    vehicle = KinematicBicycle()
    simulation = Simulation(
        Scenario("circle", _circle(), "test"), vehicle, PurePursuit(vehicle.geometry), SimulationConfig(laps=2)
    )
    assert simulation.total_length_m == pytest.approx(2 * simulation.path.length_m)
