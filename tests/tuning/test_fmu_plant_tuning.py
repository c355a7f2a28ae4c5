"""The tuning chain on a plant from an FMU (the example FMU of CommonRoad's single track, tests/conftest.py): the
clothoid controller's own tuning is made on first use exactly as for a shipped vehicle file, and the FMU's content
is part of the vehicle's identity.

Shortened for the test suite (QUICK): the lag identified and the lead filter designed at one speed, 40 km/h, instead
of the shipped options' schedule, and the curvature limits at 10, 50 and 100 km/h; everything else is the shipped
options' (`tuning.preset_tuning.PRESET_TUNING_OPTIONS`). The full chain on this FMU took 46 s by hand."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from fmu_plant_files import write_fmu_vehicle_file
from quick_tuning import QUICK

from tuning import preset_tuning
from tuning.own_tuning import cache_key, tuning_for
from tuning.tuning_dirs import VEHICLE_FILE, params_sha256
from workbench.apps.cli import main
from workbench.vehicles import load_vehicle
from workbench.vehicles.presets import params_from_toml

pytestmark = pytest.mark.usefixtures("private_cache")  # no test reads or writes the user's cache


def test_an_fmu_plant_is_tuned_on_first_use_into_the_cache(example_plant_fmus, private_cache, capsys) -> None:
    plant = load_vehicle(str(example_plant_fmus["2"]))
    tuning = tuning_for(plant, QUICK)
    directory = private_cache / cache_key(plant, QUICK)
    assert str(directory) in tuning.source
    assert "no clothoid-controller tuning yet for this fmu" in capsys.readouterr().err
    assert tuning.filter_schedule.speeds_kmh == (40.0,)
    # The cache's vehicle file reads back as this plant, so the recorded tuning commands can be re-run by hand.
    assert params_from_toml((directory / VEHICLE_FILE).read_text(), "x")[1] == plant.params
    assert tuning_for(plant, QUICK) == tuning  # read from the cache the second time


def test_another_fmu_behind_the_same_vehicle_file_is_another_vehicle(example_plant_fmus, tmp_path) -> None:
    plant = load_vehicle(str(example_plant_fmus["2"]))
    fmu = Path(plant.params.fmu_file)
    other = tmp_path / "other.fmu"
    shutil.copyfile(fmu, other)
    with open(other, "ab") as handle:  # the same archive with a different byte at its end: another file
        handle.write(b"\0")
    twin = load_vehicle(str(write_fmu_vehicle_file(fmu, tmp_path / "twin.toml")))
    changed = load_vehicle(str(write_fmu_vehicle_file(other, tmp_path / "changed.toml")))
    assert params_sha256(twin) == params_sha256(plant)
    assert params_sha256(changed) != params_sha256(plant)


def test_workbench_run_clothoid_on_an_fmu_vehicle_file_builds_its_tuning(
    example_plant_fmus, tmp_path, monkeypatch, capsys
) -> None:
    monkeypatch.setattr(preset_tuning, "PRESET_TUNING_OPTIONS", QUICK)  # the shortened chain (module docstring)
    out = tmp_path / "run"
    args = ["run", "dlc", "--controller", "clothoid", "--vehicle-file", str(example_plant_fmus["2"])]
    assert main([*args, "--out", str(out), "--no-plots"]) in (0, None)
    captured = capsys.readouterr()
    assert "tuning of this fmu done" in captured.err
    assert "clothoid on fmu at 30 km/h -> completed" in captured.out
    metrics = json.loads((out / "metrics.json").read_text())
    assert metrics["max_abs_cte_m"] < 0.05  # measured 0.004 m with the full chain, 30 km/h
