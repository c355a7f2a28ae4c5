"""A lookahead floor above max_lookahead_m is said before the run (`ClothoidController.run_warnings`, printed by
`Simulation.warnings` and `workbench run`): the speeds, the floor (or that none keeps the margins), max_lookahead_m
and what to change. With a weak lead filter the truck's loop needs a longer lookahead than the configured range
allows; the controller then holds its lookahead at the floor, outside the range, and the Fréchet search never acts.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from controllers.clothoid import ClothoidConfig
from controllers.clothoid.controller import MAX_FLOOR_LOOKAHEAD_M
from controllers.clothoid.filter_schedule import FilterSchedule
from controllers.clothoid.lead_filter import LeadFilterParams
from tuning.filter_file import write_filter_file
from tuning.own_tuning import tuned_controller
from workbench.apps.cli import main as workbench_main
from workbench.base.path import ReferencePath
from workbench.simulation.run_config import SimulationConfig
from workbench.simulation.scenarios import ScenarioOptions, make_scenario
from workbench.simulation.simulator import Simulation
from workbench.vehicles import make_vehicle

TRUCK = make_vehicle("tractor-semitrailer")
#: A lead filter with far less phase lead than the truck's own (zeros at 5 rad/s, poles at 12): on the truck at
#: 30 km/h its floor is about 16 m, at 60 km/h no lookahead up to 40 m keeps 45 deg / 6 dB.
WEAK = LeadFilterParams(5.0, 1.0, 12.0)
STRAIGHT = ReferencePath.from_xy(np.linspace(0.0, 300.0, 31), np.zeros(31), name="straight")
DT_S = 0.02


def _controller(**options):
    config = ClothoidConfig(lead_filter=FilterSchedule((0.0,), (WEAK,)), **options)
    return tuned_controller("clothoid", TRUCK, config)


def _at(speed_kmh: float) -> ReferencePath:
    return STRAIGHT.with_speed(np.full(STRAIGHT.s_m.size, speed_kmh / 3.6))


def test_a_floor_above_the_range_is_said_with_the_speed_the_floor_and_what_to_do() -> None:
    controller = _controller(max_lookahead_m=12.0)
    (warning,) = controller.run_warnings(_at(30.0), DT_S)
    floor = controller.lookahead_floor_m(30.0 / 3.6)
    assert 12.0 < floor < MAX_FLOOR_LOOKAHEAD_M  # a floor that keeps the margins, above the range
    assert f"lies above max_lookahead_m = 12 m at 30 km/h (floor {floor:g} m)" in warning
    assert "the lookahead is held at the floor" in warning and "configured 5-12 m" in warning
    assert "the Fréchet search does not act" in warning
    assert f"raise max_lookahead_m to at least {floor:g} m" in warning
    assert "or use a lead filter with more phase margin" in warning


def test_no_lookahead_keeping_the_margins_is_said_in_words() -> None:
    controller = _controller()
    (warning,) = controller.run_warnings(_at(60.0), DT_S)
    assert controller.lookahead_floor_m(60.0 / 3.6) == MAX_FLOOR_LOOKAHEAD_M  # the search's top: none keeps them
    assert "at 60 km/h (floor none: no lookahead up to 40 m keeps them)" in warning
    assert "raise max_lookahead_m" not in warning  # a longer range does not help where nothing keeps the margins
    assert "use a lead filter with more phase margin" in warning


def test_neighbouring_bands_that_say_the_same_are_one_span() -> None:
    speeds = np.linspace(50.0, 60.0, STRAIGHT.s_m.size) / 3.6  # the bands of 50, 55 and 60 km/h
    (warning,) = _controller().run_warnings(STRAIGHT.with_speed(speeds), DT_S)
    assert "at 50-60 km/h (floor none: no lookahead up to 40 m keeps them):" in warning


@pytest.mark.parametrize(
    ("speed_kmh", "options"),
    [
        (30.0, {}),  # the floor (about 16 m) inside the default 5-20 m
        (30.0, {"max_lookahead_m": 30.0}),
        (60.0, {"lookahead_mode": "fixed"}),  # the fixed lookahead ignores the floor
    ],
)
def test_no_warning_where_the_floor_is_inside_the_range_or_does_not_apply(speed_kmh: float, options: dict) -> None:
    assert _controller(**options).run_warnings(_at(speed_kmh), DT_S) == []


def test_the_trucks_own_tuning_keeps_its_floor_inside_the_range_at_30_kmh() -> None:
    assert tuned_controller("clothoid", TRUCK).run_warnings(_at(30.0), DT_S) == []


def test_the_simulation_says_it_before_the_run_and_the_run_holds_the_floor() -> None:
    scenario = make_scenario("dlc", ScenarioOptions(vehicle_width_m=TRUCK.geometry.width_m))
    controller = _controller(max_lookahead_m=12.0)
    simulation = Simulation(scenario, TRUCK, controller, SimulationConfig(speed_kmh=30.0))
    warnings = [w for w in simulation.warnings("dlc: clothoid") if "lookahead floor" in w]
    assert len(warnings) == 1 and warnings[0].startswith("dlc: clothoid: the clothoid controller's lookahead floor")
    trace = simulation.run().to_pandas()
    floors = trace["ctrl_lookahead_floor_m"].to_numpy()
    above = floors > 12.0
    assert above.mean() > 0.5  # most of the run is at speeds whose floor is above the range
    speeds = trace["speed_mps"].to_numpy()[above]  # measured exactly (ideal conditions)
    np.testing.assert_allclose(floors[above], [controller.lookahead_floor_m(v) for v in speeds], atol=1e-9)
    np.testing.assert_allclose(trace["ctrl_lookahead_m"][above], floors[above], atol=1e-9)  # held at the floor


def test_workbench_run_prints_the_warning(tmp_path: Path, capsys) -> None:
    lead = write_filter_file(tmp_path / "weak.json", WEAK, source="a weak lead")
    argv = ["run", "dlc", "--vehicle", "tractor-semitrailer", "--speed", "30", "--set", f"filter_file={lead}",
            "--set", "max_lookahead_m=12", "--out", str(tmp_path / "run"), "--no-plots"]  # fmt: skip
    assert workbench_main(argv) == 0
    err = capsys.readouterr().err
    assert "workbench: warning: dlc: clothoid on tractor-semitrailer: the clothoid controller's lookahead floor" in err
    assert "raise max_lookahead_m to at least" in err
