"""The curvature-limits file (`tuning/limits_file.py`): round trip, the rate column from the vehicle, bad tables
named."""

from __future__ import annotations

from pathlib import Path

import pytest

from controllers.clothoid.curvature_limits import CurvatureLimits
from tuning.limits_file import read_limits_file, write_limits_file
from workbench.base.errors import WorkbenchInputError
from workbench.vehicles import make_vehicle

TRUCK = make_vehicle("tractor-semitrailer").geometry


def test_csv_round_trip_and_interpolation(tmp_path: Path) -> None:
    limits = CurvatureLimits((10.0, 50.0, 90.0), (0.1, 0.02, 0.006), (0.3, 0.2, 0.1))
    write_limits_file(limits, tmp_path / "limits.csv")
    back = read_limits_file(tmp_path / "limits.csv")
    assert back.speeds_kmh == limits.speeds_kmh and back.max_curvature_1pm == limits.max_curvature_1pm
    assert back.at_speed(30 / 3.6) == pytest.approx((0.06, 0.25), rel=1e-12)
    assert back.at_speed(200 / 3.6) == pytest.approx((0.006, 0.1), rel=1e-12)  # clamped beyond the table


def test_csv_without_rate_column_takes_the_rate_from_the_vehicle(tmp_path: Path) -> None:
    (tmp_path / "l.csv").write_text("speed_kmh,max_curvature_1pm\n10,0.1\n100,0.01\n")
    limits = read_limits_file(tmp_path / "l.csv", TRUCK)
    assert limits.at_speed(5.0)[1] == pytest.approx(CurvatureLimits.default_for(TRUCK).at_speed(5.0)[1])


@pytest.mark.parametrize(
    ("text", "needle"),
    [
        ("speed,kappa\n1,2\n", "missing column"),
        ("speed_kmh,max_curvature_1pm\n10,abc\n", "not a number"),
        ("speed_kmh,max_curvature_1pm\n10,0.1\n5,0.2\n", "increase strictly"),
        ("speed_kmh,max_curvature_1pm\n10,-0.1\n", "must be finite and > 0"),
        ("speed_kmh,max_curvature_1pm\n", "one curvature and one rate per speed"),
        ("speed_kmh,max_curvature_1pm,max_curvature_1pm\n10,0.1,0.2\n", "column 'max_curvature_1pm' appears 2 times"),
        ("speed_kmh,max_curvature_1pm,Speed_kmh\n10,0.1,20\n", "column 'speed_kmh' appears 2 times"),
    ],
)
def test_bad_tables_are_rejected(text: str, needle: str, tmp_path: Path) -> None:
    (tmp_path / "bad.csv").write_text(text)
    with pytest.raises(WorkbenchInputError, match=needle):
        read_limits_file(tmp_path / "bad.csv", TRUCK)


def test_missing_file_is_named(tmp_path: Path) -> None:
    with pytest.raises(WorkbenchInputError, match=r"nope\.csv"):
        read_limits_file(tmp_path / "nope.csv", TRUCK)
