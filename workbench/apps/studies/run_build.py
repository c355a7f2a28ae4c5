"""The objects a study run is built from, from its parameters: its SimulationConfig, its plant and the vehicle its
controller is built for, its scenario started with the initial error it asks for, and its controller config.

The worker builds a run with these (`runner.py`), and the spec builds every planned value with them when it loads
(`spec.py`), so that a value every run would refuse is refused before any run, by the same checks.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

from controllers import CONTROLLERS
from workbench.apps.controller_config import read_controller_config
from workbench.apps.studies.condition_parameters import CONDITION_FIELDS, run_conditions
from workbench.base.errors import WorkbenchInputError, require_positive, value_text
from workbench.simulation.simulator import SimulationConfig

if TYPE_CHECKING:
    from workbench.simulation.scenarios import Scenario
    from workbench.vehicles.base import VehicleModel
    from workbench.vehicles.geometry import VehicleGeometry

#: The run parameters besides SimulationConfig's fields, with their types.
EXTRA_RUN_PARAMETERS: dict[str, Any] = {
    "payload_kg": float,
    "controller_payload_kg": float,
    "initial_offset_m": float,
    "initial_heading_error_deg": float,
    "circuit_ranges": Path,
}
#: Factors on a lead filter's zero and pole frequencies, parameters of controllers that read one (`filter_file`).
LEAD_FILTER_SCALES = ("lead_filter_zero_scale", "lead_filter_pole_scale")


def split_values(values: Mapping[str, Any]) -> tuple[dict[str, Any], dict[str, Any]]:
    """A run's parameters as (the SimulationConfig's, conditions included; EXTRA_RUN_PARAMETERS, None when not
    given).

    Parameters
    ----------
    values : mapping
        A run's parameters (`PlannedRun.values`), typed.

    Returns
    -------
    tuple of (dict, dict)
        The SimulationConfig's parameters as given, and every key of EXTRA_RUN_PARAMETERS with its value or None.
    """
    config = {k: v for k, v in values.items() if k not in EXTRA_RUN_PARAMETERS}
    return config, {k: values.get(k) for k in EXTRA_RUN_PARAMETERS}


def simulation_config(values: Mapping[str, Any]) -> SimulationConfig:
    """The SimulationConfig of a run's SimulationConfig parameters: its fields, `conditions` (a preset name or a
    file; None: ideal) and the condition fields set on top of it (`condition_parameters.py`).

    Parameters
    ----------
    values : mapping
        SimulationConfig fields, conditions and condition fields (`split_values`), typed.

    Returns
    -------
    SimulationConfig
        The run's simulation settings.

    Raises
    ------
    WorkbenchInputError
        A value SimulationConfig or the conditions refuse, or a conditions file it cannot read.
    """
    values = dict(values)
    name = values.pop("conditions", None)
    fields = {k: values.pop(k) for k in list(values) if k in CONDITION_FIELDS}
    return SimulationConfig(**values, conditions=run_conditions(name, fields))


def started_scenario(
    scenario: Scenario, offset_m: float | None, heading_deg: float | None, max_abs_cte_m: float
) -> Scenario:
    """The scenario started with the lateral offset (m) and heading error (deg) asked for (None: the scenario's
    own). A start further from the path than max_abs_cte_m (the distance at which a run has left the path and
    stops) is refused: such a run would stop before its first step.

    Parameters
    ----------
    scenario : Scenario
        The scenario as built.
    offset_m : float or None
        Lateral offset (m) of the start from the path (None: the scenario's own).
    heading_deg : float or None
        Heading error (deg) of the start (None: the scenario's own).
    max_abs_cte_m : float
        The |CTE| (m) at which a run has left the path (`SimulationConfig.max_abs_cte_m`).

    Returns
    -------
    Scenario
        The scenario with that start.

    Raises
    ------
    WorkbenchInputError
        |offset| at or beyond max_abs_cte_m.
    """
    started = scenario.with_initial_error(offset_m, None if heading_deg is None else math.radians(heading_deg))
    if not abs(started.initial_offset_m) < max_abs_cte_m:
        raise WorkbenchInputError(
            f"initial_offset_m = {value_text(started.initial_offset_m)} m starts the run at or beyond max_abs_cte_m "
            f"= {value_text(max_abs_cte_m)} m from the path, where a run has left it and stops; allowed: "
            "|initial_offset_m| < max_abs_cte_m"
        )
    return started


def plant_and_controller_vehicles(
    vehicle: VehicleModel, payload_kg: float | None, controller_payload_kg: float | None
) -> tuple[VehicleModel, VehicleModel]:
    """(the plant: the vehicle with payload_kg, its own payload when None; the vehicle the controller is built for:
    the vehicle with controller_payload_kg when given, a payload mismatch, else the plant itself).

    Parameters
    ----------
    vehicle : VehicleModel
        The run's vehicle, with its own payload.
    payload_kg : float or None
        The plant's payload (kg; None: the vehicle's own).
    controller_payload_kg : float or None
        The payload (kg) the controller is built for (None: the plant's).

    Returns
    -------
    tuple of (VehicleModel, VehicleModel)
        The plant, and the vehicle the controller is built for (the plant itself without a mismatch).

    Raises
    ------
    WorkbenchInputError
        A payload for a vehicle that carries none, or not a number.
    """
    from workbench.vehicles.presets import with_payload

    plant = vehicle if payload_kg is None else with_payload(vehicle, payload_kg)
    if controller_payload_kg is None:
        return plant, plant
    return plant, with_payload(vehicle, controller_payload_kg)


def option_text(value: Any) -> str:
    """A typed option value as the text of a `--set KEY=VALUE` override (floats by repr: exact round trip).

    Parameters
    ----------
    value : object
        None, a bool, a number or text.

    Returns
    -------
    str
        "none", "true"/"false", repr of a float, str of anything else.

    Examples
    --------
    >>> from workbench.apps.studies.run_build import option_text
    >>> [option_text(v) for v in (None, True, 0.1, 3, "adaptive")]
    ['none', 'true', '0.1', '3', 'adaptive']
    """
    if value is None:
        return "none"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return repr(value)
    return str(value)


def untuned_controller_config(
    controller: str,
    config_file: Path | None,
    options: Mapping[str, Any],
    geometry: VehicleGeometry | None,
) -> tuple[Any, dict[str, float]]:
    """(the controller's config from the controller-config file's table with the run's options on top, file
    options read into their objects, without any vehicle's tuning; the lead-filter scales given).

    Parameters
    ----------
    controller : str
        A registered controller's name.
    config_file : pathlib.Path or None
        A controller-config TOML file (None: the defaults).
    options : mapping
        Option -> typed value, over the file's; the lead-filter scales (`LEAD_FILTER_SCALES`) among them are
        returned apart.
    geometry : VehicleGeometry or None
        The vehicle's geometry, for options that depend on it (None: none).

    Returns
    -------
    tuple of (object, dict of str to float)
        The controller's config, and the lead-filter scales given.

    Raises
    ------
    WorkbenchInputError
        An option the controller does not have, a value it refuses, or a file it cannot read.
    """
    options = dict(options)
    scales = {k: options.pop(k) for k in LEAD_FILTER_SCALES if k in options}
    config_type = CONTROLLERS[controller].config_type
    overrides = [f"{key}={option_text(value)}" for key, value in options.items()]
    return read_controller_config(config_file, controller, config_type, overrides, geometry), scales


def with_scaled_filter(config: Any, scales: Mapping[str, float]) -> Any:
    """The config with its lead filter scaled (`lead_filter_scaling.scaled_filter`: its own lead filter, else the
    vehicle's tuning's, else the default) when a scale other than 1 is given; as it is otherwise.

    Parameters
    ----------
    config : object
        A controller's config; one with a lead_filter field when a scale other than 1 is given.
    scales : mapping of str to float
        `LEAD_FILTER_SCALES` -> factor (a missing one: 1).

    Returns
    -------
    object
        The config, its lead filter scaled when asked.
    """
    from workbench.apps.studies.lead_filter_scaling import scaled_filter

    zero, pole = (scales.get(k, 1.0) for k in LEAD_FILTER_SCALES)
    if zero == 1.0 and pole == 1.0:
        return config
    tuning = getattr(config, "tuning", None)
    own = tuning.filter_schedule if tuning is not None and config.lead_filter is None else None
    return dataclasses.replace(config, lead_filter=scaled_filter(config.lead_filter, zero, pole, own))


def check_scales(config: Any, scales: Mapping[str, float]) -> None:
    """The lead-filter scales checked as far as they can be without the vehicle's tuning: positive, and the
    configured lead filter (when the config has one) scaled as a run scales it.

    Parameters
    ----------
    config : object
        A controller's config.
    scales : mapping of str to float
        `LEAD_FILTER_SCALES` -> factor.

    Raises
    ------
    WorkbenchInputError
        A scale not positive, or scales that give the configured lead filter a zero or pole Eq. 6 does not allow.
    """
    for key, value in scales.items():
        require_positive(key, value)
    if getattr(config, "lead_filter", None) is not None:
        with_scaled_filter(config, scales)


__all__ = [
    "EXTRA_RUN_PARAMETERS",
    "LEAD_FILTER_SCALES",
    "check_scales",
    "option_text",
    "plant_and_controller_vehicles",
    "simulation_config",
    "split_values",
    "started_scenario",
    "untuned_controller_config",
    "with_scaled_filter",
]
