"""Side-by-side comparisons: one row per controller and plant, failures kept, the report self-contained."""

from __future__ import annotations

import base64
import math
import re
from html.parser import HTMLParser
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
import pytest
from matplotlib.colors import to_rgba

from workbench.apps.comparison import (
    CONVERGED_CTE_M,
    FIGURES,
    RunSpec,
    approach_end,
    compare,
    converge_distance_m,
    step_time_ratios,
)
from workbench.apps.report import ReportSection, render_report, write_report
from workbench.base.errors import WorkbenchInputError
from workbench.simulation.metrics import METRIC_KEYS
from workbench.simulation.plots import CONTROLLER_COLOURS, VEHICLE_LINE_STYLES, Stretch, run_styles
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


def _run_lines(ax, labels: list[str]) -> dict[str, tuple[tuple[float, ...], object]]:
    """Each run's line on the axes (by its label): its colour (RGBA) and line style."""
    lines = {line.get_label(): line for line in ax.get_lines()}
    return {label: (to_rgba(lines[label].get_color()), lines[label].get_linestyle()) for label in labels}


def test_each_figure_draws_a_colour_per_controller_and_a_style_per_vehicle(comparison) -> None:
    """Alike on the four figures: runs of one controller share a colour, runs on one vehicle a line style, and no two
    controllers (vehicles) share one."""
    drawn = []
    for _, method in FIGURES:
        ax = getattr(comparison, method)()
        drawn.append(_run_lines(ax, comparison.labels))
        plt.close(ax.figure)
    assert all(styles == drawn[0] for styles in drawn[1:])  # the same on every figure
    styles = drawn[0]
    for a in RUNS:
        for b in RUNS:
            colour_a, line_a = styles[a.label]
            colour_b, line_b = styles[b.label]
            assert (colour_a == colour_b) == (a.controller == b.controller)
            assert (line_a == line_b) == (a.vehicle == b.vehicle)


def test_run_styles_three_controllers_on_two_vehicles() -> None:
    controllers = ["clothoid", "stanley", "pure-pursuit"] * 2
    vehicles = ["kinematic-bicycle"] * 3 + ["dynamic-bicycle"] * 3
    styles = run_styles(controllers, vehicles)
    assert [s.colour for s in styles] == list(CONTROLLER_COLOURS[:3]) * 2
    assert [s.line_style for s in styles] == [VEHICLE_LINE_STYLES[0]] * 3 + [VEHICLE_LINE_STYLES[1]] * 3
    assert len({(s.colour, s.line_style) for s in styles}) == 6


def test_the_trajectories_inset_bounds_the_hardest_stretch(comparison) -> None:
    """One inset, on the stretch round the largest |CTE| any run has once on the path, showing every run there."""
    stretch = comparison.hardest_stretch()
    peak, where = -1.0, math.nan
    for result in comparison.results:  # the largest |CTE| after each run's approach, found here on its own
        cte = np.abs(result.trace["cte_m"])
        on_path = np.flatnonzero(cte <= CONVERGED_CTE_M)[0]
        k = on_path + int(np.argmax(cte[on_path:]))
        if cte[k] > peak:
            peak, where = float(cte[k]), float(result.trace["progress_m"][k])
    assert stretch.from_m < where < stretch.to_m and f"{peak:.3g} m" in stretch.reason
    ax = comparison.plot_trajectories()
    (inset,) = ax.child_axes
    (x0, x1), (y0, y1) = inset.get_xlim(), inset.get_ylim()
    for result in comparison.results:
        progress = result.trace["progress_m"]
        there = (progress >= stretch.from_m) & (progress <= stretch.to_m)
        assert there.any()
        x, y = result.trace["x_m"][there], result.trace["y_m"][there]
        assert x0 <= x.min() and x.max() <= x1 and y0 <= y.min() and y.max() <= y1
    # a magnified view: the inset spans the stretch, not the course
    assert max(x1 - x0, y1 - y0) < 0.5 * min(np.ptp(ax.get_xlim()), np.ptp(ax.get_ylim()))
    courses = {result.scenario.description for result in comparison.results}  # the dlc: sized per vehicle
    assert len(inset.get_lines()) == len(courses) + len(RUNS)  # each course's reference and every run
    plt.close(ax.figure)
    # the CTE figure shades the same stretch
    ax = comparison.plot_cte()
    (span,) = [p for p in ax.patches if p.get_label() == "the trajectories' inset"]
    corners = span.get_path().transformed(span.get_patch_transform()).vertices  # a Rectangle or a Polygon
    assert corners[:, 0].min() == pytest.approx(stretch.from_m) and corners[:, 0].max() == pytest.approx(stretch.to_m)
    plt.close(ax.figure)


@pytest.mark.parametrize(
    ("cte", "expected"), [([1.0, 0.5, 0.05, 0.2], 2), ([0.0, 0.3], 0), ([1.0, 0.9], 0)]
)
def test_approach_end(cte: list[float], expected: int) -> None:
    assert approach_end(np.array(cte)) == expected


def test_a_stretch_runs_forward() -> None:
    with pytest.raises(WorkbenchInputError, match="from_m must be below to_m; got from_m = 5, to_m = 2"):
        Stretch(5.0, 2.0)
