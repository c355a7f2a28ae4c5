"""The workbench CLI: listing, a full run's files, and clear errors with exit code 2 for bad input."""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from workbench.apps.cli import main
from workbench.base.errors import WorkbenchInputError
from workbench.simulation.metrics import METRIC_KEYS


def test_scenarios_lists_every_named_scenario(capsys: pytest.CaptureFixture[str], monkeypatch, tmp_path: Path) -> None:
    monkeypatch.delenv("WORKBENCH_ZANDVOORT_CSV", raising=False)
    monkeypatch.chdir(tmp_path)  # no tracks/ here, and none beside the checkout: the track file is not found
    monkeypatch.setattr("workbench.simulation.scenarios.CHECKOUT_ROOT", None)
    assert main(["scenarios"]) == 0
    out = capsys.readouterr().out
    for name in ("figure8", "dlc", "fig17", "zandvoort"):
        assert name in out
    assert "download" in out  # zandvoort says where to get its file


def test_run_dlc_writes_trace_metrics_and_plots(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "dlc"
    args = ["run", "dlc", "--controller", "pure-pursuit", "--vehicle", "kinematic-bicycle", "--out", str(out)]
    assert main(args) == 0
    metrics = json.loads((out / "metrics.json").read_text())
    assert tuple(metrics)[: len(METRIC_KEYS)] == METRIC_KEYS
    assert metrics["scenario"] == "dlc" and metrics["completed"] is True
    assert metrics["max_ltr"] is None and metrics["max_offtracking_m"] is None
    assert 0 < metrics["max_abs_cte_m"] < 0.3
    trace = pd.read_parquet(out / "trace.parquet")
    for column in ("t_s", "x_m", "y_m", "cte_m", "steer_wheel_rad", "speed_mps", "lat_accel_mps2", "step_time_s"):
        assert column in trace.columns
    assert np.isfinite(trace.select_dtypes("number").to_numpy()).all()
    assert trace["cte_m"].abs().max() == pytest.approx(metrics["max_abs_cte_m"])
    for png in ("trajectory.png", "cte_vs_distance.png", "steering_vs_time.png", "speed_vs_distance.png"):
        assert (out / png).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "completed" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["run", "nowhere", "--out", "X"], "unknown scenario 'nowhere'"),
        (["run", "dlc", "--controller", "magic", "--out", "X"], "unknown controller 'magic'"),
        (["run", "dlc", "--vehicle", "hovercraft", "--out", "X"], "unknown vehicle 'hovercraft'"),
        (["run", "dlc", "--speed", "0", "--out", "X"], "speed_kmh"),
        (["run", "dlc", "--speed", "-10", "--out", "X"], "speed_kmh"),
        (["run", "dlc", "--speed", "nan", "--out", "X"], "speed_kmh"),
        (["run", "missing.csv", "--out", "X"], "waypoint file 'missing.csv': no such file"),
    ],
)
def test_bad_input_exits_2_with_a_message(args: list[str], needle: str, capsys, tmp_path: Path) -> None:
    args = [a if a != "X" else str(tmp_path / "out") for a in args]
    assert main(args) == 2
    err = capsys.readouterr().err
    assert needle in err
    assert "Traceback" not in err


@pytest.mark.parametrize(
    ("content", "needle"),
    [
        ("a,b\n1,2\n3,4\n5,6\n", "x"),
        ("x,y\n0,0\n1,nan\n2,0\n", "nan"),
        ("x,y\n0,0\n1,1\n", "at least 3"),
        ("x,y\n0,0\n0,0\n1,1\n", "repeat"),
    ],
)
def test_malformed_waypoint_file_exits_2(content: str, needle: str, tmp_path: Path, capsys) -> None:
    path = tmp_path / "bad.csv"
    path.write_text(content)
    assert main(["run", str(path), "--out", str(tmp_path / "out")]) == 2
    assert needle in capsys.readouterr().err.lower()


def test_waypoint_csv_runs_as_a_scenario(tmp_path: Path) -> None:
    s = np.linspace(0, 80, 41)
    pd.DataFrame({"x": s, "y": 2.0 * np.sin(s / 15.0)}).to_csv(tmp_path / "wiggle.csv", index=False)
    assert main(["run", str(tmp_path / "wiggle.csv"), "--out", str(tmp_path / "o"), "--no-plots"]) == 0
    assert json.loads((tmp_path / "o" / "metrics.json").read_text())["completed"] is True


SCRIPTS = Path(sys.executable).parent


@pytest.mark.parametrize(
    ("script", "args", "needle"), [("workbench", ["scenarios"], "fig17"), ("tuning", ["--help"], "generate-data")]
)
def test_console_scripts_are_installed(script: str, args: list[str], needle: str) -> None:
    exe = SCRIPTS / script
    if not exe.exists():
        pytest.skip(f"{exe} not installed: run `pip install -e .` first")
    done = subprocess.run([str(exe), *args], capture_output=True, text=True, check=False, timeout=120)
    assert done.returncode == 0, done.stderr
    assert needle in done.stdout


def test_vehicles_lists_presets_and_shows_toml(capsys) -> None:
    assert main(["vehicles"]) == 0
    out = capsys.readouterr().out
    for name in ("kinematic-bicycle", "dynamic-bicycle", "tractor-semitrailer", "commonroad-mb"):
        assert name in out
    assert main(["vehicles", "--show", "tractor-semitrailer"]) == 0
    assert "payload_kg" in capsys.readouterr().out


def test_truck_run_with_payload_fills_the_vehicle_metrics(tmp_path: Path) -> None:
    out = tmp_path / "truck"
    args = [
        "run",
        "fig17",
        "--vehicle",
        "tractor-semitrailer",
        "--payload-kg",
        "17000",
        "--out",
        str(out),
        "--no-plots",
    ]
    assert main(args) == 0
    metrics = json.loads((out / "metrics.json").read_text())
    assert metrics["completed"] is True
    assert 0 < metrics["max_ltr"] < 1  # 0.3 g speed profile: far from wheel lift-off
    assert 0 < metrics["max_offtracking_m"] < 3


def test_payload_on_a_car_is_rejected(tmp_path: Path, capsys) -> None:
    assert main(["run", "dlc", "--vehicle", "kinematic-bicycle", "--payload-kg", "500", "--out", str(tmp_path)]) == 2
    assert "payload" in capsys.readouterr().err


def test_clothoid_options_from_a_config_file_and_set(tmp_path: Path, capsys) -> None:
    assert main(["controllers", "--show", "clothoid"]) == 0
    template = capsys.readouterr().out
    assert "[clothoid]" in template and "frechet_threshold_m" in template
    config = tmp_path / "clothoid.toml"
    config.write_text(template.replace('lookahead_mode = "adaptive"', 'lookahead_mode = "fixed"'))
    out = tmp_path / "run"
    args = ["run", "fig17", "--controller", "clothoid", "--controller-config", str(config), "--out", str(out)]
    assert main([*args, "--set", "fixed_lookahead_m=7", "--no-plots"]) == 0
    trace = pd.read_parquet(out / "trace.parquet")
    assert (trace["ctrl_lookahead_m"] == 7.0).all()
    assert main([*args, "--set", "fixed_lookahead_m=-7", "--overwrite"]) == 2
    err = capsys.readouterr().err
    assert "[clothoid]: fixed_lookahead_m must be" in err and "got -7.0" in err
    assert (out / "trace.parquet").is_file()  # a refused run leaves the earlier output as it was


def test_compare_writes_report_summary_and_runs(tmp_path: Path, capsys) -> None:
    out = tmp_path / "cmp"
    args = ["compare", "dlc", "--controllers", "pure-pursuit,stanley", "--vehicle", "kinematic-bicycle,dynamic-bicycle"]
    assert main([*args, "--out", str(out)]) == 0
    summary = pd.read_csv(out / "summary.csv")
    assert sorted(zip(summary["controller"], summary["vehicle"], strict=True)) == sorted(
        (c, v) for c in ("pure-pursuit", "stanley") for v in ("kinematic-bicycle", "dynamic-bicycle")
    )
    assert (summary["status"] == "completed").all()
    html = (out / "report.html").read_text(encoding="utf-8")
    assert html.count("data:image/png;base64,") == 4 and "report.html" in capsys.readouterr().out
    for row in summary.itertuples():
        metrics = json.loads((out / "runs" / f"{row.controller}-{row.vehicle}" / "metrics.json").read_text())
        assert metrics["max_abs_cte_m"] == pytest.approx(row.max_abs_cte_m)


def test_run_and_compare_warn_of_a_steering_limit_cycle(tmp_path: Path, capsys) -> None:
    # Stanley at 8/s weaves on the loaded truck (tests/workbench/test_metrics.py)
    args = ["run", "dlc", "--controller", "stanley", "--vehicle", "tractor-semitrailer", "--no-plots"]
    assert main([*args, "--set", "gain_per_s=8", "--out", str(tmp_path / "run")]) == 0
    out = capsys.readouterr().out
    assert re.search(r"steering oscillation \d+\.\d+ deg \(RMS about its 1 s average\), RMS steering rate", out)
    assert re.search(
        r"\n  WARNING: steering limit cycle at 0\.\d\d Hz, ±\d+° steering wheel for \d+\.\d s from t = ", out
    )
    config = tmp_path / "stanley.toml"
    config.write_text("[stanley]\ngain_per_s = 8.0\n")
    args = ["compare", "dlc", "--controllers", "stanley", "--vehicle", "tractor-semitrailer"]
    assert main([*args, "--controller-config", str(config), "--out", str(tmp_path / "cmp")]) == 0
    out = capsys.readouterr().out
    assert "steer_oscillation_deg" in out
    assert "  WARNING: steering limit cycle: stanley on tractor-semitrailer at 0." in out


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["--controllers", "pure-pursuit,mpc2", "--vehicle", "kinematic-bicycle"], "unknown controller 'mpc2'"),
        (["--controllers", ",", "--vehicle", "kinematic-bicycle"], "--controllers needs at least one name"),
        (["--controllers", "stanley", "--vehicle", "bus"], "unknown vehicle 'bus'"),
    ],
)
def test_compare_bad_names_exit_2(args: list[str], needle: str, tmp_path: Path, capsys) -> None:
    assert main(["compare", "dlc", *args, "--out", str(tmp_path / "x")]) == 2
    assert needle in capsys.readouterr().err
    assert not (tmp_path / "x").exists()  # refused before any run


# --- output folders and input files: refused before any work ---------------------------------------------------

QUICK_RUN = ["run", "dlc", "--controller", "pure-pursuit", "--vehicle", "kinematic-bicycle"]


def test_a_reused_output_folder_is_refused_or_replaced_whole(tmp_path: Path, capsys) -> None:
    out = tmp_path / "dlc"
    assert main([*QUICK_RUN, "--out", str(out)]) == 0
    (out / "notes.txt").write_text("my notes")
    capsys.readouterr()
    assert main([*QUICK_RUN, "--no-plots", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"workbench: error: --out {str(out)!r} holds the output of an earlier `workbench run`")
    assert "give --overwrite" in err
    assert main([*QUICK_RUN, "--no-plots", "--overwrite", "--out", str(out)]) == 0
    # the PNGs of the earlier run are gone, the new trace and metrics are there, the user's file is kept and named
    assert sorted(p.name for p in out.iterdir()) == [
        ".workbench-manifest.json",
        "metrics.json",
        "notes.txt",
        "trace.parquet",
    ]
    assert "kept: notes.txt" in capsys.readouterr().err
    manifest = json.loads((out / ".workbench-manifest.json").read_text())
    assert manifest["command"] == "run" and manifest["files"] == ["metrics.json", "trace.parquet"]


def test_compare_replaces_its_own_output_only(tmp_path: Path, capsys) -> None:
    out = tmp_path / "cmp"
    args = ["compare", "dlc", "--vehicle", "kinematic-bicycle", "--out", str(out)]
    assert main([*args, "--controllers", "pure-pursuit,stanley"]) == 0
    assert main([*args, "--controllers", "stanley"]) == 2
    assert "holds the output of an earlier `workbench compare`" in capsys.readouterr().err
    assert main([*args, "--controllers", "stanley", "--overwrite"]) == 0
    assert sorted(p.name for p in (out / "runs").iterdir()) == ["stanley-kinematic-bicycle"]


COMMANDS_WITH_OUT = {
    "run": QUICK_RUN,
    "compare": ["compare", "dlc", "--controllers", "stanley", "--vehicle", "kinematic-bicycle"],
    "fig17": ["fig17"],
    "paper": ["paper"],
    "sweep": ["sweep", "{spec}"],
    "optimise": ["optimise", "{spec}"],
    "tournament": ["tournament", "{spec}"],
}


@pytest.fixture
def spec_file(tmp_path: Path) -> Path:
    path = tmp_path / "spec.toml"
    path.write_text('[study]\nscenarios = ["dlc"]\ncontrollers = ["pure-pursuit"]\nvehicles = ["kinematic-bicycle"]\n')
    return path


@pytest.mark.parametrize("command", COMMANDS_WITH_OUT)
@pytest.mark.parametrize("case", ["a file", "parent a file", "not writable"])
def test_an_unusable_output_folder_is_refused_before_any_work(
    command: str, case: str, tmp_path: Path, spec_file: Path, capsys, monkeypatch
) -> None:
    (tmp_path / "file").write_text("x")
    out = {"a file": tmp_path / "file", "parent a file": tmp_path / "file" / "out"}.get(case, tmp_path / "new")
    if case == "not writable":  # simulated: root may write anyway
        monkeypatch.setattr("workbench.base.output_dir.os.access", lambda *_args, **_kw: False)
    argv = [a.format(spec=spec_file) for a in COMMANDS_WITH_OUT[command]]
    assert main([*argv, "--out", str(out)]) == 2
    err = capsys.readouterr().err
    expected = {
        "a file": "is a file, not a folder",
        "parent a file": f"{str(tmp_path / 'file')!r} is a file, not a folder",
        "not writable": "is not writable (permission denied)",
    }[case]
    assert err.startswith(f"workbench: error: --out {str(out)!r}") and expected in err and err.count("\n") == 1
    assert not (tmp_path / "new").exists()


@pytest.mark.skipif(os.geteuid() == 0, reason="root may write anywhere")
def test_a_read_only_output_folder_is_refused(tmp_path: Path, capsys) -> None:
    folder = tmp_path / "ro"
    folder.mkdir()
    folder.chmod(0o500)
    try:
        assert main([*QUICK_RUN, "--out", str(folder / "out")]) == 2
        assert "is not writable (permission denied)" in capsys.readouterr().err
    finally:
        folder.chmod(0o700)


@pytest.mark.parametrize(
    ("option", "label"),
    [
        ("--controller-config", "--controller-config"),
        ("--vehicle-file", "--vehicle-file"),
        ("--track", "--track"),
        ("scenario", "waypoint file"),
    ],
)
@pytest.mark.parametrize("command", ["run", "compare"])
def test_an_input_file_that_is_a_folder_or_missing_is_refused(
    option: str, label: str, command: str, tmp_path: Path, capsys
) -> None:
    folder = tmp_path / "inputs.csv"
    folder.mkdir()
    base = COMMANDS_WITH_OUT[command]
    for path, problem in ((folder, "a folder, not a file"), (tmp_path / "file" / "x.csv", "is a file, not a folder")):
        (tmp_path / "file").write_text("x")
        argv = [*base[:1], str(path), *base[2:]] if option == "scenario" else [*base, option, str(path)]
        assert main([*argv, "--out", str(tmp_path / "out")]) == 2
        err = capsys.readouterr().err
        assert err.startswith(f"workbench: error: {label} {str(path)!r}: ") and problem in err, err
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("option", ["--controller-config", "--vehicle-file"])
def test_a_toml_nested_5000_deep_is_refused(option: str, tmp_path: Path, capsys) -> None:
    deep = tmp_path / "deep.toml"
    deep.write_text("[pure-pursuit]\nx = " + "[" * 5000 + "]" * 5000 + "\n")
    assert main([*QUICK_RUN, option, str(deep), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert "nested deeper than 64 levels" in err and str(deep) in err and "Traceback" not in err


def test_a_path_tighter_than_the_vehicle_turns_is_named_before_the_run(tmp_path: Path, capsys, monkeypatch) -> None:
    def stop(*_args, **_kwargs):
        raise WorkbenchInputError("stopped before simulating")

    monkeypatch.setattr("workbench.simulation.simulator.Simulation.run", stop)
    angles = np.linspace(0.0, 2 * np.pi, 60)  # a 1 m circle: the car turns no tighter than a 1.42 m radius
    pd.DataFrame({"x": 1.0 * np.cos(angles), "y": 1.0 * np.sin(angles)}).to_csv(tmp_path / "tight.csv", index=False)
    args = [*QUICK_RUN[:1], str(tmp_path / "tight.csv"), *QUICK_RUN[2:], "--out", str(tmp_path / "o")]
    assert main([*args, "--allow-infeasible"]) == 2
    warning = next(line for line in capsys.readouterr().err.splitlines() if not line.startswith("workbench run: "))
    assert warning.startswith("workbench: warning: ") and "tighter than the kinematic-bicycle can turn" in warning


def test_run_refuses_a_path_the_vehicle_cannot_follow_unless_allowed(tmp_path: Path, capsys, monkeypatch) -> None:
    """A 3 m semicircle between straights: within the car's lock, but its curvature changes faster than the car's
    steering follows. Refused before the run (exit 2), naming where (s in m) and against what limit; with
    --allow-infeasible it runs, warned."""
    runs = []

    def stop(*_args, **_kwargs):
        runs.append(1)
        raise WorkbenchInputError("stopped before simulating")

    monkeypatch.setattr("workbench.simulation.simulator.Simulation.run", stop)
    arc = [(3.0 * np.sin(a), 3.0 - 3.0 * np.cos(a)) for a in np.linspace(0.0, np.pi, 13)[1:-1]]
    points = [(x, 0.0) for x in range(-20, 1)] + arc + [(x, 6.0) for x in range(0, -21, -1)]
    pd.DataFrame(points, columns=["x", "y"]).to_csv(tmp_path / "r3.csv", index=False)
    args = [*QUICK_RUN[:1], str(tmp_path / "r3.csv"), *QUICK_RUN[2:], "--out", str(tmp_path / "o")]
    assert main(args) == 2 and runs == []
    (error,) = [line for line in capsys.readouterr().err.splitlines() if not line.startswith("workbench run: ")]
    assert error.startswith(
        "workbench: error: r3 changes its curvature faster than the kinematic-bicycle's steering follows at the "
        "planned speed (its road wheels turn at most 23 deg/s: 34 deg in any 1.5 s) at s = 1"
    )
    assert re.search(r"at s = \d+\.\d-\d+\.\d m \(the road-wheel angle asked for changes by 1\.\d\d times", error)
    assert error.endswith("; --allow-infeasible runs it anyway")
    assert main([*args, "--allow-infeasible"]) == 2 and runs == [1]  # run (stopped by the stand-in)
    assert "workbench: warning: r3 changes its curvature faster" in capsys.readouterr().err
