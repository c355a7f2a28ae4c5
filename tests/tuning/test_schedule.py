"""schedule: lag and filter per speed, and the scheduled filter file the clothoid controller reads."""

from __future__ import annotations

from pathlib import Path

import pytest

from controllers.clothoid.filter_file import read_filter_file
from tuning.schedule import compare_closed_loop, fixed_and_scheduled_filters, identify_schedule, steer_amplitude_deg
from workbench.errors import WorkbenchInputError
from workbench.vehicles import make_vehicle


@pytest.fixture(scope="module")
def truck():
    return make_vehicle("tractor-semitrailer")


@pytest.fixture(scope="module")
def result(truck):
    return identify_schedule(truck, [30.0, 60.0, 90.0])


def test_the_trucks_lag_slows_with_speed(result) -> None:
    # Measured omega_n 4.29 / 3.37 / 2.54 rad/s, zeta 0.78 / 1.20 / 1.33 at 30 / 60 / 90 km/h.
    wn = [e.fit.lag.omega_n_rad_s for e in result.entries]
    assert wn[0] > wn[1] > wn[2]
    assert wn == pytest.approx([4.29, 3.37, 2.54], rel=0.03)
    for e in result.entries:
        assert e.design.cascade_bandwidth_rad_s >= 2 * e.design.plant_bandwidth_rad_s
        assert e.fit.lag.speed_range_mps[0] == pytest.approx(e.speed_kmh / 3.6, rel=1e-3)


@pytest.mark.parametrize("suffix", [".json", ".toml"])
def test_the_schedule_round_trips_through_read_filter_file(result, tmp_path: Path, suffix: str) -> None:
    path = result.write(tmp_path / f"schedule{suffix}", nominal_speed_kmh=30.0)
    schedule = read_filter_file(path)
    assert schedule.speeds_kmh == (30.0, 60.0, 90.0)
    assert schedule.params == tuple(e.design.params for e in result.entries)
    assert schedule.metadata["plant"]["omega_n_rad_s"] == result.entries[0].fit.lag.omega_n_rad_s
    per_speed = schedule.metadata["design"]["per_speed"]
    assert [row["speed_kmh"] for row in per_speed] == [30.0, 60.0, 90.0]
    mid = schedule.at_speed(45.0)
    p30, p60 = result.entries[0].design.params, result.entries[1].design.params
    assert mid.omega_z_rad_s == pytest.approx(0.5 * (p30.omega_z_rad_s + p60.omega_z_rad_s))


def test_fixed_and_scheduled_files_for_the_closed_loop_comparison(truck, result, tmp_path: Path) -> None:
    files = fixed_and_scheduled_filters(truck, result, 30.0, tmp_path)
    assert set(files) == {"scheduled", "fixed 30 km/h"}
    fixed = read_filter_file(files["fixed 30 km/h"])
    assert fixed.params == (result.entries[0].design.params,)
    with pytest.raises(WorkbenchInputError, match="fixed_speed_kmh 40 is not a speed of the schedule"):
        fixed_and_scheduled_filters(truck, result, 40.0, tmp_path)


def test_closed_loop_comparison_runs_the_clothoid_controller(truck, result, tmp_path: Path) -> None:
    # Measured on the dlc at 60 km/h (0.3 g speed profile): max |CTE| 0.65 m with the 30 km/h filter, 1.97 m
    # without a lead filter.
    files = {"fixed": fixed_and_scheduled_filters(truck, result, 30.0, tmp_path)["fixed 30 km/h"], "off": None}
    rows = compare_closed_loop(lambda: make_vehicle("tractor-semitrailer"), files, [60.0])
    by_filter = {row.filter: row for row in rows}
    assert all(row.completed and row.speed_kmh == 60.0 for row in rows)
    assert by_filter["fixed"].max_abs_cte_m < 0.5 * by_filter["off"].max_abs_cte_m


def test_identification_amplitude_gives_the_asked_lateral_acceleration(truck) -> None:
    # 0.1 g at 60 km/h: kappa = 0.981 / 16.67^2 = 0.00353 1/m; Ackermann x steering ratio 22.
    assert steer_amplitude_deg(truck, 60.0, 0.1) == pytest.approx(25.1, abs=0.1)
    with pytest.raises(WorkbenchInputError, match="speeds must increase strictly"):
        identify_schedule(truck, [60.0, 30.0])
