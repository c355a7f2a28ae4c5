"""The side-by-side report: one self-contained HTML file (figures embedded as base64 PNG, no external links), so
it can be mailed, archived and read offline.

A report has sections; each shows one `Comparison`: a short text, its summary table (one row per controller and
plant), a line naming each run whose steering limit-cycles (`simulation/limit_cycle.py`: frequency, steering-wheel
amplitude, duration, start) and its four figures (Figures 17a/b and 18a/b of the paper: trajectories, CTE against
distance, speed against distance, steering against time).
"""

from __future__ import annotations

import base64
import html
import io
import math
from collections.abc import Sequence
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path

import pandas as pd

from workbench.apps.comparison import FIGURES, Comparison
from workbench.simulation.limit_cycle import LimitCycle

#: Summary columns shown in the report, with their headings (the CSV keeps every column).
TABLE_COLUMNS: tuple[tuple[str, str], ...] = (
    ("controller", "controller"),
    ("vehicle", "vehicle"),
    ("status", "status"),
    ("max_abs_cte_m", "max |CTE| (m)"),
    ("rms_cte_m", "RMS CTE (m)"),
    ("converge_distance_m", "converged within 0.1 m after (m)"),
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

_STYLE = """
body { font-family: system-ui, sans-serif; margin: 2em auto; max-width: 72em; color: #222; }
table { border-collapse: collapse; margin: 1em 0; font-size: 0.9em; }
th, td { border: 1px solid #bbb; padding: 0.3em 0.6em; text-align: right; }
th { background: #eee; } td:nth-child(-n+3) { text-align: left; }
figure { display: inline-block; margin: 0.5em; } img { max-width: 34em; }
.failed, .warning { color: #b00; }
"""


@dataclass(frozen=True)
class ReportSection:
    """heading, explanatory text (plain), and the comparison it shows."""

    heading: str
    text: str
    comparison: Comparison


def _cell(value: object) -> str:
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "–"
    if isinstance(value, float):
        return f"{value:.3g}" if abs(value) < 1000 else f"{value:.0f}"
    return html.escape(str(value))


def _table(summary: pd.DataFrame, cycles: Sequence[LimitCycle]) -> str:
    head = "".join(f"<th>{html.escape(title)}</th>" for _, title in TABLE_COLUMNS)
    rows = []
    for (_, row), cycle in zip(summary.iterrows(), cycles, strict=True):
        cls = "" if row["status"] == "completed" else ' class="failed"'
        values = {key: row.get(key) for key, _ in TABLE_COLUMNS} | {"limit_cycle": cycle.brief()}
        cells = "".join(f"<td>{_cell(value)}</td>" for value in values.values())
        rows.append(f"<tr{cls}>{cells}</tr>")
    failed = summary[summary["status"] != "completed"]
    notes = "".join(
        f"<p class='failed'>{html.escape(r.controller)} on {html.escape(r.vehicle)}: {html.escape(r.message)}</p>"
        for r in failed.itertuples()
    )
    return f"<table><tr>{head}</tr>{''.join(rows)}</table>{notes}"


def _png(comparison: Comparison, method: str) -> str:
    import matplotlib.pyplot as plt

    ax = getattr(comparison, method)()
    buffer = io.BytesIO()
    ax.figure.savefig(buffer, format="png", dpi=100)
    plt.close(ax.figure)
    return base64.b64encode(buffer.getvalue()).decode("ascii")


def render_report(title: str, sections: Sequence[ReportSection], intro: str = "") -> str:
    """The report as one HTML document."""
    parts = [
        "<!DOCTYPE html>",
        '<html lang="en"><head><meta charset="utf-8">',
        f"<title>{html.escape(title)}</title><style>{_STYLE}</style></head><body>",
        f"<h1>{html.escape(title)}</h1>",
        f"<p>{html.escape(intro)}</p>" if intro else "",
        f"<p><small>Generated {datetime.now(UTC):%Y-%m-%d %H:%M} UTC by the lateral-control workbench.</small></p>",
    ]
    for section in sections:
        c = section.comparison
        parts.append(f"<h2>{html.escape(section.heading)}</h2>")
        if section.text:
            parts.append(f"<p>{html.escape(section.text)}</p>")
        cfg = c.config
        parts.append(
            f"<p>Scenario <b>{html.escape(c.scenario.name)}</b> ({html.escape(c.scenario.description)}); target "
            f"speed {cfg.speed_kmh:g} km/h, lateral-acceleration bound {cfg.max_lateral_accel_g:g} g, controllers "
            f"at {cfg.controller_rate_hz:g} Hz, plant at {cfg.plant_rate_hz:g} Hz.</p>"
        )
        cycles = c.limit_cycles()
        parts.append(_table(c.summary(), cycles))
        parts += [
            f"<p class='warning'>Limit cycle: {html.escape(spec.label)} oscillates at {html.escape(cycle.describe())}"
            ".</p>"
            for spec, cycle in zip(c.specs, cycles, strict=True)
            if cycle.detected
        ]
        for name, method in FIGURES:
            alt = html.escape(f"{section.heading}: {name.removesuffix('.png').replace('_', ' ')}")
            parts.append(
                f'<figure><img alt="{alt}" src="data:image/png;base64,{_png(c, method)}"><figcaption>{alt}'
                "</figcaption></figure>"
            )
    parts.append("</body></html>")
    return "\n".join(p for p in parts if p)


def write_report(path: str | Path, title: str, sections: Sequence[ReportSection], intro: str = "") -> Path:
    """Write the report to `path` (its directory is created); return the path."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(render_report(title, sections, intro), encoding="utf-8")
    return path


__all__ = ["ReportSection", "render_report", "write_report"]
