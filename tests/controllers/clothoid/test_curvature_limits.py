"""Curvature limits: defaults from the vehicle's geometry, the CSV table format, interpolation, bad files."""

from __future__ import annotations

import itertools
import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from controllers.clothoid.curvature_limits import G_MPS2, CurvatureLimits
from tuning.limits_file import read_limits_file, write_limits_file
from workbench.base.errors import WorkbenchInputError
from workbench.vehicles import make_vehicle

TRUCK = make_vehicle("tractor-semitrailer").geometry


def test_default_limits_follow_lock_lateral_accel_and_steering_rate() -> None:
    limits = CurvatureLimits.default_for(TRUCK, max_lateral_accel_g=0.4)
    lock = math.tan(TRUCK.max_road_wheel_angle_rad) / TRUCK.wheelbase_m
    kappa, rate = limits.at_speed(0.0)
    assert kappa == pytest.approx(lock, rel=1e-12)  # at standstill only the steering lock limits
    for kmh in (30.0, 60.0, 90.0):
        v = kmh / 3.6
        kappa, rate = limits.at_speed(v)
        assert kappa == pytest.approx(min(lock, 0.4 * G_MPS2 / v**2), rel=1e-9)
        assert rate == pytest.approx(TRUCK.max_steer_wheel_rate_rad_s / TRUCK.steering_ratio / TRUCK.wheelbase_m)
    # Limits fall with speed, as Figure 6's rollover limits do.
    kappas = [limits.at_speed(kmh / 3.6)[0] for kmh in range(20, 150, 10)]
    assert all(b < a for a, b in itertools.pairwise(kappas))


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
    ],
)
def test_bad_tables_are_rejected(text: str, needle: str, tmp_path: Path) -> None:
    (tmp_path / "bad.csv").write_text(text)
    with pytest.raises(WorkbenchInputError, match=needle):
        read_limits_file(tmp_path / "bad.csv", TRUCK)


def test_missing_file_is_named(tmp_path: Path) -> None:
    with pytest.raises(WorkbenchInputError, match=r"nope\.csv"):
        read_limits_file(tmp_path / "nope.csv", TRUCK)


@settings(max_examples=300, deadline=None)
@given(
    st.lists(st.floats(0.01, 1.0), min_size=1, max_size=8),
    st.floats(-10.0, 200.0),
)
def test_interpolation_is_numpys_clamped_linear_one(values: list[float], speed_kmh: float) -> None:
    speeds = tuple(10.0 * (i + 1) for i in range(len(values)))
    rates = tuple(2.0 * v for v in values)
    limits = CurvatureLimits(speeds, tuple(values), rates)
    kappa, rate = limits.at_speed(speed_kmh / 3.6)
    assert kappa == pytest.approx(float(np.interp(speed_kmh, speeds, values)), rel=1e-12, abs=1e-15)
    assert rate == pytest.approx(float(np.interp(speed_kmh, speeds, rates)), rel=1e-12, abs=1e-15)
