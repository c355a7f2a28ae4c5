"""How each controller degrades away from ideal conditions: one factor at a time around a base (`ideal` by default),
over the actuation dead time, the pose latency, the position noise, the road's friction and, for a vehicle with a
payload, the plant's payload while the controller stays built for the nominal one (`payload_axis`; what that
mismatch changes differs by controller, `PAYLOAD_MISMATCH`). Every run is a study run (`PlannedRun`),
executed on the study backends (local processes or Dask) into a resumable store; the report is one self-contained
HTML file with the degradation curves (max |CTE|, steering oscillation, completion) and a table of the values at
which each controller stops completing or starts to limit-cycle.

With inform_delays (`workbench robustness --inform-delays`) every controller is told the base conditions' nominal
delays (`KnownDelays`, `Controller.informed_config`), the same in every run: a run with more dead time or latency
than the base meets a controller that does not know it, which is what the study measures. The options told are
given to each run as that controller's options (`told_options`), so the results record them.
"""

from __future__ import annotations

import dataclasses
import html
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import pandas as pd

from controllers import CONTROLLERS
from workbench.apps.studies.backends import Backend
from workbench.apps.studies.condition_parameters import resolve_conditions
from workbench.apps.studies.spec import PlannedRun, StudySpec
from workbench.apps.studies.store import RunStore, write_results
from workbench.apps.studies.sweep import execute_runs
from workbench.base.console import warn_on_stderr
from workbench.base.errors import WorkbenchInputError, require_positive
from workbench.simulation.conditions import load_conditions
from workbench.simulation.known_delays import KnownDelays
from workbench.simulation.scenarios import is_named_scenario
from workbench.vehicles import load_vehicle

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from workbench.simulation.circuit_ranges import CircuitRanges


@dataclass(frozen=True)
class Axis:
    """One factor varied around the base: the run parameter, its values (the base's own first), how the report
    shows them (label, unit, factor from the parameter's unit to the shown one)."""

    parameter: str
    values: tuple[float, ...]
    label: str
    unit: str
    shown_factor: float = 1.0
    #: Larger values are harder (the tolerance is the largest value that still passes); False: smaller are.
    rising: bool = True


#: The factors, each from its base value outward.
AXES: tuple[Axis, ...] = (
    Axis("actuation_dead_time_s", (0.0, 0.05, 0.1, 0.15, 0.2, 0.25, 0.3), "actuation dead time", "ms", 1000.0),
    Axis("localisation_latency_s", (0.0, 0.05, 0.1, 0.2, 0.3), "pose latency", "ms", 1000.0),
    Axis("localisation_position_noise_m", (0.0, 0.05, 0.1, 0.2, 0.5), "position noise sigma", "m"),
    Axis("road_friction_scale", (1.0, 0.8, 0.6, 0.4), "road friction scale", "", rising=False),
)
#: The tolerance table's "how" of a factor at every value of which the controller passed.
PASSES_ALL = "passes all"
#: What a payload mismatch (the plant carries another payload than the controller was built for) changes, by
#: controller: the plant always; of the controller, only what it takes from the vehicle.
PAYLOAD_MISMATCH: dict[str, str] = {
    "clothoid": "the plant only: the controller keeps its tuning (lead filter, identified steering lags, curvature "
    "and rollover limits), made for the preset at its nominal payload",
    "lmpc": "the plant; the controller keeps predicting with the single-track model (mass, yaw inertia, axle "
    "loads) of the vehicle at the nominal payload",
    "nmpc": "the plant; the controller keeps predicting with the single-track model (mass, yaw inertia, axle "
    "loads) of the vehicle at the nominal payload",
    "pure-pursuit": "the plant only: the controller uses the path's geometry and the wheelbase, no vehicle model",
    "stanley": "the plant only: the controller uses the path's geometry and the wheelbase, no vehicle model",
}
#: What a payload mismatch changes for a controller not in PAYLOAD_MISMATCH.
OTHER_CONTROLLER_MISMATCH = "the plant; the controller is built for the vehicle at the nominal payload"
#: The plant's payloads of the payload axis, as fractions of the nominal payload, from the nominal outward.
PAYLOAD_FRACTIONS = (1.0, 0.5, 0.0)
#: A run passes when it completes, its steering does not limit-cycle and its max |CTE| stays within this (m; half
#: of an ISO 3888 lane's spare width for a 2.5 m wide truck is about 0.25 m, so 0.5 m is leaving the lane).
PASS_MAX_CTE_M = 0.5


def _payload_kg(vehicle: str) -> float | None:
    """The plant's own payload (None for a vehicle without one)."""
    return getattr(load_vehicle(vehicle).params, "payload_kg", None)


def payload_axis(vehicle: str) -> Axis | None:
    """The payload factor of a vehicle with a payload (None for one without, or with none on board): the plant
    carries PAYLOAD_FRACTIONS of its nominal payload while the controller stays built for the nominal one
    (controller_payload_kg), so every run of the axis but the base is a payload mismatch.

    Parameters
    ----------
    vehicle : str
        A vehicle preset name or a vehicle TOML file.

    Returns
    -------
    Axis or None
        The payload axis (kg), the nominal payload first, falling; None without a payload.

    Raises
    ------
    WorkbenchInputError
        An unknown vehicle or a vehicle file it cannot read.

    Examples
    --------
    >>> from workbench.apps.robustness import payload_axis
    >>> payload_axis("tractor-semitrailer").values
    (17000.0, 8500.0, 0.0)
    >>> payload_axis("dynamic-bicycle") is None
    True
    """
    nominal = _payload_kg(vehicle)
    if nominal is None or nominal <= 0:
        return None
    values = tuple(nominal * f for f in PAYLOAD_FRACTIONS)
    return Axis("payload_kg", values, f"plant payload (controller built for {nominal:g} kg)", "kg", rising=False)


def robustness_axes(vehicle: str, axes: Sequence[Axis] = AXES) -> tuple[Axis, ...]:
    """The factors of a study on `vehicle`: `axes`, and the payload factor when the vehicle carries a payload.

    Parameters
    ----------
    vehicle : str
        A vehicle preset name or a vehicle TOML file.
    axes : sequence of Axis
        The condition factors (default `AXES`).

    Returns
    -------
    tuple of Axis
        `axes`, then the payload axis when there is one (`payload_axis`).
    """
    payload = payload_axis(vehicle)
    return (*axes, payload) if payload is not None else tuple(axes)


def payload_mismatch(controller: str) -> str:
    """What a payload mismatch changes for `controller` (PAYLOAD_MISMATCH).

    Parameters
    ----------
    controller : str
        A controller's name.

    Returns
    -------
    str
        A phrase for the report; a general one for a controller PAYLOAD_MISMATCH does not name.
    """
    return PAYLOAD_MISMATCH.get(controller, OTHER_CONTROLLER_MISMATCH)


def told_options(controller: str, delays: KnownDelays) -> dict[str, Any]:
    """The options `Controller.informed_config` sets for `delays` on the controller's default config, by name (the
    values that differ from the default); empty for a controller that is told nothing (Stanley, pure pursuit).

    Parameters
    ----------
    controller : str
        A registered controller's name.
    delays : KnownDelays
        The nominal delays told.

    Returns
    -------
    dict
        Option name -> the value told.
    """
    cls = CONTROLLERS[controller]
    default = cls.config_type()
    told = cls.informed_config(default, delays)
    names = (f.name for f in dataclasses.fields(told))
    return {n: getattr(told, n) for n in names if getattr(told, n) != getattr(default, n)}


def plan_robustness(
    scenario: str,
    controllers: Sequence[str],
    vehicle: str,
    speed_kmh: float = 30.0,
    conditions: str = "ideal",
    seed: int = 0,
    track_file: Path | None = None,
    base_dir: Path | None = None,
    axes: Sequence[Axis] | None = None,
    allow_long_run: bool = False,
    allow_infeasible: bool = False,
    warn: Callable[[str], None] | None = warn_on_stderr,
    inform_delays: bool = False,
    circuit_ranges: Path | None = None,
) -> list[PlannedRun]:
    """Every run of the study: per controller, the base run and each axis's other values (axes: None for
    `robustness_axes(vehicle)`; the payload axis's runs keep the controller built for the nominal payload). Each
    axis's value is set on top of `conditions`. A study whose runs may simulate more than the
    bounds of `run_size` (a very low speed) is refused before any run, unless allow_long_run
    (`--allow-long-run`); so is a path the vehicle, at its own payload, cannot follow at the planned speed
    (`feasibility.refuse_infeasible`, as `workbench run` refuses it), unless allow_infeasible
    (`--allow-infeasible`): then where it cannot is said through `warn` (None: silent). inform_delays: every
    run's controller is told the base conditions' nominal delays (`told_options`, the module docstring).
    circuit_ranges: a file whose [circuits] table a circuit:SEED scenario is drawn within (the run parameter of
    that name; relative to base_dir).

    Parameters
    ----------
    scenario : str
        A scenario name or a waypoint file (relative to base_dir).
    controllers : sequence of str
        The registered controllers compared.
    vehicle : str
        A vehicle preset name or a vehicle TOML file.
    speed_kmh : float
        Target speed (km/h) of every run.
    conditions : str
        The base conditions: a preset name or a conditions file.
    seed : int
        The conditions' noise seed.
    track_file : pathlib.Path or None
        The Zandvoort track file (None: where it is looked for).
    base_dir : pathlib.Path or None
        The folder relative paths are taken from (None: the working directory).
    axes : sequence of Axis or None
        The factors (None: `robustness_axes(vehicle)`).
    allow_long_run, allow_infeasible : bool
        Plan runs that would otherwise be refused as too long, or on a path the vehicle cannot follow.
    warn : callable or None
        Called with each place the vehicle cannot follow when allowed (None: silent).
    inform_delays : bool
        Tell every controller the base conditions' nominal delays.
    circuit_ranges : pathlib.Path or None
        The ranges file a circuit:SEED scenario is drawn within (None: the defaults).

    Returns
    -------
    list of PlannedRun
        Each distinct run once, indexed in order.

    Raises
    ------
    WorkbenchInputError
        An unknown name, a value or file refused, a run too long or a path infeasible (unless allowed).
    """
    ranges = None
    if circuit_ranges is not None:
        from workbench.simulation.circuit_ranges import read_circuit_ranges

        circuit_ranges = Path(base_dir or Path.cwd()) / circuit_ranges
        ranges = read_circuit_ranges(circuit_ranges)
    _check_path(scenario, vehicle, speed_kmh, track_file, base_dir, allow_long_run, allow_infeasible, warn, ranges)
    base: dict[str, Any] = {"speed_kmh": speed_kmh, "conditions": conditions, "seed": seed}
    if circuit_ranges is not None:
        base["circuit_ranges"] = circuit_ranges
    told: dict[str, dict[str, Any]] = {}
    if inform_delays:
        named = load_conditions(resolve_conditions(conditions, base_dir or Path.cwd()))
        delays = KnownDelays.from_conditions(named)
        told = {c: options for c in controllers if (options := told_options(c, delays))}
    grids = [dict(base)]
    for axis in robustness_axes(vehicle) if axes is None else axes:
        if axis.parameter == "road_friction_scale" and not load_vehicle(vehicle).has_tyres:
            continue
        grid = base | {axis.parameter: list(axis.values[1:])}
        if axis.parameter == "payload_kg":
            grid["controller_payload_kg"] = axis.values[0]
        grids.append(grid)
    runs: dict[str, PlannedRun] = {}
    for grid in grids:
        spec = StudySpec(
            scenarios=[scenario],
            controllers=list(controllers),
            vehicles=[vehicle],
            grid=grid,
            controller_grid=told,
            track_file=track_file,
            base_dir=base_dir or Path.cwd(),
            description="robustness",
            allow_long_runs=True,  # sized above, as the option asks
            allow_infeasible=True,  # judged above, as the option asks
        )
        for run in spec.plan():
            runs.setdefault(run.run_id, run)
    return [dataclasses.replace(run, index=i) for i, run in enumerate(runs.values())]


def _check_path(
    scenario: str,
    vehicle: str,
    speed_kmh: float,
    track_file: Path | None,
    base_dir: Path | None,
    allow_long_run: bool,
    allow_infeasible: bool,
    warn: Callable[[str], None] | None,
    circuit_ranges: CircuitRanges | None = None,
) -> None:
    """Refuse runs that may simulate more than the bounds of `run_size` (`check_run_size`), unless
    allow_long_run, and a path the vehicle cannot follow at the planned speed (`refuse_infeasible`), unless
    allow_infeasible (then said through `warn`): every run of the study drives the scenario's path at the same
    speed, so one planned path is every run's (the payload axis's lighter plants ask less of the vehicle than its
    own payload). circuit_ranges: what a circuit:SEED scenario is drawn within (None: the defaults)."""
    from workbench.simulation.feasibility import path_feasibility_warnings, refuse_infeasible
    from workbench.simulation.run_config import SimulationConfig
    from workbench.simulation.run_size import RunSize, check_run_size
    from workbench.simulation.scenarios import ScenarioOptions, make_scenario
    from workbench.simulation.simulator import plan_path_speed

    model = load_vehicle(vehicle)
    if not is_named_scenario(scenario):  # a file, relative to base_dir
        scenario = str((base_dir or Path.cwd()) / scenario)
    config = SimulationConfig(speed_kmh=speed_kmh)
    options = ScenarioOptions(model.geometry.width_m, track_file, circuit_ranges)
    path = plan_path_speed(make_scenario(scenario, options).path, config)
    if not allow_long_run:
        size = RunSize.of(path, config, len(model.output_names))
        shorten = f"a higher --speed (now {speed_kmh:g} km/h) shortens it"
        check_run_size(size, f"each run on {path.name}", shorten, "--allow-long-run")
    warnings = path_feasibility_warnings(path, model)
    if not allow_infeasible:
        refuse_infeasible(warnings)
    if warn is not None:
        for warning in warnings:
            warn(warning)


@dataclass(frozen=True)
class RobustnessResult:
    """The study's rows (one per run, the study columns) and what it was asked."""

    rows: pd.DataFrame
    scenario: str
    vehicle: str
    controllers: tuple[str, ...]
    conditions: str
    speed_kmh: float
    axes: tuple[Axis, ...] = AXES
    max_cte_m: float = PASS_MAX_CTE_M
    #: Whether the controllers were told the base conditions' nominal delays (`told_options`).
    inform_delays: bool = False

    def passed(self, row: pd.Series) -> bool:
        """Completed, no steering limit cycle, max |CTE| within max_cte_m.

        Parameters
        ----------
        row : pandas.Series
            A run's row of `rows`.

        Returns
        -------
        bool
            Whether the run passes (`why_failed` is "").
        """
        return self.why_failed(row) == ""

    def why_failed(self, row: pd.Series) -> str:
        """Why the run does not pass ("" when it does).

        Parameters
        ----------
        row : pandas.Series
            A run's row of `rows`.

        Returns
        -------
        str
            Its status when it did not complete, "limit cycle", "max |CTE| > ... m", or "".
        """
        if row["status"] != "completed":
            return str(row["status"])
        if bool(row["limit_cycle"]):
            return "limit cycle"
        if not row["max_abs_cte_m"] <= self.max_cte_m:
            return f"max |CTE| > {self.max_cte_m:g} m"
        return ""

    def axis_rows(self, axis: Axis, controller: str) -> pd.DataFrame:
        """The runs of one axis and controller, the base run included, by the axis's value (the base's value where
        the column is empty), in the axis's order.

        Parameters
        ----------
        axis : Axis
            One of the study's axes.
        controller : str
            One of the study's controllers.

        Returns
        -------
        pandas.DataFrame
            The rows with a ``value`` column (the axis's parameter, in its unit), from the base outward.
        """
        df = self.rows[self.rows["controller"] == controller]
        others = [a.parameter for a in self.axes if a is not axis and a.parameter in df]
        keep = df[df[others].isna().all(axis=1)].copy()
        column = keep[axis.parameter] if axis.parameter in keep else pd.Series(math.nan, index=keep.index)
        keep["value"] = column.fillna(axis.values[0]).astype(float)
        return keep.sort_values("value", ascending=axis.rising)

    def tolerance(self) -> pd.DataFrame:
        """Per controller and axis: the last value, going outward from the base, at which every run so far passed,
        the first at which one did not (None when all passed) and how it failed (PASSES_ALL when none did).

        Returns
        -------
        pandas.DataFrame
            controller, factor, unit, tolerated, fails_at (both in the shown unit), how.
        """
        out = []
        for controller in self.controllers:
            for axis in self.axes:
                rows = self.axis_rows(axis, controller)
                if len(rows) <= 1:
                    continue
                tolerated, failed, why = None, None, PASSES_ALL
                for _, row in rows.iterrows():
                    if self.passed(row):
                        tolerated = row["value"]
                        continue
                    failed, why = row["value"], self.why_failed(row)
                    break
                out.append(
                    {
                        "controller": controller,
                        "factor": axis.label,
                        "unit": axis.unit,
                        "tolerated": None if tolerated is None else tolerated * axis.shown_factor,
                        "fails_at": None if failed is None else failed * axis.shown_factor,
                        "how": why,
                    }
                )
        return pd.DataFrame(out)

    def payload_axis(self) -> Axis | None:
        """The payload factor among the study's axes (None when the vehicle carries no payload).

        Returns
        -------
        Axis or None
            The axis of payload_kg.
        """
        return next((a for a in self.axes if a.parameter == "payload_kg"), None)

    def mismatch(self) -> pd.DataFrame:
        """The payload axis's runs per controller, the base (matched) run first: the plant's payload, the payload
        the controller was built for, status, max |CTE|, its change from the base run, oscillation, limit cycle,
        and what the mismatch changes for that controller (`payload_mismatch`). Empty without a payload axis.

        Returns
        -------
        pandas.DataFrame
            One row per run of the payload axis, columns headed as the report shows them.
        """
        axis = self.payload_axis()
        if axis is None:
            return pd.DataFrame()
        tables = []
        for controller in self.controllers:
            rows = self.axis_rows(axis, controller)
            base = rows["max_abs_cte_m"].iloc[0] if len(rows) else math.nan
            tables.append(
                pd.DataFrame(
                    {
                        "controller": controller,
                        "plant payload (kg)": rows["value"],
                        "controller built for (kg)": axis.values[0],
                        "status": rows["status"],
                        "max |CTE| (m)": rows["max_abs_cte_m"],
                        "change from the base (m)": rows["max_abs_cte_m"] - base,
                        "steering oscillation (deg)": rows["steer_oscillation_deg"],
                        "limit cycle": rows["limit_cycle"],
                        "the mismatch changes": payload_mismatch(controller),
                    }
                )
            )
        return pd.concat(tables, ignore_index=True)

    def payload_summary(self) -> list[str]:
        """One line per controller on the payload axis: max |CTE| at each plant payload, from the matched base run
        outward, and what the mismatch changes for that controller. Empty without a payload axis.

        Returns
        -------
        list of str
            A heading line, then one indented line per controller.
        """
        table, axis = self.mismatch(), self.payload_axis()
        if table.empty or axis is None:  # no payload axis (the table is empty then)
            return []
        plants = ", ".join(f"{v:g}" for v in axis.values)
        lines = [f"payload: the plant carries {plants} kg, every controller is built for {axis.values[0]:g} kg"]
        for controller, rows in table.groupby("controller", sort=False):
            cte = " -> ".join("none" if math.isnan(v) else f"{v:.4g}" for v in rows["max |CTE| (m)"].astype(float))
            lines.append(f"  {controller}: max |CTE| {cte} m; the mismatch changes {payload_mismatch(controller)}")
        return lines

    def figure(self, axis: Axis) -> Figure:
        """Max |CTE|, steering oscillation and completion against the axis's value, a line per controller.

        Parameters
        ----------
        axis : Axis
            One of the study's axes.

        Returns
        -------
        matplotlib.figure.Figure
            A pyplot figure of three panels (the caller closes it).
        """
        import matplotlib.pyplot as plt

        fig, panels = plt.subplots(1, 3, figsize=(13, 3.6), layout="constrained")
        for controller in self.controllers:
            rows = self.axis_rows(axis, controller)
            x = rows["value"] * axis.shown_factor
            panels[0].plot(x, rows["max_abs_cte_m"], "o-", label=controller)
            panels[1].plot(x, rows["steer_oscillation_deg"], "o-", label=controller)
            passes = [1.0 if self.passed(r) else 0.0 for _, r in rows.iterrows()]
            panels[2].plot(x, passes, "o-", label=controller)
        unit = f" ({axis.unit})" if axis.unit else ""
        for ax, ylabel in zip(
            panels, ("max |CTE| (m)", "steering oscillation (deg)", "passes (1) / fails (0)"), strict=True
        ):
            ax.set(xlabel=f"{axis.label}{unit}", ylabel=ylabel)
            ax.grid(True, alpha=0.3)
        panels[0].set_yscale("log")
        panels[2].set_ylim(-0.1, 1.1)
        panels[0].legend()
        fig.suptitle(f"{self.scenario}, {self.vehicle}: {axis.label}")
        return fig

    def report_html(self) -> str:
        """The self-contained report (figures embedded as base64 PNG), a page of `report.html_page`.

        Returns
        -------
        str
            The whole HTML document.
        """
        from workbench.apps.report import figure_png, html_page, png_figure, text_table

        title = f"Robustness: {', '.join(self.controllers)} on {self.vehicle}, {self.scenario}"
        intro = (
            f"Target speed {self.speed_kmh:g} km/h; each factor varied on its own around the base conditions "
            f"{self.conditions}. A run passes when it completes, its steering does not limit-cycle and its max |CTE| "
            f"stays within {self.max_cte_m:g} m. "
        )
        if self.inform_delays:
            intro += "Every run's controller was told the base conditions' nominal delays, not the varied ones."
        else:
            intro += "The controllers were not told the conditions' delays (--inform-delays tells them the base's)."
        parts = ["<h2>Where each controller stops passing</h2>", text_table(self.tolerance(), missing="none")]
        mismatch, payload = self.mismatch(), self.payload_axis()
        if len(mismatch) and payload is not None:  # the table has rows only with a payload axis
            note = (
                f"The plant carries the payloads shown; every controller stays built for the nominal "
                f"{payload.values[0]:g} kg. The last column says what that changes for each controller."
            )
            parts += ["<h2>Payload mismatch</h2>", f"<p>{html.escape(note)}</p>", text_table(mismatch, missing="none")]
        for axis in self.axes:
            if all(len(self.axis_rows(axis, c)) <= 1 for c in self.controllers):
                continue  # not varied (the friction of a model without tyres)
            parts.append(png_figure(figure_png(self.figure(axis)), f"degradation against {axis.label}"))
        return html_page(title, parts, intro)

    def save(self, out_dir: str | Path) -> list[Path]:
        """DIR/report.html and DIR/tolerance.csv (results.parquet is written as the runs finish).

        Parameters
        ----------
        out_dir : str or pathlib.Path
            The study's folder DIR (it exists: the runs were written there).

        Returns
        -------
        list of pathlib.Path
            report.html and tolerance.csv.
        """
        out = Path(out_dir)
        report, table = out / "report.html", out / "tolerance.csv"
        report.write_text(self.report_html(), encoding="utf-8")
        self.tolerance().to_csv(table, index=False)
        return [report, table]


def run_robustness(
    runs: Sequence[PlannedRun],
    out_dir: str | Path,
    backend: Backend,
    scenario: str,
    vehicle: str,
    controllers: Sequence[str],
    conditions: str = "ideal",
    speed_kmh: float = 30.0,
    progress: bool = False,
    max_cte_m: float = PASS_MAX_CTE_M,
    inform_delays: bool = False,
) -> RobustnessResult:
    """Run (or resume) the planned runs into out_dir (DIR/runs/, DIR/results.parquet) and return the result;
    inform_delays: whether `plan_robustness` told the controllers the base conditions' delays (for the report).

    Parameters
    ----------
    runs : sequence of PlannedRun
        The study's runs (`plan_robustness`), at least one.
    out_dir : str or pathlib.Path
        The study's folder: runs/ (rows already there are not run again) and results.parquet.
    backend : Backend
        Where the runs execute (`make_backend`), left running.
    scenario : str
        The scenario, for the report.
    vehicle : str
        A vehicle preset name or a vehicle TOML file.
    controllers : sequence of str
        The controllers planned, in the report's order.
    conditions : str
        The base conditions, for the report.
    speed_kmh : float
        The target speed (km/h), for the report.
    progress : bool
        Show a bar on stderr counting the runs left to do.
    max_cte_m : float
        The largest max |CTE| (m) a passing run may have; positive.
    inform_delays : bool
        Whether the runs' controllers were told the base conditions' delays.

    Returns
    -------
    RobustnessResult
        The rows and what was asked; `tolerance()` says where each controller stops passing.

    Raises
    ------
    WorkbenchInputError
        No runs, or max_cte_m not positive.
    BackendError
        The backend's machinery failed; the rows already written stay.

    Examples
    --------
    >>> from workbench.apps.robustness import plan_robustness, run_robustness
    >>> from workbench.apps.studies import make_backend
    >>> runs = plan_robustness("dlc", ["clothoid", "stanley"], "dynamic-bicycle")  # doctest: +SKIP
    >>> with make_backend("local", workers=2) as backend:  # doctest: +SKIP
    ...     result = run_robustness(runs, "runs/robust", backend, "dlc", "dynamic-bicycle", ["clothoid", "stanley"])
    >>> result.tolerance()  # doctest: +SKIP
    """
    require_positive("max_cte_m", max_cte_m)
    if not runs:
        raise WorkbenchInputError("the robustness study plans no runs")
    rows, _ = execute_runs(runs, RunStore(out_dir), backend, progress, "robustness")
    write_results(out_dir, rows)
    frame = pd.DataFrame(rows)
    axes = robustness_axes(vehicle)
    return RobustnessResult(
        frame, scenario, vehicle, tuple(controllers), conditions, speed_kmh, axes, max_cte_m, inform_delays
    )


__all__ = [
    "AXES",
    "PASSES_ALL",
    "PAYLOAD_MISMATCH",
    "Axis",
    "RobustnessResult",
    "payload_axis",
    "payload_mismatch",
    "plan_robustness",
    "robustness_axes",
    "run_robustness",
    "told_options",
]
