"""benchmarks/cte_breakdown.py without simulations: each switch changes what it names and nothing else, the held-out
circuits are refused, and the summary's arithmetic (gap to the NMPC closed, ratios) on constructed runs."""

from __future__ import annotations

import dataclasses
import time

import numpy as np
import pytest

from workbench.vehicles import make_vehicle


def _changed(vehicle_name: str, plant) -> dict[str, object]:
    preset = make_vehicle(vehicle_name).params
    return {
        f.name: getattr(plant.params, f.name)
        for f in dataclasses.fields(preset)
        if getattr(plant.params, f.name) != getattr(preset, f.name)
    }


@pytest.mark.parametrize("vehicle", ["tractor-semitrailer", "dynamic-bicycle"])
def test_each_plant_switch_changes_only_what_it_names(breakdown, vehicle: str) -> None:
    assert _changed(vehicle, breakdown.plant_for(vehicle, "nominal")) == {}
    assert _changed(vehicle, breakdown.plant_for(vehicle, "constant_speed")) == {}
    assert _changed(vehicle, breakdown.plant_for(vehicle, "no_actuator_lag")) == {
        "steering_time_constant_s": breakdown.NO_LAG_TIME_CONSTANT_S
    }
    stiff = _changed(vehicle, breakdown.plant_for(vehicle, "stiff_tyres"))
    assert stiff.pop("relaxation_length_m") == breakdown.STIFF_RELAXATION_M
    axles = ("front", "drive", "trailer") if vehicle == "tractor-semitrailer" else ("front", "rear")
    assert stiff == {f"{a}_cornering_coeff_per_rad": breakdown.STIFF_CORNERING_PER_RAD[vehicle] for a in axles}
    both = _changed(vehicle, breakdown.plant_for(vehicle, "ideal_plant"))
    assert both == {**stiff, "relaxation_length_m": breakdown.STIFF_RELAXATION_M,
                    "steering_time_constant_s": breakdown.NO_LAG_TIME_CONSTANT_S}  # fmt: skip


def test_the_controller_switches(breakdown) -> None:
    from controllers.clothoid.controller import ClothoidConfig

    config = ClothoidConfig()
    assert breakdown.clothoid_config_for("nominal", config) is config
    low = breakdown.clothoid_config_for("floor_lowered", config)
    assert (low.min_phase_margin_deg, low.min_gain_margin_db) == (30.0, 3.0)
    off = breakdown.clothoid_config_for("floor_off", config)
    assert (off.min_phase_margin_deg, off.min_gain_margin_db) == (0.0, 0.0)
    assert breakdown.clothoid_config_for("feedforward_off", config).path_feedforward is False
    rate = breakdown.clothoid_config_for("feedforward_rate", config)
    assert (rate.feedforward_inversion, rate.feedforward_window_m) == (False, 6.0)
    assert breakdown.clothoid_config_for("reference_lead", config).lag_model_reference is False
    assert config.path_feedforward is True and config.min_phase_margin_deg == 45.0
    assert (config.feedforward_inversion, config.lag_model_reference, config.feedforward_window_m) == (True, True, 2.0)


def test_the_model_switch_gives_the_nmpc_the_identified_lag(breakdown) -> None:
    from tuning.own_tuning import tuning_for

    truck = make_vehicle("tractor-semitrailer")
    assert breakdown.nmpc_config_for("nominal", truck) is None
    config = breakdown.nmpc_config_for("nmpc_identified_lag", truck)
    assert config.lag == tuning_for(truck).lag_at(breakdown.SPEED_KMH)


def test_the_held_out_circuits_are_refused(breakdown, capsys) -> None:
    with pytest.raises(SystemExit) as exit_info:
        breakdown.main(["--scenarios", "dlc,circuit:9003"])
    assert exit_info.value.code == 2
    assert "circuit:9003" in capsys.readouterr().err


def test_the_plan_runs_the_nmpc_on_plant_model_and_delay_switches_only(breakdown) -> None:
    jobs = breakdown.jobs_for(["dynamic-bicycle"], ["dlc"], automotive=False)
    nmpc = {j[2] for j in jobs if j[3] == "nmpc"}
    assert nmpc == {"nominal", *breakdown.PLANT_SWITCHES, *breakdown.MODEL_SWITCHES}
    controller_free = set(breakdown.MODEL_SWITCHES) | set(breakdown.DELAY_SWITCHES)  # the delay: automotive only
    assert {j[2] for j in jobs if j[3] == "clothoid"} == set(breakdown.SWITCHES) - controller_free
    with_automotive = breakdown.jobs_for(["dynamic-bicycle"], ["dlc"], automotive=True)
    assert {j[1] for j in with_automotive if j[4] == "automotive"} == set(breakdown.AUTOMOTIVE_SCENARIOS)
    perfect = {j[3] for j in with_automotive if j[2] == "perfect_prediction"}
    assert perfect == {"clothoid", "nmpc"}
    assert all(j[4] == "automotive" for j in with_automotive if j[2] == "perfect_prediction")


def test_each_switched_plant_is_tuned_once_before_its_runs(breakdown) -> None:
    """Many runs drive each switched plant (both controllers, each scenario and conditions); its tuning is made once,
    not by two workers at once."""
    jobs = breakdown.jobs_for(["dynamic-bicycle", "tractor-semitrailer"], ["dlc", "figure8"], automotive=True)
    plants = breakdown.switched_plants(jobs)
    assert len(plants) == len(set(plants))
    vehicles = ("dynamic-bicycle", "tractor-semitrailer")
    assert set(plants) == {(v, sw) for v in vehicles for sw in breakdown.PLANT_SWITCHES}
    assert sum(j[2] in breakdown.PLANT_SWITCHES for j in jobs) > len(plants)


def _run(breakdown, scenario: str, switch: str, controller: str, cte: float, rms: float = 0.01):
    return breakdown.Run("tractor-semitrailer", scenario, switch, controller, "ideal", "completed", cte, rms,
                         0.0, 0.0, 0.0, 8.3, 0.3, 1.0, 10.0, False, 8.5, 0.1)  # fmt: skip


def test_the_summary_arithmetic(breakdown) -> None:
    runs = []
    for scenario, (clothoid, nmpc) in {"a": (0.08, 0.04), "b": (0.06, 0.02), "c": (0.05, 0.03)}.items():
        runs += [_run(breakdown, scenario, "nominal", "clothoid", clothoid, 0.02),
                 _run(breakdown, scenario, "nominal", "nmpc", nmpc)]  # fmt: skip
        # a plant switch: the clothoid halves its error, the NMPC on the same switched plant keeps its own
        runs += [_run(breakdown, scenario, "stiff_tyres", "clothoid", clothoid / 2, 0.01),
                 _run(breakdown, scenario, "stiff_tyres", "nmpc", nmpc)]  # fmt: skip
        # a controller switch: compared with the nominal NMPC run
        runs.append(_run(breakdown, scenario, "floor_off", "clothoid", nmpc))
        # a model switch: the NMPC loses half the gap, the clothoid runs as nominal
        runs.append(_run(breakdown, scenario, "nmpc_identified_lag", "nmpc", (clothoid + nmpc) / 2))
    table = {row["switch"]: row for row in breakdown.summary(runs)}
    model = table["nmpc_identified_lag"]
    assert model["median_max_cte_vs_nominal"] == pytest.approx(1.0)
    assert model["median_gap_closed"] == pytest.approx(0.5)
    assert table["nominal"]["median_gap_closed"] == 0.0
    assert table["nominal"]["median_ratio_to_nmpc_same_run"] == pytest.approx(2.0)  # 2, 3, 5/3
    stiff = table["stiff_tyres"]
    assert stiff["median_max_cte_vs_nominal"] == pytest.approx(0.5)
    assert stiff["median_rms_cte_vs_nominal"] == pytest.approx(0.5)
    # gaps 0.04, 0.04, 0.02 closed by 0.04, 0.03, 0.025: 100 %, 75 %, 125 %
    assert stiff["median_gap_closed"] == pytest.approx(1.0)
    assert table["floor_off"]["median_gap_closed"] == pytest.approx(1.0)
    assert table["floor_off"]["median_ratio_to_nmpc_same_run"] == pytest.approx(1.0)
    assert set(table) == {
        "nominal",
        "stiff_tyres",
        "floor_off",
        "nmpc_identified_lag",
    }  # switches not run are not summarised


def test_a_switch_is_summarised_only_under_the_conditions_it_ran(breakdown) -> None:
    """The delay switch runs under automotive only: under ideal it has no row (not the nominal run's again)."""
    runs = []
    for conditions in ("ideal", "automotive"):
        for controller, cte in (("clothoid", 0.08), ("nmpc", 0.04)):
            runs.append(dataclasses.replace(_run(breakdown, "dlc", "nominal", controller, cte), conditions=conditions))
    for controller, cte in (("clothoid", 0.06), ("nmpc", 0.04)):
        perfect = _run(breakdown, "dlc", "perfect_prediction", controller, cte)
        runs.append(dataclasses.replace(perfect, conditions="automotive"))
    rows = {(row["conditions"], row["switch"]): row for row in breakdown.summary(runs)}
    assert set(rows) == {("ideal", "nominal"), ("automotive", "nominal"), ("automotive", "perfect_prediction")}
    assert rows[("automotive", "perfect_prediction")]["median_gap_closed"] == pytest.approx(0.5)


def test_the_result_records_the_machine_and_the_date(breakdown) -> None:
    from benchmark_report import machine

    before = time.time()
    document = breakdown.result_document([], [{"vehicle": "v"}], [], ["f.png"], [{"vehicle": "v", "scenario": "s"}])
    assert document["machine"]["platform"] == machine()["platform"]
    assert document["machine"]["cpus"] == machine()["cpus"]
    assert before <= document["created_unix_s"] <= time.time()
    assert (document["summary"], document["figures"], document["runs"]) == ([{"vehicle": "v"}], ["f.png"], [])
    assert document["model_error"] == [{"vehicle": "v", "scenario": "s"}]


def _steady_turn(curvature_1pm: float, speed_mps: float, yaw_rate_scale: float, gain: float, geometry) -> dict:
    """A trace of a vehicle driving a long arc at a held speed: yaw rate speed x curvature (times yaw_rate_scale),
    steering whose kinematic curvature is the arc's over `gain`."""
    s = np.linspace(60.0, 140.0, 201)
    steer = np.arctan(geometry.wheelbase_m * curvature_1pm / gain) * geometry.steering_ratio
    return {
        "path_s_m": s,
        "speed_mps": np.full_like(s, speed_mps),
        "yaw_rate_rad_s": np.full_like(s, speed_mps * curvature_1pm * yaw_rate_scale),
        "steer_wheel_cmd_rad": np.full_like(s, steer),
        "path_curvature_1pm": np.full_like(s, curvature_1pm),
    }


def test_the_model_errors_in_a_steady_turn(breakdown) -> None:
    """On an arc the reference is the arc's curvature (rigid-body kinematics: yaw rate / speed) and the feed-forward
    the arc's curvature over the lag's K: a vehicle that measures and steers exactly that has no model error, one
    whose yaw rate is 1 % high a reference error of 1 % of the curvature, and the feed-forward's error is the
    steering's own."""
    from tuning.own_tuning import tuning_for
    from workbench.base.clothoid_chain import ClothoidChain

    truck = make_vehicle("tractor-semitrailer")
    tuning, curvature, speed = tuning_for(truck), 1 / 40, 30 / 3.6
    gain = tuning.lag_at(30.0).steady_state_gain
    path = ClothoidChain(curvature_1pm=curvature).arc(200.0).to_path("arc")
    exact = breakdown.model_errors(_steady_turn(curvature, speed, 1.0, gain, truck.geometry), path, tuning,
                                   truck.geometry, 2.0)  # fmt: skip
    assert exact["samples"] == 201
    assert exact["path_curvature_rms_1pm"] == pytest.approx(curvature)
    for name in ("reference", "feedforward"):
        assert exact[f"{name}_rms_1pm"] == pytest.approx(0.0, abs=1e-9)
        assert exact[f"{name}_max_1pm"] == pytest.approx(0.0, abs=1e-9)
    high = breakdown.model_errors(_steady_turn(curvature, speed, 1.01, 1.0, truck.geometry), path, tuning,
                                  truck.geometry, 2.0)  # fmt: skip
    assert high["reference_rms_1pm"] == pytest.approx(0.01 * curvature, rel=1e-6)
    assert high["reference_relative"] == pytest.approx(0.01, rel=1e-6)
    # steering for K = 1 where the lag has K: the feed-forward sends curvature / K, the vehicle curvature
    assert high["feedforward_rms_1pm"] == pytest.approx(abs(curvature - curvature / gain), rel=1e-6)
