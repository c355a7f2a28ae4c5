"""`workbench sweep` and `workbench optimise` on bad input: exit code 2 and a message naming the value."""

from __future__ import annotations

from pathlib import Path

import pytest
from study_helpers import write_spec

from workbench.apps.cli import main


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--workers", "0"], "workers must be a whole number >= 1; got 0"),
        (["--scheduler", "tcp://localhost:8786"], "needs the dask backend (--backend dask)"),
        (["--backend", "dask", "--scheduler", "tcp://x:1", "--workers", "2"], "applies to a LocalCluster"),
    ],
)
def test_bad_backend_options(
    tiny_spec: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], extra: list[str], message: str
) -> None:
    assert main(["sweep", str(tiny_spec), "--out", str(tmp_path / "out"), *extra]) == 2
    assert message in capsys.readouterr().err


def test_bad_specs(tmp_path: Path, tiny_spec: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["sweep", str(tmp_path / "missing.toml"), "--out", str(tmp_path / "out")]) == 2
    assert "spec file '" in (err := capsys.readouterr().err) and "missing.toml': no such file" in err
    assert main(["optimise", str(tiny_spec), "--out", str(tmp_path / "out")]) == 2
    assert "needs an [optimise] table" in capsys.readouterr().err
    bad = write_spec(tmp_path, tiny_spec.read_text().replace("speed_kmh = [20, 30]", "speed_kmh = [20, nan]"))
    assert main(["sweep", str(bad), "--out", str(tmp_path / "out")]) == 2
    assert "grid.speed_kmh[1] must be a finite number; got nan" in capsys.readouterr().err


def test_a_sweep_with_errored_runs_exits_1(tiny_spec: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """TINY_SPEC: 10 runs, 2 of which raise (min_lookahead_m above max_lookahead_m): the rows are kept, exit code 1."""
    out = tmp_path / "out"
    assert main(["sweep", str(tiny_spec), "--out", str(out), "--workers", "1", "--no-plots"]) == 1
    captured = capsys.readouterr()
    assert "10 runs (0 already done, 10 run now): 8 completed, 2 error" in captured.out
    assert captured.err.startswith("workbench: 2 of 10 runs raised an error (status error;")
    assert captured.err.rstrip().endswith("exit code 1")
    assert (out / "results.parquet").is_file() and not (out / "report.html").exists()  # --no-plots: no report
    assert main(["sweep", str(tiny_spec), "--out", str(out), "--workers", "1"]) == 1  # resumed: nothing to run
    assert f"{out / 'report.html'}" in capsys.readouterr().out and (out / "report.html").is_file()


def test_a_bad_controller_config_stops_the_sweep_before_any_run(
    tiny_spec: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tiny_spec.parent / "options.toml").write_text("[clothoid]\nfrechet_threshold_m = nan\n")
    spec = write_spec(
        tiny_spec.parent, tiny_spec.read_text().replace("[grid]", 'controller_config = "options.toml"\n[grid]')
    )
    out = tmp_path / "out"
    assert main(["sweep", str(spec), "--out", str(out)]) == 2
    *warnings, err = capsys.readouterr().err.splitlines()  # the file has no [pure-pursuit] table: warned first
    assert all(w.startswith("workbench: warning: ") for w in warnings)
    assert err.startswith("workbench: error: spec ") and "options.toml" in err and "got nan" in err
    assert not out.exists()


@pytest.mark.parametrize(
    ("grid", "message"),
    [
        ("speed_kmh = [20, 0]", "grid.speed_kmh = 0.0: speed_kmh must be a finite number in [0.001, 400] km/h"),
        ("laps = [0]", "grid.laps = 0: laps must be a whole number >= 1; got 0"),
        (
            "initial_offset_m = [1000]",
            "grid.initial_offset_m = 1000.0: initial_offset_m must be a finite number in [-50, 50] m",
        ),
    ],
)
def test_a_value_every_run_would_refuse_stops_the_sweep_before_any_run(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], grid: str, message: str
) -> None:
    head = '[study]\nscenarios = ["dlc"]\ncontrollers = ["clothoid"]\nvehicles = ["kinematic-bicycle"]\n'
    spec = write_spec(tmp_path / "bad", f"{head}[grid]\n{grid}\n")
    for command in ("sweep", "optimise"):
        if command == "optimise":
            spec.write_text(
                f"{head}[grid]\n{grid}\n[optimise]\ntrials = 2\n[optimise.objective]\nrms_cte_m = 1.0\n"
                "[optimise.search]\nfrechet_threshold_m = {log_uniform = [0.01, 0.5]}\n"
            )
        assert main([command, str(spec), "--out", str(tmp_path / "out"), "--workers", "1"]) == 2
        err = capsys.readouterr().err
        assert err.startswith("workbench: error: spec ") and message in err and len(err.splitlines()) == 1
        assert not (tmp_path / "out").exists()


def test_max_runs(tiny_spec: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["sweep", str(tiny_spec), "--out", str(tmp_path / "out"), "--max-runs", "5"]) == 2
    assert "the study plans 10 runs" in capsys.readouterr().err
    assert main(["optimise", str(tiny_spec), "--out", str(tmp_path / "out"), "--max-runs", "0"]) == 2
    assert "--max-runs must be a whole number >= 1; got 0" in capsys.readouterr().err
    assert not (tmp_path / "out").exists()


def test_a_sweep_resumes_only_in_a_study_folder(tiny_spec: Path, tmp_path: Path, capsys) -> None:
    other = tmp_path / "documents"
    other.mkdir()
    (other / "thesis.tex").write_text("x")
    assert main(["sweep", str(tiny_spec), "--out", str(other)]) == 2
    assert "not a study's folder (no spec.toml or runs/)" in capsys.readouterr().err
    assert sorted(p.name for p in other.iterdir()) == ["thesis.tex"]
