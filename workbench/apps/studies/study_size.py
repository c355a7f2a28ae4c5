"""A study's longest run, sized before any run starts (`check_run_sizes`): a sweep or optimisation whose slowest,
longest run may simulate more than the bounds of `workbench.simulation.run_size` (`speed_kmh = [0.001]` and no
time limit: days of simulated time and a trace of tens of GB per run) is refused naming the keys that shorten it and
`study.allow_long_runs = true`, which lets it start.

A run's size grows as its planned speed falls and its laps, controller rate and time-out grow: the planned speed
profile is pointwise monotone in the speed asked for and in its lateral and longitudinal bounds (`speed_profile`),
so the study's longest run is sized at the extremes of the values it plans (the grid's and the draws'), scenario by
scenario, with the most outputs of its vehicles. Laps asked of a study whose every scenario is an open path are
refused too: laps apply to closed paths only.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Mapping
from typing import Any

from workbench.base.errors import WorkbenchInputError, value_text
from workbench.simulation.run_config import SimulationConfig
from workbench.simulation.run_size import RunSize, check_run_size
from workbench.simulation.simulator import plan_path_speed

#: The SimulationConfig fields a run's size depends on, each with the extreme that makes the run longest.
LONGEST: dict[str, Callable[[list[Any]], Any]] = {
    "speed_kmh": min,
    "max_lateral_accel_g": min,
    "max_accel_mps2": min,
    "max_decel_mps2": min,
    "laps": max,
    "controller_rate_hz": max,
}
#: What shortens a study's runs, and what allows long ones (the refusal names both).
SHORTEN = "a higher speed_kmh, fewer laps or a max_time_s in [grid] shortens it"
ALLOW = "study.allow_long_runs = true in [study]"


def planned_values(spec: Any) -> dict[str, tuple[str, list[Any]]]:
    """Each run parameter the study plans: where it is in the spec and every value of it (grid and draws).

    Parameters
    ----------
    spec : StudySpec
        The study, its values typed.

    Returns
    -------
    dict
        Parameter -> ("grid.<key>" or "random.<key>", its values).
    """
    values = {k: (f"grid.{k}", list(v)) for k, v in spec.grid.items()}
    values |= {k: (f"random.{k}", list(v)) for k, v in spec.drawn().items()}
    return values


def longest_config(values: Mapping[str, tuple[str, list[Any]]]) -> list[SimulationConfig]:
    """The configs of the study's longest runs: the extreme of each LONGEST field planned (the others at their
    defaults), with the largest max_time_s given and, when a run has none, without one (the default time-out);
    the plant rate is the controller rate (it does not change the steps).

    Parameters
    ----------
    values : mapping
        Run parameter -> (where it is in the spec, its planned values) (`planned_values`).

    Returns
    -------
    list of SimulationConfig
        One or two configs: with the largest max_time_s given, and without one when a run has none.

    Raises
    ------
    WorkbenchInputError
        Values SimulationConfig refuses together (those runs' own errors: the caller lets them be).
    """
    fields = {k: pick(values[k][1]) for k, pick in LONGEST.items() if k in values}
    fields.setdefault("controller_rate_hz", SimulationConfig.controller_rate_hz)
    fields["plant_rate_hz"] = fields["controller_rate_hz"]
    listed = values["max_time_s"][1] if "max_time_s" in values else [None]
    given = [t for t in listed if t is not None]
    time_outs = ([max(given)] if given else []) + ([None] if None in listed else [])
    return [SimulationConfig(**fields, max_time_s=t) for t in time_outs]


def check_run_sizes(spec: Any, models: Mapping[str, Any], scenarios: Mapping[str, Any]) -> None:
    """Refuse a study (`spec`, a typed StudySpec) whose longest run exceeds the bounds, unless
    spec.allow_long_runs, and laps on a study of open paths only. models: each vehicle's model; scenarios: each
    scenario built, by the spec's names.

    Parameters
    ----------
    spec : StudySpec
        The study, its values typed.
    models : mapping
        Vehicle name -> its model (VehicleModel).
    scenarios : mapping
        Scenario name -> the scenario built (Scenario).

    Raises
    ------
    WorkbenchInputError
        Laps above 1 on open paths only, or a longest run beyond the bounds of `run_size` without
        study.allow_long_runs.
    """
    values = planned_values(spec)
    if "laps" in values and max(values["laps"][1]) > 1 and not any(s.path.closed for s in scenarios.values()):
        where, laps = values["laps"]
        raise WorkbenchInputError(
            f"{where} = {value_text(max(laps))}: the study's scenarios ({', '.join(scenarios)}) are open paths (each "
            "has two ends); laps apply to closed paths only, so give 1"
        )
    if spec.allow_long_runs:
        return
    outputs = max(len(model.output_names) for model in models.values())
    try:
        configs = longest_config(values)
    except WorkbenchInputError:
        return  # values refused together are those runs' errors
    for name, scenario in scenarios.items():
        for config in configs:
            if not scenario.path.closed:  # laps are a closed path's
                config = dataclasses.replace(config, laps=1)
            size = RunSize.of(plan_path_speed(scenario.path, config), config, outputs)
            shown = ", ".join(
                f"{k} = {value_text(getattr(config, k))}" for k in (*LONGEST, "max_time_s") if k in values
            )
            label = f"the study's longest run on {name}" + (f" ({shown})" if shown else "")
            check_run_size(size, label, SHORTEN, ALLOW)


__all__ = ["check_run_sizes", "longest_config", "planned_values"]
