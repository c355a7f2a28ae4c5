"""A path a vehicle cannot follow at the planned speed (`workbench.simulation.feasibility`) is refused by `workbench
compare` and `workbench robustness` before any run, as `workbench run` refuses it (exit 2, one line naming the
vehicle, the places and the limit, ending with --allow-infeasible), and run with --allow-infeasible, warned; the
Python `compare()` and `plan_robustness()` refuse it too unless allow_infeasible. The two paths: a 3 m circle
(started from the straight wheels a run starts with) and two 90-degree turns 0.5 m apart; the named scenarios are
never refused."""

from __future__ import annotations

import math
import re
from pathlib import Path

import pytest

from workbench.apps.cli import main
from workbench.apps.comparison import RunSpec, compare
from workbench.apps.robustness import plan_robustness
from workbench.base.errors import WorkbenchInputError

#: The waypoint files of the catalogue's cases (tests/bad_input_catalogue.py): a 3 m circle and two 90-degree turns
#: 0.5 m apart, both beyond the kinematic bicycle's steering rate at the planned speed.


def _circle_csv(radius_m: float, n: int) -> str:
    """A closed circle of n waypoints (the first repeated last), as the bad-input catalogue writes it."""
    angles = [2 * math.pi * i / n for i in range(n)]
    rows = [f"{radius_m * math.cos(a):.4f},{radius_m * math.sin(a):.4f}" for a in angles]
    return "x_m,y_m\n" + "\n".join([*rows, rows[0]]) + "\n"


PATHS = {
    "tight-radius.csv": _circle_csv(3.0, 60),
    "sharp-turns.csv": "x_m,y_m\n0,0\n20,0\n20,0.5\n40,0.5\n",
}
ALLOW = "; --allow-infeasible runs it anyway"


class ReachedTheWork(BaseException):
    """Raised where the runs would start (a BaseException: no handler of the CLI catches it)."""


def _stop(*_args, **_kwargs):
    raise ReachedTheWork


@pytest.fixture
def paths(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A folder holding PATHS, the current directory; no simulation or study backend may start."""
    for name, text in PATHS.items():
        (tmp_path / name).write_text(text)
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr("workbench.simulation.simulator.Simulation.run", _stop)
    monkeypatch.setattr("workbench.apps.studies.make_backend", _stop)
    return tmp_path


def _compare_args(scenario: str, vehicles: str = "kinematic-bicycle") -> list[str]:
    return ["compare", scenario, "--controllers", "pure-pursuit,stanley", "--vehicle", vehicles, "--out", "out"]


def _robustness_args(scenario: str) -> list[str]:
    return ["robustness", scenario, "--controllers", "pure-pursuit", "--vehicle", "kinematic-bicycle", "--out", "out"]


def _the_error(err: str) -> str:
    (error,) = [line for line in err.splitlines() if "error:" in line]
    return error


@pytest.mark.parametrize("command", [_compare_args, _robustness_args], ids=["compare", "robustness"])
@pytest.mark.parametrize("scenario", list(PATHS))
def test_an_infeasible_path_is_refused_before_any_run_and_run_when_allowed(
    command, scenario: str, paths: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(command(scenario)) == 2  # refused: neither a simulation nor a backend started
    error = _the_error(capsys.readouterr().err)
    stem = scenario.removesuffix(".csv")
    assert error.startswith(
        f"workbench: error: {stem} changes its curvature faster than the kinematic-bicycle's steering follows at "
        "the planned speed (its road wheels turn at most 23 deg/s: 34 deg in any 1.5 s) at s = "
    )
    assert re.search(r"at s = \d+\.\d-\d+\.\d m \(the road-wheel angle asked for changes by 1\.\d\d times", error)
    assert error.endswith(ALLOW)
    assert not (paths / "out").exists()

    with pytest.raises(ReachedTheWork):  # allowed: it gets to the runs, having warned
        main([*command(scenario), "--allow-infeasible"])
    err = capsys.readouterr().err
    assert f"workbench: warning: {stem} changes its curvature faster than the kinematic-bicycle's" in err
    assert "error:" not in err


def test_compare_names_each_vehicle_that_cannot_follow_the_path(paths: Path, capsys) -> None:
    """The 3 m circle: beyond the car's steering rate, and tighter than the loaded truck's lock."""
    assert main(_compare_args("tight-radius.csv", "kinematic-bicycle,tractor-semitrailer")) == 2
    error = _the_error(capsys.readouterr().err)
    assert "faster than the kinematic-bicycle's steering follows" in error
    lock = "tighter than the tractor-semitrailer can turn at full lock (32 deg road-wheel angle: a radius of 9.19 m"
    assert lock in error
    assert error.count("faster than the kinematic-bicycle's") == 1  # two controllers on it: said once
    assert error.endswith(ALLOW)


@pytest.mark.parametrize("scenario", ["dlc", "figure8"])
@pytest.mark.parametrize("speed", ["30", "100"])
def test_a_named_scenario_is_never_refused(scenario: str, speed: str, paths: Path, capsys) -> None:
    vehicles = "kinematic-bicycle,dynamic-bicycle,tractor-semitrailer,commonroad-mb"
    for argv in (_compare_args(scenario, vehicles), _robustness_args(scenario)):
        with pytest.raises(ReachedTheWork):
            main([*argv, "--speed", speed])
        assert "error:" not in capsys.readouterr().err


def test_compare_from_python_refuses_unless_allowed(paths: Path) -> None:
    runs = [RunSpec("pure-pursuit", "kinematic-bicycle")]
    with pytest.raises(WorkbenchInputError, match=r"^sharp-turns changes its curvature faster .*" + re.escape(ALLOW)):
        compare("sharp-turns.csv", runs, warn=None)
    warned: list[str] = []
    with pytest.raises(ReachedTheWork):
        compare("sharp-turns.csv", runs, warn=warned.append, allow_infeasible=True)
    assert any(w.startswith("sharp-turns changes its curvature faster") for w in warned)


def test_plan_robustness_refuses_unless_allowed(paths: Path) -> None:
    with pytest.raises(WorkbenchInputError, match=r"^tight-radius changes its curvature faster .*" + re.escape(ALLOW)):
        plan_robustness("tight-radius.csv", ["pure-pursuit"], "kinematic-bicycle")
    planned = plan_robustness("tight-radius.csv", ["pure-pursuit"], "kinematic-bicycle", allow_infeasible=True)
    assert len(planned) == len(plan_robustness("dlc", ["pure-pursuit"], "kinematic-bicycle"))
