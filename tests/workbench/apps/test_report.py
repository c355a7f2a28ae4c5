"""The side-by-side report: each vehicle's own course, what the step-time ratio divides by, a section's own table,
columns and further figures, tables of text before the sections; every table of every report in an element that
scrolls sideways, and its numbers formatted alike."""

from __future__ import annotations

import html
import math
import re
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
import pytest
from report_helpers import tables_scrolling

from workbench.apps.comparison import RunSpec, compare
from workbench.apps.paper import PaperResult, write_paper_report
from workbench.apps.report import (
    TABLE_SCROLL_CLASS,
    ReportFigure,
    ReportSection,
    ReportTable,
    html_page,
    number_text,
    render_report,
    text_table,
    write_report,
)

#: The packages whose modules may write HTML (the repository's root: tests/workbench/apps/ is three levels down).
ROOT = Path(__file__).resolve().parents[3]
PACKAGES = ("workbench", "tuning", "controllers", "benchmarks")
#: What writes an HTML page or table: a closing table or html tag, a doctype, pandas' HTML writer.
HTML_WRITING = re.compile(r"</table>|<!DOCTYPE|</html>|\.to_html\(", re.IGNORECASE)

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
    assert "Beside &lt;the paper&gt;" in text and "said &amp; done" in text
    assert "<td>x &lt; y</td><td class='number'>–</td>" in text
    assert text.index("Beside &lt;the paper&gt;") < text.index("<h2>s</h2>")


def test_every_table_of_a_report_scrolls_inside_the_page(two_courses, tmp_path: Path) -> None:
    """The summary tables and the tables of text, and any table a section's text brings, each in the scrolling
    element: a table wider than the page scrolls inside it, the page never does."""
    tables = [ReportTable("before", "", pd.DataFrame({"a": ["x"], "b": [1.0]}))]
    path = write_report(tmp_path / "report.html", "t", [ReportSection("s", "", two_courses)], tables=tables)
    page = path.read_text(encoding="utf-8")
    assert tables_scrolling(page) == [True, True]
    assert f".{TABLE_SCROLL_CLASS} {{ overflow-x: auto;" in page
    # a page of any report: a table written by hand into its body scrolls as well
    by_hand = html_page("t", ["<p>x</p><table><tr><td>1</td></tr></table>", text_table(pd.DataFrame({"a": [1]}))])
    assert tables_scrolling(by_hand) == [True, True]
    assert tables_scrolling("<html><body><table><tr><td>1</td></tr></table></body></html>") == [False]


def test_the_paper_report_s_tables_scroll(tmp_path: Path) -> None:
    table = pd.DataFrame(
        {"quantity": ["figure8 max |CTE|"], "paper": ["below 0.4 m (Figure 11b)"], "ours": [0.09], "unit": ["m"]}
    )
    png = tmp_path / "fig11a_trajectory_figure8.png"
    fig, _ = plt.subplots()
    fig.savefig(png)
    plt.close(fig)
    page = write_paper_report(tmp_path / "report.html", PaperResult([png], table)).read_text(encoding="utf-8")
    assert tables_scrolling(page) == [True, True]  # our numbers beside the paper's; Figure 11's table


def test_only_the_report_writer_writes_html() -> None:
    """Every report is a page of `report.html_page` (which puts each table in the scrolling element): no other
    module writes a page or a table of its own."""
    writers = sorted(
        str(path.relative_to(ROOT))
        for package in PACKAGES
        for path in (ROOT / package).rglob("*.py")
        if HTML_WRITING.search(path.read_text(encoding="utf-8"))
    )
    assert writers == ["workbench/apps/report.py"]


@pytest.mark.parametrize(
    ("value", "expected"),
    [
        (0.046612, "0.0466"),
        (23.84, "23.8"),
        (1.0, "1"),
        (0.0, "0"),
        (-0.00148, "-0.00148"),
        (999.4, "999"),
        (999.5, "1,000"),  # whole from here on: never 1e+03
        (13046.2, "13,046"),
        (-25000.0, "-25,000"),
        (math.nan, "–"),
        (None, "–"),
    ],
)
def test_numbers_show_three_significant_digits_or_whole_with_grouped_thousands(value, expected: str) -> None:
    assert number_text(value) == expected


def test_text_tables_right_align_numbers_and_name_what_is_missing() -> None:
    frame = pd.DataFrame({"what": ["a", "b"], "value": [np.float64(12345.6), math.nan], "count": [np.int64(3), 4]})
    text = text_table(frame, missing="none")
    assert "<td>a</td><td class='number'>12,346</td><td class='number'>3</td>" in text
    assert "<td>b</td><td class='number'>none</td><td class='number'>4</td>" in text
    assert "<td class='number'>–</td>" in text_table(pd.DataFrame({"v": [None]}))
    assert "<td>True</td>" in text_table(pd.DataFrame({"flag": [True]}))  # a flag is not a number
