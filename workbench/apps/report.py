"""The side-by-side report: one self-contained HTML file (figures embedded as base64 PNG, no external links), so
it can be mailed, archived and read offline.

A report has sections; each shows one `Comparison`: a short text, the course each vehicle ran (a scenario sized for
the vehicle, e.g. the dlc's lanes and cones, differs between vehicles), its summary table (one row per controller
and plant) with what its step-time ratio is divided by, a line naming each run whose steering limit-cycles
(`simulation/limit_cycle.py`: frequency, steering-wheel amplitude, duration, start), its four figures (Figures
17a/b and 18a/b of the paper: trajectories, CTE against distance, speed against distance, steering against time)
and any further figures the section brings. Tables of text (`ReportTable`, e.g. the paper's statements beside our
numbers) may come before the sections.

The page, its tables of text and its embedded figures (`html_page`, `text_table`, `png_figure`) are also what
`workbench paper` writes its index with.
"""

from __future__ import annotations

import base64
import html
import io
import math
import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from datetime import UTC, datetime
from pathlib import Path
from typing import TYPE_CHECKING, TypeGuard

import numpy as np
import pandas as pd

from workbench.apps.comparison import CONVERGED_CTE_M, FIGURES, Comparison
from workbench.simulation.limit_cycle import LimitCycle

if TYPE_CHECKING:
    from matplotlib.figure import Figure, SubFigure

#: Summary columns shown in the report, with their headings (the CSV keeps every column).
TABLE_COLUMNS: tuple[tuple[str, str], ...] = (
    ("controller", "controller"),
    ("vehicle", "vehicle"),
    ("status", "status"),
    ("max_abs_cte_m", "max |CTE| (m)"),
    ("rms_cte_m", "RMS CTE (m)"),
    ("converge_distance_m", f"converged within {CONVERGED_CTE_M:g} m after (m)"),
    ("max_abs_steer_wheel_deg", "max |steering wheel| (deg)"),
    ("max_abs_steer_rate_deg_s", "max |steering rate| (deg/s)"),
    ("rms_steer_rate_deg_s", "RMS steering rate (deg/s)"),
    ("steer_oscillation_deg", "steering oscillation (deg)"),
    ("limit_cycle", "limit cycle"),
    ("max_abs_lat_accel_g", "max |lateral accel.| (g)"),
    ("max_ltr", "max LTR"),
    ("max_offtracking_m", "max off-tracking (m)"),
    ("step_time_median_us", "step median (µs)"),
    ("step_time_p99_us", "step p99 (µs)"),
    ("step_time_ratio", "step time / clothoid's"),
)
#: Resolution of the embedded figures (dots per inch): a figure of 8 x 4.5 in is 800 x 450 pixels, shown at that
#: size (one to a row) so that its legend reads as it was drawn.
FIGURE_DPI = 100

#: Class of the element every table of a page sits in: it scrolls sideways when the table is wider than the page,
#: so the page itself never does (`html_page` puts each table in one).
TABLE_SCROLL_CLASS = "table-scroll"

_STYLE = """
body { font-family: system-ui, sans-serif; margin: 2em auto; padding: 0 1.5em; max-width: 110em; color: #222; }
p, ul, h1, h2, figcaption { max-width: 72em; }
.table-scroll { overflow-x: auto; max-width: 100%; margin: 1em 0; }
table { border-collapse: collapse; font-size: 0.85em; font-variant-numeric: tabular-nums; }
th, td { border: 1px solid #bbb; padding: 0.2em 0.35em; text-align: right; }
th { background: #eee; vertical-align: bottom; } td:nth-child(-n+3) { text-align: left; }
table.text th, table.text td { text-align: left; vertical-align: top; } table.text td.number { text-align: right; }
figure { display: block; margin: 1em 0; } img { max-width: 100%; }
figcaption { font-size: 0.9em; color: #444; }
.failed, .warning { color: #b00; }
"""


@dataclass(frozen=True)
class ReportFigure:
    """A further figure of a section: its caption and what draws it (the figure is closed once embedded)."""

    caption: str  # the caption, plain text
    draw: Callable[[], Figure]  # draws the figure when the report is written


@dataclass(frozen=True)
class ReportTable:
    """A table of text before the sections."""

    heading: str  # the table's heading
    text: str  # explanatory text before it, plain
    frame: pd.DataFrame  # its rows, every cell as text


@dataclass(frozen=True)
class ReportSection:
    """One section of a report: a comparison's table and figures under a heading.

    A `summary` given has the same rows as the comparison's own `summary()`, e.g. with step-time ratios taken from
    a larger comparison (the text then says what they divide by), or with further columns.
    """

    heading: str  # the section's heading
    text: str  # explanatory text, plain
    comparison: Comparison  # the comparison it shows
    summary: pd.DataFrame | None = None  # the table shown instead of the comparison's `summary()` (None: that)
    columns: tuple[tuple[str, str], ...] = TABLE_COLUMNS  # the summary columns shown: (column, heading) pairs
    figures: tuple[ReportFigure, ...] = field(default=())  # further figures after the four comparison figures


#: What a table shows for a missing number (None or NaN), unless the table says otherwise.
MISSING = "–"
#: Numbers from this magnitude on are shown whole, their thousands grouped (12,345 rather than 1.23e+04).
WHOLE_FROM = 999.5


def number_text(value: float | None, missing: str = MISSING) -> str:
    """A number as a table shows it: three significant digits (0.0466, 23.8, 269), whole with its thousands grouped
    from WHOLE_FROM on (1,234), `missing` for None or NaN.

    Parameters
    ----------
    value : float or None
        The number, in whatever unit its column states.
    missing : str
        What None or NaN shows as.

    Returns
    -------
    str
        The number as text.

    Examples
    --------
    >>> from workbench.apps.report import number_text
    >>> number_text(0.046637), number_text(23.84), number_text(12345.6), number_text(float("nan"))
    ('0.0466', '23.8', '12,346', '–')
    """
    if value is None or math.isnan(value):
        return missing
    if abs(value) >= WHOLE_FROM:
        return f"{value:,.0f}"
    return f"{value:.3g}"


def _is_number(value: object) -> TypeGuard[float | int | np.number]:
    """Whether a cell holds a number (not a flag: True shows as True)."""
    return isinstance(value, float | int | np.number) and not isinstance(value, bool | np.bool_)


def _is_missing(value: object) -> bool:
    return value is None or value is pd.NA or (_is_number(value) and math.isnan(float(value)))


def _cell(value: object, missing: str = MISSING) -> str:
    if _is_missing(value):
        return missing
    if _is_number(value):
        return number_text(float(value), missing)
    return html.escape(str(value))


def _table(summary: pd.DataFrame, cycles: Sequence[LimitCycle], columns: Sequence[tuple[str, str]]) -> str:
    head = "".join(f"<th>{html.escape(title)}</th>" for _, title in columns)
    rows = []
    for (_, row), cycle in zip(summary.iterrows(), cycles, strict=True):
        cls = "" if row["status"] == "completed" else ' class="failed"'
        values = {key: row.get(key) for key, _ in columns}
        if "limit_cycle" in values:
            values["limit_cycle"] = cycle.brief()
        cells = "".join(f"<td>{_cell(value)}</td>" for value in values.values())
        rows.append(f"<tr{cls}>{cells}</tr>")
    failed = summary[summary["status"] != "completed"]
    notes = "".join(
        f"<p class='failed'>{html.escape(r.controller)} on {html.escape(r.vehicle)}: {html.escape(r.message)}</p>"
        for r in failed.itertuples()
    )
    return f"<table><tr>{head}</tr>{''.join(rows)}</table>{notes}"


def text_table(frame: pd.DataFrame, missing: str = MISSING) -> str:
    """A table of text cells (escaped) and numbers (`number_text`, right-aligned), its columns as headings; a missing
    number shows as `missing`.

    Parameters
    ----------
    frame : pandas.DataFrame
        The rows to show; its index is not shown.
    missing : str
        What a missing number (None, NaN or pandas.NA) shows as.

    Returns
    -------
    str
        An HTML ``<table class='text'>`` element.
    """
    head = "".join(f"<th>{html.escape(str(c))}</th>" for c in frame.columns)

    def cell(value: object) -> str:
        numeric = _is_missing(value) or _is_number(value)
        return f"<td class='number'>{_cell(value, missing)}</td>" if numeric else f"<td>{_cell(value)}</td>"

    rows = "".join("<tr>" + "".join(cell(v) for v in row) + "</tr>" for row in frame.itertuples(index=False))
    return f"<table class='text'><tr>{head}</tr>{rows}</table>"


def png_figure(png: bytes, caption: str) -> str:
    """A figure element with the PNG embedded (base64) and its caption (plain) as alt text and caption.

    Parameters
    ----------
    png : bytes
        The image, PNG-encoded (`figure_png`).
    caption : str
        Plain text (escaped here).

    Returns
    -------
    str
        An HTML ``<figure>`` element.
    """
    alt = html.escape(caption)
    data = base64.b64encode(png).decode("ascii")
    return f'<figure><img alt="{alt}" src="data:image/png;base64,{data}"><figcaption>{alt}</figcaption></figure>'


def figure_png(fig: Figure | SubFigure) -> bytes:
    """The figure (an axes' `.figure`: the root figure of a subfigure) as PNG at FIGURE_DPI; the figure is closed.

    Parameters
    ----------
    fig : matplotlib.figure.Figure or matplotlib.figure.SubFigure
        The figure to encode; a subfigure's root figure is encoded and closed.

    Returns
    -------
    bytes
        The PNG file's content.
    """
    import matplotlib.pyplot as plt

    root = fig.get_figure(root=True)
    buffer = io.BytesIO()
    root.savefig(buffer, format="png", dpi=FIGURE_DPI)
    plt.close(root)
    return buffer.getvalue()


_TABLE = re.compile(r"<table\b.*?</table>", re.DOTALL | re.IGNORECASE)


def scrolling_tables(body: str) -> str:
    """body with each table put in a TABLE_SCROLL_CLASS element, which scrolls sideways when the table is wider than
    the page (tables are not nested in these reports: each runs to its first closing tag).

    Parameters
    ----------
    body : str
        HTML whose ``<table>`` elements are not nested.

    Returns
    -------
    str
        The same HTML, each table wrapped in a ``<div class="table-scroll">``.
    """
    return _TABLE.sub(lambda table: f'<div class="{TABLE_SCROLL_CLASS}">{table.group(0)}</div>', body)


def html_page(title: str, body: Sequence[str], intro: str = "") -> str:
    """A whole HTML document: the title, the intro (plain), when it was generated, then the body's parts (HTML), each
    of its tables in a sideways-scrolling element (`scrolling_tables`). Every report of the workbench is written as
    such a page, so that no table runs off the page.

    Parameters
    ----------
    title : str
        The page's title and first heading (plain text).
    body : sequence of str
        The page's parts in order, each HTML.
    intro : str
        A paragraph under the title (plain text; "" for none).

    Returns
    -------
    str
        The whole document, self-contained (its style inline, no external links).
    """
    parts = [
        "<!DOCTYPE html>",
        '<html lang="en"><head><meta charset="utf-8">',
        f"<title>{html.escape(title)}</title><style>{_STYLE}</style></head><body>",
        f"<h1>{html.escape(title)}</h1>",
        f"<p>{html.escape(intro)}</p>" if intro else "",
        f"<p><small>Generated {datetime.now(UTC):%Y-%m-%d %H:%M} UTC by the lateral-control workbench.</small></p>",
        *(scrolling_tables(part) for part in body),
        "</body></html>",
    ]
    return "\n".join(p for p in parts if p)


def _courses(c: Comparison) -> str:
    """The course of the runs: the scenario and its description when every vehicle ran the same one, else the
    scenario's name and each course (its lanes and cones) with the vehicles that ran it."""
    by_course: dict[str, list[str]] = {}
    for spec, result in zip(c.specs, c.results, strict=True):
        vehicles = by_course.setdefault(result.scenario.description, [])
        if spec.vehicle not in vehicles:
            vehicles.append(spec.vehicle)
    name = html.escape(c.scenario.name)
    if len(by_course) == 1:
        return f"<p>Scenario <b>{name}</b> ({html.escape(c.scenario.description)}).</p>"
    items = "".join(
        f"<li>for {html.escape(', '.join(vehicles))}: {html.escape(description)}</li>"
        for description, vehicles in by_course.items()
    )
    return f"<p>Scenario <b>{name}</b>, a course for each vehicle:</p><ul>{items}</ul>"


def _ratio_note(summary: pd.DataFrame, reference: str | None) -> str:
    """What the step-time ratio divides by: the reference controller's median on the same vehicle, and where the
    reference did not run on a vehicle, the median of all its runs (`comparison.step_time_ratios`)."""
    if reference is None or "step_time_ratio" not in summary or reference not in set(summary["controller"]):
        return ""
    own = set(summary.loc[summary["controller"] == reference, "vehicle"])
    without = [v for v in dict.fromkeys(summary["vehicle"]) if v not in own]
    note = f"Step time / {reference}'s: each run's median step time over the {reference} controller's on its vehicle"
    if without:
        note += f" (on {', '.join(without)}, where it did not run: over the median of all its runs)"
    return f"<p><small>{html.escape(note)}.</small></p>"


def _section(section: ReportSection) -> list[str]:
    c = section.comparison
    summary = c.summary() if section.summary is None else section.summary
    cfg = c.config
    parts = [f"<h2>{html.escape(section.heading)}</h2>"]
    if section.text:
        parts.append(f"<p>{html.escape(section.text)}</p>")
    parts.append(_courses(c))
    parts.append(
        f"<p>Target speed {cfg.speed_kmh:g} km/h, lateral-acceleration bound {cfg.max_lateral_accel_g:g} g, "
        f"controllers at {cfg.controller_rate_hz:g} Hz, plant at {cfg.plant_rate_hz:g} Hz.</p>"
    )
    cycles = c.limit_cycles()
    parts.append(_table(summary, cycles, section.columns))
    if section.summary is None and any(key == "step_time_ratio" for key, _ in section.columns):
        parts.append(_ratio_note(summary, c.reference_controller))
    parts += [
        f"<p class='warning'>Limit cycle: {html.escape(spec.label)} oscillates at {html.escape(cycle.describe())}.</p>"
        for spec, cycle in zip(c.specs, cycles, strict=True)
        if cycle.detected
    ]
    for name, method in FIGURES:
        caption = f"{section.heading}: {name.removesuffix('.png').replace('_', ' ')}"
        parts.append(png_figure(figure_png(getattr(c, method)().figure), caption))
    parts += [png_figure(figure_png(f.draw()), f"{section.heading}: {f.caption}") for f in section.figures]
    return parts


def render_report(
    title: str, sections: Sequence[ReportSection], intro: str = "", tables: Sequence[ReportTable] = ()
) -> str:
    """The report as one HTML document: the tables of text, then the sections.

    Parameters
    ----------
    title : str
        The page's title and first heading (plain text).
    sections : sequence of ReportSection
        One per comparison, each with its table, course and figures, in order.
    intro : str
        A paragraph under the title (plain text; "" for none).
    tables : sequence of ReportTable
        Tables of text shown before the sections.

    Returns
    -------
    str
        The whole HTML document, its figures embedded.
    """
    body: list[str] = []
    for table in tables:
        body.append(f"<h2>{html.escape(table.heading)}</h2>")
        if table.text:
            body.append(f"<p>{html.escape(table.text)}</p>")
        body.append(text_table(table.frame))
    for section in sections:
        body += _section(section)
    return html_page(title, body, intro)


def write_report(
    path: str | Path,
    title: str,
    sections: Sequence[ReportSection],
    intro: str = "",
    tables: Sequence[ReportTable] = (),
) -> Path:
    """Write the report to `path` (its directory is created); return the path.

    Parameters
    ----------
    path : str or pathlib.Path
        The HTML file to write (replaced if it exists).
    title : str
        The page's title and first heading (plain text).
    sections : sequence of ReportSection
        One per comparison, each with its table, course and figures, in order.
    intro : str
        A paragraph under the title (plain text; "" for none).
    tables : sequence of ReportTable
        Tables of text shown before the sections.

    Returns
    -------
    pathlib.Path
        The file written.

    Examples
    --------
    >>> from workbench.apps.comparison import RunSpec, compare
    >>> from workbench.apps.report import ReportSection, write_report
    >>> runs = [RunSpec("clothoid", "kinematic-bicycle"), RunSpec("stanley", "kinematic-bicycle")]
    >>> result = compare("dlc", runs)  # doctest: +SKIP
    >>> section = ReportSection("Double lane change", "Two controllers, kinematic bicycle.", result)  # doctest: +SKIP
    >>> write_report("out/report.html", "Clothoid against Stanley", [section])  # doctest: +SKIP
    PosixPath('out/report.html')
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(render_report(title, sections, intro, tables), encoding="utf-8")
    return path


__all__ = [
    "FIGURE_DPI",
    "MISSING",
    "TABLE_COLUMNS",
    "TABLE_SCROLL_CLASS",
    "WHOLE_FROM",
    "ReportFigure",
    "ReportSection",
    "ReportTable",
    "figure_png",
    "html_page",
    "number_text",
    "png_figure",
    "render_report",
    "scrolling_tables",
    "text_table",
    "write_report",
]
