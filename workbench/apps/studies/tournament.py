"""The controller tournament: every controller tuned with the same trial budget on the training cases, its default,
tuned and carried front configurations judged on the held-out test cases.

Per controller, optuna's multi-objective TPE sampler, seeded with the spec's seed (its first STARTUP_TRIALS trials
drawn at random), proposes its searched options;
a trial runs the training cases with them (through the study backends and the run store, as `workbench optimise`
does) and is told the mean of each objective over those cases. Trial 0 is the controller's shipped defaults
(enqueued), so that the chosen configuration, picked among every trial by the spec's selection rule over the
Pareto front, is never worse than the default on the training objective. A trial fails, is told FAIL and never
chosen, when one of its runs failed: did not complete (status and message), left the track, or limit-cycled
(`run_failure` says which), or an objective metric is missing. Trials go in batches of the spec's batch_size
(ask, run, tell in order), so any backend and number of workers give the same trials; the runs are deterministic
and kept in DIR/runs/ as they finish, so a restarted tournament replays the sampler, finds its runs and goes on
where it stopped (nothing lost or redone).

The chosen configuration is written to DIR/best/<controller>.toml, up to front_points other points spread along
the front (by the last objective, least first; neither the default nor the chosen trial, which are judged under
their own names) to DIR/front/<controller>-<k>.toml and the default (the fixed options only) to
DIR/default/<controller>.toml, each a `workbench run --controller-config` file; a controller whose configuration
differs between the vehicles (a lead filter scaled from each vehicle's own) gets one file per vehicle,
`<name>@<vehicle>.toml`, beside the first vehicle's. Then the test stage runs every controller's default,
tuned and carried configurations on the test cases, which no trial ever runs (checked: `TournamentIsolationError`).

Writes DIR/results.parquet (every run: the runner's row plus set, config, trial, case, failed, failure and, for a
judged run, the `workbench run` command that reproduces it bit for bit), DIR/history.parquet (one row per
controller and trial), DIR/tournament.json (the rules, the cases of each set, the chosen trials) and, through
`tournament_judging.judge` and `tournament_report.write_report`, DIR/report.html.
"""

from __future__ import annotations

import dataclasses
import json
import math
import shlex
import sys
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from workbench.apps.studies.backends import Backend, LocalBackend
from workbench.apps.studies.optimise import write_controller_config
from workbench.apps.studies.run_build import LEAD_FILTER_SCALES, option_text
from workbench.apps.studies.runner import build_controller_config
from workbench.apps.studies.spec import PlannedRun
from workbench.apps.studies.store import RunStore, write_results
from workbench.apps.studies.sweep import execute_runs
from workbench.apps.studies.tournament_spec import DEFAULT_OFF_PATH_M, TournamentSpec, case_id
from workbench.base.errors import value_text
from workbench.vehicles import VEHICLES
from workbench.vehicles.presets import load_vehicle

TRAIN, TEST = "train", "test"
TRIAL, DEFAULT, TUNED, FRONT_PREFIX = "trial", "default", "tuned", "front-"
HISTORY_FILE = "history.parquet"
SUMMARY_FILE = "tournament.json"
BEST_DIR, FRONT_DIR, DEFAULT_DIR = "best", "front", "default"
#: Trials drawn at random (trial 0 aside, the defaults) before the sampler models the results: optuna's default,
#: pinned here so that a tournament proposes the same trials whatever optuna's default becomes.
STARTUP_TRIALS = 10
#: Where a judged run's `workbench run` command writes its run (relative to where it is run).
REPLAY_DIR = "replay"


class TournamentIsolationError(RuntimeError):
    """A training trial ran a test case: the test set was not held out (a defect, never an input error)."""


def run_failure(row: Mapping[str, Any], off_path_m: float = DEFAULT_OFF_PATH_M) -> str:
    """Why a run counts as failed in a tournament, "" when it did not: it did not complete (its status and
    message), it left the track, it went more than off_path_m (m) off the path once on it (`max_abs_cte_on_path_m`),
    or its steering limit-cycled.

    Parameters
    ----------
    row : mapping
        A run's row (`runner.execute_run`): status and message, and the metrics left_track,
        max_abs_cte_on_path_m (m) and limit_cycle where present.
    off_path_m : float
        The largest |CTE| (m) once on the path that does not count as leaving it (the spec's off_path_m).

    Returns
    -------
    str
        The first reason in that order, "" for a run that did not fail.

    Examples
    --------
    >>> from workbench.apps.studies.tournament import run_failure
    >>> run_failure({"status": "completed", "max_abs_cte_on_path_m": 1.4})
    'left the path (max |CTE| once on it 1.4 m > 1 m)'
    >>> run_failure({"status": "completed", "max_abs_cte_on_path_m": 0.2})
    ''
    """
    if row["status"] != "completed":
        return f"did not complete ({row['status']}: {row['message']})"
    if row.get("left_track"):
        return f"left the track (least margin {value_text(row.get('min_track_margin_m'))} m)"
    off = row.get("max_abs_cte_on_path_m")
    if off is not None and off > off_path_m:
        return f"left the path (max |CTE| once on it {value_text(off)} m > {off_path_m:g} m)"
    if row.get("limit_cycle"):
        hz, deg = (value_text(row.get(k)) for k in ("limit_cycle_hz", "limit_cycle_amplitude_deg"))
        return f"limit cycle ({hz} Hz, {deg} deg)"
    return ""


def trial_objectives(
    rows: Sequence[Mapping[str, Any]], objectives: Sequence[str], off_path_m: float = DEFAULT_OFF_PATH_M
) -> tuple[list[float] | None, str]:
    """(each objective's mean over a trial's runs, "") or (None, why the trial failed: `run_failure`).

    Parameters
    ----------
    rows : sequence of mapping
        The trial's runs' rows (`runner.execute_run`), one per training case.
    objectives : sequence of str
        The metric columns averaged, in order (the spec's objectives).
    off_path_m : float
        The largest |CTE| (m) once on the path that does not count as leaving it (`run_failure`).

    Returns
    -------
    tuple of (list of float or None, str)
        The objectives' means in the order of `objectives` and ""; or None and why the trial failed: a run
        failed (how many, and the first one's case and reason) or a metric is missing or not finite.

    Examples
    --------
    >>> from workbench.apps.studies.tournament import trial_objectives
    >>> rows = [{"status": "completed", "rms_cte_m": 0.1}, {"status": "completed", "rms_cte_m": 0.3}]
    >>> trial_objectives(rows, ["rms_cte_m"])
    ([0.2], '')
    """
    failures = [(row, why) for row in rows if (why := run_failure(row, off_path_m))]
    if failures:
        row, why = failures[0]
        return None, f"{len(failures)} of {len(rows)} runs failed (e.g. {case_id(row)}: {why})"
    values = []
    for metric in objectives:
        numbers: list[float] = []
        for row in rows:
            number = row.get(metric)
            if number is None or not math.isfinite(number):
                return None, f"metric {metric} is {value_text(number)} for {case_id(row)}"
            numbers.append(number)
        values.append(float(np.mean(numbers)))
    return values, ""


def pareto_front(points: Mapping[int, Sequence[float]]) -> list[int]:
    """The trials (keys) no other trial dominates (no worse in every objective, better in one), in order.

    Parameters
    ----------
    points : mapping of int to sequence of float
        Trial number -> its objectives, every one minimised, in one order for all trials.

    Returns
    -------
    list of int
        The trials on the Pareto front, by increasing number.

    Examples
    --------
    >>> from workbench.apps.studies.tournament import pareto_front
    >>> pareto_front({0: (1.0, 3.0), 1: (2.0, 2.0), 2: (3.0, 3.0), 3: (0.5, 4.0)})
    [0, 1, 3]
    """
    front = []
    for trial, values in points.items():
        dominated = any(
            all(o <= v for o, v in zip(other, values, strict=True))
            and any(o < v for o, v in zip(other, values, strict=True))
            for key, other in points.items()
            if key != trial
        )
        if not dominated:
            front.append(trial)
    return sorted(front)


def weighted(values: Sequence[float], objectives: Sequence[str], weights: Mapping[str, float]) -> float:
    """The weighted sum of a trial's objective means (`weights`: objective -> weight)."""
    return float(sum(weights.get(metric, 0.0) * value for metric, value in zip(objectives, values, strict=True)))


def spread_points(front: Sequence[int], points: Mapping[int, Sequence[float]], count: int) -> list[int]:
    """Up to `count` trials of the front spread along it: ordered by the last objective (then the trial), the first,
    the last and evenly between.

    Parameters
    ----------
    front : sequence of int
        The front's trials (`pareto_front`).
    points : mapping of int to sequence of float
        Trial number -> its objectives.
    count : int
        The most trials to pick (0 or less: none).

    Returns
    -------
    list of int
        The picked trials, by increasing last objective; all of the front when it has at most `count`.

    Examples
    --------
    >>> from workbench.apps.studies.tournament import spread_points
    >>> points = {0: (1.0, 3.0), 1: (2.0, 2.0), 3: (0.5, 4.0)}
    >>> spread_points([0, 1, 3], points, 2)
    [1, 3]
    """
    ordered = sorted(front, key=lambda t: (points[t][-1], t))
    if count <= 0 or not ordered:
        return []
    if len(ordered) <= count:
        return ordered
    picks = np.unique(np.round(np.linspace(0, len(ordered) - 1, count)).astype(int))
    return [ordered[i] for i in picks]


@dataclass(frozen=True, eq=False)
class TournamentResult:
    """A tournament's runs, trials and chosen configurations, and its verdict when a report was asked for.

    A controller with no completed trial is judged with its default as its tuned configuration.
    """

    results: pd.DataFrame  # every run, as DIR/results.parquet (module docstring)
    history: pd.DataFrame  # one row per controller and trial, as DIR/history.parquet
    chosen: Mapping[str, int | None]  # controller -> its chosen trial (None: no trial completed)
    config_files: Mapping[str, Path]  # controller -> its chosen configuration's file (the first vehicle's)
    ran: int  # >= 0; runs executed in this call (the others were already stored)
    judgement: Any = None  # the verdict, a `tournament_judging.Judgement` (None: no report asked for)
    report: Path | None = None  # DIR/report.html (None: no report asked for)


def run_command(run: PlannedRun, config_file: Path) -> str:
    """The `workbench run` command line that reproduces a judged run bit for bit: its scenario (name, circuit or
    file), controller, vehicle (preset or file), speed, conditions, seed, informed delays, track file, circuit
    ranges file and the controller-config file of its configuration; it writes to replay/<run id>.

    Parameters
    ----------
    run : PlannedRun
        A test run of the tournament (`TournamentSpec.plan`).
    config_file : pathlib.Path
        The controller-config file of the run's configuration (`write_config_files`), written into the command
        as given.

    Returns
    -------
    str
        The command line, quoted for a POSIX shell.

    Examples
    --------
    >>> from pathlib import Path
    >>> from workbench.apps.studies import load_tournament
    >>> from workbench.apps.studies.tournament import run_command
    >>> run = load_tournament("examples/tournament_quick.toml").plan("clothoid", "test")[0]
    >>> run_command(run, Path("best/clothoid.toml"))  # doctest: +ELLIPSIS
    'workbench run figure8 --controller clothoid --vehicle dynamic-bicycle --speed 40.0 --conditions automotive ...'
    """
    values = dict(run.values)
    words = ["workbench", "run", run.scenario, "--controller", run.controller]
    words += ["--vehicle", run.vehicle] if run.vehicle in VEHICLES else ["--vehicle-file", run.vehicle]
    words += ["--speed", option_text(values["speed_kmh"])]
    words += ["--conditions", str(values.get("conditions", "ideal")), "--seed", str(values.get("seed", 0))]
    if values.get("inform_delays"):
        words.append("--inform-delays")
    if run.track_file is not None:
        words += ["--track", str(run.track_file)]
    if values.get("circuit_ranges") is not None:
        words += ["--circuit-ranges", str(values["circuit_ranges"])]
    words += ["--controller-config", str(config_file), "--out", f"{REPLAY_DIR}/{run.run_id}"]
    return shlex.join(words)


def _portable(config: Any) -> Any:
    """A controller config without the vehicle's tuning (a run adds it back for whichever vehicle it steers)."""
    if any(f.name == "tuning" for f in dataclasses.fields(config)):
        return dataclasses.replace(config, tuning=None)
    return config


def _vehicle_label(vehicle: str) -> str:
    return vehicle if vehicle in VEHICLES else Path(vehicle).stem


def write_config_files(
    spec: TournamentSpec, controller: str, options: Mapping[str, Any], folder: Path, name: str, header: str
) -> dict[str, Path]:
    """Write a configuration of `controller` (its fixed options and `options`) as controller-config files in
    `folder`: `<name>.toml`, and `<name>@<vehicle>.toml` for a vehicle whose config differs from the first
    vehicle's (a lead filter scaled from its own); return vehicle -> file.

    Parameters
    ----------
    spec : TournamentSpec
        The tournament: its vehicles, and the controller's fixed options.
    controller : str
        One of the tournament's controllers.
    options : mapping
        Searched parameter -> value of the configuration (a trial's; {} for the default).
    folder : pathlib.Path
        Where the files go (made if missing).
    name : str
        The files' stem: the controller's name, or "<controller>-<k>" for a front point.
    header : str
        Comment lines at the top of each file (plain text, one comment line per line).

    Returns
    -------
    dict of str to pathlib.Path
        Each vehicle of the tournament -> the absolute path of its file (vehicles of one config share a file).

    Raises
    ------
    WorkbenchInputError
        An option the controller does not have or a value it refuses.
    """
    folder.mkdir(parents=True, exist_ok=True)
    first_runs: dict[str, PlannedRun] = {}
    for run in spec.plan(controller, TEST, options):
        first_runs.setdefault(run.vehicle, run)
    written: list[tuple[Any, Path]] = []
    files = {}
    for vehicle, run in first_runs.items():
        # The run's config for this vehicle, without the conditions' delays (the command line tells them) and
        # without its tuning (a run adds it); the tuning is read only where a lead filter is scaled from it.
        scaled = any(dict(run.options).get(k, 1.0) != 1.0 for k in LEAD_FILTER_SCALES)
        config = _portable(build_controller_config(run, load_vehicle(vehicle) if scaled else None))
        same = next((path for other, path in written if other == config), None)
        if same is None:
            stem = name if not written else f"{name}@{_vehicle_label(vehicle)}"
            same = write_controller_config(folder / f"{stem}.toml", controller, config, header, stem=stem)
            written.append((config, same))
        files[vehicle] = same.resolve()
    return files


def _log_to_stderr(message: str) -> None:
    print(f"tournament: {message}", file=sys.stderr, flush=True)


@dataclass
class _Tuning:
    """One controller's training: its history rows, run rows, trials' options, chosen and carried trials."""

    history: list[dict[str, Any]]
    rows: list[dict[str, Any]]
    params: dict[int, dict[str, Any]]
    chosen: int | None
    carried: list[int]
    ran: int


def _tune(
    spec: TournamentSpec,
    controller: str,
    store: RunStore,
    backend: Backend,
    progress: bool,
    log: Callable[[str], None],
) -> _Tuning:
    """Run (or replay) a controller's trials on the training cases; name its front, chosen and carried trials."""
    import optuna

    optuna.logging.set_verbosity(optuna.logging.WARNING)
    sampler = optuna.samplers.TPESampler(seed=spec.seed, n_startup_trials=STARTUP_TRIALS)
    study = optuna.create_study(directions=["minimize"] * len(spec.objectives), sampler=sampler)
    study.enqueue_trial(dict(spec.defaults[controller]))
    distributions = {k: d.to_optuna() for k, d in spec.search[controller].items()}
    history: list[dict[str, Any]] = []
    rows: list[dict[str, Any]] = []
    params: dict[int, dict[str, Any]] = {}
    points: dict[int, list[float]] = {}
    ran = 0
    cases = spec.cases(TRAIN)
    while len(history) < spec.trials:
        size = min(spec.batch_size, spec.trials - len(history))
        batch = [study.ask(distributions) for _ in range(size)]
        plans = [spec.plan(controller, TRAIN, trial.params) for trial in batch]
        first, last = batch[0].number, batch[-1].number
        log(f"{controller}: training, trials {first}-{last} of {spec.trials} ({cases} case{'s' * (cases != 1)} each)")
        batch_rows, n = execute_runs(
            [r for plan in plans for r in plan], store, backend, progress, f"{controller} trials {first}-{last}"
        )
        ran += n
        start = 0
        for trial, plan in zip(batch, plans, strict=True):
            trial_rows, start = batch_rows[start : start + len(plan)], start + len(plan)
            values, reason = trial_objectives(trial_rows, spec.objectives, spec.off_path_m)
            if values is None:
                study.tell(trial, state=optuna.trial.TrialState.FAIL)
            else:
                study.tell(trial, values)
                points[trial.number] = values
            params[trial.number] = dict(trial.params)
            entry: dict[str, Any] = {
                "controller": controller,
                "trial": trial.number,
                "state": "complete" if values is not None else "failed",
                "reason": reason,
            }
            means = values if values is not None else [None] * len(spec.objectives)
            entry |= {f"train_{m}": v for m, v in zip(spec.objectives, means, strict=True)}
            entry["params_json"] = json.dumps(trial.params, sort_keys=True, default=str)
            entry["cpu_time_s"] = float(sum(r.get("cpu_time_s") or 0.0 for r in trial_rows))
            entry["runs"] = len(trial_rows)
            entry["failed_runs"] = sum(bool(run_failure(r, spec.off_path_m)) for r in trial_rows)
            history.append(entry)
            rows += [_annotated(r, spec, TRAIN, TRIAL, trial.number) for r in trial_rows]
    front = pareto_front(points)
    chosen = min(front, key=lambda t: (weighted(points[t], spec.objectives, spec.selection), t)) if front else None
    # the default (trial 0) and the chosen trial are judged under their own names: carried are the front's others
    carried = spread_points([t for t in front if t not in (0, chosen)], points, spec.front_points)
    for entry in history:
        entry["pareto"] = entry["trial"] in front
        entry["chosen"] = entry["trial"] == chosen
        entry["carried"] = carried.index(entry["trial"]) + 1 if entry["trial"] in carried else None
    return _Tuning(history, rows, params, chosen, carried, ran)


def _annotated(
    row: Mapping[str, Any], spec: TournamentSpec, set_name: str, config: str, trial: int, command: str | None = None
) -> dict:
    """A runner's row with the tournament's columns: set, config, trial, case, failed, failure and command."""
    failure = run_failure(row, spec.off_path_m)
    return (
        {"set": set_name, "config": config, "trial": trial, "case": case_id(row)}
        | dict(row)
        | {
            "failed": bool(failure),
            "failure": failure,
            "command": command,
        }
    )


@dataclass(frozen=True)
class _Judged:
    """A configuration judged on the test set: its name (config), the trial whose options it uses, those options
    and its controller-config file per vehicle."""

    config: str
    trial: int
    options: dict[str, Any]
    files: dict[str, Path]


def _judged_configs(spec: TournamentSpec, controller: str, tuning: _Tuning, out: Path) -> list[_Judged]:
    """Each configuration of a controller judged on the test set, its files written: the default (the fixed
    options only; trial 0), the tuned (the chosen trial; the default's when no trial completed) and the carried
    front points."""
    where = "the tournament" + (f" {spec.source.name}" if spec.source else "")
    chosen = tuning.chosen
    tuned = tuning.params[chosen] if chosen is not None else dict(spec.defaults[controller])
    if chosen is not None:
        why = f"trial {chosen} of {spec.trials}, chosen as {spec.selection_text()}"
    else:
        why = "no trial completed, so it is the default (trial 0)"
    plan = [
        (DEFAULT, 0, {}, DEFAULT_DIR, controller, "shipped defaults with the fixed options (trial 0 of its tuning)"),
        (TUNED, 0 if chosen is None else chosen, tuned, BEST_DIR, controller, f"chosen configuration: {why}"),
    ]
    for rank, trial in enumerate(tuning.carried, start=1):
        what = f"training front's point {rank}, carried to the test set (trial {trial})"
        plan.append((f"{FRONT_PREFIX}{rank}", trial, tuning.params[trial], FRONT_DIR, f"{controller}-{rank}", what))
    return [
        _Judged(
            config,
            trial,
            options,
            write_config_files(spec, controller, options, out / folder, name, f"{controller} in {where}: its {what}."),
        )
        for config, trial, options, folder, name, what in plan
    ]


def run_tournament(
    spec: TournamentSpec,
    out_dir: str | Path,
    backend: Backend | None = None,
    progress: bool = False,
    report: bool = True,
    log: Callable[[str], None] | None = _log_to_stderr,
) -> TournamentResult:
    """Run (or resume) the tournament into out_dir (module docstring). backend: a LocalBackend over every CPU
    unless given; progress: a progress bar per batch on stderr; report: judge the runs and write DIR/report.html;
    log: where each controller's stage is told (None: nowhere).

    Parameters
    ----------
    spec : TournamentSpec
        The tournament (`load_tournament`).
    out_dir : str or pathlib.Path
        The tournament's folder: runs/ (one JSON row per run; rows already there are not run again),
        results.parquet, history.parquet, tournament.json, best/, front/, default/ and report.html.
    backend : Backend or None
        Where the runs execute (`make_backend`); one started by the caller is left running, one started here is
        closed on return (None: a `LocalBackend` over every usable CPU).
    progress : bool
        Show a bar on stderr for each batch of runs.
    report : bool
        Judge the test runs (`tournament_judging.judge`) and write report.html.
    log : callable or None
        Called with a line for each controller's stage (None: silent); by default printed to stderr.

    Returns
    -------
    TournamentResult
        Every run, the trial history, each controller's chosen trial and configuration file, and with `report`
        the verdict and report.html's path.

    Raises
    ------
    BackendError
        The backend's machinery failed (a worker process died); the runs already written stay, and the same call
        resumes.
    TournamentIsolationError
        A training trial ran a test case (a defect: the spec refuses such a case).

    Examples
    --------
    >>> from workbench.apps.studies import load_tournament, make_backend, run_tournament
    >>> spec = load_tournament("examples/tournament_quick.toml")
    >>> with make_backend("local", workers=2) as backend:  # doctest: +SKIP
    ...     result = run_tournament(spec, "runs/tournament-quick", backend)
    >>> result.chosen, result.report  # doctest: +SKIP
    """
    out = Path(out_dir).resolve()
    store = RunStore(out)
    say = log or (lambda message: None)
    backend = backend or LocalBackend()
    started_here = not backend.started
    history: list[dict[str, Any]] = []
    rows: list[dict[str, Any]] = []
    chosen: dict[str, int | None] = {}
    tuned: dict[str, dict[str, Any]] = {}
    config_files: dict[str, Path] = {}
    ran = 0
    try:
        tunings = {}
        for controller in spec.controllers:
            tuning = _tune(spec, controller, store, backend, progress, say)
            tunings[controller] = tuning
            history += tuning.history
            rows += tuning.rows
            ran += tuning.ran
            chosen[controller] = tuning.chosen
        for controller in spec.controllers:
            configs = _judged_configs(spec, controller, tunings[controller], out)
            config_files[controller] = configs[1].files[spec.studies[(controller, TEST)].vehicles[0]]
            tuned[controller] = configs[1].options
            plans = [spec.plan(controller, TEST, judged.options) for judged in configs]
            say(f"{controller}: judging {len(configs)} configurations on {spec.cases_text(TEST)}")
            test_rows, n = execute_runs(
                [r for plan in plans for r in plan], store, backend, progress, f"{controller} test"
            )
            ran += n
            start = 0
            for judged, plan in zip(configs, plans, strict=True):
                for run, row in zip(plan, test_rows[start : start + len(plan)], strict=True):
                    command = run_command(run, judged.files[run.vehicle])
                    rows.append(_annotated(row, spec, TEST, judged.config, judged.trial, command))
                start += len(plan)
    finally:
        if started_here:
            backend.close()
    _check_isolation(rows)
    write_results(out, rows)
    history_frame = pd.DataFrame(history)
    history_frame.to_parquet(out / HISTORY_FILE, index=False)
    results = pd.read_parquet(out / "results.parquet")
    _write_summary(spec, out, results, chosen)
    result = TournamentResult(results, history_frame, chosen, config_files, ran)
    if not report:
        return result
    say("judging and writing the report")
    judgement, path = _judge_and_report(spec, out, results, history_frame, tuned)
    return dataclasses.replace(result, judgement=judgement, report=path)


def _check_isolation(rows: Sequence[Mapping[str, Any]]) -> None:
    """No training run is of a test case (the spec refuses such a case; this holds it for the runs made)."""
    test_cases = {r["case"] for r in rows if r["set"] == TEST}
    leaked = sorted({r["case"] for r in rows if r["set"] == TRAIN} & test_cases)
    if leaked:
        raise TournamentIsolationError(f"training trials ran test case(s) {', '.join(leaked)}")


def _case_lists(results: pd.DataFrame) -> dict[str, list[str]]:
    return {s: list(dict.fromkeys(results.loc[results["set"] == s, "case"])) for s in (TRAIN, TEST)}


def _write_summary(spec: TournamentSpec, out: Path, results: pd.DataFrame, chosen: Mapping[str, int | None]) -> None:
    """DIR/tournament.json: the rules, each set's cases (disjoint), and the chosen trial of each controller."""
    cases = _case_lists(results)
    document = {
        "controllers": list(spec.controllers),
        "vehicles": list(spec.vehicles),
        "trials": spec.trials,
        "batch_size": spec.batch_size,
        "seed": spec.seed,
        "objectives": list(spec.objectives),
        "selection": spec.selection_text(),
        "ranking": spec.ranking_text(),
        "failure_score": spec.failure_score,
        "inform_delays": spec.inform_delays,
        "solve_budget": spec.solve_budget_text(),
        "train_cases": cases[TRAIN],
        "test_cases": cases[TEST],
        "test_cases_run_by_trials": sorted(set(cases[TRAIN]) & set(cases[TEST])),
        "chosen_trials": dict(chosen),
    }
    (out / SUMMARY_FILE).write_text(json.dumps(document, indent=2) + "\n", encoding="utf-8")


def _judge_and_report(
    spec: TournamentSpec,
    out: Path,
    results: pd.DataFrame,
    history: pd.DataFrame,
    tuned: Mapping[str, Mapping[str, Any]],
) -> tuple[Any, Path]:
    """The verdict (`tournament_judging.judge`) and DIR/report.html (`tournament_report.write_report`), with the
    traces of each controller's tuned configuration on the first test case, simulated again."""
    from workbench.apps.studies.runner import simulate
    from workbench.apps.studies.tournament_judging import TournamentSummary, judge
    from workbench.apps.studies.tournament_report import write_report

    judgement = judge(results, spec.ranking, spec.seed, failure_score=spec.failure_score, objectives=spec.objectives)
    cases = _case_lists(results)
    summary = TournamentSummary(
        title=f"Controller tournament{f': {spec.source.stem}' if spec.source else ''}",
        description=spec.description,
        controllers=spec.controllers,
        vehicles=tuple(spec.studies[(spec.controllers[0], TEST)].vehicles),
        train_cases=tuple(cases[TRAIN]),
        test_cases=tuple(cases[TEST]),
        trials=spec.trials,
        selection_rule=spec.selection_text(),
        ranking_rule=spec.ranking_text(),
        failure_score=spec.failure_score,
        inform_delays=spec.inform_delays,
        seed=spec.seed,
        objectives=spec.objectives,
        solve_budget=spec.solve_budget_text(),
    )
    traces = {c: simulate(spec.plan(c, TEST, tuned[c])[0]) for c in spec.controllers}
    return judgement, write_report(out, summary, results, history, judgement, traces)


__all__ = [
    "TournamentIsolationError",
    "TournamentResult",
    "pareto_front",
    "run_command",
    "run_failure",
    "run_tournament",
    "spread_points",
    "trial_objectives",
    "write_config_files",
]
