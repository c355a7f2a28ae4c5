"""`--conditions` and `--seed` on run, compare and fig17; `workbench conditions`; conditions as study
parameters (issue 18, item 2)."""

from __future__ import annotations

import json
from pathlib import Path

import pandas as pd
import pytest

from workbench.apps.cli import main
from workbench.apps.studies import load_spec
from workbench.apps.studies.condition_parameters import CONDITION_FIELDS, run_conditions
from workbench.base.errors import WorkbenchInputError
from workbench.simulation.conditions import CONDITIONS, load_conditions


def test_conditions_lists_the_presets_and_shows_one_as_a_file_that_reads_back(tmp_path: Path, capsys) -> None:
    assert main(["conditions"]) == 0
    listing = capsys.readouterr().out
    assert all(name in listing for name in CONDITIONS)
    assert main(["conditions", "--show", "automotive"]) == 0
    path = tmp_path / "mine.toml"
    path.write_text(capsys.readouterr().out)
    assert load_conditions(str(path)) == CONDITIONS["automotive"]


def test_run_with_conditions_and_seed_records_them_and_the_seen_signals(tmp_path: Path, capsys) -> None:
    args = ["run", "dlc", "--vehicle", "dynamic-bicycle", "--no-plots", "--conditions", "rtk"]
    assert main([*args, "--seed", "3", "--out", str(tmp_path / "a")]) == 0
    assert main([*args, "--seed", "3", "--out", str(tmp_path / "b")]) == 0
    metrics = json.loads((tmp_path / "a" / "metrics.json").read_text())
    assert metrics["conditions"] == "rtk" and metrics["seed"] == 3
    a, b = (pd.read_parquet(tmp_path / d / "trace.parquet") for d in "ab")
    assert {"seen_x_m", "applied_steer_wheel_cmd_rad"} <= set(a.columns)
    pd.testing.assert_frame_equal(a.drop(columns="step_time_s"), b.drop(columns="step_time_s"))
    # ideal (the default) writes what it wrote before conditions existed
    assert main(["run", "dlc", "--vehicle", "dynamic-bicycle", "--no-plots", "--out", str(tmp_path / "c")]) == 0
    assert "conditions" not in json.loads((tmp_path / "c" / "metrics.json").read_text())


@pytest.mark.parametrize(
    ("conditions", "needle"),
    [("rainy", "unknown conditions 'rainy'"), ("nowhere.toml", "nowhere.toml")],
)
def test_bad_conditions_exit_2_naming_them(conditions: str, needle: str, tmp_path: Path, capsys) -> None:
    code = main(["run", "dlc", "--conditions", conditions, "--out", str(tmp_path / "o")])
    assert code == 2 and needle in capsys.readouterr().err


def test_a_bad_conditions_file_names_the_field_and_the_range(tmp_path: Path, capsys) -> None:
    path = tmp_path / "bad.toml"
    path.write_text("[actuation]\ndead_time_s = -0.1\n")
    args = ["compare", "dlc", "--controllers", "stanley", "--vehicle", "dynamic-bicycle", "--conditions", str(path)]
    assert main([*args, "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "actuation.dead_time_s" in err and "-0.1" in err


def test_condition_fields_are_run_parameters_set_on_the_named_conditions() -> None:
    assert {"actuation_dead_time_s", "localisation_position_noise_m", "road_friction_scale"} <= set(CONDITION_FIELDS)
    changed = run_conditions("automotive", {"actuation_dead_time_s": 0.2, "localisation_latency_s": 0.05})
    assert changed.actuation.dead_time_s == 0.2 and changed.localisation.latency_s == 0.05
    assert changed.inertial == CONDITIONS["automotive"].inertial and changed.name == "automotive+"
    assert run_conditions(None, {}) == CONDITIONS["ideal"]


def test_a_study_grids_conditions_and_their_fields(tmp_path: Path) -> None:
    own = tmp_path / "own.toml"
    own.write_text('name = "own"\n[localisation]\nlatency_s = 0.05\n')
    spec = tmp_path / "spec.toml"
    spec.write_text(
        '[study]\nscenarios = ["dlc"]\ncontrollers = ["stanley"]\nvehicles = ["dynamic-bicycle"]\n'
        '[grid]\nconditions = ["ideal", "own.toml"]\nactuation_dead_time_s = [0.0, 0.1]\nseed = [1, 2]\n'
    )
    runs = load_spec(spec).plan()
    assert len(runs) == 8 and len({r.run_id for r in runs}) == 8
    assert {dict(r.values)["conditions"] for r in runs} == {"ideal", str(own.resolve())}
    spec.write_text(spec.read_text().replace("own.toml", "missing.toml"))
    with pytest.raises(WorkbenchInputError, match=r"missing\.toml"):
        load_spec(spec)
    spec.write_text(spec.read_text().replace('"missing.toml"', '"ideal2"'))
    with pytest.raises(WorkbenchInputError, match=r"unknown conditions 'ideal2': choose a preset \(ideal, "):
        load_spec(spec)
