"""Small tournament tables for the judging and report tests, built as the tournament writes them: results (one row
per run: the runner's columns plus set, config, trial, case, failed, command) and history (one row per controller
and trial)."""

from __future__ import annotations

import json
from collections.abc import Sequence
from dataclasses import dataclass

import pandas as pd

from workbench.apps.studies.runner import ROW_METRICS
from workbench.apps.studies.tournament_judging import TournamentSummary

VEHICLE = "tractor-semitrailer"
SPEED_KMH = 30.0
CONDITIONS = "automotive"
#: The ranking of the tests: max |CTE| plus 0.002 x RMS steering-wheel rate.
RANKING = {"max_abs_cte_m": 1.0, "rms_steer_rate_deg_s": 0.002}
FAILURE_SCORE = 10.0
#: The objectives the frames carry (the runs here start on their paths: max |CTE| is the one on the path).
OBJECTIVES = ("rms_cte_m", "max_abs_cte_m", "rms_steer_rate_deg_s")


def case_id(scenario: str, seed: int) -> str:
    """The case text the tournament writes: scenario|vehicle|speed|conditions|seed."""
    return f"{scenario}|{VEHICLE}|{SPEED_KMH:g}|{CONDITIONS}|{seed}"


@dataclass(frozen=True)
class Run:
    """One run of the table: who ran which case with which configuration, and what it measured."""

    controller: str
    set: str
    config: str
    trial: int
    scenario: str
    seed: int
    max_abs_cte_m: float
    rms_steer_rate_deg_s: float = 10.0
    rms_cte_m: float | None = None
    failed: bool = False
    cpu_time_s: float = 1.0
    step_time_median_us: float = 50.0
    step_time_p99_us: float = 80.0


def results_frame(runs: Sequence[Run]) -> pd.DataFrame:
    """The results table of `runs`, every column of the contract filled."""
    rows = []
    for number, run in enumerate(runs):
        metrics: dict[str, object] = dict.fromkeys(ROW_METRICS)
        metrics |= {
            "completed": not run.failed,
            "max_abs_cte_m": run.max_abs_cte_m,
            "rms_cte_m": run.max_abs_cte_m / 2.0 if run.rms_cte_m is None else run.rms_cte_m,
            "rms_steer_rate_deg_s": run.rms_steer_rate_deg_s,
            "limit_cycle": False,
            "step_time_median_us": run.step_time_median_us,
            "step_time_p99_us": run.step_time_p99_us,
        }
        case = case_id(run.scenario, run.seed)
        rows.append(
            {
                "run_id": f"r{number:05d}",
                "scenario": run.scenario,
                "controller": run.controller,
                "vehicle": VEHICLE,
                "speed_kmh": SPEED_KMH,
                "conditions": CONDITIONS,
                "seed": run.seed,
                "inform_delays": True,
                **metrics,
                "status": "left_path" if run.failed else "completed",
                "message": "left the path" if run.failed else "",
                "run_time_s": run.cpu_time_s,
                "cpu_time_s": run.cpu_time_s,
                "set": run.set,
                "config": run.config,
                "trial": run.trial,
                "case": case,
                "failed": run.failed,
                "command": f"workbench run {run.scenario} --controller {run.controller} --seed {run.seed}",
            }
        )
    return pd.DataFrame(rows)


def history_frame(results: pd.DataFrame, chosen: dict[str, int], carried: dict[str, dict[int, int]]) -> pd.DataFrame:
    """The history of the results' training trials: their mean objectives, the front (by train max |CTE| and
    RMS steering rate), the chosen trial and the carried ones (controller -> trial -> rank)."""
    from workbench.apps.studies.plots import pareto_mask

    train = results[results["set"] == "train"]
    rows = []
    for (controller, trial), runs in train.groupby(["controller", "trial"], sort=True):
        failed = int(runs["failed"].sum())
        rows.append(
            {
                "controller": controller,
                "trial": int(trial),
                "state": "failed" if failed else "complete",
                "reason": f"{failed} runs failed" if failed else "",
                "train_rms_cte_m": runs["rms_cte_m"].mean(),
                "train_max_abs_cte_m": runs["max_abs_cte_m"].mean(),
                "train_rms_steer_rate_deg_s": runs["rms_steer_rate_deg_s"].mean(),
                "params_json": json.dumps({"gain": 1.0 + 0.1 * int(trial)}),
                "cpu_time_s": runs["cpu_time_s"].sum(),
                "runs": len(runs),
                "failed_runs": failed,
                "chosen": chosen.get(controller) == trial,
                "carried": carried.get(controller, {}).get(int(trial)),
            }
        )
    history = pd.DataFrame(rows)
    history["pareto"] = False
    for _, group in history.groupby("controller"):
        ok = group[group["state"] == "complete"]
        mask = pareto_mask(ok["train_rms_steer_rate_deg_s"].to_numpy(), ok["train_max_abs_cte_m"].to_numpy())
        history.loc[ok.index[mask], "pareto"] = True
    history["carried"] = history["carried"].astype("Int64")
    return history


def summary(results: pd.DataFrame) -> TournamentSummary:
    """The summary of a tournament that ran `results`."""
    train = tuple(dict.fromkeys(results.loc[results["set"] == "train", "case"]))
    test = tuple(dict.fromkeys(results.loc[results["set"] == "test", "case"]))
    return TournamentSummary(
        title="Tournament: a test",
        description="Three controllers on the loaded truck, a small synthetic tournament.",
        controllers=tuple(dict.fromkeys(results["controller"])),
        vehicles=(VEHICLE,),
        train_cases=train,
        test_cases=test,
        trials=int(results.loc[results["set"] == "train", "trial"].nunique()),
        selection_rule="the front point with the least max_abs_cte_m + 0.002 x rms_steer_rate_deg_s",
        ranking_rule="max_abs_cte_m + 0.002 x rms_steer_rate_deg_s",
        failure_score=FAILURE_SCORE,
        inform_delays=True,
        seed=7,
        objectives=OBJECTIVES,
        solve_budget="max_solve_time_s = 10 s for the MPCs: no solve is ever cut short",
    )
