"""benchmarks/fmu_plant.py: the plant step through FMI against the native model, and the truck's dlc through an
FMU plant end to end (few calls here: the numbers are the benchmark's, the test checks what they are made of)."""

from __future__ import annotations

import math

import pytest


def test_the_plant_step_entries_time_the_native_model_and_both_fmi_versions(fmu_plant, tmp_path) -> None:
    entries = fmu_plant.plant_step_entries(tmp_path, calls=100, rounds=1)
    names = [e.name for e in entries]
    assert names[0].startswith("CommonRoad single track, native")
    assert sum("FMI 2.0 (PythonFMU)" in n for n in names) == sum("FMI 3.0 (pythonfmu3)" in n for n in names) == 2
    native = entries[0].median_us
    for entry in entries[1:-1]:
        assert entry.median_us > 0.0 and entry.overhead_us == pytest.approx(entry.median_us - native)
    goals = [e for e in entries if e.goal is not None]
    assert len(goals) == 1 and "PythonFMU" in goals[0].name and "in a run" in goals[0].name
    assert goals[0].goal_met == (goals[0].overhead_us <= fmu_plant.OVERHEAD_GOAL_US)
    assert entries[-1].median_us is None and "not measured" in entries[-1].note  # no C FMU here


def test_the_truck_dlc_through_its_fmu_is_the_native_trucks_run(fmu_plant, tmp_path) -> None:
    entries, comparison = fmu_plant.truck_dlc_entries(tmp_path)
    assert all(e.note.startswith("completed") and e.wall_s > 0.0 for e in entries)
    assert comparison["rows_native"] == comparison["rows_fmu"] > 500
    # The same compiled truck stepped 1 ms at a time inside the FMU as in 20-step calls natively: the same RK4
    # steps, so the same run to rounding (measured: identical).
    for name in ("x_m", "y_m", "cte_m", "steer_wheel_rad", "ltr", "articulation_rad"):
        assert math.isfinite(comparison[name]) and comparison[name] <= 1e-9, name
