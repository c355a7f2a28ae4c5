"""The robustness study (issue 18, item 4): one factor at a time, through the study backends, a report with the
degradation curves and the values at which each controller stops passing."""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest
from report_helpers import tables_scrolling

from workbench.apps.cli import main
from workbench.apps.robustness import AXES, Axis, RobustnessResult, plan_robustness


def test_the_plan_varies_one_factor_at_a_time_and_adds_the_payload_mismatch_for_a_truck() -> None:
    runs = plan_robustness("dlc", ["clothoid", "stanley"], "tractor-semitrailer")
    per_controller = 1 + sum(len(a.values) - 1 for a in AXES) + 2
    assert len(runs) == 2 * per_controller and len({r.run_id for r in runs}) == len(runs)
    assert [r.index for r in runs] == list(range(len(runs)))
    for run in runs:
        varied = [a.parameter for a in AXES if a.parameter in dict(run.values)]
        assert len(varied) <= 1
    mismatch = [dict(r.values) for r in runs if "controller_payload_kg" in dict(r.values)]
    assert {(v["payload_kg"], v["controller_payload_kg"]) for v in mismatch} == {(0.0, 17000.0), (17000.0, 0.0)}
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
    assert pd.isna(_result([_row(None), _row(0.1)]).tolerance().iloc[0]["fails_at"])


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


@pytest.mark.parametrize(
    ("args", "needle"),
    [(["--controllers", "nope"], "unknown controller"), (["--controllers", "stanley", "--max-cte", "0"], "--max-cte")],
)
def test_bad_robustness_input_exits_2(args: list[str], needle: str, tmp_path: Path, capsys) -> None:
    code = main(["robustness", "dlc", "--vehicle", "kinematic-bicycle", "--out", str(tmp_path / "o"), *args])
    assert code == 2 and needle in capsys.readouterr().err
