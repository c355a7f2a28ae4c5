"""What a scenario is: a reference path, where the vehicle starts on it and what to draw around it
(`Scenario`), and what building one may depend on (`ScenarioOptions`). The named scenarios are built in
`workbench.simulation.scenarios`, the generated circuits in `workbench.simulation.circuits`.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from workbench.base.errors import WorkbenchInputError, require_in_range
from workbench.simulation.vehicle_widths import VEHICLE_WIDTH_RANGE_M

if TYPE_CHECKING:
    from workbench.base.path import ReferencePath
    from workbench.simulation.circuit_ranges import CircuitRanges

#: Bounds of a run's initial error: lateral offset (m, either side) and heading error (rad, either way).
MAX_INITIAL_OFFSET_M = 50.0
MAX_INITIAL_HEADING_ERROR_RAD = math.pi / 2


@dataclass(frozen=True)
class ScenarioOptions:
    """What a scenario factory may depend on.

    vehicle_width_m: overall width b (m, 0.5-4.0) of the vehicle that will be driven on the scenario, which sizes
    the ISO 3888-1 lanes of `dlc` and the track of a generated circuit; None for scenarios that do not depend on
    it. It has no default because a lane sized for one vehicle and driven by another measures nothing the standard
    defines, and nothing in a run would show the mismatch: `dlc` refuses to be built without it, from Python as
    from the command line (which passes the width of the vehicle it runs). track_file: a track CSV for scenarios
    that read one (zandvoort). circuit_ranges: the ranges a generated circuit (circuit:SEED) is drawn within
    (`workbench.simulation.circuits.CircuitRanges`; None: the defaults); any other scenario refuses them, since
    nothing in it would follow them.
    """

    vehicle_width_m: float | None = None
    track_file: Path | None = None
    circuit_ranges: CircuitRanges | None = None

    def __post_init__(self) -> None:
        if self.vehicle_width_m is not None:
            require_in_range("vehicle_width_m", self.vehicle_width_m, *VEHICLE_WIDTH_RANGE_M, "m")
        if self.circuit_ranges is not None:
            from workbench.simulation.circuit_ranges import CircuitRanges

            if not isinstance(self.circuit_ranges, CircuitRanges):
                raise WorkbenchInputError(
                    f"circuit_ranges must be a CircuitRanges or None; got {type(self.circuit_ranges).__name__}"
                )

    def required_width_m(self, scenario: str) -> float:
        """The vehicle's width (m) for a scenario sized by it; WorkbenchInputError naming `vehicle_width_m` (and
        how to give it) when it is missing."""
        if self.vehicle_width_m is None:
            raise WorkbenchInputError(
                f"{scenario} sizes its lanes for the vehicle driven on it: give ScenarioOptions(vehicle_width_m=...), "
                f"the vehicle's overall width in m, e.g. make_scenario({scenario!r}, "
                "ScenarioOptions(vehicle_width_m=vehicle.geometry.width_m)); got vehicle_width_m=None"
            )
        return self.vehicle_width_m


@dataclass(frozen=True, eq=False)
class Scenario:
    """A reference path and the initial condition of a run.

    initial_offset_m: lateral offset of the vehicle's reference point (rear-axle centre) from the path at s = 0,
    left positive (m, within +-MAX_INITIAL_OFFSET_M); initial_heading_error_rad: vehicle heading minus path heading
    at the start (rad, within +-pi/2); cones_xy: (n, 2) cone positions (m) to draw, or None; description: one line
    for `workbench scenarios`.
    """

    name: str
    path: ReferencePath
    description: str
    initial_offset_m: float = 0.0
    initial_heading_error_rad: float = 0.0
    cones_xy: np.ndarray | None = None

    def __post_init__(self) -> None:
        require_in_range("initial_offset_m", self.initial_offset_m, -MAX_INITIAL_OFFSET_M, MAX_INITIAL_OFFSET_M, "m")
        bound = MAX_INITIAL_HEADING_ERROR_RAD
        require_in_range("initial_heading_error_rad", self.initial_heading_error_rad, -bound, bound, "rad")

    def with_initial_error(self, offset_m: float | None = None, heading_error_rad: float | None = None) -> Scenario:
        """The same scenario started with this lateral offset (m, left positive) and heading error (rad); None keeps
        the scenario's own (e.g. fig17 starts 1.0 m left of the path)."""
        offset = self.initial_offset_m if offset_m is None else offset_m
        heading = self.initial_heading_error_rad if heading_error_rad is None else heading_error_rad
        return dataclasses.replace(self, initial_offset_m=offset, initial_heading_error_rad=heading)

    def initial_pose(self) -> tuple[float, float, float]:
        """(x, y, heading) of the vehicle's rear-axle centre at the start."""
        heading = float(self.path.heading_rad[0])
        x = self.path.x_m[0] - self.initial_offset_m * math.sin(heading)
        y = self.path.y_m[0] + self.initial_offset_m * math.cos(heading)
        return float(x), float(y), heading + self.initial_heading_error_rad
