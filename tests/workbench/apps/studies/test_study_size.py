"""A study's longest run sized before any run starts (`study_size.py`): a sweep, an optimisation or a robustness
study whose runs may simulate more than the bounds of `run_size` is refused (exit 2) naming what shortens it and
the key or option that allows it; laps asked of open paths only are refused."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from study_helpers import write_spec

from workbench.apps.cli import main
from workbench.apps.robustness import plan_robustness
from workbench.apps.studies import load_spec
from workbench.apps.studies.study_size import longest_config
from workbench.base.errors import WorkbenchInputError
from workbench.simulation.run_size import MAX_RUN_STEPS

SPEC = """
[study]
scenarios = ["{scenario}"]
controllers = ["pure-pursuit"]
vehicles = ["kinematic-bicycle"]
{study}
[grid]
{grid}
"""


def _spec(tmp_path: Path, grid: str, study: str = "", scenario: str = "dlc") -> Path:
    return write_spec(tmp_path / "spec", SPEC.format(scenario=scenario, study=study, grid=grid))


def _steps(message: str) -> int:
    return int(re.search(r"\(([\d,]+) controller steps at", message).group(1).replace(",", ""))


def test_a_sweep_at_a_crawl_without_a_time_limit_is_refused(tmp_path: Path) -> None:
    with pytest.raises(WorkbenchInputError) as refused:
        load_spec(_spec(tmp_path, "speed_kmh = [30.0, 0.001]"))
    message = str(refused.value)
    assert "the study's longest run on dlc (speed_kmh = 0.001) may simulate up to " in message
    assert _steps(message) > MAX_RUN_STEPS and "a max_time_s in [grid] shortens it" in message
    assert message.endswith("or allow it with study.allow_long_runs = true in [study]")


def test_a_drawn_crawl_is_refused_too(tmp_path: Path) -> None:
    text = SPEC.format(scenario="dlc", study="samples = 3", grid="")
    text += "[random]\nspeed_kmh = {uniform = [0.001, 0.002]}\n"
    with pytest.raises(WorkbenchInputError, match=r"longest run on dlc \(speed_kmh = 0\.00\d+\) may simulate"):
        load_spec(write_spec(tmp_path / "spec", text))


def test_many_laps_of_a_closed_path_are_refused(tmp_path: Path) -> None:
    with pytest.raises(WorkbenchInputError, match=r"longest run on figure8 \(laps = 100000\) may simulate"):
        load_spec(_spec(tmp_path, "laps = [1, 100000]", scenario="figure8"))


@pytest.mark.parametrize(
    ("grid", "study"),
    [
        ("speed_kmh = [0.001]", "allow_long_runs = true"),
        ("speed_kmh = [0.001]\nmax_time_s = [600.0]", ""),
        ("speed_kmh = [20.0, 60.0]\nlaps = [1]", ""),
    ],
)
def test_a_study_within_the_bounds_or_allowed_is_accepted(grid: str, study: str, tmp_path: Path) -> None:
    spec = load_spec(_spec(tmp_path, grid, study))
    assert spec.run_count() >= 1


def test_a_time_limit_given_for_some_runs_only_leaves_the_others_sized_by_default(tmp_path: Path) -> None:
    with pytest.raises(WorkbenchInputError, match=r"\(speed_kmh = 0\.001, max_time_s = None\)"):
        load_spec(_spec(tmp_path, 'speed_kmh = [0.001]\nmax_time_s = [600.0, "none"]'))


def test_the_longest_config_takes_each_extreme() -> None:
    values = {
        "speed_kmh": ("grid.speed_kmh", [40.0, 10.0, 25.0]),
        "laps": ("random.laps", [1, 4, 2]),
        "controller_rate_hz": ("grid.controller_rate_hz", [50.0, 100.0]),
        "max_time_s": ("grid.max_time_s", [None, 30.0, 90.0]),
    }
    configs = longest_config(values)
    assert [(c.speed_kmh, c.laps, c.controller_rate_hz, c.max_time_s) for c in configs] == [
        (10.0, 4, 100.0, 90.0),
        (10.0, 4, 100.0, None),
    ]


def test_laps_asked_of_open_paths_only_are_refused(tmp_path: Path) -> None:
    with pytest.raises(WorkbenchInputError, match=r"grid\.laps = 2: the study's scenarios \(dlc\) are open paths"):
        load_spec(_spec(tmp_path, "laps = [1, 2]"))


def test_allow_long_runs_must_be_a_boolean(tmp_path: Path) -> None:
    with pytest.raises(WorkbenchInputError, match=r"study\.allow_long_runs must be true or false; got 'yes'"):
        load_spec(_spec(tmp_path, "speed_kmh = [30.0]", 'allow_long_runs = "yes"'))


def test_the_sweep_command_refuses_it_with_exit_2_before_any_run(tmp_path: Path, capsys) -> None:
    spec = _spec(tmp_path, "speed_kmh = [0.001]")
    assert main(["sweep", str(spec), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("workbench: error: spec ") and "study.allow_long_runs = true" in err
    assert not (tmp_path / "out" / "runs").exists()


def test_a_robustness_study_at_a_crawl_is_refused_naming_the_option(tmp_path: Path, capsys) -> None:
    with pytest.raises(WorkbenchInputError, match=r"^each run on dlc may simulate .* allow it with --allow-long-run$"):
        plan_robustness("dlc", ["pure-pursuit"], "kinematic-bicycle", speed_kmh=0.001)
    assert len(plan_robustness("dlc", ["pure-pursuit"], "kinematic-bicycle", 0.001, allow_long_run=True)) > 1
    argv = ["robustness", "dlc", "--controllers", "pure-pursuit", "--vehicle", "kinematic-bicycle", "--speed", "0.001"]
    assert main([*argv, "--out", str(tmp_path / "rob")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("workbench: error: each run on dlc may simulate") and "--speed (now 0.001 km/h)" in err
    assert not (tmp_path / "rob").exists()
