"""The paper's figures regenerated on the open models, and our numbers beside the ones it reports
(`workbench paper --out DIR`).

Shaju, Southward & Ahmadian (2024), all on the loaded tractor-semitrailer at 30 km/h as in the paper:
  4b   Fréchet distance against lookahead on a curve            (workbench.apps.lookahead_study)
  5b   least Fréchet distance against initial CTE               (workbench.apps.lookahead_study)
  6    curvature limits from rollover against speed             (tuning.rollover)
  7    curvature response to one steering profile, (a) against payload, (b) against speed
  8    the lag of Eq. 5 fitted to a DLC and a step series       (tuning.lag_fit)
  9    time-domain check of the lead filter                     (tuning.lead_design.validate)
  10   Bode plot of lag, lead filter and cascade                (tuning.lead_design)
  11-16 the clothoid controller on the figure-8, the DLC and Zandvoort: (a) tracked trajectory, (b) CTE against
       time; then (a) speed against arc length, (b) steering-wheel angle against time.
Zandvoort (Figures 15, 16 and its table row) needs the TUMFTM track file and is skipped, saying so, without it.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

from workbench.apps.lookahead_study import frechet_vs_lookahead, min_frechet_vs_cte
from workbench.simulation import plots
from workbench.simulation.result import SimulationResult
from workbench.simulation.scenarios import ZANDVOORT_ENV, ScenarioOptions, make_scenario
from workbench.simulation.simulator import Simulation, SimulationConfig
from workbench.vehicles import make_vehicle

SPEED_KMH = 30.0
TRUCK = "tractor-semitrailer"
#: Figure 7a payloads (kg) and 7b speeds (km/h); the paper's steering profile is the DLC one.
FIG7_PAYLOADS_KG = (0.0, 8500.0, 17000.0)
FIG7_SPEEDS_KMH = (30.0, 60.0, 90.0)
FIG6_SPEEDS_KMH = (10.0, 20.0, 30.0, 40.0, 50.0, 60.0, 70.0, 80.0, 90.0, 100.0)
MPH_PER_MPS = 3600.0 / 1609.344

#: The paper's reported figures (section 6): quantity -> (what it reports, our value's unit, bound or None).
PAPER_REPORTS: dict[str, tuple[str, str]] = {
    "figure8 max |CTE|": ("below 0.4 m (Figure 11b)", "m"),
    "dlc max |CTE|": ("within ±0.2 m (Figure 13b)", "m"),
    "zandvoort max |CTE|": ("within ±0.4 m (Figure 15b)", "m"),
    "figure8 steering-wheel peak": ("about 300 deg (Figure 12b)", "deg"),
    "figure8 speed at the largest curvature rate": ("about 17 mph (Figure 12a)", "mph"),
}


@dataclass(frozen=True, eq=False)
class PaperResult:
    """files: what was written; table: our numbers beside the paper's; skipped: what could not run, and why."""

    files: list[Path]
    table: pd.DataFrame
    skipped: list[str] = field(default_factory=list)


def _save(ax_or_fig: plt.Axes | plt.Figure, path: Path) -> Path:
    fig = ax_or_fig if isinstance(ax_or_fig, plt.Figure) else ax_or_fig.figure
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def _lookahead_figures(out: Path) -> list[Path]:
    path = make_scenario("figure8").path
    s_on_curve = float(np.argmax(np.abs(path.curvature_1pm)) * path.spacing_m)
    fig4 = frechet_vs_lookahead(path, s_on_curve)
    fig5 = min_frechet_vs_cte(path, s_on_curve, np.linspace(0.0, 2.0, 11))
    return [
        _save(fig4.plot(), out / "fig04b_frechet_vs_lookahead.png"),
        _save(fig5.plot(), out / "fig05b_min_frechet_vs_cte.png"),
    ]


def _tuning_figures(out: Path) -> list[Path]:
    from tuning.lag_fit import fit_lag
    from tuning.lead_design import design_lead, validate
    from tuning.plots import bode_figure, lag_fit_figure, rollover_figure, validation_figure
    from tuning.rollover import rollover_limits
    from tuning.schedule import identification_logs

    truck = make_vehicle(TRUCK)
    written = [rollover_figure(rollover_limits(truck, FIG6_SPEEDS_KMH), out / "fig06_rollover_limits.png", TRUCK)]
    written.append(_fig7(out / "fig07_curvature_vs_payload_and_speed.png"))
    logs = identification_logs(truck, SPEED_KMH)
    fit = fit_lag(logs, truck.geometry)
    design = design_lead(fit.lag)
    written.append(lag_fit_figure(fit, out / "fig08_lag_fit.png"))
    written.append(
        validation_figure([validate(design, log, truck.geometry) for log in logs], out / "fig09_lead_validation.png")
    )
    written.append(bode_figure(design, out / "fig10_bode.png"))
    return written


def _fig7(path: Path) -> Path:
    """Figure 7: the rear-axle path curvature for the same DLC steering profile, (a) at three payloads at 30 km/h,
    (b) at three speeds with the full payload."""
    from tuning.data_generation import generate_open_loop_log
    from tuning.lag_fit import path_curvature
    from tuning.log_file import VehicleLog
    from tuning.maneuvers import Maneuver

    maneuver = Maneuver("dlc", amplitude_deg=60.0, duration_s=20.0)
    fig, (ax_a, ax_b) = plt.subplots(1, 2, figsize=(11, 4), layout="constrained")
    for ax, cases, title in (
        (ax_a, [(p, SPEED_KMH) for p in FIG7_PAYLOADS_KG], "(a) payload, at 30 km/h"),
        (ax_b, [(FIG7_PAYLOADS_KG[-1], v) for v in FIG7_SPEEDS_KMH], "(b) speed, full payload"),
    ):
        for payload, speed in cases:
            log = VehicleLog.from_frame(
                generate_open_loop_log(make_vehicle(TRUCK, payload_kg=payload), maneuver, speed)
            )
            label = f"{payload / 1000:g} t payload" if ax is ax_a else f"{speed:g} km/h"
            ax.plot(log.t_s, path_curvature(log), label=label)
        ax.set(xlabel="time (s)", ylabel="path curvature (1/m)", title=f"Figure 7{title}")
        ax.legend(fontsize="small")
    return _save(fig, path)


def _tracking(scenario: str, options: ScenarioOptions) -> SimulationResult:
    from tuning.own_tuning import tuned_controller

    vehicle = make_vehicle(TRUCK)
    scen = make_scenario(scenario, ScenarioOptions(vehicle.geometry.width_m, options.track_file))
    controller = tuned_controller("clothoid", vehicle)
    return Simulation(scen, vehicle, controller, SimulationConfig(speed_kmh=SPEED_KMH)).run()


def _cte_vs_time(result: SimulationResult, ax: plt.Axes | None = None) -> plt.Axes:
    if ax is None:
        _, ax = plt.subplots(figsize=(8, 4.5), layout="constrained")
    ax.plot(result.trace["t_s"], result.trace["cte_m"])
    ax.axhline(0.0, color="k", lw=0.5)
    ax.set(xlabel="time (s)", ylabel="cross-track error (m)", title=f"{result.scenario.name}: CTE vs time")
    return ax


#: Figures 11-16: (figure number, scenario, plot, file suffix).
TRACKING_FIGURES: tuple[tuple[int, str, Callable[[SimulationResult], plt.Axes], str], ...] = (
    (11, "figure8", plots.trajectory, "a_trajectory"),
    (11, "figure8", _cte_vs_time, "b_cte_vs_time"),
    (12, "figure8", plots.speed_vs_distance, "a_speed_vs_arc_length"),
    (12, "figure8", plots.steering_vs_time, "b_steering_vs_time"),
    (13, "dlc", plots.trajectory, "a_trajectory"),
    (13, "dlc", _cte_vs_time, "b_cte_vs_time"),
    (14, "dlc", plots.speed_vs_distance, "a_speed_vs_arc_length"),
    (14, "dlc", plots.steering_vs_time, "b_steering_vs_time"),
    (15, "zandvoort", plots.trajectory, "a_trajectory"),
    (15, "zandvoort", _cte_vs_time, "b_cte_vs_time"),
    (16, "zandvoort", plots.speed_vs_distance, "a_speed_vs_arc_length"),
    (16, "zandvoort", plots.steering_vs_time, "b_steering_vs_time"),
)


def speed_at_largest_curvature_rate_mps(result: SimulationResult) -> float:
    """The vehicle's speed (m/s) where the path's |dκ/ds| is largest (the paper's Figure 12a remark)."""
    path = result.path
    rate = np.abs(np.gradient(path.curvature_1pm, path.spacing_m))
    s_peak = float(np.argmax(rate) * path.spacing_m)
    return float(np.interp(s_peak, result.trace["path_s_m"], result.trace["speed_mps"]))


def _table(runs: dict[str, SimulationResult]) -> pd.DataFrame:
    ours: dict[str, float] = {}
    for name, result in runs.items():
        ours[f"{name} max |CTE|"] = float(result.metrics.max_abs_cte_m or math.nan)
    if "figure8" in runs:
        ours["figure8 steering-wheel peak"] = float(runs["figure8"].metrics.max_abs_steer_wheel_deg or math.nan)
        ours["figure8 speed at the largest curvature rate"] = (
            speed_at_largest_curvature_rate_mps(runs["figure8"]) * MPH_PER_MPS
        )
    rows = [
        {"quantity": key, "paper": reported, "ours": ours.get(key, math.nan), "unit": unit}
        for key, (reported, unit) in PAPER_REPORTS.items()
    ]
    return pd.DataFrame(rows)


def reproduce_paper(out_dir: str | Path, options: ScenarioOptions | None = None) -> PaperResult:
    """Write every figure to out_dir and the comparison table as paper_vs_ours.csv; return what was written."""
    out = Path(out_dir)
    options = options or ScenarioOptions()
    skipped = []
    scenarios = ["figure8", "dlc"]
    if _track_given(options):  # a track given must be usable: a broken one is refused before any work
        make_scenario("zandvoort", options)
        scenarios.append("zandvoort")
    else:
        skipped.append("Figures 15-16 and the Zandvoort row: no track file (give --track or $WORKBENCH_ZANDVOORT_CSV)")
    out.mkdir(parents=True, exist_ok=True)
    files = _lookahead_figures(out) + _tuning_figures(out)
    runs = {name: _tracking(name, options) for name in scenarios}
    for number, scenario, draw, suffix in TRACKING_FIGURES:
        if scenario in runs:
            files.append(_save(draw(runs[scenario]), out / f"fig{number}{suffix}_{scenario}.png"))
    table = _table(runs)
    table_path = out / "paper_vs_ours.csv"
    table.to_csv(table_path, index=False)
    files.append(table_path)
    return PaperResult(files, table, skipped)


def _track_given(options: ScenarioOptions) -> bool:
    """Whether a Zandvoort track file is given (`--track` or $WORKBENCH_ZANDVOORT_CSV)."""
    return options.track_file is not None or bool(os.environ.get(ZANDVOORT_ENV))


__all__ = ["PAPER_REPORTS", "PaperResult", "reproduce_paper", "speed_at_largest_curvature_rate_mps"]
