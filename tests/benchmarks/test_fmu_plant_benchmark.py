"""benchmarks/fmu_plant.py: the plant step through FMI against the native model, and the truck's dlc through an
FMU plant end to end (few calls here: the numbers are the benchmark's, the test checks what they are made of)."""

from __future__ import annotations

import math
import shutil

import numpy as np
import pytest


def test_the_plant_step_entries_time_the_native_model_and_both_fmi_versions(fmu_plant, tmp_path) -> None:
    entries = fmu_plant.plant_step_entries(tmp_path, calls=100, rounds=1)
    names = [e.name for e in entries]
    assert names[0].startswith("CommonRoad single track, native")
    assert sum("FMI 2.0 (PythonFMU)" in n for n in names) == sum("FMI 3.0 (pythonfmu3)" in n for n in names) == 2
    native = entries[0].median_us
    for entry in entries[1:5]:  # the Python FMUs: the overhead is the difference from the same model natively
        assert entry.median_us > 0.0 and entry.overhead_us == pytest.approx(entry.median_us - native)
    goals = [e for e in entries if e.goal is not None]
    assert len(goals) == 1 and "PythonFMU" in goals[0].name and "in a run" in goals[0].name
    assert goals[0].goal_met == (goals[0].overhead_us <= fmu_plant.OVERHEAD_GOAL_US)
    c_entries = [e for e in entries if "(C, " in e.name]
    if shutil.which("cc") or shutil.which("gcc"):
        assert len(c_entries) == 2 and all(e.median_us > 0.0 and e.overhead_us is None for e in c_entries)
    else:
        assert len(c_entries) == 1 and "not measured" in c_entries[0].note


@pytest.mark.skipif(not (shutil.which("cc") or shutil.which("gcc")), reason="no C compiler")
def test_the_c_fmu_is_the_example_model_ported(fmu_plant, example_plant_fmus, tmp_path) -> None:
    """The benchmark's C FMU runs the dlc closed loop as the example's PythonFMU FMU does, to rounding: the same
    formulas, from the same CommonRoad parameters, in C (measured: identical to the last bit here)."""
    from fmu_plant_files import write_fmu_vehicle_file

    from controllers import PurePursuit
    from workbench.simulation.scenarios import ScenarioOptions, make_scenario
    from workbench.simulation.simulator import Simulation, SimulationConfig
    from workbench.vehicles import load_vehicle

    c_plant = load_vehicle(str(write_fmu_vehicle_file(fmu_plant.build_c_fmu(tmp_path), tmp_path / "c.toml")))
    python_plant = load_vehicle(str(example_plant_fmus["2"]))
    traces = []
    for plant in (c_plant, python_plant):
        scenario = make_scenario("dlc", ScenarioOptions(vehicle_width_m=plant.geometry.width_m))
        config = SimulationConfig(speed_kmh=60.0)
        traces.append(Simulation(scenario, plant, PurePursuit(plant.geometry), config).run().trace)
    assert traces[0]["t_s"].size == traces[1]["t_s"].size > 300
    for name in ("x_m", "y_m", "yaw_rad", "vy_mps", "yaw_rate_rad_s", "steer_wheel_rad", "lat_accel_mps2"):
        assert np.max(np.abs(traces[0][name] - traces[1][name])) <= 1e-9, name


def test_the_truck_dlc_through_its_fmu_is_the_native_trucks_run(fmu_plant, tmp_path) -> None:
    entries, comparison = fmu_plant.truck_dlc_entries(tmp_path)
    assert all(e.note.startswith("completed") and e.wall_s > 0.0 for e in entries)
    assert comparison["rows_native"] == comparison["rows_fmu"] > 500
    # The same compiled truck stepped 1 ms at a time inside the FMU as in 20-step calls natively: the same RK4
    # steps, so the same run to rounding (measured: identical).
    for name in ("x_m", "y_m", "cte_m", "steer_wheel_rad", "ltr", "articulation_rad"):
        assert math.isfinite(comparison[name]) and comparison[name] <= 1e-9, name


def test_the_rollover_limits_of_the_truck_through_its_fmu_are_the_native_trucks(fmu_plant, tmp_path) -> None:
    """A plant from an FMU with load transfer (`ltr_output`) gives the tuning chain's rollover limits: the same
    step-steer bisection lifts a wheel at the same step as the native truck; the path curvature at that moment is
    the FMU plant's estimate from its mapped outputs, without the longitudinal-acceleration term (measured 1.1 %
    below the native truck's at 40, 60 and 80 km/h; 2 % allowed)."""
    from tuning.rollover import rollover_limits
    from workbench.vehicles import load_vehicle, make_vehicle

    through_fmu = load_vehicle(str(fmu_plant._truck_fmu_vehicle_file(tmp_path)))
    assert "path_curvature_1pm" in through_fmu.output_names
    vehicles = (make_vehicle("tractor-semitrailer"), through_fmu)
    native, fmu = (rollover_limits(v, [60.0], bisections=8)[0] for v in vehicles)
    assert fmu.limited_by == native.limited_by == "rollover"
    assert fmu.steer_wheel_deg == native.steer_wheel_deg
    assert fmu.peak_ltr == pytest.approx(native.peak_ltr, rel=1e-12)
    assert fmu.path_curvature_1pm == pytest.approx(native.path_curvature_1pm, rel=0.02)
