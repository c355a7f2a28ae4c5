"""One run of a study, as a worker executes it: a PlannedRun in, its row out (parameters, the metrics.json fields,
status, message).

The run is built as `workbench run` builds one: the vehicle (with its payload), the scenario sized for it (with
the initial offset and heading error; a generated circuit within the ranges of the run parameter circuit_ranges),
the controller's options from the controller-config file and the run's options on top
(`workbench.apps.controller_config.read_controller_config`, the `--set KEY=VALUE` path), told the conditions' nominal
delays when the run parameter inform_delays is true (`known_delays.KnownDelays`, as `workbench
run --inform-delays`), the lead filter scaled when asked (`lead_filter_scaling.py`), then `Simulation(...).run()`.
Nothing in it is random, so the same PlannedRun gives the same row, bit for bit, on any worker, except the
wall-clock fields (TIMING_COLUMNS). One exception: the MPCs drop a solve that overruns its wall-clock budget
(`max_solve_time_s`, default the controller period), so on a loaded machine their runs can differ; give them a
budget they never reach (e.g. `max_solve_time_s = 10.0` in [grid.nmpc]) for reproducible MPC sweeps.

A run that raises (a value its vehicle, scenario or controller refuses, a controller that fails while being built)
becomes a row with status "error", the exception as its message and the traceback; a run that ends early (left
the path, timed out, diverged, the controller failed mid-run) keeps the simulator's status and message.
"""

from __future__ import annotations

import time
import traceback
from typing import Any

from controllers import CONTROLLERS, make_controller
from tuning.own_tuning import with_vehicle_tuning
from workbench.apps.studies.run_build import (
    option_text,
    plant_and_controller_vehicles,
    simulation_config,
    split_values,
    started_scenario,
    untuned_controller_config,
    with_scaled_filter,
)
from workbench.apps.studies.spec import PlannedRun
from workbench.simulation.circuit_ranges import read_circuit_ranges
from workbench.simulation.known_delays import KnownDelays
from workbench.simulation.metrics import METRIC_KEYS
from workbench.simulation.result import SimulationResult
from workbench.simulation.scenarios import ScenarioOptions, make_scenario
from workbench.simulation.simulator import Simulation
from workbench.vehicles.base import VehicleModel
from workbench.vehicles.presets import load_vehicle

#: The status of a run that raised.
ERROR_STATUS = "error"
#: The metrics.json fields a row carries (the names are the run's own columns).
ROW_METRICS = tuple(k for k in METRIC_KEYS if k not in ("scenario", "controller", "vehicle"))
#: The columns of a row after the run's parameters, in order.
RESULT_COLUMNS = (*ROW_METRICS, "status", "message", "traceback", "run_time_s", "cpu_time_s")
#: Wall-clock fields: they differ from run to run; everything else in a row is reproducible bit for bit.
#: cpu_time_s, the CPU time (s) of the worker process while it ran the run, is measured like them.
TIMING_COLUMNS = ("step_time_median_us", "step_time_p99_us", "run_time_s", "cpu_time_s")


def build_controller_config(
    run: PlannedRun, vehicle: VehicleModel | None = None, delays: KnownDelays | None = None
) -> Any:
    """The run's controller config: the controller-config file's table, then the run's options (file options read
    into their objects), then the vehicle's tuning (when a vehicle is given), then told `delays` when given
    (`Controller.informed_config`; the run parameter inform_delays gives its conditions'). With lead-filter scales
    other than 1, the config holds the scaled filter (of its own lead filter, else of the vehicle's tuning).

    Parameters
    ----------
    run : PlannedRun
        The run: its controller, controller-config file and options.
    vehicle : VehicleModel or None
        The vehicle the controller is tuned for (None: no vehicle tuning).
    delays : KnownDelays or None
        The delays the controller is told (None: none).

    Returns
    -------
    object
        An instance of the controller class's `config_type` (e.g. `ClothoidConfig`).

    Raises
    ------
    WorkbenchInputError
        An option the controller does not have, a value it refuses, or a file it cannot read.
    """
    geometry = vehicle.geometry if vehicle is not None else None
    config, scales = untuned_controller_config(run.controller, run.controller_config, dict(run.options), geometry)
    if vehicle is not None:
        config = with_vehicle_tuning(config, vehicle)
    if delays is not None:
        config = CONTROLLERS[run.controller].informed_config(config, delays)
    return with_scaled_filter(config, scales)


def simulate(run: PlannedRun, progress: bool = False) -> SimulationResult:
    """Build and simulate the run; return the SimulationResult.

    Parameters
    ----------
    run : PlannedRun
        The run (`StudySpec.plan`).
    progress : bool
        Show the run's metres on stderr.

    Returns
    -------
    SimulationResult
        The run's trace, metrics and status.

    Raises
    ------
    WorkbenchInputError
        A value the vehicle, scenario or controller refuses (`execute_run` records it as an "error" row).
    """
    values, extra = split_values(dict(run.values))
    config = simulation_config(values)
    # The controller is built for the vehicle with controller_payload_kg when given (a payload mismatch), else for
    # the plant itself.
    vehicle, built_for = plant_and_controller_vehicles(
        load_vehicle(run.vehicle), extra["payload_kg"], extra["controller_payload_kg"]
    )  # run.vehicle: a preset name or a vehicle file
    ranges = read_circuit_ranges(extra["circuit_ranges"]) if extra["circuit_ranges"] is not None else None
    scenario = make_scenario(run.scenario, ScenarioOptions(vehicle.geometry.width_m, run.track_file, ranges))
    scenario = started_scenario(
        scenario, extra["initial_offset_m"], extra["initial_heading_error_deg"], config.max_abs_cte_m
    )
    delays = config.known_delays
    options = build_controller_config(run, built_for, delays)
    controller = make_controller(run.controller, vehicle.geometry, options, vehicle=built_for)
    return Simulation(scenario, vehicle, controller, config).run(progress=progress)


def execute_run(run: PlannedRun) -> dict[str, Any]:
    """The run's row: its parameters, the metrics.json fields, status, message, traceback (errors only) and
    run_time_s (wall time) and cpu_time_s (this process's CPU time while it ran). Exceptions become an "error" row;
    KeyboardInterrupt and SystemExit propagate.

    Parameters
    ----------
    run : PlannedRun
        One run of a study (`StudySpec.plan`).

    Returns
    -------
    dict
        The run's row: `PlannedRun.parameters`, then `RESULT_COLUMNS` (status "error" with the exception's
        message and traceback when the run raised). The same run gives the same row bit for bit, but for
        `TIMING_COLUMNS`.

    Examples
    --------
    >>> from workbench.apps.studies import execute_run, load_spec
    >>> run = load_spec("examples/sweep_dlc.toml").plan()[0]
    >>> row = execute_run(run)  # doctest: +SKIP
    >>> row["status"], row["max_abs_cte_m"]  # doctest: +SKIP
    """
    start, cpu_start = time.perf_counter(), time.process_time()
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
    row["cpu_time_s"] = time.process_time() - cpu_start
    return row


def failed_row(run: PlannedRun, message: str) -> dict[str, Any]:
    """The row of a run the backend could not execute (e.g. its worker died every time it ran it).

    Parameters
    ----------
    run : PlannedRun
        The run.
    message : str
        Why it could not be executed.

    Returns
    -------
    dict
        `PlannedRun.parameters`, no metrics, status "error" and the message.
    """
    return (
        run.parameters()
        | dict.fromkeys(ROW_METRICS)
        | {"completed": False, "status": ERROR_STATUS, "message": message, "traceback": None}
        | dict.fromkeys(("run_time_s", "cpu_time_s"))
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
