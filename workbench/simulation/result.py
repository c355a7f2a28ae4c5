"""The result of one closed-loop run: the trace, how the run ended, its metrics; converts and plots itself."""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from enum import StrEnum
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from workbench.base.path import ReferencePath
from workbench.simulation.metrics import Metrics, compute_metrics
from workbench.simulation.scenarios import Scenario

if TYPE_CHECKING:
    import pandas as pd
    from matplotlib.axes import Axes

    from workbench.simulation.feasibility import InfeasibleSpan
    from workbench.simulation.plot_worker import PlotWorker
    from workbench.simulation.run_config import SimulationConfig
    from workbench.simulation.track_margin import VehicleOutline


class Status(StrEnum):
    """How a run ended."""

    COMPLETED = "completed"
    TIMEOUT = "timeout"
    LEFT_PATH = "left_path"
    DIVERGED = "diverged"
    CONTROLLER_FAILED = "controller_failed"
    #: The plant could not go on (`workbench.vehicles.base.PlantStepError`: an FMU plant's doStep failed).
    PLANT_FAILED = "plant_failed"


@dataclass(frozen=True, eq=False)
class SimulationResult:
    """One closed-loop run: its trace, how and why it ended, what it ran; computes its metrics on first use.

    A run that did not complete keeps its partial trace; `status` and `message` say why it stopped. Without an
    `outline` the track metrics are null. `infeasible_curvature` lists where the vehicle cannot follow the path at
    its planned speed (`feasibility.check_path`): empty when it can, None when not checked.
    """

    trace: dict[str, np.ndarray]  # one array per logged signal (SI, unit in the name), one row per controller step
    status: Status  # how the run ended
    message: str  # why it ended, in words (what failed and when, for a run that did not complete)
    scenario: Scenario  # the scenario run
    path: ReferencePath  # the path the vehicle followed
    controller: str  # the controller's name
    vehicle: str  # the vehicle model's name
    config: SimulationConfig  # how the run was simulated (speed, rates, laps, conditions)
    outline: VehicleOutline | None = None  # vehicle's plan-view outline, for the track margin (None: not known)
    infeasible_curvature: tuple[InfeasibleSpan, ...] | None = None  # spans it cannot follow at speed
    _metrics: list[Metrics] = field(default_factory=list, repr=False)

    @property
    def completed(self) -> bool:
        """Whether the run reached the end of its path, or completed its laps (`Status.COMPLETED`)."""
        return self.status is Status.COMPLETED

    @property
    def metrics(self) -> Metrics:
        """The run's metrics (`compute_metrics`, the numbers of metrics.json), computed on first use."""
        if not self._metrics:  # computed once, on first use
            laps = self.config.laps if self.path.closed else 1
            self._metrics.append(
                compute_metrics(
                    self.trace,
                    self.path,
                    scenario=self.scenario.name,
                    controller=self.controller,
                    vehicle=self.vehicle,
                    completed=self.completed,
                    path_length_m=self.path.length_m * laps,
                    outline=self.outline,
                )
            )
        return self._metrics[0]

    def to_pandas(self) -> pd.DataFrame:
        """The trace as a DataFrame, one row per controller step.

        Returns
        -------
        pandas.DataFrame
            One column per logged signal (SI units, the unit in each name, e.g. ``cte_m``, ``t_s``).
        """
        import pandas as pd

        return pd.DataFrame(self.trace)

    # Plots: each draws on the given axes (or a new figure) and returns the axes.
    def plot_trajectory(self, ax: Axes | None = None) -> Axes:
        """The path (with its track edges and cones, when it has them) and the vehicle's trajectory: the
        rear-axle centre's, and the trailer's for an articulated vehicle; x and y in m.

        Parameters
        ----------
        ax : matplotlib.axes.Axes or None
            The axes to draw on (None: a new figure's).

        Returns
        -------
        matplotlib.axes.Axes
            The axes drawn on.
        """
        from workbench.simulation import plots

        return plots.trajectory(self, ax)

    def plot_cte(self, ax: Axes | None = None) -> Axes:
        """The cross-track error at the rear-axle centre (m) against the distance along the path (m).

        Parameters
        ----------
        ax : matplotlib.axes.Axes or None
            The axes to draw on (None: a new figure's).

        Returns
        -------
        matplotlib.axes.Axes
            The axes drawn on.
        """
        from workbench.simulation import plots

        return plots.cte_vs_distance(self, ax)

    def plot_steering(self, ax: Axes | None = None) -> Axes:
        """The steering-wheel angle commanded and measured (deg) against time (s).

        Parameters
        ----------
        ax : matplotlib.axes.Axes or None
            The axes to draw on (None: a new figure's).

        Returns
        -------
        matplotlib.axes.Axes
            The axes drawn on.
        """
        from workbench.simulation import plots

        return plots.steering_vs_time(self, ax)

    def plot_speed(self, ax: Axes | None = None) -> Axes:
        """The planned and the actual speed (km/h) against the distance along the path (m).

        Parameters
        ----------
        ax : matplotlib.axes.Axes or None
            The axes to draw on (None: a new figure's).

        Returns
        -------
        matplotlib.axes.Axes
            The axes drawn on.
        """
        from workbench.simulation import plots

        return plots.speed_vs_distance(self, ax)

    def save(self, out_dir: str | Path, with_plots: bool = True, plot_worker: PlotWorker | None = None) -> list[Path]:
        """Write trace.parquet, metrics.json (the metrics, then infeasible_curvature: a list of
        `InfeasibleSpan.to_dict`, or null when not checked, then status and message; under conditions other than
        ideal, their name, the seed and inform_delays) and the PNG plots; return the paths. The files a run writes
        that are already in out_dir (an earlier run's, the plots included when with_plots is False) are removed
        first, so the folder never holds files of two runs. plot_worker: a `plot_worker.PlotWorker` that draws the
        plots meanwhile (here, if it cannot).

        Parameters
        ----------
        out_dir : str or pathlib.Path
            The folder to write into; created when missing.
        with_plots : bool
            Also draw the PNG plots (trajectory, CTE, steering, speed).
        plot_worker : PlotWorker or None
            A worker that draws the plots while the trace and metrics are written (None: drawn here).

        Returns
        -------
        list of pathlib.Path
            The files written: trace.parquet, metrics.json, then the PNG plots.

        Examples
        --------
        >>> result.save("runs/fig17-stanley")  # doctest: +SKIP
        >>> result.to_pandas()[["t_s", "cte_m"]].describe()  # doctest: +SKIP
        """
        from workbench.simulation import plots  # matplotlib itself only when the plots are drawn

        out = Path(out_dir)
        out.mkdir(parents=True, exist_ok=True)
        for name in ("trace.parquet", "metrics.json", *plots.RUN_PLOTS):
            (out / name).unlink(missing_ok=True)
        if with_plots and plot_worker is not None:
            plot_worker.submit(self, out)
        written = [out / "trace.parquet", out / "metrics.json"]
        _write_parquet(self.trace, written[0])
        spans = self.infeasible_curvature
        document = self.metrics.to_dict() | {
            "infeasible_curvature": None if spans is None else [span.to_dict() for span in spans],
            "status": self.status.value,
            "message": self.message,
        }
        if not self.config.conditions.is_ideal:  # only a run under conditions records them
            c = self.config  # inform_delays: whether the controller was told the conditions' delays
            document |= {"conditions": c.conditions.name, "seed": c.seed, "inform_delays": c.inform_delays}
            if c.perfect_prediction:  # the controller was handed the state one dead time ahead
                document["perfect_prediction"] = True
        written[1].write_text(json.dumps(document, indent=2) + "\n")
        if with_plots:
            drawn = plot_worker.wait() if plot_worker is not None else None
            written += drawn if drawn is not None else plots.save_run_plots(self, out)
        return written


def _write_parquet(trace: dict[str, np.ndarray], file: Path) -> None:
    """The trace as a Parquet file, one column per signal, with pyarrow (what pandas' to_parquet calls). Numeric
    columns go to Arrow as buffers: `pyarrow.array` would look for a pandas Series first and import pandas, ~0.3 s of
    a CLI run that needs no pandas otherwise."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    def arrow(values: np.ndarray) -> pa.Array:
        values = np.asarray(values)
        if values.ndim == 1 and values.dtype.kind in "fiu":
            values = np.ascontiguousarray(values)
            return pa.Array.from_buffers(pa.from_numpy_dtype(values.dtype), values.size, [None, pa.py_buffer(values)])
        return pa.array(values)

    pq.write_table(pa.Table.from_arrays([arrow(v) for v in trace.values()], names=list(trace)), file)


__all__ = ["SimulationResult", "Status"]
