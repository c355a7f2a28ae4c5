"""`workbench run` and `compare` before and while they simulate: laps only on closed paths, the planned top speed
said with what limited it, a run longer than the bounds refused unless --allow-long-run, and a line per stage on
stderr when it is not a terminal."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from workbench.apps.cli import main
from workbench.base.errors import WorkbenchInputError
from workbench.simulation.run_size import MAX_RUN_STEPS
from workbench.simulation.scenarios import ScenarioOptions, make_scenario
from workbench.simulation.simulator import SimulationConfig, plan_path_speed_and_top
from workbench.vehicles import KinematicBicycle

RUN = ["run", "dlc", "--controller", "pure-pursuit", "--vehicle", "kinematic-bicycle", "--no-plots"]
COMPARE = ["compare", "dlc", "--controllers", "pure-pursuit", "--vehicle", "kinematic-bicycle", "--no-plots"]


@pytest.fixture
def runs(monkeypatch) -> list[object]:
    """Simulation.run replaced by a stop: the simulations that were started."""
    started: list[object] = []

    def stop(simulation, *_args, **_kwargs):
        started.append(simulation)
        raise WorkbenchInputError("stopped before simulating")

    monkeypatch.setattr("workbench.simulation.simulator.Simulation.run", stop)
    return started


@pytest.mark.parametrize("command", [RUN, COMPARE])
@pytest.mark.parametrize("laps", ["2", "1000000000"])
def test_laps_on_an_open_path_are_refused(command, laps: str, tmp_path: Path, capsys, runs) -> None:
    assert main([*command, "--laps", laps, "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert f"workbench: error: laps = {laps}: dlc is an open path" in err and "laps apply to closed paths" in err
    assert runs == [] and not (tmp_path / "out").exists()


@pytest.mark.parametrize("command", [RUN, COMPARE])
@pytest.mark.parametrize("laps", ["0", "-1"])
def test_fewer_than_one_lap_is_refused(command, laps: str, tmp_path: Path, capsys, runs) -> None:
    assert main([*command, "--laps", laps, "--out", str(tmp_path / "out")]) == 2
    assert f"workbench: error: --laps must be a whole number >= 1; got {laps}" in capsys.readouterr().err
    assert runs == []


def test_laps_of_a_closed_path_are_run(tmp_path: Path, capsys, runs) -> None:
    argv = ["run", "figure8", "--controller", "pure-pursuit", "--laps", "3", "--out", str(tmp_path / "o")]
    assert main(argv) == 2  # the stop
    (simulation,) = runs
    assert simulation.config.laps == 3 and simulation.total_length_m == pytest.approx(3 * simulation.path.length_m)


def test_run_says_the_planned_top_speed_and_what_limited_it(tmp_path: Path, capsys) -> None:
    assert main([*RUN, "--speed", "200", "--out", str(tmp_path / "fast")]) == 0
    out, err = capsys.readouterr()
    path = make_scenario("dlc", ScenarioOptions(vehicle_width_m=KinematicBicycle().geometry.width_m)).path
    _, top = plan_path_speed_and_top(path, SimulationConfig(speed_kmh=200.0))
    headline = f"dlc: pure-pursuit on kinematic-bicycle target 200 km/h, planned top {top.top_mps * 3.6:.3g} km/h ->"
    assert out.splitlines()[0].startswith(headline) and 60.0 < top.top_mps * 3.6 < 80.0
    assert "  the planned top speed is limited by the braking bound of 2 m/s^2 before the curves ahead" in out
    assert "workbench: warning: dlc: pure-pursuit on kinematic-bicycle: target 200 km/h, planned top" in err


def test_a_run_reaching_its_speed_says_only_the_speed(tmp_path: Path, capsys) -> None:
    assert main([*RUN, "--out", str(tmp_path / "o")]) == 0
    out = capsys.readouterr().out
    assert out.startswith("dlc: pure-pursuit on kinematic-bicycle at 30 km/h -> completed") and "planned top" not in out


def test_compare_warns_of_the_planned_top_speed(tmp_path: Path, capsys, runs) -> None:
    assert main([*COMPARE, "--speed", "200", "--out", str(tmp_path / "o")]) == 2  # the stop
    err = capsys.readouterr().err
    assert "workbench: warning: pure-pursuit on kinematic-bicycle: target 200 km/h, planned top " in err
    assert "(limited by the braking bound of 2 m/s^2" in err


@pytest.mark.parametrize(
    ("command", "options"),
    [
        (RUN, ["--speed", "0.001"]),
        (["run", "figure8", "--controller", "pure-pursuit"], ["--laps", "100000"]),
        (COMPARE, ["--speed", "0.001"]),
    ],
)
def test_a_run_longer_than_the_bounds_is_refused_before_it_starts(command, options, tmp_path: Path, capsys, runs):
    assert main([*command, *options, "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    error = err.splitlines()[-1]
    assert error.startswith("workbench: error: ") and "may simulate up to " in error
    steps = int(re.search(r"\(([\d,]+) controller steps at 50 Hz\)", error).group(1).replace(",", ""))
    assert steps > MAX_RUN_STEPS and f"more than the bound of {MAX_RUN_STEPS:,} steps" in error
    assert re.search(r"about [\d,]+\.\d GB\)", error) and error.endswith("or allow it with --allow-long-run")
    assert "--speed" in error and "--laps" in error and "--max-time-s" in error
    assert runs == [] and not (tmp_path / "o").exists()


@pytest.mark.parametrize("command", [RUN, COMPARE])
def test_allow_long_run_lets_it_start(command, tmp_path: Path, capsys, runs) -> None:
    assert main([*command, "--speed", "0.001", "--allow-long-run", "--out", str(tmp_path / "o")]) == 2
    assert "workbench: error: stopped before simulating" in capsys.readouterr().err
    assert len(runs) == 1 and runs[0].size.steps > MAX_RUN_STEPS


def test_a_time_out_within_the_bounds_lets_a_slow_run_start(tmp_path: Path, capsys, runs) -> None:
    assert main([*RUN, "--speed", "0.001", "--max-time-s", "600", "--out", str(tmp_path / "o")]) == 2
    assert runs[0].size.steps == 600 * 50 + 1


def test_run_names_each_stage_on_stderr_when_it_is_not_a_terminal(tmp_path: Path, capsys) -> None:
    assert main([*RUN, "--out", str(tmp_path / "o")]) == 0
    stages = [line for line in capsys.readouterr().err.splitlines() if line.startswith("workbench run: ")]
    assert stages[0] == "workbench run: building the vehicle, the controller and the scenario"
    assert re.fullmatch(r"workbench run: simulating 191 m of dlc \(time-out after \d+ s simulated\)", stages[1])
    assert stages[2] == f"workbench run: writing to {tmp_path / 'o'}" and len(stages) == 3


def test_fig17_refuses_a_crawl_naming_its_option(tmp_path: Path, capsys, runs) -> None:
    assert main(["fig17", "--speed", "0.001", "--out", str(tmp_path / "o")]) == 2
    error = capsys.readouterr().err.splitlines()[-1]
    assert error.startswith("workbench: error: clothoid on ") and error.endswith("allow it with --allow-long-run")
    assert runs == []
