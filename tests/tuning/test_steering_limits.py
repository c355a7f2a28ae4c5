"""steering-limits (the curvature limits of a vehicle without a roll model) and schedule's --delay and
--drop-refused, through the tuning CLI."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

import tuning.schedule
from controllers.clothoid.curvature_limits import CurvatureLimits
from tuning.cli import main
from tuning.limits_file import read_limits_file
from tuning.steering_limits import steering_limits
from workbench.base.errors import WorkbenchInputError
from workbench.vehicles import make_vehicle


def test_the_limits_are_the_controllers_default_rule_at_the_speeds_asked() -> None:
    car = make_vehicle("dynamic-bicycle")
    default = CurvatureLimits.default_for(car.geometry)
    speeds = [10.0, 20.0, 50.0, 150.0]
    limits = steering_limits(car.geometry, speeds)
    for lim in limits:
        kappa, rate = default.at_speed(lim.speed_kmh / 3.6)
        assert (lim.max_curvature_1pm, lim.max_curvature_rate_1pm_s) == pytest.approx((kappa, rate), rel=1e-12)
        assert lim.limited_by == "lateral acceleration" and lim.lateral_accel_g == pytest.approx(0.4)
    truck = make_vehicle("tractor-semitrailer")  # its lock (0.107 1/m) limits below 22 km/h at 0.4 g
    assert [lim.limited_by for lim in steering_limits(truck.geometry, [10.0, 30.0])] == [
        "steering lock",
        "lateral acceleration",
    ]
    with pytest.raises(WorkbenchInputError, match="max_lateral_accel_g must be a finite number in"):
        steering_limits(car.geometry, speeds, 0.0)


def test_the_cli_writes_the_limits_file(tmp_path: Path, capsys) -> None:
    out = tmp_path / "limits.csv"
    argv = ["steering-limits", "--vehicle", "kinematic-bicycle", "--speeds", "10,20,...,150", "--lat-accel-g", "0.3"]
    assert main([*argv, "--out", str(out)]) == 0
    limits = read_limits_file(out)
    assert limits.speeds_kmh == tuple(float(s) for s in range(10, 151, 10))
    assert limits.max_curvature_1pm[2] == pytest.approx(0.3 * 9.80665 / (30 / 3.6) ** 2)
    assert "lateral acceleration" in capsys.readouterr().out


def test_the_schedule_fits_a_delay_and_drops_a_refused_speed(tmp_path: Path, capsys, monkeypatch) -> None:
    # A fit refused at 10 km/h (as the kinematic bicycle's was, its rate limit making it look first-order, before
    # the identification maneuvers kept to half the rate limit): dropped, named, the other speed kept. At 40 km/h
    # the car is a fast lag (its 0.05 s actuator) behind no delay to speak of.
    real_fit_lag = tuning.schedule.fit_lag

    def refusing_at_10_kmh(logs, geometry, options):
        if logs[0].speed_mps.mean() < 5.0:
            raise WorkbenchInputError("the fit ran to the bound of zeta (a test's refusal)")
        return real_fit_lag(logs, geometry, options)

    monkeypatch.setattr(tuning.schedule, "fit_lag", refusing_at_10_kmh)
    out = tmp_path / "lead.json"
    argv = ["schedule", "--vehicle", "kinematic-bicycle", "--speeds", "10,40", "--delay", "--drop-refused"]
    assert main([*argv, "--out", str(out)]) == 0
    design = json.loads(out.read_text())["design"]
    assert design["fit_delay"] is True and design["method"] == "cancel"
    (row,) = design["per_speed"]
    assert row["speed_kmh"] == 40.0 and 0.0 <= row["delay_s"] < 0.01 and row["zeta"] <= 2.0
    assert 0.0 <= row["measured_delay_s"] < 0.01
    (dropped,) = design["dropped_speeds"]
    assert dropped["speed_kmh"] == 10.0 and "bound of zeta" in dropped["reason"]
    assert "10 km/h: dropped: the fit ran to the bound of zeta" in capsys.readouterr().err
    # without --drop-refused the refusal refuses the schedule, naming the speed
    assert main(["schedule", "--vehicle", "kinematic-bicycle", "--speeds", "10", "--out", str(out), "--overwrite"]) == 2
    assert "at 10 km/h: the fit ran to the bound of zeta" in capsys.readouterr().err
