"""The tournament's judging statistics (`tournament_judging.py`) against references computed here: bootstrap
intervals against the t interval, the paired test on constructed cases, scores with failures, the generalisation
gap, step and CPU time, and the refusals."""

from __future__ import annotations

import dataclasses

import numpy as np
import pandas as pd
import pytest
from judging_frames import FAILURE_SCORE, OBJECTIVES, RANKING, Run, case_id, results_frame, summary
from scipy import stats

from workbench.apps.studies.tournament_judging import (
    MIN_PAIRED_CASES,
    SCORE,
    Judgement,
    bootstrap_mean,
    judge,
    paired_difference,
    ranking_scores,
    statistic_rng,
)
from workbench.base.errors import WorkbenchInputError

TRAIN = (("dlc", 1), ("figure8", 1))
#: Test cases of very different difficulty (a hard track costs every controller alike).
TEST = tuple((f"circuit:{k}", seed) for k in range(8) for seed in (11, 12))
DIFFICULTY = {case: 0.05 + 0.4 * (k % 5) + 0.003 * case[1] for k, case in enumerate(TEST)}


def _tournament(margins: dict[str, float], failed: frozenset[tuple[str, str, int]] = frozenset()) -> pd.DataFrame:
    """Three trials per controller on TRAIN, trial 2 chosen; default (trial 0) and tuned on TEST, where a
    controller's max |CTE| is the case's difficulty plus its margin (the default 0.1 m worse)."""
    runs = []
    for controller, margin in margins.items():
        for trial in range(3):
            for scenario, seed in TRAIN:
                runs.append(Run(controller, "train", "trial", trial, scenario, seed, 0.2 + margin - 0.01 * trial))
        for config, trial, extra in (("default", 0, 0.1), ("tuned", 2, 0.0)):
            for scenario, seed in TEST:
                value = DIFFICULTY[(scenario, seed)] + margin + extra
                failing = (controller, scenario, seed) in failed
                runs.append(Run(controller, "test", config, trial, scenario, seed, value, failed=failing))
    return results_frame(runs)


def _judge(results: pd.DataFrame, seed: int = 3, resamples: int = 2000) -> Judgement:
    return judge(results, RANKING, seed, resamples, failure_score=FAILURE_SCORE, objectives=OBJECTIVES)


def test_the_bootstrap_interval_of_a_normal_sample_s_mean_is_the_t_interval() -> None:
    sample = np.random.default_rng(5).normal(2.0, 0.5, size=400)
    interval = bootstrap_mean(sample, statistic_rng(1, "t"), resamples=8000)
    low, high = stats.t.interval(0.95, df=sample.size - 1, loc=sample.mean(), scale=stats.sem(sample))
    half = 0.5 * (high - low)
    assert interval.mean == pytest.approx(sample.mean(), abs=1e-12)
    assert interval.low == pytest.approx(low, abs=0.08 * half)
    assert interval.high == pytest.approx(high, abs=0.08 * half)


def test_one_value_has_no_spread_and_none_has_no_mean() -> None:
    one = bootstrap_mean([0.3], statistic_rng(1, "x"))
    assert (one.mean, one.low, one.high) == (0.3, 0.3, 0.3)
    assert np.isnan(bootstrap_mean([], statistic_rng(1, "x")).mean)


def test_a_margin_on_every_case_is_distinguishable_and_equal_values_are_not() -> None:
    spread = np.random.default_rng(2).uniform(0.05, 2.0, size=12)  # cases far apart: unpaired intervals overlap
    better = paired_difference(spread - 0.01, spread, statistic_rng(1, "p"))
    assert better.mean == pytest.approx(-0.01, abs=1e-12)
    assert better.high < 0.0
    equal = paired_difference(spread, spread, statistic_rng(1, "p"))
    assert (equal.low, equal.high) == (0.0, 0.0) and equal.contains(0.0)
    unpaired = bootstrap_mean(spread - 0.01, statistic_rng(1, "a")), bootstrap_mean(spread, statistic_rng(1, "b"))
    assert unpaired[0].high > unpaired[1].low  # what the pairing tells apart, the means' intervals cannot


def test_the_leaderboard_ranks_by_the_tuned_score_and_names_who_cannot_be_told_apart() -> None:
    judgement = _judge(_tournament({"clothoid": 0.0, "nmpc": 0.02, "stanley": 0.02}))
    board = judgement.leaderboard.set_index("controller")
    assert list(judgement.leaderboard["controller"]) == ["clothoid", "nmpc", "stanley"]  # ties by name
    assert list(judgement.leaderboard["rank"]) == [1, 2, 3]
    assert board.loc["clothoid", "not_distinguishable_from"] == ""
    assert board.loc["nmpc", "not_distinguishable_from"] == "stanley"
    assert board.loc["stanley", "not_distinguishable_from"] == "nmpc"
    pairs = judgement.pairwise.set_index(["controller_a", "controller_b"])
    assert pairs.loc[("clothoid", "nmpc"), "difference"] == pytest.approx(-0.02, abs=1e-12)
    assert bool(pairs.loc[("clothoid", "nmpc"), "distinguishable"])
    assert not bool(pairs.loc[("nmpc", "stanley"), "distinguishable"])
    assert (pairs["cases"] == len(TEST)).all()


def test_a_margin_on_too_few_common_cases_is_not_distinguishable() -> None:
    results = _tournament({"clothoid": 0.0, "nmpc": 0.02})
    few = {case_id(*case) for case in TEST[: MIN_PAIRED_CASES - 1]}
    judgement = _judge(results[(results["set"] == "train") | results["case"].isin(few)])
    pair = judgement.pairwise.iloc[0]
    assert pair["cases"] == MIN_PAIRED_CASES - 1 and pair["high"] < 0.0  # one sign on every case, yet too few
    assert not pair["distinguishable"]
    assert list(judgement.leaderboard["not_distinguishable_from"]) == ["nmpc", "clothoid"]


def test_scores_are_the_weighted_sum_averaged_per_case_with_the_failure_score() -> None:
    failed = frozenset({("nmpc", "circuit:0", 11), ("nmpc", "circuit:3", 12)})
    results = _tournament({"clothoid": 0.0, "nmpc": 0.02}, failed)
    judgement = _judge(results)
    test = results[(results["set"] == "test") & (results["controller"] == "nmpc") & (results["config"] == "tuned")]
    reference = np.where(test["failed"], FAILURE_SCORE, test["max_abs_cte_m"] + 0.002 * test["rms_steer_rate_deg_s"])
    scores = judgement.scores.set_index(["controller", "config"])
    assert scores.loc[("nmpc", "tuned"), SCORE] == pytest.approx(reference.mean(), rel=1e-12)
    assert scores.loc[("nmpc", "tuned"), "failed_fraction"] == pytest.approx(2 / len(TEST))
    completed = test.loc[~test["failed"], "max_abs_cte_m"]  # objective metrics: over the runs that did not fail
    assert scores.loc[("nmpc", "tuned"), "max_abs_cte_m"] == pytest.approx(completed.mean(), rel=1e-12)
    row = scores.loc[("nmpc", "tuned")]
    assert row[f"{SCORE}_low"] <= row[SCORE] <= row[f"{SCORE}_high"]
    assert scores.loc[("clothoid", "default"), SCORE] == pytest.approx(scores.loc[("clothoid", "tuned"), SCORE] + 0.1)
    board = judgement.leaderboard.set_index("controller")
    assert board.loc["clothoid", "default_score"] == pytest.approx(scores.loc[("clothoid", "default"), SCORE])


def test_the_ranking_scalar_refuses_a_completed_run_without_its_metric() -> None:
    results = _tournament({"clothoid": 0.0})
    results.loc[3, "rms_steer_rate_deg_s"] = np.nan
    with pytest.raises(WorkbenchInputError, match=r"r00003 .*did not fail but its rms_steer_rate_deg_s is nan"):
        ranking_scores(results, RANKING, FAILURE_SCORE)
    results.loc[3, "failed"] = True  # a failed run needs none: it scores the failure score
    assert ranking_scores(results, RANKING, FAILURE_SCORE)[3] == FAILURE_SCORE


def test_the_gap_compares_the_chosen_trial_s_training_cases_with_the_tuned_test_cases() -> None:
    runs = [
        # the chosen trial 1: dlc twice (0.1 and 0.3: the case's mean 0.2), figure8 once (0.5); per case 0.35
        Run("clothoid", "train", "trial", 1, "dlc", 1, 0.1),
        Run("clothoid", "train", "trial", 1, "dlc", 1, 0.3),
        Run("clothoid", "train", "trial", 1, "figure8", 1, 0.5),
        Run("clothoid", "train", "trial", 0, "dlc", 1, 9.0),  # another trial's runs count for another config
        Run("clothoid", "train", "trial", 0, "figure8", 1, 9.0),
        Run("clothoid", "test", "tuned", 1, "circuit:1", 2, 0.4),
        Run("clothoid", "test", "tuned", 1, "circuit:2", 2, 0.6),
        Run("clothoid", "test", "default", 0, "circuit:1", 2, 1.0),
    ]
    gap = _judge(results_frame(runs)).gap.set_index(["config", "metric"])
    tuned = gap.loc[("tuned", "max_abs_cte_m")]
    assert tuned["train"] == pytest.approx(0.35) and tuned["test"] == pytest.approx(0.5)
    assert tuned["gap"] == pytest.approx(0.15)
    assert (tuned["train_cases"], tuned["test_cases"]) == (2, 2)
    assert gap.loc[("tuned", SCORE), "gap"] == pytest.approx(0.15)  # the steering rate is alike on both
    assert gap.loc[("default", "max_abs_cte_m"), "gap"] == pytest.approx(1.0 - 9.0)


def test_step_and_cpu_time() -> None:
    runs = [
        Run("lmpc", "train", "trial", trial, "dlc", 1, 0.2, cpu_time_s=cpu) for trial, cpu in enumerate((2.0, 4.0, 9.0))
    ]
    runs += [
        Run("lmpc", "test", "tuned", 2, f"circuit:{k}", 5, 0.2, step_time_median_us=m, step_time_p99_us=p)
        for k, (m, p) in enumerate(((100.0, 300.0), (120.0, 900.0), (400.0, 500.0)))
    ]
    board = _judge(results_frame(runs)).leaderboard.iloc[0]
    assert board["step_time_median_us"] == 120.0  # the median of the runs' medians
    assert board["step_time_p99_us"] == 500.0  # the median of the runs' p99
    assert board["cpu_time_s"] == pytest.approx(15.0) and board["cpu_time_per_trial_s"] == pytest.approx(5.0)
    assert board["trials"] == 3
    assert np.isnan(board["default_score"])  # no default judged


def test_the_same_seed_gives_the_same_verdict_and_another_seed_other_intervals() -> None:
    results = _tournament({"clothoid": 0.0, "nmpc": 0.02})
    first, again, other = _judge(results, seed=3), _judge(results, seed=3), _judge(results, seed=4)
    for name, frame in first.to_pandas().items():
        pd.testing.assert_frame_equal(frame, again.to_pandas()[name])
    assert first.scores[f"{SCORE}_low"].tolist() != other.scores[f"{SCORE}_low"].tolist()
    assert first.scores[SCORE].tolist() == other.scores[SCORE].tolist()


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (lambda r: r.drop(columns="case"), "lack the column.*case"),
        (lambda r: r.assign(set=r["set"].replace("test", "holdout")), "set must be 'train' or 'test'; got 'holdout'"),
        (lambda r: r.assign(config=r["config"].replace("tuned", "best")), "config must be .*; got 'best'"),
        (lambda r: r.assign(config=r["config"].replace("tuned", "front-0")), "got 'front-0'"),
        (lambda r: r[r["config"] != "tuned"], "'clothoid' has test runs but no tuned configuration"),
        (lambda r: r[r["set"] == "train"], "no test runs"),
        (
            lambda r: r.assign(case=r["case"].where(r["set"] == "test", case_id("circuit:0", 11))),
            r"case 'circuit:0\|.*' is in both the train and the test set",
        ),
    ],
)
def test_malformed_results_are_refused(change, message: str) -> None:
    with pytest.raises(WorkbenchInputError, match=message):
        _judge(change(_tournament({"clothoid": 0.0})))


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"ranking": {}}, "at least one metric"),
        ({"ranking": {"cte": 1.0}}, "unknown metric 'cte'"),
        ({"ranking": {"max_abs_cte_m": float("nan")}}, "weight of max_abs_cte_m must be a finite number; got nan"),
        ({"resamples": 10}, "resamples must be an integer >= 100; got 10"),
        ({"seed": -1}, "seed must be an integer >= 0; got -1"),
        ({"failure_score": float("inf")}, "failure_score must be a finite number; got inf"),
        ({"objectives": ("status",)}, "unknown metric 'status'"),
    ],
)
def test_bad_settings_are_refused(kwargs: dict, message: str) -> None:
    settings = {"ranking": RANKING, "seed": 1, "resamples": 200, "failure_score": FAILURE_SCORE}
    settings |= {"objectives": OBJECTIVES} | kwargs
    with pytest.raises(WorkbenchInputError, match=message):
        judge(_tournament({"clothoid": 0.0}), **settings)


def test_a_summary_refuses_a_case_in_both_sets_and_an_unknown_objective() -> None:
    good = summary(_tournament({"clothoid": 0.0}))
    with pytest.raises(WorkbenchInputError, match="both the train and the test set; got 'dlc"):
        dataclasses.replace(good, test_cases=(*good.test_cases, good.train_cases[0]))
    with pytest.raises(WorkbenchInputError, match="unknown metric 'cte'"):
        dataclasses.replace(good, objectives=("cte",))
    with pytest.raises(WorkbenchInputError, match="trials must be an integer >= 1; got 0"):
        dataclasses.replace(good, trials=0)
