"""The tournament's verdict from its runs: scores on the test set with bootstrap intervals, the generalisation gap,
step and CPU time, and a ranking of the controllers' tuned configurations that says which of them the test cases
cannot tell apart.

The results table holds one row per run (`judge` names the columns it reads): the training trials (set "train",
config "trial") and the judged runs (set "test"; config "default", "tuned" or a carried front point "front-K"),
each with its case (the same text for the same scenario, vehicle, speed, conditions and seed across controllers)
and the trial whose options it used. Every statistic works per case: a case's runs (one, as a tournament plans
them) are averaged first, so that each case weighs alike.

- The ranking scalar of a run: the weighted sum of the ranking metrics (`ranking`, e.g. max_abs_cte_on_path_m + 0.002 x
  rms_steer_rate_deg_s); a failed run (did not complete, left the track, limit-cycled) scores `failure_score`.
  The objective metrics are averaged over the runs that did not fail; the fraction that failed is given beside.
- Intervals: the percentile bootstrap of the mean over cases (`bootstrap_mean`): the cases are drawn with
  replacement `resamples` times, seeded, and the interval holds the central CONFIDENCE of the resampled means.
- The generalisation gap of a judged configuration: its mean on the test cases minus the mean of the same metric
  on the training cases, where its trial ran them (for the tuned configuration, the chosen trial).
- The ranking: the controllers' tuned configurations by their mean scalar on the test set, lowest first. Two
  controllers are not distinguishable when the interval of their paired mean difference (the bootstrap over the
  test cases both ran, `paired_difference`) contains 0, or when they ran fewer than MIN_PAIRED_CASES cases in
  common.
"""

from __future__ import annotations

import math
import numbers
import zlib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from itertools import combinations

import numpy as np
import pandas as pd

from workbench.apps.studies.spec import OBJECTIVE_METRICS
from workbench.apps.studies.tournament_spec import DEFAULT_OBJECTIVES
from workbench.base.errors import WorkbenchInputError, value_text

#: The share of the resampled means an interval holds (a 95 % interval).
CONFIDENCE = 0.95
#: Bootstrap resamples when none are given, and the fewest allowed (fewer make the interval's ends noisy).
DEFAULT_RESAMPLES = 2000
MIN_RESAMPLES = 100
#: The fewest common test cases for two controllers to be told apart: with fewer, even a difference of the same sign
#: on every case is no evidence at 5 % (a sign test: 2 x 0.5^5 = 6 % for five cases), and the percentile
#: bootstrap of a handful of values draws its interval too narrow.
MIN_PAIRED_CASES = 6
#: The column of the per-case table and the metric name of the gap table that hold the ranking scalar.
SCORE = "score"
#: The configurations of a results row: a training trial, and the judged ones (plus FRONT_PREFIX + rank).
TRIAL, DEFAULT, TUNED, FRONT_PREFIX = "trial", "default", "tuned", "front-"
TRAIN_SET, TEST_SET = "train", "test"
#: The columns `judge` reads (besides the ranking and objective metrics).
REQUIRED_COLUMNS = (
    "run_id", "scenario", "controller", "set", "config", "trial", "case", "failed", "cpu_time_s",
    "step_time_median_us", "step_time_p99_us",
)  # fmt: skip


@dataclass(frozen=True)
class TournamentSummary:
    """What a tournament's report states about it (plain text where a rule is given in words).

    controllers, vehicles: as the spec names them; train_cases, test_cases: the case ids of each set (they never
    overlap); trials: the trial budget every controller gets; selection_rule: how the chosen configuration is named
    from a front; ranking_rule: the ranking scalar in words; failure_score: what a failed run scores on it;
    inform_delays: whether the controllers are told the conditions' latency and dead time; seed: the sampler's and
    the bootstrap's seed; objectives: the metrics the front is drawn over; solve_budget: the MPCs' solve budget in
    words (it decides whether a run reproduces bit for bit)."""

    title: str
    description: str
    controllers: tuple[str, ...]
    vehicles: tuple[str, ...]
    train_cases: tuple[str, ...]
    test_cases: tuple[str, ...]
    trials: int
    selection_rule: str
    ranking_rule: str
    failure_score: float
    inform_delays: bool
    seed: int
    objectives: tuple[str, ...]
    solve_budget: str

    def __post_init__(self) -> None:
        for name in ("title", "description", "selection_rule", "ranking_rule", "solve_budget"):
            if not isinstance(getattr(self, name), str):
                raise WorkbenchInputError(f"summary {name} must be text; got {value_text(getattr(self, name))}")
        for name in ("controllers", "vehicles", "train_cases", "test_cases", "objectives"):
            values = getattr(self, name)
            if not isinstance(values, tuple) or not values or not all(isinstance(v, str) for v in values):
                raise WorkbenchInputError(f"summary {name} must be a non-empty tuple of text; got {value_text(values)}")
        both = sorted(set(self.train_cases) & set(self.test_cases))
        if both:
            raise WorkbenchInputError(f"a case cannot be in both the train and the test set; got {both[0]!r} in both")
        _require_metrics("summary objectives", self.objectives)
        if not _is_int(self.trials) or self.trials < 1:
            raise WorkbenchInputError(f"summary trials must be an integer >= 1; got {value_text(self.trials)}")
        if not _is_int(self.seed) or self.seed < 0:
            raise WorkbenchInputError(f"summary seed must be an integer >= 0; got {value_text(self.seed)}")
        _require_finite_number("summary failure_score", self.failure_score)
        if not isinstance(self.inform_delays, bool):
            value = value_text(self.inform_delays)
            raise WorkbenchInputError(f"summary inform_delays must be true or false; got {value}")


@dataclass(frozen=True)
class Interval:
    """A mean and its bootstrap interval [low, high] (NaN for no values)."""

    mean: float
    low: float
    high: float

    def contains(self, value: float) -> bool:
        """Whether `value` lies in [low, high], ends included.

        Parameters
        ----------
        value : float
            The value, in the unit of the mean.

        Returns
        -------
        bool
            False for NaN ends.
        """
        return self.low <= value <= self.high


@dataclass(frozen=True, eq=False)
class Judgement:
    """The verdict, as tables (one DataFrame each; `to_pandas` gives them by name).

    leaderboard: one row per controller, best first: rank, controller, trial (the chosen one), score and
    score_low/score_high (its tuned configuration's mean scalar on the test set and interval), the same of its
    default (default_score, default_low, default_high), failed_fraction, the mean of each objective metric,
    step_time_median_us (the median of the runs' median step times), step_time_p99_us (the median of the runs'
    99th percentiles), cpu_time_s (its training trials' CPU time, summed), cpu_time_per_trial_s, trials, and
    not_distinguishable_from (the controllers it cannot be told from, comma-separated, "" for none);
    scores: one row per judged (controller, config): trial, cases, failed_fraction, score with its interval, each
    objective metric with its interval (METRIC, METRIC_low, METRIC_high), the step times;
    per_case: one row per judged (controller, config, case): trial, scenario, failed (the fraction of the case's
    runs), score and the objective metrics;
    gap: one row per judged (controller, config) and metric (SCORE and each objective): train and test means, gap
    = test - train, and the cases each averages;
    pairwise: one row per pair of controllers, a ranked above b: cases (common test cases), difference (the mean
    of a's scalar minus b's) with low/high, distinguishable (the interval excludes 0 and there are at least
    MIN_PAIRED_CASES cases).
    ranking, failure_score, objectives, seed, resamples: what it was judged with."""

    leaderboard: pd.DataFrame
    scores: pd.DataFrame
    per_case: pd.DataFrame
    gap: pd.DataFrame
    pairwise: pd.DataFrame
    ranking: Mapping[str, float]
    failure_score: float
    objectives: tuple[str, ...]
    seed: int
    resamples: int

    def to_pandas(self) -> dict[str, pd.DataFrame]:
        """The tables by name: leaderboard, scores, per_case, gap, pairwise.

        Returns
        -------
        dict of str to pandas.DataFrame
            The tables themselves (not copies), in that order.
        """
        return {
            "leaderboard": self.leaderboard,
            "scores": self.scores,
            "per_case": self.per_case,
            "gap": self.gap,
            "pairwise": self.pairwise,
        }


def _is_int(value: object) -> bool:
    return isinstance(value, numbers.Integral) and not isinstance(value, bool | np.bool_)


def _require_finite_number(name: str, value: object) -> None:
    if not isinstance(value, numbers.Real) or isinstance(value, bool | np.bool_) or not math.isfinite(value):
        raise WorkbenchInputError(f"{name} must be a finite number; got {value_text(value)}")


def _require_metrics(name: str, metrics: Sequence[str]) -> None:
    for metric in metrics:
        if metric not in OBJECTIVE_METRICS:
            raise WorkbenchInputError(f"{name}: unknown metric {metric!r}; allowed: {', '.join(OBJECTIVE_METRICS)}")


def statistic_rng(seed: int, *key: str) -> np.random.Generator:
    """The generator of one statistic's resamples: seeded by the seed and the statistic's key (e.g. the
    controller, config and metric), so that each interval is the same whatever else is judged beside it.

    Parameters
    ----------
    seed : int
        The tournament's seed, at least 0.
    *key : str
        The statistic's key, e.g. the controller, config and metric.

    Returns
    -------
    numpy.random.Generator
        The same generator for the same seed and key, in any process.
    """
    return np.random.default_rng(np.random.SeedSequence([seed, *(zlib.crc32(k.encode()) for k in key)]))


def bootstrap_mean(
    values: Sequence[float] | np.ndarray, rng: np.random.Generator, resamples: int = DEFAULT_RESAMPLES
) -> Interval:
    """The mean of `values` (one per case) and its percentile-bootstrap interval: the values drawn with replacement
    `resamples` times, the interval's ends the (1 - CONFIDENCE) / 2 and (1 + CONFIDENCE) / 2 quantiles of the
    resampled means, widened to the mean where rounding puts it a hair outside (equal values). One value gives
    [value, value] (nothing to resample); none gives NaN.

    Parameters
    ----------
    values : sequence of float or numpy.ndarray
        One value per case, finite.
    rng : numpy.random.Generator
        The resampling generator (`statistic_rng`).
    resamples : int
        How many bootstrap resamples.

    Returns
    -------
    Interval
        The mean and its interval at CONFIDENCE.

    Raises
    ------
    WorkbenchInputError
        A value that is not finite.

    Examples
    --------
    >>> from workbench.apps.studies.tournament_judging import bootstrap_mean, statistic_rng
    >>> interval = bootstrap_mean([1.0, 2.0, 3.0, 4.0], statistic_rng(0, "clothoid", "tuned", "score"))
    >>> interval.mean, interval.contains(2.5)
    (2.5, True)
    """
    x = np.asarray(values, dtype=float)
    if x.size == 0:
        return Interval(math.nan, math.nan, math.nan)
    bad = ~np.isfinite(x)
    if bad.any():
        raise WorkbenchInputError(f"bootstrap values must be finite; got {value_text(x[bad][0])}")
    means = x[rng.integers(0, x.size, size=(resamples, x.size))].mean(axis=1)
    tail = 0.5 * (1.0 - CONFIDENCE)
    low, high = np.quantile(means, [tail, 1.0 - tail])
    return Interval(float(x.mean()), float(min(low, x.mean())), float(max(high, x.mean())))


def paired_difference(
    a: Sequence[float] | np.ndarray,
    b: Sequence[float] | np.ndarray,
    rng: np.random.Generator,
    resamples: int = DEFAULT_RESAMPLES,
) -> Interval:
    """The mean of a - b over paired cases (entry i of each is the same case) and its bootstrap interval: the cases
    are resampled as pairs, so what the cases share (a hard track for both) cancels.

    Parameters
    ----------
    a, b : sequence of float or numpy.ndarray
        One value per case each, entry i of both the same case; finite.
    rng : numpy.random.Generator
        The resampling generator (`statistic_rng`).
    resamples : int
        How many bootstrap resamples.

    Returns
    -------
    Interval
        The mean difference a - b and its interval at CONFIDENCE.

    Raises
    ------
    WorkbenchInputError
        a and b differ in length, or a value is not finite.
    """
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    if a.shape != b.shape:
        raise WorkbenchInputError(f"paired values come in pairs; got {a.size} and {b.size} values")
    return bootstrap_mean(a - b, rng, resamples)


def ranking_scores(results: pd.DataFrame, ranking: Mapping[str, float], failure_score: float) -> pd.Series:
    """Each run's ranking scalar: sum of weight x metric over `ranking`, `failure_score` for a failed run. A run
    that did not fail needs every ranking metric finite (it is refused otherwise, naming the run).

    Parameters
    ----------
    results : pandas.DataFrame
        One row per run, with failed, run_id, controller, case and the ranking metrics.
    ranking : mapping of str to float
        Metric -> weight.
    failure_score : float
        A failed run's scalar.

    Returns
    -------
    pandas.Series
        The scalar of each run, named SCORE, on the results' index.

    Raises
    ------
    WorkbenchInputError
        A run that did not fail with a ranking metric missing or not finite.
    """
    failed = results["failed"].astype(bool).to_numpy()
    total = np.zeros(len(results))
    for metric, weight in ranking.items():
        values = pd.to_numeric(results[metric], errors="coerce").to_numpy(dtype=float)
        bad = ~failed & ~np.isfinite(values)
        if bad.any():
            row = results.iloc[int(np.flatnonzero(bad)[0])]
            raise WorkbenchInputError(
                f"run {row['run_id']} ({row['controller']}, {row['case']}) did not fail but its {metric} is "
                f"{value_text(values[bad][0])}; a run that did not fail needs every ranking metric"
            )
        total += weight * np.where(failed, 0.0, values)
    return pd.Series(np.where(failed, failure_score, total), index=results.index, name=SCORE)


def _check_results(results: pd.DataFrame, metrics: Sequence[str]) -> None:
    missing = [c for c in (*REQUIRED_COLUMNS, *metrics) if c not in results.columns]
    if missing:
        raise WorkbenchInputError(f"the results lack the column(s) {', '.join(missing)}")
    sets = sorted(set(results["set"]) - {TRAIN_SET, TEST_SET})
    if sets:
        raise WorkbenchInputError(f"results set must be {TRAIN_SET!r} or {TEST_SET!r}; got {sets[0]!r}")
    train, test = results[results["set"] == TRAIN_SET], results[results["set"] == TEST_SET]
    if test.empty:
        raise WorkbenchInputError("the results hold no test runs: nothing to judge")
    if (train["config"] != TRIAL).any():
        raise WorkbenchInputError(f"training runs are trials (config {TRIAL!r}); got {train['config'].iloc[0]!r}")
    configs = set(test["config"])
    bad = sorted(c for c in configs if c not in (DEFAULT, TUNED) and not _is_front(c))
    if bad:
        allowed = f"{DEFAULT!r}, {TUNED!r} or {FRONT_PREFIX}K"
        raise WorkbenchInputError(f"a test run's config must be {allowed}; got {bad[0]!r}")
    both = sorted(set(train["case"]) & set(test["case"]))
    if both:
        raise WorkbenchInputError(f"case {both[0]!r} is in both the train and the test set")
    trials = test.groupby(["controller", "config"], sort=False)["trial"].nunique()
    if (trials > 1).any():
        controller, config = trials[trials > 1].index[0]
        raise WorkbenchInputError(f"{controller}'s {config} configuration ran with more than one trial's options")
    untuned = sorted(set(test["controller"]) - set(test.loc[test["config"] == TUNED, "controller"]))
    if untuned:
        raise WorkbenchInputError(f"controller {untuned[0]!r} has test runs but no tuned configuration among them")


def _is_front(config: str) -> bool:
    rank = config.removeprefix(FRONT_PREFIX)
    return config.startswith(FRONT_PREFIX) and rank.isdigit() and int(rank) >= 1


def _per_case(runs: pd.DataFrame, objectives: Sequence[str]) -> pd.DataFrame:
    """Each (controller, config, trial, case)'s mean: score over every run, objectives over the runs that did not
    fail, failed as the fraction that did."""
    frame = runs[["controller", "config", "trial", "case", "scenario", SCORE]].copy()
    frame["failed"] = runs["failed"].astype(float)
    for metric in objectives:
        frame[metric] = pd.to_numeric(runs[metric], errors="coerce").astype(float).where(~runs["failed"].astype(bool))
    return frame.groupby(["controller", "config", "trial", "case"], sort=False, as_index=False).agg(
        scenario=("scenario", "first"),
        failed=("failed", "mean"),
        **{name: (name, "mean") for name in (SCORE, *objectives)},
    )


def _scores(
    test: pd.DataFrame, per_case: pd.DataFrame, objectives: Sequence[str], seed: int, resamples: int
) -> pd.DataFrame:
    rows = []
    for (controller, config), cases in per_case.groupby(["controller", "config"], sort=False):
        runs = test[(test["controller"] == controller) & (test["config"] == config)]
        row: dict[str, object] = {
            "controller": controller,
            "config": config,
            "trial": int(cases["trial"].iloc[0]),
            "cases": len(cases),
            "failed_fraction": float(cases["failed"].mean()),
        }
        for metric in (SCORE, *objectives):
            values = cases[metric].dropna().to_numpy()
            interval = bootstrap_mean(values, statistic_rng(seed, controller, config, metric), resamples)
            row |= {metric: interval.mean, f"{metric}_low": interval.low, f"{metric}_high": interval.high}
        row["step_time_median_us"] = float(pd.to_numeric(runs["step_time_median_us"]).median())
        row["step_time_p99_us"] = float(pd.to_numeric(runs["step_time_p99_us"]).median())
        rows.append(row)
    return pd.DataFrame(rows)


def _gap(train: pd.DataFrame, per_case: pd.DataFrame, objectives: Sequence[str]) -> pd.DataFrame:
    trained = _per_case(train, objectives) if not train.empty else per_case.iloc[:0]
    rows = []
    for (controller, config), cases in per_case.groupby(["controller", "config"], sort=False):
        trial = cases["trial"].iloc[0]
        own = trained[(trained["controller"] == controller) & (trained["trial"] == trial)]
        for metric in (SCORE, *objectives):
            train_mean = float(own[metric].mean()) if own[metric].notna().any() else math.nan
            test_mean = float(cases[metric].mean()) if cases[metric].notna().any() else math.nan
            rows.append(
                {
                    "controller": controller,
                    "config": config,
                    "trial": int(trial),
                    "metric": metric,
                    "train": train_mean,
                    "test": test_mean,
                    "gap": test_mean - train_mean,
                    "train_cases": int(own[metric].notna().sum()),
                    "test_cases": int(cases[metric].notna().sum()),
                }
            )
    return pd.DataFrame(rows)


def _pairwise(per_case: pd.DataFrame, order: Sequence[str], seed: int, resamples: int) -> pd.DataFrame:
    tuned = per_case[per_case["config"] == TUNED].pivot(index="case", columns="controller", values=SCORE)
    rows = []
    for a, b in combinations(order, 2):
        common = tuned[[a, b]].dropna()
        interval = paired_difference(common[a], common[b], statistic_rng(seed, "paired", a, b), resamples)
        rows.append(
            {
                "controller_a": a,
                "controller_b": b,
                "cases": len(common),
                "difference": interval.mean,
                "low": interval.low,
                "high": interval.high,
                "distinguishable": bool(len(common) >= MIN_PAIRED_CASES and not interval.contains(0.0)),
            }
        )
    return pd.DataFrame(
        rows, columns=["controller_a", "controller_b", "cases", "difference", "low", "high", "distinguishable"]
    )


def _leaderboard(
    train: pd.DataFrame, scores: pd.DataFrame, pairwise: pd.DataFrame, order: Sequence[str], objectives: Sequence[str]
) -> pd.DataFrame:
    rows = []
    for rank, controller in enumerate(order, start=1):
        tuned = scores[(scores["controller"] == controller) & (scores["config"] == TUNED)].iloc[0]
        default = scores[(scores["controller"] == controller) & (scores["config"] == DEFAULT)]
        own = train[train["controller"] == controller]
        trials = int(own["trial"].nunique())
        cpu = float(pd.to_numeric(own["cpu_time_s"]).sum()) if trials else math.nan
        pairs = pairwise[(pairwise["controller_a"] == controller) | (pairwise["controller_b"] == controller)]
        tied = [
            p.controller_b if p.controller_a == controller else p.controller_a
            for p in pairs.itertuples()
            if not p.distinguishable
        ]
        rows.append(
            {
                "rank": rank,
                "controller": controller,
                "trial": int(tuned["trial"]),
                "score": tuned[SCORE],
                "score_low": tuned[f"{SCORE}_low"],
                "score_high": tuned[f"{SCORE}_high"],
                "default_score": default[SCORE].iloc[0] if len(default) else math.nan,
                "default_low": default[f"{SCORE}_low"].iloc[0] if len(default) else math.nan,
                "default_high": default[f"{SCORE}_high"].iloc[0] if len(default) else math.nan,
                "failed_fraction": tuned["failed_fraction"],
                **{metric: tuned[metric] for metric in objectives},
                "step_time_median_us": tuned["step_time_median_us"],
                "step_time_p99_us": tuned["step_time_p99_us"],
                "cpu_time_s": cpu,
                "cpu_time_per_trial_s": cpu / trials if trials else math.nan,
                "trials": trials,
                "not_distinguishable_from": ", ".join(tied),
            }
        )
    return pd.DataFrame(rows)


def judge(
    results: pd.DataFrame,
    ranking: Mapping[str, float],
    seed: int,
    resamples: int = DEFAULT_RESAMPLES,
    *,
    failure_score: float,
    objectives: Sequence[str] = DEFAULT_OBJECTIVES,
) -> Judgement:
    """Judge a tournament's runs (the module's docstring says how).

    results: one row per run, with the columns REQUIRED_COLUMNS, the ranking metrics and the objectives; ranking:
    metric -> weight of the ranking scalar; seed: of every bootstrap (each statistic draws from its own stream,
    `statistic_rng`); resamples: per interval; failure_score: a failed run's scalar; objectives: the metrics judged
    beside the scalar. Refused (WorkbenchInputError): a missing column, an unknown set, config or metric, a case in
    both sets, a controller judged without a tuned configuration, a run that did not fail without a ranking metric.

    Parameters
    ----------
    results : pandas.DataFrame
        One row per run, with the columns REQUIRED_COLUMNS, the ranking metrics and the objectives.
    ranking : mapping of str to float
        Metric -> weight of the ranking scalar; at least one, every weight finite.
    seed : int
        The bootstraps' seed, at least 0.
    resamples : int
        Bootstrap resamples per interval, at least MIN_RESAMPLES.
    failure_score : float
        A failed run's scalar, finite.
    objectives : sequence of str
        The metrics judged beside the scalar, each of OBJECTIVE_METRICS.

    Returns
    -------
    Judgement
        The leaderboard, scores, per-case scores, train-test gap and pairwise differences.

    Raises
    ------
    WorkbenchInputError
        Any of the refusals above, or an unknown metric, a weight or failure_score not finite, a seed below 0 or
        resamples below MIN_RESAMPLES.
    """
    if not ranking:
        raise WorkbenchInputError("the ranking needs at least one metric and its weight; got none")
    _require_metrics("ranking", list(ranking))
    _require_metrics("objectives", objectives)
    for metric, weight in ranking.items():
        _require_finite_number(f"ranking weight of {metric}", weight)
    _require_finite_number("failure_score", failure_score)
    if not _is_int(seed) or seed < 0:
        raise WorkbenchInputError(f"seed must be an integer >= 0; got {value_text(seed)}")
    if not _is_int(resamples) or resamples < MIN_RESAMPLES:
        raise WorkbenchInputError(f"resamples must be an integer >= {MIN_RESAMPLES}; got {value_text(resamples)}")
    objectives = tuple(objectives)
    _check_results(results, [*ranking, *objectives])
    runs = results.assign(**{SCORE: ranking_scores(results, ranking, failure_score)})
    train, test = runs[runs["set"] == TRAIN_SET], runs[runs["set"] == TEST_SET]
    per_case = _per_case(test, objectives)
    scores = _scores(test, per_case, objectives, seed, resamples)
    tuned = scores[scores["config"] == TUNED].sort_values([SCORE, "controller"], kind="stable")
    order = list(tuned["controller"])
    pairwise = _pairwise(per_case, order, seed, resamples)
    return Judgement(
        leaderboard=_leaderboard(train, scores, pairwise, order, objectives),
        scores=scores,
        per_case=per_case,
        gap=_gap(train, per_case, objectives),
        pairwise=pairwise,
        ranking=dict(ranking),
        failure_score=float(failure_score),
        objectives=objectives,
        seed=int(seed),
        resamples=int(resamples),
    )


__all__ = [
    "CONFIDENCE",
    "DEFAULT",
    "DEFAULT_RESAMPLES",
    "FRONT_PREFIX",
    "MIN_PAIRED_CASES",
    "MIN_RESAMPLES",
    "REQUIRED_COLUMNS",
    "SCORE",
    "TEST_SET",
    "TRAIN_SET",
    "TRIAL",
    "TUNED",
    "Interval",
    "Judgement",
    "TournamentSummary",
    "bootstrap_mean",
    "judge",
    "paired_difference",
    "ranking_scores",
    "statistic_rng",
]
