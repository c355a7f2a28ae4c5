"""What a generated circuit may be (`CircuitRanges`: its turns' radii and curvature rates, its turns, straights and
length, its track's margins and clearance) and those ranges as a file.

A TOML file's [circuits] table holds CircuitRanges fields (any left out keep their defaults), so that `workbench run
circuit:7 --circuit-ranges FILE`, a study's run parameter `circuit_ranges` and a tournament set's `circuit_ranges`
draw the same circuit from the same seed and ranges (`workbench.simulation.circuits`). The file may be a ranges file
of its own or a study or tournament spec that carries a [circuits] table: only that table is read.
`circuit_ranges_toml` writes the table (`workbench scenarios --circuit-ranges` prints it) and reads back to the
ranges written.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, fields
from pathlib import Path

from workbench.base.errors import WorkbenchInputError, require_in_range, value_text
from workbench.base.input_files import read_toml
from workbench.base.toml_text import toml_value
from workbench.base.typed_tables import dataclass_from_table
from workbench.simulation.vehicle_widths import VEHICLE_WIDTH_RANGE_M

#: The widest vehicle the scenarios size a track for (m): every circuit leaves room for its track.
MAX_VEHICLE_WIDTH_M = VEHICLE_WIDTH_RANGE_M[1]
#: The allowed numbers of turns (min_turns, max_turns): whole numbers from 3 to 24.
TURNS_RANGE = (3, 24)


@dataclass(frozen=True)
class CircuitRanges:
    """What a generated circuit may be. Each field: unit, default, allowed values.

    min_radius_m: the tightest turn's radius (m, 25; 5-500), 1/the largest curvature; max_radius_m: the widest
    turn's radius at its apex (m, 60; min_radius_m-2000), 1/the least peak curvature of a turn.
    min_curvature_rate_1pm2, max_curvature_rate_1pm2: the clothoids' sharpness |dkappa/ds| (1/m^2, 0.0006 and
    0.002; 1e-5-0.1): 0.002 takes a 25 m turn's transition over 20 m, as the paper's Figure 17 path (1/30 1/m over
    20 m, 0.00167). min_turn_deg, max_turn_deg: a turn's angle (degrees, 20 and 160; 5-270).
    max_reverse_turn_deg: the largest angle of a turn against the loop's sense (degrees, 60; min_turn_deg to
    max_turn_deg): larger ones leave the other turns so much to turn that few such loops close.
    min_turns, max_turns: the number of turns (3 and 7; 3-24, whole numbers).
    reverse_turn_share: the probability that a turn turns against the loop's sense (0.3; 0-0.5).
    min_straight_m, max_straight_m: each straight's length (m, 10 and 80; 1-2000).
    min_length_m, max_length_m: the lap's length (m, 300 and 700; 50-20000).
    side_margin_m: the room (m, 1.5; 0-10) each side of the track beyond half the vehicle's width and the
    off-tracking allowance: the controller's error and the tractor's front swinging wide (0.55 m for the
    tractor-semitrailer preset at a 25 m radius) share it.
    offtracking_length_m: the kingpin-to-axle distance (m, 13.768, the tractor-semitrailer preset's; 0-25, below
    min_radius_m) of the semitrailer the track makes room for: its axle runs R - sqrt(R^2 - l^2) inside the
    tractor's path on a radius R (4.1 m at 25 m), on either side of the centre line since turns go both ways;
    0 sizes the track for vehicles without a trailer.
    clearance_m: the least distance (m, 20; up to 2 min_radius_m) between parts of the centre line that are not
    neighbours along it; it must exceed the widest track (`side_width_m` on both sides for a 4.0 m wide vehicle,
    the widest the scenarios size for), so that no two stretches of track overlap.

    With the defaults, every circuit is followed by the four vehicle presets at 40 km/h under the paper's 0.3 g
    speed profile (`workbench.simulation.feasibility`; tested over seeds).
    """

    min_radius_m: float = 25.0
    max_radius_m: float = 60.0
    min_curvature_rate_1pm2: float = 0.0006
    max_curvature_rate_1pm2: float = 0.002
    min_turn_deg: float = 20.0
    max_turn_deg: float = 160.0
    max_reverse_turn_deg: float = 60.0
    min_turns: int = 3
    max_turns: int = 7
    reverse_turn_share: float = 0.3
    min_straight_m: float = 10.0
    max_straight_m: float = 80.0
    min_length_m: float = 300.0
    max_length_m: float = 700.0
    side_margin_m: float = 1.5
    offtracking_length_m: float = 13.768
    clearance_m: float = 20.0

    def __post_init__(self) -> None:
        for spec in fields(self):
            value = getattr(self, spec.name)
            if spec.name in ("min_turns", "max_turns"):
                fewest, most = TURNS_RANGE
                if isinstance(value, bool) or not isinstance(value, int) or not fewest <= value <= most:
                    raise WorkbenchInputError(
                        f"CircuitRanges.{spec.name} must be a whole number in [{fewest}, {most}]; got "
                        f"{value_text(value)}"
                    )
            else:
                low, high, unit = _BOUNDS[spec.name]
                require_in_range(f"CircuitRanges.{spec.name}", value, low, high, unit)
        for lower, upper, unit in (
            ("min_radius_m", "max_radius_m", "m"),
            ("min_curvature_rate_1pm2", "max_curvature_rate_1pm2", "1/m^2"),
            ("min_turn_deg", "max_turn_deg", "deg"),
            ("min_turn_deg", "max_reverse_turn_deg", "deg"),
            ("max_reverse_turn_deg", "max_turn_deg", "deg"),
            ("min_turns", "max_turns", ""),
            ("min_straight_m", "max_straight_m", "m"),
            ("min_length_m", "max_length_m", "m"),
        ):
            if getattr(self, lower) > getattr(self, upper):
                raise WorkbenchInputError(
                    f"CircuitRanges.{lower} must not exceed {upper}; got {value_text(getattr(self, lower))} and "
                    f"{value_text(getattr(self, upper))} {unit}".rstrip()
                )
        self._check_consistent()

    def _check_consistent(self) -> None:
        """The ranges together: a semitrailer fits the tightest turn, the shortest turn reaches the widest peak
        curvature at the sharpest rate, and the clearance exceeds the widest track and fits the tightest turn."""
        if self.offtracking_length_m >= self.min_radius_m:
            raise WorkbenchInputError(
                f"CircuitRanges.offtracking_length_m must be below min_radius_m (a trailer that long cannot follow "
                f"the tightest turn); got {value_text(self.offtracking_length_m)} and "
                f"{value_text(self.min_radius_m)} m"
            )
        # A clothoid pair turning theta at rate c peaks at sqrt(c theta): the shortest turn at the sharpest rate
        # must reach the widest turn's curvature.
        reach = math.sqrt(self.max_curvature_rate_1pm2 * math.radians(self.min_turn_deg))
        if reach < 1.0 / self.max_radius_m:
            raise WorkbenchInputError(
                f"CircuitRanges: a {value_text(self.min_turn_deg)} deg turn at the largest curvature rate "
                f"{value_text(self.max_curvature_rate_1pm2)} 1/m^2 peaks at a radius of {1 / reach:.4g} m, wider "
                f"than max_radius_m = {value_text(self.max_radius_m)}; allow a larger max_radius_m, a larger "
                "max_curvature_rate_1pm2 or a larger min_turn_deg"
            )
        widest = 2.0 * self.side_width_m(MAX_VEHICLE_WIDTH_M)
        if not widest < self.clearance_m <= 2.0 * self.min_radius_m:
            raise WorkbenchInputError(
                f"CircuitRanges.clearance_m must exceed the widest track ({widest:.4g} m, for a "
                f"{MAX_VEHICLE_WIDTH_M:g} m wide vehicle) and be at most 2 min_radius_m = "
                f"{value_text(2.0 * self.min_radius_m)} m; got {value_text(self.clearance_m)} m"
            )

    @property
    def offtracking_m(self) -> float:
        """The steady-state off-tracking (m) of the semitrailer's axle at the tightest radius."""
        r, length = self.min_radius_m, self.offtracking_length_m
        return r - math.sqrt(r * r - length * length)

    def side_width_m(self, vehicle_width_m: float) -> float:
        """The track's width each side of the centre line (m) for a vehicle this wide (m): half its width, the
        off-tracking allowance and the side margin."""
        return 0.5 * vehicle_width_m + self.offtracking_m + self.side_margin_m


#: The allowed values of CircuitRanges' real fields: (low, high, unit).
_BOUNDS: dict[str, tuple[float, float, str]] = {
    "min_radius_m": (5.0, 500.0, "m"),
    "max_radius_m": (5.0, 2000.0, "m"),
    "min_curvature_rate_1pm2": (1e-5, 0.1, "1/m^2"),
    "max_curvature_rate_1pm2": (1e-5, 0.1, "1/m^2"),
    "min_turn_deg": (5.0, 270.0, "deg"),
    "max_turn_deg": (5.0, 270.0, "deg"),
    "max_reverse_turn_deg": (5.0, 270.0, "deg"),
    "reverse_turn_share": (0.0, 0.5, ""),
    "min_straight_m": (1.0, 2000.0, "m"),
    "max_straight_m": (1.0, 2000.0, "m"),
    "min_length_m": (50.0, 20000.0, "m"),
    "max_length_m": (50.0, 20000.0, "m"),
    "side_margin_m": (0.0, 10.0, "m"),
    "offtracking_length_m": (0.0, 25.0, "m"),
    "clearance_m": (1.0, 1000.0, "m"),
}


#: The table of a TOML file that holds the ranges.
CIRCUITS_TABLE = "circuits"


def read_circuit_ranges(path: str | os.PathLike[str]) -> CircuitRanges:
    """The CircuitRanges of the file's [circuits] table (fields left out keep their defaults). WorkbenchInputError
    naming the file and what is allowed for a file that cannot be read or parsed, a missing [circuits] table, an
    unknown key, a value of the wrong type or not finite, and ranges `CircuitRanges` refuses."""
    label = f"circuit ranges file {str(Path(path))!r}"
    document = read_toml(path, label)
    allowed = ", ".join(f.name for f in fields(CircuitRanges))
    if CIRCUITS_TABLE not in document:
        raise WorkbenchInputError(
            f"{label}: no [{CIRCUITS_TABLE}] table (it has {', '.join(document) or 'nothing'}); give one with any of "
            f"{allowed}"
        )
    try:
        return dataclass_from_table(CircuitRanges, document[CIRCUITS_TABLE], f"[{CIRCUITS_TABLE}]")
    except WorkbenchInputError as exc:
        raise WorkbenchInputError(f"{label}: {exc}") from None


def circuit_ranges_toml(ranges: CircuitRanges | None = None) -> str:
    """The ranges (None: the defaults) as a [circuits] table, one field a line with the values it allows on its
    own (`CircuitRanges` also checks them together), that `read_circuit_ranges` reads back to the same ranges."""
    ranges = CircuitRanges() if ranges is None else ranges
    if not isinstance(ranges, CircuitRanges):
        raise WorkbenchInputError(f"ranges must be a CircuitRanges; got {value_text(ranges)}")
    lines = [
        "# The generated circuits' ranges (CircuitRanges; units in each name: m, deg, 1/m^2). Edit, then give the",
        "# file to `workbench run circuit:SEED --circuit-ranges FILE` or as a spec's circuit_ranges.",
        f"[{CIRCUITS_TABLE}]",
    ]
    for spec in fields(CircuitRanges):
        low, high, unit = _BOUNDS.get(spec.name, (*TURNS_RANGE, ""))
        allowed = f"{low:g} to {high:g} {unit}".rstrip()
        lines.append(f"{spec.name} = {toml_value(getattr(ranges, spec.name))}  # {allowed}")
    return "\n".join(lines) + "\n"


__all__ = ["CIRCUITS_TABLE", "MAX_VEHICLE_WIDTH_M", "CircuitRanges", "circuit_ranges_toml", "read_circuit_ranges"]
