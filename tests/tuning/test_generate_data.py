"""tuning generate-data: maneuver shapes and the open-loop log against the kinematic bicycle's analytic response."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from tuning.cli import main
from tuning.data_generation import LOG_COLUMNS, MAX_LOG_SAMPLES, MAX_PLANT_STEPS, check_log_size, generate_open_loop_log
from tuning.maneuvers import Maneuver
from workbench.base.errors import WorkbenchInputError
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


def test_chirp_sweeps_from_start_to_end_frequency_at_the_amplitude() -> None:
    m = Maneuver("chirp", amplitude_deg=30.0, start_s=1.0, duration_s=21.0, start_hz=0.1, end_hz=2.0)
    t = np.arange(0.0, 21.0, 0.001)
    sw = m.steer_wheel_rad(t)
    assert sw[t < 1.0].max() == 0.0 and sw[0] == 0.0
    assert np.max(np.abs(sw)) == pytest.approx(math.radians(30.0), rel=1e-3)
    # the periods between rising zero crossings are those of the frequency at their middle (6.3 s, then down to
    # 0.53 s; 2 Hz is reached at the end)
    rising = t[1:][(sw[:-1] < 0.0) & (sw[1:] >= 0.0)]
    middles = 0.5 * (rising[1:] + rising[:-1])
    np.testing.assert_allclose(np.diff(rising), 1.0 / m.chirp_frequency_hz(middles), rtol=0.03)
    assert m.chirp_frequency_hz(np.array([1.0, 11.0, 21.0])) == pytest.approx([0.1, 0.1 * 20**0.5, 2.0])
    # about 12 cycles in all: (f1 - f0) T / ln(f1 / f0)
    assert rising.size == pytest.approx(1.9 * 20.0 / math.log(20.0), abs=1.5)


def test_a_rate_limit_turns_steps_into_ramps_and_lowers_the_chirp_at_high_frequency() -> None:
    t = np.arange(0.0, 20.0, 0.001)
    step = Maneuver("step", amplitude_deg=90.0, start_s=1.0, max_rate_deg_s=45.0).steer_wheel_rad(t)
    rate = np.degrees(np.diff(step)) / 0.001
    assert rate.max() == pytest.approx(45.0, rel=1e-3)
    assert step[t >= 3.05] == pytest.approx(math.radians(90.0))  # the 2 s ramp is done
    assert step[np.searchsorted(t, 2.0)] == pytest.approx(math.radians(45.0), rel=0.01)
    chirp = Maneuver("chirp", amplitude_deg=90.0, max_rate_deg_s=180.0)
    sw = chirp.steer_wheel_rad(t)
    assert np.max(np.abs(np.degrees(np.diff(sw)) / 0.001)) <= 180.0 * 1.001
    early, late = np.abs(sw[t < 6.0]).max(), np.abs(sw[t > 17.0]).max()
    assert math.degrees(early) == pytest.approx(90.0, rel=1e-3)  # 0.1-0.3 Hz: 90 deg x 2 pi f under 180 deg/s
    # capped at 180 / (2 pi f), largest at the window's lowest frequency, 1.25 Hz
    assert math.degrees(late) == pytest.approx(180.0 / (2 * math.pi * chirp.chirp_frequency_hz(17.0)), rel=0.01)


def test_the_chirp_is_checked() -> None:
    with pytest.raises(WorkbenchInputError, match="end_hz must be a finite number in"):
        Maneuver("chirp", start_hz=2.0, end_hz=1.0)
    with pytest.raises(WorkbenchInputError, match="a chirp needs duration_s > start_s"):
        Maneuver("chirp", start_s=5.0, duration_s=5.0)
    with pytest.raises(WorkbenchInputError, match="max_rate_deg_s must be"):
        Maneuver("dlc", max_rate_deg_s=0.0)


def test_the_steering_between_samples_is_the_profiles() -> None:
    """The plant is driven with the profile at each 1 ms plant step, not with the logged sample held: the
    kinematic bicycle's yaw rate after a ramp is the same whatever the log's sample rate."""
    vehicle = KinematicBicycle()
    maneuver = Maneuver("chirp", amplitude_deg=20.0, duration_s=6.0, end_hz=1.0)
    fine = generate_open_loop_log(vehicle, maneuver, 30.0, sample_rate_hz=100.0)
    coarse = generate_open_loop_log(vehicle, maneuver, 30.0, sample_rate_hz=10.0)
    np.testing.assert_allclose(coarse["yaw_rate_rad_s"].to_numpy(), fine["yaw_rate_rad_s"].to_numpy()[::10], atol=1e-4)


def test_cli_writes_a_chirp(tmp_path: Path) -> None:
    out = tmp_path / "chirp.csv"
    argv = ["generate-data", "--vehicle", "kinematic-bicycle", "--maneuver", "chirp", "--speed", "30",
            "--lat-accel-g", "0.1", "--chirp-hz", "0.2:1.5", "--max-rate-deg-s", "100", "--out", str(out)]  # fmt: skip
    assert main(argv) == 0
    log = pd.read_csv(out)
    assert np.max(np.abs(np.diff(log["steer_wheel_deg"]))) / 0.01 <= 100.0 * 1.01
    assert main([*argv[:-2], "--chirp-hz", "fast", "--out", str(out)]) == 2


def test_the_log_size_is_bounded_at_its_stated_limits() -> None:
    # 100 Hz with the plant at 1 kHz: 10 plant steps a sample, so the plant steps bind first: 1e6 samples, 9999.99 s
    check_log_size(9999.99, 100.0)
    with pytest.raises(WorkbenchInputError, match=r"1,000,001 log samples and 10,000,010 plant steps"):
        check_log_size(10_000.0, 100.0)
    # at 1 kHz and above one plant step a sample: the samples bind
    check_log_size((MAX_LOG_SAMPLES - 1) / 1000.0, 1000.0)
    with pytest.raises(WorkbenchInputError, match=f"at most {MAX_LOG_SAMPLES:,} samples and {MAX_PLANT_STEPS:,}"):
        check_log_size(MAX_LOG_SAMPLES / 1000.0, 1000.0)


def test_a_huge_duration_is_refused_before_anything_is_allocated(monkeypatch) -> None:
    monkeypatch.setattr(np, "arange", lambda *a, **k: pytest.fail("allocated before the size was checked"))
    maneuver = Maneuver("step", duration_s=1e9)
    with pytest.raises(WorkbenchInputError, match=r"duration_s 1000000000.0 s at sample_rate_hz 100.0 Hz plans "
                       r"100,000,000,001 log samples"):  # fmt: skip
        generate_open_loop_log(KinematicBicycle(), maneuver, 30.0)


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["--duration-s", "1e9"], "--duration-s 1000000000.0 s at --sample-rate-hz 100.0 Hz plans 100,000,000,001 log "
         "samples and 1,000,000,000,010 plant steps at 1000 Hz (about 1.36e+04 GB); at most 2,000,000 samples and "
         "10,000,000 plant steps, 9,999.99 s at this rate: give a shorter --duration-s or a lower --sample-rate-hz"),
        (["--duration-s", "100", "--sample-rate-hz", "1e5"],
         "--sample-rate-hz must be a finite number in [1, 10000] Hz; got 100000.0"),
        (["--duration-s", "inf"], "--duration-s must be a finite number > 0; got inf"),
        (["--duration-s", "1e308"], "--duration-s 1e+308 s at --sample-rate-hz 100.0 Hz plans over 1e+308 log samples "
         "and over 1e+308 plant steps at 1000 Hz (beyond any memory); at most 2,000,000 samples"),
        (["--duration-s", "1e-300"], "--duration-s 1e-300 s at --sample-rate-hz 100.0 Hz gives 1 log sample; a log "
         "needs at least 2: --duration-s at least 0.01 s"),
        (["--duration-s", "-1"], "--duration-s must be a finite number > 0; got -1.0"),
    ],
)  # fmt: skip
def test_cli_refuses_a_log_too_long_naming_the_options(args: list[str], needle: str, tmp_path: Path, capsys) -> None:
    argv = ["generate-data", "--vehicle", "kinematic-bicycle", "--maneuver", "step", "--speed", "30", *args]
    assert main([*argv, "--out", str(tmp_path / "x.csv")]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"tuning: error: {needle}") and err.count("\n") == 1
    assert not (tmp_path / "x.csv").exists()
