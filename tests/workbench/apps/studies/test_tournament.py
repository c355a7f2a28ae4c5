"""The tournament end to end on three cheap controllers (pure pursuit, Stanley, the clothoid controller) on the
kinematic car, one short training case and one test case (under the automotive conditions, the controllers told
their delays), 3 trials: what it writes, that no trial runs a test
case, that a tournament killed mid-way resumes with nothing lost or redone and gives the same results bit for bit
(but the wall-clock columns) as one run straight through, and that a judged run's command reproduces it."""

from __future__ import annotations

import json
import shlex
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

import pandas as pd
import pytest
from study_helpers import NotSimulating, SerialBackend, write_spec

from controllers import CONTROLLERS
from tuning.own_tuning import tuning_for
from workbench.apps.cli import main
from workbench.apps.controller_config import read_controller_config
from workbench.apps.studies import TIMING_COLUMNS, DaskBackend, LocalBackend, PlannedRun
from workbench.apps.studies.backends import BackendError
from workbench.apps.studies.runner import ROW_METRICS
from workbench.apps.studies.tournament import (
    TournamentIsolationError,
    _check_isolation,
    pareto_front,
    run_command,
    run_failure,
    run_tournament,
    spread_points,
    trial_objectives,
    weighted,
    write_config_files,
)
from workbench.apps.studies.tournament_spec import load_tournament
from workbench.vehicles import make_vehicle

SPEC = """
[tournament]
controllers = ["pure-pursuit", "stanley", "clothoid"]
vehicles = ["kinematic-bicycle"]
trials = 3
batch_size = 2
front_points = 2
seed = 3

[train]
scenarios = ["dlc"]
speeds_kmh = [30]

[test]
scenarios = ["dlc"]
speeds_kmh = [40]
conditions = ["automotive"]
seeds = [1]
"""
CONTROLLER_NAMES = ("pure-pursuit", "stanley", "clothoid")


class CountingBackend(SerialBackend):
    """Runs in this process and counts them; with `fail_after`, the machinery fails after that many runs (a kill)."""

    def __init__(self, fail_after: int | None = None) -> None:
        super().__init__()
        self.ran = 0
        self.fail_after = fail_after

    def map_runs(self, runs: Sequence[PlannedRun]) -> Iterator[dict[str, Any]]:
        for row in super().map_runs(runs):
            if self.fail_after is not None and self.ran >= self.fail_after:
                raise BackendError("killed in this test")
            self.ran += 1
            yield row


@pytest.fixture(scope="module")
def tournament(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    """The tournament straight through (with its report), and the same one killed after 7 runs, then resumed."""
    folder = tmp_path_factory.mktemp("tournament")
    spec = load_tournament(write_spec(folder, SPEC))
    whole = run_tournament(spec, folder / "whole", CountingBackend(), log=None)
    killed = CountingBackend(fail_after=7)
    with pytest.raises(BackendError):
        run_tournament(spec, folder / "resumed", killed, report=False, log=None)
    resumed_backend = CountingBackend()
    resumed = run_tournament(spec, folder / "resumed", resumed_backend, report=False, log=None)
    return {
        "folder": folder,
        "spec": spec,
        "whole": whole,
        "resumed": resumed,
        "killed_ran": killed.ran,
        "resumed_ran": resumed_backend.ran,
    }


def comparable(frame: pd.DataFrame, out: Path) -> pd.DataFrame:
    """The frame without its wall-clock columns, its commands' output folder written as OUT."""
    frame = frame.drop(columns=[c for c in TIMING_COLUMNS if c in frame.columns])
    if "command" in frame.columns:
        frame = frame.assign(command=frame["command"].str.replace(str(out.resolve()), "OUT", regex=False))
    return frame


def test_the_tournament_trains_judges_and_writes(tournament: dict[str, Any]) -> None:
    spec, result = tournament["spec"], tournament["whole"]
    out = tournament["folder"] / "whole"
    history, results = result.history, result.results
    assert list(history["controller"]) == [c for c in CONTROLLER_NAMES for _ in range(3)]
    assert list(history["trial"]) == [0, 1, 2] * 3
    assert pd.read_parquet(out / "history.parquet").equals(history)
    for controller in CONTROLLER_NAMES:
        own = history[history["controller"] == controller].set_index("trial")
        # trial 0 is the shipped defaults
        assert json.loads(own.loc[0, "params_json"]) == pytest.approx(dict(spec.defaults[controller]))
        chosen = result.chosen[controller]
        assert own["chosen"].sum() == 1 and own.loc[chosen, "chosen"] and own.loc[chosen, "pareto"]

        def score(trial: int, own: pd.DataFrame = own) -> float:
            return weighted([own.loc[trial, f"train_{m}"] for m in spec.objectives], spec.objectives, spec.selection)

        # the chosen trial is no worse than the default on the training objective, nor than any front point
        assert score(chosen) <= score(0)
        assert all(score(chosen) <= score(t) for t in own.index[own["pareto"]])
        carried = own["carried"].dropna()
        assert sorted(carried) == list(range(1, len(carried) + 1)) and len(carried) <= spec.front_points
        # carried: the front's other points, the default and the chosen trial being judged under their own names
        assert set(carried.index) <= set(own.index[own["pareto"]]) - {0, chosen}
        assert (own["runs"] == 1).all() and (own["cpu_time_s"] > 0).all()
        # its judged configurations: default (trial 0), tuned (the chosen trial), the carried points
        test = results[(results["controller"] == controller) & (results["set"] == "test")]
        configs = dict(zip(test["config"], test["trial"], strict=True))
        assert configs == {"default": 0, "tuned": chosen} | {f"front-{int(k)}": t for t, k in carried.items()}
        best = read_controller_config(
            out / "best" / f"{controller}.toml", controller, CONTROLLERS[controller].config_type
        )
        for key, value in json.loads(own.loc[chosen, "params_json"]).items():
            if hasattr(best, key):
                assert getattr(best, key) == value
    assert (results["cpu_time_s"] > 0).all()  # the runner's CPU time of each run
    assert set(results["failed"]) == {False} and set(results["failure"]) == {""}
    assert results.loc[results["set"] == "train", "command"].isna().all()
    assert results.loc[results["set"] == "test", "command"].str.startswith("workbench run dlc --controller ").all()
    assert result.report == out / "report.html" and result.report.stat().st_size > 10_000
    summary = json.loads((out / "tournament.json").read_text())
    assert summary["test_cases"] == ["dlc|kinematic-bicycle|40|automotive|1"]
    assert summary["train_cases"] == ["dlc|kinematic-bicycle|30|ideal|0"]
    assert summary["test_cases_run_by_trials"] == []


def test_no_trial_ever_runs_a_test_case(tournament: dict[str, Any]) -> None:
    results = tournament["whole"].results
    trials = results[results["config"] == "trial"]
    judged = results[results["config"] != "trial"]
    assert (trials["set"] == "train").all() and (judged["set"] == "test").all()
    assert not set(trials["case"]) & set(judged["case"])
    assert not set(trials["run_id"]) & set(judged["run_id"])
    rows = [{"set": "train", "case": "a"}, {"set": "test", "case": "a"}]
    with pytest.raises(TournamentIsolationError, match="training trials ran test case"):
        _check_isolation(rows)


def test_a_killed_tournament_resumes_with_nothing_lost_or_redone(tournament: dict[str, Any]) -> None:
    whole, resumed = tournament["whole"], tournament["resumed"]
    distinct = whole.results["run_id"].nunique()
    assert tournament["killed_ran"] == 7
    assert tournament["resumed_ran"] == distinct - 7 == resumed.ran
    # same seed, same result: bit for bit but the wall-clock columns (and where the commands' files are)
    pd.testing.assert_frame_equal(
        comparable(resumed.results, tournament["folder"] / "resumed"),
        comparable(whole.results, tournament["folder"] / "whole"),
        check_exact=True,
    )
    pd.testing.assert_frame_equal(
        comparable(resumed.history, Path()), comparable(whole.history, Path()), check_exact=True
    )
    again = CountingBackend()
    run_tournament(tournament["spec"], tournament["folder"] / "resumed", again, report=False, log=None)
    assert again.ran == 0


def test_a_judged_runs_command_reproduces_it_bit_for_bit(
    tournament: dict[str, Any], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    results = tournament["whole"].results
    row = results[(results["controller"] == "clothoid") & (results["config"] == "tuned")].iloc[0]
    words = shlex.split(row["command"])
    assert words[:2] == ["workbench", "run"] and "--inform-delays" in words
    assert words[words.index("--conditions") + 1] == "automotive" and words[words.index("--seed") + 1] == "1"
    monkeypatch.chdir(tmp_path)
    assert main([*words[1:], "--no-plots"]) == 0
    metrics = json.loads((tmp_path / "replay" / row["run_id"] / "metrics.json").read_text())
    for key in ROW_METRICS:
        if key not in TIMING_COLUMNS:
            assert metrics[key] == row[key] or (metrics[key] is None and pd.isna(row[key])), key


def test_a_judged_run_on_a_circuit_under_a_sets_ranges_replays_bit_for_bit(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The command of a run on a circuit drawn within the test set's circuit_ranges names the ranges file, and
    replays the run exactly (a circuit under the default ranges would be another path)."""
    from workbench.apps.studies import execute_run

    ranges = "[circuits]\nmin_radius_m = 12.0\nmax_radius_m = 20.0\nmax_curvature_rate_1pm2 = 0.02\n"
    ranges += "offtracking_length_m = 0.0\nclearance_m = 14.0\nmin_length_m = 150.0\nmax_length_m = 400.0\n"
    write_spec(tmp_path / "spec" / "circuits", ranges, "small.toml")
    text = SPEC.replace('scenarios = ["dlc"]\nspeeds_kmh = [40]', 'scenarios = ["circuit:7"]\nspeeds_kmh = [30]')
    spec = load_tournament(write_spec(tmp_path / "spec", text + 'circuit_ranges = "circuits/small.toml"\n'))
    options = {"gain_per_s": 2.5}
    (run,) = spec.plan("stanley", "test", options)
    files = write_config_files(spec, "stanley", options, tmp_path / "best", "stanley", "a test's configuration")
    row = execute_run(run)
    assert row["status"] == "completed" and row["path_length_m"] < 400.0
    words = shlex.split(run_command(run, files[run.vehicle]))
    assert words[words.index("--circuit-ranges") + 1] == str(tmp_path / "spec" / "circuits" / "small.toml")
    assert "--inform-delays" in words and words[words.index("--conditions") + 1] == "automotive"
    monkeypatch.chdir(tmp_path)
    assert main([*words[1:], "--no-plots"]) == 0
    metrics = json.loads((tmp_path / "replay" / run.run_id / "metrics.json").read_text())
    for key in ROW_METRICS:
        if key not in TIMING_COLUMNS:
            assert metrics[key] == row[key], key


def test_the_cli_runs_a_tournament_and_prints_its_leaderboard(
    tournament: dict[str, Any], capsys: pytest.CaptureFixture[str]
) -> None:
    folder = tournament["folder"]
    capsys.readouterr()
    # resumed from the finished tournament's folder: every run is found, none run again
    assert main(["tournament", str(folder / "spec.toml"), "--out", str(folder / "whole"), "--workers", "1"]) == 0
    printed = capsys.readouterr().out
    assert "3 controllers x 3 trials on 1 training case, judged on 1 test case" in printed
    assert "(0 run now)" in printed
    for controller in CONTROLLER_NAMES:
        assert controller in printed


def test_trial_objectives_and_failures() -> None:
    row = {"scenario": "dlc", "vehicle": "v", "speed_kmh": 30.0, "conditions": "ideal", "seed": 0}
    ok = row | {"status": "completed", "message": "", "rms_cte_m": 0.1, "left_track": False, "limit_cycle": False}
    assert run_failure(ok) == ""
    assert trial_objectives([ok, ok | {"rms_cte_m": 0.3}], ["rms_cte_m"]) == ([pytest.approx(0.2)], "")
    off = ok | {"status": "left_path", "message": "|CTE| > 30 m"}
    assert run_failure(off) == "did not complete (left_path: |CTE| > 30 m)"
    assert run_failure(ok | {"left_track": True, "min_track_margin_m": -0.5}) == "left the track (least margin -0.5 m)"
    wide = ok | {"max_abs_cte_on_path_m": 1.5}
    assert run_failure(wide) == "left the path (max |CTE| once on it 1.5 m > 1 m)"
    assert run_failure(wide, off_path_m=2.0) == "" and run_failure(ok | {"max_abs_cte_on_path_m": 1.0}) == ""
    cycle = ok | {"limit_cycle": True, "limit_cycle_hz": 2.5, "limit_cycle_amplitude_deg": 1.0}
    assert run_failure(cycle) == "limit cycle (2.5 Hz, 1.0 deg)"
    values, reason = trial_objectives([ok, cycle], ["rms_cte_m"])
    assert values is None and reason == "1 of 2 runs failed (e.g. dlc|v|30|ideal|0: limit cycle (2.5 Hz, 1.0 deg))"
    values, reason = trial_objectives([ok | {"rms_cte_m": None}], ["rms_cte_m"])
    assert values is None and reason == "metric rms_cte_m is None for dlc|v|30|ideal|0"


def test_the_front_and_its_spread() -> None:
    points = {0: [1.0, 5.0], 1: [2.0, 4.0], 2: [2.0, 6.0], 3: [3.0, 1.0], 4: [1.5, 4.5], 5: [4.0, 0.5]}
    front = pareto_front(points)
    assert front == [0, 1, 3, 4, 5]  # 2 is dominated by 1 (and 0)
    assert spread_points(front, points, 3) == [5, 1, 0]  # by the last objective: the ends and the middle
    assert spread_points(front, points, 9) == [5, 3, 1, 4, 0]
    assert spread_points(front, points, 0) == []


def test_a_controller_whose_every_trial_fails_is_judged_with_its_defaults(tmp_path: Path) -> None:
    spec = load_tournament(write_spec(tmp_path, SPEC.replace('"stanley", "clothoid"]', '"stanley"]')))
    backend = NotSimulating()  # every run an error row: every trial fails
    result = run_tournament(spec, tmp_path / "out", backend, log=None)
    history = result.history
    assert (history["state"] == "failed").all() and not history["pareto"].any() and not history["chosen"].any()
    assert set(history["reason"]) == {
        "1 of 1 runs failed (e.g. dlc|kinematic-bicycle|30|ideal|0: did not complete (error: not simulated in this "
        "test))"
    }
    assert result.chosen == {"pure-pursuit": None, "stanley": None}
    test = result.results[result.results["set"] == "test"]
    assert list(test["config"]) == ["default", "tuned"] * 2 and (test["trial"] == 0).all() and test["failed"].all()
    board = result.judgement.leaderboard  # judged and reported all the same: every run scores the failure score
    assert set(board["controller"]) == {"pure-pursuit", "stanley"} and (board["score"] == spec.failure_score).all()
    assert result.report.is_file()


def test_a_configuration_scaled_from_each_vehicles_filter_gets_a_file_per_vehicle(tmp_path: Path) -> None:
    text = SPEC.replace('"stanley", "clothoid"]', '"clothoid"]').replace(
        '["kinematic-bicycle"]', '["kinematic-bicycle", "dynamic-bicycle"]'
    )
    spec = load_tournament(write_spec(tmp_path, text))
    scaled = write_config_files(spec, "clothoid", {"lead_filter_pole_scale": 1.2}, tmp_path / "best", "clothoid", "h")
    assert scaled == {
        "kinematic-bicycle": (tmp_path / "best" / "clothoid.toml").resolve(),
        "dynamic-bicycle": (tmp_path / "best" / "clothoid@dynamic-bicycle.toml").resolve(),
    }
    config_type = CONTROLLERS["clothoid"].config_type
    for vehicle, path in scaled.items():
        own = tuning_for(make_vehicle(vehicle)).filter_schedule
        lead = read_controller_config(path, "clothoid", config_type).lead_filter
        assert [p.omega_p_rad_s for p in lead.params] == [p.omega_p_rad_s * 1.2 for p in own.params]
    assert (tmp_path / "best" / "clothoid@dynamic-bicycle_lead_filter.json").is_file()
    # unscaled, the configuration is the same for both vehicles (each run adds its own tuning): one file
    plain = write_config_files(spec, "clothoid", {"frechet_threshold_m": 0.05}, tmp_path / "plain", "clothoid", "h")
    assert set(plain.values()) == {(tmp_path / "plain" / "clothoid.toml").resolve()}


@pytest.mark.parametrize("backend", ["local", "dask"])
def test_two_workers_on_either_backend_give_the_same_tournament(tournament: dict[str, Any], backend: str) -> None:
    out = tournament["folder"] / backend
    workers = LocalBackend(workers=2) if backend == "local" else DaskBackend(workers=2)
    pooled = run_tournament(tournament["spec"], out, workers, report=False, log=None)
    whole = tournament["whole"]
    pd.testing.assert_frame_equal(
        comparable(pooled.results, out), comparable(whole.results, tournament["folder"] / "whole"), check_exact=True
    )
    pd.testing.assert_frame_equal(comparable(pooled.history, out), comparable(whole.history, out), check_exact=True)
