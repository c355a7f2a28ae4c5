"""tuning generate-data: maneuver shapes and the open-loop log against the kinematic bicycle's analytic response."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from tuning.cli import main
from tuning.data_generation import LOG_COLUMNS, generate_open_loop_log
from tuning.maneuvers import Maneuver
from workbench.errors import WorkbenchInputError
from workbench.vehicles import KinematicBicycle


def test_step_series_alternates_and_dlc_returns_to_zero() -> None:
    t = np.arange(0, 20, 0.01)
    series = Maneuver("step-series", amplitude_deg=45.0, start_s=1.0, hold_s=2.0).steer_wheel_rad(t)
    a = math.radians(45.0)
    assert series[t < 1.0].max() == 0.0
    assert series[(t > 1.5) & (t < 2.5)] == pytest.approx(a)
    assert series[(t > 5.5) & (t < 6.5)] == pytest.approx(-a)
    dlc = Maneuver("dlc", amplitude_deg=60.0, start_s=1.0, period_s=4.0, hold_s=2.0).steer_wheel_rad(t)
    assert np.max(dlc) == pytest.approx(math.radians(60.0), rel=1e-3)
    assert np.min(dlc) == pytest.approx(-math.radians(60.0), rel=1e-3)
    assert np.sum(dlc) * 0.01 == pytest.approx(0.0, abs=1e-9)  # the two periods cancel
    assert dlc[t > 11.5].max() == 0.0


def test_open_loop_step_gives_the_kinematic_curvature() -> None:
    vehicle = KinematicBicycle()
    log = generate_open_loop_log(vehicle, Maneuver("step", amplitude_deg=90.0, start_s=0.5, duration_s=8.0), 30.0)
    assert tuple(log.columns) == LOG_COLUMNS
    assert log["speed_mps"].to_numpy() == pytest.approx(30 / 3.6, rel=1e-6)
    late = log["t_s"] > 5.0
    curvature = log["yaw_rate_rad_s"][late] / log["speed_mps"][late]
    p = vehicle.params
    expected = math.tan(math.radians(90.0) / p.steering_ratio) / p.wheelbase_m  # tan(phi) = L kappa
    assert curvature.to_numpy() == pytest.approx(expected, rel=1e-6)


def test_cli_writes_the_log(tmp_path: Path) -> None:
    out = tmp_path / "step.csv"
    assert main(["generate-data", "--vehicle", "kinematic-bicycle", "--maneuver", "dlc", "--speed", "30",
                 "--out", str(out)]) == 0  # fmt: skip
    log = pd.read_csv(out)
    assert tuple(log.columns) == LOG_COLUMNS
    assert len(log) == 2001
    assert np.isfinite(log.to_numpy()).all()


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["--vehicle", "zeppelin", "--maneuver", "step", "--speed", "30"], "unknown vehicle 'zeppelin'"),
        (["--vehicle", "kinematic-bicycle", "--maneuver", "step", "--speed", "0"], "speed_kmh"),
        (["--vehicle", "kinematic-bicycle", "--maneuver", "step", "--speed", "30", "--amplitude-deg", "0"], "non-zero"),
    ],
)
def test_bad_input_exits_2(args: list[str], needle: str, tmp_path: Path, capsys) -> None:
    assert main(["generate-data", *args, "--out", str(tmp_path / "x.csv")]) == 2
    assert needle in capsys.readouterr().err


def test_unknown_maneuver_is_rejected() -> None:
    with pytest.raises(WorkbenchInputError, match="unknown maneuver 'slalom'"):
        Maneuver("slalom")
