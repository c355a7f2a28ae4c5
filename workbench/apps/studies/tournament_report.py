"""The tournament's report: DIR/report.html, one self-contained page (`report.html_page`, figures embedded as PNG)
with the leaderboard, each controller's front on the training cases and its judged points on the test cases,
default against tuned, train against test (the generalisation gap), a table per test scenario, the steering and
CTE traces of each controller's chosen configuration on one test scenario, the rules in words and how to read it.

The figures are drawn by functions that take the axes to draw on (and return them), from the tournament's tables:
the history (one row per controller and trial), the judgement's tables (`tournament_judging.Judgement`) and the
traces of the chosen configurations (`SimulationResult`s). Each figure is a bare matplotlib Figure (Agg, no
pyplot state), closed once embedded.
"""

from __future__ import annotations

import html
import json
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import pandas as pd

from workbench.apps.report import figure_png, html_page, number_text, png_figure, text_table
from workbench.apps.studies.plots import LABELS, shown_value
from workbench.apps.studies.tournament_judging import (
    CONFIDENCE,
    DEFAULT,
    FRONT_PREFIX,
    MIN_PAIRED_CASES,
    SCORE,
    TEST_SET,
    TUNED,
    Judgement,
    TournamentSummary,
)
from workbench.base.errors import WorkbenchInputError
from workbench.simulation import plots

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from workbench.simulation.result import SimulationResult

REPORT_FILE = "report.html"
#: The report's sections, in order: (id, heading). Each heading carries its id, so a section can be linked to.
SECTIONS: tuple[tuple[str, str], ...] = (
    ("leaderboard", "Leaderboard"),
    ("fronts", "Fronts on the training cases, points on the test cases"),
    ("default-vs-tuned", "Default against tuned"),
    ("train-vs-test", "Train against test: the generalisation gap"),
    ("per-scenario", "Per test scenario"),
    ("traces", "Steering and CTE of the chosen configurations on one test scenario"),
    ("rules", "The rules"),
    ("reading", "How to read this report"),
)
#: The history columns the report reads, besides the train_ mean of each objective.
HISTORY_COLUMNS = ("controller", "trial", "state", "params_json", "pareto", "chosen", "carried")
#: The steering effort the fronts are drawn against when it is an objective.
EFFORT = "rms_steer_rate_deg_s"
#: Sizes (inches) of a two-panel figure (a front and its test points) and of the stacked traces.
WIDE_FIGURE_IN = (12.0, 4.5)
TRACES_FIGURE_IN = (8.0, 11.0)
SCORE_LABEL = "ranking score (lower is better)"
#: The tracking metrics a front may be drawn with, the preferred first.
TRACKING_METRICS = ("max_abs_cte_on_path_m", "max_abs_cte_m", "rms_cte_m")
_PERCENT = f"{CONFIDENCE:.0%}"


def _new_axes(size: tuple[float, float] = plots.FIGURE_SIZE_IN, panels: int = 1, rows: int = 1) -> list[Axes]:
    """The axes of a bare figure (no pyplot state; `report.figure_png` draws it with Agg and closes it)."""
    from matplotlib.figure import Figure

    figure = Figure(figsize=size, layout="constrained")
    return list(np.ravel(figure.subplots(rows, panels, squeeze=False)))


def front_metrics(objectives: Sequence[str], ranking: Mapping[str, float]) -> tuple[str, str]:
    """(effort, error): the objectives the fronts are drawn with. Effort: the RMS steering rate when it is an
    objective, else the last objective; error: of the TRACKING_METRICS the first the ranking weighs when it is an
    objective, else the first that is one, else the first objective.

    Parameters
    ----------
    objectives : sequence of str
        The tournament's objectives, at least one.
    ranking : mapping of str to float
        The ranking's metric -> weight.

    Returns
    -------
    tuple of (str, str)
        (effort, error).

    Examples
    --------
    >>> from workbench.apps.studies.tournament_report import front_metrics
    >>> front_metrics(["rms_cte_m", "max_abs_cte_on_path_m", "rms_steer_rate_deg_s"], {"max_abs_cte_on_path_m": 1.0})
    ('rms_steer_rate_deg_s', 'max_abs_cte_on_path_m')
    """
    effort = EFFORT if EFFORT in objectives else objectives[-1]
    weighed = [m for m in TRACKING_METRICS if m in ranking]
    preferred = [*weighed, *TRACKING_METRICS]
    error = next((m for m in preferred if m in objectives and m != effort), objectives[0])
    return effort, error


def _label(metric: str) -> str:
    return LABELS.get(metric, metric)


def training_front(
    history: pd.DataFrame, controller: str, ax: Axes, error: str = "max_abs_cte_on_path_m", effort: str = EFFORT
) -> Axes:
    """The controller's trials on the training cases (the history's train_ means of `error` against `effort`):
    every trial, the points of its front (over every objective: with more than two, a front point may look beaten
    in this projection), the default (trial 0), the chosen trial and the front points carried to the test set
    (F1.., by their rank).

    Parameters
    ----------
    history : pandas.DataFrame
        One row per controller and trial (HISTORY_COLUMNS and the train_ means).
    controller : str
        The controller drawn.
    ax : matplotlib.axes.Axes
        The axes to draw on.
    error : str
        The tracking objective (y), e.g. "max_abs_cte_on_path_m" (`front_metrics`).
    effort : str
        The effort objective (x), e.g. "rms_steer_rate_deg_s".

    Returns
    -------
    matplotlib.axes.Axes
        The axes drawn on.
    """
    own = history[history["controller"] == controller]
    xs, ys = f"train_{effort}", f"train_{error}"
    x, y = own[xs].astype(float), own[ys].astype(float)
    complete = (own["state"] == "complete").to_numpy()
    ax.scatter(x[complete], y[complete], s=14, color="0.55", alpha=0.6, linewidths=0, label="trials")
    failed = ~complete & np.isfinite(x.to_numpy()) & np.isfinite(y.to_numpy())
    if failed.any():
        ax.scatter(x[failed], y[failed], s=18, marker="x", color="tab:red", alpha=0.6, label="failed trials")
    front = own[own["pareto"].astype(bool)]
    ax.scatter(front[xs], front[ys], s=22, color="tab:blue", zorder=2, label="front")
    _mark(ax, own[own["trial"] == 0], xs, ys, "s", "default (trial 0)")
    _mark(ax, own[own["chosen"].astype(bool)], xs, ys, "*", "chosen (tuned)")
    carried = own[own["carried"].notna()]
    if not carried.empty:
        ax.scatter(
            carried[xs], carried[ys], s=70, facecolors="none", edgecolors="tab:green", label="carried to the test set"
        )
        for row in carried.itertuples():
            point = (getattr(row, xs), getattr(row, ys))
            ax.annotate(f"F{int(row.carried)}", point, xytext=(4, 4), textcoords="offset points", fontsize=7)
    ax.set(xlabel=_label(effort), ylabel=_label(error), title=f"{controller}: trials on the training cases (means)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize="small")
    return ax


def _mark(ax: Axes, rows: pd.DataFrame, x: str, y: str, marker: str, label: str) -> None:
    if not rows.empty:
        size = 110 if marker == "*" else 55
        ax.scatter(rows[x], rows[y], s=size, marker=marker, color="tab:orange", edgecolors="k", zorder=3, label=label)


def judged_points(
    scores: pd.DataFrame, controller: str, ax: Axes, error: str = "max_abs_cte_on_path_m", effort: str = EFFORT
) -> Axes:
    """The controller's judged configurations on the test cases: mean `error` against mean `effort`, with their
    intervals as error bars: the default, the tuned configuration and the carried front points (F1..).

    Parameters
    ----------
    scores : pandas.DataFrame
        `Judgement.scores`.
    controller : str
        The controller drawn.
    ax : matplotlib.axes.Axes
        The axes to draw on.
    error : str
        The tracking objective (y), e.g. "max_abs_cte_on_path_m" (`front_metrics`).
    effort : str
        The effort objective (x), e.g. "rms_steer_rate_deg_s".

    Returns
    -------
    matplotlib.axes.Axes
        The axes drawn on.
    """
    own = scores[scores["controller"] == controller]
    for row in own.itertuples():
        config = str(row.config)
        x, y = getattr(row, effort), getattr(row, error)
        xerr = [[x - getattr(row, f"{effort}_low")], [getattr(row, f"{effort}_high") - x]]
        yerr = [[y - getattr(row, f"{error}_low")], [getattr(row, f"{error}_high") - y]]
        style: dict[str, Any]  # matplotlib's keyword arguments, of mixed types
        if config == DEFAULT:
            style = {"marker": "s", "color": "tab:orange", "label": "default"}
        elif config == TUNED:
            style = {"marker": "*", "color": "tab:orange", "label": "tuned (chosen)", "markersize": 12}
        else:
            style = {"marker": "o", "color": "tab:green", "mfc": "none", "label": None}
        ax.errorbar(x, y, xerr=xerr, yerr=yerr, ls="none", capsize=2, elinewidth=0.8, mec="k", **style)
        if config.startswith(FRONT_PREFIX):
            ax.annotate(
                f"F{config.removeprefix(FRONT_PREFIX)}", (x, y), xytext=(4, 4), textcoords="offset points", fontsize=7
            )
    if own["config"].astype(str).str.startswith(FRONT_PREFIX).any():
        ax.plot([], [], "o", color="tab:green", mfc="none", label="carried front points")
    ax.set(xlabel=_label(effort), ylabel=_label(error), title=f"{controller}: on the test cases (means, {_PERCENT})")
    ax.grid(alpha=0.3)
    ax.legend(fontsize="small")
    return ax


def _interval_bars(
    ax: Axes, x: np.ndarray, mean: np.ndarray, low: np.ndarray, high: np.ndarray, **style: Any
) -> None:
    ax.errorbar(x, mean, yerr=[mean - low, high - mean], ls="none", capsize=3, **style)


def default_against_tuned(leaderboard: pd.DataFrame, ax: Axes) -> Axes:
    """Each controller's test score (mean and interval), default beside tuned, in the leaderboard's order.

    Parameters
    ----------
    leaderboard : pandas.DataFrame
        `Judgement.leaderboard`.
    ax : matplotlib.axes.Axes
        The axes to draw on.

    Returns
    -------
    matplotlib.axes.Axes
        The axes drawn on.
    """
    x = np.arange(len(leaderboard))
    board = leaderboard
    _interval_bars(
        ax,
        x - 0.12,
        board["default_score"].to_numpy(float),
        board["default_low"].to_numpy(float),
        board["default_high"].to_numpy(float),
        marker="s",
        color="tab:gray",
        label="default",
    )
    _interval_bars(
        ax,
        x + 0.12,
        board["score"].to_numpy(float),
        board["score_low"].to_numpy(float),
        board["score_high"].to_numpy(float),
        marker="*",
        markersize=11,
        color="tab:orange",
        label="tuned",
    )
    ax.set_xticks(x, list(board["controller"]))
    ax.set(ylabel=SCORE_LABEL, title=f"Test score, default against tuned (mean, {_PERCENT} interval)")
    ax.grid(alpha=0.3, axis="y")
    ax.legend(fontsize="small")
    return ax


def train_against_test(gap: pd.DataFrame, order: Sequence[str], ax: Axes, metric: str = SCORE) -> Axes:
    """Each controller's `metric` on the training cases (its trial's runs) and on the test cases, for the tuned
    and the default configuration, joined by a line: a line going up is a setting that holds less well off the
    cases it was tuned on.

    Parameters
    ----------
    gap : pandas.DataFrame
        `Judgement.gap`.
    order : sequence of str
        The controllers, left to right.
    ax : matplotlib.axes.Axes
        The axes to draw on.
    metric : str
        SCORE (the ranking scalar) or one of the objectives.

    Returns
    -------
    matplotlib.axes.Axes
        The axes drawn on.
    """
    rows = gap[gap["metric"] == metric].set_index(["controller", "config"])
    for config, colour, offset, marker in ((DEFAULT, "tab:gray", -0.12, "s"), (TUNED, "tab:orange", 0.12, "*")):
        for k, controller in enumerate(order):
            if (controller, config) not in rows.index:
                continue
            row = rows.loc[(controller, config)]
            ax.plot([k + offset - 0.06, k + offset + 0.06], [row["train"], row["test"]], "-", color=colour, lw=1.2)
            ax.plot(k + offset - 0.06, row["train"], marker="o", color=colour, mfc="white")
            ax.plot(k + offset + 0.06, row["test"], marker=marker, color=colour)
        ax.plot([], [], marker=marker, color=colour, label=f"{config}: training (hollow) to test")
    ax.set_xticks(np.arange(len(order)), list(order))
    ylabel = SCORE_LABEL if metric == SCORE else _label(metric)
    ax.set(ylabel=ylabel, title="Train against test (each averaged per case)")
    ax.grid(alpha=0.3, axis="y")
    ax.legend(fontsize="small")
    return ax


def steering_rate_comparison(
    results: Sequence[plots.PlottedRun],
    labels: Sequence[str],
    ax: Axes,
    styles: Sequence[plots.RunStyle] | None = None,
) -> Axes:
    """The measured steering-wheel rate against time (differenced at the controller rate, as the metrics take
    it), every run on one axis.

    Parameters
    ----------
    results : sequence of PlottedRun
        The runs (a SimulationResult is one).
    labels : sequence of str
        The legend's label of each run.
    ax : matplotlib.axes.Axes
        The axes to draw on.
    styles : sequence of RunStyle or None
        How each run is drawn (None: a colour per label).

    Returns
    -------
    matplotlib.axes.Axes
        The axes drawn on.
    """
    styles = plots.run_styles(labels, [""] * len(labels)) if styles is None else styles
    for result, label, style in zip(results, labels, styles, strict=True):
        t, steer = result.trace["t_s"], result.trace["steer_wheel_rad"]
        rate = np.degrees(np.diff(steer) / np.diff(t))
        ax.plot(t[1:], rate, color=style.colour, ls=style.line_style, lw=1.0, label=label)
    ax.set(xlabel="time (s)", ylabel="steering-wheel rate (deg/s)", title="Steering-wheel rate")
    ax.legend(loc="best", fontsize="small")
    return ax


def _traces_figure(traces: Mapping[str, SimulationResult], labels: Sequence[str]) -> Figure:
    runs = list(traces.values())
    styles = plots.run_styles(list(traces), [r.vehicle for r in runs])
    angle, rate, cte = _new_axes(TRACES_FIGURE_IN, rows=3)
    plots.steering_comparison(runs, labels, angle, styles)
    steering_rate_comparison(runs, labels, rate, styles)
    plots.cte_comparison(runs, labels, cte, styles)
    return angle.figure.get_figure(root=True)


def _interval_text(mean: float, low: float, high: float) -> str:
    return f"{number_text(mean)} [{number_text(low)}, {number_text(high)}]"


def _heading(section: str) -> str:
    title = dict(SECTIONS)[section]
    return f'<h2 id="{section}">{html.escape(title)}</h2>'


def _paragraph(text: str) -> str:
    return f"<p>{html.escape(text)}</p>"


def _contents() -> str:
    links = " · ".join(f'<a href="#{key}">{html.escape(title)}</a>' for key, title in SECTIONS)
    return f"<p>{links}</p>"


def _leaderboard_section(summary: TournamentSummary, judgement: Judgement) -> list[str]:
    board = judgement.leaderboard
    rows = []
    for row in board.itertuples():
        rows.append(
            {
                "rank": row.rank,
                "controller": row.controller,
                f"tuned score [{_PERCENT}]": _interval_text(row.score, row.score_low, row.score_high),
                f"default score [{_PERCENT}]": _interval_text(row.default_score, row.default_low, row.default_high),
                "failed runs": f"{row.failed_fraction:.0%}",
                **{_label(m): getattr(row, m) for m in (*TRACKING_METRICS, EFFORT) if m in board.columns},
                "step median (µs)": row.step_time_median_us,
                "step p99 (µs)": row.step_time_p99_us,
                "CPU time, training (s)": row.cpu_time_s,
                "CPU time per trial (s)": row.cpu_time_per_trial_s,
                "not distinguishable from": row.not_distinguishable_from or "–",
            }
        )
    pairs = [
        {
            "a": p.controller_a,
            "b": p.controller_b,
            "common test cases": p.cases,
            f"mean of a - b [{_PERCENT}]": _interval_text(p.difference, p.low, p.high),
            "distinguishable": "yes" if p.distinguishable else "no",
        }
        for p in judgement.pairwise.itertuples()
    ]
    text = (
        f"The controllers' tuned configurations by their mean ranking score on the {len(summary.test_cases)} test "
        f"cases ({summary.ranking_rule}), best first. The metrics are "
        "the tuned configuration's means over its test runs that did not fail; step times are measured in the same "
        "runs (the median of the runs' medians and of their 99th percentiles); CPU time is the training trials'."
    )
    parts = [_heading("leaderboard"), _paragraph(text), text_table(pd.DataFrame(rows))]
    if pairs:
        parts += [
            _paragraph(
                f"Paired comparisons: the mean difference of the ranking score over the test cases both ran, with its "
                f"{_PERCENT} bootstrap interval; two controllers are distinguishable when the interval excludes 0 "
                f"and they ran at least {MIN_PAIRED_CASES} test cases in common."
            ),
            text_table(pd.DataFrame(pairs)),
        ]
    return parts


def _fronts_section(history: pd.DataFrame, judgement: Judgement) -> list[str]:
    effort, error = front_metrics(judgement.objectives, judgement.ranking)
    parts = [
        _heading("fronts"),
        _paragraph(
            f"Left: every trial of the controller on the training cases ({_label(error)} against "
            f"{_label(effort)}, each the mean over the training cases), the points of its front (over the objectives "
            f"{', '.join(judgement.objectives)}), its default (trial 0), the chosen trial and the front points carried "
            "to the test set (F1.., by rank). Right: the same configurations judged on the test cases (means, "
            f"{_PERCENT} intervals as bars)."
        ),
    ]
    chosen = []
    for controller in judgement.leaderboard["controller"]:
        left, right = _new_axes(WIDE_FIGURE_IN, panels=2)
        training_front(history, controller, left, error, effort)
        judged_points(judgement.scores, controller, right, error, effort)
        parts.append(png_figure(figure_png(left.figure), f"{controller}: front on training, points on test"))
        row = history[(history["controller"] == controller) & history["chosen"].astype(bool)]
        if not row.empty:
            options = json.loads(row["params_json"].iloc[0])
            shown = ", ".join(f"{k} = {shown_value(v)}" for k, v in options.items())
            chosen.append({"controller": controller, "chosen trial": int(row["trial"].iloc[0]), "options": shown})
    if chosen:
        parts += [_paragraph("The chosen (tuned) configurations:"), text_table(pd.DataFrame(chosen))]
    return parts


def _default_section(judgement: Judgement) -> list[str]:
    board = judgement.leaderboard
    axes = _new_axes()[0]
    default_against_tuned(board, axes)
    rows = [
        {
            "controller": row.controller,
            f"default [{_PERCENT}]": _interval_text(row.default_score, row.default_low, row.default_high),
            f"tuned [{_PERCENT}]": _interval_text(row.score, row.score_low, row.score_high),
            "tuned - default": row.score - row.default_score,
        }
        for row in board.itertuples()
    ]
    return [
        _heading("default-vs-tuned"),
        _paragraph(
            "Each controller's shipped defaults against its tuned configuration on the test cases: the mean ranking "
            f"score with its {_PERCENT} interval. Tuning never makes the training objective worse (the defaults are "
            "trial 0); whether it helps on cases it never saw is what this shows."
        ),
        png_figure(figure_png(axes.figure), "Default against tuned on the test cases"),
        text_table(pd.DataFrame(rows)),
    ]


def _gap_section(judgement: Judgement) -> list[str]:
    order = list(judgement.leaderboard["controller"])
    axes = _new_axes()[0]
    train_against_test(judgement.gap, order, axes)
    gap = judgement.gap[judgement.gap["config"].isin((TUNED, DEFAULT))]
    rows = [
        {
            "controller": row.controller,
            "config": row.config,
            "trial": row.trial,
            "metric": SCORE_LABEL if row.metric == SCORE else _label(row.metric),
            "training": row.train,
            "test": row.test,
            "gap (test - training)": row.gap,
            "cases (training, test)": f"{row.train_cases}, {row.test_cases}",
        }
        for row in gap.itertuples()
    ]
    return [
        _heading("train-vs-test"),
        _paragraph(
            "The same metric on the training cases (the runs of the configuration's trial) and on the test cases, "
            "each averaged per case first. A positive gap is a configuration that does worse off the cases it was "
            "tuned on; tuning that only fits the training cases shows as a tuned gap well above the default's."
        ),
        png_figure(figure_png(axes.figure), "Train against test: the ranking score"),
        text_table(pd.DataFrame(rows)),
    ]


def _scenario_section(judgement: Judgement) -> list[str]:
    tuned = judgement.per_case[judgement.per_case["config"] == TUNED]
    order = list(judgement.leaderboard["controller"])
    table = tuned.pivot_table(index="scenario", columns="controller", values=SCORE, aggfunc="mean", sort=False)
    table = table.reindex(columns=order).reset_index()
    failed = tuned[tuned["failed"] > 0]
    notes = [
        f"{row.controller} failed on {row.case} (score {judgement.failure_score:g})" for row in failed.itertuples()
    ]
    parts = [
        _heading("per-scenario"),
        _paragraph(
            "The tuned configurations' mean ranking score per test scenario (over its speeds, conditions and seeds); "
            f"a failed run counts as {judgement.failure_score:g}."
        ),
        text_table(table),
    ]
    if notes:
        parts.append("<ul>" + "".join(f"<li class='failed'>{html.escape(n)}</li>" for n in notes) + "</ul>")
    return parts


def _traces_section(judgement: Judgement, traces: Mapping[str, SimulationResult]) -> list[str]:
    parts = [_heading("traces")]
    if not traces:
        return [*parts, _paragraph("No traces were given.")]
    first = next(iter(traces.values()))
    trials = judgement.leaderboard.set_index("controller")["trial"]
    labels = [f"{c} (tuned, trial {trials[c]})" if c in trials.index else c for c in traces]
    parts += [
        _paragraph(
            f"Each controller's chosen configuration on the test scenario {first.scenario.name} ({first.vehicle}, "
            f"{first.config.speed_kmh:g} km/h, conditions {first.config.conditions.name}, seed {first.config.seed}): "
            "the measured steering-wheel angle and its rate against time, and the cross-track error along the path."
        ),
        png_figure(figure_png(_traces_figure(traces, labels)), f"Steering and CTE on {first.scenario.name}"),
    ]
    return parts


def _cases_list(cases: Sequence[str]) -> str:
    items = "".join(f"<li>{html.escape(case.replace('|', ' | '))}</li>" for case in cases)
    count = f"{len(cases)} case" + ("" if len(cases) == 1 else "s")
    summary = f"{count} (scenario | vehicle | km/h | conditions | seed)"
    return f"<details><summary>{summary}</summary><ul>{items}</ul></details>"


def _rules_section(summary: TournamentSummary, results: pd.DataFrame, judgement: Judgement) -> list[str]:
    told = "are told" if summary.inform_delays else "are not told"
    judged = results["set"] == TEST_SET
    rules = [
        f"Controllers: {', '.join(summary.controllers)}; vehicles: {', '.join(summary.vehicles)}.",
        f"Budget: every controller gets {summary.trials} trials on the training cases; its shipped defaults are "
        "trial 0. The trials are proposed by a seeded multi-objective sampler over the controller's own search space; "
        "the CPU time each spent is in the leaderboard (an MPC trial costs many times a geometric controller's).",
        f"Objectives of the front (each the mean over the training cases): {', '.join(summary.objectives)}.",
        f"Selection: {summary.selection_rule}.",
        f"Ranking: by the mean over the test cases, lowest first, of {summary.ranking_rule}.",
        f"Failure: a run that did not complete, left the track or limit-cycled has failed; it scores "
        f"{summary.failure_score:g} on the ranking, and a trial with a failed run is never chosen.",
        f"Known delays: the controllers {told} the conditions' nominal latency and dead time (inform_delays = "
        f"{str(summary.inform_delays).lower()}).",
        f"MPC solve budget: {summary.solve_budget}.",
        f"Held out: no trial ever ran a test case. Seed {summary.seed}; the intervals are percentile bootstraps over "
        f"the test cases, {judgement.resamples} resamples, seeded {judgement.seed}.",
        f"Runs: {int((~judged).sum())} training runs and {int(judged.sum())} judged runs, of which "
        f"{int(results.loc[judged, 'failed'].astype(bool).sum())} failed.",
    ]
    return [
        _heading("rules"),
        "<ul>" + "".join(f"<li>{html.escape(rule)}</li>" for rule in rules) + "</ul>",
        _paragraph("Training set:"),
        _cases_list(summary.train_cases),
        _paragraph("Test set:"),
        _cases_list(summary.test_cases),
    ]


READING = (
    "Scores: the ranking score of a run is the stated weighted sum of its metrics; a configuration's score is the "
    "mean over the test cases, lower is better.",
    f"Intervals: [low, high] is a {_PERCENT} bootstrap interval of that mean: the test cases were drawn again with "
    "replacement many times and the interval holds the middle of the means so drawn. It says how much the mean "
    "depends on which cases happened to be in the test set; few cases make it wide.",
    "Not distinguishable: two controllers are compared case by case (the paired difference over the test cases "
    f"both ran); when the {_PERCENT} interval of that mean difference contains 0, the test set cannot tell them apart, "
    "whatever their ranks say; so it is with fewer than "
    f"{MIN_PAIRED_CASES} common cases, too few for any verdict. Pairing removes what the cases share (a hard track is "
    "hard for both), so two controllers whose own intervals overlap can still be distinguishable.",
    "The gap: the same metric on the training cases and on the test cases, each averaged per case first; test minus "
    "training. A large positive gap is tuning that fits the training cases and does not carry over.",
    "Fronts: on the training cases no configuration of the front is beaten on both tracking and steering effort; "
    "the right-hand panels show whether that order holds on the test cases.",
    "Reproducing: results.parquet gives, for every judged run, the workbench run command line that reproduces it "
    "bit for bit; best/<controller>.toml holds each chosen configuration.",
)


def _reading_section() -> list[str]:
    return [_heading("reading"), "<ul>" + "".join(f"<li>{html.escape(t)}</li>" for t in READING) + "</ul>"]


def render_report(
    summary: TournamentSummary,
    results: pd.DataFrame,
    history: pd.DataFrame,
    judgement: Judgement,
    traces: Mapping[str, SimulationResult],
) -> str:
    """The report as one HTML document (sections SECTIONS, in order).

    Parameters
    ----------
    summary : TournamentSummary
        What the tournament was: its title, controllers, cases and rules.
    results : pandas.DataFrame
        The tournament's runs (every judged controller among them).
    history : pandas.DataFrame
        One row per controller and trial: train_ objective means, pareto, chosen, carried.
    judgement : Judgement
        `tournament_judging.judge`'s verdict on the results.
    traces : mapping
        Controller -> its chosen configuration's run on one test scenario (SimulationResult); may be empty.

    Returns
    -------
    str
        One self-contained HTML page (`report.html_page`).
    """
    body = [
        _contents(),
        *_leaderboard_section(summary, judgement),
        *_fronts_section(history, judgement),
        *_default_section(judgement),
        *_gap_section(judgement),
        *_scenario_section(judgement),
        *_traces_section(judgement, traces),
        *_rules_section(summary, results, judgement),
        *_reading_section(),
    ]
    return html_page(summary.title, body, summary.description)


def write_report(
    out_dir: Path,
    summary: TournamentSummary,
    results: pd.DataFrame,
    history: pd.DataFrame,
    judgement: Judgement,
    traces: Mapping[str, SimulationResult],
) -> Path:
    """Write DIR/report.html (REPORT_FILE) and return its path. results: the tournament's runs (every judged
    controller must be in it); history: one row per controller and trial (train_ objective means, pareto, chosen,
    carried); judgement: `tournament_judging.judge`'s of the results; traces: controller -> its chosen
    configuration's run on one test scenario (may be empty).

    Parameters
    ----------
    out_dir : pathlib.Path
        The tournament's folder (made if missing).
    summary : TournamentSummary
        What the tournament was: its title, controllers, cases and rules.
    results : pandas.DataFrame
        The tournament's runs (every judged controller among them).
    history : pandas.DataFrame
        One row per controller and trial: train_ objective means, pareto, chosen, carried.
    judgement : Judgement
        `tournament_judging.judge`'s verdict on the results.
    traces : mapping
        Controller -> its chosen configuration's run on one test scenario (SimulationResult); may be empty.

    Returns
    -------
    pathlib.Path
        out_dir/report.html.

    Raises
    ------
    WorkbenchInputError
        The judgement names a controller the results or the history do not hold, the history lacks a column,
        or a trace is given for a controller not judged.
    """
    judged = set(judgement.leaderboard["controller"])
    unknown = sorted(judged - set(results["controller"]))
    if unknown:
        raise WorkbenchInputError(f"the judgement names controller {unknown[0]!r}, which the results do not hold")
    untrained = sorted(judged - set(history["controller"]))
    if untrained:
        raise WorkbenchInputError(f"the history holds no trial of controller {untrained[0]!r}")
    lacking = [f"train_{m}" for m in judgement.objectives if f"train_{m}" not in history.columns]
    lacking += [c for c in HISTORY_COLUMNS if c not in history.columns]
    if lacking:
        raise WorkbenchInputError(f"the history lacks the column(s) {', '.join(lacking)}")
    extra = sorted(set(traces) - judged)
    if extra:
        raise WorkbenchInputError(f"a trace is given for {extra[0]!r}, which was not judged")
    path = Path(out_dir) / REPORT_FILE
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(render_report(summary, results, history, judgement, traces), encoding="utf-8")
    return path


__all__ = [
    "EFFORT",
    "HISTORY_COLUMNS",
    "READING",
    "REPORT_FILE",
    "SECTIONS",
    "default_against_tuned",
    "front_metrics",
    "judged_points",
    "render_report",
    "steering_rate_comparison",
    "train_against_test",
    "training_front",
    "write_report",
]
