"""The vehicle-log format: validation of columns, values and sampling."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from synthetic_logs import synthetic_frame

from tuning.log_file import LOG_COLUMNS, VehicleLog, read_log
from workbench.base.errors import WorkbenchInputError


def frame() -> pd.DataFrame:
    return synthetic_frame("dlc", 4.0, 0.8, duration_s=8.0)


def test_a_generated_log_reads_back_in_si_units(tmp_path: Path) -> None:
    df = frame()
    df.to_csv(tmp_path / "log.csv", index=False)
    log = read_log(tmp_path / "log.csv")
    assert tuple(df.columns) == LOG_COLUMNS
    assert log.dt_s == pytest.approx(0.01, rel=1e-9)
    assert not log.resampled
    np.testing.assert_allclose(log.steer_wheel_rad, np.radians(df["steer_wheel_deg"]), rtol=1e-12)
    assert log.has_positions and log.has_yaw_rate


def test_column_names_are_case_insensitive_and_yaw_rate_alone_suffices() -> None:
    df = frame().drop(columns=["x_m", "y_m", "yaw_rad"]).rename(columns=str.upper)
    log = VehicleLog.from_frame(df, "upper")
    assert not log.has_positions and log.has_yaw_rate


@pytest.mark.parametrize(
    ("drop", "needle"),
    [
        (["steer_wheel_deg"], "missing column(s) steer_wheel_deg"),
        (["x_m", "yaw_rate_rad_s"], "x_m and y_m, or yaw_rate_rad_s"),
        (["t_s", "speed_mps"], "missing column(s) t_s, speed_mps"),
    ],
)
def test_missing_columns_are_named(drop: list[str], needle: str) -> None:
    with pytest.raises(WorkbenchInputError) as info:
        VehicleLog.from_frame(frame().drop(columns=drop), "log.csv")
    assert needle in str(info.value) and "log.csv" in str(info.value)


@pytest.mark.parametrize("bad", [np.nan, np.inf, "n/a"])
def test_nan_inf_and_text_are_refused_naming_column_and_row(bad: object) -> None:
    df = frame().astype(object)
    df.loc[7, "speed_mps"] = bad
    with pytest.raises(WorkbenchInputError, match=r"column speed_mps row 8 is .*finite number"):
        VehicleLog.from_frame(df, "log.csv")


def test_time_must_increase_and_gaps_are_refused() -> None:
    df = frame()
    df.loc[10, "t_s"] = df.loc[9, "t_s"]
    with pytest.raises(WorkbenchInputError, match="t_s must increase strictly; row 11"):
        VehicleLog.from_frame(df, "log.csv")
    with pytest.raises(WorkbenchInputError, match=r"a gap of 0\.51 s"):
        VehicleLog.from_frame(frame().drop(index=range(100, 150)), "log.csv")
    with pytest.raises(WorkbenchInputError, match="at least 5 Hz"):
        VehicleLog.from_frame(frame().iloc[::50], "log.csv")


def test_jittered_sampling_is_resampled_onto_a_uniform_grid() -> None:
    df = frame()
    rng = np.random.default_rng(1)
    df["t_s"] += rng.uniform(-0.002, 0.002, len(df))
    log = VehicleLog.from_frame(df, "jitter")
    assert log.resampled
    np.testing.assert_allclose(np.diff(log.t_s), log.dt_s, rtol=1e-9)
    assert log.duration_s <= df["t_s"].iloc[-1] - df["t_s"].iloc[0]


def test_unreadable_and_absent_files(tmp_path: Path) -> None:
    with pytest.raises(WorkbenchInputError, match="does not exist"):
        read_log(tmp_path / "none.csv")
    (tmp_path / "empty.csv").write_text("")
    with pytest.raises(WorkbenchInputError, match="not a readable CSV"):
        read_log(tmp_path / "empty.csv")
    (tmp_path / "one.csv").write_text("t_s,steer_wheel_deg,speed_mps,yaw_rate_rad_s\n0,1,10,0\n")
    with pytest.raises(WorkbenchInputError, match="1 row"):
        read_log(tmp_path / "one.csv")


@pytest.mark.parametrize(
    ("header", "column"),
    [
        ("t_s,steer_wheel_deg,speed_mps,yaw_rate_rad_s,speed_mps", "speed_mps"),  # read as speed_mps.1
        ("t_s,steer_wheel_deg,speed_mps,yaw_rate_rad_s,SPEED_MPS", "speed_mps"),  # names are case-insensitive
        ("t_s,steer_wheel_deg,speed_mps,yaw_rate_rad_s, Speed_mps ", "speed_mps"),  # and stripped
        ("t_s,steer_wheel_deg,speed_mps,yaw_rate_rad_s,note,note", "note"),  # an ignored column too: ambiguous
    ],
)
def test_a_column_named_twice_is_refused_naming_it(tmp_path: Path, header: str, column: str) -> None:
    rows = "".join(f"{0.01 * i:.2f},{i % 7},10,0.1,10,{i}\n" for i in range(300))
    (tmp_path / "twice.csv").write_text(header + "\n" + rows)
    with pytest.raises(WorkbenchInputError, match=rf"twice\.csv: column '{column}' appears 2 times"):
        read_log(tmp_path / "twice.csv")


def test_a_column_named_like_a_repeat_of_no_column_is_kept(tmp_path: Path) -> None:
    rows = "".join(f"{0.01 * i:.2f},{i % 7},10,0.1,{i}\n" for i in range(300))
    (tmp_path / "dotted.csv").write_text("t_s,steer_wheel_deg,speed_mps,yaw_rate_rad_s,gps.1\n" + rows)
    assert len(read_log(tmp_path / "dotted.csv")) == 300
