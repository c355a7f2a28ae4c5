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
Zandvoort (Figures 15, 16 and its table row) needs the TUMFTM track file and is skipped, saying so, without it
or when the file given or found is another (`zandvoort_skip_reason`).

Beside the PNGs and paper_vs_ours.csv (the values the paper reports, ours beside them) it writes report.html: one
self-contained page (figures embedded, as the other reports) with each figure under the paper's caption, what the
paper's text says of it and our numbers. A progress line on stderr counts the steps (a tracking run also shows its
metres), as `workbench run` and `sweep` do.
"""

from __future__ import annotations

import html
import math
import os
import re
import sys
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
from tqdm import tqdm

from workbench.apps.lookahead_study import (
    DEFAULT_FRECHET_THRESHOLD_M,
    FrechetVsLookahead,
    frechet_vs_lookahead,
    growing_stretch,
    min_frechet_vs_cte,
)
from workbench.base.errors import WorkbenchInputError
from workbench.base.path import ReferencePath
from workbench.simulation import plots
from workbench.simulation.result import SimulationResult
from workbench.simulation.scenarios import (
    ZANDVOORT_ENV,
    ScenarioOptions,
    is_zandvoort_file,
    make_scenario,
    zandvoort_track_file,
)
from workbench.simulation.simulator import Simulation, SimulationConfig
from workbench.vehicles import make_vehicle

SPEED_KMH = 30.0
TRUCK = "tractor-semitrailer"
#: Figure 7a payloads (kg) and 7b speeds (km/h); the paper's steering profile is the DLC one.
FIG7_PAYLOADS_KG = (0.0, 8500.0, 17000.0)
FIG7_SPEEDS_KMH = (30.0, 60.0, 90.0)
FIG6_SPEEDS_KMH = (10.0, 20.0, 30.0, 40.0, 50.0, 60.0, 70.0, 80.0, 90.0, 100.0)
#: Figure 5b's initial CTEs (m).
FIG5_CTES_M = np.linspace(0.0, 2.0, 11)
#: The paper's Fréchet-distance threshold (m, section 3); Figure 4b draws the controller's own
#: (`lookahead_study.DEFAULT_FRECHET_THRESHOLD_M`, the ClothoidConfig default).
PAPER_FRECHET_THRESHOLD_M = 0.5
MPH_PER_MPS = 3600.0 / 1609.344

#: The paper's reported figures (section 6): quantity -> (what it reports, with its figure, and our value's unit).
PAPER_REPORTS: dict[str, tuple[str, str]] = {
    "figure8 max |CTE|": ("below 0.4 m (Figure 11b)", "m"),
    "dlc max |CTE|": ("within ±0.2 m (Figure 13b)", "m"),
    "zandvoort max |CTE|": ("within ±0.4 m (Figure 15b)", "m"),
    "figure8 steering-wheel peak": ("about 300 deg (Figure 12b)", "deg"),
    "figure8 speed at the largest curvature rate": ("about 17 mph (Figure 12a)", "mph"),
}

#: Each regenerated figure: the paper's caption, and what its text says of the figure (sections 3-6).
PAPER_FIGURES: dict[int, tuple[str, str]] = {
    4: (
        "(a) Pictorial representation of deviation between the locally fitted clothoid and the reference path. (b) "
        "Variation of Fréchet distance with respect to the distance between the current vehicle coordinates and the "
        "target point.",
        "The Fréchet distance grows notably with the lookahead where the path curves; a threshold on it (0.5 m) "
        "sets the lookahead. We draw (b) where it grows most on the figure-8 (a bend's entry), with our controller's "
        "threshold and the lookahead it picks, and on the arc of constant curvature beside it.",
    ),
    5: (
        "(a) Pictorial representation of deviation between the locally fitted clothoid and the reference path. (b) "
        "Minimum Fréchet distance vs. initial cross-track error.",
        "The minimum Fréchet distance (over lookaheads of 5-20 m) grows with the initial cross-track error. We draw "
        "(b).",
    ),
    6: (
        "Curvature saturation limits based on roll-over speeds.",
        "Step-steer tests to rollover: the curvature limit falls as the speed rises.",
    ),
    7: (
        "Variation of curvature w.r.t, (a) payload mass, (b) vehicle speed for the same steering profile input.",
        "The lag due to payload inertia is negligible; it grows with the speed.",
    ),
    8: (
        "Characterization of a second-order-lag equation (transfer function) relating the steering wheel angle (i/p) "
        "to the realized curvature (o/p) when vehicle speed is ~30 kmph. (a) Dual-lane-change maneuver. (b) Series "
        "of step inputs.",
        "The second-order lag of Eq. 5 mirrors the lag of the TruckSim truck (its ωn and ζ are not given).",
    ),
    9: (
        "Time–domain validation of lead filter. (a) Dual-lane-change maneuver. (b) Step series maneuver.",
        "Through the lead filter, the lagged response aligns with the kinematic (unlagged) curvature.",
    ),
    10: (
        "Frequency response of the plant (estimated lag transfer function), cascaded dynamics, and compensator "
        "(lead filter) (a) Magnitude and (b) Phase plot.",
        "The lead filter raises the bandwidth and reduces the phase lag at the frequencies of interest.",
    ),
    11: (
        "(a) Tracked trajectory of an 8-shaped figure. (b) CTE vs. time plot.",
        "The maximum CTE stays below 0.4 m, largest where the curvature rate peaks.",
    ),
    12: (
        "(a) Tracked speed vs. arc length. (b) Steering angle vs. time plot for the 8-shaped-figure tracking.",
        "About 17 mph where the curvature rate is largest; the steering wheel peaks at around 300 degrees.",
    ),
    13: (
        "(a) Tracked trajectory of a dual-lane-change (DLC) maneuver. (b) CTE vs. time plot.",
        "A near-perfect overlap with the path; the CTE fluctuates within ±0.2 m.",
    ),
    14: (
        "(a) Tracked speed vs. arc length. (b) Steering angle vs. time plot for the DLC trajectory tracking.",
        "Active steering with some peaks, but smooth commands for the speeds held (no values given).",
    ),
    15: (
        "(a) Tracked trajectory of the Zandvoort racetrack. (b) CTE vs. time plot.",
        "The trajectory closely mirrors the path; the CTE stays within a narrow band of ±0.4 m.",
    ),
    16: (
        "(a) Tracked speed vs. arc length. (b) Steering angle vs. time plot for the Zandvoort racetrack.",
        "Frequent steering adjustments with some sharp spikes in the complex turns (no values given).",
    ),
}


@dataclass(frozen=True, eq=False)
class PaperResult:
    """files: what was written (report.html last); table: our numbers beside the paper's; skipped: what could not
    run, and why; notes: our numbers on each figure besides the table's (figure number -> text)."""

    files: list[Path]
    table: pd.DataFrame
    skipped: list[str] = field(default_factory=list)
    notes: dict[int, str] = field(default_factory=dict)


#: What a step writes: its files, and our numbers on its figures (figure number -> text).
StepOutput = tuple[list[Path], dict[int, str]]


def _save(ax_or_fig: plt.Axes | plt.Figure, path: Path) -> Path:
    fig = ax_or_fig.figure.get_figure(root=True)  # the figure itself, or the axes' (root) figure
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def tightest_curve_m(path: ReferencePath) -> float:
    """Arc length (m) of the path's largest |curvature| (its first sample)."""
    return float(np.argmax(np.abs(path.curvature_1pm)) * path.spacing_m)


def figure_4b(path: ReferencePath) -> tuple[plt.Axes, FrechetVsLookahead, FrechetVsLookahead]:
    """Figure 4b: the Fréchet distance against the lookahead where it grows most on the path (`growing_stretch`: a
    bend's entry, where the curvature ahead changes), with the controller's threshold and the lookahead it picks;
    beside it, on the tightest curve's constant curvature, where the fitted clothoid is the arc itself (zero at every
    lookahead). Returns the axes and the two sweeps (growing, on the arc)."""
    growing = growing_stretch(path, DEFAULT_FRECHET_THRESHOLD_M)
    on_arc = frechet_vs_lookahead(path, tightest_curve_m(path))
    ax = growing.plot(threshold_m=DEFAULT_FRECHET_THRESHOLD_M)
    ax.lines[0].set_label(f"a bend's entry: {growing.label}")
    ax.plot(on_arc.lookahead_m, on_arc.frechet_m, "s", ms=2.5, color="tab:gray", label=f"on the arc: {on_arc.label}")
    ax.set_title(f"{path.name}: Fréchet distance vs lookahead (controller's threshold)")
    ax.legend(fontsize="small", loc="upper left")
    return ax, growing, on_arc


def _lookahead_figures(out: Path) -> StepOutput:
    path = make_scenario("figure8").path
    ax, fig4, on_arc = figure_4b(path)
    fig5 = min_frechet_vs_cte(path, tightest_curve_m(path), FIG5_CTES_M)
    crossing = fig4.lookahead_m[np.flatnonzero(fig4.frechet_m > DEFAULT_FRECHET_THRESHOLD_M)[0]]
    notes = {
        4: f"On the figure-8 at s = {fig4.s_m:g} m (a bend's entry, curvature {path.curvature(fig4.s_m):.3g} 1/m "
        f"rising): {fig4.frechet_m[0]:.3g} m at {fig4.lookahead_m[0]:g} m lookahead, {fig4.frechet_m[-1]:.3g} m at "
        f"{fig4.lookahead_m[-1]:g} m, above the controller's threshold ({DEFAULT_FRECHET_THRESHOLD_M:g} m; the "
        f"paper's: {PAPER_FRECHET_THRESHOLD_M:g} m) from {crossing:g} m, so the search picks "
        f"{fig4.chosen_lookahead_m():g} m. On the arc (s = {on_arc.s_m:.4g} m) at most "
        f"{np.max(on_arc.frechet_m):.2g} m at any lookahead: the fitted clothoid is the arc itself",
        5: f"{fig5.min_frechet_m[0]:.3g} m at {fig5.cte_m[0]:g} m initial CTE, {fig5.min_frechet_m[-1]:.3g} m at "
        f"{fig5.cte_m[-1]:g} m",
    }
    files = [
        _save(ax, out / "fig04b_frechet_vs_lookahead.png"),
        _save(fig5.plot(), out / "fig05b_min_frechet_vs_cte.png"),
    ]
    return files, notes


def _rollover_figure(out: Path) -> StepOutput:
    from tuning.plots import rollover_figure
    from tuning.rollover import rollover_limits

    limits = rollover_limits(make_vehicle(TRUCK), FIG6_SPEEDS_KMH)
    first, last = limits[0], limits[-1]
    note = (
        f"{first.path_curvature_1pm:.3g} 1/m at {first.speed_kmh:g} km/h ({first.limited_by}), "
        f"{last.path_curvature_1pm:.3g} 1/m at {last.speed_kmh:g} km/h ({last.limited_by})"
    )
    return [rollover_figure(limits, out / "fig06_rollover_limits.png", TRUCK)], {6: note}


def _lag_figures(out: Path) -> StepOutput:
    """Figures 8-10: the lag of Eq. 5 identified on the truck at 30 km/h, the lead filter designed for it, its
    time-domain check and Bode plot."""
    from tuning.lag_fit import fit_lag
    from tuning.lead_design import design_lead, validate
    from tuning.plots import bode_figure, lag_fit_figure, validation_figure
    from tuning.schedule import identification_logs

    truck = make_vehicle(TRUCK)
    logs = identification_logs(truck, SPEED_KMH)
    fit = fit_lag(logs, truck.geometry)
    design = design_lead(fit.lag)
    files = [
        lag_fit_figure(fit, out / "fig08_lag_fit.png"),
        validation_figure([validate(design, log, truck.geometry) for log in logs], out / "fig09_lead_validation.png"),
        bode_figure(design, out / "fig10_bode.png"),
    ]
    note = f"ωn {fit.lag.omega_n_rad_s:.3g} rad/s, ζ {fit.lag.zeta:.3g} (NRMSE {fit.nrmse:.3g}) at {SPEED_KMH:g} km/h"
    return files, {8: note}


def _fig7(out: Path) -> StepOutput:
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
    return [_save(fig, out / "fig07_curvature_vs_payload_and_speed.png")], {}


def _tracking(scenario: str, options: ScenarioOptions, progress: bool = False) -> SimulationResult:
    from tuning.own_tuning import tuned_controller

    vehicle = make_vehicle(TRUCK)
    scen = make_scenario(scenario, ScenarioOptions(vehicle.geometry.width_m, options.track_file))
    controller = tuned_controller("clothoid", vehicle)
    return Simulation(scen, vehicle, controller, SimulationConfig(speed_kmh=SPEED_KMH)).run(progress=progress)


def _cte_vs_time(result: SimulationResult, ax: plt.Axes | None = None) -> plt.Axes:
    if ax is None:
        _, ax = plt.subplots(figsize=(8, 4.5), layout="constrained")
    ax.plot(result.trace["t_s"], result.trace["cte_m"])
    ax.axhline(0.0, color="k", lw=0.5)
    ax.set(xlabel="time (s)", ylabel="cross-track error (m)", title=f"{result.scenario.name}: CTE vs time")
    return ax


#: Figures 11-16: (figure number, scenario, plot, file suffix).
TRACKING_FIGURES: tuple[tuple[int, str, Callable[[SimulationResult, plt.Axes | None], plt.Axes], str], ...] = (
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
    """The vehicle's speed (m/s) where the path's |dκ/ds| is largest (the paper's Figure 12a remark).

    Parameters
    ----------
    result : SimulationResult
        A run, its trace with path_s_m and speed_mps.

    Returns
    -------
    float
        Speed (m/s), interpolated at that arc length.
    """
    path = result.path
    rate = np.abs(np.gradient(path.curvature_1pm, path.spacing_m))
    s_peak = float(np.argmax(rate) * path.spacing_m)
    return float(np.interp(s_peak, result.trace["path_s_m"], result.trace["speed_mps"]))


def _tracking_notes(runs: dict[str, SimulationResult]) -> dict[int, str]:
    """Our numbers on each run's two figures: max |CTE| and where it is; speed range and steering."""
    notes = {}
    for number, scenario, _, suffix in TRACKING_FIGURES:
        result = runs.get(scenario)
        if result is None or not suffix.startswith("a"):
            continue
        metrics, trace = result.metrics, result.trace
        if number % 2:  # trajectory and CTE: 11, 13, 15
            worst = int(np.argmax(np.abs(trace["cte_m"])))
            notes[number] = (
                f"max |CTE| {metrics.max_abs_cte_m:.3g} m at t = {trace['t_s'][worst]:.1f} s, RMS "
                f"{metrics.rms_cte_m:.3g} m ({result.status.value})"
            )
        else:  # speed and steering: 12, 14, 16
            speed = trace["speed_mps"] * 3.6
            notes[number] = (
                f"speed {np.min(speed):.2f}-{np.max(speed):.2f} km/h; max |steering wheel| "
                f"{metrics.max_abs_steer_wheel_deg:.0f} deg, RMS steering rate {metrics.rms_steer_rate_deg_s:.0f} deg/s"
            )
    return notes


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


def figure_number(path: Path) -> int:
    """The paper's figure a written file shows (its name starts "figNN").

    Parameters
    ----------
    path : pathlib.Path
        A figure file written by `reproduce_paper`.

    Returns
    -------
    int
        The figure's number.

    Raises
    ------
    ValueError
        The name does not start with "fig" and a number.

    Examples
    --------
    >>> from pathlib import Path
    >>> from workbench.apps.paper import figure_number
    >>> figure_number(Path("fig12a_speed_vs_arc_length_figure8.png"))
    12
    """
    match = re.match(r"fig(\d+)", path.name)
    if match is None:
        raise ValueError(f"{path.name} is not a figure file (fig<number>...)")
    return int(match.group(1))


def _report_figure_section(number: int, pngs: list[Path], table: pd.DataFrame, note: str | None) -> list[str]:
    from workbench.apps.report import number_text, png_figure, text_table

    caption, said = PAPER_FIGURES[number]
    rows = [{"the paper": said, "ours": note or "see the figure"}]
    for row in table.itertuples():
        if re.search(rf"\bFigure {number}[ab]?\b", row.paper):
            ours = number_text(row.ours) + ("" if pd.isna(row.ours) else f" {row.unit}")
            rows.append({"the paper": f"{row.quantity}: {row.paper}", "ours": ours})
    parts = [
        f"<h2 id='fig{number}'>Figure {number}</h2>",
        f"<p><i>The paper's caption:</i> {html.escape(caption)}</p>",
        text_table(pd.DataFrame(rows)),
    ]
    return parts + [png_figure(path.read_bytes(), path.name) for path in pngs]


def write_paper_report(path: Path, result: PaperResult) -> Path:
    """report.html: the table, what was skipped, then each figure written (embedded) under the paper's caption with
    what the paper says of it beside our numbers.

    Parameters
    ----------
    path : pathlib.Path
        The HTML file to write (replaced if it exists).
    result : PaperResult
        What `reproduce_paper` wrote: its figure files are embedded.

    Returns
    -------
    pathlib.Path
        The file written.
    """
    from workbench.apps.report import html_page, text_table

    by_figure: dict[int, list[Path]] = {}
    for file in result.files:
        if file.suffix == ".png":
            by_figure.setdefault(figure_number(file), []).append(file)
    body = [
        "<h2>Our numbers beside the paper's</h2>",
        "<p>The values the paper's text reports (section 6), ours on the open truck model (paper_vs_ours.csv).</p>",
        text_table(result.table),
        *(f"<p class='warning'>Skipped: {html.escape(reason)}.</p>" for reason in result.skipped),
        "<p>" + " · ".join(f"<a href='#fig{n}'>Figure {n}</a>" for n in sorted(by_figure)) + "</p>",
    ]
    for number in sorted(by_figure):
        body += _report_figure_section(number, by_figure[number], result.table, result.notes.get(number))
    intro = (
        "The figures of Shaju, Southward & Ahmadian (2024), sections 3-6, regenerated on the open models: the "
        f"clothoid controller on the loaded tractor-semitrailer at {SPEED_KMH:g} km/h as in the paper."
    )
    path.write_text(html_page("The paper's figures, regenerated", body, intro), encoding="utf-8")
    return path


def reproduce_paper(
    out_dir: str | Path, options: ScenarioOptions | None = None, progress: bool | None = None
) -> PaperResult:
    """Write every figure to out_dir, the comparison table as paper_vs_ours.csv and report.html (every figure with
    the paper's caption, what it says and our numbers); return what was written. progress: a line on stderr counting
    the steps (None: when stderr is a terminal, as the CLI shows it).

    Parameters
    ----------
    out_dir : str or pathlib.Path
        The folder to write to (made if missing).
    options : ScenarioOptions or None
        Options of the scenarios, e.g. the Zandvoort track file (None: the defaults; Zandvoort where the track is
        found).
    progress : bool or None
        Show the steps' progress on stderr (None: when stderr is a terminal).

    Returns
    -------
    PaperResult
        The files written (report.html last), our numbers beside the paper's, and what was skipped and why.

    Raises
    ------
    WorkbenchInputError
        A track file given that cannot be used.

    Examples
    --------
    >>> from workbench.apps.paper import reproduce_paper
    >>> result = reproduce_paper("runs/paper")  # doctest: +SKIP
    >>> result.table, result.skipped  # doctest: +SKIP
    """
    out = Path(out_dir)
    options = options or ScenarioOptions()
    show = sys.stderr.isatty() if progress is None else progress
    skipped = []
    scenarios = ["figure8", "dlc"]
    why_not = zandvoort_skip_reason(options)
    if why_not is None:
        scenarios.append("zandvoort")
    else:
        skipped.append(why_not)
    out.mkdir(parents=True, exist_ok=True)
    steps: list[tuple[str, Callable[[], StepOutput]]] = [
        ("Figures 4b-5b: lookahead", lambda: _lookahead_figures(out)),
        ("Figure 6: rollover limits", lambda: _rollover_figure(out)),
        ("Figure 7: payload and speed", lambda: _fig7(out)),
        ("Figures 8-10: lag and lead filter", lambda: _lag_figures(out)),
    ]
    files: list[Path] = []
    notes: dict[int, str] = {}
    runs: dict[str, SimulationResult] = {}
    total = len(steps) + len(scenarios) + 1  # and the last: Figures 11-16, the table and report.html
    with tqdm(total=total, unit="step", desc="paper", leave=False, disable=not show) as bar:
        for label, step in steps:
            bar.set_postfix_str(label)
            written, said = step()
            files += written
            notes |= said
            bar.update()
        for name in scenarios:
            bar.set_postfix_str(f"{name} run")
            runs[name] = _tracking(name, options, show)
            bar.update()
        bar.set_postfix_str("Figures 11-16 and report.html")
        for number, scenario, draw, suffix in TRACKING_FIGURES:
            if scenario in runs:
                files.append(_save(draw(runs[scenario], None), out / f"fig{number}{suffix}_{scenario}.png"))
        notes |= _tracking_notes(runs)
        table = _table(runs)
        table_path = out / "paper_vs_ours.csv"
        table.to_csv(table_path, index=False)
        files.append(table_path)
        result = PaperResult(files, table, skipped, notes)
        result.files.append(write_paper_report(out / "report.html", result))
        bar.update()
    return result


def zandvoort_skip_reason(options: ScenarioOptions) -> str | None:
    """Why Figures 15-16 and the Zandvoort row cannot be given, or None when they can: the paper's verdict on
    Zandvoort is given for the TUMFTM Zandvoort file only (`scenarios.is_zandvoort_file`), never for another file
    given or found in its place, which is named instead. A track file given must be usable: a broken one is refused
    (WorkbenchInputError) before any work.

    Parameters
    ----------
    options : ScenarioOptions
        The scenarios' options, with the track file given (or None to look for it).

    Returns
    -------
    str or None
        Why the Zandvoort figures are skipped, or None when the TUMFTM track is there.

    Raises
    ------
    WorkbenchInputError
        A track file given that cannot be read as a track.
    """
    if not _track_given(options):
        return (
            "Figures 15-16 and the Zandvoort row: no track file (give --track or $WORKBENCH_ZANDVOORT_CSV, or put "
            "Zandvoort_track.csv in ./tracks or ../shared/tracks)"
        )
    track = zandvoort_track_file(options.track_file)
    make_scenario("zandvoort", options)
    if is_zandvoort_file(track):
        return None
    return (
        f"Figures 15-16 and the Zandvoort row: the track file {track} is not the TUMFTM Zandvoort track (its "
        f"SHA-256 differs), and the paper's Zandvoort results are compared on that track only; `workbench run "
        f"{track}` runs the controller on this one"
    )


def _track_given(options: ScenarioOptions) -> bool:
    """Whether there is a Zandvoort track file: given (`--track` or $WORKBENCH_ZANDVOORT_CSV; then it must be
    usable, checked by the caller) or found where `scenarios.zandvoort_track_file` looks."""
    if options.track_file is not None or os.environ.get(ZANDVOORT_ENV):
        return True
    try:
        zandvoort_track_file(None)
    except WorkbenchInputError:
        return False
    return True


__all__ = [
    "PAPER_FIGURES",
    "PAPER_REPORTS",
    "PaperResult",
    "figure_number",
    "reproduce_paper",
    "speed_at_largest_curvature_rate_mps",
    "write_paper_report",
    "zandvoort_skip_reason",
]
