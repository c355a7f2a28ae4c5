"""schedule: lag and filter per speed, and the scheduled filter file the clothoid controller reads."""

from __future__ import annotations

from pathlib import Path

import pytest

from tuning.filter_file import read_filter_file
from tuning.lag_fit import DELAY_FIT_MAX_ZETA, LagFitOptions
from tuning.schedule import identify_schedule, steer_amplitude_deg
from workbench.base.errors import WorkbenchInputError
from workbench.base.input_files import read_json, read_toml


def test_the_trucks_lag_slows_with_speed(result) -> None:
    # Measured omega_n 4.40 / 3.22 / 2.55 rad/s, zeta 0.70 / 1.05 / 1.29 at 30 / 60 / 90 km/h (dlc, step series and
    # chirp; without a delay).
    wn = [e.fit.lag.omega_n_rad_s for e in result.entries]
    assert wn[0] > wn[1] > wn[2]
    assert wn == pytest.approx([4.40, 3.22, 2.55], rel=0.03)
    for e in result.entries:  # x1.56 / x2.64 / x2.91 under the default bound of 3 on the peak gain
        assert e.design.cascade_bandwidth_rad_s >= 1.5 * e.design.plant_bandwidth_rad_s
        assert e.fit.lag.speed_range_mps[0] == pytest.approx(e.speed_kmh / 3.6, rel=1e-3)


@pytest.mark.parametrize("suffix", [".json", ".toml"])
def test_the_schedule_round_trips_through_read_filter_file(result, tmp_path: Path, suffix: str) -> None:
    path = result.write(tmp_path / f"schedule{suffix}", nominal_speed_kmh=30.0)
    schedule = read_filter_file(path)
    assert schedule.speeds_kmh == (30.0, 60.0, 90.0)
    assert schedule.params == tuple(e.design.params for e in result.entries)
    doc = (read_json if suffix == ".json" else read_toml)(path, "the schedule file")  # the rest, as written
    assert doc["plant"]["omega_n_rad_s"] == result.entries[0].fit.lag.omega_n_rad_s
    per_speed = doc["design"]["per_speed"]
    assert [row["speed_kmh"] for row in per_speed] == [30.0, 60.0, 90.0]
    mid = schedule.at_speed(45.0)
    p30, p60 = result.entries[0].design.params, result.entries[1].design.params
    assert mid.omega_z_rad_s == pytest.approx(0.5 * (p30.omega_z_rad_s + p60.omega_z_rad_s))


def test_the_nominal_filter_is_the_one_of_the_nominal_speed(result, tmp_path: Path) -> None:
    path = result.write(tmp_path / "s60.json", nominal_speed_kmh=60.0)
    doc = read_json(path, "the schedule file")
    assert read_filter_file(path).speeds_kmh == (30.0, 60.0, 90.0) and doc["speed_kmh"] == 60.0
    assert doc["plant"]["omega_n_rad_s"] == result.entries[1].fit.lag.omega_n_rad_s


@pytest.mark.parametrize("speed", [50.0, 59.9, 0.0, float("nan")])
def test_a_nominal_speed_not_identified_is_refused_naming_the_speeds(result, tmp_path: Path, speed: float) -> None:
    with pytest.raises(WorkbenchInputError, match=r"is not a speed of the schedule; .* one of the speeds identified: "
                       r"30, 60, 90 km/h"):  # fmt: skip
        result.write(tmp_path / "s.json", nominal_speed_kmh=speed)
    assert not (tmp_path / "s.json").exists()


def test_identification_amplitude_gives_the_asked_lateral_acceleration(truck) -> None:
    # 0.1 g at 60 km/h: kappa = 0.981 / 16.67^2 = 0.00353 1/m; Ackermann x steering ratio 22.
    assert steer_amplitude_deg(truck, 60.0, 0.1) == pytest.approx(25.1, abs=0.1)
    with pytest.raises(WorkbenchInputError, match="speeds must increase strictly"):
        identify_schedule(truck, [60.0, 30.0])


@pytest.fixture(scope="module")
def margins_result(truck):
    return identify_schedule(truck, [30.0, 60.0], fit_options=LagFitOptions(fit_delay=True), design="margins")


def test_the_margins_design_records_both_lags_and_the_floors(margins_result, tmp_path: Path) -> None:
    """Measured on the loaded truck: path lag (omega_n, zeta, delay) 34.5 / 2.0 / 0.25 s at 30 km/h, 8.2 / 2.0 /
    0.18 s at 60 km/h (zeta at its bound: a first-order lag behind a delay); measured (yaw-rate) lag 10.0 / 0.93 /
    0.064 s and 13.1 / 2.0 / 0.073 s; floors with the lead 8.5 m and 17.5 m, none up to 40 m without one."""
    result = margins_result
    assert result.design == "margins" and result.fit_delay and not result.dropped
    for e in result.entries:
        path, measured = e.fit.lag, e.measured_fit.lag
        assert 0.1 < path.delay_s < 0.3 and path.zeta <= DELAY_FIT_MAX_ZETA
        assert measured.delay_s < path.delay_s  # the yaw rate leads the path curvature
        assert e.design.method == "margins" and e.design.lead_peak_gain <= 6.0 * (1 + 1e-6)
        assert e.margins is not None and 3.0 <= e.margins.floor_m <= 40.0
        assert not e.margins.floor_without_lead_m <= e.margins.floor_m  # nan (none) or longer
    floors = [e.margins.floor_m for e in result.entries]
    assert floors == pytest.approx([8.5, 17.5], abs=1.0)
    path = result.write(tmp_path / "lead.json")
    read_filter_file(path)
    design = read_json(path, "the schedule file")["design"]
    assert design["method"] == "margins" and "max_cascade_peak_db" not in design
    assert design["controller_rate_hz"] == 50.0 and design["prediction_time_s"] == 0.2
    assert (design["phase_margin_deg"], design["gain_margin_db"]) == (45.0, 6.0)  # the floors' margins
    assert design["maneuvers"] == ["dlc", "step-series", "chirp"]
    for row, e in zip(design["per_speed"], result.entries, strict=True):
        assert row["measured_omega_n_rad_s"] == e.measured_fit.lag.omega_n_rad_s
        assert row["measured_delay_s"] == e.measured_fit.lag.delay_s
        assert row["lookahead_floor_m"] == e.margins.floor_m
        assert "floor_without_lead_m" not in row  # none up to 40 m: left out
    assert "floor" in result.table().splitlines()[0]


def test_design_and_loop_options_are_checked(truck) -> None:
    with pytest.raises(WorkbenchInputError, match="design must be one of cancel, margins"):
        identify_schedule(truck, [30.0], design="loop")
    with pytest.raises(WorkbenchInputError, match="controller_rate_hz must be a finite number in"):
        identify_schedule(truck, [30.0], design="margins", controller_rate_hz=0.0)
