"""A study spec (TOML) and the runs it plans: which scenarios, controllers and vehicles, over which parameter grids
and seeded random draws; for `workbench optimise` also the objective and the search space.

The format, tables [study], [grid], [grid.NAME], [random], [random.NAME] and [optimise] (with its objective and
search), is described with an example in docs/guide/studies.md ("Sweeps and optimisation"). Run parameters
(RUN_PARAMETERS) are the fields of `SimulationConfig` (its conditions as a preset name or file, and each of their
scalar fields, `condition_parameters.py`), payload_kg, controller_payload_kg (the payload the controller is built
for; omitted: the plant's), initial_offset_m and initial_heading_error_deg (omitted: the scenario's own), and
circuit_ranges (a file whose [circuits] table the generated circuits are drawn within, `circuit_parameters.py`;
a spec may carry the table and name itself).
Controller parameters are the controller's options and, for a controller that reads a lead filter,
lead_filter_zero_scale and lead_filter_pole_scale (`lead_filter_scaling.py`).

Planned runs are the product, per scenario, vehicle and controller, of the run-parameter axes, that controller's
axes and the random samples (draw i of every key together). Each run's id is a hash of its canonical parameters
(files by their path relative to the spec and a hash of their content; a circuit_ranges file by the ranges it
holds), so the same run always has the same id
and a restarted or extended study finds the runs it already has.

The spec is checked before any run starts, so that a mistake costs no runs: unknown tables, keys and names,
missing files, empty lists, NaN and wrong types are WorkbenchInputError naming the key and what is allowed; every
file the spec names is read as the runs will read it (`_check_files`); a study planning more than max_runs runs
(`run_count`, from the axes' sizes, before anything is planned; an optimisation: trials x runs) is refused saying
how many. Every planned value is then built into the objects its runs build (`value_check.py`): a value every run
with it would refuse (speed_kmh = 0, laps = 0, initial_offset_m = 1000, a controller option out of its range) is
refused naming the key and the value; a value refused only in combination with others stays that run's error. A
scenario a vehicle cannot follow at the study's fastest run is refused (`study_feasibility.py`) unless
study.allow_infeasible.
"""

from __future__ import annotations

import dataclasses
import hashlib
import itertools
import json
import math
import os
import typing
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import TYPE_CHECKING, Any

from controllers import CONTROLLERS
from workbench.apps.studies.circuit_parameters import (
    CIRCUIT_RANGES,
    check_circuits_table,
    planned_circuit_ranges,
    ranged_options,
    ranges_identity,
    scenario_values,
)
from workbench.apps.studies.condition_parameters import CONDITION_PARAMETERS, resolve_conditions
from workbench.apps.studies.distributions import SEARCHABLE, Distribution, key_rng
from workbench.apps.studies.run_build import EXTRA_RUN_PARAMETERS, LEAD_FILTER_SCALES
from workbench.apps.studies.study_feasibility import check_feasibility
from workbench.apps.studies.study_size import check_run_sizes
from workbench.apps.studies.value_check import check_values
from workbench.base.errors import WorkbenchInputError, value_text
from workbench.base.input_files import check_input_file, read_json, read_toml
from workbench.base.typed_tables import type_name, typed_value, unwrap
from workbench.simulation.metrics import METRIC_KEYS
from workbench.simulation.scenarios import (
    SCENARIOS,
    ZANDVOORT_ENV,
    ZANDVOORT_SOURCE,
    ScenarioOptions,
    is_named_scenario,
    zandvoort_track_file,
)
from workbench.simulation.simulator import SimulationConfig
from workbench.vehicles import VEHICLES

if TYPE_CHECKING:
    from workbench.vehicles.base import VehicleModel
    from workbench.vehicles.geometry import VehicleGeometry

#: Every run parameter and its type: SimulationConfig's fields (its conditions as `conditions`, a preset name or a
#: file, and each scalar field of them, `condition_parameters.py`), then the extras.
RUN_PARAMETERS: dict[str, Any] = {
    **{
        f.name: typing.get_type_hints(SimulationConfig)[f.name]
        for f in dataclasses.fields(SimulationConfig)
        if f.name != "conditions"
    },
    **CONDITION_PARAMETERS,
    **EXTRA_RUN_PARAMETERS,
}
#: Metrics an objective may weigh: the numeric metrics.json fields except the wall-clock step times and the limit
#: cycle's frequency and amplitude (null for a run without one, which would fail the trial). limit_cycle counts as
#: 1 or 0 (a penalty on runs that limit-cycle).
OBJECTIVE_METRICS = tuple(
    k
    for k in METRIC_KEYS
    if k not in ("scenario", "controller", "vehicle", "completed", "step_time_median_us", "step_time_p99_us")
    and k not in ("limit_cycle_hz", "limit_cycle_amplitude_deg")
)
AGGREGATES = ("mean", "max")
STUDY_KEYS = (
    "scenarios",
    "controllers",
    "vehicles",
    "controller_config",
    "track_file",
    "seed",
    "samples",
    "description",
    "max_runs",
    "allow_long_runs",
    "allow_infeasible",
)
OPTIMISE_KEYS = ("trials", "batch_size", "seed", "startup_trials", "aggregate", "objective", "search")
SCENARIO_FILE_SUFFIXES = (".csv", ".txt")
RUN_FORMAT = "workbench-run/1"
#: The most runs a study may plan (an optimisation: trials x runs per trial) unless study.max_runs or
#: `--max-runs N` allows more: 100 000 runs take hours on a workstation (about 0.2 s each on one core).
DEFAULT_MAX_RUNS = 100_000


def controller_parameters(controller: str) -> dict[str, Any]:
    """The parameters of a controller's runs and their types: its config options (`option_types`: a file option
    such as filter_file in place of the object it is read into), and the lead-filter scales when it reads a lead
    filter.

    Parameters
    ----------
    controller : str
        A registered controller's name (`controllers.CONTROLLERS`).

    Returns
    -------
    dict
        Option name -> its type annotation, in the config's field order.
    """
    from workbench.apps.controller_config import option_types

    params = option_types(CONTROLLERS[controller].config_type)
    if "filter_file" in params:
        params |= dict.fromkeys(LEAD_FILTER_SCALES, float)
    return params


def _check_distribution(where: str, dist: Distribution, annotation: Any, base_dir: Path) -> Distribution:
    base, _ = unwrap(annotation)
    if dist.produces == "choice":
        return Distribution(
            "choice", tuple(typed_value(f"{where} choice", v, annotation, base_dir) for v in dist.values)
        )
    if (dist.produces == "int" and base in (int, float)) or (dist.produces == "float" and base is float):
        return dist
    raise WorkbenchInputError(
        f"{where}: {dist.kind} draws {'whole numbers' if dist.produces == 'int' else 'numbers'}, but the parameter "
        f"is a {type_name(annotation)}"
        + ("; use integers = [low, high]" if base is int else "; use choice = [...]" if base is not float else "")
    )


def _names(key: str, value: object) -> tuple[str, ...]:
    if isinstance(value, str):
        value = [value]
    if not isinstance(value, list | tuple) or not all(isinstance(v, str) and v for v in value):
        raise WorkbenchInputError(f"study.{key} must be a list of names; got {value!r}")
    if not value:
        raise WorkbenchInputError(f"study.{key} is empty; give at least one")
    if len(set(value)) != len(value):
        raise WorkbenchInputError(f"study.{key} names one twice: {list(value)}")
    return tuple(value)


def _resolve_name(key: str, name: str, known: Sequence[str], suffixes: tuple[str, ...], base_dir: Path) -> str:
    """A registered name (for scenarios also a generated circuit's, circuit:SEED) as it is, or a file (relative to
    base_dir) as its absolute path."""
    if name in known:
        return name
    if key == "scenarios":
        try:
            if is_named_scenario(name):
                return name
        except WorkbenchInputError as exc:  # circuit: without a valid seed
            raise WorkbenchInputError(f"study.{key}: {exc}") from None
        known = [*known, "circuit:SEED"]
    path = Path(name).expanduser()
    path = path if path.is_absolute() else base_dir / path
    if path.suffix.lower() in suffixes or os.path.lexists(path):
        if not os.path.lexists(path):
            raise WorkbenchInputError(f"study.{key}: file {name!r} does not exist (looked for {path})")
        return str(check_input_file(path, f"study.{key}: file {name!r} ({path})"))
    kinds = " or ".join(f"a {s} file" for s in suffixes)
    raise WorkbenchInputError(f"study.{key}: unknown name {name!r}; choose one of {', '.join(known)} or give {kinds}")


def _axes(where: str, table: Mapping[str, Any], allowed: Mapping[str, Any], base_dir: Path) -> dict[str, tuple]:
    axes = {}
    for key, values in table.items():
        if key not in allowed:
            raise WorkbenchInputError(f"unknown parameter {where}.{key}; allowed: {', '.join(allowed)}")
        values = list(values) if isinstance(values, list | tuple) else [values]
        if not values:
            raise WorkbenchInputError(f"{where}.{key} is empty; give at least one value")
        typed = tuple(typed_value(f"{where}.{key}[{i}]", v, allowed[key], base_dir) for i, v in enumerate(values))
        if len({repr(v) for v in typed}) != len(typed):
            raise WorkbenchInputError(f"{where}.{key} lists a value twice: {values}")
        axes[key] = typed
    return axes


def _draws(where: str, table: Mapping[str, Any], allowed: Mapping[str, Any], base_dir: Path) -> dict:
    out = {}
    for key, dist in table.items():
        if key not in allowed:
            raise WorkbenchInputError(f"unknown parameter {where}.{key}; allowed: {', '.join(allowed)}")
        if not isinstance(dist, Distribution):
            dist = Distribution.parse(f"{where}.{key}", dist)
        out[key] = _check_distribution(f"{where}.{key}", dist, allowed[key], base_dir)
    return out


def _split(where: str, table: Mapping[str, Any], controllers: Sequence[str]) -> tuple[dict, dict[str, dict]]:
    """A [grid] or [random] table: (run-parameter entries, {controller: its entries})."""
    if not isinstance(table, Mapping):
        raise WorkbenchInputError(f"[{where}] must be a table; got {table!r}")
    run, per_controller = {}, {}
    for key, value in table.items():
        if key in CONTROLLERS:
            if key not in controllers:
                raise WorkbenchInputError(
                    f"[{where}.{key}] sets options of {key!r}, which study.controllers does not run "
                    f"({', '.join(controllers)})"
                )
            if not isinstance(value, Mapping):
                raise WorkbenchInputError(f"[{where}.{key}] must be a table of {key}'s options; got {value!r}")
            per_controller[key] = dict(value)
        elif key in RUN_PARAMETERS:
            run[key] = value
        else:
            raise WorkbenchInputError(
                f"unknown parameter {where}.{key}; allowed: the run parameters {', '.join(RUN_PARAMETERS)}, or a "
                f"table named by a controller ({', '.join(CONTROLLERS)}) for its options"
            )
    return run, per_controller


def _file_digest(path: Path, cache: dict[Path, str | None]) -> str | None:
    if path not in cache:
        try:
            cache[path] = hashlib.sha256(path.read_bytes()).hexdigest()
        except OSError:
            cache[path] = None
    return cache[path]


@dataclass(frozen=True)
class PlannedRun:
    """One run of a study, everything a worker needs."""

    run_id: str  # hash of the run's canonical parameters
    index: int  # >= 0; its place in the study's order
    scenario: str  # a scenario's name or an absolute waypoint-file path
    controller: str  # a registered controller's name
    vehicle: str  # a preset's name or an absolute vehicle-file path
    values: tuple[tuple[str, Any], ...] = ()  # the run parameters given, (name, typed value) pairs
    options: tuple[tuple[str, Any], ...] = ()  # the controller options given, (name, typed value) pairs
    sample: int | None = None  # the random draw's index (None: the study has no draws)
    controller_config: Path | None = None  # a controller-options TOML file
    track_file: Path | None = None  # the Zandvoort track file, for a zandvoort run (None: other scenarios)

    def parameters(self) -> dict[str, Any]:
        """The run's columns before its metrics: ids, names, speed_kmh (always) and each given parameter
        (controller options as "<controller>.<option>"), paths as text.

        Returns
        -------
        dict
            run_id, index, scenario, controller, vehicle, sample, speed_kmh (km/h, the default unless given),
            then the run's parameters and options.
        """

        def plain(v: Any) -> Any:
            return str(v) if isinstance(v, Path) else v

        row: dict[str, Any] = {
            "run_id": self.run_id,
            "index": self.index,
            "scenario": self.scenario,
            "controller": self.controller,
            "vehicle": self.vehicle,
            "sample": self.sample,
            "speed_kmh": SimulationConfig.speed_kmh,
        }
        row |= {k: plain(v) for k, v in self.values}
        row |= {f"{self.controller}.{k}": plain(v) for k, v in self.options}
        return row


@dataclass(frozen=True)
class OptimiseSettings:
    """The [optimise] table: trials (total), batch_size (trials asked and run together; fixed by the spec, not by
    the workers, so a study is the same on any machine), seed (the sampler's; None: the study's seed),
    startup_trials (random trials before TPE models the results), aggregate ("mean" or "max" of a trial's runs),
    objective (metric -> weight, summed per run) and search (controller parameter -> distribution)."""

    trials: int
    objective: Mapping[str, float]
    search: Mapping[str, Distribution]
    batch_size: int = 4
    seed: int | None = None
    startup_trials: int = 10
    aggregate: str = "mean"

    def __post_init__(self) -> None:
        for name, low in (("trials", 1), ("batch_size", 1), ("startup_trials", 0)):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int) or value < low:
                raise WorkbenchInputError(f"optimise.{name} must be a whole number >= {low}; got {value_text(value)}")
        if self.seed is not None and (isinstance(self.seed, bool) or not isinstance(self.seed, int) or self.seed < 0):
            raise WorkbenchInputError(f"optimise.seed must be a whole number >= 0; got {value_text(self.seed)}")
        if self.aggregate not in AGGREGATES:
            raise WorkbenchInputError(
                f"optimise.aggregate must be one of {', '.join(AGGREGATES)}; got {self.aggregate!r}"
            )
        if not isinstance(self.objective, Mapping) or not self.objective:
            raise WorkbenchInputError(
                "optimise.objective must be a table of metric weights, e.g. {rms_cte_m = 1.0, rms_steer_rate_deg_s = "
                f"0.002}}; allowed metrics: {', '.join(OBJECTIVE_METRICS)}; got {self.objective!r}"
            )
        weights = {}
        for key, weight in self.objective.items():
            if key not in OBJECTIVE_METRICS:
                raise WorkbenchInputError(
                    f"unknown metric optimise.objective.{key}; allowed: {', '.join(OBJECTIVE_METRICS)} (the wall-clock "
                    "step times are not: they differ between runs and machines; nor limit_cycle_hz and "
                    "limit_cycle_amplitude_deg: null for a run without a limit cycle; weigh limit_cycle)"
                )
            weights[key] = typed_value(f"optimise.objective.{key}", weight, float, Path())
        if not any(weights.values()):
            raise WorkbenchInputError(f"optimise.objective needs a weight other than 0; got {weights}")
        object.__setattr__(self, "objective", MappingProxyType(weights))
        if not isinstance(self.search, Mapping) or not self.search:
            raise WorkbenchInputError(
                "optimise.search must be a table of controller parameters and distributions, e.g. "
                "{frechet_threshold_m = {log_uniform = [0.005, 0.5]}}"
            )
        search = {}
        for key, dist in self.search.items():
            dist = dist if isinstance(dist, Distribution) else Distribution.parse(f"optimise.search.{key}", dist)
            if dist.kind not in SEARCHABLE:
                raise WorkbenchInputError(
                    f"optimise.search.{key}: an optimiser needs a bounded distribution ({', '.join(SEARCHABLE)}); "
                    f"got {dist.kind}"
                )
            search[key] = dist
        object.__setattr__(self, "search", MappingProxyType(search))

    @classmethod
    def from_table(cls, table: object) -> OptimiseSettings:
        """The settings from a spec's [optimise] table, every value checked.

        Parameters
        ----------
        table : mapping
            The parsed table: trials, objective and search (required), and the other keys of OPTIMISE_KEYS.

        Returns
        -------
        OptimiseSettings
            The checked settings.

        Raises
        ------
        WorkbenchInputError
            Not a table, an unknown or missing key, or a value the settings refuse.
        """
        if not isinstance(table, Mapping):
            raise WorkbenchInputError(f"[optimise] must be a table; got {table!r}")
        unknown = [k for k in table if k not in OPTIMISE_KEYS]
        if unknown:
            raise WorkbenchInputError(
                f"unknown key(s) optimise.{', optimise.'.join(unknown)}; allowed: {', '.join(OPTIMISE_KEYS)}"
            )
        for key in ("trials", "objective", "search"):
            if key not in table:
                raise WorkbenchInputError(f"[optimise] needs {key}; it has {', '.join(table) or 'nothing'}")
        return cls(**table)


@dataclass(frozen=True)
class StudySpec:
    """A study: see the module docstring. Values are checked and typed on construction (paths made absolute, the
    files they name read); the name lists are not empty and name none twice."""

    scenarios: Sequence[str]  # scenario names, or waypoint files relative to base_dir
    controllers: Sequence[str]  # registered controller names
    vehicles: Sequence[str]  # preset names, or vehicle TOML files relative to base_dir
    grid: Mapping[str, Any] = field(default_factory=dict)  # run parameter -> its axis of values ([grid])
    controller_grid: Mapping[str, Mapping[str, Any]] = field(default_factory=dict)  # controller -> option -> axis
    random: Mapping[str, Any] = field(default_factory=dict)  # run parameter -> its distribution ([random])
    controller_random: Mapping[str, Mapping[str, Any]] = field(default_factory=dict)  # controller -> option -> draw
    seed: int = 0  # whole, >= 0; the seed of the random draws
    samples: int | None = None  # whole, >= 1; the number of draws, given exactly when something is drawn
    controller_config: Path | None = None  # a controller-options TOML file for every run
    track_file: Path | None = None  # the Zandvoort track (None: from $WORKBENCH_ZANDVOORT_CSV or where it is kept)
    description: str = ""  # free text
    base_dir: Path = field(default_factory=Path.cwd)  # the folder relative paths are taken from (the spec file's)
    optimise: OptimiseSettings | None = None  # the [optimise] table (None: a sweep)
    max_runs: int = DEFAULT_MAX_RUNS  # whole, >= 1; most runs it may plan (an optimisation: trials x runs per trial)
    allow_long_runs: bool = False  # let runs longer than the bounds of `run_size` start (`study_size.py`)
    allow_infeasible: bool = False  # let runs start on a path a vehicle cannot follow at its planned speed

    def __post_init__(self) -> None:
        """Check and type the study, in this order: the names (controllers, scenarios, vehicles), the files and
        scalars of [study], the axes and draws, the samples, the optimisation, then its size and every file a run
        will read, then every value planned, built into the objects its runs build (`value_check.py`), the
        longest run's size (`study_size.py`) and whether each vehicle can follow each scenario's path
        (`study_feasibility.py`)."""
        object.__setattr__(self, "base_dir", Path(self.base_dir).resolve())
        self._resolve_names()
        self._resolve_study_files()
        self._check_scalars()
        models = self._type_axes()
        self._check_samples()
        if self.optimise is not None:
            object.__setattr__(self, "optimise", self._checked_optimise(self.optimise))
        if isinstance(self.max_runs, bool) or not isinstance(self.max_runs, int) or self.max_runs < 1:
            raise WorkbenchInputError(f"study.max_runs must be a whole number >= 1; got {value_text(self.max_runs)}")
        self._check_size()
        scenarios = self._check_files(models)
        check_values(self, models, scenarios)
        check_run_sizes(self, models, scenarios)
        check_feasibility(self, models, scenarios)

    # ------------------------------------------------------------------------------------------- typing
    def _resolve_names(self) -> None:
        """Controllers by their registered names; scenarios and vehicles by name or as files under base_dir."""
        base = self.base_dir
        controllers = _names("controllers", self.controllers)
        for name in controllers:
            if name not in CONTROLLERS:
                raise WorkbenchInputError(
                    f"study.controllers: unknown controller {name!r}; choose one of {', '.join(CONTROLLERS)}"
                )
        scenarios = tuple(
            _resolve_name("scenarios", n, tuple(SCENARIOS), SCENARIO_FILE_SUFFIXES, base)
            for n in _names("scenarios", self.scenarios)
        )
        vehicles = tuple(
            _resolve_name("vehicles", n, tuple(VEHICLES), (".toml",), base) for n in _names("vehicles", self.vehicles)
        )
        object.__setattr__(self, "controllers", controllers)
        object.__setattr__(self, "scenarios", scenarios)
        object.__setattr__(self, "vehicles", vehicles)

    def _resolve_study_files(self) -> None:
        """controller_config and track_file as absolute paths to readable files (track_file from the environment
        when zandvoort is run without one)."""
        if "zandvoort" in self.scenarios and self.track_file is None:
            try:  # $WORKBENCH_ZANDVOORT_CSV, or where the scenario looks for it
                found = zandvoort_track_file(None)
            except WorkbenchInputError as exc:
                raise WorkbenchInputError(
                    f"study.scenarios has zandvoort, which needs {ZANDVOORT_SOURCE}: give study.track_file "
                    f"or set the environment variable {ZANDVOORT_ENV} ({exc})"
                ) from None
            object.__setattr__(self, "track_file", str(found))
        for name in ("controller_config", "track_file"):
            value = getattr(self, name)
            if value is not None:
                path = typed_value(f"study.{name}", value, Path, self.base_dir)
                if not os.path.lexists(path):
                    raise WorkbenchInputError(f"study.{name}: file {str(value)!r} does not exist (looked for {path})")
                object.__setattr__(self, name, check_input_file(path, f"study.{name}: file {str(value)!r}"))

    def _check_scalars(self) -> None:
        for name in ("allow_long_runs", "allow_infeasible"):
            if not isinstance(getattr(self, name), bool):
                raise WorkbenchInputError(f"study.{name} must be true or false; got {value_text(getattr(self, name))}")
        if not isinstance(self.description, str):
            raise WorkbenchInputError(f"study.description must be text; got {self.description!r}")
        if isinstance(self.seed, bool) or not isinstance(self.seed, int) or self.seed < 0:
            raise WorkbenchInputError(f"study.seed must be a whole number >= 0; got {value_text(self.seed)}")

    def _type_axes(self) -> dict[str, Any]:
        """The grid and random tables typed against the run parameters and each controller's options (a
        parameter in one of them only); returns the vehicle models, read here so that a vehicle file a run cannot
        use is refused now."""
        base, controllers = self.base_dir, self.controllers
        grid = _axes("grid", self.grid, RUN_PARAMETERS, base)
        if "conditions" in grid:
            grid["conditions"] = tuple(resolve_conditions(v, base) for v in grid["conditions"])
        random = _draws("random", self.random, RUN_PARAMETERS, base)
        if "conditions" in random:
            raise WorkbenchInputError(
                "random.conditions: draw the conditions' fields (e.g. actuation_dead_time_s), not the preset; give "
                "conditions in [grid]"
            )
        controller_grid: dict[str, Mapping[str, Any]] = {}
        controller_random: dict[str, Mapping[str, Any]] = {}
        for where, table, out, parse in (
            ("grid", self.controller_grid, controller_grid, _axes),
            ("random", self.controller_random, controller_random, _draws),
        ):
            for name, entries in table.items():
                if name not in controllers:
                    raise WorkbenchInputError(
                        f"[{where}.{name}] sets options of {name!r}, which study.controllers does not run "
                        f"({', '.join(controllers)})"
                    )
                out[name] = MappingProxyType(parse(f"{where}.{name}", entries, controller_parameters(name), base))
        for where, axes, draws in [("", grid, random)] + [
            (f".{c}", controller_grid.get(c, {}), controller_random.get(c, {})) for c in controllers
        ]:
            both = sorted(set(axes) & set(draws))
            if both:
                raise WorkbenchInputError(
                    f"{', '.join(both)} is both in [grid{where}] and in [random{where}]; keep one"
                )
        models = _vehicle_models(self.vehicles)
        if any(k in grid or k in random for k in ("payload_kg", "controller_payload_kg")):
            others = [v for v in self.vehicles if not _has_payload(models[v])]
            if others:
                raise WorkbenchInputError(
                    f"payload_kg is given but vehicle(s) {', '.join(others)} have no payload; a payload applies to "
                    f"{', '.join(n for n in VEHICLES if _has_payload(n))}: run the others in a separate study"
                )
        object.__setattr__(self, "grid", MappingProxyType(grid))
        object.__setattr__(self, "random", MappingProxyType(random))
        object.__setattr__(self, "controller_grid", MappingProxyType(controller_grid))
        object.__setattr__(self, "controller_random", MappingProxyType(controller_random))
        return models

    def _check_samples(self) -> None:
        """samples is given exactly when something is drawn."""
        has_draws = bool(self.random) or any(self.controller_random.values())
        if self.samples is not None:
            if isinstance(self.samples, bool) or not isinstance(self.samples, int) or self.samples < 1:
                raise WorkbenchInputError(f"study.samples must be a whole number >= 1; got {value_text(self.samples)}")
            if not has_draws:
                raise WorkbenchInputError(f"study.samples = {self.samples} but [random] draws nothing; drop samples")
        elif has_draws:
            raise WorkbenchInputError("[random] draws parameters: give study.samples, the number of draws")

    # ------------------------------------------------------------------------------------------- checks
    def run_count(self) -> int:
        """How many runs `plan()` gives, counted from the axes' sizes without planning them: per scenario and
        vehicle, the sum over controllers of the product of the run-parameter axes, that controller's axes and
        the samples. (An optimisation runs this many per trial.)

        Returns
        -------
        int
            The number of runs `plan()` gives.
        """
        runs_per_controller = sum(self._runs_per_controller().values())
        return len(self.scenarios) * len(self.vehicles) * runs_per_controller

    def _runs_per_controller(self) -> dict[str, int]:
        grid = math.prod(len(values) for values in self.grid.values())
        samples = self.samples or 1
        return {
            c: grid * math.prod(len(v) for v in self.controller_grid.get(c, {}).values()) * samples
            for c in self.controllers
        }

    def total_runs(self) -> int:
        """The runs the whole study executes: run_count(), times the trials of an optimisation.

        Returns
        -------
        int
            The number of runs; a study planning more than `max_runs` is refused when built.
        """
        return self.run_count() * (self.optimise.trials if self.optimise is not None else 1)

    def _check_size(self) -> None:
        total = self.total_runs()
        if total <= self.max_runs:
            return
        axes = [f"{len(self.scenarios)} scenario(s)", f"{len(self.vehicles)} vehicle(s)"]
        per_controller = self._runs_per_controller()
        axes.append(
            " + ".join(f"{c} {n:,}" for c, n in per_controller.items()) + " runs per scenario and vehicle"
            if len(per_controller) > 1
            else f"{next(iter(per_controller.values())):,} runs per scenario and vehicle"
        )
        sizes = [f"{k} {len(v)}" for k, v in self.grid.items()]
        sizes += [f"{c}.{k} {len(v)}" for c, axes_c in self.controller_grid.items() for k, v in axes_c.items()]
        if self.samples:
            sizes.append(f"samples {self.samples:,}")
        trials = f" x {self.optimise.trials:,} trials" if self.optimise is not None else ""
        raise WorkbenchInputError(
            f"the study plans {total:,} runs ({' x '.join(axes)}{trials}; axes: {', '.join(sizes) or 'none'}), "
            f"more than the limit of {self.max_runs:,}: shrink the grid, the samples or the trials, or raise the "
            "limit with study.max_runs or --max-runs N"
        )

    def _check_files(self, models: Mapping[str, Any]) -> dict[str, Any]:
        """Read every file the runs will read, as they will: the controller-config file for each controller
        (its keys and values), waypoint and track files, and each file a controller option names (in the config
        file, the grid or a choice). A WorkbenchInputError names the key and the file; a controller-config file
        without a controller's table is warned about on stderr (`controller_config.missing_table_warning`). Returns
        each scenario built (sized for the first vehicle), by its name in the spec."""
        from workbench.apps.controller_config import read_controller_config
        from workbench.base.console import warn_on_stderr
        from workbench.simulation.scenarios import make_scenario

        scenarios = {}
        width = next(iter(models.values())).geometry.width_m
        ranges = planned_circuit_ranges(self)
        for scenario in self.scenarios:
            key, track = ("study.track_file", self.track_file) if scenario == "zandvoort" else ("study.scenarios", None)
            built_with = ranged_options(scenario, ScenarioOptions(width, track), ranges, self.base_dir)
            for label, options in built_with.items():
                try:
                    scenarios[label] = make_scenario(scenario, options)
                except WorkbenchInputError as exc:
                    raise WorkbenchInputError(f"{key}: {exc}") from None
        geometry = next(iter(models.values())).geometry
        checked: set[Path] = set()
        for controller in self.controllers:
            params = controller_parameters(controller)
            file_options = [k for k, t in params.items() if unwrap(t)[0] is Path]
            # Its file options are read here, into the config's objects, as a run will read them.
            config_type = CONTROLLERS[controller].config_type
            read_controller_config(self.controller_config, controller, config_type, (), geometry, warn_on_stderr)
            named: list[tuple[str, str, Any]] = []
            for where, table in (("grid", self.controller_grid), ("random", self.controller_random)):
                for key, values in table.get(controller, {}).items():
                    if key in file_options:
                        values = values.values if isinstance(values, Distribution) else values
                        named += [(f"{where}.{controller}.{key}", key, v) for v in values]
            search = self.optimise.search if self.optimise is not None else {}
            named += [(f"optimise.search.{k}", k, v) for k, d in search.items() if k in file_options for v in d.values]
            for where, key, path in named:
                if path is not None and path not in checked:
                    _check_option_file(where, key, path, geometry)
                    checked.add(path)
        return scenarios

    def _checked_optimise(self, optimise: OptimiseSettings) -> OptimiseSettings:
        """The [optimise] settings checked against the study (one controller, its options fixed or searched), with
        the search distributions typed."""
        if len(self.controllers) != 1:
            raise WorkbenchInputError(
                f"an optimise study tunes one controller; study.controllers has {list(self.controllers)}"
            )
        controller = self.controllers[0]
        allowed = controller_parameters(controller)
        if self.controller_random.get(controller):
            raise WorkbenchInputError(
                f"[random.{controller}] is not allowed in an optimise study: the best options would depend on the "
                f"draw; fix them in [grid.{controller}] or search them in [optimise.search]"
            )
        for key, values in self.controller_grid.get(controller, {}).items():
            if len(values) != 1:
                raise WorkbenchInputError(
                    f"grid.{controller}.{key} lists {len(values)} values; an optimise study fixes a controller option "
                    f"(one value) or searches it (optimise.search)"
                )
        search = {}
        for key, dist in optimise.search.items():
            if key not in allowed:
                raise WorkbenchInputError(
                    f"unknown parameter optimise.search.{key} for {controller}; allowed: {', '.join(allowed)}"
                )
            if key in self.controller_grid.get(controller, {}):
                raise WorkbenchInputError(f"{key} is both fixed in [grid.{controller}] and in [optimise.search]")
            search[key] = _check_distribution(f"optimise.search.{key}", dist, allowed[key], self.base_dir)
        return dataclasses.replace(optimise, search=search)

    # ------------------------------------------------------------------------------------------- planning
    def drawn(self, controller: str | None = None) -> dict[str, Any]:
        """The random draws, parameter -> one value per sample: of the run parameters (controller None), or of
        that controller's options.

        Parameters
        ----------
        controller : str or None
            One of the study's controllers (its [random.<controller>] table), or None for the run parameters'
            [random] table.

        Returns
        -------
        dict
            Parameter -> its `samples` values (one per sample), drawn from the study's seed and the parameter's
            name: the same spec draws the same values; {} when nothing is drawn.
        """
        samples = self.samples or 1
        if controller is None:
            return {k: d.draw(key_rng(self.seed, k), samples) for k, d in self.random.items()}
        table = self.controller_random.get(controller, {})
        return {k: d.draw(key_rng(self.seed, f"{controller}.{k}"), samples) for k, d in table.items()}

    def plan(self, options: Mapping[str, Any] | None = None) -> list[PlannedRun]:
        """Every run of the study, in order: per scenario, vehicle and controller, the product of the run-parameter
        axes (first listed outermost), the controller's axes, and the random samples. `options` adds controller
        parameters to every run (an optimiser's trial; the study must have one controller).

        Parameters
        ----------
        options : mapping or None
            Controller option -> value, added to every run (None: none).

        Returns
        -------
        list of PlannedRun
            `run_count()` runs, their index their place in that list; a run's id depends on its parameters and
            the content of the files it reads, not on its place.

        Raises
        ------
        WorkbenchInputError
            `options` given for a study of several controllers, an option the controller does not have, or a
            value it refuses.
        """
        digests: dict[Path, str | None] = {}
        extra = {}
        if options:
            if len(self.controllers) != 1:
                raise WorkbenchInputError("extra options need a study of one controller")
            allowed = controller_parameters(self.controllers[0])
            for key, value in options.items():
                if key not in allowed:
                    raise WorkbenchInputError(f"unknown option {key!r} for {self.controllers[0]}")
                extra[key] = typed_value(key, value, allowed[key], self.base_dir)
        samples = self.samples or 1
        run_draws = self.drawn()
        runs: list[PlannedRun] = []
        for scenario, vehicle, controller in itertools.product(self.scenarios, self.vehicles, self.controllers):
            axes = self.controller_grid.get(controller, {})
            draws = self.drawn(controller)
            for run_values in itertools.product(*self.grid.values()):
                for option_values in itertools.product(*axes.values()):
                    for i in range(samples):
                        values = dict(zip(self.grid, run_values, strict=True))
                        values |= {k: v[i] for k, v in run_draws.items()}
                        opts = dict(zip(axes, option_values, strict=True)) | {k: v[i] for k, v in draws.items()}
                        opts |= extra
                        sample = i if self.samples is not None else None
                        runs.append(self._run(len(runs), scenario, vehicle, controller, values, opts, sample, digests))
        return runs

    def _canonical(self, value: Any, digests: dict[Path, str | None]) -> Any:
        if isinstance(value, Path):
            return {
                "file": Path(os.path.relpath(value, self.base_dir)).as_posix(),
                "sha256": _file_digest(value, digests),
            }
        return value

    def _run(
        self,
        index: int,
        scenario: str,
        vehicle: str,
        controller: str,
        values: dict[str, Any],
        options: dict[str, Any],
        sample: int | None,
        digests: dict[Path, str | None],
    ) -> PlannedRun:
        def canon_name(name: str, known: Mapping[str, Any]) -> Any:
            return name if name in known or is_named_scenario(name) else self._canonical(Path(name), digests)

        track = self.track_file if scenario == "zandvoort" else None
        values = scenario_values(scenario, values)
        parameters = {k: self._canonical(v, digests) for k, v in sorted(values.items())}
        if CIRCUIT_RANGES in values:  # by the ranges it holds: a spec naming itself keeps its ids when edited
            parameters[CIRCUIT_RANGES] = ranges_identity(values[CIRCUIT_RANGES])
        document = {
            "format": RUN_FORMAT,
            "scenario": canon_name(scenario, SCENARIOS),
            "vehicle": canon_name(vehicle, VEHICLES),
            "controller": controller,
            "controller_config": self._canonical(self.controller_config, digests),
            "track_file": self._canonical(track, digests),
            "parameters": parameters,
            "options": {k: self._canonical(v, digests) for k, v in sorted(options.items())},
            "sample": sample,
        }
        text = json.dumps(document, sort_keys=True, separators=(",", ":"), allow_nan=False)
        return PlannedRun(
            run_id=hashlib.sha256(text.encode()).hexdigest()[:16],
            index=index,
            scenario=scenario,
            controller=controller,
            vehicle=vehicle,
            values=tuple(values.items()),
            options=tuple(options.items()),
            sample=sample,
            controller_config=self.controller_config,
            track_file=track,
        )


def _has_payload(vehicle: VehicleModel | str) -> bool:
    """Whether a vehicle (a model, or a preset name) carries a payload."""
    from workbench.vehicles.presets import carries_payload

    return carries_payload(vehicle if isinstance(vehicle, str) else vehicle.name)


def _vehicle_models(vehicles: Sequence[str]) -> dict[str, Any]:
    """Each vehicle (preset name or file) built from its preset or file: a file a run cannot use is refused now,
    naming it."""
    from workbench.vehicles.presets import load_vehicle

    models = {}
    for vehicle in vehicles:
        try:
            models[vehicle] = load_vehicle(vehicle)
        except WorkbenchInputError as exc:
            raise WorkbenchInputError(f"study.vehicles: {exc}") from None
    return models


def _check_option_file(where: str, key: str, path: Path, geometry: VehicleGeometry | None) -> None:
    """Read a file a controller option names, as the controller will (lead filters, curvature limits, steering
    lags, vehicle files); any other file must at least be readable."""
    from workbench.apps.controller_config import FILE_OPTIONS

    label = f"{where}: {path}"
    check_input_file(path, label)
    if path.suffix.lower() == ".json":
        read_json(path, label)  # deep nesting, bad JSON: refused here, whatever reads it next
    if key in FILE_OPTIONS:
        try:
            FILE_OPTIONS[key].read(path, geometry)
        except WorkbenchInputError as exc:
            raise WorkbenchInputError(f"{where}: {exc}") from None


def load_spec(path: str | Path, kind: str = "sweep", max_runs: int | None = None) -> StudySpec:
    """Read a study spec from a TOML file. kind: "sweep" (no [optimise] table) or "optimise" (one required);
    max_runs: the limit on the study's runs, over the spec's study.max_runs (None: the spec's, else
    DEFAULT_MAX_RUNS). WorkbenchInputError naming the file, the key and what is allowed for anything it cannot
    use.

    Parameters
    ----------
    path : str or pathlib.Path
        The spec's TOML file; relative paths in it are taken from its folder.
    kind : str
        "sweep" (the spec may not have an [optimise] table) or "optimise" (it must have one).
    max_runs : int or None
        The most runs the study may plan, whole and at least 1 (None: the spec's study.max_runs, else
        `DEFAULT_MAX_RUNS`).

    Returns
    -------
    StudySpec
        The study, every value it plans checked and typed (paths absolute, the files they name read).

    Raises
    ------
    WorkbenchInputError
        The file is missing or not TOML, a table or key is unknown, a name, value or file is refused, the study
        plans more than max_runs runs, or a run is too long or on a path a vehicle cannot follow (unless the spec
        allows them); the message names the file and the key.

    Examples
    --------
    >>> from workbench.apps.studies import load_spec
    >>> spec = load_spec("examples/sweep_dlc.toml")
    >>> spec.run_count()
    200
    >>> spec.plan()[0].parameters()["clothoid.frechet_threshold_m"]
    0.01
    """
    if kind not in ("sweep", "optimise"):
        raise WorkbenchInputError(f"kind must be sweep or optimise; got {kind!r}")
    path = Path(path)
    document = read_toml(path, f"spec file {str(path)!r}")
    try:
        spec = _from_document(document, kind, path.resolve().parent, max_runs)
        named = list(spec.grid.get("circuit_ranges", ())) + list(spec.drawn().get("circuit_ranges", ()))
        check_circuits_table(document, path, named, "in [grid]")
        return spec
    except WorkbenchInputError as exc:
        raise WorkbenchInputError(f"spec {path}: {exc}") from None


def _from_document(document: Mapping[str, Any], kind: str, base_dir: Path, max_runs: int | None = None) -> StudySpec:
    tables = ("study", "grid", "random", "circuits") + (("optimise",) if kind == "optimise" else ())
    unknown = [k for k in document if k not in tables]
    if unknown:
        hint = " ([optimise] belongs to `workbench optimise`)" if "optimise" in unknown else ""
        raise WorkbenchInputError(f"unknown table(s) {', '.join(unknown)}; allowed: {', '.join(tables)}{hint}")
    study = document.get("study")
    if not isinstance(study, Mapping):
        raise WorkbenchInputError(f"the spec needs a [study] table with {', '.join(STUDY_KEYS[:3])}")
    unknown = [k for k in study if k not in STUDY_KEYS]
    if unknown:
        raise WorkbenchInputError(f"unknown key(s) study.{', study.'.join(unknown)}; allowed: {', '.join(STUDY_KEYS)}")
    missing = [k for k in STUDY_KEYS[:3] if k not in study]
    if missing:
        raise WorkbenchInputError(f"[study] needs {', '.join(missing)}")
    controllers = _names("controllers", study["controllers"])
    grid, controller_grid = _split("grid", document.get("grid", {}), controllers)
    random, controller_random = _split("random", document.get("random", {}), controllers)
    optimise = None
    if kind == "optimise":
        if "optimise" not in document:
            raise WorkbenchInputError(f"an optimise spec needs an [optimise] table with {', '.join(OPTIMISE_KEYS)}")
        optimise = OptimiseSettings.from_table(document["optimise"])
    return StudySpec(
        scenarios=study["scenarios"],
        controllers=controllers,
        vehicles=study["vehicles"],
        grid=grid,
        controller_grid=controller_grid,
        random=random,
        controller_random=controller_random,
        seed=study.get("seed", 0),
        samples=study.get("samples"),
        controller_config=study.get("controller_config"),
        track_file=study.get("track_file"),
        description=study.get("description", ""),
        base_dir=base_dir,
        optimise=optimise,
        max_runs=max_runs if max_runs is not None else study.get("max_runs", DEFAULT_MAX_RUNS),
        allow_long_runs=study.get("allow_long_runs", False),
        allow_infeasible=study.get("allow_infeasible", False),
    )


__all__ = [
    "DEFAULT_MAX_RUNS",
    "LEAD_FILTER_SCALES",
    "OBJECTIVE_METRICS",
    "RUN_PARAMETERS",
    "OptimiseSettings",
    "PlannedRun",
    "StudySpec",
    "controller_parameters",
    "load_spec",
]
