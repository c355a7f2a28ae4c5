"""Every value a study plans, built when the spec loads into the objects its runs build (`run_build.py`), so that a
value every run with it would refuse (`grid.speed_kmh = 0`, `grid.laps = 0`, `grid.initial_offset_m = 1000`, a NaN,
a negative rate, a controller option out of its range) is refused before any run, naming the spec key and the value.

A value is refused when, with the other parameters at their defaults, building it fails in every context (on every
vehicle, or on every scenario), and no planned combination with the other swept values of the same object builds
either. A value refused only in some combinations (`min_lookahead_m = 30` where `max_lookahead_m` is swept over 20
and 40) stays those runs' error.

The objects, each with the parameters it takes:

- the SimulationConfig: its fields, `conditions` and the condition fields;
- the vehicles: payload_kg and controller_payload_kg, on each of the study's vehicles, and every vehicle's width
  as the scenarios take it (`ScenarioOptions`);
- the start: initial_offset_m (within +-MAX_INITIAL_OFFSET_M = 50 m, and nearer the path than max_abs_cte_m, beyond
  which a run has left the path and stops), initial_heading_error_deg (within +-90 deg) and max_abs_cte_m, on each
  scenario (whose own initial error applies where none is given);
- each controller's config: its options and lead-filter scales, for each vehicle's geometry. The vehicle's tuning is
  not looked up (it is made on first use, which may take minutes): scales are checked against a configured lead
  filter only.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Iterator, Mapping, Sequence
from typing import Any

from workbench.apps.studies.run_build import (
    EXTRA_RUN_PARAMETERS,
    check_scales,
    plant_and_controller_vehicles,
    simulation_config,
    started_scenario,
    untuned_controller_config,
)
from workbench.base.errors import WorkbenchInputError, value_text
from workbench.simulation.scenarios import ScenarioOptions
from workbench.simulation.simulator import SimulationConfig

#: The parameters of a run's start.
START_PARAMETERS = ("initial_offset_m", "initial_heading_error_deg", "max_abs_cte_m")
#: The parameters of the vehicles.
VEHICLE_PARAMETERS = ("payload_kg", "controller_payload_kg")

#: A spec parameter: key -> (where it is in the spec, e.g. "grid.speed_kmh"; its values: the grid's, or one per
#: sample).
Parameters = Mapping[str, tuple[str, Sequence[Any]]]


def _combinations(
    key: str, value: Any, sample: int | None, axes: Parameters, draws: Parameters, samples: int
) -> Iterator[dict[str, Any]]:
    """The planned values of one object's parameters with key = value: the product of the other axes, with the
    other draws of that sample (a drawn value) or of every sample (a grid value)."""
    other_axes = {k: values for k, (_, values) in axes.items() if k != key}
    other_draws = {k: values for k, (_, values) in draws.items() if k != key}
    indices = [sample] if sample is not None else range(samples) if other_draws else [None]
    for i in indices:
        drawn = {k: values[i] for k, values in other_draws.items()} if i is not None else {}
        for combination in itertools.product(*other_axes.values()):
            yield {key: value} | dict(zip(other_axes, combination, strict=True)) | drawn


def _error(build: Callable[[Any, dict[str, Any]], object], contexts: Sequence[Any], values: dict[str, Any]) -> str:
    """The first context's error when building `values` fails in every context; "" when it builds in one."""
    first = ""
    for context in contexts:
        try:
            build(context, values)
        except WorkbenchInputError as exc:
            first = first or str(exc)
        else:
            return ""
    return first


def check_object(
    axes: Parameters,
    draws: Parameters,
    samples: int,
    contexts: Sequence[Any],
    build: Callable[[Any, dict[str, Any]], object],
) -> None:
    """Refuse a value of one object's parameters (axes and draws) that fails to build (`build(context, values)`)
    in every context and every planned combination with the object's other values: first a value that fails on
    its own (the others at their defaults), so that the value to blame is named, then one that fails only with the
    others planned. See the module docstring.

    Parameters
    ----------
    axes : mapping
        The object's grid parameters: key -> (where it is in the spec, its values).
    draws : mapping
        The object's drawn parameters: key -> (where it is in the spec, one value per sample).
    samples : int
        The study's number of samples (1 without draws).
    contexts : sequence
        What the object is built in (e.g. each vehicle's geometry; [None] for none).
    build : callable
        Called as ``build(context, values)``; raises WorkbenchInputError for values it refuses.

    Raises
    ------
    WorkbenchInputError
        A value that fails to build in every context and every planned combination, naming its spec key.
    """
    # (parameter, where it is set, value, the random draw's index: None for a grid value)
    given: list[tuple[str, str, Any, int | None]] = [
        (k, where, v, None) for k, (where, values) in axes.items() for v in values
    ]
    given += [(k, where, v, i) for k, (where, values) in draws.items() for i, v in enumerate(values)]
    alone: dict[tuple[str, str], str] = {}
    for key, _, value, _ in given:
        ident = (key, repr(value))
        if ident not in alone:
            alone[ident] = _error(build, contexts, {key: value})
    for on_its_own in (True, False):
        for key, where, value, sample in given:
            if bool(alone[(key, repr(value))]) != on_its_own:
                continue
            for values in _combinations(key, value, sample, axes, draws, samples):
                error = _error(build, contexts, values)
                if not error:
                    break  # refused only in some combinations: those runs' error
            else:
                others = ", ".join(f"{k} = {value_text(v)}" for k, v in values.items() if k != key)
                reason = alone[(key, repr(value))] or f"with {others}: {error}"
                drawn = "" if sample is None else f" (sample {sample})"
                raise WorkbenchInputError(
                    f"{where}{drawn} = {value_text(value)}: {reason}; every run with it would fail, so none is started"
                )


def _parameters(
    where: str, axes: Mapping[str, Sequence[Any]], draws: Mapping[str, Sequence[Any]], keys: Sequence[str] | None
) -> tuple[dict[str, tuple[str, Sequence[Any]]], dict[str, tuple[str, Sequence[Any]]]]:
    """The axes and draws among `keys` (None: all), each with where it is in the spec."""

    def pick(table: str, values: Mapping[str, Sequence[Any]]) -> dict[str, tuple[str, Sequence[Any]]]:
        return {k: (f"{table}.{k}", v) for k, v in values.items() if keys is None or k in keys}

    return pick(f"grid{where}", axes), pick(f"random{where}", draws)


def check_values(spec: Any, models: Mapping[str, Any], scenarios: Mapping[str, Any]) -> None:
    """Check every value `spec` (a StudySpec, typed) plans, as the module docstring says. models: each vehicle's
    model (by the spec's name for it); scenarios: each scenario built (by the spec's name for it).

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
        A value every run with it would refuse, naming the spec key and the value.
    """
    samples = spec.samples or 1
    for vehicle, model in models.items():
        try:
            ScenarioOptions(model.geometry.width_m, spec.track_file)
        except WorkbenchInputError as exc:
            raise WorkbenchInputError(f"study.vehicles: {vehicle}: {exc}") from None
    run_draws = spec.drawn()
    simulation = [k for k in (*spec.grid, *run_draws) if k not in EXTRA_RUN_PARAMETERS]
    axes, draws = _parameters("", spec.grid, run_draws, simulation)
    check_object(axes, draws, samples, [None], lambda _, values: simulation_config(values))

    axes, draws = _parameters("", spec.grid, run_draws, VEHICLE_PARAMETERS)
    check_object(
        axes,
        draws,
        samples,
        list(models.values()),
        lambda model, v: plant_and_controller_vehicles(model, v.get("payload_kg"), v.get("controller_payload_kg")),
    )

    def start(scenario: Any, values: dict[str, Any]) -> object:
        cte = values.get("max_abs_cte_m", SimulationConfig.max_abs_cte_m)
        offset, heading = values.get("initial_offset_m"), values.get("initial_heading_error_deg")
        return started_scenario(scenario, offset, heading, cte)

    axes, draws = _parameters("", spec.grid, run_draws, START_PARAMETERS)
    check_object(axes, draws, samples, list(scenarios.values()), start)

    geometries = list({id(m.geometry): m.geometry for m in models.values()}.values())
    for controller in spec.controllers:

        def options(geometry: Any, values: dict[str, Any], controller: str = controller) -> object:
            config, scales = untuned_controller_config(controller, spec.controller_config, values, geometry)
            check_scales(config, scales)
            return config

        axes, draws = _parameters(
            f".{controller}", spec.controller_grid.get(controller, {}), spec.drawn(controller), None
        )
        check_object(axes, draws, samples, geometries, options)


__all__ = ["START_PARAMETERS", "VEHICLE_PARAMETERS", "check_object", "check_values"]
