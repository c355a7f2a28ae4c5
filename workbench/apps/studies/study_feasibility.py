"""Whether a study's vehicles can follow its scenarios' paths, judged before any run starts
(`check_feasibility`): a sweep or optimisation with a scenario a vehicle cannot follow at the planned speed (a
waypoint file with a 3 m circle, two 90-degree turns 0.5 m apart; `workbench.simulation.feasibility`) is refused
naming study.scenarios, the file, the vehicle and the speed, with the places and the limit, unless
`study.allow_infeasible = true`, which lets it start (the same refusal as `workbench run`'s,
`feasibility.refuse_infeasible`).

What a path asks of a vehicle grows with its planned speed (the steering's rate, the rollover threshold, the tyres'
grip and an understeering vehicle's lock), and the planned speed profile is pointwise monotone in the speed asked
for and in its lateral and longitudinal bounds (`speed_profile`): so each scenario is judged once, at the study's
fastest run (the largest of each of those values it plans, the grid's and the draws'), for each vehicle at the
heaviest payload it plans (a heavier payload only lowers the tractor-semitrailer's rollover threshold). A study of
200 runs over one scenario and one vehicle plans one path and judges it once.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from workbench.apps.studies.study_size import planned_values
from workbench.base.errors import WorkbenchInputError, value_text
from workbench.simulation.feasibility import path_feasibility_warnings, refuse_infeasible
from workbench.simulation.run_config import SimulationConfig
from workbench.simulation.simulator import plan_path_speed

#: The SimulationConfig fields the planned speed grows with: the study's fastest run takes the largest of each.
FASTEST = ("speed_kmh", "max_lateral_accel_g", "max_accel_mps2", "max_decel_mps2")
#: What lets a study start on a path its vehicles cannot follow (the refusal ends with it).
ALLOW = "study.allow_infeasible = true in [study]"


def fastest_config(values: Mapping[str, tuple[str, list[Any]]]) -> SimulationConfig:
    """The config of the study's fastest run: the largest of each FASTEST field planned (`planned_values`), the
    others at their defaults.

    Parameters
    ----------
    values : mapping
        Run parameter -> (where it is in the spec, its planned values) (`planned_values`).

    Returns
    -------
    SimulationConfig
        The fastest run's settings.

    Raises
    ------
    WorkbenchInputError
        Values SimulationConfig refuses together (those runs' own errors: the caller lets them be).
    """
    return SimulationConfig(**{k: max(values[k][1]) for k in FASTEST if k in values})


def check_feasibility(spec: Any, models: Mapping[str, Any], scenarios: Mapping[str, Any]) -> None:
    """Refuse a study (`spec`, a typed StudySpec) one of whose vehicles cannot follow one of its scenarios at the
    study's fastest run, unless spec.allow_infeasible: the refusal names study.scenarios, the scenario (a file by
    its path), the vehicle and the speed, then the places and the limit of the first such pair, and how many
    other pairs there are. models: each vehicle's model; scenarios: each scenario built, by the spec's names.

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
        A vehicle cannot follow a scenario at the fastest run's planned speed, without study.allow_infeasible.
    """
    if spec.allow_infeasible:
        return
    from workbench.vehicles.presets import with_payload

    values = planned_values(spec)
    try:
        config = fastest_config(values)
    except WorkbenchInputError:
        return  # values refused together are those runs' errors
    payloads = values.get("payload_kg", ("", []))[1]
    heaviest = max(payloads) if payloads else None
    refused: list[tuple[str, str, list[str]]] = []
    for name, scenario in scenarios.items():
        path = plan_path_speed(scenario.path, config)
        for vehicle, model in models.items():
            plant = model if heaviest is None else with_payload(model, heaviest)  # every vehicle carries one then
            warnings = path_feasibility_warnings(path, plant)
            if warnings:
                refused.append((name, vehicle, warnings))
    if not refused:
        return
    name, vehicle, warnings = refused[0]
    speed = f"speed_kmh = {value_text(config.speed_kmh)}"
    shown = [f"{k} = {value_text(getattr(config, k))}" for k in FASTEST[1:] if k in values]
    if heaviest is not None:
        shown.append(f"payload_kg = {value_text(heaviest)}")
    others = f" (and {len(refused) - 1} more scenario-vehicle pair(s))" if len(refused) > 1 else ""
    about = (
        f"study.scenarios: {name} cannot be followed by {vehicle} at the study's fastest run, "
        f"{', '.join([speed, *shown])}{others}"
    )
    refuse_infeasible(warnings, ALLOW, about)


__all__ = ["check_feasibility", "fastest_config"]
