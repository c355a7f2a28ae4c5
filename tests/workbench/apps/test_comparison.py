"""Side-by-side comparisons: one row per controller and plant, failures kept, the report self-contained."""

from __future__ import annotations

import base64
import math
import re
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from workbench.apps.comparison import RunSpec, compare, converge_distance_m, step_time_ratios
from workbench.apps.report import ReportSection, render_report, write_report
from workbench.base.errors import WorkbenchInputError
from workbench.simulation.metrics import METRIC_KEYS
from workbench.simulation.simulator import SimulationConfig

RUNS = (
    RunSpec("pure-pursuit", "kinematic-bicycle"),
    RunSpec("stanley", "kinematic-bicycle"),
    RunSpec("pure-pursuit", "dynamic-bicycle"),
)


@pytest.fixture(scope="module")
def comparison():
    return compare("dlc", RUNS, SimulationConfig(speed_kmh=30.0), reference_controller="pure-pursuit")


def test_summary_has_one_row_per_controller_and_plant_with_the_run_metrics(comparison) -> None:
    table = comparison.summary()
    assert list(zip(table["controller"], table["vehicle"], strict=True)) == [(r.controller, r.vehicle) for r in RUNS]
    assert set(METRIC_KEYS) <= set(table.columns)
    for row, result in zip(table.itertuples(), comparison.results, strict=True):
        assert row.max_abs_cte_m == pytest.approx(float(np.max(np.abs(result.trace["cte_m"]))), rel=1e-12)
        assert row.status == "completed"
    # the reference controller's ratio is 1 on its own plant; the others are their median over its median
    assert table["step_time_ratio"].iloc[0] == pytest.approx(1.0)
    assert table["step_time_ratio"].iloc[1] == pytest.approx(
        table["step_time_median_us"].iloc[1] / table["step_time_median_us"].iloc[0]
    )
    assert table["step_time_ratio"].iloc[2] == pytest.approx(1.0)


def test_saved_files_round_trip(comparison, tmp_path: Path) -> None:
    written = comparison.save(tmp_path)
    assert all(p.is_file() and p.stat().st_size > 0 for p in written)
    summary = pd.read_csv(tmp_path / "summary.csv")
    assert len(summary) == len(RUNS)
    for spec in RUNS:
        trace = pd.read_parquet(tmp_path / "runs" / spec.slug / "trace.parquet")
        assert len(trace) > 100 and (tmp_path / "runs" / spec.slug / "metrics.json").is_file()
    stacked = comparison.to_pandas()
    assert set(stacked["run"]) == {r.label for r in RUNS}


class _Checker(HTMLParser):
    """Well-formedness of the tags that must close, and every src/href."""

    VOID = frozenset({"meta", "img", "br", "hr", "link", "input"})

    def __init__(self) -> None:
        super().__init__()
        self.stack: list[str] = []
        self.sources: list[str] = []
        self.errors: list[str] = []

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        self.sources += [v or "" for k, v in attrs if k in ("src", "href")]
        if tag not in self.VOID:
            self.stack.append(tag)

    def handle_endtag(self, tag: str) -> None:
        if not self.stack or self.stack[-1] != tag:
            self.errors.append(f"</{tag}> closes {self.stack[-1:] or 'nothing'}")
        else:
            self.stack.pop()


def test_report_is_valid_html_with_its_images_embedded(comparison, tmp_path: Path) -> None:
    path = write_report(tmp_path / "r" / "report.html", "t", [ReportSection("s", "text <&>", comparison)])
    text = path.read_text(encoding="utf-8")
    assert text.startswith("<!DOCTYPE html>")
    checker = _Checker()
    checker.feed(text)
    checker.close()
    assert checker.errors == [] and checker.stack == []
    assert len(checker.sources) == 4  # the four figures, nothing else
    for src in checker.sources:
        assert src.startswith("data:image/png;base64,")
        assert base64.b64decode(src.split(",", 1)[1])[:8] == b"\x89PNG\r\n\x1a\n"
    assert "text &lt;&amp;&gt;" in text  # user text is escaped
    assert len(re.findall(r"<tr", text)) == 1 + len(RUNS)


def test_the_report_says_which_run_limit_cycles() -> None:
    # Stanley at 8/s weaves on the loaded truck (tests/workbench/test_metrics.py); at its default it does not
    runs = (RunSpec("stanley", "tractor-semitrailer"), RunSpec("stanley", "tractor-semitrailer", ("gain_per_s=8",)))
    weaving = compare("dlc", runs)
    quiet_cycle, cycle = weaving.limit_cycles()
    assert not quiet_cycle.detected and cycle.detected and cycle.duration_s >= 3.0
    table = weaving.summary()
    assert list(table["limit_cycle"]) == [False, True] and table["limit_cycle_hz"].iloc[1] == cycle.frequency_hz
    html = render_report("t", [ReportSection("s", "", weaving)])
    for heading in ("RMS steering rate (deg/s)", "steering oscillation (deg)", "limit cycle"):
        assert f"<th>{heading}</th>" in html
    assert "<td>no</td>" in html and f"<td>{cycle.brief()}</td>" in html
    line = f"Limit cycle: stanley (gain_per_s=8) on tractor-semitrailer oscillates at {cycle.describe()}."
    assert line in html and html.count("Limit cycle:") == 1
    assert re.search(r"at 0\.\d\d Hz, ±\d+° steering wheel for \d+\.\d s from t = \d+\.\d s\.", line)


def test_a_failed_run_keeps_its_row_and_says_why() -> None:
    # fig17 starts 1 m off the path: a 0.5 m leave-the-path bound stops every run at once
    failing = compare("fig17", RUNS[:1], SimulationConfig(max_abs_cte_m=0.5))
    row = failing.summary().iloc[0]
    assert row["status"] == "left_path" and "0.5" in row["message"]
    html = render_report("t", [ReportSection("s", "", failing)])
    assert 'class="failed"' in html and "left_path" in html


@pytest.mark.parametrize(
    ("progress", "cte", "expected"),
    [
        ([0.0, 1.0, 2.0, 3.0], [1.0, 0.5, 0.05, 0.0], 2.0),  # within 0.1 m from the third sample on
        ([0.0, 1.0, 2.0], [0.0, 0.05, -0.02], 0.0),  # never outside
        ([0.0, 1.0, 2.0], [1.0, 0.05, 0.2], math.nan),  # outside at the end
        ([5.0, 6.0, 7.0, 8.0], [1.0, 0.05, 0.3, 0.0], 3.0),  # left again, came back: the last return counts
    ],
)
def test_converge_distance(progress: list[float], cte: list[float], expected: float) -> None:
    got = converge_distance_m(np.array(progress), np.array(cte))
    assert (math.isnan(got) and math.isnan(expected)) or got == expected


@pytest.mark.parametrize(
    ("kwargs", "needle"),
    [
        ({"controller": "mpc2", "vehicle": "kinematic-bicycle"}, "unknown controller 'mpc2'"),
        ({"controller": "stanley", "vehicle": "bus"}, "unknown vehicle 'bus'"),
    ],
)
def test_bad_run_specs_are_named(kwargs: dict, needle: str) -> None:
    with pytest.raises(WorkbenchInputError, match=needle):
        RunSpec(**kwargs)


def test_empty_or_repeated_runs_are_refused() -> None:
    with pytest.raises(WorkbenchInputError, match="at least one"):
        compare("dlc", [])
    with pytest.raises(WorkbenchInputError, match="once"):
        compare("dlc", [RUNS[0], RUNS[0]])


def test_step_time_ratio_with_the_reference_run_more_than_once_on_a_plant() -> None:
    # two clothoid runs (different options) on the truck, one on the car; nmpc on the truck and on a plant the
    # reference never ran on
    table = pd.DataFrame(
        {
            "controller": ["clothoid", "clothoid", "nmpc", "clothoid", "nmpc"],
            "vehicle": ["truck", "truck", "truck", "car", "bus"],
            "step_time_median_us": [40.0, 60.0, 500.0, 30.0, 700.0],
        }
    )
    ratios = step_time_ratios(table, "clothoid")
    assert ratios == pytest.approx([0.8, 1.2, 10.0, 1.0, 700.0 / 40.0])  # bus: over the median of all clothoid runs
    assert all(math.isnan(r) for r in step_time_ratios(table, None))
    assert all(math.isnan(r) for r in step_time_ratios(table, "stanley"))
