"""Sweeps end to end: the local pool and Dask give the same rows bit for bit (but the wall-clock columns); a failing
run is a row with its error; a sweep killed part-way resumes without redoing its finished runs."""

from __future__ import annotations

import multiprocessing
import os
import re
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import pytest
from study_helpers import SerialBackend, assert_same_results, write_spec

from workbench.apps.cli import main
from workbench.apps.studies import DaskBackend, LocalBackend, SweepResult, execute_run, load_spec, run_sweep
from workbench.apps.studies.backends import BackendError
from workbench.apps.studies.plots import pareto_mask


@pytest.fixture(scope="module")
def local_sweep(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, SweepResult]:
    """The tiny study on the local pool of 2 workers (study_helpers.TINY_SPEC: 10 runs, 2 of them failing)."""
    from study_helpers import TINY_SPEC

    folder = tmp_path_factory.mktemp("local")
    spec = write_spec(folder, TINY_SPEC)
    return spec, run_sweep(load_spec(spec), folder / "out", LocalBackend(workers=2))


def test_the_results_table_has_a_row_per_run_with_real_values(local_sweep: tuple[Path, SweepResult]) -> None:
    spec_path, result = local_sweep
    table = pd.read_parquet(result.out_dir / "results.parquet")
    assert_same_results(table, result.table)
    runs = load_spec(spec_path).plan()
    assert list(table["run_id"]) == [r.run_id for r in runs] and result.ran == 10
    clothoid = ["completed", "completed", "error", "completed"]  # (min, max) lookahead (5, 20), (5, 31), (30, 20), ...
    assert list(table["status"]) == ["completed"] * 2 + clothoid * 2
    # each row holds exactly what its run gives when executed here
    for run, (_, row) in zip(runs, table.iterrows(), strict=True):
        if row["status"] == "completed":
            direct = execute_run(run)
            assert row["rms_cte_m"] == direct["rms_cte_m"] and row["max_abs_cte_m"] == direct["max_abs_cte_m"]
            assert 0.0 < row["max_abs_cte_m"] < 0.5
    assert table.loc[table["controller"] == "pure-pursuit", "clothoid.min_lookahead_m"].isna().all()
    done = table[table["status"] == "completed"]
    assert (done["steer_oscillation_deg"] > 0).all() and done["limit_cycle"].eq(False).all()
    assert table["limit_cycle_hz"].isna().all() and table["limit_cycle_amplitude_deg"].isna().all()


def test_a_failing_run_is_recorded_with_its_error(local_sweep: tuple[Path, SweepResult]) -> None:
    _, result = local_sweep
    errors = result.errors()
    assert len(errors) == 2 and set(errors["clothoid.min_lookahead_m"]) == {30.0}
    assert set(errors["clothoid.max_lookahead_m"]) == {20.0}
    for message in errors["message"]:
        assert message.startswith("WorkbenchInputError: max_lookahead_m must be") and "30.0" in message
    assert errors["completed"].eq(False).all() and errors["rms_cte_m"].isna().all()
    assert result.status_counts() == {"completed": 8, "error": 2}
    summary = result.summary().set_index("controller")
    assert summary.loc["clothoid", "errors"] == 2 and summary.loc["pure-pursuit", "completed"] == 2
    assert (summary["limit_cycles"] == 0).all() and (summary["median_steer_oscillation_deg"] > 0).all()


def test_dask_gives_the_local_results_bit_for_bit(local_sweep: tuple[Path, SweepResult], tmp_path: Path) -> None:
    spec_path, local = local_sweep
    dask = run_sweep(load_spec(spec_path), tmp_path, DaskBackend(workers=2))
    assert dask.ran == 10
    assert_same_results(dask.table, local.table)
    assert (dask.table["step_time_median_us"] != local.table["step_time_median_us"]).any()  # wall clock: differs


def test_a_restarted_sweep_runs_only_what_is_missing(local_sweep: tuple[Path, SweepResult], tmp_path: Path) -> None:
    spec_path, local = local_sweep
    out = tmp_path / "out"
    shutil.copytree(local.out_dir, out)
    (out / "results.parquet").unlink()
    ids = list(local.table["run_id"])
    for run_id in (ids[1], ids[4]):  # as if killed before these two finished
        (out / "runs" / f"{run_id}.json").unlink()
    (out / "runs" / f".{ids[1]}.99.tmp").write_text('{"run_id"')  # a write the kill cut short
    backend = SerialBackend()
    resumed = run_sweep(load_spec(spec_path), out, backend)
    assert backend.given == [[ids[1], ids[4]]] and resumed.ran == 2
    assert_same_results(resumed.table, local.table)
    again = SerialBackend()
    assert run_sweep(load_spec(spec_path), out, again).ran == 0 and again.given == []


KILL_SPEC = """
[study]
scenarios = ["dlc"]
controllers = ["pure-pursuit"]
vehicles = ["kinematic-bicycle"]

[grid]
speed_kmh = [15, 20, 25, 30, 35, 40]
initial_offset_m = [0.0, 0.5]
"""


def test_a_killed_sweep_resumes_and_matches_an_uninterrupted_one(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    spec = write_spec(tmp_path, KILL_SPEC)
    out = tmp_path / "out"
    command = [sys.executable, "-m", "workbench.apps.cli", "sweep", str(spec), "--out", str(out), "--workers", "1"]
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 120
    while not list((out / "runs").glob("*.json")) and time.monotonic() < deadline and process.poll() is None:
        time.sleep(0.01)
    process.send_signal(signal.SIGTERM)
    _, stderr = process.communicate(timeout=120)
    assert process.returncode == 130, stderr
    assert "interrupted" in stderr and "rerun to resume" in stderr
    done = len(list((out / "runs").glob("*.json")))
    assert 1 <= done < 12, "the sweep was not stopped part-way"
    assert not (out / "results.parquet").exists()

    capsys.readouterr()
    assert main(["sweep", str(spec), "--out", str(out), "--workers", "2"]) == 0
    printed = capsys.readouterr().out
    assert f"12 runs ({done} already done, {12 - done} run now): 12 completed" in printed
    assert (out / "spec.toml").read_text() == KILL_SPEC
    assert (out / "cte_vs_speed.png").is_file() and (out / "pareto.png").is_file()
    uninterrupted = run_sweep(load_spec(spec), tmp_path / "reference", SerialBackend())
    assert_same_results(SweepResult.load(out).table, uninterrupted.table)


def test_the_figures(local_sweep: tuple[Path, SweepResult], tmp_path: Path) -> None:
    import matplotlib.pyplot as plt

    _, result = local_sweep
    done = result.table[result.table["status"] == "completed"]
    ax = result.plot_cte_vs_speed()
    lines = {line.get_label(): line for line in ax.get_lines()}
    assert set(lines) == {"pure-pursuit (median)", "clothoid (median)"}
    pp = done[done["controller"] == "pure-pursuit"].groupby("speed_kmh")["rms_cte_m"].median()
    assert list(lines["pure-pursuit (median)"].get_xdata()) == list(pp.index)
    assert list(lines["pure-pursuit (median)"].get_ydata()) == list(pp)
    plt.close(ax.figure)
    ax = result.plot_pareto()
    front = {line.get_label(): line for line in ax.get_lines()}["pure-pursuit front"]
    pp_runs = done[done["controller"] == "pure-pursuit"]
    on_front = pp_runs[pareto_mask(pp_runs["rms_steer_rate_deg_s"], pp_runs["rms_cte_m"])]
    assert sorted(front.get_xdata()) == sorted(on_front["rms_steer_rate_deg_s"])
    plt.close(ax.figure)
    written = result.save_figures(tmp_path)
    assert [p.name for p in written] == ["cte_vs_speed.png", "pareto.png"]
    assert all(p.stat().st_size > 10_000 for p in written)


def test_the_report_shows_what_was_swept_the_runs_and_the_fronts_with_their_swept_values(
    local_sweep: tuple[Path, SweepResult], tmp_path: Path
) -> None:
    import matplotlib.pyplot as plt

    _, result = local_sweep
    assert result.swept() == ["speed_kmh", "clothoid.min_lookahead_m", "clothoid.max_lookahead_m"]  # not the fixed
    page = result.report_html("Sweep: tiny")
    assert page.startswith("<!DOCTYPE html>") and "<title>Sweep: tiny</title>" in page
    assert "10 runs: 8 completed, 2 error. Swept: speed_kmh: 20, 30; clothoid.min_lookahead_m: 5, 30; " in page
    assert "clothoid.max_lookahead_m: 20, 31." in page
    assert page.count("<tr>") == 1 + 2 + 1 + 10 + 1 + len(result.pareto_fronts())  # summary, runs, fronts
    assert "max_lookahead_m must be &gt;= min_lookahead_m" in page  # the error's message
    captions = re.findall(r"<figcaption>([^<]*)</figcaption>", page)
    assert captions[:3] == [f"RMS CTE against {c}" for c in result.swept()]
    assert len(captions) == 4 and captions[3].startswith("Tracking error against steering effort")
    fronts = result.pareto_fronts()
    clothoid = fronts[fronts["series"] == "clothoid"]
    assert list(clothoid["point"]) == list(range(1, len(clothoid) + 1))
    assert clothoid["swept values"].str.contains("min_lookahead_m=").all()
    assert fronts.loc[fronts["series"] == "pure-pursuit", "swept values"].str.fullmatch(r"speed_kmh=\d+").all()
    ax = result.plot_pareto()
    numbers = sorted(t.get_text() for t in ax.texts)
    assert numbers == sorted(str(p) for p in fronts["point"])  # each front point numbered as in the table
    plt.close(ax.figure)
    path = result.save_report(tmp_path, "Sweep: tiny")
    assert path == tmp_path / "report.html" and "data:image/png;base64," in path.read_text()


def test_pareto_mask() -> None:
    x = [1.0, 2.0, 3.0, 2.0, 4.0, float("nan"), 1.0]
    y = [5.0, 3.0, 1.0, 4.0, 1.0, 0.0, 6.0]
    # (2, 4) is beaten by (2, 3); (4, 1) by (3, 1); (1, 6) by (1, 5); NaN is never on the front
    assert list(pareto_mask(x, y)) == [True, True, True, False, False, False, False]


def test_a_dead_worker_stops_the_study_with_a_clear_error(tiny_spec: Path) -> None:
    runs = load_spec(tiny_spec).plan()
    others = {child.pid for child in multiprocessing.active_children()}
    with LocalBackend(workers=1) as backend:
        rows = backend.map_runs(runs)
        assert next(rows)["run_id"] == runs[0].run_id
        workers = [c.pid for c in multiprocessing.active_children() if c.pid not in others]
        assert len(workers) == 1
        os.kill(workers[0], signal.SIGKILL)
        with pytest.raises(BackendError, match="a worker process died"):
            list(rows)
