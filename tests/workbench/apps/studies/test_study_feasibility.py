"""A study spec whose scenario a vehicle cannot follow at the study's fastest run (`study_feasibility.py`) is
refused when it loads (exit 2, naming study.scenarios, the file, the vehicle and the speed, the places and the
limit), unless study.allow_infeasible = true; each scenario's path is planned once whatever the study's size."""

from __future__ import annotations

import math
import re
from pathlib import Path

import pytest
from study_helpers import write_spec

import workbench.apps.studies.study_feasibility as study_feasibility
from workbench.apps.cli import main
from workbench.apps.studies import load_spec
from workbench.base.errors import WorkbenchInputError


def _circle_csv(radius_m: float, n: int) -> str:
    """A closed circle of n waypoints (the first repeated last), as the bad-input catalogue writes it."""
    angles = [2 * math.pi * i / n for i in range(n)]
    rows = [f"{radius_m * math.cos(a):.4f},{radius_m * math.sin(a):.4f}" for a in angles]
    return "x_m,y_m\n" + "\n".join([*rows, rows[0]]) + "\n"


#: A 3 m circle and two 90-degree turns 0.5 m apart (the bad-input catalogue's), beyond the kinematic bicycle's
#: steering rate at the planned speed: the turns from 15 km/h (at 10 km/h it follows them); a 50 m circle, which the
#: tractor-semitrailer rounds at 0.44 g within its rollover threshold at its own payload (0.448 g) but not with
#: 22,100 kg (0.431 g).
PATHS = {
    "tight-radius.csv": _circle_csv(3.0, 60),
    "sharp-turns.csv": "x_m,y_m\n0,0\n20,0\n20,0.5\n40,0.5\n",
    "circle50.csv": _circle_csv(50.0, 120),
}
SPEC = """
[study]
scenarios = {scenarios}
controllers = ["pure-pursuit"]
vehicles = {vehicles}
{study}
[grid]
{grid}
"""
ALLOW = "; study.allow_infeasible = true in [study] runs it anyway"


class ReachedTheWork(BaseException):
    """Raised where the study's runs would start."""


def _stop(*_args, **_kwargs):
    raise ReachedTheWork


def _spec(folder: Path, scenarios: list[str], grid: str = "", study: str = "", vehicles=("kinematic-bicycle",)) -> Path:
    for name, text in PATHS.items():
        (folder / "spec").mkdir(parents=True, exist_ok=True)
        (folder / "spec" / name).write_text(text)
    text = SPEC.format(
        scenarios=str(list(scenarios)).replace("'", '"'),
        vehicles=str(list(vehicles)).replace("'", '"'),
        study=study,
        grid=grid,
    )
    return write_spec(folder / "spec", text)


@pytest.mark.parametrize("scenario", ["tight-radius.csv", "sharp-turns.csv"])
def test_the_sweep_refuses_an_infeasible_scenario_when_the_spec_loads_and_runs_it_when_allowed(
    scenario: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.setattr("workbench.apps.studies.make_backend", _stop)
    spec = _spec(tmp_path, ["dlc", scenario], "speed_kmh = [20, 30]")
    assert main(["sweep", str(spec), "--out", str(tmp_path / "out"), "--no-plots"]) == 2
    (error,) = [line for line in capsys.readouterr().err.splitlines() if "error:" in line]
    stem = scenario.removesuffix(".csv")
    assert error.startswith(
        f"workbench: error: spec {spec}: study.scenarios: {spec.parent / scenario} cannot be followed by "
        f"kinematic-bicycle at the study's fastest run, speed_kmh = 30.0: {stem} changes its curvature faster than "
        "the kinematic-bicycle's steering follows at the planned speed (its road wheels turn at most 23 deg/s"
    )
    assert re.search(r"at s = \d+\.\d-\d+\.\d m \(the road-wheel angle asked for changes by 1\.\d\d times", error)
    assert error.endswith(ALLOW)
    assert not (tmp_path / "out" / "runs").exists()

    allowed = _spec(tmp_path, ["dlc", scenario], "speed_kmh = [20, 30]", "allow_infeasible = true")
    with pytest.raises(ReachedTheWork):
        main(["sweep", str(allowed), "--out", str(tmp_path / "out"), "--no-plots"])


def test_the_optimise_spec_is_refused_too(tmp_path: Path, capsys) -> None:
    spec = _spec(tmp_path, ["sharp-turns.csv"], "speed_kmh = 30")
    spec.write_text(
        spec.read_text()
        + "\n[optimise]\ntrials = 2\nobjective = { rms_cte_m = 1.0 }\n"
        + "search = { lookahead_gain_s = { uniform = [0.5, 1.0] } }\n"
    )
    assert main(["optimise", str(spec), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert "study.scenarios: " in err and "cannot be followed by kinematic-bicycle" in err
    assert err.strip().endswith(ALLOW)


def test_the_fastest_run_is_judged(tmp_path: Path) -> None:
    """The turns are followed up to 10 km/h: a study up to 10 km/h loads, one with a 20 km/h run is refused at
    20 km/h."""
    assert load_spec(_spec(tmp_path, ["sharp-turns.csv"], "speed_kmh = [5, 10]")).run_count() == 2
    with pytest.raises(WorkbenchInputError, match=r"fastest run, speed_kmh = 20\.0: sharp-turns changes"):
        load_spec(_spec(tmp_path, ["sharp-turns.csv"], "speed_kmh = [5, 10, 20]"))
    drawn = "samples = 3\n[random]\nspeed_kmh = { uniform = [19.0, 20.0] }"  # the fastest of the draws
    with pytest.raises(WorkbenchInputError, match=r"fastest run, speed_kmh = 19\.\d+: sharp-turns changes"):
        load_spec(_spec(tmp_path, ["sharp-turns.csv"], "", drawn))


def test_the_heaviest_payload_and_the_largest_lateral_bound_are_judged(tmp_path: Path) -> None:
    truck = ["tractor-semitrailer"]
    grid = "speed_kmh = 60\nmax_lateral_accel_g = [0.3, 0.44]\npayload_kg = [0.0, {}]"
    assert load_spec(_spec(tmp_path, ["circle50.csv"], grid.format(17000.0), vehicles=truck)).run_count() == 4
    with pytest.raises(WorkbenchInputError) as refused:
        load_spec(_spec(tmp_path, ["circle50.csv"], grid.format(22100.0), vehicles=truck))
    message = str(refused.value)
    assert "cannot be followed by tractor-semitrailer at the study's fastest run, speed_kmh = 60.0, " in message
    assert "max_lateral_accel_g = 0.44, payload_kg = 22100.0: circle50 asks the tractor-semitrailer" in message
    assert "static rollover threshold (0.43 g)" in message and message.endswith(ALLOW)


def test_a_named_scenario_is_never_refused(tmp_path: Path) -> None:
    vehicles = ["kinematic-bicycle", "dynamic-bicycle", "tractor-semitrailer", "commonroad-mb"]
    spec = load_spec(_spec(tmp_path, ["dlc", "figure8", "fig17"], "speed_kmh = [30, 100]", vehicles=vehicles))
    assert spec.run_count() == 3 * 4 * 2


def test_each_scenario_is_planned_once_however_many_runs(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    planned, judged = [], []
    plan, judge = study_feasibility.plan_path_speed, study_feasibility.path_feasibility_warnings
    monkeypatch.setattr(study_feasibility, "plan_path_speed", lambda *a: planned.append(1) or plan(*a))
    monkeypatch.setattr(study_feasibility, "path_feasibility_warnings", lambda *a: judged.append(1) or judge(*a))
    grid = f"speed_kmh = {list(range(10, 30, 2))}\ninitial_offset_m = {[i / 20 for i in range(10)]}"
    spec = load_spec(_spec(tmp_path, ["dlc", "figure8"], grid, vehicles=["kinematic-bicycle", "dynamic-bicycle"]))
    assert spec.run_count() == 400
    assert len(planned) == 2 and len(judged) == 4  # each scenario once; each scenario and vehicle once


def test_allow_infeasible_must_be_true_or_false(tmp_path: Path) -> None:
    with pytest.raises(WorkbenchInputError, match=r"study\.allow_infeasible must be true or false; got 'yes'"):
        load_spec(_spec(tmp_path, ["dlc"], "speed_kmh = 30", 'allow_infeasible = "yes"'))
