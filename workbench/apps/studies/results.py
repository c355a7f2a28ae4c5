"""The result of a sweep: the table of runs (one row per run: its parameters, the metrics.json fields, status,
message), its summary, its figures and its report (one self-contained HTML page, `report.html_page`)."""

from __future__ import annotations

import html
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import pandas as pd

from workbench.apps.studies import plots
from workbench.apps.studies.runner import TIMING_COLUMNS
from workbench.apps.studies.store import RESULTS_FILE, rows_frame
from workbench.base.errors import WorkbenchInputError

if TYPE_CHECKING:
    from matplotlib.axes import Axes

#: The figures a sweep writes: file name, SweepResult method.
FIGURES: tuple[tuple[str, str], ...] = (("cte_vs_speed.png", "plot_cte_vs_speed"), ("pareto.png", "plot_pareto"))
#: The report of a sweep, in its folder.
REPORT_FILE = "report.html"
#: The most runs the report's table lists (the first ones, in the study's order; results.parquet holds them all).
REPORT_MAX_ROWS = 1000
#: The metrics of each run in the report's table, with their headings.
REPORT_METRICS: tuple[tuple[str, str], ...] = (
    ("status", "status"),
    ("rms_cte_m", "RMS CTE (m)"),
    ("max_abs_cte_m", "max |CTE| (m)"),
    ("rms_steer_rate_deg_s", "RMS steering rate (deg/s)"),
    ("steer_oscillation_deg", "steering oscillation (deg)"),
    ("limit_cycle", "limit cycle"),
)


@dataclass(frozen=True, eq=False)
class SweepResult:
    """The runs of a sweep as one table, and where it is stored."""

    table: pd.DataFrame  # one row per run, in the study's order
    out_dir: Path | None = None  # where the sweep is stored (None: nowhere)
    ran: int = 0  # >= 0; runs executed in the call that produced it (the others were already stored)

    @classmethod
    def from_rows(cls, rows: Sequence[Mapping[str, Any]], out_dir: Path | None = None, ran: int = 0) -> SweepResult:
        """A result from the runs' rows (`runner.execute_run`), their columns in the order results.parquet has.

        Parameters
        ----------
        rows : sequence of mapping
            One row per run, in the study's order.
        out_dir : pathlib.Path or None
            Where the sweep is stored (None: nowhere; `save_report` and `save_figures` then need a folder).
        ran : int
            How many of the runs executed in the call that produced the rows.

        Returns
        -------
        SweepResult
            The table of the rows.
        """
        return cls(rows_frame(rows), out_dir, ran)

    @classmethod
    def load(cls, out_dir: str | Path) -> SweepResult:
        """The sweep stored in out_dir (its results.parquet).

        Parameters
        ----------
        out_dir : str or pathlib.Path
            The folder a sweep wrote (`run_sweep`, ``workbench sweep --out``).

        Returns
        -------
        SweepResult
            Its table, with `ran` 0.

        Raises
        ------
        WorkbenchInputError
            out_dir holds no results.parquet.

        Examples
        --------
        >>> from workbench.apps.studies import SweepResult
        >>> result = SweepResult.load("runs/sweep-dlc")  # doctest: +SKIP
        >>> result.summary()  # doctest: +SKIP
        """
        path = Path(out_dir) / RESULTS_FILE
        if not path.is_file():
            raise WorkbenchInputError(f"{str(path)!r} does not exist; run `workbench sweep SPEC --out {out_dir}` first")
        return cls(pd.read_parquet(path), Path(out_dir))

    def to_pandas(self) -> pd.DataFrame:
        """The runs table (a copy).

        Returns
        -------
        pandas.DataFrame
            One row per run in the study's order: its parameters, the metrics.json fields, status and message.
        """
        return self.table.copy()

    def reproducible(self) -> pd.DataFrame:
        """The table without the wall-clock columns (TIMING_COLUMNS): what equal studies give bit for bit.

        Returns
        -------
        pandas.DataFrame
            The runs table less the timing columns.
        """
        return self.table.drop(columns=[c for c in TIMING_COLUMNS if c in self.table.columns])

    def status_counts(self) -> dict[str, int]:
        """How many runs ended with each status.

        Returns
        -------
        dict of str to int
            Status ("completed", "error", "left_path", ...) -> number of runs, the statuses in order of first
            appearance.
        """
        return {str(k): int(v) for k, v in self.table["status"].value_counts(sort=False).items()}

    def summary(self) -> pd.DataFrame:
        """Per scenario, vehicle and controller: runs, completed, errors, and over the completed runs the median
        RMS CTE, the worst max |CTE|, the median RMS steering rate and steering oscillation, and how many
        limit-cycle (`workbench.simulation.limit_cycle`).

        Returns
        -------
        pandas.DataFrame
            One row per (scenario, vehicle, controller): runs, completed, errors, median_rms_cte_m,
            worst_max_abs_cte_m, median_rms_steer_rate_deg_s, median_steer_oscillation_deg, limit_cycles.
        """
        table = self.table.assign(
            is_completed=self.table["status"] == "completed",
            is_error=self.table["status"] == "error",
            has_limit_cycle=self.table["limit_cycle"].eq(True),
        )
        done = table[table["is_completed"]]
        keys = ["scenario", "vehicle", "controller"]
        counts = table.groupby(keys, sort=False).agg(
            runs=("run_id", "size"), completed=("is_completed", "sum"), errors=("is_error", "sum")
        )
        stats = done.groupby(keys, sort=False).agg(
            median_rms_cte_m=("rms_cte_m", "median"),
            worst_max_abs_cte_m=("max_abs_cte_m", "max"),
            median_rms_steer_rate_deg_s=("rms_steer_rate_deg_s", "median"),
            median_steer_oscillation_deg=("steer_oscillation_deg", "median"),
            limit_cycles=("has_limit_cycle", "sum"),
        )
        return counts.join(stats).reset_index()

    def errors(self) -> pd.DataFrame:
        """The runs that raised: their parameters and messages.

        Returns
        -------
        pandas.DataFrame
            The rows with status "error" (a copy), empty when none raised.
        """
        return self.table[self.table["status"] == "error"].copy()

    def plot_cte_vs_speed(self, ax: Axes | None = None, metric: str = "rms_cte_m") -> Axes:
        """`metric` of every completed run against its speed (points) and the median per speed (line), per
        scenario, vehicle and controller (`plots.cte_vs_speed`).

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            The axes to draw on (None: a fresh figure's).
        metric : str
            The column drawn, a numeric column of the table, e.g. "rms_cte_m" or "max_abs_cte_m" (m).

        Returns
        -------
        matplotlib.axes.Axes
            The axes drawn on.
        """
        return plots.cte_vs_speed(self.table, ax, metric)

    def plot_pareto(
        self, ax: Axes | None = None, effort: str = "rms_steer_rate_deg_s", error: str = "rms_cte_m"
    ) -> Axes:
        """The Pareto fronts, each front point numbered as its row of `pareto_fronts()`.

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            The axes to draw on (None: a fresh figure's).
        effort : str
            The column on the x axis (steering effort), a numeric column of the table, e.g. "rms_steer_rate_deg_s".
        error : str
            The column on the y axis (tracking error), a numeric column of the table, e.g. "rms_cte_m".

        Returns
        -------
        matplotlib.axes.Axes
            The axes drawn on.
        """
        return plots.pareto(self.table, ax, effort, error, label_columns=self.swept())

    def pareto_fronts(self, effort: str = "rms_steer_rate_deg_s", error: str = "rms_cte_m") -> pd.DataFrame:
        """The runs on each Pareto front with their swept values (`plots.pareto_fronts`).

        Parameters
        ----------
        effort : str
            The steering-effort column, a numeric column of the table, e.g. "rms_steer_rate_deg_s".
        error : str
            The tracking-error column, a numeric column of the table, e.g. "rms_cte_m".

        Returns
        -------
        pandas.DataFrame
            Per series, its front's runs by increasing effort: series, point (its number on `plot_pareto`'s
            figure), the swept values that vary within the series, effort and error.
        """
        return plots.pareto_fronts(self.table, self.swept(), effort, error)

    def swept(self) -> list[str]:
        """The parameter columns that take more than one value in this sweep (`plots.swept_columns`).

        Returns
        -------
        list of str
            Column names, in the table's order.
        """
        return plots.swept_columns(self.table)

    def report_html(self, title: str = "Sweep") -> str:
        """The sweep's report: what was swept, the summary per scenario, vehicle and controller, the first error
        messages, a table of the runs (their swept values and metrics; at most REPORT_MAX_ROWS), then the figures:
        RMS CTE against speed and each other numeric swept parameter, and the Pareto fronts, numbered, with a
        table of each front point's swept values.

        Parameters
        ----------
        title : str
            The page's title and first heading (plain text).

        Returns
        -------
        str
            One self-contained HTML page, its figures embedded.
        """
        from workbench.apps.report import figure_png, html_page, png_figure, text_table

        swept = self.swept()
        counts = ", ".join(f"{n} {status}" for status, n in self.status_counts().items())
        values = "; ".join(f"{c}: {', '.join(plots.shown_value(v) for v in self._values(c))}" for c in swept)
        intro = f"{len(self.table)} runs: {counts}. Swept: {values or 'nothing'}."
        body = ["<h2>Summary</h2>", text_table(self.summary())]
        errors = list(dict.fromkeys(self.errors()["message"]))
        if errors:
            body.append("<h2>Errors</h2>")
            body += [f"<p class='failed'>{html.escape(str(m))}</p>" for m in errors[:5]]
        keys = [k for k in ("scenario", "vehicle", "controller") if self.table[k].nunique() > 1] or ["controller"]
        runs = self.table[[*keys, *swept, *(c for c, _ in REPORT_METRICS)]].head(REPORT_MAX_ROWS)
        runs = runs.rename(columns=dict(REPORT_METRICS))
        more = len(self.table) > REPORT_MAX_ROWS
        shown = f" (the first {REPORT_MAX_ROWS:,}; results.parquet holds all)" if more else ""
        body += [f"<h2>Runs{shown}</h2>", text_table(runs)]
        body.append("<h2>Figures</h2>")
        numeric = [c for c in swept if pd.api.types.is_numeric_dtype(self.table[c].dropna())]
        for column in ["speed_kmh", *(c for c in numeric if c != "speed_kmh")]:
            ax = plots.metric_vs_parameter(self.table, column)
            body.append(png_figure(figure_png(ax.figure), f"RMS CTE against {column}"))
        caption = "Tracking error against steering effort; the Pareto-front points numbered as in the table below"
        body.append(png_figure(figure_png(self.plot_pareto().figure), caption))
        body += ["<h2>Pareto fronts: the swept values of each point</h2>", text_table(self.pareto_fronts())]
        return html_page(title, body, intro)

    def _values(self, column: str) -> list[Any]:
        """The distinct values of a column, in the order they first appear (missing ones left out)."""
        return list(dict.fromkeys(self.table[column].dropna().tolist()))

    def save_report(self, out_dir: str | Path | None = None, title: str = "Sweep") -> Path:
        """Write the report (`report_html`) to out_dir/REPORT_FILE (default: the sweep's folder); return its path.

        Parameters
        ----------
        out_dir : str or pathlib.Path or None
            An existing folder to write report.html to (None: the sweep's folder).
        title : str
            The page's title and first heading (plain text).

        Returns
        -------
        pathlib.Path
            The file written.

        Raises
        ------
        WorkbenchInputError
            No out_dir and the result has no folder (made by `from_rows` without one).
        """
        out = Path(out_dir) if out_dir is not None else self.out_dir
        if out is None:
            raise WorkbenchInputError("save_report needs an output folder")
        path = out / REPORT_FILE
        path.write_text(self.report_html(title), encoding="utf-8")
        return path

    def save_figures(self, out_dir: str | Path | None = None) -> list[Path]:
        """Write the figures (FIGURES) as PNG to out_dir (default: the sweep's folder); return their paths.

        Parameters
        ----------
        out_dir : str or pathlib.Path or None
            An existing folder to write to (None: the sweep's folder).

        Returns
        -------
        list of pathlib.Path
            The files written, in the order of `FIGURES`.

        Raises
        ------
        WorkbenchInputError
            No out_dir and the result has no folder (made by `from_rows` without one).
        """
        import matplotlib.pyplot as plt

        out = Path(out_dir) if out_dir is not None else self.out_dir
        if out is None:
            raise WorkbenchInputError("save_figures needs an output folder")
        written = []
        for name, method in FIGURES:
            ax = getattr(self, method)()
            ax.figure.savefig(out / name, dpi=110)
            plt.close(ax.figure)
            written.append(out / name)
        return written


__all__ = ["FIGURES", "REPORT_FILE", "REPORT_MAX_ROWS", "SweepResult"]
