"""Plots of one run (trajectory over the reference with cones, CTE vs distance, steering vs time, speed), and of
several runs on shared axes (the paper's Figures 17 and 18: `trajectories`, `cte_comparison`, `speed_comparison`,
`steering_comparison`).

matplotlib is imported where a figure is drawn, not with this module (issue 17): `result.py` and the CLI's
startup need none of it; figures written to files are bare Figures (`file_axes`), without pyplot. A plotted run is
anything with a `SimulationResult`'s fields (`PlottedRun`, its path and scenario read through `PlottedPath` and
`PlottedCourse`), so this module does not import the result that draws itself with it; `RunDrawing` is such a run in
plain arrays, for a process that only draws (`plot_worker.py`)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Protocol

import numpy as np

if TYPE_CHECKING:
    from matplotlib.axes import Axes


class PlottedPath(Protocol):
    """What a plot reads of a path (a `ReferencePath` is one): its samples and its track's edges."""

    x_m: np.ndarray
    y_m: np.ndarray

    def track_edges(self) -> tuple[tuple[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]] | None: ...


class PlottedCourse(Protocol):
    """What a plot reads of a scenario (a `Scenario` is one): its name, description and cones."""

    name: str
    description: str
    cones_xy: np.ndarray | None


class PlottedRun(Protocol):
    """What a plot reads of a run (a `SimulationResult` is one): its trace, the path and scenario it ran on, and
    which controller and vehicle ran it."""

    trace: dict[str, np.ndarray]
    path: PlottedPath
    scenario: PlottedCourse
    controller: str
    vehicle: str


@dataclass(frozen=True)
class PathOutline:
    """A path as the plots draw it: its samples and its track's edges (None: no widths)."""

    x_m: np.ndarray
    y_m: np.ndarray
    edges: tuple[tuple[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]] | None

    def track_edges(self) -> tuple[tuple[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]] | None:
        return self.edges


@dataclass(frozen=True)
class CourseLabel:
    """A scenario as the plots draw it: name, description and cones ((n, 2) m, or None)."""

    name: str
    description: str
    cones_xy: np.ndarray | None


#: The trace signals the run plots read (those a run has: the trailer's only with a trailer).
RUN_PLOT_SIGNALS = (
    "t_s", "x_m", "y_m", "trailer_x_m", "trailer_y_m", "progress_m", "cte_m", "steer_wheel_cmd_rad",
    "steer_wheel_rad", "speed_ref_mps", "speed_mps",
)  # fmt: skip


@dataclass(frozen=True)
class RunDrawing:
    """What the run plots read of a run, in arrays and strings: a `PlottedRun` that unpickles with numpy alone, so a
    process that only draws (`plot_worker.py`) needs none of the run's own classes and their imports."""

    trace: dict[str, np.ndarray]
    path: PathOutline
    scenario: CourseLabel
    controller: str
    vehicle: str

    @classmethod
    def of(cls, run: PlottedRun) -> RunDrawing:
        trace = {name: run.trace[name] for name in RUN_PLOT_SIGNALS if name in run.trace}
        path, course = run.path, run.scenario
        return cls(
            trace,
            PathOutline(path.x_m, path.y_m, path.track_edges()),
            CourseLabel(course.name, course.description, course.cones_xy),
            run.controller,
            run.vehicle,
        )


#: Size of a plot's figure (inches), on screen and in files.
FIGURE_SIZE_IN = (8.0, 4.5)


def _axes(ax: Axes | None) -> Axes:
    """ax, or the axes of a new pyplot figure (shown inline in a notebook)."""
    if ax is None:
        import matplotlib.pyplot as plt

        _, ax = plt.subplots(figsize=FIGURE_SIZE_IN, layout="constrained")
    return ax


def file_axes() -> Axes:
    """The axes of a new figure to be written to a file: a bare `matplotlib.figure.Figure`, not pyplot's (no
    figure manager or GUI backend loaded, nothing to close: matplotlib's way for figures a program saves)."""
    from matplotlib.figure import Figure

    return Figure(figsize=FIGURE_SIZE_IN, layout="constrained").add_subplot()


def _label(result: PlottedRun) -> str:
    return f"{result.controller} on {result.vehicle}"


def _distance(result: PlottedRun) -> np.ndarray:
    return result.trace["progress_m"]


def trajectory(result: PlottedRun, ax: Axes | None = None) -> Axes:
    ax = _axes(ax)
    _draw_reference(result, ax)
    ax.plot(result.trace["x_m"], result.trace["y_m"], lw=1.5, label=f"{_label(result)} (rear axle)")
    if "trailer_x_m" in result.trace:
        ax.plot(
            result.trace["trailer_x_m"],
            result.trace["trailer_y_m"],
            lw=1.0,
            color="tab:green",
            label="trailer rear axle",
        )
    ax.set(xlabel="x (m)", ylabel="y (m)", title=f"{result.scenario.name}: tracked trajectory")
    ax.legend(loc="best", fontsize="small")
    return ax


def cte_vs_distance(result: PlottedRun, ax: Axes | None = None) -> Axes:
    ax = _axes(ax)
    ax.plot(_distance(result), result.trace["cte_m"], label=_label(result))
    ax.axhline(0.0, color="k", lw=0.5)
    ax.set(xlabel="distance along path (m)", ylabel="cross-track error (m)", title="CTE at the rear-axle centre")
    ax.legend(loc="best", fontsize="small")
    return ax


def steering_vs_time(result: PlottedRun, ax: Axes | None = None) -> Axes:
    ax = _axes(ax)
    t = result.trace["t_s"]
    ax.plot(t, np.degrees(result.trace["steer_wheel_cmd_rad"]), lw=1.0, label="command")
    ax.plot(t, np.degrees(result.trace["steer_wheel_rad"]), lw=1.5, label="measured")
    ax.set(xlabel="time (s)", ylabel="steering-wheel angle (deg)", title=f"Steering: {_label(result)}")
    ax.legend(loc="best", fontsize="small")
    return ax


#: A speed axis spans at least twice the larger of these about its curves' middle (km/h, and a fraction of the mean
#: speed): at a constant 30 km/h the speed controller's few m/h would otherwise fill the plot like real swings.
SPEED_AXIS_MIN_HALF_SPAN_KMH = 1.0
SPEED_AXIS_MIN_HALF_SPAN_FRACTION = 0.05


def _at_least_speed_span(ax: Axes) -> None:
    """Widen the speed axis to its minimum span (centred on the curves' range) when the curves span less."""
    speeds = np.concatenate([np.asarray(line.get_ydata(), dtype=float) for line in ax.get_lines()])
    speeds = speeds[np.isfinite(speeds)]
    if speeds.size == 0:
        return
    low, high = float(speeds.min()), float(speeds.max())
    half = max(SPEED_AXIS_MIN_HALF_SPAN_KMH, SPEED_AXIS_MIN_HALF_SPAN_FRACTION * abs(float(speeds.mean())))
    if high - low < 2.0 * half:
        middle = 0.5 * (low + high)
        ax.set_ylim(middle - half, middle + half)


def speed_vs_distance(result: PlottedRun, ax: Axes | None = None) -> Axes:
    ax = _axes(ax)
    d = _distance(result)
    ax.plot(d, result.trace["speed_ref_mps"] * 3.6, "k--", lw=1.0, label="planned")
    ax.plot(d, result.trace["speed_mps"] * 3.6, lw=1.5, label="actual")
    _at_least_speed_span(ax)
    ax.set(xlabel="distance along path (m)", ylabel="speed (km/h)", title="Speed")
    ax.legend(loc="best", fontsize="small")
    return ax


RUN_PLOTS = {
    "trajectory.png": trajectory,
    "cte_vs_distance.png": cte_vs_distance,
    "steering_vs_time.png": steering_vs_time,
    "speed_vs_distance.png": speed_vs_distance,
}


def save_run_plots(result: PlottedRun, out_dir: Path) -> list[Path]:
    """Write the four standard plots of a run as PNG files in out_dir."""
    written = []
    for filename, draw in RUN_PLOTS.items():
        path = out_dir / filename
        draw(result, file_axes()).figure.savefig(path, dpi=120)
        written.append(path)
    return written


# ---------------------------------------------------------------------------------------------- several runs
#: How each course of a comparison is drawn, in turn: the reference's colour and line style, the cones' colour.
COURSE_STYLES: tuple[tuple[str, str, str], ...] = (
    ("k", "--", "tab:red"),
    ("tab:gray", "-.", "tab:gray"),
    ("tab:brown", ":", "tab:brown"),
)


def _draw_reference(
    result: PlottedRun, ax: Axes, whose: str = "", style: tuple[str, str, str] = COURSE_STYLES[0]
) -> None:
    """The path, the track's edges (when the path has widths) and the cones of the run's scenario; whose: the
    vehicles that ran it, named in the legend when a plot shows several courses."""
    path = result.path
    suffix = f" ({whose})" if whose else ""
    colour, line, cone_colour = style
    edges = path.track_edges()
    if edges is not None:
        for k, (x, y) in enumerate(edges):
            ax.plot(x, y, color=colour, lw=0.8, alpha=0.45, label=f"track edges{suffix}" if k == 0 else None)
    ax.plot(path.x_m, path.y_m, color=colour, ls=line, lw=1.0, label=f"reference{suffix}")
    cones = result.scenario.cones_xy
    if cones is not None:
        ax.plot(cones[:, 0], cones[:, 1], "^", color=cone_colour, ms=5, label=f"cones{suffix}")
    width, height = np.ptp(path.x_m), np.ptp(path.y_m)
    if min(width, height) > 0.25 * max(width, height):  # true shape unless the path is long and thin (a DLC)
        ax.set_aspect("equal", adjustable="datalim")


def trajectories(results: Sequence[PlottedRun], labels: Sequence[str], ax: Axes | None = None) -> Axes:
    """Figure 17a: each run's rear-axle path over the reference and cones of the course it ran: one course when
    every run ran the same, else each (a dlc is sized for its vehicle's width), named by the vehicles that ran it."""
    ax = _axes(ax)
    courses: dict[str, tuple[PlottedRun, list[str]]] = {}
    for result in results:
        _, vehicles = courses.setdefault(result.scenario.description, (result, []))
        if result.vehicle not in vehicles:
            vehicles.append(result.vehicle)
    for k, (first, vehicles) in enumerate(courses.values()):
        whose = ", ".join(vehicles) if len(courses) > 1 else ""
        _draw_reference(first, ax, whose, COURSE_STYLES[k % len(COURSE_STYLES)])
    for result, label in zip(results, labels, strict=True):
        ax.plot(result.trace["x_m"], result.trace["y_m"], lw=1.3, label=label)
    ax.set(xlabel="x (m)", ylabel="y (m)", title=f"{results[0].scenario.name}: tracked trajectories (rear axle)")
    ax.legend(loc="best", fontsize="small")
    return ax


def cte_comparison(results: Sequence[PlottedRun], labels: Sequence[str], ax: Axes | None = None) -> Axes:
    """Figure 17b: CTE against distance along the path, every run on one axis."""
    ax = _axes(ax)
    for result, label in zip(results, labels, strict=True):
        ax.plot(_distance(result), result.trace["cte_m"], lw=1.3, label=label)
    ax.axhline(0.0, color="k", lw=0.5)
    ax.set(xlabel="distance along path (m)", ylabel="cross-track error (m)", title="CTE at the rear-axle centre")
    ax.legend(loc="best", fontsize="small")
    return ax


def speed_comparison(results: Sequence[PlottedRun], labels: Sequence[str], ax: Axes | None = None) -> Axes:
    """Figure 18a: speed against distance along the path (and the planned profile of the first run)."""
    ax = _axes(ax)
    ax.plot(_distance(results[0]), results[0].trace["speed_ref_mps"] * 3.6, "k--", lw=1.0, label="planned")
    for result, label in zip(results, labels, strict=True):
        ax.plot(_distance(result), result.trace["speed_mps"] * 3.6, lw=1.3, label=label)
    _at_least_speed_span(ax)
    ax.set(xlabel="distance along path (m)", ylabel="speed (km/h)", title="Speed")
    ax.legend(loc="best", fontsize="small")
    return ax


def steering_comparison(results: Sequence[PlottedRun], labels: Sequence[str], ax: Axes | None = None) -> Axes:
    """Figure 18b: measured steering-wheel angle against time."""
    ax = _axes(ax)
    for result, label in zip(results, labels, strict=True):
        ax.plot(result.trace["t_s"], np.degrees(result.trace["steer_wheel_rad"]), lw=1.3, label=label)
    ax.set(xlabel="time (s)", ylabel="steering-wheel angle (deg)", title="Steering-wheel angle")
    ax.legend(loc="best", fontsize="small")
    return ax
