"""Plots of one run (trajectory over the reference with cones, CTE vs distance, steering vs time, speed), and of
several runs on shared axes (the paper's Figures 17 and 18: `trajectories`, `cte_comparison`, `speed_comparison`,
`steering_comparison`).

Several runs are told apart alike on every figure (`RunStyle`, `run_styles`): one colour per controller and one line
style per vehicle, so that three controllers on two vehicles are six lines of three colours in two styles. Their
tracked trajectories overlap at the scale of the course, so `trajectories` can zoom an inset on a stretch of it
(`Stretch`: the hardest, chosen by the caller).

matplotlib is imported where a figure is drawn, not with this module, for a fast start-up: `result.py` and the CLI's
startup need none of it; figures written to files are bare Figures (`file_figure`), without pyplot. A plotted run is
anything with a `SimulationResult`'s fields (`PlottedRun`, its path and scenario read through `PlottedPath` and
`PlottedCourse`), so this module does not import the result that draws itself with it; `RunDrawing` is such a run in
plain arrays, for a process that only draws (`plot_worker.py`)."""

from __future__ import annotations

from collections.abc import Hashable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Protocol

import numpy as np

from workbench.base.errors import WorkbenchInputError, require_finite

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure
    from matplotlib.lines import Line2D


class PlottedPath(Protocol):
    """What a plot reads of a path (a `ReferencePath` is one): its samples and its track's edges."""

    @property
    def x_m(self) -> np.ndarray: ...
    @property
    def y_m(self) -> np.ndarray: ...

    def track_edges(self) -> tuple[tuple[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]] | None: ...


class PlottedCourse(Protocol):
    """What a plot reads of a scenario (a `Scenario` is one): its name, description and cones."""

    @property
    def name(self) -> str: ...
    @property
    def description(self) -> str: ...
    @property
    def cones_xy(self) -> np.ndarray | None: ...


class PlottedRun(Protocol):
    """What a plot reads of a run (a `SimulationResult` is one): its trace, the path and scenario it ran on, and
    which controller and vehicle ran it."""

    @property
    def trace(self) -> dict[str, np.ndarray]: ...
    @property
    def path(self) -> PlottedPath: ...
    @property
    def scenario(self) -> PlottedCourse: ...
    @property
    def controller(self) -> str: ...
    @property
    def vehicle(self) -> str: ...


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


def file_figure() -> Figure:
    """A new figure to be written to a file: a bare `matplotlib.figure.Figure`, not pyplot's (no figure manager or
    GUI backend loaded, nothing to close: matplotlib's way for figures a program saves)."""
    from matplotlib.figure import Figure

    return Figure(figsize=FIGURE_SIZE_IN, layout="constrained")


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
        figure = file_figure()
        draw(result, figure.add_subplot())
        figure.savefig(path, dpi=120)
        written.append(path)
    return written


# ---------------------------------------------------------------------------------------------- several runs
#: A comparison's controllers' colours, in the order the controllers first appear (matplotlib's tab10, the red and
#: grey the courses' cones and second reference use last); more controllers than colours reuse them.
CONTROLLER_COLOURS: tuple[str, ...] = (
    "tab:blue", "tab:orange", "tab:green", "tab:purple", "tab:brown", "tab:pink", "tab:olive", "tab:cyan", "tab:red",
    "tab:gray",
)  # fmt: skip
#: A comparison's vehicles' line styles (matplotlib's), in the order the vehicles first appear; more vehicles than
#: styles reuse them.
VEHICLE_LINE_STYLES: tuple[str | tuple[float, tuple[float, ...]], ...] = (
    "-", "--", ":", "-.", (0.0, (6.0, 1.5, 1.0, 1.5, 1.0, 1.5)), (0.0, (1.0, 3.0)),
)  # fmt: skip


@dataclass(frozen=True)
class RunStyle:
    """How one run of several is drawn: its colour (its controller's) and line style (its vehicle's)."""

    colour: str
    line_style: str | tuple[float, tuple[float, ...]]


def run_styles(controllers: Sequence[Hashable], vehicles: Sequence[Hashable]) -> list[RunStyle]:
    """Each run's style: a colour per distinct controller and a line style per distinct vehicle, each in the order
    they first appear (a controller with other options is another controller here, when its key says so)."""
    colour = {key: k for k, key in enumerate(dict.fromkeys(controllers))}
    style = {key: k for k, key in enumerate(dict.fromkeys(vehicles))}
    return [
        RunStyle(
            CONTROLLER_COLOURS[colour[c] % len(CONTROLLER_COLOURS)],
            VEHICLE_LINE_STYLES[style[v] % len(VEHICLE_LINE_STYLES)],
        )
        for c, v in zip(controllers, vehicles, strict=True)
    ]


def _styles(labels: Sequence[str], styles: Sequence[RunStyle] | None) -> Sequence[RunStyle]:
    """The styles given, or one colour per run, all solid (runs not known by controller and vehicle)."""
    return run_styles(labels, [""] * len(labels)) if styles is None else styles


@dataclass(frozen=True)
class Stretch:
    """A stretch of the course, by distance along the path (m, as the traces' progress_m counts it), and why it was
    chosen (for the inset's title)."""

    from_m: float
    to_m: float
    reason: str = ""

    def __post_init__(self) -> None:
        require_finite("from_m", self.from_m)
        require_finite("to_m", self.to_m)
        if not self.from_m < self.to_m:
            raise WorkbenchInputError(
                f"a stretch runs forward: from_m must be below to_m; got from_m = {self.from_m:g}, to_m = {self.to_m:g}"
            )

    def bounds(self, results: Sequence[PlottedRun]) -> tuple[float, float, float, float]:
        """(x_min, x_max, y_min, y_max) of every run's rear axle over the stretch, with a margin of a tenth of the
        larger side each way; NaN when no run was there."""
        x = np.concatenate([r.trace["x_m"][self._within(r)] for r in results])
        y = np.concatenate([r.trace["y_m"][self._within(r)] for r in results])
        if x.size == 0:
            return (np.nan, np.nan, np.nan, np.nan)
        margin = max(INSET_MIN_MARGIN_M, 0.1 * max(np.ptp(x), np.ptp(y)))
        return (x.min() - margin, x.max() + margin, y.min() - margin, y.max() + margin)

    def _within(self, result: PlottedRun) -> np.ndarray:
        progress = result.trace["progress_m"]
        return (progress >= self.from_m) & (progress <= self.to_m)


#: The inset's size (fraction of the axes' width and height), its distance from the axes' edges (fraction), and the
#: least margin (m) round the stretch it shows.
INSET_SIZE = 0.36
INSET_EDGE = 0.02
INSET_MIN_MARGIN_M = 0.05


def _inset_place(ax: Axes) -> tuple[float, float, float, float]:
    """(x0, y0, width, height) (axes fraction) of the place for the inset: of the corners, the edges' middles and the
    centre, the first (from the top right) that covers no point drawn (trajectories, references, cones); when each
    covers some, the top right, with the axes' data limits raised so that everything drawn lies below it."""
    points = np.concatenate([np.asarray(line.get_xydata(), dtype=float) for line in ax.get_lines()])
    points = points[np.all(np.isfinite(points), axis=1)]
    ax.autoscale_view()
    ax.apply_aspect()  # the limits the figure will show
    axes_xy = ax.transAxes.inverted().transform(ax.transData.transform(points))
    steps = (1.0 - INSET_SIZE - INSET_EDGE, 0.5 * (1.0 - INSET_SIZE), INSET_EDGE)
    places = [(x0, y0) for y0 in steps for x0 in reversed(steps)]  # top right first, bottom left last
    for x0, y0 in places:
        if not np.any(np.all((axes_xy >= (x0, y0)) & (axes_xy <= (x0 + INSET_SIZE, y0 + INSET_SIZE)), axis=1)):
            return (x0, y0, INSET_SIZE, INSET_SIZE)
    # Room above: the data limits reach up so far that what the axes show fills at most `below` of the height (the
    # limits stay automatic, so that an equal aspect widens them about their middle, which keeps it so).
    low, top = float(ax.dataLim.y0), float(ax.dataLim.y1)
    below = 1.0 - INSET_SIZE - 2.0 * INSET_EDGE
    ax.update_datalim([(float(ax.dataLim.x0), low + (top - low) / below)])
    ax.autoscale_view()
    return (steps[0], steps[0], INSET_SIZE, INSET_SIZE)


def _zoom_inset(
    ax: Axes, results: Sequence[PlottedRun], styles: Sequence[RunStyle], stretch: Stretch, references: Sequence[Line2D]
) -> Axes | None:
    """An inset of the axes showing every run and the references (as drawn on the axes) over the stretch, its frame
    marked on the axes; its ticks and caption face the axes' middle, clear of the axes' own labels and title."""
    x0, x1, y0, y1 = stretch.bounds(results)
    if not np.isfinite(x0):
        return None
    place = _inset_place(ax)
    inset = ax.inset_axes(place)
    for line in references:
        inset.plot(line.get_xdata(), line.get_ydata(), color=line.get_color(), ls=line.get_linestyle(), lw=0.8)
    for result, style in zip(results, styles, strict=True):
        inset.plot(result.trace["x_m"], result.trace["y_m"], color=style.colour, ls=style.line_style, lw=1.3)
    inset.set_xlim(x0, x1)
    inset.set_ylim(y0, y1)
    if ax.get_aspect() == 1.0:  # true shape as the axes (the box shrinks to the stretch's shape, the limits stay)
        inset.set_aspect("equal", adjustable="box")
    inset.tick_params(labelsize="x-small")
    if place[0] < 0.5 * (1.0 - INSET_SIZE):  # on the left: its y ticks on its right
        inset.yaxis.tick_right()
    caption = f"{stretch.from_m:.0f}-{stretch.to_m:.0f} m" + (f": {stretch.reason}" if stretch.reason else "")
    if place[1] < 0.5 * (1.0 - INSET_SIZE):  # at the bottom: x ticks and caption above it
        inset.xaxis.tick_top()
        inset.set_title(caption, fontsize="x-small")
    else:
        inset.set_xlabel(caption, fontsize="x-small")
    ax.indicate_inset_zoom(inset, edgecolor="0.3")
    return inset


#: How each course of a comparison is drawn, in turn: the reference's colour and line style, the cones' colour.
COURSE_STYLES: tuple[tuple[str, str, str], ...] = (
    ("k", "--", "tab:red"),
    ("tab:gray", "-.", "tab:gray"),
    ("tab:brown", ":", "tab:brown"),
)


def _draw_reference(
    result: PlottedRun, ax: Axes, whose: str = "", style: tuple[str, str, str] = COURSE_STYLES[0]
) -> Line2D:
    """The path, the track's edges (when the path has widths) and the cones of the run's scenario; whose: the
    vehicles that ran it, named in the legend when a plot shows several courses. Returns the path's line."""
    path = result.path
    suffix = f" ({whose})" if whose else ""
    colour, line, cone_colour = style
    edges = path.track_edges()
    if edges is not None:
        for k, (x, y) in enumerate(edges):
            ax.plot(x, y, color=colour, lw=0.8, alpha=0.45, label=f"track edges{suffix}" if k == 0 else None)
    (reference,) = ax.plot(path.x_m, path.y_m, color=colour, ls=line, lw=1.0, label=f"reference{suffix}")
    cones = result.scenario.cones_xy
    if cones is not None:
        ax.plot(cones[:, 0], cones[:, 1], "^", color=cone_colour, ms=5, label=f"cones{suffix}")
    width, height = np.ptp(path.x_m), np.ptp(path.y_m)
    if min(width, height) > 0.25 * max(width, height):  # true shape unless the path is long and thin (a DLC)
        ax.set_aspect("equal", adjustable="datalim")
    return reference


def trajectories(
    results: Sequence[PlottedRun],
    labels: Sequence[str],
    ax: Axes | None = None,
    styles: Sequence[RunStyle] | None = None,
    zoom: Stretch | None = None,
) -> Axes:
    """Figure 17a: each run's rear-axle path over the reference and cones of the course it ran: one course when
    every run ran the same, else each (a dlc is sized for its vehicle's width), named by the vehicles that ran it.
    styles: each run's (`run_styles`; None: a colour per run); zoom: a stretch shown magnified in an inset (the
    axes' only child axes), the legend then beside the axes."""
    ax = _axes(ax)
    styles = _styles(labels, styles)
    courses: dict[str, tuple[PlottedRun, list[str]]] = {}
    for result in results:
        _, vehicles = courses.setdefault(result.scenario.description, (result, []))
        if result.vehicle not in vehicles:
            vehicles.append(result.vehicle)
    references = []
    for k, (first, vehicles) in enumerate(courses.values()):
        whose = ", ".join(vehicles) if len(courses) > 1 else ""
        references.append(_draw_reference(first, ax, whose, COURSE_STYLES[k % len(COURSE_STYLES)]))
    for result, label, style in zip(results, labels, styles, strict=True):
        ax.plot(result.trace["x_m"], result.trace["y_m"], color=style.colour, ls=style.line_style, lw=1.3, label=label)
    ax.set(xlabel="x (m)", ylabel="y (m)", title=f"{results[0].scenario.name}: tracked trajectories (rear axle)")
    if zoom is not None and _zoom_inset(ax, results, styles, zoom, references) is not None:
        ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize="small")
    else:
        ax.legend(loc="best", fontsize="small")
    return ax


def cte_comparison(
    results: Sequence[PlottedRun],
    labels: Sequence[str],
    ax: Axes | None = None,
    styles: Sequence[RunStyle] | None = None,
    zoom: Stretch | None = None,
) -> Axes:
    """Figure 17b: CTE against distance along the path, every run on one axis (styles: as `trajectories`); zoom:
    the stretch the trajectories' inset shows, shaded."""
    ax = _axes(ax)
    for result, label, style in zip(results, labels, _styles(labels, styles), strict=True):
        ax.plot(_distance(result), result.trace["cte_m"], color=style.colour, ls=style.line_style, lw=1.3, label=label)
    ax.axhline(0.0, color="k", lw=0.5)
    if zoom is not None:
        ax.axvspan(zoom.from_m, zoom.to_m, color="0.5", alpha=0.15, lw=0, label="the trajectories' inset")
    ax.set(xlabel="distance along path (m)", ylabel="cross-track error (m)", title="CTE at the rear-axle centre")
    ax.legend(loc="best", fontsize="small")
    return ax


def speed_comparison(
    results: Sequence[PlottedRun],
    labels: Sequence[str],
    ax: Axes | None = None,
    styles: Sequence[RunStyle] | None = None,
) -> Axes:
    """Figure 18a: speed against distance along the path (and the planned profile of the first run; styles: as
    `trajectories`)."""
    ax = _axes(ax)
    ax.plot(_distance(results[0]), results[0].trace["speed_ref_mps"] * 3.6, color="k", ls="--", lw=0.8, label="planned")
    for result, label, style in zip(results, labels, _styles(labels, styles), strict=True):
        speed_kmh = result.trace["speed_mps"] * 3.6
        ax.plot(_distance(result), speed_kmh, color=style.colour, ls=style.line_style, lw=1.3, label=label)
    _at_least_speed_span(ax)
    ax.set(xlabel="distance along path (m)", ylabel="speed (km/h)", title="Speed")
    ax.legend(loc="best", fontsize="small")
    return ax


def steering_comparison(
    results: Sequence[PlottedRun],
    labels: Sequence[str],
    ax: Axes | None = None,
    styles: Sequence[RunStyle] | None = None,
) -> Axes:
    """Figure 18b: measured steering-wheel angle against time (styles: as `trajectories`)."""
    ax = _axes(ax)
    for result, label, style in zip(results, labels, _styles(labels, styles), strict=True):
        steer_deg = np.degrees(result.trace["steer_wheel_rad"])
        ax.plot(result.trace["t_s"], steer_deg, color=style.colour, ls=style.line_style, lw=1.3, label=label)
    ax.set(xlabel="time (s)", ylabel="steering-wheel angle (deg)", title="Steering-wheel angle")
    ax.legend(loc="best", fontsize="small")
    return ax
