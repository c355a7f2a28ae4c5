"""The result of a sweep: the table of runs (one row per run: its parameters, the metrics.json fields, status,
message), its summary and its figures."""

from __future__ import annotations

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


@dataclass(frozen=True, eq=False)
class SweepResult:
    """table: one row per run, in the study's order; out_dir: where it is stored; ran: how many runs executed in
    the call that produced it (the others were already stored)."""

    table: pd.DataFrame
    out_dir: Path | None = None
    ran: int = 0

    @classmethod
    def from_rows(cls, rows: Sequence[Mapping[str, Any]], out_dir: Path | None = None, ran: int = 0) -> SweepResult:
        return cls(rows_frame(rows), out_dir, ran)

    @classmethod
    def load(cls, out_dir: str | Path) -> SweepResult:
        """The sweep stored in out_dir (its results.parquet)."""
        path = Path(out_dir) / RESULTS_FILE
        if not path.is_file():
            raise WorkbenchInputError(f"{str(path)!r} does not exist; run `workbench sweep SPEC --out {out_dir}` first")
        return cls(pd.read_parquet(path), Path(out_dir))

    def to_pandas(self) -> pd.DataFrame:
        """The runs table (a copy)."""
        return self.table.copy()

    def reproducible(self) -> pd.DataFrame:
        """The table without the wall-clock columns (TIMING_COLUMNS): what equal studies give bit for bit."""
        return self.table.drop(columns=[c for c in TIMING_COLUMNS if c in self.table.columns])

    def status_counts(self) -> dict[str, int]:
        """How many runs ended with each status."""
        return {str(k): int(v) for k, v in self.table["status"].value_counts(sort=False).items()}

    def summary(self) -> pd.DataFrame:
        """Per scenario, vehicle and controller: runs, completed, errors, and over the completed runs the median
        RMS CTE, the worst max |CTE|, the median RMS steering rate and steering oscillation, and how many
        limit-cycle (`workbench.simulation.limit_cycle`)."""
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
        """The runs that raised: their parameters and messages."""
        return self.table[self.table["status"] == "error"].copy()

    def plot_cte_vs_speed(self, ax: Axes | None = None, metric: str = "rms_cte_m") -> Axes:
        return plots.cte_vs_speed(self.table, ax, metric)

    def plot_pareto(
        self, ax: Axes | None = None, effort: str = "rms_steer_rate_deg_s", error: str = "rms_cte_m"
    ) -> Axes:
        return plots.pareto(self.table, ax, effort, error)

    def save_figures(self, out_dir: str | Path | None = None) -> list[Path]:
        """Write the figures (FIGURES) as PNG to out_dir (default: the sweep's folder); return their paths."""
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


__all__ = ["FIGURES", "SweepResult"]
