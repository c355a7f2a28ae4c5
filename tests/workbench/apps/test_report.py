"""The side-by-side report: each vehicle's own course, what the step-time ratio divides by, a section's own table,
columns and further figures, and tables of text before the sections."""

from __future__ import annotations

import html

import matplotlib.pyplot as plt
import pandas as pd
import pytest

from workbench.apps.comparison import RunSpec, compare
from workbench.apps.report import ReportFigure, ReportSection, ReportTable, render_report

#: Pure pursuit on a car and on the truck: the dlc is sized for each vehicle's width.
RUNS = (RunSpec("pure-pursuit", "kinematic-bicycle"), RunSpec("pure-pursuit", "tractor-semitrailer"))


@pytest.fixture(scope="module")
def two_courses():
    return compare("dlc", RUNS, reference_controller="pure-pursuit", warn=None)


def test_each_vehicle_s_course_is_described(two_courses) -> None:
    descriptions = [r.scenario.description for r in two_courses.results]
    assert descriptions[0] != descriptions[1]  # 1.61 m and 2.59 m wide vehicles: different lanes and cones
    text = render_report("t", [ReportSection("s", "", two_courses)])
    assert "a course for each vehicle" in text
    for spec, description in zip(RUNS, descriptions, strict=True):
        assert f"<li>for {spec.vehicle}: {html.escape(description)}</li>" in text


def test_one_course_is_described_once() -> None:
    same = compare("dlc", [RunSpec("pure-pursuit", "kinematic-bicycle"), RunSpec("stanley", "kinematic-bicycle")])
    text = render_report("t", [ReportSection("s", "", same)])
    assert f"Scenario <b>dlc</b> ({html.escape(same.scenario.description)})." in text
    assert "a course for each vehicle" not in text


def test_the_step_time_ratio_says_what_it_divides_by(two_courses) -> None:
    text = render_report("t", [ReportSection("s", "", two_courses)])
    assert "over the pure-pursuit controller&#x27;s on its vehicle." in text
    # the reference on one vehicle only: the others are over the median of all its runs, and the report says so
    one = two_courses.select(RUNS[:1])
    mixed = compare("dlc", [RUNS[0], RunSpec("stanley", "tractor-semitrailer")], reference_controller="pure-pursuit")
    assert "where it did not run" not in render_report("t", [ReportSection("s", "", one)])
    assert "(on tractor-semitrailer, where it did not run: over the median of all its runs)" in render_report(
        "t", [ReportSection("s", "", mixed)]
    )


def test_a_section_may_bring_its_table_columns_and_figures(two_courses) -> None:
    table = two_courses.summary().assign(step_time_ratio=[1.0, 2.5], extra_m=[0.125, 0.25])
    columns = (("controller", "controller"), ("vehicle", "vehicle"), ("extra_m", "extra (m)"))

    def draw() -> plt.Figure:
        fig, ax = plt.subplots()
        ax.plot([0, 1], [0, 1])
        return fig

    section = ReportSection("s", "", two_courses, table, columns, (ReportFigure("a further <view>", draw),))
    tables = [ReportTable("Beside <the paper>", "said & done", pd.DataFrame({"a": ["x < y"], "b": [float("nan")]}))]
    text = render_report("t", [section], tables=tables)
    assert "<th>extra (m)</th>" in text and "<td>0.125</td><td>" not in text  # extra_m shown, last column
    assert "<td>0.125</td></tr>" in text and "<td>0.25</td></tr>" in text
    assert "<th>RMS CTE (m)</th>" not in text
    assert "Step time /" not in text  # the section's own table: its text says what its ratios are
    assert text.count("data:image/png;base64,") == 5 and "s: a further &lt;view&gt;" in text
    assert "Beside &lt;the paper&gt;" in text and "said &amp; done" in text and "<td>x &lt; y</td><td>–</td>" in text
    assert text.index("Beside &lt;the paper&gt;") < text.index("<h2>s</h2>")
