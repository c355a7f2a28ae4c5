"""Figures of a study's results table: CTE against speed per controller, and the Pareto front of CTE against
steering effort. Each draws on the given axes (or a new figure) and returns the axes; only completed runs are
drawn (a run that left the path has no meaningful CTE figure)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

if TYPE_CHECKING:
    from matplotlib.axes import Axes

LABELS = {
    "rms_cte_m": "RMS CTE (m)",
    "max_abs_cte_m": "max |CTE| (m)",
    "rms_steer_rate_deg_s": "RMS steering-wheel rate (deg/s)",
    "max_abs_steer_rate_deg_s": "max |steering-wheel rate| (deg/s)",
    "steer_oscillation_deg": "steering-wheel oscillation, RMS about its 1 s average (deg)",
    "limit_cycle_hz": "steering limit cycle (Hz)",
    "limit_cycle_amplitude_deg": "steering limit cycle, steering-wheel amplitude (deg)",
    "speed_kmh": "speed (km/h)",
}


def _axes(ax: Axes | None) -> Axes:
    import matplotlib.pyplot as plt

    if ax is None:
        _, ax = plt.subplots(figsize=(7, 4.5), layout="constrained")
    return ax


def series(table: pd.DataFrame) -> list[tuple[str, pd.DataFrame]]:
    """The completed runs grouped into one series per controller (and per vehicle and scenario when the study has
    several), each with its label."""
    done = table[table["status"] == "completed"]
    keys = ["controller"] + [k for k in ("vehicle", "scenario") if table[k].nunique() > 1]
    out = []
    for values, group in done.groupby(keys, sort=False):
        values = values if isinstance(values, tuple) else (values,)
        label = str(values[0]) + "".join(f", {v}" for v in values[1:])
        out.append((label, group))
    return out


def pareto_mask(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """True where (x, y) is on the Pareto front of minimising both: no other point is at least as good in both and
    better in one. NaN points are never on it."""
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    mask = np.zeros(x.shape, dtype=bool)
    finite = np.flatnonzero(np.isfinite(x) & np.isfinite(y))
    best = np.inf
    for i in finite[np.lexsort((y[finite], x[finite]))]:  # by x, ties by y
        if y[i] < best:
            mask[i] = True
            best = y[i]
    return mask


def cte_vs_speed(table: pd.DataFrame, ax: Axes | None = None, metric: str = "rms_cte_m") -> Axes:
    """`metric` of every completed run against its speed (points) and the median per speed (line), per series."""
    ax = _axes(ax)
    for i, (label, group) in enumerate(series(table)):
        colour = f"C{i % 10}"
        values = group[["speed_kmh", metric]].astype(float)
        ax.scatter(values["speed_kmh"], values[metric], s=10, alpha=0.35, color=colour, linewidths=0)
        median = values.groupby("speed_kmh")[metric].median()
        ax.plot(median.index, median.to_numpy(), "o-", color=colour, label=f"{label} (median)")
    ax.set(
        xlabel=LABELS["speed_kmh"], ylabel=LABELS.get(metric, metric), title=f"{LABELS.get(metric, metric)} vs speed"
    )
    ax.grid(alpha=0.3)
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize="small")
    return ax


def pareto(
    table: pd.DataFrame, ax: Axes | None = None, effort: str = "rms_steer_rate_deg_s", error: str = "rms_cte_m"
) -> Axes:
    """Every completed run as (steering effort, tracking error), per series, with its Pareto front (runs no other
    run of the series beats in both) as a line."""
    ax = _axes(ax)
    for i, (label, group) in enumerate(series(table)):
        colour = f"C{i % 10}"
        x, y = group[effort].to_numpy(dtype=float), group[error].to_numpy(dtype=float)
        ax.scatter(x, y, s=10, alpha=0.35, color=colour, linewidths=0)
        front = pareto_mask(x, y)
        order = np.argsort(x[front])
        ax.plot(x[front][order], y[front][order], "o-", drawstyle="steps-post", color=colour, label=f"{label} front")
    ax.set(
        xlabel=LABELS.get(effort, effort),
        ylabel=LABELS.get(error, error),
        title="Tracking error against steering effort (line: Pareto front)",
    )
    ax.grid(alpha=0.3)
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize="small")
    return ax


__all__ = ["cte_vs_speed", "pareto", "pareto_mask", "series"]
