"""One run of a study: the same numbers as a direct simulation, the initial error it asks for, lead-filter scaling,
and an exception turned into an error row."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
from study_helpers import write_spec

from controllers import CONTROLLERS, make_controller
from controllers.clothoid.filter_schedule import DEFAULT_FILTER
from workbench.apps.controller_config import read_controller_config
from workbench.apps.studies import PlannedRun, execute_run, load_spec
from workbench.apps.studies.runner import ROW_METRICS, build_controller_config, option_text, simulate
from workbench.simulation.scenarios import ScenarioOptions, make_scenario
from workbench.simulation.simulator import Simulation, SimulationConfig
from workbench.vehicles import make_vehicle, preset_text


def _run(**kwargs: object) -> PlannedRun:
    fields = {
        "run_id": "r",
        "index": 0,
        "scenario": "dlc",
        "controller": "pure-pursuit",
        "vehicle": "kinematic-bicycle",
    }
    return PlannedRun(**(fields | kwargs))


def test_a_run_row_holds_the_direct_simulations_metrics_exactly() -> None:
    run = _run(values=(("speed_kmh", 25.0),), options=(("lookahead_gain_s", 0.6),))
    row = execute_run(run)
    vehicle = make_vehicle("kinematic-bicycle")
    scenario = make_scenario("dlc", ScenarioOptions(vehicle.geometry.width_m))
    options = read_controller_config(
        None, "pure-pursuit", CONTROLLERS["pure-pursuit"].config_type, ["lookahead_gain_s=0.6"]
    )
    controller = make_controller("pure-pursuit", vehicle.geometry, options, vehicle=vehicle)
    direct = Simulation(scenario, vehicle, controller, SimulationConfig(speed_kmh=25.0)).run().metrics.to_dict()
    assert row["status"] == "completed" and row["completed"] is True and row["traceback"] is None
    for key in ROW_METRICS:
        if key not in ("step_time_median_us", "step_time_p99_us"):
            assert row[key] == direct[key], key  # bit for bit
    assert row["speed_kmh"] == 25.0 and row["pure-pursuit.lookahead_gain_s"] == 0.6 and row["run_time_s"] > 0


def test_initial_offset_and_heading_error_are_where_the_run_starts() -> None:
    run = _run(values=(("initial_offset_m", -0.7), ("initial_heading_error_deg", 4.0)))
    trace = simulate(run).trace
    assert trace["cte_m"][0] == pytest.approx(-0.7, abs=1e-6)
    assert trace["heading_error_rad"][0] == pytest.approx(math.radians(4.0), abs=1e-9)
    # fig17 starts 1.0 m left of its path unless the run says otherwise
    assert simulate(_run(scenario="fig17")).trace["cte_m"][0] == pytest.approx(1.0, abs=1e-6)
    assert simulate(_run(scenario="fig17", values=(("initial_offset_m", 0.0),))).trace["cte_m"][0] == pytest.approx(
        0.0, abs=1e-6
    )


def test_an_exception_is_an_error_row_with_its_message() -> None:
    row = execute_run(_run(controller="clothoid", options=(("min_lookahead_m", 30.0),)))
    assert row["status"] == "error" and row["completed"] is False
    assert row["message"].startswith("WorkbenchInputError: max_lookahead_m must be") and "30.0" in row["message"]
    assert "read_controller_config" in row["traceback"]
    assert all(row[k] is None for k in ROW_METRICS if k != "completed")
    assert row["clothoid.min_lookahead_m"] == 30.0
    # a value the scenario refuses, and a payload the vehicle refuses
    offset = execute_run(_run(values=(("initial_offset_m", 80.0),)))
    assert "initial_offset_m must be a finite number in" in offset["message"]
    truck = _run(vehicle="tractor-semitrailer", values=(("payload_kg", -5.0),))
    assert execute_run(truck)["status"] == "error"


def test_a_run_that_leaves_the_path_keeps_the_simulators_status() -> None:
    values = (("max_abs_cte_m", 0.5), ("initial_offset_m", 0.3), ("initial_heading_error_deg", 20.0))
    row = execute_run(_run(values=values))
    assert row["status"] == "left_path" and row["completed"] is False
    assert "exceeds max_abs_cte_m = 0.5 m at t = 0.08 s" in row["message"]
    assert 0.3 < row["max_abs_cte_m"] <= 0.5 and row["distance_m"] < 1.0


def test_lead_filter_scaling_gives_the_config_the_scaled_filter(tmp_path: Path) -> None:
    """No file: the config holds the scaled filter (here of DEFAULT_FILTER: no vehicle, no configured filter)."""
    run = _run(controller="clothoid", options=(("lead_filter_zero_scale", 1.25), ("lead_filter_pole_scale", 0.8)))
    config = build_controller_config(run)
    assert list(tmp_path.iterdir()) == []
    (params,) = config.lead_filter.params
    assert params.omega_z_rad_s == DEFAULT_FILTER.omega_z_rad_s * 1.25
    assert params.omega_p_rad_s == DEFAULT_FILTER.omega_p_rad_s * 0.8
    assert params.psi == DEFAULT_FILTER.psi
    # Eq. 6 needs omega_p >= omega_z: a scaling that breaks it is the run's error
    bad = _run(controller="clothoid", options=(("lead_filter_zero_scale", 4.0),))
    row = execute_run(bad)
    assert row["status"] == "error" and "lead_filter_zero_scale = 4.0" in row["message"]
    assert "omega_p_rad_s / omega_z_rad_s must be in [1.0, 100.0]" in row["message"]


def test_lead_filter_scaling_changes_the_run(tmp_path: Path) -> None:
    text = (
        '[study]\nscenarios = ["dlc"]\ncontrollers = ["clothoid"]\nvehicles = ["kinematic-bicycle"]\n'
        "[grid.clothoid]\nlead_filter_pole_scale = [1.0, 1.5]\n"
    )
    plain, scaled = (execute_run(r) for r in load_spec(write_spec(tmp_path, text)).plan())
    assert plain["status"] == scaled["status"] == "completed"
    assert plain["rms_steer_rate_deg_s"] != scaled["rms_steer_rate_deg_s"]


@pytest.mark.parametrize("value", [0.1, 1e-300, 1 / 3, True, False, None, 7, "text", Path("/a/b.json")])
def test_option_text_round_trips(value: object) -> None:
    text = option_text(value)
    if isinstance(value, float):
        assert float(text) == value
    elif value is None:
        assert text == "none"
    elif isinstance(value, bool):
        assert text == ("true" if value else "false")
    else:
        assert text == str(value)


def test_a_vehicle_file_runs_as_its_preset_does_with_the_payload_asked(tmp_path: Path) -> None:
    path = tmp_path / "truck.toml"
    path.write_text(preset_text("tractor-semitrailer"))
    values = (("speed_kmh", 20.0), ("payload_kg", 5000.0))
    from_file = execute_run(_run(vehicle=str(path), values=values))
    from_preset = execute_run(_run(vehicle="tractor-semitrailer", values=values))
    assert from_file["status"] == "completed"
    for key in ("max_abs_cte_m", "rms_cte_m", "max_ltr"):
        assert from_file[key] == from_preset[key], key
    light = execute_run(_run(vehicle=str(path), values=(("speed_kmh", 20.0), ("payload_kg", 0.0))))
    assert light["max_ltr"] != from_file["max_ltr"]  # the payload reached the file's vehicle
