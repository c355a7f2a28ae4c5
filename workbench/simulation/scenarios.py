"""Named test scenarios: a reference path, where the vehicle starts, and what to draw around it.

`make_scenario(name)` builds one by name (`figure8`, `dlc`, `fig17`, `zandvoort`, or `circuit:SEED`, a closed
circuit drawn from a seed, `workbench.simulation.circuits`) or from a waypoint file path (CSV with x,y[,v] columns,
a TUMFTM racetrack-database CSV with its track widths, or a GPS CSV with lat/lon columns).
"""

from __future__ import annotations

import dataclasses
import math
import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from workbench.base.errors import WorkbenchInputError
from workbench.simulation.scenario import Scenario, ScenarioOptions

#: Environment variable naming the TUMFTM Zandvoort centre-line CSV when --track is not given.
ZANDVOORT_ENV = "WORKBENCH_ZANDVOORT_CSV"
#: The names the Zandvoort file is looked for under when neither --track nor the environment variable gives it:
#: the shared copy's and the database's own (tracks/Zandvoort.csv).
ZANDVOORT_FILE_NAMES = ("Zandvoort_track.csv", "Zandvoort.csv")
#: The folder of the current directory the Zandvoort file is looked for in.
TRACKS_FOLDER = "tracks"
#: The root of the checkout this module runs from (the folder with pyproject.toml), or None for an installed
#: package: the Zandvoort file is also looked for beside it, in ../shared/tracks/.
CHECKOUT_ROOT: Path | None = (
    Path(__file__).resolve().parents[2] if (Path(__file__).resolve().parents[2] / "pyproject.toml").is_file() else None
)
ZANDVOORT_SOURCE = (
    "the TUMFTM racetrack-database file tracks/Zandvoort.csv "
    "(https://github.com/TUMFTM/racetrack-database/blob/master/tracks/Zandvoort.csv, LGPL-3.0)"
)
#: SHA-256 (hex) of the bytes of that file (the database's commit e59595d1f3573b30d1ded6a08984935b957688e0, also
#: ../shared/tracks/Zandvoort_track.csv): the one track file the `zandvoort` scenario is named after and the
#: paper's Zandvoort figures and verdict are given for. Any other file given for it is run under its own name.
ZANDVOORT_SHA256 = "f3f2a82c9f41bcee8d7161a6ad6c0b8e6d4b902dd772459918c9fe7f7451bc59"


# ---------------------------------------------------------------------------------------------- figure-8
def figure8(options: ScenarioOptions, radius_m: float = 22.0, transition_m: float = 15.0) -> Scenario:
    """Two lobes through a self-crossing at the origin, with clothoid transitions between straights and arcs.

    The crossing straights lie at +-45 degrees; each lobe turns 270 degrees (clothoid to 1/R, arc, clothoid back
    to zero). The straight's length is solved so that each lobe is symmetric about the x axis, which closes the
    loop exactly. Minimum radius `radius_m` (default 22 m).

    Parameters
    ----------
    options : ScenarioOptions
        What a scenario may depend on; this one depends on none of it (a factory of `SCENARIOS` takes it).
    radius_m : float
        Radius of each lobe's arc (m, > 0), the path's tightest.
    transition_m : float
        Length of each clothoid between a straight and an arc (m, >= 0), shorter than a lobe's 270 degrees of
        turn at `radius_m` asks (3 pi / 2 * radius_m).

    Returns
    -------
    Scenario
        The closed figure-8 path, starting at the crossing on the path.

    Raises
    ------
    WorkbenchInputError
        When `transition_m` leaves no arc at `radius_m`.
    """
    from workbench.base.clothoid_chain import ClothoidChain

    kappa = 1.0 / radius_m
    lobe_turn = 1.5 * math.pi
    arc_length = lobe_turn / kappa - transition_m  # kappa * Lc / 2 * 2 + kappa * La = lobe turn
    if arc_length <= 0:
        raise WorkbenchInputError(f"figure8: transition_m={transition_m} is too long for radius_m={radius_m}")
    start_heading = math.pi / 4
    # Half of the right lobe (clockwise) from the crossing; its y at the lobe's apex is linear in the straight.
    half = ClothoidChain(0.0, 0.0, start_heading).clothoid_to(-kappa, transition_m).arc(arc_length / 2)
    straight = -half.end_pose()[1] / math.sin(start_heading)
    chain = (
        ClothoidChain(0.0, 0.0, start_heading)
        .straight(straight)
        .clothoid_to(-kappa, transition_m)
        .arc(arc_length)
        .clothoid_to(0.0, transition_m)
        .straight(2 * straight)
        .clothoid_to(kappa, transition_m)
        .arc(arc_length)
        .clothoid_to(0.0, transition_m)
        .straight(straight)
    )
    return Scenario(
        "figure8",
        chain.to_path("figure8", closed=True, closure_tol_m=1e-6),
        _figure8_description(radius_m),
    )


def _figure8_description(radius_m: float = 22.0) -> str:
    return f"figure-8, two 270-degree lobes of radius {radius_m:g} m through a self-crossing, clothoid transitions"


# ---------------------------------------------------------------------------------------------- ISO 3888-1
@dataclass(frozen=True)
class DoubleLaneChangeLayout:
    """ISO 3888-1 double lane change for a vehicle of width b (m), as Project Chrono's `ISO3888_Helper` and
    MathWorks' `sm_car_trajectory_double_lane_change_iso3888.m` lay it out.

    Lane widths 1.1 b + 0.25, 1.2 b + 0.25 and 1.3 b + 0.25 m; sections 15, 30, 25, 25 and 15 m. The 3.5 m lateral
    offset is taken between the right-hand cone lines of sections 1 and 3 (the datum varies between sources);
    the exit lane is centred on the entry lane's centre line. The layout checks no range itself; the `dlc`
    scenario builds it from `ScenarioOptions.vehicle_width_m`, which is checked there.
    """

    vehicle_width_m: float  # overall width b of the vehicle the lanes are sized for (m), > 0 (`dlc`: 0.5 to 4)
    run_in_m: float = 40.0  # the straight before section 1 (m), >= 0
    run_out_m: float = 40.0  # the straight after section 5 (m), >= 0
    lateral_offset_m: float = 3.5  # offset between the right-hand cone lines of sections 1 and 3 (m), ISO: 3.5

    @property
    def lane_widths_m(self) -> tuple[float, float, float]:
        """Widths (m) of lanes 1, 3 and 5: 1.1 b + 0.25, 1.2 b + 0.25 and 1.3 b + 0.25 for a vehicle b m wide."""
        b = self.vehicle_width_m
        return 1.1 * b + 0.25, 1.2 * b + 0.25, 1.3 * b + 0.25

    @property
    def section_starts_m(self) -> np.ndarray:
        """x of the start of sections 1-5 and of the end of section 5."""
        return self.run_in_m + np.cumsum([0.0, 15.0, 30.0, 25.0, 25.0, 15.0])

    @property
    def offset_lane_centre_m(self) -> float:
        """y (m, left positive) of the centre of the offset lane (section 3) from the entry lane's centre line."""
        w1, w3, _ = self.lane_widths_m
        return -w1 / 2 + self.lateral_offset_m + w3 / 2

    def centre_line(self, x_m: np.ndarray) -> np.ndarray:
        """y of the smooth centre line: straight in each lane, quintic smoothsteps (curvature-continuous) between.

        Parameters
        ----------
        x_m : numpy.ndarray
            Distances along the course from the start of the run-in (m), any shape.

        Returns
        -------
        numpy.ndarray
            The centre line's lateral position y (m, left positive) at each x, of the shape of `x_m`.
        """
        _, x1, x2, x3, x4, _ = self.section_starts_m
        h = self.offset_lane_centre_m

        def smoothstep(u: np.ndarray) -> np.ndarray:
            u = np.clip(u, 0.0, 1.0)
            return u**3 * (10 - 15 * u + 6 * u**2)  # zero slope and curvature at both ends

        return h * (smoothstep((x_m - x1) / (x2 - x1)) - smoothstep((x_m - x3) / (x4 - x3)))

    def cones(self) -> np.ndarray:
        """(n, 2) cone positions: both edges of lanes 1, 3 and 5 at their start, middle and end.

        Returns
        -------
        numpy.ndarray
            Array of shape (18, 2): x and y (m) of each cone.
        """
        x0, x1, x2, x3, x4, x5 = self.section_starts_m
        w1, w3, w5 = self.lane_widths_m
        h = self.offset_lane_centre_m
        rows = []
        for start, end, centre, width in ((x0, x1, 0.0, w1), (x2, x3, h, w3), (x4, x5, 0.0, w5)):
            for x in np.linspace(start, end, 3):
                rows += [(x, centre - width / 2), (x, centre + width / 2)]
        return np.array(rows)


def double_lane_change(options: ScenarioOptions) -> Scenario:
    """ISO 3888-1 double lane change laid out for the vehicle's width, with run-in and run-out straights.

    Parameters
    ----------
    options : ScenarioOptions
        `vehicle_width_m`, the overall width (m) of the vehicle to be driven, sizes the lanes; required.

    Returns
    -------
    Scenario
        The open centre-line path (sampled every 0.5 m) and the cones to draw.

    Raises
    ------
    WorkbenchInputError
        When `options.vehicle_width_m` is None (the message says how to give it).
    """
    from workbench.base.path import ReferencePath
    from workbench.base.waypoints import Waypoints

    layout = DoubleLaneChangeLayout(options.required_width_m("dlc"))
    x = np.arange(0.0, layout.section_starts_m[-1] + layout.run_out_m + 1e-9, 0.5)
    path = ReferencePath.from_waypoints(Waypoints(x, layout.centre_line(x), source="dlc"), name="dlc")
    return Scenario("dlc", path, _dlc_description(options), cones_xy=layout.cones())


def _dlc_description(options: ScenarioOptions) -> str:
    if options.vehicle_width_m is None:
        return (
            "ISO 3888-1 double lane change, lanes sized for the vehicle driven on it (1.1 b + 0.25, 1.2 b + 0.25 "
            "and 1.3 b + 0.25 m for a vehicle b m wide)"
        )
    layout = DoubleLaneChangeLayout(options.vehicle_width_m)
    w1, w3, w5 = layout.lane_widths_m
    return (
        f"ISO 3888-1 double lane change for a {options.vehicle_width_m:g} m wide vehicle "
        f"(lanes {w1:.2f}/{w3:.2f}/{w5:.2f} m, centre-line offset {layout.offset_lane_centre_m:.2f} m)"
    )


# ---------------------------------------------------------------------------------------------- Figure 17
FIG17_DESCRIPTION = "Figure 17 comparison path: S-bend of radius 30 m between straights, start 1.0 m left of the path"


def fig17(options: ScenarioOptions) -> Scenario:
    """The controller-comparison path of the paper's Figure 17, built from clothoids (curvature-continuous).

    40 m straight; 20 m clothoid to 1/30 1/m (left); 30 m arc; 40 m clothoid to -1/30 1/m; 30 m arc; 20 m clothoid
    to 0; 60 m straight. The vehicle starts 1.0 m left of the path, heading along it.

    Parameters
    ----------
    options : ScenarioOptions
        What a scenario may depend on; this one depends on none of it (a factory of `SCENARIOS` takes it).

    Returns
    -------
    Scenario
        The open 240 m path, with its initial offset of 1.0 m.
    """
    from workbench.base.clothoid_chain import ClothoidChain

    kappa = 1.0 / 30.0
    chain = (
        ClothoidChain()
        .straight(40.0)
        .clothoid_to(kappa, 20.0)
        .arc(30.0)
        .clothoid_to(-kappa, 40.0)
        .arc(30.0)
        .clothoid_to(0.0, 20.0)
        .straight(60.0)
    )
    return Scenario(
        "fig17",
        chain.to_path("fig17"),
        FIG17_DESCRIPTION,
        initial_offset_m=1.0,
    )


# ---------------------------------------------------------------------------------------------- Zandvoort
def zandvoort(options: ScenarioOptions) -> Scenario:
    """The Zandvoort centre line and track widths from the TUMFTM racetrack database (closed loop, 4316.5 m).

    The file is third-party data (LGPL-3.0) and is not shipped: pass it with --track FILE, set the environment
    variable WORKBENCH_ZANDVOORT_CSV, or keep it where `zandvoort_track_file` looks (tracks/ of the current
    directory, ../shared/tracks/ beside the checkout). Only that file (recognised by `is_zandvoort_file`, its
    content's digest) makes the scenario named "zandvoort"; any other waypoint file given for it is read as it is
    and named by the file (its stem), so that no result on another track is labelled, or judged, as Zandvoort.

    Parameters
    ----------
    options : ScenarioOptions
        `track_file`, the track CSV to read (None: looked for as `zandvoort_track_file` says).

    Returns
    -------
    Scenario
        The closed centre line with its track widths, named "zandvoort" when the file is the TUMFTM one.

    Raises
    ------
    WorkbenchInputError
        When no track file is found or named, or the file cannot be read as waypoints.
    """
    track = _zandvoort_track(options)
    scenario = from_file(track, options)
    if not is_zandvoort_file(track):
        return dataclasses.replace(scenario, description=_zandvoort_description(options))
    return Scenario("zandvoort", scenario.path, _zandvoort_description(options))


def is_zandvoort_file(track_file: Path) -> bool:
    """Whether this file holds exactly the bytes of the TUMFTM Zandvoort track file (SHA-256 `ZANDVOORT_SHA256`).

    Parameters
    ----------
    track_file : pathlib.Path
        The file to check.

    Returns
    -------
    bool
        True when its SHA-256 is `ZANDVOORT_SHA256`.

    Raises
    ------
    WorkbenchInputError
        When the file cannot be read (the message names it and why).
    """
    import hashlib

    try:
        return hashlib.sha256(Path(track_file).read_bytes()).hexdigest() == ZANDVOORT_SHA256
    except OSError as exc:
        raise WorkbenchInputError(f"zandvoort: cannot read the track file {str(track_file)!r} ({exc})") from None


def zandvoort_places() -> list[Path]:
    """Where the Zandvoort file is looked for when neither --track nor $WORKBENCH_ZANDVOORT_CSV names it, in order:
    each of ZANDVOORT_FILE_NAMES in tracks/ of the current directory, then in ../shared/tracks/ beside the checkout
    (when running from one).

    Returns
    -------
    list of pathlib.Path
        The candidate files, in the order they are tried; they need not exist.
    """
    folders = [Path.cwd() / TRACKS_FOLDER]
    if CHECKOUT_ROOT is not None:
        folders.append(CHECKOUT_ROOT.parent / "shared" / "tracks")
    return [folder / name for folder in folders for name in ZANDVOORT_FILE_NAMES]


def zandvoort_track_file(track_file: Path | None = None) -> Path:
    """The Zandvoort file: `track_file` (--track), else $WORKBENCH_ZANDVOORT_CSV, else the first of
    `zandvoort_places` that exists. WorkbenchInputError when a file named by the first two does not exist, or when
    neither names one and no place holds it (the message lists every place looked in).

    Parameters
    ----------
    track_file : pathlib.Path or None
        The file given with --track (None: the environment variable, then the places).

    Returns
    -------
    pathlib.Path
        An existing file; whether it is the TUMFTM track is for `is_zandvoort_file` to say.

    Raises
    ------
    WorkbenchInputError
        When the named file does not exist, or none is named and none of `zandvoort_places` exists.
    """
    named, by = (track_file, "--track") if track_file is not None else (None, "")
    if named is None and os.environ.get(ZANDVOORT_ENV):
        named, by = Path(os.environ[ZANDVOORT_ENV]), f"${ZANDVOORT_ENV}"
    if named is not None:
        if not Path(named).is_file():
            raise WorkbenchInputError(
                f"zandvoort: track file {str(named)!r} does not exist (named by {by}); expected {ZANDVOORT_SOURCE}"
            )
        return Path(named)
    places = zandvoort_places()
    for place in places:
        if place.is_file():
            return place
    raise WorkbenchInputError(
        f"zandvoort needs {ZANDVOORT_SOURCE}; no --track, no ${ZANDVOORT_ENV}, and none of these exists: "
        f"{', '.join(str(p) for p in places)}; download it and pass --track FILE, set the environment variable "
        f"{ZANDVOORT_ENV}, or put it at one of those places"
    )


def _zandvoort_track(options: ScenarioOptions) -> Path:
    """The track file for these options (`zandvoort_track_file` of --track)."""
    return zandvoort_track_file(options.track_file)


def _zandvoort_description(options: ScenarioOptions) -> str:
    track = _zandvoort_track(options)
    if not is_zandvoort_file(track):
        return (
            f"waypoints from {track}, given for zandvoort but not the TUMFTM Zandvoort track file (its SHA-256 "
            f"differs), so named {track.stem} and compared with none of the paper's Zandvoort results"
        )
    return f"Zandvoort (TUMFTM racetrack-database centre line and track widths, closed loop) from {track}"


# ---------------------------------------------------------------------------------------------- files
def from_file(path: Path, options: ScenarioOptions) -> Scenario:
    """A scenario from any waypoint file (CSV x,y[,v]; TUMFTM racetrack CSV; GPS CSV with lat/lon columns).

    Parameters
    ----------
    path : pathlib.Path
        The waypoint file: x, y (m) and optionally v (m/s) columns, a TUMFTM racetrack CSV (x, y and the track
        widths, m), or latitude and longitude (degrees) projected onto a local plane.
    options : ScenarioOptions
        What a scenario may depend on; a file's path depends on none of it.

    Returns
    -------
    Scenario
        The path named after the file's stem; a closed loop when the file's last point repeats its first, and
        for a TUMFTM racetrack file.

    Raises
    ------
    WorkbenchInputError
        When the file cannot be read, or its columns or waypoints are malformed (the message names the file and
        the fault).
    """
    from workbench.base.path import ReferencePath
    from workbench.base.waypoint_files import read_waypoints  # pyproj for a GPS file only (start-up time)

    waypoints = read_waypoints(path)
    ref = ReferencePath.from_waypoints(waypoints, name=path.stem)
    kind = "closed loop" if waypoints.closed else "open path"
    widths = ", track widths" if waypoints.has_widths else ""
    return Scenario(path.stem, ref, f"waypoints from {path.name} ({len(waypoints)} points, {kind}{widths})")


ScenarioFactory = Callable[[ScenarioOptions], Scenario]

#: The named scenarios, in the order `workbench scenarios` lists them.
SCENARIOS: dict[str, ScenarioFactory] = {
    "figure8": figure8,
    "dlc": double_lane_change,
    "fig17": fig17,
    "zandvoort": zandvoort,
}


def make_scenario(name_or_file: str, options: ScenarioOptions | None = None) -> Scenario:
    """Build a named scenario, or one from a waypoint file when the argument is a path to a file.

    `dlc` and `circuit:SEED` need `options.vehicle_width_m` (the width of the vehicle to be driven: the lanes and
    the track are sized for it); the other scenarios do not depend on the vehicle. `circuit:SEED` is drawn within
    `options.circuit_ranges` (None: the defaults), which any other scenario refuses.

    Parameters
    ----------
    name_or_file : str
        A named scenario ("figure8", "dlc", "fig17", "zandvoort"), a generated circuit "circuit:SEED" (SEED a
        whole number from 0 to 2**63 - 1), or the path of a waypoint file (.csv or .txt, or any existing file).
    options : ScenarioOptions, optional
        The vehicle's width, the track file and the circuit ranges the scenario may depend on (None: none given).

    Returns
    -------
    Scenario
        The reference path, where the vehicle starts on it and what to draw around it.

    Raises
    ------
    WorkbenchInputError
        An unknown name (the message lists the scenarios), a waypoint file that does not exist or is malformed,
        `dlc` or a circuit without `options.vehicle_width_m`, circuit ranges given for a scenario that is not a
        circuit, or a Zandvoort track file that cannot be found.

    Examples
    --------
    >>> from workbench.simulation.scenario import ScenarioOptions
    >>> from workbench.simulation.scenarios import make_scenario
    >>> make_scenario("fig17").initial_offset_m
    1.0
    >>> dlc = make_scenario("dlc", ScenarioOptions(vehicle_width_m=1.8))
    >>> dlc.path.closed, dlc.cones_xy.shape
    (False, (18, 2))
    >>> make_scenario("circuit:7", ScenarioOptions(vehicle_width_m=1.8)).path.closed
    True
    """
    options = options or ScenarioOptions()
    from workbench.simulation.circuits import DEFAULT_RANGES, circuit_seed, generate_circuit

    seed = None if name_or_file in SCENARIOS else circuit_seed(name_or_file)
    if seed is None and options.circuit_ranges is not None:
        raise WorkbenchInputError(
            f"circuit ranges shape the generated circuits (circuit:SEED) only; scenario {name_or_file!r} is not one: "
            "drop the ranges (--circuit-ranges) or name a circuit"
        )
    if name_or_file in SCENARIOS:
        return SCENARIOS[name_or_file](options)
    if seed is not None:
        ranges = options.circuit_ranges if options.circuit_ranges is not None else DEFAULT_RANGES
        return generate_circuit(seed, ranges, vehicle_width_m=options.required_width_m(name_or_file))
    candidate = Path(name_or_file)
    if candidate.suffix.lower() in {".csv", ".txt"} or candidate.is_file():
        if not candidate.is_file():
            raise WorkbenchInputError(f"waypoint file {name_or_file!r} does not exist")
        return from_file(candidate, options)
    raise WorkbenchInputError(
        f"unknown scenario {name_or_file!r}; choose one of {', '.join(SCENARIOS)} or give a waypoint CSV file, or "
        "name a generated circuit circuit:SEED (SEED a whole number >= 0)"
    )


def is_named_scenario(name: str) -> bool:
    """Whether `name` names a scenario rather than a file: one of SCENARIOS, or a generated circuit's name
    (circuit:SEED). A name that starts with circuit: but has no valid seed is refused (`circuits.circuit_seed`).

    Parameters
    ----------
    name : str
        A scenario name or a waypoint file's path, as given to `make_scenario`.

    Returns
    -------
    bool
        True for a named scenario or a generated circuit, False for anything else (a file).

    Raises
    ------
    WorkbenchInputError
        When `name` starts with "circuit:" but does not end in a valid seed.
    """
    if name in SCENARIOS:
        return True
    from workbench.simulation.circuits import circuit_seed

    return circuit_seed(name) is not None


#: Each named scenario's one-line description, without building its path (`workbench scenarios` starts fast).
DESCRIPTIONS: dict[str, Callable[[ScenarioOptions], str]] = {
    "figure8": lambda _options: _figure8_description(),
    "dlc": _dlc_description,
    "fig17": lambda _options: FIG17_DESCRIPTION,
    "zandvoort": _zandvoort_description,
}


def describe_scenarios(options: ScenarioOptions | None = None) -> list[tuple[str, str]]:
    """(name, one-line description) of every named scenario; a scenario that needs a missing file says so.

    Parameters
    ----------
    options : ScenarioOptions, optional
        The vehicle's width and track file the descriptions may depend on (None: none given: `dlc` then describes
        its lanes by formula).

    Returns
    -------
    list of tuple of (str, str)
        (name, description) of each named scenario in the order `workbench scenarios` lists them, then the
        generated circuits' family ("circuit:SEED").
    """
    rows = []
    for name, factory in SCENARIOS.items():
        try:
            rows.append((name, DESCRIPTIONS[name](options or ScenarioOptions())))
        except WorkbenchInputError as exc:
            rows.append((name, f"{(factory.__doc__ or '').strip().splitlines()[0]} [unavailable: {exc}]"))
    from workbench.simulation.circuits import CIRCUIT_PREFIX, circuit_family_description

    rows.append((f"{CIRCUIT_PREFIX}SEED", circuit_family_description()))
    return rows


__all__ = [
    "DoubleLaneChangeLayout",
    "describe_scenarios",
    "double_lane_change",
    "fig17",
    "figure8",
    "from_file",
    "is_named_scenario",
    "is_zandvoort_file",
    "make_scenario",
    "zandvoort",
    "zandvoort_places",
    "zandvoort_track_file",
]
