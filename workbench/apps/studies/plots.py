"""Figures of a study's results table: a metric against a swept parameter (speed, or any other) per controller,
and the Pareto front of CTE against steering effort, its points labelled with the values swept. Each draws on the
given axes (or a new figure) and returns the axes; only completed runs are drawn (a run that left the path has no
meaningful CTE figure)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

from workbench.apps.studies.runner import RESULT_COLUMNS

if TYPE_CHECKING:
    from matplotlib.axes import Axes

LABELS = {
    "rms_cte_m": "RMS CTE (m)",
    "max_abs_cte_m": "max |CTE| (m)",
    "max_abs_cte_on_path_m": "max |CTE| once on the path (m)",
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
    several), each with its label.

    Parameters
    ----------
    table : pandas.DataFrame
        A study's results table (`SweepResult.table`).

    Returns
    -------
    list of tuple of (str, pandas.DataFrame)
        (label, the series' completed runs), in the table's order.
    """
    done = table[table["status"] == "completed"]
    keys = ["controller"] + [k for k in ("vehicle", "scenario") if table[k].nunique() > 1]
    out = []
    for values, group in done.groupby(keys, sort=False):
        values = values if isinstance(values, tuple) else (values,)
        label = str(values[0]) + "".join(f", {v}" for v in values[1:])
        out.append((label, group))
    return out


def swept_columns(table: pd.DataFrame) -> list[str]:
    """The parameter columns of a results table that take more than one value (`PlannedRun.parameters`: run
    parameters and `<controller>.<option>` columns; speed_kmh included), in the table's order.

    Parameters
    ----------
    table : pandas.DataFrame
        A study's results table (`SweepResult.table`).

    Returns
    -------
    list of str
        The swept columns' names.
    """
    fixed = {"run_id", "index", "scenario", "controller", "vehicle", "sample", "trial", *RESULT_COLUMNS}
    return [c for c in table.columns if c not in fixed and table[c].dropna().astype(str).nunique() > 1]


def shown_value(value: object) -> str:
    """A parameter's value as figures and reports show it: a float to 3 significant digits, anything else as text.

    Parameters
    ----------
    value : object
        A parameter's value.

    Returns
    -------
    str
        The value as text.

    Examples
    --------
    >>> from workbench.apps.studies.plots import shown_value
    >>> shown_value(0.012345), shown_value(40), shown_value("adaptive")
    ('0.0123', '40', 'adaptive')
    """
    return f"{value:.3g}" if isinstance(value, float | np.floating) else str(value)


def value_label(row: pd.Series, columns: list[str]) -> str:
    """The row's values of `columns` as `name=value` text (`shown_value`; missing ones left out), controller
    options without their controller's prefix.

    Parameters
    ----------
    row : pandas.Series
        A run's row of a results table.
    columns : list of str
        The columns to show, in order.

    Returns
    -------
    str
        "name=value" parts joined by ", ".
    """
    parts = []
    for column in columns:
        value = row[column]
        if value is None or (isinstance(value, float) and np.isnan(value)):
            continue
        parts.append(f"{column.split('.', 1)[-1]}={shown_value(value)}")
    return ", ".join(parts)


def pareto_mask(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """True where (x, y) is on the Pareto front of minimising both: no other point is at least as good in both and
    better in one. NaN points are never on it.

    Parameters
    ----------
    x, y : numpy.ndarray
        The two objectives of each point, shape (n,), both minimised.

    Returns
    -------
    numpy.ndarray
        Booleans, shape (n,).

    Examples
    --------
    >>> import numpy as np
    >>> from workbench.apps.studies.plots import pareto_mask
    >>> pareto_mask(np.array([1.0, 2.0, 3.0, 0.5]), np.array([3.0, 2.0, 3.0, 4.0])).tolist()
    [True, True, False, True]
    """
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
    """`metric` of every completed run against its speed (points) and the median per speed (line), per series.

    Parameters
    ----------
    table : pandas.DataFrame
        A study's results table (`SweepResult.table`).
    ax : matplotlib.axes.Axes, optional
        The axes to draw on (None: a fresh pyplot figure's).
    metric : str
        The column drawn, e.g. "rms_cte_m".

    Returns
    -------
    matplotlib.axes.Axes
        The axes drawn on.
    """
    return metric_vs_parameter(table, "speed_kmh", ax, metric)


def metric_vs_parameter(table: pd.DataFrame, parameter: str, ax: Axes | None = None, metric: str = "rms_cte_m") -> Axes:
    """`metric` of every completed run against a numeric parameter column (points) and the median per value
    (line), per series; a series without the parameter (another controller's option) is left out.

    Parameters
    ----------
    table : pandas.DataFrame
        A study's results table (`SweepResult.table`).
    parameter : str
        A numeric parameter column (x).
    ax : matplotlib.axes.Axes, optional
        The axes to draw on (None: a fresh pyplot figure's).
    metric : str
        The column drawn (y), e.g. "rms_cte_m".

    Returns
    -------
    matplotlib.axes.Axes
        The axes drawn on.
    """
    ax = _axes(ax)
    for i, (label, group) in enumerate(series(table)):
        colour = f"C{i % 10}"
        values = group[[parameter, metric]].astype(float).dropna(subset=[parameter])
        if values.empty:
            continue
        ax.scatter(values[parameter], values[metric], s=10, alpha=0.35, color=colour, linewidths=0)
        median = values.groupby(parameter)[metric].median()
        ax.plot(median.index, median.to_numpy(), "o-", color=colour, label=f"{label} (median)")
    name = LABELS.get(parameter, parameter)
    ax.set(xlabel=name, ylabel=LABELS.get(metric, metric), title=f"{LABELS.get(metric, metric)} vs {name}")
    ax.grid(alpha=0.3)
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize="small")
    return ax


def pareto(
    table: pd.DataFrame,
    ax: Axes | None = None,
    effort: str = "rms_steer_rate_deg_s",
    error: str = "rms_cte_m",
    label_columns: list[str] | None = None,
) -> Axes:
    """Every completed run as (steering effort, tracking error), per series, with its Pareto front (runs no other
    run of the series beats in both) as a line. With `label_columns`, each front point is numbered as its row of
    `pareto_fronts(table, label_columns, ...)`, which holds its swept values (a front is often too dense for the
    values themselves to be legible on it).

    Parameters
    ----------
    table : pandas.DataFrame
        A study's results table (`SweepResult.table`).
    ax : matplotlib.axes.Axes, optional
        The axes to draw on (None: a fresh pyplot figure's).
    effort : str
        The steering-effort column (x), e.g. "rms_steer_rate_deg_s".
    error : str
        The tracking-error column (y), e.g. "rms_cte_m".
    label_columns : list of str or None
        The swept columns of the front's table (None: the points are not numbered).

    Returns
    -------
    matplotlib.axes.Axes
        The axes drawn on.
    """
    ax = _axes(ax)
    for i, (label, group) in enumerate(series(table)):
        colour = f"C{i % 10}"
        x, y = group[effort].to_numpy(dtype=float), group[error].to_numpy(dtype=float)
        ax.scatter(x, y, s=10, alpha=0.35, color=colour, linewidths=0)
        front = pareto_mask(x, y)
        order = np.argsort(x[front])
        ax.plot(x[front][order], y[front][order], "o-", drawstyle="steps-post", color=colour, label=f"{label} front")
        if label_columns:
            for number, (xi, yi) in enumerate(zip(x[front][order], y[front][order], strict=True), start=1):
                ax.annotate(str(number), (xi, yi), xytext=(3, 3), textcoords="offset points", fontsize=7, color=colour)
    ax.set(
        xlabel=LABELS.get(effort, effort),
        ylabel=LABELS.get(error, error),
        title="Tracking error against steering effort (line: Pareto front)",
    )
    ax.grid(alpha=0.3)
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize="small")
    return ax


def pareto_fronts(
    table: pd.DataFrame,
    label_columns: list[str],
    effort: str = "rms_steer_rate_deg_s",
    error: str = "rms_cte_m",
) -> pd.DataFrame:
    """The runs on each series' Pareto front (`pareto`), by increasing effort: series, point (its number on the
    figure), the values of `label_columns` that vary within the series (`value_label`), effort and error.

    Parameters
    ----------
    table : pandas.DataFrame
        A study's results table (`SweepResult.table`).
    label_columns : list of str
        The swept columns (`swept_columns`).
    effort : str
        The steering-effort column (x), e.g. "rms_steer_rate_deg_s".
    error : str
        The tracking-error column (y), e.g. "rms_cte_m".

    Returns
    -------
    pandas.DataFrame
        One row per front point: series, point, "swept values", and the two objectives under their headings.
    """
    rows = []
    for label, group in series(table):
        x, y = group[effort].to_numpy(dtype=float), group[error].to_numpy(dtype=float)
        front = group[pareto_mask(x, y)].sort_values(effort, kind="stable")
        varying = [c for c in label_columns if group[c].dropna().astype(str).nunique() > 1]
        for number, (_, row) in enumerate(front.iterrows(), start=1):
            rows.append(
                {
                    "series": label,
                    "point": number,
                    "swept values": value_label(row, varying),
                    LABELS.get(effort, effort): row[effort],
                    LABELS.get(error, error): row[error],
                }
            )
    return pd.DataFrame(rows)


__all__ = [
    "cte_vs_speed",
    "metric_vs_parameter",
    "pareto",
    "pareto_fronts",
    "pareto_mask",
    "series",
    "shown_value",
    "swept_columns",
    "value_label",
]
