"""The sideslip's release (`sideslip_release.py`): what a release accepts, its table row, the steady sideslip read
from it (linear on the grid, in proportion beyond, odd in lateral acceleration); in the controller, nothing
released where the plan holds the speed, and at a braked hairpin the delayed loop brought near the delay-free
one."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.constants import g as G_MPS2

from controllers.base import Measurement
from controllers.clothoid import ClothoidConfig
from controllers.clothoid.preview_model import HANDLING_GRID_G
from controllers.clothoid.sideslip_release import SideslipRelease, steady_sideslip
from tuning.own_tuning import tuned_controller
from tuning.tuning_dirs import read_vehicle_tuning, shipped_tuning_root
from workbench.base.clothoid_chain import ClothoidChain
from workbench.base.errors import WorkbenchInputError
from workbench.base.path import ReferencePath
from workbench.simulation.conditions import load_conditions
from workbench.simulation.scenarios import Scenario
from workbench.simulation.simulator import Simulation, SimulationConfig
from workbench.vehicles import make_vehicle

#: A rear axle slipping 0.5 deg per 0.1 g, a little more above 0.2 g.
GRID = tuple(math.radians(-5.0 * a - (20.0 * (a - 0.2) ** 2 if a > 0.2 else 0.0)) for a in HANDLING_GRID_G)


def test_the_row_is_the_rate_then_the_grid() -> None:
    release = SideslipRelease(GRID, 0.08)
    assert release.row() == [pytest.approx(12.5, rel=1e-12), *GRID]
    assert SideslipRelease(GRID).rate_1ps == 0.0  # not identified: nothing released


@pytest.mark.parametrize(
    ("grid", "time", "message"),
    [
        (GRID[:-1], 0.1, "steady_sideslip_rad must be 9 sideslips"),
        ((1e-3, *GRID[1:]), 0.1, "the first 0"),
        ((*GRID[:-1], math.nan), 0.1, "each within"),
        ((*GRID[:-1], math.radians(25.0)), 0.1, "each within"),
        (GRID, 0.0, r"release_time_s must be in \[0.001, 10\] s, or inf"),
        (GRID, math.nan, "release_time_s must be"),
        (GRID, True, "release_time_s must be"),
        (GRID, 11.0, "release_time_s must be"),
    ],
)
def test_an_impossible_release_is_refused(grid: tuple[float, ...], time: float, message: str) -> None:
    with pytest.raises(WorkbenchInputError, match=message):
        SideslipRelease(grid, time)


def test_on_the_grid_the_steady_sideslip_is_the_grids() -> None:
    row = np.array(SideslipRelease(GRID, 0.1).row())
    for a, expected in zip(HANDLING_GRID_G, GRID, strict=True):
        assert steady_sideslip(row, a * G_MPS2) == pytest.approx(expected, rel=1e-12, abs=1e-18)


@settings(max_examples=80, deadline=None)
@given(lat_accel_mps2=st.floats(-12.0, 12.0))
def test_the_steady_sideslip_is_the_grids_interpolation_odd_and_proportional_beyond(lat_accel_mps2: float) -> None:
    """Against np.interp on the grid within it; beyond its last point, the last point's sideslip per g times the
    lateral acceleration; a right turn's the opposite of the left turn's."""
    row = np.array(SideslipRelease(GRID, 0.1).row())
    a = abs(lat_accel_mps2) / G_MPS2
    top = HANDLING_GRID_G[-1]
    expected = np.interp(a, HANDLING_GRID_G, GRID) if a <= top else GRID[-1] * a / top
    got = steady_sideslip(row, lat_accel_mps2)
    assert math.copysign(1.0, lat_accel_mps2) * got == pytest.approx(expected, rel=1e-9, abs=1e-15)
    assert steady_sideslip(row, -lat_accel_mps2) == pytest.approx(-got, abs=1e-15)


def test_a_release_read_as_a_rate() -> None:
    """As a tuning file holds it: rate 0 is not identified (inf), a rate its time's inverse; out of range refused."""
    assert SideslipRelease.from_rate(GRID, 0.0).release_time_s == math.inf
    assert SideslipRelease.from_rate(GRID, 12.5).release_time_s == pytest.approx(0.08, rel=1e-15)
    for rate in (-1.0, 0.05, 2000.0, math.nan, "fast", True):
        with pytest.raises(WorkbenchInputError, match=r"release_rate_1ps must be in \[0.1, 1000\] 1/s, or 0"):
            SideslipRelease.from_rate(GRID, rate)


TRUCK = make_vehicle("tractor-semitrailer")
#: A hairpin like Zandvoort's (radius 11.4 m): 12 m clothoids either side of a 7.5 m arc; the scenario plans
#: braking into it and accelerating out (its 0.3 g profile).
HAIRPIN = (
    ClothoidChain().straight(80.0).clothoid_to(-1 / 11.4, 12.0).arc(7.5).clothoid_to(0.0, 12.0).straight(60.0)
).to_path("hairpin")


#: A straight, a clothoid into a 30 m arc, a clothoid out and a straight (the weaving measurements' bend).
BEND = ClothoidChain().straight(20.0).clothoid_to(1 / 30, 15.0).arc(30.0).clothoid_to(0.0, 15.0).straight(40.0)
BEND_PATH = BEND.to_path("bend")


def _commands(path: ReferencePath, release: bool, measurements: list[Measurement]) -> list[float]:
    controller = tuned_controller("clothoid", TRUCK, ClothoidConfig(known_delay_s=0.11, sideslip_release=release))
    controller.reset(path, 0.02)
    return [controller.step(m, path) for m in measurements]


def test_where_the_plan_holds_the_speed_nothing_is_released(weaving) -> None:
    """The truck's tuning has a release at every speed it was braked at; stepping along a bend (made-up
    measurements with sideslip) with no planned speeds or a held one, the commands are those without the release,
    bit for bit; with a planned braking through the bend they are not."""
    measurements = weaving(BEND_PATH, 120, 7)
    assert read_vehicle_tuning(shipped_tuning_root() / TRUCK.name).release_table[:, 0].max() > 0.0
    held = BEND_PATH.with_speed(np.full(BEND_PATH.s_m.size, 8.0))
    for path in (BEND_PATH, held):
        assert _commands(path, True, measurements) == _commands(path, False, measurements)
    braking = BEND_PATH.with_speed(np.sqrt(np.maximum(100.0 - 2.0 * 1.5 * BEND_PATH.s_m, 1.0)))  # 1.5 m/s^2
    assert _commands(braking, True, measurements) != _commands(braking, False, measurements)


@pytest.mark.parametrize(("vehicle", "measured"), [("tractor-semitrailer", (0.128, 0.121, 0.125)),
                                                     ("dynamic-bicycle", (0.041, 0.035, 0.030))])  # fmt: skip
def test_the_release_brings_a_braked_hairpin_near_the_delay_free_loop(vehicle: str, measured: tuple) -> None:
    """Automotive conditions (pose 10 ms late, steering 0.1 s dead time), known_delay_s = 0.11, braking into the
    hairpin and accelerating out: the sideslip the braking pushes and the vehicle releases is predicted over the
    dead time, and max |CTE| falls by at least 5 mm, to within 20 % of the delay-free controller's under `ideal`
    (measured: without the release, with it, delay-free, in `measured`; with it, the floor keeps the margins of the
    loop with the release in it too, the car's 0.5 m higher at 30 km/h), the steering's oscillation and RMS rate
    within 2 % of the run without."""
    plant = make_vehicle(vehicle)
    metrics = {}
    for name, conditions, delay, release in (
        ("without", "automotive", 0.11, False), ("with", "automotive", 0.11, True), ("delay-free", "ideal", 0.0, True),
    ):  # fmt: skip
        controller = tuned_controller("clothoid", plant, ClothoidConfig(known_delay_s=delay, sideslip_release=release))
        sim = SimulationConfig(conditions=load_conditions(conditions))
        result = Simulation(Scenario("hairpin", HAIRPIN, "test"), plant, controller, sim).run()
        assert result.completed, result.message
        metrics[name] = result.metrics
    without, with_release, delay_free = (metrics[k].max_abs_cte_m for k in ("without", "with", "delay-free"))
    assert with_release <= without - 0.005
    assert with_release <= 1.2 * delay_free
    assert [round(v, 3) for v in (without, with_release, delay_free)] == pytest.approx(measured, abs=0.002)
    for key in ("steer_oscillation_deg", "rms_steer_rate_deg_s"):
        assert getattr(metrics["with"], key) <= 1.02 * getattr(metrics["without"], key)
