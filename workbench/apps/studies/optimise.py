"""Controller tuning: optuna's TPE sampler, seeded, proposes a controller's options; each trial runs the study's
runs (its scenarios, vehicles, speeds and other run parameters) with them, through the same backends and run
store as a sweep, and scores them by the spec's objective.

The objective: per run, the weighted sum of metrics in [optimise.objective] (e.g. rms_cte_m + 0.002 x
rms_steer_rate_deg_s), then the mean (or the max, `aggregate`) over the trial's runs; minimised. A trial with a
run that did not complete (left the path, timed out, an error...) or whose metric is null is marked failed: it is
in the history, never the best, and the sampler does not model it.

Trials go in batches of `batch_size` (ask/tell): the batch's runs go to the backend together, then the trials are
told in order. The batch size is part of the spec, not of the machine, and the runs are deterministic, so a study
proposes the same trials on any backend and any number of workers; a restarted study replays the sampler and finds
its runs in DIR/runs/, so it resumes where it stopped.

Writes DIR/best.toml (the best trial's options as a controller-config file, `workbench run --controller-config`;
a scaled lead filter beside it as DIR/best_lead_filter.json), DIR/best.json (trial, value, options, objective),
DIR/history.parquet (one row per trial), DIR/results.parquet (every run, with its trial), DIR/runs/ and
DIR/history.png.
"""

from __future__ import annotations

import dataclasses
import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import pandas as pd

from tuning.limits_file import write_limits_file
from workbench.apps.studies.backends import Backend, LocalBackend
from workbench.apps.studies.results import SweepResult
from workbench.apps.studies.runner import build_controller_config
from workbench.apps.studies.spec import LEAD_FILTER_SCALES, StudySpec
from workbench.apps.studies.store import RunStore, write_results
from workbench.apps.studies.sweep import execute_runs
from workbench.base.errors import WorkbenchInputError, value_text
from workbench.base.toml_text import toml_value
from workbench.vehicles.presets import load_vehicle

if TYPE_CHECKING:
    from _typeshed import DataclassInstance
    from matplotlib.axes import Axes

BEST_CONFIG = "best.toml"
BEST_FILTER = "best_lead_filter.json"
BEST_LIMITS = "best_limits.csv"
BEST_LAG = "best_lag.json"
BEST_JSON = "best.json"
HISTORY_FILE = "history.parquet"
HISTORY_FIGURE = "history.png"


def objective_text(spec: StudySpec) -> str:
    """The objective in words, e.g. "mean over runs of 1 x rms_cte_m + 0.002 x rms_steer_rate_deg_s".

    Parameters
    ----------
    spec : StudySpec
        An optimisation's study, with its [optimise] table.

    Returns
    -------
    str
        The aggregate and the weighted sum.

    Raises
    ------
    WorkbenchInputError
        The spec has no [optimise] table.
    """
    settings = spec.optimise
    if settings is None:
        raise WorkbenchInputError("the spec has no [optimise] table")
    terms = " + ".join(f"{w:g} x {k}" for k, w in settings.objective.items())
    return f"{settings.aggregate} over runs of {terms}"


def trial_value(rows: list[dict[str, Any]], weights: dict[str, float], aggregate: str) -> tuple[float | None, str]:
    """(the trial's objective, "") or (None, why it failed) from its runs' rows.

    Parameters
    ----------
    rows : list of dict
        The trial's runs' rows (`runner.execute_run`).
    weights : dict of str to float
        Metric -> weight of the weighted sum taken per run.
    aggregate : str
        "mean" or "max": how the runs' sums combine.

    Returns
    -------
    tuple of (float or None, str)
        The objective and ""; or None and why the trial failed: a run did not complete, or a metric is missing
        or not finite.
    """
    bad = [r for r in rows if r["status"] != "completed"]
    if bad:
        first = bad[0]
        return None, f"{len(bad)} of {len(rows)} runs did not complete (e.g. {first['status']}: {first['message']})"
    values = []
    for row in rows:
        total = 0.0
        for key, weight in weights.items():
            value = row.get(key)
            if value is None or not math.isfinite(value):
                where = f"run {row['run_id']} ({row['vehicle']}, {row['scenario']})"
                return None, f"metric {key} is {value_text(value)} for {where}"
            total += weight * value
        values.append(total)
    return float(np.mean(values) if aggregate == "mean" else np.max(values)), ""


def _write_object(folder: Path, value: Any, stem: str = "best") -> str | None:
    """Write an object a file option was read into beside the config, named `<stem>_lead_filter.json`,
    `<stem>_limits.csv` or `<stem>_lag.json` (its file's name), or None when it has no file form (a vehicle's
    single-track equivalent)."""
    from controllers.clothoid.curvature_limits import CurvatureLimits
    from controllers.clothoid.filter_schedule import FilterSchedule
    from tuning.filter_file import write_filter_file
    from workbench.vehicles.steering_lag import SteeringLag, write_lag_file

    if isinstance(value, FilterSchedule):
        name = BEST_FILTER.replace("best", stem, 1)
        write_filter_file(folder / name, value.params[0] if len(value.params) == 1 else value, source=value.source)
        return name
    if isinstance(value, CurvatureLimits):
        name = BEST_LIMITS.replace("best", stem, 1)
        write_limits_file(value, folder / name)
        return name
    if isinstance(value, SteeringLag):
        name = BEST_LAG.replace("best", stem, 1)
        write_lag_file(value, folder / name)
        return name
    return None


def write_controller_config(
    path: Path, controller: str, config: DataclassInstance, header: str, stem: str = "best"
) -> Path:
    """Write every field of a controller config as a controller-config TOML file (one [controller] table; None
    as "none"; paths inside the file's folder relative to it, others absolute); an object a file option was read
    into (`FILE_OPTIONS`) is written to a file beside it, its name starting with `stem` (`_write_object`), and
    named by that option; return the path.

    Parameters
    ----------
    path : pathlib.Path
        The TOML file to write (replaced if it exists); objects go beside it.
    controller : str
        The controller the config is of: the file's one table.
    config : dataclass instance
        The controller's config (e.g. `controllers.clothoid.ClothoidConfig`).
    header : str
        Comment lines at the top of the file (plain text, one comment line per line).
    stem : str
        The start of the names of the files objects are written to.

    Returns
    -------
    pathlib.Path
        The file written.
    """
    from workbench.apps.controller_config import FILE_OPTIONS

    file_keys = {option.field: name for name, option in FILE_OPTIONS.items()}
    lines = [f"# {line}" for line in header.splitlines()] + ["", f"[{controller}]"]
    for f in dataclasses.fields(config):
        if not f.init:
            continue
        value = getattr(config, f.name)
        if f.name in file_keys:
            name = None if value is None else _write_object(path.parent, value, stem)
            if value is not None and name is None:
                lines.append(f"# {file_keys[f.name]}: {type(value).__name__} has no file form; give its file again")
            else:
                lines.append(f"{file_keys[f.name]} = {toml_value(name)}")
            continue
        if isinstance(value, Path):
            value = value.resolve()
            value = value.relative_to(path.parent.resolve()) if value.is_relative_to(path.parent.resolve()) else value
            value = value.as_posix()
        lines.append(f"{f.name} = {toml_value(value)}")
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


@dataclass(frozen=True, eq=False)
class OptimisationResult:
    """An optimisation's trials, the best of them (the least objective) and every run they made.

    The history has one row per trial: trial, state, value, the options as "<controller>.<option>", runs,
    failed_runs, reason (why it failed) and mean_<metric> of each objective metric over its runs.
    """

    history: pd.DataFrame  # one row per trial, in the order proposed
    best_trial: int | None  # the best completed trial's number (None: no trial completed)
    best_value: float | None  # its objective value (None: no trial completed)
    best_params: dict[str, Any]  # its options, option name to value (empty: no trial completed)
    config_file: Path | None  # DIR/best.toml, the best options as a controller config (None: no trial completed)
    runs: SweepResult  # every run of every trial, with its trial number
    objective: str  # the objective in words (`objective_text`)
    ran: int = 0  # >= 0; runs executed in this call

    def to_pandas(self) -> pd.DataFrame:
        """The trial history (a copy).

        Returns
        -------
        pandas.DataFrame
            One row per trial in the order proposed: trial, state ("complete" or "failed"), value, the options as
            "<controller>.<option>", runs, failed_runs, reason, and mean_<metric> for each objective metric.
        """
        return self.history.copy()

    def plot_history(self, ax: Axes | None = None) -> Axes:
        """Each trial's objective (failed trials not drawn) and the best so far.

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            The axes to draw on (None: a fresh pyplot figure's).

        Returns
        -------
        matplotlib.axes.Axes
            The axes drawn on.
        """
        import matplotlib.pyplot as plt

        if ax is None:
            _, ax = plt.subplots(figsize=(7, 4.5), layout="constrained")
        done = self.history[self.history["state"] == "complete"]
        ax.plot(done["trial"], done["value"], "o", ms=4, alpha=0.6, label="trial")
        best = self.history["value"].where(self.history["state"] == "complete").cummin()
        ax.plot(self.history["trial"], best, "-", color="C3", label="best so far")
        ax.set(xlabel="trial", ylabel="objective", title=f"Optimisation: {self.objective}")
        ax.grid(alpha=0.3)
        ax.legend(fontsize="small")
        return ax


def run_optimisation(
    spec: StudySpec, out_dir: str | Path, backend: Backend | None = None, progress: bool = False
) -> OptimisationResult:
    """Run (or resume) the optimisation the spec's [optimise] table describes into out_dir (module docstring).

    Parameters
    ----------
    spec : StudySpec
        A study of one controller with an [optimise] table (``load_spec(path, kind="optimise")``).
    out_dir : str or pathlib.Path
        The study's folder: runs/ (one JSON row per run; rows already there are not run again), results.parquet,
        history.parquet, history.png, and best.toml and best.json when a trial completed.
    backend : Backend or None
        Where the runs execute (`make_backend`); one started by the caller is left running, one started here is
        closed on return (None: a `LocalBackend` over every usable CPU).
    progress : bool
        Show a bar on stderr for each batch of trials.

    Returns
    -------
    OptimisationResult
        The trial history, the best trial and its options (None and {} when no trial completed), best.toml's
        path, and every run of every trial.

    Raises
    ------
    WorkbenchInputError
        The spec has no [optimise] table, or the output folder cannot be created.
    BackendError
        The backend's machinery failed (a worker process died); the runs already written stay, and the same call
        resumes.

    Examples
    --------
    >>> from workbench.apps.studies import load_spec, make_backend, run_optimisation
    >>> spec = load_spec("examples/optimise_clothoid.toml", kind="optimise")
    >>> spec.run_count(), spec.total_runs()  # runs per trial, runs of the 40 trials
    (6, 240)
    >>> with make_backend("local", workers=2) as backend:  # doctest: +SKIP
    ...     result = run_optimisation(spec, "runs/tune-clothoid", backend)
    >>> result.best_params, result.config_file  # doctest: +SKIP
    """
    import optuna

    settings = spec.optimise
    if settings is None:
        raise WorkbenchInputError("the spec has no [optimise] table; `workbench optimise` needs one")
    controller = spec.controllers[0]
    out = Path(out_dir)
    store = RunStore(out)
    optuna.logging.set_verbosity(optuna.logging.WARNING)
    sampler = optuna.samplers.TPESampler(
        seed=spec.seed if settings.seed is None else settings.seed, n_startup_trials=settings.startup_trials
    )
    study = optuna.create_study(direction="minimize", sampler=sampler)
    distributions = {k: d.to_optuna() for k, d in settings.search.items()}
    weights = dict(settings.objective)
    history: list[dict[str, Any]] = []
    all_rows: list[dict[str, Any]] = []
    ran = 0
    backend = backend or LocalBackend()
    started_here = not backend.started
    try:
        while len(history) < settings.trials:
            batch = [study.ask(distributions) for _ in range(min(settings.batch_size, settings.trials - len(history)))]
            plans = [spec.plan(trial.params) for trial in batch]
            rows, n = execute_runs(
                [r for plan in plans for r in plan],
                store,
                backend,
                progress,
                f"trials {batch[0].number}-{batch[-1].number}",
            )
            ran += n
            start = 0
            for trial, plan in zip(batch, plans, strict=True):
                trial_rows, start = rows[start : start + len(plan)], start + len(plan)
                value, reason = trial_value(trial_rows, weights, settings.aggregate)
                if value is None:
                    study.tell(trial, state=optuna.trial.TrialState.FAIL)
                else:
                    study.tell(trial, value)
                entry = {"trial": trial.number, "state": "complete" if value is not None else "failed", "value": value}
                entry |= {f"{controller}.{k}": v for k, v in trial.params.items()}
                entry |= {"runs": len(trial_rows), "failed_runs": sum(r["status"] != "completed" for r in trial_rows)}
                entry["reason"] = reason
                for key in weights:
                    numbers = [x for r in trial_rows if isinstance(x := r.get(key), int | float)]
                    entry[f"mean_{key}"] = float(np.mean(numbers)) if len(numbers) == len(trial_rows) else None
                history.append(entry)
                all_rows += [{"trial": trial.number} | r for r in trial_rows]
            pd.DataFrame(history).to_parquet(out / HISTORY_FILE, index=False)
    finally:
        if started_here:
            backend.close()
    write_results(out, all_rows)
    complete = [h for h in history if h["state"] == "complete"]
    best = min(complete, key=lambda h: (h["value"], h["trial"])) if complete else None
    best_params = {} if best is None else dict(study.trials[best["trial"]].params)
    config_file = None
    if best is not None:
        config_file = _write_best(spec, out, best, best_params)
    result = OptimisationResult(
        history=pd.DataFrame(history),
        best_trial=None if best is None else best["trial"],
        best_value=None if best is None else best["value"],
        best_params=best_params,
        config_file=config_file,
        runs=SweepResult.from_rows(all_rows, out, ran),
        objective=objective_text(spec),
        ran=ran,
    )
    _save_history_figure(result, out)
    return result


def _write_best(spec: StudySpec, out: Path, best: dict[str, Any], params: dict[str, Any]) -> Path:
    """DIR/best.toml (and DIR/best_lead_filter.json when the trial scaled the filter) and DIR/best.json."""
    controller = spec.controllers[0]
    run = spec.plan(params)[0]  # the options are the same in every run of the trial
    config = build_controller_config(run, load_vehicle(run.vehicle))
    scales = {k: v for k, v in run.options if k in LEAD_FILTER_SCALES}
    header = (
        f"The best of {spec.optimise.trials if spec.optimise else '?'} trials of `workbench optimise`: trial "
        f"{best['trial']}, objective {best['value']!r}\n({objective_text(spec)}).\n"
        f"Use: workbench run SCENARIO --controller {controller} --controller-config {BEST_CONFIG}"
    )
    if scales and getattr(config, "lead_filter", None) is not None:
        header += f"\n{BEST_FILTER}: the lead filter with {', '.join(f'{k} = {v!r}' for k, v in scales.items())}."
    path = write_controller_config(out / BEST_CONFIG, controller, config, header)
    document = {
        "trial": best["trial"],
        "value": best["value"],
        "objective": objective_text(spec),
        "controller": controller,
        "params": params,
        "config_file": BEST_CONFIG,
    }
    (out / BEST_JSON).write_text(json.dumps(document, indent=2) + "\n", encoding="utf-8")
    return path


def _save_history_figure(result: OptimisationResult, out: Path) -> None:
    import matplotlib.pyplot as plt

    figure = result.plot_history().figure.get_figure(root=True)
    figure.savefig(out / HISTORY_FIGURE, dpi=110)
    plt.close(figure)


__all__ = ["OptimisationResult", "objective_text", "run_optimisation", "trial_value", "write_controller_config"]
