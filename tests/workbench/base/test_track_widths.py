"""Track widths (issue 20, item 12): read from TUMFTM files (w_tr_right_m, w_tr_left_m), refused with the row and
column named when malformed, kept by `Waypoints`, resampled along the `ReferencePath` like its speed, and turned
into the track's edges."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from workbench.base.errors import WorkbenchInputError
from workbench.base.path import ReferencePath
from workbench.base.waypoint_files import read_waypoints
from workbench.base.waypoints import Waypoints

# Third-party TUMFTM racetrack-database files (LGPL) live beside the repo, never inside it.
ZANDVOORT_TRACK = Path(__file__).resolve().parents[4] / "shared" / "tracks" / "Zandvoort_track.csv"
needs_zandvoort = pytest.mark.skipif(
    not ZANDVOORT_TRACK.is_file(), reason=f"TUMFTM {ZANDVOORT_TRACK.name} not found (third-party data)"
)
SQUARE_ROWS = ("0,0,5,4", "10,0,5,4", "10,10,6,3", "0,10,6,3")


def write(folder: Path, rows: tuple[str, ...] | list[str], header: str = "# x_m,y_m,w_tr_right_m,w_tr_left_m") -> Path:
    path = folder / "track.csv"
    path.write_text(header + "\n" + "\n".join(rows) + "\n", encoding="utf-8")
    return path


@needs_zandvoort
def test_zandvoort_keeps_its_widths_and_the_path_resamples_them_within_the_files_range() -> None:
    table = pd.read_csv(ZANDVOORT_TRACK)
    right_file, left_file = table["w_tr_right_m"].to_numpy(), table["w_tr_left_m"].to_numpy()
    waypoints = read_waypoints(ZANDVOORT_TRACK)
    assert waypoints.has_widths
    np.testing.assert_array_equal(waypoints.width_right_m, right_file)  # 864 rows, the loop's last not repeated
    np.testing.assert_array_equal(waypoints.width_left_m, left_file)
    path = ReferencePath.from_waypoints(waypoints)
    assert path.has_widths and path.width_right_m.shape == path.x_m.shape == path.width_left_m.shape
    for resampled, given in ((path.width_right_m, right_file), (path.width_left_m, left_file)):
        assert given.min() - 1e-12 <= resampled.min() and resampled.max() <= given.max() + 1e-12
        assert resampled.mean() == pytest.approx(given.mean(), rel=0.01)  # points are evenly spaced (about 5 m)
    # The seam is continuous: the last sample repeats the first.
    assert path.width_right_m[-1] == pytest.approx(path.width_right_m[0], abs=1e-12)
    # The first waypoint is the path's first sample: its widths are the file's first row.
    assert (path.width_right_m[0], path.width_left_m[0]) == (right_file[0], left_file[0])


def test_widths_are_linear_in_arc_length_between_waypoints() -> None:
    x = np.arange(0.0, 41.0, 10.0)
    waypoints = Waypoints(x, np.zeros_like(x), width_right_m=[1.0, 2.0, 3.0, 3.0, 3.0], width_left_m=np.full(5, 4.0))
    path = ReferencePath.from_waypoints(waypoints)
    expected_right = np.interp(path.s_m, x, [1.0, 2.0, 3.0, 3.0, 3.0])
    np.testing.assert_allclose(path.width_right_m, expected_right, atol=1e-9)
    np.testing.assert_allclose(path.width_left_m, 4.0, atol=1e-12)
    # A planned speed keeps them, and the edges lie the widths to either side of the straight path.
    planned = path.with_speed(np.full(path.x_m.size, 5.0))
    np.testing.assert_array_equal(planned.width_right_m, path.width_right_m)
    edges = planned.track_edges()
    assert edges is not None
    (left_x, left_y), (right_x, right_y) = edges
    np.testing.assert_allclose(left_y, 4.0, atol=1e-9)
    np.testing.assert_allclose(right_y, -expected_right, atol=1e-9)
    np.testing.assert_allclose(left_x, path.x_m, atol=1e-9)
    np.testing.assert_allclose(right_x, path.x_m, atol=1e-9)


def test_a_path_without_widths_has_no_edges() -> None:
    path = ReferencePath.from_xy(np.arange(0.0, 30.0, 5.0), np.zeros(6))
    assert not path.has_widths and path.track_edges() is None


def test_a_closed_file_that_repeats_its_first_point_drops_the_repeated_widths(tmp_path: Path) -> None:
    waypoints = read_waypoints(write(tmp_path, [*SQUARE_ROWS, "0,0,5,4"], header="x_m,y_m,w_tr_right_m,w_tr_left_m"))
    assert waypoints.closed and len(waypoints) == 4
    np.testing.assert_array_equal(waypoints.width_right_m, [5, 5, 6, 6])
    np.testing.assert_array_equal(waypoints.width_left_m, [4, 4, 3, 3])


@pytest.mark.parametrize(
    ("cell", "shown"), [("nan", "'nan'"), ("abc", "'abc'"), ("", "an empty entry"), ("inf", "'inf'")]
)
def test_a_malformed_width_is_refused_naming_its_row_and_column(tmp_path: Path, cell: str, shown: str) -> None:
    rows = list(SQUARE_ROWS)
    rows[2] = f"10,10,{cell},3"  # file line 4
    with pytest.raises(WorkbenchInputError) as info:
        read_waypoints(write(tmp_path, rows))
    assert str(info.value) == (
        f"track.csv: column 'w_tr_right_m', line 4: {shown} is not allowed; every entry must be a finite number"
    )


def test_a_negative_or_huge_width_is_refused_naming_its_row_column_and_the_allowed_range(tmp_path: Path) -> None:
    rows = list(SQUARE_ROWS)
    rows[1] = "10,0,5,-0.5"  # file line 3
    with pytest.raises(WorkbenchInputError, match=r"column 'w_tr_left_m', line 3: -0\.5 m is outside the allowed "):
        read_waypoints(write(tmp_path, rows))
    rows[1] = "10,0,5000,4"
    with pytest.raises(WorkbenchInputError, match=r"line 3: 5000\.0 m is outside the allowed range \[0, 200\] m"):
        read_waypoints(write(tmp_path, rows))


def test_one_width_without_the_other_is_refused(tmp_path: Path) -> None:
    rows = ["0,0,5", "10,0,5", "10,10,6", "0,10,6"]
    with pytest.raises(WorkbenchInputError, match=r"column 'w_tr_right_m' gives one track width but no column gives"):
        read_waypoints(write(tmp_path, rows, header="# x_m,y_m,w_tr_right_m"))
    with pytest.raises(WorkbenchInputError, match=r"right width is given but not its left width"):
        Waypoints(np.arange(3.0), np.zeros(3), width_right_m=np.ones(3))


def test_waypoint_widths_are_checked() -> None:
    x, y = np.arange(0.0, 4.0), np.zeros(4)
    with pytest.raises(WorkbenchInputError, match=r"the left track width has 3 values but there are 4 waypoints"):
        Waypoints(x, y, width_right_m=np.ones(4), width_left_m=np.ones(3))
    with pytest.raises(WorkbenchInputError, match=r"the right track width at waypoint 2 is -1 m; it must be in \[0, "):
        Waypoints(x, y, width_right_m=[1.0, 1.0, -1.0, 1.0], width_left_m=np.ones(4))
    with pytest.raises(WorkbenchInputError, match=r"left track width must be finite numbers; entry 1 is nan"):
        Waypoints(x, y, width_right_m=np.ones(4), width_left_m=[1.0, math.nan, 1.0, 1.0])
    with pytest.raises(WorkbenchInputError, match=r"give both track widths"):
        ReferencePath(x, y, np.zeros(4), np.zeros(4), 1.0, False, width_left_m=np.ones(4))
