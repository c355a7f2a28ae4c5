"""The tournament spec: what it plans (cases, fixed options, search spaces, trial 0) and what it refuses, each
refusal naming the key, the value and what is allowed."""

from __future__ import annotations

from pathlib import Path

import pytest
from study_helpers import SMALL_CIRCUITS, write_spec

from controllers import CONTROLLERS
from controllers.search_space import controller_search_space
from workbench.apps.cli import main
from workbench.apps.studies.tournament_spec import (
    DEFAULT_RANKING,
    DEFAULT_SELECTION,
    MPC_SOLVE_BUDGET_S,
    TOURNAMENT_KEYS,
    case_id,
    load_tournament,
)
from workbench.base.errors import WorkbenchInputError

SPEC = """
[tournament]
controllers = ["pure-pursuit", "stanley"]
vehicles = ["kinematic-bicycle"]
trials = 3

[train]
scenarios = ["dlc"]
speeds_kmh = [20, 30]
seeds = [0, 1]

[test]
scenarios = ["fig17"]
speeds_kmh = [30]
"""


def load(tmp_path: Path, text: str = SPEC, **kw: object):
    return load_tournament(write_spec(tmp_path, text), **kw)


def refused(tmp_path: Path, text: str) -> str:
    with pytest.raises(WorkbenchInputError) as info:
        load(tmp_path, text)
    return str(info.value)


def test_a_spec_plans_each_controller_on_each_set(tmp_path: Path) -> None:
    spec = load(tmp_path)
    assert spec.cases("train") == 4 and spec.cases("test") == 1
    assert (spec.cases_text("train"), spec.cases_text("test")) == ("4 training cases", "1 test case")
    assert dict(spec.selection) == dict(DEFAULT_SELECTION) and dict(spec.ranking) == dict(DEFAULT_RANKING)
    assert spec.total_runs() == 2 * (3 * 4 + 7 * 1)
    train = spec.plan("stanley", "train", {"gain_per_s": 2.0})
    assert [case_id(r.parameters()) for r in train] == [
        f"dlc|kinematic-bicycle|{speed}|ideal|{seed}" for speed in (20, 30) for seed in (0, 1)
    ]
    assert all(dict(r.options) == {"gain_per_s": 2.0} and dict(r.values)["inform_delays"] is True for r in train)
    # the controller's own space is the default search space, its shipped defaults trial 0
    space = {t.name for t in controller_search_space("pure-pursuit")}
    assert set(spec.search["pure-pursuit"]) == space
    config = CONTROLLERS["pure-pursuit"].config_type()
    assert spec.defaults["pure-pursuit"] == {k: getattr(config, k) for k in space}


def test_search_and_fixed_tables_and_the_mpc_solve_budget(tmp_path: Path) -> None:
    text = (
        SPEC.replace('"stanley"]', '"stanley", "lmpc"]')
        + """
[search.stanley]
gain_per_s = {uniform = [1.0, 2.0]}

[fixed.stanley]
softening_mps = 2.0
"""
    )
    spec = load(tmp_path, text)
    assert spec.search["stanley"]["gain_per_s"].values == (1.0, 2.0)  # the table over the controller's own
    assert "softening_mps" not in spec.search["stanley"]  # fixed: not searched
    assert dict(spec.fixed["stanley"]) == {"softening_mps": 2.0}
    assert dict(spec.fixed["lmpc"]) == {"max_solve_time_s": MPC_SOLVE_BUDGET_S}  # never cut short
    assert all(dict(r.options)["max_solve_time_s"] == MPC_SOLVE_BUDGET_S for r in spec.plan("lmpc", "test"))
    assert "lmpc 10 s" in spec.solve_budget_text()


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (("[test]", "[tests]"), "unknown table(s) tests; allowed: tournament, train, test, search, fixed"),
        (
            ("trials = 3", "trials = 3\nbudget = 3"),
            f"unknown key(s) tournament.budget; allowed: {', '.join(TOURNAMENT_KEYS)}",
        ),
        (
            ("seeds = [0, 1]", "seed = [0, 1]"),
            "unknown key(s) train.seed; allowed: scenarios, speeds_kmh, conditions, seeds",
        ),
        (("trials = 3", "trials = 0"), "tournament.trials must be a whole number >= 1; got 0"),
        (
            ("trials = 3", "trials = 3\nfront_points = 6"),
            "tournament.front_points must be a whole number from 0 to 5; got 6",
        ),
        (('"stanley"]', '"stanly"]'), "tournament.controllers: unknown controller 'stanly'; choose one of"),
        (
            ("trials = 3", "trials = 3\nobjectives = ['rms_cte_m', 'cte']"),
            "unknown metric 'cte' in tournament.objectives",
        ),
        (
            ("trials = 3", "trials = 3\nselection = {max_ltr = 1.0}"),
            "unknown metric tournament.selection.max_ltr; allowed: rms_cte_m, max_abs_cte_on_path_m, "
            "rms_steer_rate_deg_s",
        ),
        (
            ("trials = 3", "trials = 3\nranking = {max_abs_cte_m = -1.0}"),
            "tournament.ranking.max_abs_cte_m must be a weight >= 0; got -1",
        ),
        (("trials = 3", "trials = 3\noff_path_m = 0.0"), "tournament.off_path_m must be > 0 m; got 0"),
        (("trials = 3", "trials = 3\noff_path_m = nan"), "tournament.off_path_m"),
        (("speeds_kmh = [30]", "speeds_kmh = [-30]"), "test.speeds_kmh must be > 0 km/h; got -30"),
        (('scenarios = ["fig17"]', 'scenarios = ["nowhere"]'), "test.scenarios: unknown name 'nowhere'"),
        (("trials = 3", "trials = 3\nmax_runs = 10"), "the tournament plans up to 38 runs"),
    ],
)
def test_bad_input_is_refused_naming_it(tmp_path: Path, edit: tuple[str, str], message: str) -> None:
    assert message in refused(tmp_path, SPEC.replace(*edit))


def test_a_case_in_both_sets_is_refused(tmp_path: Path) -> None:
    text = SPEC.replace('scenarios = ["fig17"]', 'scenarios = ["fig17", "dlc"]').replace(
        "speeds_kmh = [30]", "speeds_kmh = [30]\nseeds = [1, 2]"
    )
    message = refused(tmp_path, text)
    assert "case 'dlc|kinematic-bicycle|30|ideal|1' (scenario|vehicle|speed|conditions|seed) is in both" in message
    # another seed of the same scenario and speed is another case
    load(tmp_path, text.replace("seeds = [1, 2]", "seeds = [2]"))


def test_search_tables_are_checked(tmp_path: Path) -> None:
    outside = SPEC + "\n[search.stanley]\ngain_per_s = {uniform = [2.0, 3.0]}\n"
    assert "search.stanley.gain_per_s: uniform [2.0, 3.0] does not contain the shipped default 1.5" in refused(
        tmp_path, outside
    )
    both = SPEC + "\n[search.stanley]\ngain_per_s = {uniform = [1.0, 3.0]}\n[fixed.stanley]\ngain_per_s = 1.0\n"
    assert "gain_per_s is both fixed in [fixed.stanley] and searched in [search.stanley]" in refused(tmp_path, both)
    unknown = SPEC + "\n[search.stanley]\ngain = {uniform = [1.0, 3.0]}\n"
    assert "unknown parameter search.stanley.gain for stanley; allowed:" in refused(tmp_path, unknown)
    unbounded = SPEC + "\n[search.stanley]\ngain_per_s = {normal = [1.5, 0.5]}\n"
    bounded = "a search needs a bounded distribution (uniform, log_uniform, integers, choice); got normal"
    assert f"search.stanley.gain_per_s: {bounded}" in refused(tmp_path, unbounded)
    bad_fixed = SPEC + "\n[fixed.stanley]\ngain_per_s = -1.0\n"
    assert "stanley on the train set: fixed.stanley.gain_per_s = -1.0: gain_per_s must be" in refused(
        tmp_path, bad_fixed
    )
    other = SPEC + "\n[fixed.clothoid]\nprediction_time_s = 0.1\n"
    assert "[fixed.clothoid] names a controller the tournament does not run" in refused(tmp_path, other)


def test_a_controller_without_a_search_space_needs_a_table(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(CONTROLLERS["stanley"], "search_space", ())
    message = refused(tmp_path, SPEC)
    assert "controller 'stanley' declares no search space and the spec gives none: add a [search.stanley]" in message
    spec = load(tmp_path, SPEC + "\n[search.stanley]\ngain_per_s = {log_uniform = [0.5, 5.0]}\n")
    assert list(spec.search["stanley"]) == ["gain_per_s"] and spec.defaults["stanley"] == {"gain_per_s": 1.5}


def test_the_cli_refuses_a_bad_spec_in_one_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    spec = write_spec(tmp_path, SPEC.replace("trials = 3", "trials = 3\nbudget = 1"))
    assert main(["tournament", str(spec), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("workbench: error: spec ") and "unknown key(s) tournament.budget" in err
    assert len(err.strip().splitlines()) == 1




def test_a_set_draws_its_circuits_within_its_ranges_file(tmp_path: Path) -> None:
    write_spec(tmp_path, SMALL_CIRCUITS, "small.toml")
    text = SPEC.replace('scenarios = ["dlc"]', 'scenarios = ["dlc", "circuit:7"]\ncircuit_ranges = "small.toml"')
    spec = load(tmp_path, text.replace('scenarios = ["fig17"]', 'scenarios = ["circuit:7"]'))
    train = spec.plan("stanley", "train")
    ranges = {r.scenario: dict(r.values).get("circuit_ranges") for r in train}
    assert ranges == {"dlc": None, "circuit:7": tmp_path / "small.toml"}  # the set's circuits only
    cases = [case_id(r.parameters()) for r in train]
    assert {"circuit:7 (small.toml)|kinematic-bicycle|20|ideal|0", "dlc|kinematic-bicycle|20|ideal|0"} <= set(cases)
    # the test set's circuit:7 is drawn within the default ranges: another circuit, another case
    (test,) = spec.plan("stanley", "test")
    assert "circuit_ranges" not in dict(test.values) and case_id(test.parameters()).startswith("circuit:7|")
    same = text.replace('scenarios = ["fig17"]', 'scenarios = ["circuit:7"]\ncircuit_ranges = "small.toml"')
    assert "case 'circuit:7 (small.toml)|kinematic-bicycle|30|ideal|0'" in refused(tmp_path, same)


def test_a_spec_names_itself_for_its_own_circuits_table_and_an_unread_table_is_refused(tmp_path: Path) -> None:
    text = SPEC.replace('scenarios = ["fig17"]', 'scenarios = ["circuit:7"]\ncircuit_ranges = "spec.toml"')
    spec = load(tmp_path, text + SMALL_CIRCUITS)
    (run,) = spec.plan("pure-pursuit", "test")
    assert dict(run.values)["circuit_ranges"] == tmp_path / "spec.toml"
    message = refused(tmp_path, SPEC + SMALL_CIRCUITS)
    assert "[circuits] holds circuit ranges, read by the runs whose circuit_ranges names this spec file" in message
    assert "give circuit_ranges = 'spec.toml' in [train] or [test]" in message


@pytest.mark.parametrize(
    ("ranges", "message"),
    [
        ('"none.toml"', "on the test set: test.circuit_ranges: circuit ranges file '"),
        ("3", "test.circuit_ranges must be a text; got 3"),
    ],
)
def test_a_sets_unusable_ranges_are_refused_naming_the_key(tmp_path: Path, ranges: str, message: str) -> None:
    text = SPEC.replace('scenarios = ["fig17"]', f'scenarios = ["circuit:7"]\ncircuit_ranges = {ranges}')
    assert message in refused(tmp_path, text)
    no_circuit = SPEC.replace('scenarios = ["fig17"]', 'scenarios = ["fig17"]\ncircuit_ranges = "spec.toml"')
    assert "test.circuit_ranges gives the ranges of generated circuits" in refused(tmp_path, no_circuit)


def test_one_circuit_named_through_two_files_of_the_same_ranges_is_one_case(tmp_path: Path) -> None:
    from workbench.simulation.circuit_ranges import circuit_ranges_toml

    write_spec(tmp_path, SMALL_CIRCUITS, "small.toml")
    write_spec(tmp_path, "# a copy\n" + SMALL_CIRCUITS, "copy.toml")
    write_spec(tmp_path, circuit_ranges_toml(), "defaults.toml")
    head = '[tournament]\ncontrollers = ["stanley"]\nvehicles = ["kinematic-bicycle"]\ntrials = 2\n'
    circuit = 'scenarios = ["circuit:7"]\nspeeds_kmh = [30]\n'
    for train, test, shown in (
        ('circuit_ranges = "small.toml"\n', 'circuit_ranges = "copy.toml"\n', "circuit:7 (small.toml)"),
        ("", 'circuit_ranges = "defaults.toml"\n', "circuit:7"),
    ):
        text = f"{head}[train]\n{circuit}{train}[test]\n{circuit}{test}"
        assert f"case '{shown}|kinematic-bicycle|30|ideal|0'" in refused(tmp_path, text)
