"""A closed test track in the TUMFTM racetrack-database format, for the feasibility and track-margin tests."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np


def stadium_file(
    folder: Path,
    name: str,
    radius_m: float,
    right_m: float = 5.0,
    left_m: float = 5.0,
    straight_m: float = 80.0,
    first: int = 0,
) -> Path:
    """A TUMFTM centre line (closed, counter-clockwise) of two straights joined by semicircular hairpins of
    `radius_m`, points every 2 m on the straights and 0.8 m or so on the hairpins, track widths right_m / left_m,
    starting at point `first` (0: mid-way along the lower straight). Written to folder/name."""
    points = [(x, 0.0) for x in np.arange(0.0, straight_m / 2, 2.0)]
    arc = np.linspace(-math.pi / 2, math.pi / 2, 26)[:-1]
    points += [(straight_m / 2 + radius_m * math.cos(a), radius_m + radius_m * math.sin(a)) for a in arc]
    points += [(x, 2 * radius_m) for x in np.arange(straight_m / 2, -straight_m / 2, -2.0)]
    points += [(-straight_m / 2 - radius_m * math.cos(a), radius_m - radius_m * math.sin(a)) for a in arc]
    points += [(x, 0.0) for x in np.arange(-straight_m / 2, 0.0, 2.0)]
    rows = "\n".join(f"{float(x)!r},{float(y)!r},{right_m},{left_m}" for x, y in points[first:] + points[:first])
    file = folder / name
    file.write_text("# x_m,y_m,w_tr_right_m,w_tr_left_m\n" + rows + "\n", encoding="utf-8")
    return file
