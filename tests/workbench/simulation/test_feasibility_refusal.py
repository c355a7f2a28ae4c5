"""The one refusal of a path a vehicle cannot follow (`feasibility.refuse_infeasible`), which `workbench run`,
`compare`, `robustness` and the study specs share: one line, the warnings once each, what allows it last."""

from __future__ import annotations

import pytest

from workbench.base.errors import WorkbenchInputError
from workbench.simulation.feasibility import (
    ALLOW_INFEASIBLE_OPTION,
    path_feasibility_warnings,
    refuse_infeasible,
)
from workbench.simulation.scenarios import ScenarioOptions, make_scenario
from workbench.simulation.simulator import SimulationConfig, plan_path_speed
from workbench.vehicles import make_vehicle


def test_nothing_to_refuse_without_warnings() -> None:
    assert refuse_infeasible([]) is None


def test_the_refusal_says_each_warning_once_then_what_allows_it() -> None:
    with pytest.raises(WorkbenchInputError) as refused:
        refuse_infeasible(["a: too tight at s = 1.0 m", "b: too fast at s = 2.0 m", "a: too tight at s = 1.0 m"])
    assert str(refused.value) == (
        f"a: too tight at s = 1.0 m; b: too fast at s = 2.0 m; {ALLOW_INFEASIBLE_OPTION} runs it anyway"
    )
    with pytest.raises(WorkbenchInputError) as refused:
        refuse_infeasible(["a: too tight"], "key = true", about="key: x.csv")
    assert str(refused.value) == "key: x.csv: a: too tight; key = true runs it anyway"
    assert "\n" not in str(refused.value)


def test_path_feasibility_warnings_judge_the_planned_path_for_the_vehicle(tmp_path) -> None:
    """Two 90-degree turns 0.5 m apart: beyond the car's steering rate at 30 km/h, within it at 10 km/h."""
    (tmp_path / "turns.csv").write_text("x_m,y_m\n0,0\n20,0\n20,0.5\n40,0.5\n")
    path = make_scenario(str(tmp_path / "turns.csv"), ScenarioOptions()).path
    car = make_vehicle("kinematic-bicycle")
    (warning,) = path_feasibility_warnings(plan_path_speed(path, SimulationConfig(speed_kmh=30.0)), car)
    assert warning.startswith("turns changes its curvature faster than the kinematic-bicycle's steering follows")
    assert path_feasibility_warnings(plan_path_speed(path, SimulationConfig(speed_kmh=10.0)), car) == []
