"""The robustness study (issue 18, item 4): one factor at a time, through the study backends, a report with the
degradation curves and the values at which each controller stops passing."""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest
from report_helpers import tables_scrolling

from workbench.apps.cli import main
from workbench.apps.robustness import AXES, Axis, RobustnessResult, plan_robustness, robustness_axes


def test_the_plan_varies_one_factor_at_a_time_and_adds_the_payload_mismatch_for_a_truck() -> None:
    runs = plan_robustness("dlc", ["clothoid", "stanley"], "tractor-semitrailer")
    per_controller = 1 + sum(len(a.values) - 1 for a in AXES) + 2
    assert len(runs) == 2 * per_controller and len({r.run_id for r in runs}) == len(runs)
    assert [r.index for r in runs] == list(range(len(runs)))
    for run in runs:
        varied = [a.parameter for a in AXES if a.parameter in dict(run.values)]
        assert len(varied) <= 1
    mismatch = [dict(r.values) for r in runs if "controller_payload_kg" in dict(r.values)]
    assert sorted((v["payload_kg"], v["controller_payload_kg"]) for v in mismatch) == [
        (0.0, 17000.0),
        (0.0, 17000.0),
        (8500.0, 17000.0),
        (8500.0, 17000.0),
    ]  # the plant's payload varied, each controller built for the nominal payload
    # a car has no payload, and the kinematic bicycle no tyres: no mismatch, no friction axis
    kinematic = plan_robustness("dlc", ["stanley"], "kinematic-bicycle")
    assert len(kinematic) == 1 + sum(len(a.values) - 1 for a in AXES if a.parameter != "road_friction_scale")


def _result(rows: list[dict]) -> RobustnessResult:
    axis = Axis("actuation_dead_time_s", (0.0, 0.1, 0.2, 0.3), "actuation dead time", "ms", 1000.0)
    return RobustnessResult(pd.DataFrame(rows), "dlc", "truck", ("a",), "ideal", 30.0, axes=(axis,))


def _row(delay: float | None, status: str = "completed", cycle: bool = False, cte: float = 0.1) -> dict:
    return {
        "controller": "a",
        "actuation_dead_time_s": delay,
        "status": status,
        "limit_cycle": cycle,
        "max_abs_cte_m": cte,
        "steer_oscillation_deg": 1.0,
    }


def test_the_tolerance_is_the_last_value_passed_going_outward_and_says_why_it_fails() -> None:
    rows = [_row(None), _row(0.1), _row(0.2, cycle=True), _row(0.3, status="left_path")]
    table = _result(rows).tolerance()
    assert table.to_dict("records") == [
        {
            "controller": "a",
            "factor": "actuation dead time",
            "unit": "ms",
            "tolerated": 100.0,
            "fails_at": 200.0,
            "how": "limit cycle",
        }
    ]
    wide = _result([_row(None), _row(0.1, cte=0.9)]).tolerance().iloc[0]
    assert wide["tolerated"] == 0.0 and wide["fails_at"] == 100.0 and wide["how"] == "max |CTE| > 0.5 m"
    passes = _result([_row(None), _row(0.1)]).tolerance().iloc[0]
    assert pd.isna(passes["fails_at"]) and passes["how"] == "passes all" and passes["tolerated"] == 100.0


def test_the_report_is_a_page_of_the_report_writer_its_tables_scrolling() -> None:
    page = _result([_row(None), _row(0.1)]).report_html()
    assert page.startswith("<!DOCTYPE html>") and tables_scrolling(page) == [True]
    assert "<td class='number'>none</td>" in page  # never failed: no value it fails at


def test_the_command_runs_the_study_and_writes_a_self_contained_report(tmp_path: Path, capsys) -> None:
    out = tmp_path / "rob"
    code = main(
        [
            "robustness",
            "dlc",
            "--controllers",
            "stanley",
            "--vehicle",
            "kinematic-bicycle",
            "--out",
            str(out),
            "--workers",
            "1",
            "--speed",
            "20",
        ]
    )
    assert code == 0
    report = (out / "report.html").read_text()
    assert "data:image/png;base64," in report and "http" not in report.split("<body>")[1]
    assert tables_scrolling(report) and all(tables_scrolling(report))  # each table scrolls inside the page
    results = pd.read_parquet(out / "results.parquet")
    assert len(results) == len(plan_robustness("dlc", ["stanley"], "kinematic-bicycle"))
    tolerance = pd.read_csv(out / "tolerance.csv")
    assert set(tolerance["factor"]) == {"actuation dead time", "pose latency", "position noise sigma"}
    assert "stanley" in capsys.readouterr().out


def test_the_payload_axis_changes_the_plant_and_keeps_each_controller_built_for_the_nominal_payload(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Every registered controller: the plant carries the axis's payload, the controller is built for 17 000 kg."""
    from controllers import CONTROLLERS
    from workbench.apps.studies import runner

    planned = plan_robustness("dlc", list(CONTROLLERS), "tractor-semitrailer")
    runs = [r for r in planned if "payload_kg" in dict(r.values)]
    assert sorted(r.controller for r in runs) == sorted(list(CONTROLLERS) * 2)
    seen: list[tuple[str, float, float]] = []

    def make_controller(name, geometry, config, vehicle):
        return (name, vehicle.params.payload_kg)

    class Simulation:
        def __init__(self, scenario, vehicle, controller, config) -> None:
            seen.append((controller[0], vehicle.params.payload_kg, controller[1]))

        def run(self, progress: bool = False) -> None:
            return None

    monkeypatch.setattr(runner, "make_controller", make_controller)
    monkeypatch.setattr(runner, "Simulation", Simulation)
    for run in runs:
        runner.simulate(run)
    assert sorted(seen) == sorted((c, p, 17000.0) for c in CONTROLLERS for p in (8500.0, 0.0))


def test_what_the_payload_mismatch_changes_is_what_each_controller_takes_from_the_vehicle() -> None:
    """The MPCs predict with the nominal payload's model, which differs from the plant's; the clothoid controller's
    tuning is the preset's whatever the payload; Stanley and pure pursuit take no vehicle model."""
    from controllers.mpc.prediction_model import prediction_params_for
    from tuning.own_tuning import tuning_for
    from workbench.apps.robustness import OTHER_CONTROLLER_MISMATCH, PAYLOAD_MISMATCH, payload_mismatch
    from workbench.vehicles import load_vehicle

    nominal, empty = load_vehicle("tractor-semitrailer", 17000.0), load_vehicle("tractor-semitrailer", 0.0)
    assert prediction_params_for(nominal) != prediction_params_for(empty)
    assert tuning_for(nominal).filter_schedule == tuning_for(empty).filter_schedule
    assert "prediction" not in PAYLOAD_MISMATCH["clothoid"] and "keeps its tuning" in PAYLOAD_MISMATCH["clothoid"]
    for mpc in ("lmpc", "nmpc"):
        assert "predicting with the single-track model" in payload_mismatch(mpc)
    for geometric in ("stanley", "pure-pursuit"):
        assert payload_mismatch(geometric).startswith("the plant only")
    assert payload_mismatch("someone-elses") == OTHER_CONTROLLER_MISMATCH


def test_the_payload_factor_is_in_the_table_the_csv_and_stdout_with_its_measured_effect(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The truck at 30 km/h through the dlc: the lighter plant changes max |CTE| for the clothoid controller and
    Stanley alike (0.079 -> 0.147 m and 0.042 -> 0.073 m when measured); a factor passed everywhere says so."""
    out = tmp_path / "rob"
    args = ["robustness", "dlc", "--controllers", "clothoid,stanley", "--vehicle", "tractor-semitrailer"]
    assert main([*args, "--out", str(out), "--workers", "1"]) == 0
    stdout = capsys.readouterr().out
    factor = "plant payload (controller built for 17000 kg)"
    tolerance = pd.read_csv(out / "tolerance.csv")
    payload = tolerance[tolerance["factor"] == factor]
    assert list(payload["controller"]) == ["clothoid", "stanley"] and (payload["unit"] == "kg").all()
    assert factor in stdout and "NaN" not in stdout
    for how, fails_at in zip(tolerance["how"], tolerance["fails_at"], strict=True):
        assert (how == "passes all") == pd.isna(fails_at) and isinstance(how, str) and how
    assert "payload: the plant carries 17000, 8500, 0 kg, every controller is built for 17000 kg" in stdout
    results = pd.read_parquet(out / "results.parquet")
    factors = [a.parameter for a in robustness_axes("tractor-semitrailer") if a.parameter in results]
    for controller in ("clothoid", "stanley"):
        own = results[results["controller"] == controller]
        empty, base = own[own["payload_kg"] == 0.0], own[own[factors].isna().all(axis=1)]
        assert len(empty) == 1 and len(base) == 1 and empty["controller_payload_kg"].iloc[0] == 17000.0
        assert empty["max_abs_cte_m"].iloc[0] > 1.3 * base["max_abs_cte_m"].iloc[0]
        assert f"  {controller}: max |CTE| " in stdout
    report = (out / "report.html").read_text()
    assert "Payload mismatch" in report and "keeps its tuning" in report


@pytest.mark.parametrize(
    ("args", "needle"),
    [(["--controllers", "nope"], "unknown controller"), (["--controllers", "stanley", "--max-cte", "0"], "--max-cte")],
)
def test_bad_robustness_input_exits_2(args: list[str], needle: str, tmp_path: Path, capsys) -> None:
    code = main(["robustness", "dlc", "--vehicle", "kinematic-bicycle", "--out", str(tmp_path / "o"), *args])
    assert code == 2 and needle in capsys.readouterr().err
