"""Read waypoint files into `Waypoints`: TUMFTM racetrack-database CSV, plain x/y CSV and GPS CSV.

Every format is a comma-separated file with one header row; column names are matched case-insensitively,
ignoring surrounding spaces (and a leading ``#``):

- x/y, metres: ``x``/``x_m`` and ``y``/``y_m``. A header starting with ``#`` is the TUMFTM racetrack-database
  convention (``# x_m,y_m,w_tr_right_m,w_tr_left_m``, or ``# x_m,y_m`` for race lines): a closed loop whose
  last point is not repeated.
- optional track widths, metres: ``w_tr_right_m``/``w_right_m`` and ``w_tr_left_m``/``w_left_m`` (TUMFTM's names
  first), the distances from each point to the track's right and left edges; both or neither, finite and in
  [0, `MAX_TRACK_HALF_WIDTH_M`]. Kept in the waypoints (and the path, scenario, metrics and figures after them).
  Other columns are ignored.
- GPS, degrees (WGS84): ``lat``/``latitude``/``lat_deg`` and ``lon``/``lng``/``longitude``/``lon_deg``,
  projected to east/north metres centred on the first point (see `geodetic_to_local_en`). If a file has
  both x/y and latitude/longitude columns, x/y are used.
- optional speed: ``v``/``v_mps``/``speed_mps`` in m/s, or ``v_kmh``/``speed_kmh`` in km/h (converted to m/s).
  Any other column that reads as a speed (``speed``, ``velocity``, ``v_kph``, ...) is refused, unit unknown.

A path whose last point repeats its first (within `MIN_WAYPOINT_SPACING_M`) is a closed loop: the repeated
point is dropped and ``closed=True``. Bad input raises `WorkbenchInputError` naming the file.
"""

from __future__ import annotations

import csv
import math
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike

from workbench.base.errors import WorkbenchInputError, require_in_range
from workbench.base.waypoints import MAX_TRACK_HALF_WIDTH_M, MIN_WAYPOINT_SPACING_M, Waypoints

X_NAMES = ("x", "x_m")
Y_NAMES = ("y", "y_m")
LAT_NAMES = ("lat", "latitude", "lat_deg")
LON_NAMES = ("lon", "lng", "longitude", "lon_deg")
SPEED_MPS_NAMES = ("v", "v_mps", "speed_mps")
SPEED_KMH_NAMES = ("v_kmh", "speed_kmh")
WIDTH_RIGHT_NAMES = ("w_tr_right_m", "w_right_m")
WIDTH_LEFT_NAMES = ("w_tr_left_m", "w_left_m")
KMH_PER_MPS = 3.6


def read_waypoints(path: str | os.PathLike[str]) -> Waypoints:
    """Read a TUMFTM, plain x/y or GPS waypoint CSV (format detected from the header) into `Waypoints`.

    Positions come back in metres in a local east/north frame, speeds in m/s; ``source`` is the file's name.
    """
    file = Path(path)
    name = file.name
    table = _read_table(file)
    x_col, y_col = _find(table, X_NAMES, name), _find(table, Y_NAMES, name)
    lat_col, lon_col = _find(table, LAT_NAMES, name), _find(table, LON_NAMES, name)
    if x_col and y_col:
        _require_rows(table, name)
        x, y = _numbers(table, x_col, name), _numbers(table, y_col, name)
    elif lat_col and lon_col:
        _require_rows(table, name)
        lat, lon = _in_range(table, lat_col, name, 90.0), _in_range(table, lon_col, name, 180.0)
        x, y = geodetic_to_local_en(lat, lon, float(lat[0]), float(lon[0]))
    else:
        raise WorkbenchInputError(
            f"{name}: the header has no x/y or latitude/longitude columns; found {list(table.columns)}; "
            f"accepted (case-insensitive): x {X_NAMES} with y {Y_NAMES}, or latitude {LAT_NAMES} with "
            f"longitude {LON_NAMES}, comma-separated"
        )

    speed = None
    speed_col = _find(table, SPEED_MPS_NAMES + SPEED_KMH_NAMES, name)
    if speed_col is None:
        _refuse_unknown_speed_unit(table, name)
    if speed_col:
        speed = _numbers(table, speed_col, name)
        if _normalise(speed_col) in SPEED_KMH_NAMES:
            speed = speed / KMH_PER_MPS

    right, left = _track_widths(table, name)
    closed = str(table.columns[0]).lstrip().startswith("#")
    if np.hypot(x[-1] - x[0], y[-1] - y[0]) < MIN_WAYPOINT_SPACING_M:
        x, y, speed = x[:-1], y[:-1], None if speed is None else speed[:-1]
        right, left = (None, None) if right is None or left is None else (right[:-1], left[:-1])
        closed = True
    return Waypoints(x, y, speed_mps=speed, closed=closed, source=name, width_right_m=right, width_left_m=left)


def geodetic_to_local_en(
    lat_deg: ArrayLike, lon_deg: ArrayLike, origin_lat_deg: float, origin_lon_deg: float
) -> tuple[np.ndarray, np.ndarray]:
    """WGS84 latitude/longitude (degrees) to (east_m, north_m) around an origin (degrees).

    Azimuthal equidistant projection (``+proj=aeqd``, pyproj) centred on the origin: distance and bearing from
    the origin are exact (geodesic); lengths across that direction are stretched by about (d / 6371 km)^2 / 6
    at distance d, i.e. < 1e-6 within 15 km. Scalars give 0-d arrays.
    """
    require_in_range("origin latitude", origin_lat_deg, -90.0, 90.0, "deg")
    require_in_range("origin longitude", origin_lon_deg, -180.0, 180.0, "deg")
    lat, lon = np.asarray(lat_deg, dtype=float), np.asarray(lon_deg, dtype=float)
    for label, values, limit in (("latitude", lat, 90.0), ("longitude", lon, 180.0)):
        bad = np.flatnonzero(~(np.abs(values) <= limit))
        if bad.size:
            i = int(bad[0])
            raise WorkbenchInputError(
                f"{label} must be finite and in [-{limit:g}, {limit:g}] deg; entry {i} is {float(values.ravel()[i])!r}"
            )
    from pyproj import CRS, Transformer  # only for a GPS file: not on every waypoint file's path (~50 ms)

    centre = f"+lat_0={float(origin_lat_deg)!r} +lon_0={float(origin_lon_deg)!r}"
    local = CRS.from_proj4(f"+proj=aeqd {centre} +datum=WGS84 +units=m +no_defs")
    east, north = Transformer.from_crs(CRS.from_epsg(4326), local, always_xy=True).transform(lon, lat)
    return np.asarray(east, dtype=float), np.asarray(north, dtype=float)


@dataclass(frozen=True)
class _Table:
    """A CSV file's header and cells: columns as written in the header, cells[j] the stripped strings of column j,
    lines[i] the file line of data row i (blank rows dropped)."""

    columns: tuple[str, ...]
    cells: tuple[tuple[str, ...], ...]
    lines: tuple[int, ...]

    def column(self, name: str) -> tuple[str, ...]:
        return self.cells[self.columns.index(name)]

    def __len__(self) -> int:
        return len(self.lines)


def _read_table(file: Path) -> _Table:
    """The file's header and cells (the standard library's csv: a waypoint file is a few thousand rows of text).
    The header is the first row that is not blank; a row shorter than it is padded with empty cells, a longer one
    refused."""
    if not file.is_file():
        what = "is not a file" if file.exists() else "does not exist"
        raise WorkbenchInputError(f"waypoint file {str(file)!r} {what}; expected a CSV file")
    header: list[str] | None = None
    rows: list[list[str]] = []
    lines: list[int] = []
    try:
        with file.open(newline="", encoding="utf-8-sig") as stream:
            reader = csv.reader(stream, strict=True)
            for row in reader:
                cells = [cell.strip() for cell in row]
                if not any(cells):
                    continue
                if header is None:
                    header = row
                elif len(row) > len(header):
                    raise csv.Error(
                        f"line {reader.line_num} has {len(row)} fields, more fields than the header's {len(header)}"
                    )
                else:
                    rows.append(cells + [""] * (len(header) - len(cells)))
                    lines.append(reader.line_num)
    except (csv.Error, UnicodeDecodeError, OSError) as err:
        raise WorkbenchInputError(
            f"{file.name}: not readable as CSV ({str(err).strip()}); expected UTF-8 text, comma-separated, a header "
            "row and rows with the same number of fields"
        ) from err
    if header is None:
        raise WorkbenchInputError(
            f"{file.name}: the file is empty; expected a CSV header row (x,y or lat,lon) and data rows"
        )
    return _Table(tuple(header), tuple(zip(*rows, strict=True)) or ((),) * len(header), tuple(lines))


def _normalise(column: object) -> str:
    return str(column).strip().lstrip("#").strip().lower()


def _find(table: _Table, names: tuple[str, ...], file_name: str) -> str | None:
    """The one column whose normalised name is in `names`, or None; several is an error."""
    found = [column for column in table.columns if _normalise(column) in names]
    if len(found) > 1:
        raise WorkbenchInputError(f"{file_name}: columns {found} all mean the same quantity; keep one of them")
    return found[0] if found else None


def _refuse_unknown_speed_unit(table: _Table, file_name: str) -> None:
    """A column that reads as a speed but names no unit would be ignored, and the path planned at another speed."""
    for column in table.columns:
        label = _normalise(column)
        if "speed" in label or "vel" in label or label.startswith("v_"):
            raise WorkbenchInputError(
                f"{file_name}: column {str(column).strip()!r} looks like a speed, but its unit is not known; name it "
                f"one of {SPEED_MPS_NAMES} (m/s) or {SPEED_KMH_NAMES} (km/h)"
            )


def _track_widths(table: _Table, file_name: str) -> tuple[np.ndarray | None, np.ndarray | None]:
    """The right and left track widths (m), or (None, None) without width columns; one without the other, a
    blank, non-numeric, NaN, negative or implausibly large entry raises naming the column and line."""
    right_col, left_col = _find(table, WIDTH_RIGHT_NAMES, file_name), _find(table, WIDTH_LEFT_NAMES, file_name)
    if right_col is None and left_col is None:
        return None, None
    if right_col is None or left_col is None:
        found, wanted = (right_col, WIDTH_LEFT_NAMES) if left_col is None else (left_col, WIDTH_RIGHT_NAMES)
        raise WorkbenchInputError(
            f"{file_name}: column {str(found).strip()!r} gives one track width but no column gives the other "
            f"(one of {wanted}); give both edges' distances from the centre line, or neither"
        )
    widths = []
    for column in (right_col, left_col):
        values = _numbers(table, column, file_name)
        bad = np.flatnonzero((values < 0.0) | (values > MAX_TRACK_HALF_WIDTH_M))
        if bad.size:
            i = int(bad[0])
            raise WorkbenchInputError(
                f"{file_name}: column {column!r}, line {table.lines[i]}: {float(values[i])!r} m is outside the "
                f"allowed range [0, {MAX_TRACK_HALF_WIDTH_M:g}] m (the distance from the centre line to the edge)"
            )
        widths.append(values)
    return widths[0], widths[1]


def _require_rows(table: _Table, file_name: str) -> None:
    if len(table) < 3:
        raise WorkbenchInputError(f"{file_name}: a path needs at least 3 waypoint rows; the file has {len(table)}")


def _numbers(table: _Table, column: str, file_name: str) -> np.ndarray:
    """Column as floats; raise naming column, line and text at the first blank, non-numeric, NaN or inf."""
    texts = table.column(column)
    values = np.array([_number(text) for text in texts], dtype=float)
    bad = np.flatnonzero(~np.isfinite(values))
    if bad.size:
        i = int(bad[0])
        text = texts[i]
        shown = repr(text) if text else "an empty entry"
        raise WorkbenchInputError(
            f"{file_name}: column {column!r}, line {table.lines[i]}: {shown} is not allowed; "
            "every entry must be a finite number"
        )
    return values


def _number(text: str) -> float:
    """A cell as a float, NaN when it is not a number (blank, text)."""
    try:
        return float(text)
    except ValueError:
        return math.nan


def _in_range(table: _Table, column: str, file_name: str, limit: float) -> np.ndarray:
    """Column as floats in [-limit, limit] degrees; raise naming column, line and value otherwise."""
    values = _numbers(table, column, file_name)
    bad = np.flatnonzero(np.abs(values) > limit)
    if bad.size:
        i = int(bad[0])
        raise WorkbenchInputError(
            f"{file_name}: column {column!r}, line {table.lines[i]}: {float(values[i])!r} deg is outside "
            f"the allowed range [-{limit:g}, {limit:g}] deg"
        )
    return values
