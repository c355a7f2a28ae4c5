"""`--inform-delays` on run, compare, fig17 and robustness: the controllers told the conditions' nominal delays
(`KnownDelays`, `Controller.informed_config`) only when asked, and the output saying whether they were."""

from __future__ import annotations

import html
import json
from pathlib import Path

import pytest

import controllers
from workbench.apps.cli import _parser, main
from workbench.apps.comparison import Comparison
from workbench.apps.robustness import AXES, RobustnessResult, plan_robustness, told_options
from workbench.simulation.conditions import CONDITIONS
from workbench.simulation.known_delays import KnownDelays
from workbench.simulation.simulator import SimulationConfig

#: automotive: pose latency 10 ms + actuation dead time 100 ms
AUTOMOTIVE_LOOP_DELAY_S = 0.11


@pytest.fixture
def built_configs(monkeypatch: pytest.MonkeyPatch) -> list[object]:
    """The configs controllers are built with (`tuned_controller` looks make_controller up when it builds)."""
    configs: list[object] = []
    make = controllers.make_controller

    def spy(name: str, geometry: object, config: object = None, **kwargs: object) -> object:
        configs.append(config)
        return make(name, geometry, config, **kwargs)

    monkeypatch.setattr(controllers, "make_controller", spy)
    return configs


@pytest.mark.parametrize("told", [True, False])
def test_run_tells_the_clothoid_controller_only_with_the_flag(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], built_configs: list[object], told: bool
) -> None:
    flag = ["--inform-delays"] if told else []
    out = tmp_path / "run"
    args = ["run", "dlc", "--conditions", "automotive", *flag, "--no-plots", "--max-time-s", "3", "--out", str(out)]
    main(args)  # a 3 s run stops by its time-out: its files are written all the same
    (config,) = built_configs
    assert config.known_delay_s == pytest.approx(AUTOMOTIVE_LOOP_DELAY_S if told else 0.0, abs=1e-12)
    assert json.loads((out / "metrics.json").read_text())["inform_delays"] is told
    said = capsys.readouterr().out
    assert ("the controller told their delays" in said) is told
    assert ("not told their delays" in said) is not told


def test_the_flag_is_on_run_compare_fig17_and_robustness_and_off_by_default() -> None:
    parser = _parser()
    common = ["--out", "x", "--inform-delays"]
    commands = [
        ["run", "dlc"],
        ["compare", "dlc", "--controllers", "clothoid", "--vehicle", "kinematic-bicycle"],
        ["fig17"],
        ["robustness", "dlc", "--controllers", "clothoid", "--vehicle", "kinematic-bicycle"],
    ]
    for command in commands:
        assert parser.parse_args([*command, *common]).inform_delays is True
        assert parser.parse_args([*command, "--out", "x"]).inform_delays is False


def test_compare_tells_every_controller_and_its_report_says_so(tmp_path: Path, built_configs: list[object]) -> None:
    out = tmp_path / "cmp"
    args = ["compare", "dlc", "--controllers", "clothoid,stanley", "--vehicle", "kinematic-bicycle"]
    main([*args, "--conditions", "automotive", "--inform-delays", "--max-time-s", "2", "--out", str(out)])
    clothoid, stanley = built_configs
    assert clothoid.known_delay_s == pytest.approx(AUTOMOTIVE_LOOP_DELAY_S, abs=1e-12)
    assert stanley == controllers.CONTROLLERS["stanley"].config_type()
    for name in ("clothoid-kinematic-bicycle", "stanley-kinematic-bicycle"):
        assert json.loads((out / "runs" / name / "metrics.json").read_text())["inform_delays"] is True
    report = (out / "report.html").read_text()
    assert "The controllers were told their nominal delays (pose latency 10 ms" in report


def test_a_comparisons_conditions_text_says_whether_the_controllers_were_told() -> None:
    def text(config: SimulationConfig) -> str:
        return Comparison(None, (), (), config).conditions_text()  # type: ignore[arg-type]

    assert text(SimulationConfig()) == ""
    automotive = CONDITIONS["automotive"]
    assert "were not told their delays" in text(SimulationConfig(conditions=automotive))
    told = text(SimulationConfig(conditions=automotive, inform_delays=True))
    assert told.startswith("Conditions automotive (seed 0): ") and "dead time 100 ms" in told


def test_robustness_tells_every_run_the_base_conditions_delays_not_the_varied_ones() -> None:
    plan = {"scenario": "dlc", "controllers": ["clothoid", "stanley"], "vehicle": "kinematic-bicycle"}
    runs = plan_robustness(**plan, conditions="automotive", axes=AXES[:2], warn=None, inform_delays=True)
    clothoid = [r for r in runs if r.controller == "clothoid"]
    varied = {dict(r.values).get("actuation_dead_time_s") for r in clothoid} - {None}
    assert len(varied) == len(AXES[0].values) - 1  # the dead-time axis was run
    for run in clothoid:  # the base's 10 ms + 100 ms in every run, the 300 ms dead-time run's included; the yaw
        # rate 20 ms late, 10 ms older than the pose
        assert dict(run.options) == {
            "known_delay_s": pytest.approx(AUTOMOTIVE_LOOP_DELAY_S, abs=1e-12),
            "yaw_rate_age_s": pytest.approx(0.01, abs=1e-12),
        }
    assert all(r.options == () for r in runs if r.controller == "stanley")
    untold = plan_robustness(**plan, conditions="automotive", axes=AXES[:2], warn=None)
    assert all(r.options == () for r in untold)
    ids = {told: {c: {r.run_id for r in plan_runs if r.controller == c} for c in ("clothoid", "stanley")}
           for told, plan_runs in ((True, runs), (False, untold))}  # fmt: skip
    assert ids[True]["clothoid"].isdisjoint(ids[False]["clothoid"])
    assert ids[True]["stanley"] == ids[False]["stanley"]  # told nothing: the same runs
    assert told_options("nmpc", KnownDelays()) == {}


def test_the_robustness_report_says_whether_the_controllers_were_told() -> None:
    import pandas as pd

    def intro(told: bool) -> str:
        result = RobustnessResult(pd.DataFrame(), "dlc", "kinematic-bicycle", (), "automotive", 30.0, (), 0.5, told)
        return html.unescape(result.report_html())

    assert "told the base conditions' nominal delays, not the varied ones" in intro(True)
    assert "were not told the conditions' delays" in intro(False)


def test_run_with_a_perfect_prediction_tells_the_sensing_delays_only_and_says_so(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], built_configs: list[object]
) -> None:
    out = tmp_path / "run"
    args = ["run", "dlc", "--conditions", "automotive", "--inform-delays", "--perfect-prediction", "--no-plots"]
    main([*args, "--max-time-s", "3", "--out", str(out)])
    (config,) = built_configs
    assert config.known_delay_s == pytest.approx(AUTOMOTIVE_LOOP_DELAY_S - 0.1, abs=1e-12)  # the pose latency
    assert json.loads((out / "metrics.json").read_text())["perfect_prediction"] is True
    assert "handed the true state one dead time ahead (--perfect-prediction)" in capsys.readouterr().out


def test_a_perfect_prediction_without_a_dead_time_is_refused_naming_it(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code = main(["run", "dlc", "--perfect-prediction", "--no-plots", "--out", str(tmp_path / "run")])
    err = capsys.readouterr().err
    assert code != 0 and "perfect_prediction" in err and "'ideal' have no dead time" in err
    assert "Traceback" not in err
