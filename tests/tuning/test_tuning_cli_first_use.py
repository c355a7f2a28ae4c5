"""What a new user meets in the tuning CLI (issue 20): `--version` (the installed version and the checkout's
commit), one name for the validation's normalised RMS error, units written "(unit)" on every figure, and progress
bars on a terminal for `tuning schedule`."""

from __future__ import annotations

import importlib.metadata
import json
import re
import shutil
import subprocess
import sys
from pathlib import Path

import matplotlib.pyplot as plt
import pytest

import tuning.plots
from tuning.cli import main
from tuning.rollover import RolloverLimit
from tuning.schedule import ScheduleResult
from workbench.base import version
from workbench.base.version import checkout_commit

TRUCK = ["--vehicle", "tractor-semitrailer"]
needs_git = pytest.mark.skipif(shutil.which("git") is None, reason="git is not installed")


def test_version_is_the_installed_distributions(capsys) -> None:
    with pytest.raises(SystemExit) as done:
        main(["--version"])
    assert done.value.code == 0
    line = capsys.readouterr().out.strip()
    version = re.escape(importlib.metadata.version("lateral-workbench"))
    assert re.fullmatch(rf"tuning \(lateral-workbench\) {version}(, commit [0-9a-f]{{7,}}(\+dirty)?)?", line)


def _git(folder: Path, *args: str) -> None:
    subprocess.run(["git", "-C", str(folder), "-c", "user.name=t", "-c", "user.email=t@t", *args], check=True)


@needs_git
def test_the_commit_of_a_checkout_and_whether_it_has_changes(tmp_path: Path) -> None:
    module = tmp_path / version.THIS_MODULE
    module.parent.mkdir(parents=True)
    module.write_text("x = 1\n")
    _git(tmp_path, "init", "-q")
    _git(tmp_path, "add", version.THIS_MODULE)
    _git(tmp_path, "commit", "-q", "-m", "first")
    head = subprocess.run(
        ["git", "-C", str(tmp_path), "rev-parse", "--short", "HEAD"], capture_output=True, text=True, check=True
    ).stdout.strip()
    assert checkout_commit(tmp_path) == head
    (tmp_path / "notes.txt").write_text("untracked: not a change of the tree")
    assert checkout_commit(tmp_path) == head
    module.write_text("x = 2\n")
    assert checkout_commit(tmp_path) == f"{head}+dirty"


@needs_git
def test_no_commit_outside_a_checkout_of_this_project(tmp_path: Path) -> None:
    assert checkout_commit(tmp_path) is None  # no repository
    _git(tmp_path, "init", "-q")
    (tmp_path / "other.txt").write_text("another project")
    _git(tmp_path, "add", "other.txt")
    _git(tmp_path, "commit", "-q", "-m", "other")
    assert checkout_commit(tmp_path) is None  # a repository, but the code is not tracked in it (an installed copy)


def test_no_commit_and_no_error_without_git(monkeypatch, capsys) -> None:
    monkeypatch.setenv("PATH", "")
    assert checkout_commit() is None
    with pytest.raises(SystemExit):
        main(["--version"])
    assert capsys.readouterr().out.startswith(
        f"tuning (lateral-workbench) {importlib.metadata.version('lateral-workbench')}\n"
    )


@pytest.fixture(scope="module")
def lag_and_log(tmp_path_factory) -> tuple[Path, Path]:
    folder = tmp_path_factory.mktemp("lead")
    log, lag = folder / "dlc.csv", folder / "lag.json"
    args = ["generate-data", *TRUCK, "--maneuver", "dlc", "--speed", "30", "--lat-accel-g", "0.1"]
    assert main([*args, "--out", str(log)]) == 0
    assert main(["fit-lag", str(log), *TRUCK, "--out", str(lag)]) == 0
    return lag, log


def test_design_lead_validation_says_nrmse_as_the_file_does(lag_and_log, tmp_path: Path, capsys) -> None:
    lag, log = lag_and_log
    capsys.readouterr()
    assert (
        main(["design-lead", "--lag", str(lag), "--out", str(tmp_path / "lead.json"), "--validate", str(log), *TRUCK])
        == 0
    )
    out = capsys.readouterr().out
    assert "RMS error against" not in out
    line = next(line for line in out.splitlines() if line.startswith("  dlc"))
    found = re.fullmatch(r"  dlc.csv: NRMSE \(normalised RMS error: .*\): lagged (\S+), compensated (\S+)", line)
    assert found is not None, line
    stored = json.loads((tmp_path / "lead.json").read_text())["design"]["validation"][0]
    assert (float(found[1]), float(found[2])) == pytest.approx(
        (stored["nrmse_lagged"], stored["nrmse_compensated"]), abs=5e-5
    )


@pytest.fixture
def labels(monkeypatch) -> list[str]:
    """Every axis label of the tuning figures drawn while the test runs."""
    seen: list[str] = []
    save = tuning.plots._save

    def record(fig: plt.Figure, path: str | Path) -> Path:
        seen.extend(label for ax in fig.axes for label in (ax.get_xlabel(), ax.get_ylabel()) if label)
        return save(fig, path)

    monkeypatch.setattr(tuning.plots, "_save", record)
    return seen


def test_tuning_figures_write_units_as_the_run_figures_do(
    labels: list[str], lag_and_log, result: ScheduleResult, tmp_path: Path
) -> None:
    lag, log = lag_and_log
    argv = ["design-lead", "--lag", str(lag), "--out", str(tmp_path / "lead.json"), "--plot", str(tmp_path / "b.png")]
    assert main([*argv, "--validate", str(log), *TRUCK]) == 0
    assert (
        main(["fit-lag", str(log), *TRUCK, "--out", str(tmp_path / "lag.json"), "--plot", str(tmp_path / "f.png")]) == 0
    )
    tuning.plots.schedule_figure(result, tmp_path / "s.png")
    limits = [
        RolloverLimit(30.0, 0.05, 0.06, 120.0, 1.0, "rollover"),
        RolloverLimit(60.0, 0.02, 0.03, 60.0, 1.0, "rollover"),
    ]
    tuning.plots.rollover_figure(limits, tmp_path / "r.png")
    assert {"time (s)", "curvature (1/m)", "magnitude (dB)", "phase (deg)", "frequency (rad/s)", "speed (km/h)"} <= set(
        labels
    )
    assert [label for label in labels if "[" in label] == []


def test_schedule_shows_its_speeds_and_closed_loop_runs_on_a_terminal(tmp_path: Path, capsys, monkeypatch) -> None:
    monkeypatch.setattr(sys.stderr, "isatty", lambda: True)
    argv = ["schedule", *TRUCK, "--speeds", "30,60", "--out", str(tmp_path / "s.json"), "--compare", "60"]
    assert main(argv) == 0
    err = capsys.readouterr().err
    assert re.search(r"tuning schedule: 100%\|.*\| 2/2 \[", err)
    assert re.search(r"closed loop: 100%\|.*\| 3/3 \[.*no filter at 60 km/h\]", err)
    # each speed's line stays, above the bar
    assert len(re.findall(r"tuning schedule: \d+ km/h: path omega_n", err)) == 2
