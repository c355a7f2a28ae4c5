"""The tuning CLI end to end: generate-data -> fit-lag -> design-lead, rollover-limits, schedule; and bad input
(exit code 2 with one line naming the problem)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from tuning.cli import main
from tuning.filter_file import read_filter_file
from tuning.limits_file import read_limits_file
from workbench.base.input_files import read_toml
from workbench.vehicles import make_vehicle
from workbench.vehicles.steering_lag import read_lag_file

TRUCK = ["--vehicle", "tractor-semitrailer"]


@pytest.fixture(scope="module")
def logs(tmp_path_factory) -> dict[str, Path]:
    folder = tmp_path_factory.mktemp("logs")
    out = {}
    for kind in ("dlc", "step-series"):
        out[kind] = folder / f"{kind}.csv"
        args = ["generate-data", *TRUCK, "--maneuver", kind, "--speed", "30", "--lat-accel-g", "0.1"]
        assert main([*args, "--out", str(out[kind])]) == 0
    return out


@pytest.fixture(scope="module")
def lag_file(logs, tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("fit")
    argv = ["fit-lag", str(logs["dlc"]), str(logs["step-series"]), *TRUCK, "--out", str(folder / "lag.json")]
    assert main([*argv, "--plot", str(folder / "fig8.png")]) == 0
    assert (folder / "fig8.png").stat().st_size > 10_000
    return folder / "lag.json"


def test_generate_data_sizes_the_steering_for_a_lateral_acceleration(logs) -> None:
    log = pd.read_csv(logs["dlc"])
    # 0.1 g at 30 km/h: kappa = 0.981 / 8.33^2 = 0.0141 1/m -> 100.1 deg of steering wheel on the truck
    assert np.abs(log["steer_wheel_deg"]).max() == pytest.approx(100.1, abs=0.2)


def test_fit_lag_writes_the_steering_lag_file(lag_file) -> None:
    lag = read_lag_file(lag_file)
    assert lag.omega_n_rad_s == pytest.approx(4.29, rel=0.03)
    assert lag.zeta == pytest.approx(0.78, rel=0.03)
    assert lag.nrmse < 0.03
    assert lag.speed_range_mps == pytest.approx((30 / 3.6, 30 / 3.6), rel=1e-3)
    assert "curvature from path" in lag.source


def test_design_lead_writes_a_filter_file_the_controller_reads(lag_file, logs, tmp_path: Path, capsys) -> None:
    out = tmp_path / "lead.toml"
    argv = ["design-lead", "--lag", str(lag_file), "--out", str(out), "--plot", str(tmp_path / "fig10.png")]
    assert main([*argv, "--validate", str(logs["dlc"]), *TRUCK]) == 0
    schedule = read_filter_file(out)
    lag = read_lag_file(lag_file)
    (params,) = schedule.params
    assert params.dc_gain == pytest.approx(1.0, abs=1e-12)
    assert (params.omega_z_rad_s, params.psi) == pytest.approx((lag.omega_n_rad_s, lag.zeta))
    doc = read_toml(out, "the lead filter file")
    design = doc["design"]
    # The default bound of 6 on the peak gain: x2.2 the -3 dB bandwidth for the truck's lag at 30 km/h.
    assert design["lead_peak_gain"] == pytest.approx(6.0, rel=1e-6)
    assert design["cascade_bandwidth_rad_s"] >= 2 * design["plant_bandwidth_rad_s"]
    # Figure 9 on the dlc log: NRMSE against the kinematic curvature 0.120 lagged, 0.060 compensated.
    assert design["validation"][0]["nrmse_compensated"] < 0.55 * design["validation"][0]["nrmse_lagged"]
    assert doc["plant"] == {"omega_n_rad_s": lag.omega_n_rad_s, "zeta": lag.zeta}
    assert doc["speed_kmh"] == pytest.approx(30.0, rel=1e-3)
    assert (tmp_path / "fig10.png").stat().st_size > 10_000
    assert (tmp_path / "lead_validation.png").stat().st_size > 10_000
    assert "-3 dB bandwidth" in capsys.readouterr().out


def test_design_lead_json_and_a_real_vehicle_by_its_wheelbase(lag_file, logs, tmp_path: Path) -> None:
    out = tmp_path / "lead.json"
    geometry = make_vehicle("tractor-semitrailer").geometry
    argv = ["design-lead", "--lag", str(lag_file), "--out", str(out), "--format", "json", "--max-lead-gain", "5"]
    argv += ["--validate", str(logs["step-series"]), "--validate-plot", str(tmp_path / "fig9.png")]
    argv += ["--wheelbase-m", str(geometry.wheelbase_m), "--steering-ratio", str(geometry.steering_ratio)]
    assert main(argv) == 0
    doc = json.loads(out.read_text())
    assert doc["format"] == "lead-filter/1" and doc["dc_gain"] == 1.0
    assert doc["design"]["lead_peak_gain"] == pytest.approx(5.0, rel=1e-6)
    assert (tmp_path / "fig9.png").exists()


def test_rollover_limits_writes_the_limits_csv(tmp_path: Path, capsys) -> None:
    out = tmp_path / "limits.csv"
    argv = [
        "rollover-limits",
        *TRUCK,
        "--speeds",
        "20,40,...,80",
        "--out",
        str(out),
        "--plot",
        str(tmp_path / "f6.png"),
    ]
    assert main(argv) == 0
    limits = read_limits_file(out)
    assert limits.speeds_kmh == (20.0, 40.0, 60.0, 80.0)
    assert list(limits.max_curvature_1pm) == sorted(limits.max_curvature_1pm, reverse=True)
    assert "steering lock" in capsys.readouterr().out
    assert (tmp_path / "f6.png").exists()


def test_schedule_writes_a_scheduled_filter_file_and_compares_in_closed_loop(tmp_path: Path, capsys) -> None:
    out = tmp_path / "schedule.toml"
    argv = ["schedule", *TRUCK, "--speeds", "30,60", "--out", str(out), "--plot", str(tmp_path / "s.png")]
    assert main([*argv, "--nominal-speed", "30", "--compare", "60"]) == 0
    schedule = read_filter_file(out)
    assert schedule.speeds_kmh == (30.0, 60.0)
    assert schedule.params[1].omega_z_rad_s < schedule.params[0].omega_z_rad_s
    assert read_toml(out, "the schedule file")["speed_kmh"] == 30.0
    assert (tmp_path / "s.png").exists()
    table = capsys.readouterr().out
    for label in ("scheduled", "fixed 30 km/h", "no filter"):
        assert f"60.0  {label}" in table
    assert "60 km/h: max |CTE| scheduled " in table and ", fixed 30 km/h " in table


def test_schedule_designs_for_the_margins_from_both_lags(tmp_path: Path, capsys) -> None:
    """--design margins --delay (what the presets are made with): per speed the path and the measured lag and the
    lookahead floors with and without the lead; the loop options recorded. (The kinematic bicycle at 40 km/h:
    a 0.05 s first-order actuator, the same lag to both curvatures; floors 3 m with the lead, 5.5 m without.)"""
    out = tmp_path / "lead.json"
    argv = ["schedule", "--vehicle", "kinematic-bicycle", "--speeds", "40", "--delay", "--design", "margins"]
    argv += ["--controller-rate-hz", "50", "--prediction-time-s", "0.2", "--preview-past-s", "3"]
    argv += ["--preview-lat-accel-g", "0.15", "--out", str(out)]
    assert main(argv) == 0
    design = json.loads(out.read_text())["design"]
    assert design["preview_fit"]["past_s"] == 3.0 and design["preview_fit"]["future_s"] == 2.0
    assert design["preview_fit"]["lat_accel_g"] == 0.15 and design["lat_accel_g"] == 0.1  # the lags' stays
    assert design["method"] == "margins" and design["fit_delay"] is True
    assert (design["controller_rate_hz"], design["prediction_time_s"]) == (50.0, 0.2)
    (row,) = design["per_speed"]
    assert row["preview_first_tap_s"] == -3.0 and len(row["preview_steering_taps"]) == 101  # -3 s to 2 s by 0.05 s
    assert sum(row["preview_steering_taps"]) == pytest.approx(1.0, abs=0.01)  # a kinematic bicycle: no understeer
    assert row["measured_omega_n_rad_s"] == pytest.approx(row["omega_n_rad_s"], rel=0.02)
    assert row["lookahead_floor_m"] == pytest.approx(3.0) and row["floor_without_lead_m"] == pytest.approx(5.5)
    captured = capsys.readouterr()
    assert "floor_m  floor_no_lead_m" in captured.out
    assert "lookahead floor 3 m with the lead, 5.5 m without" in captured.err
    with pytest.raises(SystemExit) as info:  # argparse: invalid choice
        main([*argv[:-2], "--design", "loop", "--out", str(out)])
    assert info.value.code == 2
    assert main([*argv[:-2], "--preview-past-s", "31", "--out", str(out), "--overwrite"]) == 2
    assert "--preview-past-s must be a finite number in [0, 30] s; got 31" in capsys.readouterr().err
    assert main([*argv[:-2], "--preview-lat-accel-g", "nan", "--out", str(out), "--overwrite"]) == 2
    assert "--preview-lat-accel-g must be a finite number in [0.001, 1] g; got nan" in capsys.readouterr().err


# --- bad input ------------------------------------------------------------------------------------------------


def write(tmp_path: Path, frame: pd.DataFrame, name: str = "bad.csv") -> str:
    frame.to_csv(tmp_path / name, index=False)
    return str(tmp_path / name)


@pytest.mark.parametrize(
    ("edit", "needle"),
    [
        (lambda f: f.drop(columns=["steer_wheel_deg"]), "bad.csv: missing column(s) steer_wheel_deg"),
        (lambda f: f.drop(columns=["x_m", "yaw_rate_rad_s"]), "x_m and y_m, or yaw_rate_rad_s"),
        (lambda f: f.assign(steer_wheel_deg=12.0), "the steering wheel hardly moves"),
        (lambda f: f.assign(speed_mps=np.where(f.index == 40, math.nan, f["speed_mps"])), "column speed_mps row 41"),
        (lambda f: f.iloc[:150], "too short to identify a lag"),
        (lambda f: f.assign(speed_mps=np.linspace(5.0, 10.0, len(f))), "speed varies over the log from 5 to 10 m/s"),
        (lambda f: pd.concat([f, 2.0 * f[["speed_mps"]]], axis=1), "bad.csv: column 'speed_mps' appears 2 times"),
    ],
)
def test_fit_lag_refuses_bad_logs(logs, tmp_path: Path, capsys, edit, needle: str) -> None:
    path = write(tmp_path, edit(pd.read_csv(logs["dlc"])))
    assert main(["fit-lag", path, *TRUCK, "--out", str(tmp_path / "lag.json")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("tuning: error: ") and needle in err and err.count("\n") == 1
    assert not (tmp_path / "lag.json").exists()


@pytest.mark.parametrize(
    ("argv", "needle"),
    [
        (["fit-lag", "{dlc}", "--vehicle", "zeppelin", "--out", "{tmp}/l.json"], "unknown vehicle 'zeppelin'"),
        (["fit-lag", "{dlc}", "--out", "{tmp}/l.json"], "the kinematic curvature needs the vehicle"),
        (["fit-lag", "{dlc}", "--wheelbase-m", "5", "--out", "{tmp}/l.json"], "go together; give both"),
        (["fit-lag", "{tmp}/none.csv", *TRUCK, "--out", "{tmp}/l.json"], "vehicle log '{tmp}/none.csv': no such file"),
        (["design-lead", "--lag", "{tmp}/none.json", "--out", "{tmp}/f.json"], "steering-lag file"),
        (["design-lead", "--lag", "{lag}", "--out", "{tmp}/f.json", "--format", "toml"], "must end in .toml"),
        (["design-lead", "--lag", "{lag}", "--out", "{tmp}/f.yaml"], "must end in .json or .toml"),
        (["design-lead", "--lag", "{lag}", "--out", "{tmp}/f.json", "--max-lead-gain", "0.5"], "max_lead_gain"),
        (["design-lead", "--lag", "{lag}", "--out", "{tmp}/f.json", "--validate", "{dlc}"], "needs the vehicle"),
        (["rollover-limits", "--vehicle", "zeppelin", "--speeds", "40", "--out", "{tmp}/r.csv"], "unknown vehicle"),
        (["rollover-limits", "--vehicle", "kinematic-bicycle", "--speeds", "40", "--out", "{tmp}/r.csv"], "no 'ltr'"),
        (["rollover-limits", *TRUCK, "--speeds", "40,30", "--out", "{tmp}/r.csv"], "increase strictly"),
        (["schedule", "--vehicle", "zeppelin", "--speeds", "30", "--out", "{tmp}/s.json"], "unknown vehicle"),
        (["schedule", *TRUCK, "--speeds", "30,abc", "--out", "{tmp}/s.json"], "'abc' is not a number"),
        (["schedule", *TRUCK, "--speeds", "40", "--out", "{tmp}/s.json", "--compare", "60"], "--compare needs"),
        (["schedule", *TRUCK, "--speeds", "30", "--out", "{tmp}/s.json", "--nominal-speed", "50"],
         "--nominal-speed 50 km/h is not one of the --speeds (30 km/h)"),
        (["schedule", *TRUCK, "--speeds", "30,60", "--out", "{tmp}/s.json", "--nominal-speed", "50", "--compare", "60"],
         "--nominal-speed 50 km/h is not one of the --speeds (30, 60 km/h)"),
        (["generate-data", "--maneuver", "dlc", "--speed", "30", "--out", "{tmp}/g.csv"], "give --vehicle NAME"),
        (["generate-data", *TRUCK, "--maneuver", "dlc", "--speed", "30", "--lat-accel-g", "2", "--out", "{tmp}/g.csv"],
         "--lat-accel-g must be in (0, 1] g"),
    ],
)  # fmt: skip
def test_bad_input_exits_2_naming_the_problem(logs, lag_file, tmp_path: Path, capsys, argv, needle: str) -> None:
    fields = {"dlc": logs["dlc"], "lag": lag_file, "tmp": tmp_path}
    assert main([a.format(**fields) for a in argv]) == 2
    err = capsys.readouterr().err
    assert err.startswith("tuning: error: ") and needle.format(**fields) in err


GENERATE = ["generate-data", "--vehicle", "kinematic-bicycle", "--maneuver", "step", "--speed", "30"]


@pytest.mark.parametrize(
    ("argv", "needle"),
    [
        ([*GENERATE, "--out", "{tmp}"], "--out '{tmp}' is a folder, not a file"),
        ([*GENERATE, "--out", "{tmp}/file/log.csv"], "--out '{tmp}/file/log.csv': '{tmp}/file' is a file, not a"),
        (["generate-data", "--vehicle-file", "{tmp}", "--maneuver", "dlc", "--speed", "30", "--out", "{tmp}/g.csv"],
         "vehicle file '{tmp}' (--vehicle-file): a folder, not a file"),
        (["fit-lag", "{tmp}", *TRUCK, "--out", "{tmp}/l.json"], "vehicle log '{tmp}': a folder, not a file"),
        (["fit-lag", "{dlc}", *TRUCK, "--out", "{tmp}/l.json", "--plot", "{tmp}"], "--plot '{tmp}' is a folder"),
        (["design-lead", "--lag", "{tmp}", "--out", "{tmp}/f.json"], "steering-lag file '{tmp}' (--lag): a folder"),
        (["design-lead", "--lag", "{tmp}/deep.json", "--out", "{tmp}/f.json"],
         "steering-lag file '{tmp}/deep.json' (--lag): nested deeper than 64 levels"),
        (["design-lead", "--lag", "{lag}", "--out", "{tmp}/f.json", "--validate", "{tmp}/file/x.csv", *TRUCK],
         "vehicle log '{tmp}/file/x.csv' (--validate): no such file ('{tmp}/file' is a file, not a folder)"),
        (["design-lead", "--lag", "{lag}", "--out", "{tmp}/f.json", "--validate-plot", "{tmp}"], "--validate-plot"),
        (["margins", "--lag", "{lag}", "--lead", "{tmp}", "--speeds", "30", "--out", "{tmp}/m.csv"],
         "lead filter file '{tmp}' (--lead): a folder, not a file"),
        (["margins", "--lag", "{lag}", "--measured-lag", "{tmp}/none.json", "--speeds", "30", "--out", "{tmp}/m.csv"],
         "steering-lag file '{tmp}/none.json' (--measured-lag): no such file"),
        (["rollover-limits", *TRUCK, "--speeds", "40", "--out", "{tmp}/file/r.csv"], "'{tmp}/file' is a file"),
        (["schedule", *TRUCK, "--speeds", "40", "--out", "{tmp}/s.json", "--plot", "{tmp}/file/p.png"], "--plot"),
    ],
)  # fmt: skip
def test_unusable_files_and_folders_are_refused_before_any_work(
    logs, lag_file, tmp_path: Path, capsys, argv, needle: str
) -> None:
    (tmp_path / "file").write_text("x")
    (tmp_path / "deep.json").write_text("[" * 5000 + "]" * 5000)
    fields = {"dlc": logs["dlc"], "lag": lag_file, "tmp": tmp_path}
    assert main([a.format(**fields) for a in argv]) == 2
    err = capsys.readouterr().err
    assert err.startswith("tuning: error: ") and needle.format(**fields) in err and err.count("\n") == 1, err


def test_an_unwritable_output_folder_is_refused(tmp_path: Path, capsys, monkeypatch) -> None:
    monkeypatch.setattr("workbench.base.output_dir.os.access", lambda *_args, **_kw: False)  # as without permission
    assert main([*GENERATE, "--out", str(tmp_path / "new" / "log.csv")]) == 2
    assert f"the folder {str(tmp_path)!r} is not writable (permission denied)" in capsys.readouterr().err
    assert not (tmp_path / "new").exists()


def test_amplitude_and_lateral_acceleration_exclude_each_other(tmp_path: Path) -> None:
    argv = ["generate-data", *TRUCK, "--maneuver", "dlc", "--speed", "30", "--amplitude-deg", "50"]
    with pytest.raises(SystemExit) as info:
        main([*argv, "--lat-accel-g", "0.1", "--out", str(tmp_path / "g.csv")])
    assert info.value.code == 2


# --- existing output files ---------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("argv", "existing"),
    [
        ([*GENERATE, "--out", "{tmp}/old"], "--out"),
        (["fit-lag", "{dlc}", *TRUCK, "--out", "{tmp}/old"], "--out"),
        (["fit-lag", "{dlc}", *TRUCK, "--out", "{tmp}/l.json", "--plot", "{tmp}/old"], "--plot"),
        (["design-lead", "--lag", "{lag}", "--out", "{tmp}/old.json"], "--out"),
        (["design-lead", "--lag", "{lag}", "--out", "{tmp}/f.json", "--validate", "{dlc}", "--validate-plot",
          "{tmp}/old", *TRUCK], "--validate-plot"),
        (["design-lead", "--lag", "{lag}", "--out", "{tmp}/old.json", "--validate", "{dlc}", *TRUCK], "--out"),
        (["rollover-limits", *TRUCK, "--speeds", "40", "--out", "{tmp}/old"], "--out"),
        (["steering-limits", "--vehicle", "kinematic-bicycle", "--speeds", "40", "--out", "{tmp}/old"], "--out"),
        (["schedule", *TRUCK, "--speeds", "40", "--out", "{tmp}/old.json"], "--out"),
        (["margins", "--lag", "{lag}", "--speeds", "30", "--out", "{tmp}/old"], "--out"),
        (["margins", "--lag", "{lag}", "--speeds", "30", "--out", "{tmp}/m.csv", "--plot", "{tmp}/old"], "--plot"),
    ],
)  # fmt: skip
def test_an_existing_output_file_is_refused_without_overwrite(
    logs, lag_file, tmp_path: Path, capsys, argv, existing: str
) -> None:
    fields = {"dlc": logs["dlc"], "lag": lag_file, "tmp": tmp_path}
    argv = [a.format(**fields) for a in argv]
    old = Path(argv[argv.index(existing) + 1])
    old.write_text("the user's own\n")
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err == f"tuning: error: {existing} {str(old)!r} exists; give --overwrite to replace it, or choose another " \
        "file name\n"  # fmt: skip
    assert old.read_text() == "the user's own\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == [old.name]  # refused before any work: nothing else written


def test_design_leads_default_validation_figure_is_protected_too(logs, lag_file, tmp_path: Path, capsys) -> None:
    figure = tmp_path / "lead_validation.png"
    figure.write_text("x")
    argv = ["design-lead", "--lag", str(lag_file), "--out", str(tmp_path / "lead.json"), "--validate", str(logs["dlc"])]
    assert main([*argv, *TRUCK]) == 2
    assert f"the --validate figure {str(figure)!r} exists; give --overwrite" in capsys.readouterr().err


def test_overwrite_replaces_an_existing_output_file(tmp_path: Path, capsys) -> None:
    out = tmp_path / "log.csv"
    out.write_text("the user's own\n")
    assert main([*GENERATE, "--duration-s", "2", "--out", str(out), "--overwrite"]) == 0
    assert pd.read_csv(out)["t_s"].iloc[-1] == pytest.approx(2.0, abs=0.011)
