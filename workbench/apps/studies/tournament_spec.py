"""A tournament spec (TOML): which controllers compete on which vehicles, the training set they are tuned on, the
test set they are judged on, the trial budget each gets alike, the objectives, and the rules that name each
controller's chosen configuration and rank the controllers.

Tables: [tournament] (controllers, vehicles, trials, batch_size, seed, objectives, selection, ranking,
failure_score, off_path_m, front_points, inform_delays, max_runs, track_file, description), [train] and [test]
(scenarios, speeds_kmh, conditions, seeds: a set's cases are their product with the vehicles; circuit_ranges: a
file whose [circuits] table the set's generated circuits are drawn within, the run parameter of that name, which
may be the spec itself when it carries the table), [circuits] (`workbench.simulation.circuit_ranges`), [search.NAME] (a
controller's search space: its own, `controllers.search_space.controller_search_space`, with the table's entries
over it, key by key) and [fixed.NAME] (options fixed for every run of a controller). docs/guide/studies.md
("Tournament") shows an annotated example.

A case is one scenario (a generated circuit with the ranges file it is drawn within), vehicle, speed, conditions
and seed; its id (`case_id`) is the same text across controllers and configurations. A case in both sets is
refused: the test set is held out. Internally the spec is one `StudySpec` per controller and set (`studies`), so
that every check of a study applies to each (names, files, values every run would refuse, run sizes, feasibility
of each path for each vehicle at the set's fastest speed); the training study carries the trial budget and the
search space as its [optimise] settings, which checks them against the controller's options. The MPCs (every
controller with a `max_solve_time_s` option) get a solve budget they never reach, MPC_SOLVE_BUDGET_S, unless
[fixed.NAME] gives one, so that their runs reproduce bit for bit.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import Any

from controllers import CONTROLLERS
from workbench.apps.studies.circuit_parameters import check_circuits_table, drawn_ranges_key
from workbench.apps.studies.distributions import SEARCHABLE, Distribution
from workbench.apps.studies.run_build import LEAD_FILTER_SCALES
from workbench.apps.studies.spec import (
    DEFAULT_MAX_RUNS,
    OBJECTIVE_METRICS,
    OptimiseSettings,
    PlannedRun,
    StudySpec,
    controller_parameters,
)
from workbench.base.errors import WorkbenchInputError, value_text
from workbench.base.input_files import read_toml
from workbench.base.typed_tables import typed_value

TABLES = ("tournament", "train", "test", "search", "fixed", "circuits")
TOURNAMENT_KEYS = (
    "controllers",
    "vehicles",
    "trials",
    "batch_size",
    "seed",
    "objectives",
    "selection",
    "ranking",
    "failure_score",
    "off_path_m",
    "front_points",
    "inform_delays",
    "max_runs",
    "track_file",
    "description",
)
SET_KEYS = ("scenarios", "speeds_kmh", "conditions", "seeds", "circuit_ranges")
SETS = ("train", "test")
#: The objectives a front is drawn over unless the spec names others: tracking (RMS and max |CTE|, m) against
#: steering effort (RMS steering-wheel rate, deg/s), each the mean over the training cases. The max |CTE| is the one
#: once on the path (`max_abs_cte_on_path_m`): the same as max_abs_cte_m for a run that starts on it, and for a
#: scenario that starts off it (fig17: 1 m) the tracking after the approach, so that the offset every controller
#: starts with does not swamp the differences between them.
DEFAULT_OBJECTIVES = ("rms_cte_m", "max_abs_cte_on_path_m", "rms_steer_rate_deg_s")
#: The weighted sum that names the chosen point of a front unless the spec states another: max |CTE| on the path
#: (m) plus 0.002 m per deg/s of RMS steering-wheel rate (100 deg/s of steering rate weigh as 0.2 m of |CTE|).
DEFAULT_SELECTION = MappingProxyType({"max_abs_cte_on_path_m": 1.0, "rms_steer_rate_deg_s": 0.002})
#: The ranking scalar of a test run unless the spec states another: the same weighted sum.
DEFAULT_RANKING = DEFAULT_SELECTION
#: The ranking scalar of a failed run unless the spec states another: 30, the |CTE| (m) at which a run has left
#: the path (`SimulationConfig.max_abs_cte_m`), worse than any run that stays on it.
DEFAULT_FAILURE_SCORE = 30.0
#: A run whose |CTE| once on the path (`max_abs_cte_on_path_m`) exceeds this (m) has left the path and fails, unless
#: the spec states another bound: with its reference point 1 m off the path, the truck's 2.59 m outline reaches past
#: the edge of a 3.5 m lane centred on the path (1 + 1.3 > 1.75 m). The simulator's own bound (30 m, the run stops)
#: is for a run that has lost the path altogether, and a path without track widths has no track to leave.
DEFAULT_OFF_PATH_M = 1.0
#: The most front points carried to the test set per controller, and the default.
MAX_FRONT_POINTS = 5
#: Trials asked and run together unless the spec says: part of the spec, so any backend gives the same trials.
DEFAULT_BATCH_SIZE = 4
#: The MPCs' solver budget (s) in a tournament: the most their option allows, never reached by a solve of the
#: horizons they search, so that no solve is cut short and a run reproduces bit for bit on any machine.
MPC_SOLVE_BUDGET_S = 10.0
#: The option that sets an MPC's solver budget.
SOLVE_BUDGET_OPTION = "max_solve_time_s"


def case_id(row: Mapping[str, Any]) -> str:
    """A case's id from a run's row or parameters: "scenario|vehicle|speed_kmh|conditions|seed" (speed as %g); a
    circuit drawn within a circuit_ranges file is "circuit:SEED (FILE NAME)".

    Parameters
    ----------
    row : mapping
        A run's row or `PlannedRun.parameters`: scenario, vehicle, speed_kmh (km/h), conditions, seed, and
        circuit_ranges when given.

    Returns
    -------
    str
        The id, the same for every controller and configuration run on the case.

    Examples
    --------
    >>> from workbench.apps.studies.tournament_spec import case_id
    >>> row = {"scenario": "dlc", "vehicle": "dynamic-bicycle", "speed_kmh": 40.0,
    ...        "conditions": "automotive", "seed": 0}
    >>> case_id(row)
    'dlc|dynamic-bicycle|40|automotive|0'
    """
    scenario, ranges = row["scenario"], row.get("circuit_ranges")
    if isinstance(ranges, str | Path) and str(ranges):
        scenario = f"{scenario} ({Path(ranges).name})"
    return f"{scenario}|{row['vehicle']}|{row['speed_kmh']:g}|{row['conditions']}|{row['seed']}"


def weights_text(weights: Mapping[str, float]) -> str:
    """A weighted sum in words, e.g. "1 x max_abs_cte_on_path_m + 0.002 x rms_steer_rate_deg_s".

    Parameters
    ----------
    weights : mapping of str to float
        Metric -> weight, in the order the sum names them.

    Returns
    -------
    str
        The terms joined by " + ".
    """
    return " + ".join(f"{w:g} x {k}" for k, w in weights.items())


@dataclass(frozen=True)
class CaseSet:
    """A set of cases (train or test): its scenarios (names, "circuit:SEED", or waypoint/track files relative to
    the spec), speeds (km/h), conditions (presets or files) and seeds of the conditions' noise; circuit_ranges: a
    file (relative to the spec) whose [circuits] table its generated circuits are drawn within (None: the
    defaults)."""

    name: str
    scenarios: tuple[str, ...]
    speeds_kmh: tuple[float, ...]
    conditions: tuple[str, ...] = ("ideal",)
    seeds: tuple[int, ...] = (0,)
    circuit_ranges: str | None = None

    @classmethod
    def from_table(cls, name: str, table: object) -> CaseSet:
        """A set from its spec table ([train] or [test]), every value checked and typed.

        Parameters
        ----------
        name : str
            "train" or "test": the table's name, in messages.
        table : mapping
            The parsed table: scenarios and speeds_kmh (required), conditions, seeds, circuit_ranges.

        Returns
        -------
        CaseSet
            The set.

        Raises
        ------
        WorkbenchInputError
            Not a table, an unknown or missing key, an empty list or a value listed twice, a value of the wrong
            type, a speed not above 0 km/h or a negative seed.
        """
        if not isinstance(table, Mapping):
            raise WorkbenchInputError(f"[{name}] must be a table with {', '.join(SET_KEYS)}; got {value_text(table)}")
        unknown = [k for k in table if k not in SET_KEYS]
        if unknown:
            raise WorkbenchInputError(
                f"unknown key(s) {name}.{f', {name}.'.join(unknown)}; allowed: {', '.join(SET_KEYS)}"
            )
        missing = [k for k in SET_KEYS[:2] if k not in table]
        if missing:
            raise WorkbenchInputError(f"[{name}] needs {', '.join(missing)}")
        values: dict[str, tuple[Any, ...]] = {}
        for key, kind in (("scenarios", str), ("speeds_kmh", float), ("conditions", str), ("seeds", int)):
            if key not in table:
                continue
            raw = table[key]
            items = list(raw) if isinstance(raw, list | tuple) else [raw]
            if not items:
                raise WorkbenchInputError(f"{name}.{key} is empty; give at least one")
            typed = tuple(typed_value(f"{name}.{key}[{i}]", v, kind) for i, v in enumerate(items))
            if len(set(typed)) != len(typed):
                raise WorkbenchInputError(f"{name}.{key} lists a value twice: {items}")
            values[key] = typed
        for speed in values["speeds_kmh"]:
            if not speed > 0:
                raise WorkbenchInputError(f"{name}.speeds_kmh must be > 0 km/h; got {value_text(speed)}")
        for seed in values.get("seeds", ()):
            if seed < 0:
                raise WorkbenchInputError(f"{name}.seeds must be whole numbers >= 0; got {seed}")
        ranges = None
        if "circuit_ranges" in table:
            ranges = typed_value(f"{name}.circuit_ranges", table["circuit_ranges"], str)
        return cls(name, **values, circuit_ranges=ranges)


def _weights(where: str, table: object, allowed: Sequence[str], default: Mapping[str, float]) -> dict[str, float]:
    """A table of metric weights: metrics among `allowed`, finite weights >= 0, not all 0."""
    if table is None:
        return dict(default)
    if not isinstance(table, Mapping) or not table:
        raise WorkbenchInputError(
            f"tournament.{where} must be a table of metric weights, e.g. {{max_abs_cte_m = 1.0, "
            f"rms_steer_rate_deg_s = 0.002}}; got {value_text(table)}"
        )
    weights = {}
    for key, weight in table.items():
        if key not in allowed:
            raise WorkbenchInputError(f"unknown metric tournament.{where}.{key}; allowed: {', '.join(allowed)}")
        value = typed_value(f"tournament.{where}.{key}", weight, float)
        if value < 0:
            raise WorkbenchInputError(f"tournament.{where}.{key} must be a weight >= 0; got {value_text(weight)}")
        weights[key] = value
    if not any(weights.values()):
        raise WorkbenchInputError(f"tournament.{where} needs a weight other than 0; got {weights}")
    return weights


def _whole(where: str, value: object, low: int, high: int | None = None) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < low or (high is not None and value > high):
        allowed = f"from {low} to {high}" if high is not None else f">= {low}"
        raise WorkbenchInputError(f"{where} must be a whole number {allowed}; got {value_text(value)}")
    return value


def _default_value(controller: str, key: str) -> Any:
    """The shipped default of a controller parameter: its config field's default (1.0 for a lead-filter scale)."""
    if key in LEAD_FILTER_SCALES:
        return 1.0
    config_type = CONTROLLERS[controller].config_type
    for f in dataclasses.fields(config_type):
        if f.name == key:
            if f.default is not dataclasses.MISSING:
                return f.default
            if f.default_factory is not dataclasses.MISSING:
                return f.default_factory()
    return None


def _contains(dist: Distribution, value: Any) -> bool:
    """Whether a searchable distribution can give `value`."""
    if dist.kind == "choice":
        return any(type(value) is type(c) and value == c for c in dist.values)
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        return False
    if dist.kind == "integers" and value != int(value):
        return False
    return dist.values[0] <= value <= dist.values[1]


@dataclass(frozen=True)
class TournamentSpec:
    """A tournament (module docstring). Built on construction: search, per controller, parameter -> distribution
    (its own space with the spec's [search.NAME] over it, the fixed options left out); fixed, per controller,
    option -> value for every run (the MPCs' solve budget included); defaults, per controller, the shipped default
    of each searched parameter (trial 0); studies, (controller, set) -> StudySpec."""

    controllers: tuple[str, ...]  # registered controller names, not empty, none twice
    vehicles: tuple[str, ...]  # preset names or vehicle TOML files, not empty
    train: CaseSet  # the training cases, the CaseSet named "train"
    test: CaseSet  # the held-out test cases, the CaseSet named "test" (no case in both sets)
    trials: int  # whole, >= 1; the trial budget of each controller
    batch_size: int = DEFAULT_BATCH_SIZE  # whole, >= 1; trials asked and run together
    seed: int = 0  # whole, >= 0; the seed of the trial samplers and of the judging's bootstrap
    objectives: tuple[str, ...] = DEFAULT_OBJECTIVES  # the metrics a front is drawn over (of OBJECTIVE_METRICS)
    # None gives the default weights; __post_init__ replaces it by the checked weights, so that a constructed spec
    # always holds a mapping (a field's type cannot differ between the constructor and the instance)
    selection: Mapping[str, float] = field(
        default=None,  # type: ignore[arg-type]
        metadata={"doc": "objective -> weight (>= 0, not all 0) naming each front's chosen point (None: the "
                         "default, DEFAULT_SELECTION)"},
    )
    ranking: Mapping[str, float] = field(
        default=None,  # type: ignore[arg-type]
        metadata={"doc": "metric of OBJECTIVE_METRICS -> weight (>= 0, not all 0) of a test run's ranking scalar "
                         "(None: the default, DEFAULT_RANKING)"},
    )
    failure_score: float = DEFAULT_FAILURE_SCORE  # finite; the ranking scalar of a failed run
    off_path_m: float = DEFAULT_OFF_PATH_M  # m, > 0; a run whose |CTE| once on the path exceeds this fails
    front_points: int = MAX_FRONT_POINTS  # whole, 0 to MAX_FRONT_POINTS; front points carried to the test set
    inform_delays: bool = True  # whether the controllers are told the conditions' nominal delays and pose noise
    search_tables: Mapping[str, Mapping[str, Any]] = field(default_factory=dict)  # [search.NAME] per controller
    fixed_tables: Mapping[str, Mapping[str, Any]] = field(default_factory=dict)  # [fixed.NAME] per controller
    max_runs: int = DEFAULT_MAX_RUNS  # whole, >= 1; the most runs the tournament may plan
    track_file: str | None = None  # the Zandvoort track file (None: $WORKBENCH_ZANDVOORT_CSV or where it is kept)
    description: str = ""  # free text
    base_dir: Path = field(default_factory=Path.cwd)  # the folder relative paths are taken from (the spec file's)
    source: Path | None = None  # the spec file, if read from one
    search: Mapping[str, Mapping[str, Distribution]] = field(init=False)  # controller -> parameter -> distribution
    fixed: Mapping[str, Mapping[str, Any]] = field(init=False)  # controller -> option -> value for every run
    defaults: Mapping[str, Mapping[str, Any]] = field(init=False)  # controller -> searched parameter -> default
    studies: Mapping[tuple[str, str], StudySpec] = field(init=False)  # (controller, set) -> StudySpec

    def __post_init__(self) -> None:
        """Check the scalars and rules, the controllers and their tables, the tournament's size (at most
        max_runs), then build the studies (every check of a study) and refuse a case in both sets."""
        object.__setattr__(self, "base_dir", Path(self.base_dir).resolve())
        self._check_scalars()
        self._check_controllers()
        search, fixed, defaults = {}, {}, {}
        for controller in self.controllers:
            fixed[controller] = self._fixed(controller)
            search[controller], defaults[controller] = self._search(controller, fixed[controller])
        object.__setattr__(self, "fixed", MappingProxyType(fixed))
        object.__setattr__(self, "search", MappingProxyType(search))
        object.__setattr__(self, "defaults", MappingProxyType(defaults))
        self._check_size()
        studies: dict[tuple[str, str], StudySpec] = {}
        for controller in self.controllers:
            for case_set in (self.train, self.test):
                studies[(controller, case_set.name)] = self._study(controller, case_set)
            if controller == self.controllers[0]:
                self._check_held_out(studies[(controller, "train")], studies[(controller, "test")])
        object.__setattr__(self, "studies", MappingProxyType(studies))

    # ------------------------------------------------------------------------------------------- checks
    def _check_scalars(self) -> None:
        for name in ("train", "test"):
            value = getattr(self, name)
            if not isinstance(value, CaseSet) or value.name != name:
                raise WorkbenchInputError(f"{name} must be the CaseSet named {name!r}; got {value!r}")
        _whole("tournament.trials", self.trials, 1)
        _whole("tournament.batch_size", self.batch_size, 1)
        _whole("tournament.seed", self.seed, 0)
        _whole("tournament.front_points", self.front_points, 0, MAX_FRONT_POINTS)
        _whole("tournament.max_runs", self.max_runs, 1)
        if not isinstance(self.inform_delays, bool):
            value = value_text(self.inform_delays)
            raise WorkbenchInputError(f"tournament.inform_delays must be true or false; got {value}")
        if not isinstance(self.description, str):
            raise WorkbenchInputError(f"tournament.description must be text; got {value_text(self.description)}")
        objectives = self.objectives
        if isinstance(objectives, str) or not isinstance(objectives, Sequence) or not objectives:
            raise WorkbenchInputError(
                f"tournament.objectives must be a list of metrics; got {value_text(objectives)}; allowed: "
                f"{', '.join(OBJECTIVE_METRICS)}"
            )
        for metric in objectives:
            if metric not in OBJECTIVE_METRICS:
                raise WorkbenchInputError(
                    f"unknown metric {metric!r} in tournament.objectives; allowed: {', '.join(OBJECTIVE_METRICS)}"
                )
        if len(set(objectives)) != len(objectives):
            raise WorkbenchInputError(f"tournament.objectives names a metric twice: {list(objectives)}")
        object.__setattr__(self, "objectives", tuple(objectives))
        selection = _weights("selection", self.selection, self.objectives, DEFAULT_SELECTION)
        object.__setattr__(self, "selection", MappingProxyType(selection))
        object.__setattr__(
            self, "ranking", MappingProxyType(_weights("ranking", self.ranking, OBJECTIVE_METRICS, DEFAULT_RANKING))
        )
        object.__setattr__(self, "failure_score", typed_value("tournament.failure_score", self.failure_score, float))
        off_path = typed_value("tournament.off_path_m", self.off_path_m, float)
        if not off_path > 0:
            raise WorkbenchInputError(f"tournament.off_path_m must be > 0 m; got {value_text(self.off_path_m)}")
        object.__setattr__(self, "off_path_m", off_path)

    def _check_controllers(self) -> None:
        controllers = self.controllers
        if isinstance(controllers, str):
            controllers = (controllers,)
        if not isinstance(controllers, Sequence) or not controllers or not all(isinstance(c, str) for c in controllers):
            raise WorkbenchInputError(f"tournament.controllers must be a list of names; got {value_text(controllers)}")
        for name in controllers:
            if name not in CONTROLLERS:
                raise WorkbenchInputError(
                    f"tournament.controllers: unknown controller {name!r}; choose one of {', '.join(CONTROLLERS)}"
                )
        if len(set(controllers)) != len(controllers):
            raise WorkbenchInputError(f"tournament.controllers names one twice: {list(controllers)}")
        object.__setattr__(self, "controllers", tuple(controllers))
        vehicles = (self.vehicles,) if isinstance(self.vehicles, str) else self.vehicles
        if not isinstance(vehicles, Sequence) or not vehicles or not all(isinstance(v, str) for v in vehicles):
            raise WorkbenchInputError(f"tournament.vehicles must be a list of names; got {value_text(vehicles)}")
        object.__setattr__(self, "vehicles", tuple(vehicles))
        for table_name, tables in (("search", self.search_tables), ("fixed", self.fixed_tables)):
            if not isinstance(tables, Mapping):
                raise WorkbenchInputError(f"[{table_name}] must hold a table per controller; got {value_text(tables)}")
            for name, table in tables.items():
                if name not in self.controllers:
                    raise WorkbenchInputError(
                        f"[{table_name}.{name}] names a controller the tournament does not run; its controllers: "
                        f"{', '.join(self.controllers)}"
                    )
                if not isinstance(table, Mapping):
                    raise WorkbenchInputError(f"[{table_name}.{name}] must be a table; got {value_text(table)}")

    def _fixed(self, controller: str) -> dict[str, Any]:
        """The options fixed for every run of `controller`: its [fixed.NAME] table, and the MPCs' solve budget."""
        allowed = controller_parameters(controller)
        fixed = dict(self.fixed_tables.get(controller, {}))
        for key in fixed:
            if key not in allowed:
                raise WorkbenchInputError(f"unknown option fixed.{controller}.{key}; allowed: {', '.join(allowed)}")
        if SOLVE_BUDGET_OPTION in allowed and SOLVE_BUDGET_OPTION not in fixed:
            fixed[SOLVE_BUDGET_OPTION] = MPC_SOLVE_BUDGET_S
        return fixed

    def _search(self, controller: str, fixed: Mapping[str, Any]) -> tuple[dict[str, Distribution], dict[str, Any]]:
        """The controller's search space (its own, the spec's [search.NAME] over it, the fixed options left out)
        and the shipped default of each of its parameters, which must be a point of it (trial 0)."""
        from controllers.search_space import controller_search_space

        table = dict(self.search_tables.get(controller, {}))
        allowed = controller_parameters(controller)
        for key in table:
            if key not in allowed:
                raise WorkbenchInputError(
                    f"unknown parameter search.{controller}.{key} for {controller}; allowed: {', '.join(allowed)}"
                )
        space: dict[str, Any] = {t.name: t.distribution_table() for t in controller_search_space(controller)}
        space = {k: v for k, v in space.items() if k not in fixed}
        both = sorted(set(table) & set(fixed))
        if both:
            raise WorkbenchInputError(
                f"{', '.join(both)} is both fixed in [fixed.{controller}] and searched in [search.{controller}]; "
                "keep one"
            )
        space |= table
        if not space:
            raise WorkbenchInputError(
                f"controller {controller!r} declares no search space and the spec gives none: add a "
                f"[search.{controller}] table of its options and distributions, e.g. `option = {{uniform = [low, "
                f"high]}}` (its options: `workbench controllers --show {controller}`)"
            )
        distributions, defaults = {}, {}
        for key, value in space.items():
            dist = value if isinstance(value, Distribution) else Distribution.parse(f"search.{controller}.{key}", value)
            if dist.kind not in SEARCHABLE:
                raise WorkbenchInputError(
                    f"search.{controller}.{key}: a search needs a bounded distribution ({', '.join(SEARCHABLE)}); "
                    f"got {dist.kind}"
                )
            default = _default_value(controller, key)
            if not _contains(dist, default):
                raise WorkbenchInputError(
                    f"search.{controller}.{key}: {dist.kind} {list(dist.values)} does not contain the shipped default "
                    f"{value_text(default)}, which is every controller's trial 0 (so that tuned is never worse than "
                    "default on the training objective); widen it, or fix the option in [fixed." + controller + "]"
                )
            distributions[key], defaults[key] = dist, default
        return distributions, defaults

    def _study(self, controller: str, case_set: CaseSet) -> StudySpec:
        """The StudySpec of one controller on one set: its cases as the grid, its fixed options, and (training)
        the trial budget and search space as the [optimise] settings."""
        grid = {
            "speed_kmh": list(case_set.speeds_kmh),
            "conditions": list(case_set.conditions),
            "seed": list(case_set.seeds),
            "inform_delays": [self.inform_delays],
        }
        if case_set.circuit_ranges is not None:
            grid["circuit_ranges"] = [case_set.circuit_ranges]
        try:
            optimise = None
            if case_set.name == "train":
                optimise = OptimiseSettings(
                    trials=self.trials,
                    objective={self.objectives[0]: 1.0},
                    search=dict(self.search[controller]),
                    batch_size=self.batch_size,
                    seed=self.seed,
                )
            return StudySpec(
                scenarios=case_set.scenarios,
                controllers=(controller,),
                vehicles=self.vehicles,
                grid=grid,
                controller_grid={controller: {k: [v] for k, v in self.fixed[controller].items()}},
                seed=self.seed,
                # the file's text: StudySpec checks it and makes it an absolute Path, naming study.track_file
                track_file=self.track_file,  # type: ignore[arg-type]
                description=self.description,
                base_dir=self.base_dir,
                optimise=optimise,
                max_runs=self.max_runs,
            )
        except WorkbenchInputError as exc:
            raise WorkbenchInputError(_in_tournament_terms(str(exc), case_set.name, controller)) from None

    def _check_held_out(self, train: StudySpec, test: StudySpec) -> None:
        """Refuse a case in both sets: compared with a circuit's ranges file as the circuits it draws, so that one
        circuit under two files of the same ranges (or a file of the default ranges) is one case."""
        trained = {_held_out_key(r): case_id(r.parameters()) for r in train.plan()}
        both = sorted(trained[key] for key in {_held_out_key(r) for r in test.plan()} & set(trained))
        if both:
            raise WorkbenchInputError(
                f"case {both[0]!r} (scenario|vehicle|speed|conditions|seed) is in both the train and the test set"
                + (f", and {len(both) - 1} more" if len(both) > 1 else "")
                + ": the test set must be held out; change its scenarios, speeds, conditions or seeds"
            )

    def _check_size(self) -> None:
        total = self.total_runs()
        if total > self.max_runs:
            raise WorkbenchInputError(
                f"the tournament plans up to {total:,} runs ({len(self.controllers)} controller(s) x ({self.trials} "
                f"trials x {self.cases('train')} training cases + {2 + self.front_points} judged configurations x "
                f"{self.cases('test')} test cases)), more than the limit of {self.max_runs:,}: fewer trials, cases "
                "or front points, or raise the limit with tournament.max_runs or --max-runs N"
            )

    # ------------------------------------------------------------------------------------------- planning
    def cases(self, set_name: str) -> int:
        """How many cases a set has (scenarios x vehicles x speeds x conditions x seeds).

        Parameters
        ----------
        set_name : str
            "train" or "test".

        Returns
        -------
        int
            The number of cases, each run once per configuration judged or trial.
        """
        case_set = self.train if set_name == "train" else self.test
        return (
            len(case_set.scenarios)
            * len(self.vehicles)
            * len(case_set.speeds_kmh)
            * len(case_set.conditions)
            * len(case_set.seeds)
        )

    def cases_text(self, set_name: str) -> str:
        """A set's number of cases in words: "1 training case", "12 test cases".

        Parameters
        ----------
        set_name : str
            "train" or "test".

        Returns
        -------
        str
            The count and the set's name, in the singular for one case.
        """
        count = self.cases(set_name)
        return f"{count} {'training' if set_name == 'train' else 'test'} case{'s' * (count != 1)}"

    def total_runs(self) -> int:
        """The most runs the tournament executes: per controller, its trials on the training cases and its default,
        tuned and carried front configurations on the test cases.

        Returns
        -------
        int
            controllers x (trials x training cases + (2 + front_points) x test cases); at most max_runs.
        """
        per_controller = self.trials * self.cases("train") + (2 + self.front_points) * self.cases("test")
        return len(self.controllers) * per_controller

    def plan(self, controller: str, set_name: str, options: Mapping[str, Any] | None = None) -> list[PlannedRun]:
        """The runs of `controller` on a set's cases with `options` (searched parameters) over its fixed ones.

        Parameters
        ----------
        controller : str
            One of the tournament's controllers.
        set_name : str
            "train" or "test".
        options : mapping or None
            Searched parameter -> value (a trial's or a chosen configuration's; None: the controller's defaults).

        Returns
        -------
        list of PlannedRun
            One run per case of the set, in the set's order.

        Raises
        ------
        WorkbenchInputError
            An unknown set, or an option the controller does not have or a value it refuses.
        """
        if set_name not in SETS:
            raise WorkbenchInputError(f"set must be one of {', '.join(SETS)}; got {set_name!r}")
        return self.studies[(controller, set_name)].plan(dict(options or {}))

    def selection_text(self) -> str:
        """The selection rule in words.

        Returns
        -------
        str
            The rule that names each controller's chosen point of its training front, for the report.
        """
        return (
            f"the point of the controller's training front (objectives {', '.join(self.objectives)}, each the mean "
            f"over the training cases) with the least {weights_text(self.selection)}; ties: the earlier trial"
        )

    def ranking_text(self) -> str:
        """The ranking scalar of a test run in words.

        Returns
        -------
        str
            The weighted sum and what a failed run scores, for the report.
        """
        return (
            f"{weights_text(self.ranking)} per test run; a failed run (did not complete, left the track, more than "
            f"{self.off_path_m:g} m off the path once on it, limit cycle) scores {self.failure_score:g}"
        )

    def solve_budget_text(self) -> str:
        """The MPCs' solve budget in words.

        Returns
        -------
        str
            Each MPC's `SOLVE_BUDGET_OPTION` in s, or that no controller has one.
        """
        mpcs = [c for c in self.controllers if SOLVE_BUDGET_OPTION in self.fixed[c]]
        if not mpcs:
            return "no controller in the tournament has a solve budget"
        budgets = ", ".join(f"{c} {self.fixed[c][SOLVE_BUDGET_OPTION]:g} s" for c in mpcs)
        return f"{SOLVE_BUDGET_OPTION}: {budgets} (never reached, so no solve is cut short and runs reproduce)"


def _held_out_key(run: PlannedRun) -> str:
    """A run's case as the held-out check compares it: its case id without the ranges file's name, with the
    circuits that file draws (`circuit_parameters.drawn_ranges_key`)."""
    parameters = run.parameters()
    ranges = parameters.pop("circuit_ranges", None)
    return f"{case_id(parameters)}|{drawn_ranges_key(None if ranges is None else Path(ranges))}"


_TERMS = (
    ("study.scenarios", "{set}.scenarios"),
    ("study.vehicles", "tournament.vehicles"),
    ("study.track_file", "tournament.track_file"),
    ("study.max_runs or --max-runs N", "tournament.max_runs or --max-runs N"),
    ("study.allow_infeasible", "a feasible path"),
    ("grid.speed_kmh", "{set}.speeds_kmh"),
    ("grid.conditions", "{set}.conditions"),
    ("grid.seed", "{set}.seeds"),
    ("grid.circuit_ranges", "{set}.circuit_ranges"),
    ("grid.{controller}.", "fixed.{controller}."),
    ("[grid.{controller}]", "[fixed.{controller}]"),
    ("optimise.search.", "search.{controller}."),
    ("[optimise.search]", "[search.{controller}]"),
)


def _in_tournament_terms(message: str, set_name: str, controller: str) -> str:
    """A study's error message in the tournament spec's terms (its keys named as the tournament names them)."""
    for study_term, term in _TERMS:
        message = message.replace(
            study_term.format(controller=controller), term.format(set=set_name, controller=controller)
        )
    return f"{controller} on the {set_name} set: {message}"


def load_tournament(path: str | Path, max_runs: int | None = None) -> TournamentSpec:
    """Read a tournament spec from a TOML file; max_runs (`--max-runs`) over the spec's tournament.max_runs.
    WorkbenchInputError naming the file, the key and what is allowed for anything it cannot use.

    Parameters
    ----------
    path : str or pathlib.Path
        The spec's TOML file; relative paths in it are taken from its folder.
    max_runs : int or None
        The most runs the tournament may plan (None: the spec's tournament.max_runs, else `DEFAULT_MAX_RUNS`).

    Returns
    -------
    TournamentSpec
        The tournament, each controller's training and test study built and checked.

    Raises
    ------
    WorkbenchInputError
        The file is missing or not TOML, a table or key is unknown, a name, value, weight or file is refused, a
        case is in both sets, or the tournament plans more than max_runs runs; the message names the file and
        the key.

    Examples
    --------
    >>> from workbench.apps.studies import load_tournament
    >>> spec = load_tournament("examples/tournament_quick.toml")
    >>> spec.controllers
    ('clothoid', 'nmpc', 'lmpc', 'stanley', 'pure-pursuit')
    >>> spec.cases_text("train"), spec.cases_text("test"), spec.total_runs()
    ('1 training case', '1 test case', 35)
    """
    path = Path(path)
    document = read_toml(path, f"tournament spec {str(path)!r}")
    try:
        return tournament_from_document(document, path.resolve().parent, max_runs, source=path)
    except WorkbenchInputError as exc:
        raise WorkbenchInputError(f"spec {path}: {exc}") from None


def tournament_from_document(
    document: Mapping[str, Any], base_dir: Path, max_runs: int | None = None, source: Path | None = None
) -> TournamentSpec:
    """A TournamentSpec from a parsed TOML document (paths relative to base_dir).

    Parameters
    ----------
    document : mapping
        The parsed spec: its [tournament], [train], [test], [search.NAME], [fixed.NAME] and [circuits] tables.
    base_dir : pathlib.Path
        The folder relative paths are taken from.
    max_runs : int or None
        The most runs the tournament may plan, over the spec's tournament.max_runs (None: the spec's).
    source : pathlib.Path or None
        The spec file, named in the report and in messages (None: not read from a file).

    Returns
    -------
    TournamentSpec
        The tournament, each controller's training and test study built and checked.

    Raises
    ------
    WorkbenchInputError
        As `load_tournament`, without the file's name in the message.
    """
    unknown = [k for k in document if k not in TABLES]
    if unknown:
        hint = " ([study], [grid] and [optimise] belong to sweep and optimise specs)" if "study" in unknown else ""
        raise WorkbenchInputError(f"unknown table(s) {', '.join(unknown)}; allowed: {', '.join(TABLES)}{hint}")
    head = document.get("tournament")
    if not isinstance(head, Mapping):
        raise WorkbenchInputError("the spec needs a [tournament] table with controllers, vehicles and trials")
    unknown = [k for k in head if k not in TOURNAMENT_KEYS]
    if unknown:
        raise WorkbenchInputError(
            f"unknown key(s) tournament.{', tournament.'.join(unknown)}; allowed: {', '.join(TOURNAMENT_KEYS)}"
        )
    missing = [k for k in ("controllers", "vehicles", "trials") if k not in head]
    missing += [f"[{name}]" for name in SETS if name not in document]
    if missing:
        raise WorkbenchInputError(f"the spec needs {', '.join(missing)}")
    options = {k: head[k] for k in TOURNAMENT_KEYS if k in head and k not in ("controllers", "vehicles", "trials")}
    if "objectives" in options and isinstance(options["objectives"], list):
        options["objectives"] = tuple(options["objectives"])
    if max_runs is not None:
        options["max_runs"] = max_runs
    sets = {name: CaseSet.from_table(name, document[name]) for name in SETS}
    named = [base_dir / s.circuit_ranges for s in sets.values() if s.circuit_ranges is not None]
    check_circuits_table(document, source if source is not None else base_dir, named, "in [train] or [test]")
    return TournamentSpec(
        controllers=head["controllers"],
        vehicles=head["vehicles"],
        train=sets["train"],
        test=sets["test"],
        trials=head["trials"],
        search_tables=document.get("search", {}),
        fixed_tables=document.get("fixed", {}),
        base_dir=base_dir,
        source=source,
        **options,
    )


__all__ = [
    "DEFAULT_FAILURE_SCORE",
    "DEFAULT_OBJECTIVES",
    "DEFAULT_OFF_PATH_M",
    "DEFAULT_RANKING",
    "DEFAULT_SELECTION",
    "MAX_FRONT_POINTS",
    "MPC_SOLVE_BUDGET_S",
    "CaseSet",
    "TournamentSpec",
    "case_id",
    "load_tournament",
    "tournament_from_document",
    "weights_text",
]
