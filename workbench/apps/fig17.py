"""The paper's Figure 17/18 comparison (section 6.6): the clothoid controller against an MPC on the fig17 path at
30 km/h, the vehicle starting 1 m off the path.

The paper could only compare its clothoid controller on the TruckSim truck with an "improved MPC" on a CarSim car
(`PUBLISHED`). Here every controller also runs on every plant (`FAIR`: clothoid and NMPC on the loaded
tractor-semitrailer and on the dynamic bicycle car), so that the plant is not confounded with the controller.
`run_fig17` simulates the fair set once (a progress line counts the runs); the published pairs are a selection of
it, and their step-time ratios are the fair set's (each controller over the clothoid controller on the same plant).

Every run starts 1 m off the path, so max |CTE| is that offset: the summary adds how far the approach overshoots
the path and the max |CTE| once converged (`max_cte_after_convergence_m`), the report a zoomed view of the first
`CONVERGENCE_VIEW_M` where the runs converge, and the paper's statements about Figures 17 and 18 beside our numbers
(`paper_table`: the paper gives no values for them, only comparisons).
"""

from __future__ import annotations

import itertools
import math
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

from workbench.apps.comparison import CONVERGED_CTE_M, Comparison, RunSpec, compare, converge_distance_m
from workbench.apps.report import TABLE_COLUMNS, ReportFigure, ReportSection, ReportTable, figure_png, write_report
from workbench.simulation.simulator import SimulationConfig

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from workbench.base.path import ReferencePath

SCENARIO = "fig17"
SPEED_KMH = 30.0
TRUCK, CAR = "tractor-semitrailer", "dynamic-bicycle"
#: As published: the clothoid controller on the truck, the MPC on the car.
PUBLISHED: tuple[RunSpec, ...] = (RunSpec("clothoid", TRUCK), RunSpec("nmpc", CAR))
#: Each controller on each plant.
FAIR: tuple[RunSpec, ...] = tuple(
    RunSpec(controller, vehicle) for vehicle, controller in itertools.product((TRUCK, CAR), ("clothoid", "nmpc"))
)
#: Distance along the path (m) of the zoomed convergence view: the 40 m lead-in straight, where every run converges
#: within 0.1 m (after 9-24 m at 30 km/h), and the first clothoid into the curves.
CONVERGENCE_VIEW_M = 60.0
#: |curvature| (1/m) above which the path counts as curving (the lead-in straight's is 0 to rounding).
CURVING_1PM = 1e-6

#: Section 6.6 on Figures 17 and 18, and what of ours answers it: figure, what the paper says, our measure, its
#: summary column and unit.
PAPER_STATEMENTS: tuple[tuple[str, str, str, str, str], ...] = (
    (
        "17b",
        "The clothoid controller converges the error to zero slightly later than the MPC (no distances given).",
        f"distance to converge within {CONVERGED_CTE_M:g} m",
        "converge_distance_m",
        "m",
    ),
    (
        "17b",
        "Comparable tracking accuracy (no values given).",
        "max |CTE| after convergence",
        "max_abs_cte_after_convergence_m",
        "m",
    ),
    (
        "18a",
        "The clothoid controller holds its speed despite the curvature (the MPC study gave no speed; the paper "
        "inferred it from the MPC's steering plot).",
        "spread of the measured speed (max - min)",
        "speed_spread_kmh",
        "km/h",
    ),
    (
        "18b",
        "Peaks in the steering angle, but smooth and measured steering inputs (no values given).",
        "max |steering-wheel angle|",
        "max_abs_steer_wheel_deg",
        "deg",
    ),
    ("18b", "(as above)", "RMS steering-wheel rate", "rms_steer_rate_deg_s", "deg/s"),
)


#: The step-time columns, the replication's headline (section 6.6: the clothoid controller's cost against the MPC's).
STEP_TIME_COLUMNS = ("step_time_ratio", "step_time_median_us", "step_time_p99_us")


def _fig17_columns() -> tuple[tuple[str, str], ...]:
    """The report's columns: the step times first after the run's status (the headline, in view without scrolling),
    max |CTE| named as the start offset it is, and the approach's overshoot and the max |CTE| once converged beside
    the distance to converge."""
    titles = dict(TABLE_COLUMNS)
    columns = []
    for key, title in TABLE_COLUMNS:
        if key in STEP_TIME_COLUMNS:
            continue
        columns.append((key, "max |CTE| (m; the 1 m start offset)" if key == "max_abs_cte_m" else title))
        if key == "status":
            columns += [(step, titles[step]) for step in STEP_TIME_COLUMNS]
        if key == "converge_distance_m":
            columns += [
                ("overshoot_m", "overshoot (m)"),
                ("max_abs_cte_after_convergence_m", "max |CTE| after convergence (m)"),
            ]
    return tuple(columns)


#: The fig17 table's columns (`_fig17_columns`).
FIG17_COLUMNS = _fig17_columns()


def curves_start_m(path: ReferencePath) -> float:
    """Arc length (m) where the path first curves (|curvature| above CURVING_1PM): the end of its lead-in straight.

    Parameters
    ----------
    path : ReferencePath
        The reference path, resampled at its spacing_m.

    Returns
    -------
    float
        Arc length (m); 0.0 for a path that never curves.
    """
    curving = np.flatnonzero(np.abs(path.curvature_1pm) > CURVING_1PM)
    return float(curving[0] * path.spacing_m) if curving.size else 0.0


def max_cte_after_convergence_m(progress_m: np.ndarray, cte_m: np.ndarray, from_m: float = 0.0) -> float:
    """Max |CTE| (m) once the run has converged: from the later of the distance after which |CTE| stays within
    CONVERGED_CTE_M (`converge_distance_m`) and from_m; NaN if it never converged.

    from_m (the start of the curves, `curves_start_m`) keeps the measure off the approach's last metres, where |CTE|
    is still just under the tolerance by definition and would read as CONVERGED_CTE_M for every run.

    Parameters
    ----------
    progress_m : numpy.ndarray
        Distance along the path (m) of each sample, shape (n,).
    cte_m : numpy.ndarray
        Cross-track error (m) of each sample, shape (n,).
    from_m : float
        Distance (m) from the first sample before which the measure does not look.

    Returns
    -------
    float
        Max |CTE| (m); NaN if the run never converged or has no sample after that distance.
    """
    converged = converge_distance_m(progress_m, cte_m)
    if math.isnan(converged):
        return math.nan
    after = (progress_m - progress_m[0]) >= max(converged, from_m)
    return float(np.max(np.abs(cte_m[after]))) if after.any() else math.nan


def overshoot_m(cte_m: np.ndarray) -> float:
    """How far (m) the run crosses to the other side of the path from where it started (0 if it never does).

    Parameters
    ----------
    cte_m : numpy.ndarray
        Cross-track error (m) of each sample, shape (n,); its first sample's sign is the side the run starts on.

    Returns
    -------
    float
        The largest |CTE| (m) on the other side; NaN for no samples.

    Examples
    --------
    >>> import numpy as np
    >>> from workbench.apps.fig17 import overshoot_m
    >>> overshoot_m(np.array([1.0, 0.4, -0.05, 0.01, 0.0]))
    0.05
    """
    side = math.copysign(1.0, float(cte_m[0])) if cte_m.size else 1.0
    return float(max(0.0, np.max(-side * cte_m))) if cte_m.size else math.nan


def _convergence_figure(comparison: Comparison) -> Figure:
    """The first CONVERGENCE_VIEW_M of each run: (a) CTE, with the convergence tolerance, (b) steering-wheel angle,
    both against distance along the path."""
    import matplotlib.pyplot as plt

    fig, (ax_cte, ax_steer) = plt.subplots(2, 1, figsize=(9, 7), sharex=True, layout="constrained")
    comparison.plot_cte(ax_cte, zoom=False)
    ax_cte.axhspan(-CONVERGED_CTE_M, CONVERGED_CTE_M, color="tab:green", alpha=0.12, label=f"±{CONVERGED_CTE_M:g} m")
    cte_seen, steer_seen = [0.0], [0.0]
    for result, label, style in zip(comparison.results, comparison.labels, comparison.styles, strict=True):
        distance = result.trace["progress_m"] - result.trace["progress_m"][0]
        shown = distance <= CONVERGENCE_VIEW_M
        steer_deg = np.degrees(result.trace["steer_wheel_rad"])
        ax_steer.plot(distance, steer_deg, color=style.colour, ls=style.line_style, lw=1.3, label=label)
        cte_seen += [float(np.min(result.trace["cte_m"][shown])), float(np.max(result.trace["cte_m"][shown]))]
        steer_seen += [float(np.min(steer_deg[shown])), float(np.max(steer_deg[shown]))]
    for ax, seen in ((ax_cte, cte_seen), (ax_steer, steer_seen)):
        margin = 0.05 * (max(seen) - min(seen))
        ax.set_ylim(min(seen) - margin, max(seen) + margin)
    ax_cte.set(xlim=(0.0, CONVERGENCE_VIEW_M), xlabel="", title=f"(a) CTE in the first {CONVERGENCE_VIEW_M:g} m")
    ax_cte.legend(loc="upper right")
    ax_steer.set(
        xlabel="distance along path (m)",
        ylabel="steering-wheel angle (deg)",
        title=f"(b) steering-wheel angle in the first {CONVERGENCE_VIEW_M:g} m",
    )
    ax_steer.axhline(0.0, color="k", lw=0.5)
    ax_steer.legend(loc="lower right")
    return fig


@dataclass(frozen=True)
class Fig17Result:
    """published: the paper's pairing; fair: every controller on every plant."""

    published: Comparison
    fair: Comparison

    def summary(self) -> pd.DataFrame:
        """The fair set's summary with each run's overshoot_m, max_abs_cte_after_convergence_m and speed_spread_kmh
        (max - min of the measured speed).

        Returns
        -------
        pandas.DataFrame
            One row per run of the fair set (`Comparison.summary` and those three columns).
        """
        table = self.fair.summary()
        start = curves_start_m(self.fair.scenario.path)
        table["overshoot_m"] = [overshoot_m(r.trace["cte_m"]) for r in self.fair.results]
        table["max_abs_cte_after_convergence_m"] = [
            max_cte_after_convergence_m(r.trace["progress_m"], r.trace["cte_m"], start) for r in self.fair.results
        ]
        table["speed_spread_kmh"] = [float(np.ptp(r.trace["speed_mps"])) * 3.6 for r in self.fair.results]
        return table

    def published_summary(self) -> pd.DataFrame:
        """The published pairs' rows of `summary()`: their step-time ratios are over the clothoid controller's on the
        same plant (the published selection alone has no clothoid run on the car).

        Returns
        -------
        pandas.DataFrame
            One row per published pair, in the published order.
        """
        table = self.summary()
        rows = [self.fair.specs.index(spec) for spec in self.published.specs]
        return table.iloc[rows].reset_index(drop=True)

    def paper_table(self) -> pd.DataFrame:
        """What section 6.6 of the paper says of Figures 17 and 18 (it gives no values), beside our numbers: the
        published pairing (clothoid on the truck, NMPC on the car) and both controllers on the truck.

        Returns
        -------
        pandas.DataFrame
            One row per statement of PAPER_STATEMENTS: figure, the paper, what we measure, and our numbers.
        """
        table = self.summary().set_index(["controller", "vehicle"])

        def ours(column: str, unit: str, clothoid_on: str, nmpc_on: str) -> str:
            clothoid, nmpc = table.loc[("clothoid", clothoid_on), column], table.loc[("nmpc", nmpc_on), column]
            return f"clothoid {clothoid:.3g} {unit}, NMPC {nmpc:.3g} {unit}"

        return pd.DataFrame(
            [
                {
                    "figure": figure,
                    "the paper": said,
                    "ours: what": what,
                    "ours: clothoid on the truck, NMPC on the car": ours(column, unit, TRUCK, CAR),
                    "ours: both on the truck": ours(column, unit, TRUCK, TRUCK),
                }
                for figure, said, what, column, unit in PAPER_STATEMENTS
            ]
        )

    def save(self, out_dir: str | Path) -> list[Path]:
        """Write the fair set's runs, summary.csv (with the columns of `summary()`) and figures to out_dir, the
        published set's figures with the prefix "published_", both sets' convergence views, paper_vs_ours.csv
        (`paper_table`) and report.html with all of it; return the paths (the report last).

        Parameters
        ----------
        out_dir : str or pathlib.Path
            The folder to write to (made if missing); files there of the same names are replaced.

        Returns
        -------
        list of pathlib.Path
            Every file written, report.html last.
        """
        out = Path(out_dir)
        written = self.fair.save(out)
        self.summary().to_csv(out / "summary.csv", index=False)  # the fair set's, with the fig17 columns
        written += self.published.save_figures(out, prefix="published_")
        for prefix, comparison in (("", self.fair), ("published_", self.published)):
            path = out / f"{prefix}convergence_first_{CONVERGENCE_VIEW_M:g}m.png"
            path.write_bytes(figure_png(_convergence_figure(comparison)))
            written.append(path)
        paper = self.paper_table()
        paper.to_csv(out / "paper_vs_ours.csv", index=False)
        written.append(out / "paper_vs_ours.csv")
        zoom = f"convergence in the first {CONVERGENCE_VIEW_M:g} m: CTE and steering-wheel angle against distance"
        converged = (
            f" The start's 1 m offset is every run's max |CTE|; overshoot is how far a run crosses to the path's other "
            f"side, and max |CTE| after convergence is taken from where |CTE| stays within {CONVERGED_CTE_M:g} m, or "
            f"from the first curve ({curves_start_m(self.fair.scenario.path):g} m) if that is later."
        )
        sections = [
            ReportSection(
                "As published: clothoid on the truck, NMPC on the car",
                "The pairing of the paper's Figure 17: its clothoid controller on the loaded tractor-semitrailer, "
                "the MPC baseline on a passenger car. Each step-time ratio is over the clothoid controller's on the "
                "same plant (from the fair set below)." + converged,
                self.published,
                summary=self.published_summary(),
                columns=FIG17_COLUMNS,
                figures=(ReportFigure(zoom, lambda: _convergence_figure(self.published)),),
            ),
            ReportSection(
                "Fair: each controller on each plant",
                "The comparison the paper could not run: both controllers on both plants. The step-time ratio is "
                "each controller's median step time over the clothoid controller's on the same plant." + converged,
                self.fair,
                summary=self.summary(),
                columns=FIG17_COLUMNS,
                figures=(ReportFigure(zoom, lambda: _convergence_figure(self.fair)),),
            ),
        ]
        tables = [
            ReportTable(
                "Beside the paper (section 6.6)",
                "The paper compares its clothoid controller on a TruckSim truck with an MPC on a CarSim car and states "
                "its findings without values; ours are from the runs below.",
                paper,
            )
        ]
        intro = (
            "Replication of Figures 17 and 18 of Shaju, Southward & Ahmadian (2024): tracked trajectories, "
            "cross-track error against distance, speed against distance and steering against time, "
            f"on the fig17 path at {self.fair.config.speed_kmh:g} km/h from a 1 m initial offset. "
            + self.fair.conditions_text()
        ).strip()
        written.append(
            write_report(out / "report.html", "Figure 17: clothoid controller against NMPC", sections, intro, tables)
        )
        return written


def run_fig17(
    config: SimulationConfig | None = None, progress: bool | None = None, allow_long_run: bool = False
) -> Fig17Result:
    """Simulate the fair set (it contains the published pairs) on the fig17 scenario; progress: a line on stderr
    counting the runs (`compare`; None: when stderr is a terminal, as the CLI shows it); allow_long_run: run even
    when a run may simulate more than the bounds of `run_size` (`compare`).

    Parameters
    ----------
    config : SimulationConfig or None
        The simulation settings (None: the defaults at SPEED_KMH, 30 km/h).
    progress : bool or None
        Show the runs' progress on stderr (None: when stderr is a terminal).
    allow_long_run : bool
        Run even a run longer than the bounds of `run_size`.

    Returns
    -------
    Fig17Result
        The fair set and the published pairs selected from it.

    Raises
    ------
    WorkbenchInputError
        A run too long (unless allowed), or a path a vehicle cannot follow at the config's speed.

    Examples
    --------
    >>> from workbench.apps.fig17 import run_fig17
    >>> result = run_fig17()  # doctest: +SKIP
    >>> result.save("runs/fig17")[-1]  # doctest: +SKIP
    PosixPath('runs/fig17/report.html')
    """
    show = sys.stderr.isatty() if progress is None else progress
    config = config or SimulationConfig(speed_kmh=SPEED_KMH)
    fair = compare(
        SCENARIO, FAIR, config, reference_controller="clothoid", progress=show, allow_long_run=allow_long_run
    )
    return Fig17Result(published=fair.select(PUBLISHED), fair=fair)


__all__ = [
    "CONVERGENCE_VIEW_M",
    "FAIR",
    "FIG17_COLUMNS",
    "PAPER_STATEMENTS",
    "PUBLISHED",
    "Fig17Result",
    "curves_start_m",
    "max_cte_after_convergence_m",
    "overshoot_m",
    "run_fig17",
]
