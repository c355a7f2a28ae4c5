"""Recorded clothoid-controller runs that `test_compiled_step.py` replays: each case names a scenario, a vehicle,
the conditions and the controller's options; `record_replays.py` ran it through the Python step of commit b614e88
(before issue 19 compiled the step) and stored, per step, the measurement the controller saw, the command it returned
and its diagnostics (`replay/<name>.npz`). Between them they take every branch of the step: each lookahead mode, each
initial curvature and heading, both threshold modes, with and without feed-forward, lead filter, tuning, ceiling,
known delay and noise."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from pathlib import Path

from controllers.base import Controller
from controllers.clothoid import ClothoidConfig, ClothoidController
from tuning.own_tuning import tuned_controller
from tuning.tuning_dirs import read_vehicle_tuning
from workbench.base.path import ReferencePath
from workbench.simulation.conditions import load_conditions
from workbench.simulation.scenarios import ScenarioOptions, make_scenario
from workbench.simulation.simulator import Simulation, SimulationConfig
from workbench.vehicles import make_vehicle

HERE = Path(__file__).resolve().parent / "replay"
#: The kinematic bicycle's wheelbase (m) when the runs were recorded.
RECORDED_KINEMATIC_WHEELBASE_M = 2.578
ZANDVOORT_CSV = HERE.parents[4] / "shared" / "tracks" / "Zandvoort_track.csv"


@dataclass(frozen=True)
class Case:
    name: str
    scenario: str
    vehicle: str
    speed_kmh: float = 30.0
    conditions: str = "ideal"
    seed: int = 0
    options: dict = field(default_factory=dict)
    tuned: bool = True
    max_steps: int = 1000

    @property
    def file(self) -> Path:
        return HERE / f"{self.name}.npz"

    def simulation(self, controller: Controller | None = None) -> Simulation:
        vehicle = make_vehicle(self.vehicle)
        track = str(ZANDVOORT_CSV) if self.scenario == "zandvoort" else None
        scenario = make_scenario(self.scenario, ScenarioOptions(vehicle.geometry.width_m, track))
        config = SimulationConfig(
            speed_kmh=self.speed_kmh, conditions=load_conditions(self.conditions), seed=self.seed,
            max_time_s=self.max_steps * 0.02,
        )  # fmt: skip
        return Simulation(scenario, vehicle, controller or self.controller(), config)

    def controller(self) -> ClothoidController:
        """The controller as it was recorded: the kinematic bicycle's geometry and tuning of then (its wheelbase
        was 2.578 m until issue 20 made it 2.579 m, and its tuning was made for that), every other vehicle's own."""
        config = dataclasses.replace(ClothoidConfig(search_start="ends"), **self.options)  # searched so then
        vehicle = make_vehicle(self.vehicle)
        geometry = vehicle.geometry
        if self.vehicle == "kinematic-bicycle":
            geometry = dataclasses.replace(geometry, wheelbase_m=RECORDED_KINEMATIC_WHEELBASE_M)
            if self.tuned:
                config = dataclasses.replace(config, tuning=read_vehicle_tuning(HERE / "kinematic-bicycle-tuning"))
            return ClothoidController(geometry, config)
        if self.tuned:
            return tuned_controller("clothoid", vehicle, config)
        return ClothoidController(geometry, config)

    def path(self) -> ReferencePath:
        return self.simulation().path


#: The feed-forward's other form: the path's curvature rate integrated with the feedback over a 6 m window.
RATE_FEEDFORWARD = {"feedforward_inversion": False, "feedforward_window_m": 6.0}

CASES = (
    Case("truck_dlc", "dlc", "tractor-semitrailer"),
    Case(
        "truck_figure8_automotive",
        "figure8",
        "tractor-semitrailer",
        conditions="automotive",
        options={"known_delay_s": 0.11, "delay_compensation": "arc", **RATE_FEEDFORWARD},
    ),
    Case(
        "truck_figure8_delay_model",
        "figure8",
        "tractor-semitrailer",
        conditions="automotive",
        # as --inform-delays tells it; recorded before the sideslip's release (test_sideslip_release checks it)
        options={"known_delay_s": 0.11, "yaw_rate_age_s": 0.01, "sideslip_release": False},
        max_steps=1500,
    ),
    Case("car_dlc_degraded", "dlc", "dynamic-bicycle", speed_kmh=50.0, conditions="degraded", seed=1),
    Case("truck_zandvoort", "zandvoort", "tractor-semitrailer", max_steps=2500),
    Case(
        "car_figure8_options",
        "figure8",
        "kinematic-bicycle",
        options={
            "heading": "yaw",
            "initial_curvature": "command",
            "threshold_mode": "excess",
            "path_feedforward": False,
            "max_target_turn_deg": 0.0,
            "max_lookahead_growth_m_per_m": None,
            "min_preview_time_s": 0.5,
            "feedforward_time_s": 0.1,
            "reference_lead_s": 0.05,
        },
    ),
    Case(
        "untuned_speed_mode",
        "dlc",
        "kinematic-bicycle",
        tuned=False,
        options={"lookahead_mode": "speed", "lookahead_gain_s": 0.8},
    ),
    Case(
        "car_fixed_steering",
        "figure8",
        "dynamic-bicycle",
        options={
            "lookahead_mode": "fixed",
            "initial_curvature": "steering",
            "prediction_time_s": 0.0,
            "use_lead_filter": False,
        },
    ),
    Case(
        "mb_dlc_options",
        "dlc",
        "commonroad-mb",
        speed_kmh=40.0,
        options={
            "max_lookahead_shrink_m_per_m": None,
            "lookahead_hysteresis_m": 0.0,
            "feedforward_time_s": 0.3,
            **RATE_FEEDFORWARD,
        },
    ),
)
