"""What a new user meets in the workbench CLI (issue 20): `run` steers with the clothoid controller unless told
otherwise, `compare` takes `run`'s options (and applies them as `run` does), `--version`, progress on a terminal,
and the listings read whole."""

from __future__ import annotations

import importlib.metadata
import json
import re
import sys
from pathlib import Path

import pandas as pd
import pytest

from controllers import CONTROLLERS
from workbench.apps.cli import main
from workbench.apps.comparison import RunSpec, compare
from workbench.base.errors import WorkbenchInputError

#: Metrics that are measured wall-clock times: they differ between two runs of the same simulation.
TIMINGS = ("step_time_median_us", "step_time_p99_us")


def _metrics(folder: Path) -> dict:
    return json.loads((folder / "metrics.json").read_text())


def test_run_steers_with_the_clothoid_controller_by_default(tmp_path: Path, capsys) -> None:
    """The README's example: the loaded truck's dlc, no --controller: the clothoid controller with the truck's own
    tuning (pure pursuit, the old default, misses the path by 0.45 m there)."""
    out = tmp_path / "truck-dlc"
    args = ["run", "dlc", "--vehicle", "tractor-semitrailer", "--payload-kg", "17000", "--out", str(out)]
    assert main([*args, "--no-plots"]) == 0
    metrics = _metrics(out)
    assert metrics["controller"] == "clothoid" and metrics["completed"] is True
    assert metrics["max_abs_cte_m"] < 0.15
    assert "ctrl_lookahead_m" in pd.read_parquet(out / "trace.parquet").columns  # the clothoid's diagnostics
    assert "dlc: clothoid on tractor-semitrailer at 30 km/h -> completed" in capsys.readouterr().out


def test_version_is_the_installed_distributions(capsys) -> None:
    with pytest.raises(SystemExit) as done:
        main(["--version"])
    assert done.value.code == 0
    line = capsys.readouterr().out.strip()
    version = importlib.metadata.version("lateral-workbench")
    assert re.fullmatch(
        rf"workbench \(lateral-workbench\) {re.escape(version)}(, commit [0-9a-f]{{7,}}(\+dirty)?)?", line
    )


def test_compare_applies_runs_options_as_run_does(tmp_path: Path) -> None:
    """Every option `run` and `compare` share, given to both: the same simulation, metric for metric (a vehicle
    file with a payload, an option, the rates, the speed profile's bound, the time-out, the conditions)."""
    truck = tmp_path / "truck.toml"
    truck.write_text(_shown(tmp_path, ["vehicles", "--show", "tractor-semitrailer"]))
    shared = ["--vehicle-file", str(truck), "--payload-kg", "9000", "--speed", "40", "--controller-rate-hz", "25"]
    shared += ["--plant-rate-hz", "500", "--lat-accel-g", "0.25", "--max-time-s", "60", "--conditions", "rtk"]
    shared += ["--seed", "3", "--no-plots"]
    assert (
        main(["run", "dlc", "--controller", "stanley", "--set", "gain_per_s=2", *shared, "--out", str(tmp_path / "r")])
        == 0
    )
    cmp_args = ["compare", "dlc", "--controllers", "stanley", "--set", "stanley:gain_per_s=2", *shared]
    assert main([*cmp_args, "--out", str(tmp_path / "c")]) == 0
    (folder,) = (tmp_path / "c" / "runs").iterdir()
    assert folder.name == "stanley-truck.toml-gain_per_s_2-9000kg"
    ran, compared = _metrics(tmp_path / "r"), _metrics(folder)
    assert ran["completed"] is True
    assert {k: v for k, v in compared.items() if k not in TIMINGS} == {k: v for k, v in ran.items() if k not in TIMINGS}
    trace = pd.read_parquet(folder / "trace.parquet")
    assert trace["t_s"].diff().iloc[1:].to_numpy() == pytest.approx(1 / 25)
    summary = pd.read_csv(tmp_path / "c" / "summary.csv")
    assert list(summary["vehicle"]) == [str(truck)] and list(summary["options"]) == ["gain_per_s=2"]
    # --no-plots: the traces, metrics and summary only
    assert not list((tmp_path / "c").glob("*.png")) and not (tmp_path / "c" / "report.html").exists()


def _shown(tmp_path: Path, argv: list[str]) -> str:
    """What a listing command prints (run in-process)."""
    import contextlib
    import io

    text = io.StringIO()
    with contextlib.redirect_stdout(text):
        assert main(argv) == 0
    return text.getvalue()


def test_compare_set_and_a_controllers_own_config_file_change_its_run_only(tmp_path: Path) -> None:
    fixed = tmp_path / "fixed.toml"
    fixed.write_text('[clothoid]\nlookahead_mode = "fixed"\n')
    args = ["compare", "dlc", "--controllers", "clothoid,pure-pursuit", "--vehicle", "kinematic-bicycle", "--no-plots"]
    args += ["--controller-config", f"clothoid={fixed}", "--set", "clothoid:fixed_lookahead_m=7"]
    assert main([*args, "--out", str(tmp_path / "c")]) == 0
    runs = tmp_path / "c" / "runs"
    clothoid = pd.read_parquet(runs / "clothoid-kinematic-bicycle-fixed_lookahead_m_7" / "trace.parquet")
    assert (clothoid["ctrl_lookahead_m"] == 7.0).all()
    assert (runs / "pure-pursuit-kinematic-bicycle").is_dir()  # its defaults, its own folder
    # without them the clothoid controller adapts its lookahead
    plain = ["compare", "dlc", "--controllers", "clothoid", "--vehicle", "kinematic-bicycle", "--no-plots"]
    assert main([*plain, "--out", str(tmp_path / "p")]) == 0
    adaptive = pd.read_parquet(tmp_path / "p" / "runs" / "clothoid-kinematic-bicycle" / "trace.parquet")
    assert adaptive["ctrl_lookahead_m"].nunique() > 1


def test_compare_payload_goes_to_the_vehicles_that_carry_one(tmp_path: Path) -> None:
    args = ["compare", "fig17", "--controllers", "stanley", "--vehicle", "tractor-semitrailer,kinematic-bicycle"]
    assert main([*args, "--payload-kg", "5000", "--no-plots", "--out", str(tmp_path / "c")]) == 0
    runs = tmp_path / "c" / "runs"
    assert sorted(p.name for p in runs.iterdir()) == ["stanley-kinematic-bicycle", "stanley-tractor-semitrailer-5000kg"]
    run = ["run", "fig17", "--controller", "stanley", "--vehicle", "tractor-semitrailer", "--payload-kg", "5000"]
    assert main([*run, "--no-plots", "--out", str(tmp_path / "r")]) == 0
    assert _metrics(runs / "stanley-tractor-semitrailer-5000kg")["max_ltr"] == _metrics(tmp_path / "r")["max_ltr"]


@pytest.mark.parametrize(
    ("extra", "needle"),
    [
        (
            ["--controller-config", "nmpc={tmp}/a.toml"],
            "--controller-config 'nmpc={tmp}/a.toml': 'nmpc' is not one of --controllers (clothoid, stanley)",
        ),
        (["--controller-config", "clothod={tmp}/a.toml"], "'clothod' is not one of --controllers (clothoid, stanley)"),
        (
            ["--controller-config", "stanley={tmp}/a.toml"],
            "the file has no [stanley] table (`workbench controllers --show stanley` writes one)",
        ),
        (
            ["--controller-config", "clothoid={tmp}/a.toml", "--controller-config", "clothoid={tmp}/a.toml"],
            "clothoid has a file already",
        ),
        (
            ["--controller-config", "{tmp}/a.toml", "--controller-config", "{tmp}/b.toml"],
            "give one FILE.toml for every controller, got 2",
        ),
        (["--controller-config", "stanley={tmp}/missing.toml"], "--controller-config 'stanley={tmp}/missing.toml': "),
        (
            ["--set", "gain_per_s=8"],
            "--set 'gain_per_s=8' is for every controller, but clothoid has no option "
            "'gain_per_s'; give it to one controller as --set NAME:gain_per_s=8, e.g. --set stanley:gain_per_s=8",
        ),
        (["--set", "lmpc:horizon=3"], "--set 'lmpc:horizon=3': 'lmpc' is not one of --controllers (clothoid, stanley)"),
        (["--set", "stanley:gain=8"], "unknown option 'gain' for StanleyConfig; allowed: "),
        (
            ["--payload-kg", "500", "--vehicle", "kinematic-bicycle"],
            "--payload-kg 500: none of the vehicles "
            "(kinematic-bicycle) carries a payload; a payload applies to: tractor-semitrailer",
        ),
        (["--max-time-s", "0"], "max_time_s"),
        (["--controller-rate-hz", "30"], "must be a whole multiple of controller_rate_hz"),
    ],
)
def test_compare_refuses_bad_options_naming_them(extra: list[str], needle: str, tmp_path: Path, capsys) -> None:
    (tmp_path / "a.toml").write_text('[clothoid]\nlookahead_mode = "fixed"\n')
    (tmp_path / "b.toml").write_text("")
    extra = [e.format(tmp=tmp_path) for e in extra]
    vehicle = [] if "--vehicle" in extra else ["--vehicle", "tractor-semitrailer"]
    argv = ["compare", "dlc", "--controllers", "clothoid,stanley", *vehicle, *extra, "--out", str(tmp_path / "out")]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("workbench: error: ") and needle.format(tmp=tmp_path) in err and err.count("\n") == 1, err
    assert not (tmp_path / "out").exists()


def test_compare_needs_a_vehicle(tmp_path: Path, capsys) -> None:
    assert main(["compare", "dlc", "--controllers", "stanley", "--out", str(tmp_path / "out")]) == 2
    assert "give --vehicle NAME[,NAME...] or --vehicle-file FILE.toml" in capsys.readouterr().err


def test_compare_shows_one_bar_counting_the_runs_on_a_terminal(tmp_path: Path, capsys, monkeypatch) -> None:
    monkeypatch.setattr(sys.stderr, "isatty", lambda: True)
    args = ["compare", "dlc", "--controllers", "pure-pursuit,stanley", "--vehicle", "kinematic-bicycle"]
    assert main([*args, "--no-plots", "--out", str(tmp_path / "c")]) == 0
    err = capsys.readouterr().err
    assert re.search(r"compare: 100%\|.*\| 2/2 \[.*stanley on kinematic-bicycle\]\n$", err)
    assert "preparing pure-pursuit on kinematic-bicycle" in err


def test_a_refused_comparison_takes_its_bar_away(capsys) -> None:
    runs = [RunSpec("stanley", "kinematic-bicycle", ("gain=1",))]
    with pytest.raises(WorkbenchInputError, match="unknown option 'gain'"):
        compare("dlc", runs, progress=True)
    err = capsys.readouterr().err
    assert "preparing stanley (gain=1) on kinematic-bicycle" in err
    assert err.endswith("\r") and "\n" not in err  # the line cleared, so that the error message stands alone


def test_vehicle_files_of_the_same_name_are_refused(tmp_path: Path) -> None:
    text = _shown(tmp_path, ["vehicles", "--show", "kinematic-bicycle"])
    for folder in ("a", "b"):
        (tmp_path / folder).mkdir()
        (tmp_path / folder / "car.toml").write_text(text)
    runs = [RunSpec("stanley", str(tmp_path / folder / "car.toml")) for folder in ("a", "b")]
    with pytest.raises(WorkbenchInputError, match=r"same folder runs/stanley-car\.toml"):
        compare("dlc", runs)


def test_controllers_listing_gives_whole_sentences(capsys) -> None:
    assert main(["controllers"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert [line.split()[0] for line in lines] == list(CONTROLLERS)
    for line in lines:
        assert line.rstrip().endswith("."), line
    assert "stanley        Stanley (Thrun et al. 2006, the DARPA Grand Challenge winner): heading error plus a " in (
        "\n".join(lines)
    )
