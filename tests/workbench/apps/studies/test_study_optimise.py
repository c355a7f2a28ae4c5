"""Optimisation: the trial objective, the best options written as a controller-config file that `workbench run`
reads and that reproduces the best trial, and a restarted study replaying without new runs."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pandas as pd
import pytest
from study_helpers import SerialBackend, write_spec

from controllers import CONTROLLERS
from controllers.clothoid.filter_schedule import DEFAULT_FILTER, FilterSchedule
from tuning.filter_file import read_filter_file
from tuning.own_tuning import tuning_for
from workbench.apps.cli import main
from workbench.apps.controller_config import read_controller_config
from workbench.apps.studies import LocalBackend, load_spec, run_optimisation
from workbench.apps.studies.optimise import trial_value, write_controller_config
from workbench.vehicles import make_vehicle

SPEC = """
[study]
scenarios = ["dlc"]
controllers = ["clothoid"]
vehicles = ["kinematic-bicycle"]
seed = 5

[grid]
speed_kmh = 30

[grid.clothoid]
prediction_time_s = 0.1

[optimise]
trials = 4
batch_size = 2
startup_trials = 2

[optimise.objective]
rms_cte_m = 1.0
rms_steer_rate_deg_s = 0.002

[optimise.search]
frechet_threshold_m = { log_uniform = [0.005, 0.5] }
lead_filter_pole_scale = { uniform = [0.8, 1.5] }
"""


def test_trial_value() -> None:
    rows = [
        {"run_id": "a", "status": "completed", "rms_cte_m": 0.1, "max_ltr": None, "vehicle": "v", "scenario": "s"},
        {"run_id": "b", "status": "completed", "rms_cte_m": 0.3, "max_ltr": 0.5, "vehicle": "v", "scenario": "s"},
    ]
    assert trial_value(rows, {"rms_cte_m": 2.0}, "mean") == (pytest.approx(0.4), "")
    assert trial_value(rows, {"rms_cte_m": 2.0}, "max") == (pytest.approx(0.6), "")
    value, reason = trial_value(rows, {"max_ltr": 1.0}, "mean")
    assert value is None and "metric max_ltr is None for run a" in reason
    rows[0]["limit_cycle"], rows[1]["limit_cycle"] = True, False  # a penalty of 1 per run that limit-cycles
    assert trial_value(rows, {"rms_cte_m": 1.0, "limit_cycle": 0.5}, "mean") == (pytest.approx(0.45), "")
    rows[1] |= {"status": "left_path", "message": "|CTE| = 31 m exceeds max_abs_cte_m"}
    value, reason = trial_value(rows, {"rms_cte_m": 1.0}, "mean")
    assert (
        value is None and reason == "1 of 2 runs did not complete (e.g. left_path: |CTE| = 31 m exceeds max_abs_cte_m)"
    )


def test_the_config_writer_round_trips(tmp_path: Path) -> None:
    config_type = CONTROLLERS["clothoid"].config_type
    lead = FilterSchedule.single(DEFAULT_FILTER, source="a test filter")
    config = config_type(frechet_threshold_m=0.1 / 3, max_lookahead_growth_m_per_m=None, lead_filter=lead)
    path = write_controller_config(tmp_path / "best.toml", "clothoid", config, "header\nsecond line")
    assert path.read_text().startswith("# header\n# second line\n\n[clothoid]\n")
    # The object a file option was read into is written beside the config and named by that option.
    assert 'filter_file = "best_lead_filter.json"' in path.read_text()
    assert read_controller_config(path, "clothoid", config_type) == config


def test_optimise_writes_the_best_trial_as_a_config_that_workbench_run_reproduces(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    spec = load_spec(write_spec(tmp_path, SPEC), "optimise")
    out = tmp_path / "out"
    result = run_optimisation(spec, out, LocalBackend(workers=2))
    history = result.history
    assert list(history["trial"]) == [0, 1, 2, 3] and (history["state"] == "complete").all()
    assert result.ran == 4  # one run per trial
    best = history.loc[history["value"].idxmin()]
    assert result.best_trial == best["trial"] and result.best_value == best["value"]
    assert result.best_params == {
        "frechet_threshold_m": best["clothoid.frechet_threshold_m"],
        "lead_filter_pole_scale": best["clothoid.lead_filter_pole_scale"],
    }
    # each trial's value is its run's objective
    runs = pd.read_parquet(out / "results.parquet")
    for _, trial in history.iterrows():
        run = runs[runs["trial"] == trial["trial"]].iloc[0]
        assert trial["value"] == run["rms_cte_m"] + 0.002 * run["rms_steer_rate_deg_s"]
    document = json.loads((out / "best.json").read_text())
    assert document["trial"] == result.best_trial and document["params"] == result.best_params

    # the config file: the best options, the fixed one, and the scaled lead filter
    config = read_controller_config(out / "best.toml", "clothoid", CONTROLLERS["clothoid"].config_type)
    assert config.frechet_threshold_m == result.best_params["frechet_threshold_m"]
    assert config.prediction_time_s == 0.1
    scaled = config.lead_filter  # read from best_lead_filter.json, which best.toml names
    assert 'filter_file = "best_lead_filter.json"' in (out / "best.toml").read_text()
    assert scaled == read_filter_file(out / "best_lead_filter.json")
    own = tuning_for(make_vehicle("kinematic-bicycle")).filter_schedule  # the vehicle's own filter is the base
    assert scaled.speeds_kmh == own.speeds_kmh
    for lead, base in zip(scaled.params, own.params, strict=True):
        assert lead.omega_p_rad_s == base.omega_p_rad_s * result.best_params["lead_filter_pole_scale"]
        assert lead.omega_z_rad_s == base.omega_z_rad_s

    # `workbench run` with it gives the best trial's run, bit for bit
    args = ["run", "dlc", "--controller", "clothoid", "--vehicle", "kinematic-bicycle", "--speed", "30"]
    assert (
        main([*args, "--controller-config", str(out / "best.toml"), "--out", str(tmp_path / "run"), "--no-plots"]) == 0
    )
    metrics = json.loads((tmp_path / "run" / "metrics.json").read_text())
    assert metrics["rms_cte_m"] + 0.002 * metrics["rms_steer_rate_deg_s"] == result.best_value

    # a restart replays the seeded sampler and finds every run done
    again = run_optimisation(spec, out, SerialBackend())
    assert again.ran == 0 and again.best_trial == result.best_trial
    pd.testing.assert_frame_equal(again.history, history)
    capsys.readouterr()
    assert main(["optimise", str(tmp_path / "spec.toml"), "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "4 trials (0 failed); 0 runs run now" in printed
    assert f"best: trial {result.best_trial}, objective {result.best_value:.6g}" in printed
    assert math.isfinite(result.best_value) and (out / "history.png").stat().st_size > 10_000
