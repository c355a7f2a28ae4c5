"""One run of a study, as a worker executes it: a PlannedRun in, its row out (parameters, the metrics.json fields,
status, message).

The run is built as `workbench run` builds one: the vehicle (with its payload), the scenario sized for it (with
the initial offset and heading error), the controller's options from the controller-config file and the run's
options on top (`workbench.apps.controller_config.read_controller_config`, the `--set KEY=VALUE` path), the lead filter
scaled when asked (`lead_filter_scaling.py`), then `Simulation(...).run()`. Nothing in it
is random, so the same PlannedRun gives the same row, bit for bit, on any worker, except the wall-clock fields
(TIMING_COLUMNS). One exception: the MPCs drop a solve that overruns its wall-clock budget (`max_solve_time_s`,
default the controller period), so on a loaded machine their runs can differ; give them a budget they never reach
(e.g. `max_solve_time_s = 10.0` in [grid.nmpc]) for reproducible MPC sweeps.

A run that raises (a value its vehicle, scenario or controller refuses, a controller that fails while being built)
becomes a row with status "error", the exception as its message and the traceback; a run that ends early (left
the path, timed out, diverged, the controller failed mid-run) keeps the simulator's status and message.
"""

from __future__ import annotations

import dataclasses
import math
import time
import traceback
from typing import Any

from controllers import CONTROLLERS, make_controller
from tuning.own_tuning import with_vehicle_tuning
from workbench.apps.controller_config import read_controller_config
from workbench.apps.studies.condition_parameters import CONDITION_FIELDS, run_conditions
from workbench.apps.studies.lead_filter_scaling import scaled_filter
from workbench.apps.studies.spec import EXTRA_RUN_PARAMETERS, LEAD_FILTER_SCALES, PlannedRun
from workbench.simulation.metrics import METRIC_KEYS
from workbench.simulation.result import SimulationResult
from workbench.simulation.scenarios import ScenarioOptions, make_scenario
from workbench.simulation.simulator import Simulation, SimulationConfig
from workbench.vehicles.base import VehicleModel
from workbench.vehicles.presets import load_vehicle

#: The status of a run that raised.
ERROR_STATUS = "error"
#: The metrics.json fields a row carries (the names are the run's own columns).
ROW_METRICS = tuple(k for k in METRIC_KEYS if k not in ("scenario", "controller", "vehicle"))
#: The columns of a row after the run's parameters, in order.
RESULT_COLUMNS = (*ROW_METRICS, "status", "message", "traceback", "run_time_s")
#: Wall-clock fields: they differ from run to run; everything else in a row is reproducible bit for bit.
TIMING_COLUMNS = ("step_time_median_us", "step_time_p99_us", "run_time_s")


def option_text(value: Any) -> str:
    """A typed option value as the text of a `--set KEY=VALUE` override (floats by repr: exact round trip)."""
    if value is None:
        return "none"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return repr(value)
    return str(value)


def build_controller_config(run: PlannedRun, vehicle: VehicleModel | None = None) -> Any:
    """The run's controller config: the controller-config file's table, then the run's options (file options read
    into their objects). With lead-filter scales other than 1, the config holds the scaled filter (of its own lead
    filter, else of the vehicle's tuning)."""
    options = dict(run.options)
    scales = {k: options.pop(k) for k in LEAD_FILTER_SCALES if k in options}
    config_type = CONTROLLERS[run.controller].config_type
    overrides = [f"{key}={option_text(value)}" for key, value in options.items()]
    geometry = vehicle.geometry if vehicle is not None else None
    config = read_controller_config(run.controller_config, run.controller, config_type, overrides, geometry)
    if vehicle is not None:
        config = with_vehicle_tuning(config, vehicle)
    zero, pole = (scales.get(k, 1.0) for k in LEAD_FILTER_SCALES)
    if zero != 1.0 or pole != 1.0:
        tuning = getattr(config, "tuning", None)
        own = tuning.filter_schedule if tuning is not None and config.lead_filter is None else None
        config = dataclasses.replace(config, lead_filter=scaled_filter(config.lead_filter, zero, pole, own))
    return config


def simulate(run: PlannedRun, progress: bool = False) -> SimulationResult:
    """Build and simulate the run; return the SimulationResult."""
    values = dict(run.values)
    extra = {k: values.pop(k, None) for k in EXTRA_RUN_PARAMETERS}
    name = values.pop("conditions", None)
    fields = {k: values.pop(k) for k in list(values) if k in CONDITION_FIELDS}
    config = SimulationConfig(**values, conditions=run_conditions(name, fields))
    vehicle = load_vehicle(run.vehicle, extra["payload_kg"])  # a preset name or a vehicle file
    scenario = make_scenario(run.scenario, ScenarioOptions(vehicle.geometry.width_m, run.track_file))
    heading_deg = extra["initial_heading_error_deg"]
    scenario = scenario.with_initial_error(
        extra["initial_offset_m"], None if heading_deg is None else math.radians(heading_deg)
    )
    # The controller is built for the vehicle with controller_payload_kg when given (a payload mismatch), else for
    # the plant itself.
    built_for = vehicle
    if extra["controller_payload_kg"] is not None:
        built_for = load_vehicle(run.vehicle, extra["controller_payload_kg"])
    options = build_controller_config(run, built_for)
    controller = make_controller(run.controller, vehicle.geometry, options, vehicle=built_for)
    return Simulation(scenario, vehicle, controller, config).run(progress=progress)


def execute_run(run: PlannedRun) -> dict[str, Any]:
    """The run's row: its parameters, the metrics.json fields, status, message, traceback (errors only) and
    run_time_s (wall time). Exceptions become an "error" row; KeyboardInterrupt and SystemExit propagate."""
    start = time.perf_counter()
    row = run.parameters()
    try:
        result = simulate(run)
        metrics = result.metrics.to_dict()
        row |= {k: metrics[k] for k in ROW_METRICS}
        row |= {"status": result.status.value, "message": result.message, "traceback": None}
    except Exception as exc:  # recorded in the row: a failed run is a result, never lost
        row |= dict.fromkeys(ROW_METRICS) | {"completed": False}
        row |= {
            "status": ERROR_STATUS,
            "message": f"{type(exc).__name__}: {exc}",
            "traceback": "".join(traceback.format_exception(exc)),
        }
    row["run_time_s"] = time.perf_counter() - start
    return row


def failed_row(run: PlannedRun, message: str) -> dict[str, Any]:
    """The row of a run the backend could not execute (e.g. its worker died every time it ran it)."""
    return (
        run.parameters()
        | dict.fromkeys(ROW_METRICS)
        | {"completed": False, "status": ERROR_STATUS, "message": message, "traceback": None, "run_time_s": None}
    )


__all__ = [
    "ERROR_STATUS",
    "RESULT_COLUMNS",
    "ROW_METRICS",
    "TIMING_COLUMNS",
    "build_controller_config",
    "execute_run",
    "failed_row",
    "option_text",
    "simulate",
]
