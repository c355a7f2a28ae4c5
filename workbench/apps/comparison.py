"""Side-by-side runs: several controllers (and plants) on one scenario, their metrics in one table, their traces
on shared axes (the paper's Figure 17: tracked trajectories and CTE against distance; Figure 18: speed and
steering).

`compare(scenario, runs)` simulates each (controller, vehicle) pair with the same `SimulationConfig` and returns a
`Comparison`: `summary()` is a DataFrame with one row per pair (the metrics.json fields, the distance to converge
within `CONVERGED_CTE_M` of the path, and each controller's step-time ratio to a reference controller), and the
`plot_*` methods draw every run on one axis, alike on every figure (`styles`: a colour per controller, a line style
per vehicle), the trajectories with an inset magnifying the hardest stretch (`hardest_stretch`). A run that fails
(a controller error, the vehicle leaving the path) keeps its row with its status and message: nothing is dropped.
`workbench compare` and `workbench fig17` write the result with `save` (traces, metrics, summary.csv, figures) and
`workbench.apps.report.write_report` (report.html).

Every run is built (vehicle, scenario, controller options and files) before the first one is simulated, so a bad
input is refused before any work, a run that may simulate more than the bounds of `run_size` is refused without
`allow_long_run`, a path a vehicle cannot follow at the planned speed is refused without `allow_infeasible`, and
what each run's `Simulation.warnings` says (a planned top speed short of the speed asked for, the places a vehicle
cannot follow when allowed) is announced first. With `progress` one bar counts the runs
(the current run named on it), and each run shows its metres as `workbench run` does.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd
from tqdm import tqdm

from controllers import CONTROLLERS
from tuning.own_tuning import tuned_controller
from workbench.apps.controller_config import read_controller_config
from workbench.base.console import warn_on_stderr
from workbench.base.errors import WorkbenchInputError
from workbench.simulation.feasibility import refuse_infeasible
from workbench.simulation.limit_cycle import LimitCycle, detect_limit_cycle
from workbench.simulation.metrics import CONVERGED_CTE_M, METRIC_KEYS, approach_end
from workbench.simulation.plots import RunStyle, Stretch, run_styles
from workbench.simulation.result import SimulationResult
from workbench.simulation.run_size import check_run_size
from workbench.simulation.scenarios import Scenario, ScenarioOptions, make_scenario
from workbench.simulation.simulator import Simulation, SimulationConfig
from workbench.vehicles import VEHICLES, load_vehicle

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from workbench.vehicles.base import VehicleModel

#: The stretch the trajectories' inset magnifies (`hardest_stretch`) reaches this many times the largest |CTE| either
#: side of it along the path, and at least ZOOM_MIN_HALF_LENGTH_M (m): the runs' spread then shows at the inset's
#: scale.
ZOOM_CTE_FACTOR = 8.0
#: The shortest half-length (m) of the inset's stretch either side of its centre along the path.
ZOOM_MIN_HALF_LENGTH_M = 1.0
#: What shortens a comparison's run refused as too long (`run_size.check_run_size`).
LONG_RUN_SHORTENED = "a higher speed, fewer laps or a max_time_s (--speed, --laps, --max-time-s) shortens it"
#: The comparison figures: file name, Comparison method (Figures 17a, 17b, 18a, 18b).
FIGURES: tuple[tuple[str, str], ...] = (
    ("trajectories.png", "plot_trajectories"),
    ("cte_vs_distance.png", "plot_cte"),
    ("speed_vs_distance.png", "plot_speed"),
    ("steering_vs_time.png", "plot_steering"),
)


@dataclass(frozen=True)
class RunSpec:
    """One run of a comparison: a controller with its options on a vehicle.

    A controller without a table in `config_file` gets its defaults; the overrides apply on top of either.
    """

    controller: str  # a registered controller's name
    vehicle: str  # a preset's name or a vehicle TOML file (as `workbench run --vehicle-file`)
    overrides: tuple[str, ...] = ()  # controller options as KEY=VALUE (as `--set`)
    config_file: Path | None = None  # TOML, a table per controller name (as `--controller-config`)
    payload_kg: float | None = None  # kg; the payload of a vehicle that carries one (None: the preset's or file's)

    def __post_init__(self) -> None:
        if self.controller not in CONTROLLERS:
            raise WorkbenchInputError(f"unknown controller {self.controller!r}; choose one of {', '.join(CONTROLLERS)}")
        if self.vehicle not in VEHICLES and Path(self.vehicle).suffix.lower() != ".toml":
            raise WorkbenchInputError(
                f"unknown vehicle {self.vehicle!r}; choose one of {', '.join(VEHICLES)} or give a vehicle TOML file"
            )

    def make_vehicle(self) -> VehicleModel:
        """A fresh vehicle of this run (a preset or the file, with the payload if given).

        Returns
        -------
        VehicleModel
            A fresh model, its state not shared with any other run.

        Raises
        ------
        WorkbenchInputError
            The vehicle file is missing or malformed, or a payload is given for a vehicle without one or is out of
            its range.
        """
        return load_vehicle(self.vehicle, self.payload_kg)

    @property
    def label(self) -> str:
        """The run in words for legends and messages: controller, its options, vehicle and payload."""
        options = f" ({', '.join(self.overrides)})" if self.overrides else ""
        payload = f" with {self.payload_kg:g} kg" if self.payload_kg is not None else ""
        return f"{self.controller}{options} on {self.vehicle}{payload}"

    @property
    def slug(self) -> str:
        """A directory name for the run's files: controller-vehicle (a vehicle file by its name), then the options
        and the payload when given."""
        vehicle = self.vehicle if self.vehicle in VEHICLES else Path(self.vehicle).name
        text = f"{self.controller}-{vehicle}" + "".join(f"-{o}" for o in self.overrides)
        text += f"-{self.payload_kg:g}kg" if self.payload_kg is not None else ""
        return "".join(c if c.isalnum() or c in "-_." else "_" for c in text)


def converge_distance_m(progress_m: np.ndarray, cte_m: np.ndarray, tolerance_m: float = CONVERGED_CTE_M) -> float:
    """Distance along the path (m) after which |CTE| stays within tolerance_m to the end of the run; 0 if it never
    left it; NaN if it is outside at the end (never converged).

    Parameters
    ----------
    progress_m : numpy.ndarray
        Distance along the path (m) of each sample, shape (n,).
    cte_m : numpy.ndarray
        Cross-track error (m) of each sample, shape (n,), aligned with `progress_m`.
    tolerance_m : float
        The band (m) |CTE| must stay within; positive (default `CONVERGED_CTE_M`).

    Returns
    -------
    float
        Distance (m) from the first sample to the first one after which |CTE| stays within the band; 0.0 when it
        never left it, NaN when the last sample is outside it.

    Examples
    --------
    >>> import numpy as np
    >>> from workbench.apps.comparison import converge_distance_m
    >>> converge_distance_m(np.array([0.0, 1.0, 2.0, 3.0]), np.array([0.5, 0.2, 0.01, 0.0]), tolerance_m=0.05)
    2.0
    """
    outside = np.flatnonzero(np.abs(cte_m) > tolerance_m)
    if outside.size == 0:
        return 0.0
    last = int(outside[-1])
    if last + 1 >= cte_m.size:
        return math.nan
    return float(progress_m[last + 1] - progress_m[0])


def step_time_ratios(table: pd.DataFrame, reference_controller: str | None) -> list[float]:
    """Each row's step_time_median_us over the reference controller's on the same vehicle (the median over its
    runs there, which may differ in options), or over all its runs when it did not run on that vehicle; NaN
    without a reference or a step time."""
    if reference_controller is None or reference_controller not in set(table["controller"]):
        return [math.nan] * len(table)
    ref_rows = table[table["controller"] == reference_controller]
    per_vehicle = ref_rows.groupby("vehicle")["step_time_median_us"].median()
    overall = float(ref_rows["step_time_median_us"].median())
    return [
        float(row.step_time_median_us) / float(per_vehicle.get(row.vehicle, overall))
        if row.step_time_median_us is not None and math.isfinite(row.step_time_median_us)
        else math.nan
        for row in table.itertuples()
    ]


@dataclass(frozen=True, eq=False)
class Comparison:
    """The runs of one scenario, in the order asked, with their results."""

    scenario: Scenario  # the scenario every run drove
    specs: tuple[RunSpec, ...]  # the runs, in the order asked
    results: tuple[SimulationResult, ...]  # their results, one per spec in the same order
    config: SimulationConfig  # how every run was simulated
    reference_controller: str | None = None  # the controller whose step time summary() divides by (None: no ratio)
    _summary: list[pd.DataFrame] = field(default_factory=list, repr=False)

    def select(self, specs: Sequence[RunSpec]) -> Comparison:
        """The sub-comparison of these runs (e.g. the paper's published pairs out of the full cross product).

        Parameters
        ----------
        specs : sequence of RunSpec
            Runs of this comparison, in the order the sub-comparison keeps them.

        Returns
        -------
        Comparison
            The same scenario, config and reference controller with only these runs' results.
        """
        index = [self.specs.index(s) for s in specs]
        return Comparison(
            self.scenario,
            tuple(self.specs[i] for i in index),
            tuple(self.results[i] for i in index),
            self.config,
            self.reference_controller,
        )

    def summary(self) -> pd.DataFrame:
        """One row per run: the metrics.json fields, status and message, the distance to converge within
        CONVERGED_CTE_M, and step_time_ratio (`step_time_ratios`).

        Returns
        -------
        pandas.DataFrame
            One row per run in the runs' order (a copy: changing it leaves the comparison as it is).
        """
        if not self._summary:
            rows = []
            for spec, result in zip(self.specs, self.results, strict=True):
                row = {k: v for k, v in result.metrics.to_dict().items() if k in METRIC_KEYS}
                row["vehicle"] = spec.vehicle  # the preset or the file asked for (the metrics name the model)
                row |= {"options": " ".join(spec.overrides), "status": result.status.value, "message": result.message}
                row["converge_distance_m"] = converge_distance_m(result.trace["progress_m"], result.trace["cte_m"])
                rows.append(row)
            table = pd.DataFrame(rows)
            table["step_time_ratio"] = step_time_ratios(table, self.reference_controller)
            self._summary.append(table)
        return self._summary[0].copy()

    def conditions_text(self) -> str:
        """The runs' conditions in a sentence for a report, and whether the controllers were told their nominal
        delays (`SimulationConfig.inform_delays`, `KnownDelays`); "" under ideal conditions.

        Returns
        -------
        str
            One or two sentences, or "" under ideal conditions.
        """
        config = self.config
        if config.conditions.is_ideal:
            return ""
        delays = config.known_delays
        if delays is not None:
            told = f"told their nominal delays ({delays.describe()})"
            if config.perfect_prediction:
                told += ", and handed the true state one dead time ahead (a perfect prediction)"
        else:
            told = "not told their delays"
        return (
            f"Conditions {config.conditions.name} (seed {config.seed}): {config.conditions.describe()}. The "
            f"controllers were {told}."
        )

    def limit_cycles(self) -> list[LimitCycle]:
        """Each run's steering limit cycle (`simulation/limit_cycle.py`; the summary's limit_cycle fields, plus when it
        starts and how long it lasts), in the runs' order.

        Returns
        -------
        list of LimitCycle
            One per run, in the runs' order.
        """
        return [detect_limit_cycle(r.trace["t_s"], r.trace["steer_wheel_rad"]) for r in self.results]

    def to_pandas(self) -> pd.DataFrame:
        """Every run's trace stacked, with `controller`, `vehicle` and `run` columns.

        Returns
        -------
        pandas.DataFrame
            One row per sample of each run, the runs in order; ``run`` is the run's label.
        """
        frames = []
        for spec, result in zip(self.specs, self.results, strict=True):
            frame = result.to_pandas()
            frame.insert(0, "run", spec.label)
            frame.insert(1, "controller", spec.controller)
            frame.insert(2, "vehicle", spec.vehicle)
            frames.append(frame)
        return pd.concat(frames, ignore_index=True)

    # Figures 17 and 18: every run on one axis, in its style (`styles`); each returns the axes.
    def plot_trajectories(self, ax: Axes | None = None) -> Axes:
        """Figure 17a, with an inset on the hardest stretch (`hardest_stretch`).

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            The axes to draw on (None: a fresh figure's).

        Returns
        -------
        matplotlib.axes.Axes
            The axes drawn on.
        """
        from workbench.simulation import plots

        return plots.trajectories(self.results, self.labels, ax, self.styles, self.hardest_stretch())

    def plot_cte(self, ax: Axes | None = None, zoom: bool = True) -> Axes:
        """Figure 17b; zoom: the stretch the trajectories' inset shows shaded.

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            The axes to draw on (None: a fresh figure's).
        zoom : bool
            Shade the stretch the trajectories' inset magnifies (`hardest_stretch`).

        Returns
        -------
        matplotlib.axes.Axes
            The axes drawn on.
        """
        from workbench.simulation import plots

        stretch = self.hardest_stretch() if zoom else None
        return plots.cte_comparison(self.results, self.labels, ax, self.styles, stretch)

    def plot_speed(self, ax: Axes | None = None) -> Axes:
        """Figure 18a: each run's speed against distance along the path, and the first run's planned profile.

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            The axes to draw on (None: a fresh figure's).

        Returns
        -------
        matplotlib.axes.Axes
            The axes drawn on.
        """
        from workbench.simulation import plots

        return plots.speed_comparison(self.results, self.labels, ax, self.styles)

    def plot_steering(self, ax: Axes | None = None) -> Axes:
        """Figure 18b: each run's measured steering-wheel angle against time.

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            The axes to draw on (None: a fresh figure's).

        Returns
        -------
        matplotlib.axes.Axes
            The axes drawn on.
        """
        from workbench.simulation import plots

        return plots.steering_comparison(self.results, self.labels, ax, self.styles)

    @property
    def labels(self) -> list[str]:
        """Each run's `RunSpec.label`, in the runs' order (the figures' legend)."""
        return [s.label for s in self.specs]

    @property
    def styles(self) -> list[RunStyle]:
        """How each run is drawn on every figure (`plots.run_styles`): a colour per controller (with its options and
        file: another controller here) and a line style per vehicle (with its payload)."""
        return run_styles(
            [(s.controller, s.overrides, s.config_file) for s in self.specs],
            [(s.vehicle, s.payload_kg) for s in self.specs],
        )

    def hardest_stretch(self) -> Stretch | None:
        """The stretch of the course around the largest |CTE| of any run once it has converged (`approach_end`),
        ZOOM_CTE_FACTOR times that |CTE| either side along the path (at least ZOOM_MIN_HALF_LENGTH_M); None when no
        run has a sample after its approach.

        Returns
        -------
        Stretch or None
            The stretch along the path (m) and a caption naming the largest |CTE|; None when no run has a sample
            after its approach.
        """
        peak, where = -1.0, math.nan
        for result in self.results:
            cte = np.abs(result.trace["cte_m"])
            start = approach_end(cte)
            if start < cte.size and float(np.max(cte[start:])) > peak:
                k = start + int(np.argmax(cte[start:]))
                peak, where = float(cte[k]), float(result.trace["progress_m"][k])
        if peak < 0.0:
            return None
        half = max(ZOOM_MIN_HALF_LENGTH_M, ZOOM_CTE_FACTOR * peak)
        return Stretch(where - half, where + half, f"largest |CTE| {peak:.3g} m")

    def save_figures(self, out_dir: str | Path, prefix: str = "") -> list[Path]:
        """Write the four comparison figures as PNG; return their paths.

        Parameters
        ----------
        out_dir : str or pathlib.Path
            The folder to write to (made if missing).
        prefix : str
            Put before each file name (`FIGURES`: trajectories.png, cte_vs_distance.png, speed_vs_distance.png,
            steering_vs_time.png).

        Returns
        -------
        list of pathlib.Path
            The files written, in the order of `FIGURES`.
        """
        from workbench.simulation.plots import file_figure

        out = Path(out_dir)
        out.mkdir(parents=True, exist_ok=True)
        written = []
        for name, method in FIGURES:
            path = out / f"{prefix}{name}"
            figure = file_figure()
            getattr(self, method)(figure.add_subplot())
            figure.savefig(path, dpi=110)
            written.append(path)
        return written

    def save(self, out_dir: str | Path, with_plots: bool = True) -> list[Path]:
        """Write each run's trace and metrics under DIR/runs/<slug>/ (`RunSpec.slug`: controller-vehicle, and the
        options when given), DIR/summary.csv and, with_plots, the figures; return the paths.

        Parameters
        ----------
        out_dir : str or pathlib.Path
            The folder DIR to write to (made if missing); files already there of the same names are replaced.
        with_plots : bool
            Also write the four figures (`save_figures`).

        Returns
        -------
        list of pathlib.Path
            Every file written: the runs' files, summary.csv, then the figures.

        Examples
        --------
        >>> from workbench.apps.comparison import RunSpec, compare
        >>> result = compare("dlc", [RunSpec("clothoid", "kinematic-bicycle")])  # doctest: +SKIP
        >>> paths = result.save("out/compare", with_plots=False)  # doctest: +SKIP
        """
        out = Path(out_dir)
        written = []
        for spec, result in zip(self.specs, self.results, strict=True):
            written += result.save(out / "runs" / spec.slug, with_plots=False)
        summary_path = out / "summary.csv"
        self.summary().to_csv(summary_path, index=False)
        written.append(summary_path)
        return written + (self.save_figures(out) if with_plots else [])


def _simulation(
    spec: RunSpec, scenario: str | Scenario, scenario_options: ScenarioOptions | None, config: SimulationConfig
) -> Simulation:
    """The run `spec` wired: its vehicle, the scenario (sized for the vehicle when named), its tuned controller
    (told the conditions' delays when config.inform_delays)."""
    vehicle = spec.make_vehicle()
    if isinstance(scenario, Scenario):
        scen = scenario
    else:
        options = scenario_options or ScenarioOptions()
        scen = make_scenario(scenario, replace(options, vehicle_width_m=vehicle.geometry.width_m))
    config_type = CONTROLLERS[spec.controller].config_type
    options = read_controller_config(spec.config_file, spec.controller, config_type, spec.overrides, vehicle.geometry)
    delays = config.known_delays
    return Simulation(scen, vehicle, tuned_controller(spec.controller, vehicle, options, delays), config)


def compare(
    scenario: str | Scenario,
    runs: Sequence[RunSpec],
    config: SimulationConfig | None = None,
    scenario_options: ScenarioOptions | None = None,
    reference_controller: str | None = "clothoid",
    warn: Callable[[str], None] | None = warn_on_stderr,
    progress: bool = False,
    allow_long_run: bool = False,
    allow_infeasible: bool = False,
) -> Comparison:
    """Simulate each run on `scenario` (a name, a waypoint file or a Scenario) with the same config. Every run is
    built first (a bad input is refused before any simulation); a planned top speed short of the config's and
    the controllers' own warnings (`Simulation.warnings`) are announced through `warn` before the first run (None:
    silent). progress: a bar on stderr counting the runs (naming the one being
    prepared or run), left on screen when done. A run that may simulate more than the bounds of `run_size` is
    refused before any run starts, unless allow_long_run. A path that one of the vehicles cannot follow at the
    planned speed (`workbench.simulation.feasibility`) is refused before any run starts, naming each such vehicle,
    the places and the limit (`feasibility.refuse_infeasible`, as `workbench run` refuses it), unless
    allow_infeasible (`--allow-infeasible`): then it is announced through `warn` with the other warnings and run,
    for a study of how the controllers fail there.

    Parameters
    ----------
    scenario : str or Scenario
        A scenario name (`workbench scenarios` lists them), a waypoint file, or a built `Scenario`.
    runs : sequence of RunSpec
        The (controller, vehicle, options) runs, each at most once; at least one.
    config : SimulationConfig, optional
        The simulation settings every run shares (None: the defaults).
    scenario_options : ScenarioOptions, optional
        Options of a named scenario or a waypoint file (None: its defaults).
    reference_controller : str or None
        The controller whose step time the table's ``step_time_ratio`` column divides by (None: no ratio).
    warn : callable or None
        Called with each warning before the first run (None: silent).
    progress : bool
        Show a progress bar on stderr.
    allow_long_run, allow_infeasible : bool
        Run what would otherwise be refused as too long, or on a path a vehicle cannot follow.

    Returns
    -------
    Comparison
        The results in the order of `runs`: ``summary()`` gives a pandas DataFrame of their metrics,
        ``plot_trajectories()`` and ``plot_cte()`` draw them.

    Raises
    ------
    WorkbenchInputError
        No run, a run given twice, two runs that would write to one folder, an unknown controller, vehicle or
        option, a run too long or a path infeasible (unless allowed).

    Examples
    --------
    >>> from workbench.apps.comparison import RunSpec, compare
    >>> runs = [RunSpec("clothoid", "kinematic-bicycle"), RunSpec("stanley", "kinematic-bicycle")]
    >>> result = compare("dlc", runs)  # doctest: +SKIP
    >>> result.summary()[["controller", "max_abs_cte_m"]]  # doctest: +SKIP
    """
    if not runs:
        raise WorkbenchInputError("a comparison needs at least one (controller, vehicle) run; got none")
    if len(set(runs)) != len(runs):
        raise WorkbenchInputError(f"each run may appear once; got {[r.label for r in runs]}")
    slugs = [r.slug for r in runs]
    if len(set(slugs)) != len(slugs):
        twice = sorted({s for s in slugs if slugs.count(s) > 1})
        raise WorkbenchInputError(
            f"two runs would write to the same folder runs/{twice[0]} (vehicle files of the same name?); got "
            f"{[r.label for r in runs]}"
        )
    config = config or SimulationConfig()
    bar = tqdm(total=len(runs), unit="run", desc="compare", leave=True, disable=not progress)
    try:
        simulations = []
        for spec in runs:
            bar.set_postfix_str(f"preparing {spec.label}")
            simulations.append(_simulation(spec, scenario, scenario_options, config))
            if not allow_long_run:
                check_run_size(simulations[-1].size, spec.label, LONG_RUN_SHORTENED, "--allow-long-run")
        if not allow_infeasible:
            refuse_infeasible([m for sim in simulations for m in sim.path_warnings()])
        messages = [m for spec, sim in zip(runs, simulations, strict=True) for m in sim.warnings(spec.label)]
        if warn is not None:
            with tqdm.external_write_mode(file=sys.stderr):  # above the bar, not through it
                for message in dict.fromkeys(messages):
                    warn(message)
        results = []
        for spec, simulation in zip(runs, simulations, strict=True):
            bar.set_postfix_str(spec.label)
            results.append(simulation.run(progress=progress))
            bar.update(1)
    except BaseException:
        bar.leave = False  # a refused input or an interrupted comparison: its message without a bar above it
        raise
    finally:
        bar.close()
    return Comparison(results[0].scenario, tuple(runs), tuple(results), config, reference_controller)


__all__ = [
    "CONVERGED_CTE_M",
    "ZOOM_CTE_FACTOR",
    "ZOOM_MIN_HALF_LENGTH_M",
    "Comparison",
    "RunSpec",
    "approach_end",
    "compare",
    "converge_distance_m",
]
