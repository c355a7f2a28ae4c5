"""`workbench fig17`: the published and fair sets, the convergence measures and view, same-plant step-time ratios,
the paper's statements beside our numbers, a progress line, and a speed axis that does not magnify noise.

fig17 runs once for the module (about 10 s: four runs and the report); every test reads its output."""

from __future__ import annotations

import io
import math
from contextlib import redirect_stderr, redirect_stdout
from html.parser import HTMLParser
from types import SimpleNamespace

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
import pytest
from report_helpers import tables_scrolling

from workbench.apps.cli import main
from workbench.apps.fig17 import (
    CONVERGENCE_VIEW_M,
    FAIR,
    PAPER_STATEMENTS,
    max_cte_after_convergence_m,
    overshoot_m,
)
from workbench.simulation import plots
from workbench.simulation.plots import SPEED_AXIS_MIN_HALF_SPAN_FRACTION, SPEED_AXIS_MIN_HALF_SPAN_KMH


class _Terminal(io.StringIO):
    """stderr as a terminal, where the CLI shows its progress line."""

    def isatty(self) -> bool:
        return True


@pytest.fixture(scope="module")
def fig17(tmp_path_factory: pytest.TempPathFactory) -> SimpleNamespace:
    out = tmp_path_factory.mktemp("fig17") / "out"
    stdout, stderr = io.StringIO(), _Terminal()
    with redirect_stdout(stdout), redirect_stderr(stderr):
        code = main(["fig17", "--out", str(out)])
    return SimpleNamespace(out=out, code=code, stdout=stdout.getvalue(), stderr=stderr.getvalue())


class _Tables(HTMLParser):
    """The report's tables (cell text by row) and the headings before them."""

    def __init__(self) -> None:
        super().__init__()
        self.tables: list[tuple[str, list[list[str]]]] = []
        self._heading, self._in, self._text = "", "", ""

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        if tag == "table":
            self.tables.append((self._heading, []))
        elif tag == "tr":
            self.tables[-1][1].append([])
        if tag in ("h2", "td", "th"):
            self._in, self._text = tag, ""

    def handle_data(self, data: str) -> None:
        self._text += data

    def handle_endtag(self, tag: str) -> None:
        if tag == "h2":
            self._heading = self._text
        elif tag in ("td", "th"):
            self.tables[-1][1][-1].append(self._text)


def _tables(html: str) -> dict[str, pd.DataFrame]:
    parser = _Tables()
    parser.feed(html)
    return {heading: pd.DataFrame(rows[1:], columns=rows[0]) for heading, rows in parser.tables}


def test_fig17_writes_the_published_and_fair_sets(fig17: SimpleNamespace) -> None:
    assert fig17.code == 0
    summary = pd.read_csv(fig17.out / "summary.csv")
    assert len(summary) == 4 and set(summary["controller"]) == {"clothoid", "nmpc"}
    assert set(summary["vehicle"]) == {"tractor-semitrailer", "dynamic-bicycle"}
    # every run starts 1 m off the path and converges onto it
    assert summary["max_abs_cte_m"].min() == pytest.approx(1.0, abs=0.01)
    assert summary["converge_distance_m"].notna().all() and (summary["converge_distance_m"] > 0).all()
    assert (summary.loc[summary["controller"] == "clothoid", "step_time_ratio"] == 1.0).all()
    for prefix in ("", "published_"):
        for name in ("trajectories", "cte_vs_distance", "speed_vs_distance", "steering_vs_time"):
            assert (fig17.out / f"{prefix}{name}.png").stat().st_size > 10_000
        assert (fig17.out / f"{prefix}convergence_first_{CONVERGENCE_VIEW_M:g}m.png").stat().st_size > 10_000
    html = (fig17.out / "report.html").read_text(encoding="utf-8")
    # two sections, each: four comparison figures and the convergence view
    assert html.count("data:image/png;base64,") == 10
    assert str(fig17.out / "report.html") in fig17.stdout


def test_the_summary_adds_overshoot_and_max_cte_after_convergence(fig17: SimpleNamespace) -> None:
    summary = pd.read_csv(fig17.out / "summary.csv")
    for spec, row in zip(FAIR, summary.itertuples(), strict=True):
        trace = pd.read_parquet(fig17.out / "runs" / spec.slug / "trace.parquet")
        progress, cte = trace["progress_m"].to_numpy(), trace["cte_m"].to_numpy()
        # once converged, on the curves (from 40 m), |CTE| is well inside the 0.1 m tolerance and below the offset
        after = (progress - progress[0]) >= max(row.converge_distance_m, 40.0)
        assert row.max_abs_cte_after_convergence_m == pytest.approx(np.max(np.abs(cte[after])), abs=1e-3)
        assert 0.0 < row.max_abs_cte_after_convergence_m < 0.1
        assert row.overshoot_m == pytest.approx(max(0.0, -np.min(cte)))  # started left (+), crosses to the right
        assert row.speed_spread_kmh == pytest.approx(np.ptp(trace["speed_mps"]) * 3.6)


def test_the_report_names_the_start_offset_and_shows_the_convergence_view(fig17: SimpleNamespace) -> None:
    html = (fig17.out / "report.html").read_text(encoding="utf-8")
    tables = _tables(html)
    for heading in ("As published: clothoid on the truck, NMPC on the car", "Fair: each controller on each plant"):
        columns = list(tables[heading].columns)
        assert "max |CTE| (m; the 1 m start offset)" in columns
        assert "max |CTE| after convergence (m)" in columns and "overshoot (m)" in columns
        assert columns.index("max |CTE| after convergence (m)") > columns.index("converged within 0.1 m after (m)")
        assert f"{heading}: convergence in the first {CONVERGENCE_VIEW_M:g} m" in html
    fair = tables["Fair: each controller on each plant"]
    summary = pd.read_csv(fig17.out / "summary.csv")
    assert list(fair["max |CTE| after convergence (m)"]) == [
        f"{v:.3g}" for v in summary["max_abs_cte_after_convergence_m"]
    ]


def test_the_tables_scroll_in_the_page_and_show_the_step_times_first(fig17: SimpleNamespace) -> None:
    """The step-time columns (the headline) follow the run's status, in view at the table's left; every table sits
    in the element that scrolls it sideways when it is wider than the page."""
    page = (fig17.out / "report.html").read_text(encoding="utf-8")
    assert tables_scrolling(page) == [True, True, True]  # beside the paper, published, fair
    for table in list(_tables(page).values())[1:]:
        assert list(table.columns)[2:6] == ["status", "step time / clothoid's", "step median (µs)", "step p99 (µs)"]


def test_the_published_ratio_is_over_the_clothoid_on_the_same_plant(fig17: SimpleNamespace) -> None:
    summary = pd.read_csv(fig17.out / "summary.csv").set_index(["controller", "vehicle"])["step_time_median_us"]
    published = _tables((fig17.out / "report.html").read_text(encoding="utf-8"))[
        "As published: clothoid on the truck, NMPC on the car"
    ].set_index(["controller", "vehicle"])["step time / clothoid's"]
    car = "dynamic-bicycle"
    assert published[("nmpc", car)] == f"{summary[('nmpc', car)] / summary[('clothoid', car)]:.3g}"
    assert published[("clothoid", "tractor-semitrailer")] == "1"


def test_the_paper_statements_stand_beside_our_numbers(fig17: SimpleNamespace) -> None:
    paper = pd.read_csv(fig17.out / "paper_vs_ours.csv")
    assert list(paper["figure"]) == [figure for figure, *_ in PAPER_STATEMENTS]
    summary = pd.read_csv(fig17.out / "summary.csv").set_index(["controller", "vehicle"])
    converge = paper.iloc[0]
    truck, car = summary.loc[("clothoid", "tractor-semitrailer")], summary.loc[("nmpc", "dynamic-bicycle")]
    assert converge["ours: clothoid on the truck, NMPC on the car"] == (
        f"clothoid {truck.converge_distance_m:.3g} m, NMPC {car.converge_distance_m:.3g} m"
    )
    html = (fig17.out / "report.html").read_text(encoding="utf-8")
    assert "Beside the paper (section 6.6)" in html and html.index("Beside the paper") < html.index("As published")


def test_a_progress_line_counts_the_runs(fig17: SimpleNamespace) -> None:
    assert f"0/{len(FAIR)} [" in fig17.stderr  # the line counts the runs (compare's bar) and names each
    for spec in FAIR:
        assert spec.label in fig17.stderr


def test_the_speed_axis_spans_at_least_its_minimum(fig17: SimpleNamespace) -> None:
    runs = [
        SimpleNamespace(trace={k: t[k].to_numpy() for k in ("progress_m", "speed_mps", "speed_ref_mps")})
        for t in (pd.read_parquet(fig17.out / "runs" / spec.slug / "trace.parquet") for spec in FAIR)
    ]
    ax = plots.speed_comparison(runs, [s.label for s in FAIR])
    low, high = ax.get_ylim()
    half = max(SPEED_AXIS_MIN_HALF_SPAN_KMH, SPEED_AXIS_MIN_HALF_SPAN_FRACTION * 30.0)
    assert high - low == pytest.approx(2.0 * half, abs=1e-3)  # the runs hold 30 km/h within a few m/h
    plt.close(ax.figure)
    assert low < 30.0 < high
    # a speed that really varies keeps its own span
    varying = SimpleNamespace(trace={"progress_m": np.arange(3.0), "speed_mps": np.array([3.0, 8.0, 5.0])})
    varying.trace["speed_ref_mps"] = varying.trace["speed_mps"]
    ax = plots.speed_vs_distance(varying)
    low, high = ax.get_ylim()
    assert low <= 3.0 * 3.6 and high >= 8.0 * 3.6 and high - low < 2.0 * 8.0 * 3.6
    plt.close(ax.figure)


@pytest.mark.parametrize(
    ("cte", "from_m", "expected"),
    [
        ([1.0, 0.5, 0.05, -0.02, 0.04, 0.01], 0.0, 0.05),  # within 0.1 m from the third sample on
        ([1.0, 0.5, 0.05, -0.02, 0.04, 0.01], 3.0, 0.04),  # from 3 m (the curves), later than convergence
        ([1.0, 0.5, 0.2], 0.0, math.nan),  # never converged
    ],
)
def test_max_cte_after_convergence(cte: list[float], from_m: float, expected: float) -> None:
    got = max_cte_after_convergence_m(np.arange(len(cte), dtype=float), np.array(cte), from_m)
    assert (math.isnan(got) and math.isnan(expected)) or got == expected


@pytest.mark.parametrize(
    ("cte", "expected"), [([1.0, 0.2, -0.15, 0.0], 0.15), ([-1.0, -0.2, 0.3, 0.0], 0.3), ([1.0, 0.5, 0.0], 0.0)]
)
def test_overshoot(cte: list[float], expected: float) -> None:
    assert overshoot_m(np.array(cte)) == expected
