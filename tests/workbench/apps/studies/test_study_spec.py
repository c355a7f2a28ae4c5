"""Study specs: the runs they plan (products, random draws, stable ids), the shipped examples, and clear errors."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
from study_helpers import write_spec

from controllers.clothoid.filter_schedule import DEFAULT_FILTER
from tuning.filter_file import write_filter_file
from workbench.apps.studies import load_spec
from workbench.apps.studies.distributions import Distribution, key_rng
from workbench.base.errors import WorkbenchInputError

EXAMPLES = Path(__file__).resolve().parents[4] / "examples"


def test_the_example_sweep_is_the_200_run_benchmark() -> None:
    spec = load_spec(EXAMPLES / "sweep_dlc.toml")
    runs = spec.plan()
    assert len(runs) == 200 and len({r.run_id for r in runs}) == 200
    assert {r.controller for r in runs} == {"clothoid"} and {r.vehicle for r in runs} == {"tractor-semitrailer"}
    speeds = sorted({dict(r.values)["speed_kmh"] for r in runs})
    assert speeds == [20.0, 25.0, 30.0, 35.0, 40.0]
    assert len({dict(r.options)["frechet_threshold_m"] for r in runs}) == 8
    assert [r.index for r in runs] == list(range(200))


def test_the_example_optimisation() -> None:
    spec = load_spec(EXAMPLES / "optimise_clothoid.toml", "optimise")
    assert spec.optimise is not None and spec.optimise.trials == 40 and spec.optimise.batch_size == 4
    assert dict(spec.optimise.objective) == {"rms_cte_m": 1.0, "rms_steer_rate_deg_s": 0.001}
    assert set(spec.optimise.search) == {
        "frechet_threshold_m",
        "min_preview_time_s",
        "prediction_time_s",
        "lead_filter_pole_scale",
    }
    runs = spec.plan({"frechet_threshold_m": 0.1, "lead_filter_pole_scale": 1.2})
    assert len(runs) == 6  # dlc and fig17 at three speeds
    assert all(dict(r.options) == {"frechet_threshold_m": 0.1, "lead_filter_pole_scale": 1.2} for r in runs)


def test_controller_axes_multiply_only_their_controller(tiny_spec: Path) -> None:
    runs = load_spec(tiny_spec).plan()
    assert [(r.controller, dict(r.values)["speed_kmh"], dict(r.options)) for r in runs] == [
        ("pure-pursuit", 20.0, {}),
        ("pure-pursuit", 30.0, {}),
        ("clothoid", 20.0, {"min_lookahead_m": 5.0, "max_lookahead_m": 20.0}),
        ("clothoid", 20.0, {"min_lookahead_m": 5.0, "max_lookahead_m": 31.0}),
        ("clothoid", 20.0, {"min_lookahead_m": 30.0, "max_lookahead_m": 20.0}),
        ("clothoid", 20.0, {"min_lookahead_m": 30.0, "max_lookahead_m": 31.0}),
        ("clothoid", 30.0, {"min_lookahead_m": 5.0, "max_lookahead_m": 20.0}),
        ("clothoid", 30.0, {"min_lookahead_m": 5.0, "max_lookahead_m": 31.0}),
        ("clothoid", 30.0, {"min_lookahead_m": 30.0, "max_lookahead_m": 20.0}),
        ("clothoid", 30.0, {"min_lookahead_m": 30.0, "max_lookahead_m": 31.0}),
    ]
    assert all(dict(r.values)["initial_offset_m"] == 0.3 for r in runs)
    row = runs[2].parameters()
    assert row["clothoid.min_lookahead_m"] == 5.0 and row["speed_kmh"] == 20.0 and row["sample"] is None


def test_run_ids_are_stable_and_canonical(tmp_path: Path) -> None:
    base = '[study]\nscenarios = ["dlc"]\ncontrollers = ["pure-pursuit"]\nvehicles = ["kinematic-bicycle"]\n'
    a = load_spec(write_spec(tmp_path / "a", base + "[grid]\nspeed_kmh = [30, 40]\nlaps = 1\n")).plan()
    # the same values written otherwise (float for int-valued speed, keys reordered) give the same ids
    b = load_spec(write_spec(tmp_path / "b", base + "[grid]\nlaps = 1\nspeed_kmh = [30.0, 40.0]\n")).plan()
    assert [r.run_id for r in a] == [r.run_id for r in b]
    c = load_spec(write_spec(tmp_path / "c", base + "[grid]\nspeed_kmh = [30, 40.5]\nlaps = 1\n")).plan()
    assert c[0].run_id == a[0].run_id and c[1].run_id != a[1].run_id


def test_a_file_the_runs_read_is_in_their_ids(tmp_path: Path) -> None:
    options = tmp_path / "options.toml"
    options.write_text("[pure-pursuit]\nlookahead_gain_s = 0.8\n")
    text = (
        '[study]\nscenarios = ["dlc"]\ncontrollers = ["pure-pursuit"]\nvehicles = ["kinematic-bicycle"]\n'
        'controller_config = "options.toml"\n'
    )
    spec_path = write_spec(tmp_path, text)
    first = load_spec(spec_path).plan()[0]
    assert first.controller_config == options
    assert load_spec(spec_path).plan()[0].run_id == first.run_id
    options.write_text("[pure-pursuit]\nlookahead_gain_s = 1.0\n")  # same name, new content: another run
    assert load_spec(spec_path).plan()[0].run_id != first.run_id


def test_random_draws_are_seeded_and_extendable(tmp_path: Path) -> None:
    def spec(seed: int, samples: int) -> str:
        return (
            '[study]\nscenarios = ["dlc"]\ncontrollers = ["clothoid"]\nvehicles = ["tractor-semitrailer"]\n'
            f"seed = {seed}\nsamples = {samples}\n[grid]\nspeed_kmh = [20, 30]\n"
            "[random]\npayload_kg = {uniform = [0, 17000]}\ninitial_heading_error_deg = {normal = [0, 2]}\n"
            '[random.clothoid]\nlookahead_mode = {choice = ["adaptive", "fixed"]}\n'
        )

    runs = load_spec(write_spec(tmp_path / "a", spec(3, 4))).plan()
    assert len(runs) == 8 and [r.sample for r in runs] == [0, 1, 2, 3] * 2
    payloads = [dict(r.values)["payload_kg"] for r in runs]
    expected = Distribution("uniform", (0, 17000)).draw(key_rng(3, "payload_kg"), 4)
    assert payloads == expected * 2  # draw i is shared by every grid point
    assert {dict(r.options)["lookahead_mode"] for r in runs} <= {"adaptive", "fixed"}
    again = load_spec(write_spec(tmp_path / "b", spec(3, 4))).plan()
    assert [r.run_id for r in again] == [r.run_id for r in runs]
    more = load_spec(write_spec(tmp_path / "c", spec(3, 6))).plan()
    assert {r.run_id for r in runs} < {r.run_id for r in more}  # more samples keep the first ones
    other = load_spec(write_spec(tmp_path / "d", spec(4, 4))).plan()
    assert [dict(r.values)["payload_kg"] for r in other] != payloads


HEAD = '[study]\nscenarios = ["dlc"]\ncontrollers = ["clothoid", "pure-pursuit"]\nvehicles = ["kinematic-bicycle"]\n'


@pytest.mark.parametrize(
    ("text", "messages"),
    [
        (HEAD + "[grids]\n", ["unknown table(s) grids", "allowed: study, grid, random"]),
        (HEAD.replace("vehicles", "vehicle"), ["unknown key(s) study.vehicle", "allowed: scenarios"]),
        ('[study]\nscenarios = ["dlc"]\ncontrollers = ["clothoid"]\n', ["[study] needs vehicles"]),
        (HEAD.replace('"dlc"', '"dlcc"'), ["study.scenarios: unknown name 'dlcc'", "figure8, dlc, fig17"]),
        (HEAD.replace('"dlc"', '"track.csv"'), ["study.scenarios: file 'track.csv' does not exist"]),
        (HEAD.replace('"kinematic-bicycle"', '"truck"'), ["unknown name 'truck'", "tractor-semitrailer"]),
        (HEAD.replace('"pure-pursuit"', '"mpc"'), ["unknown controller 'mpc'", "clothoid, pure-pursuit"]),
        (HEAD.replace('["dlc"]', "[]"), ["study.scenarios is empty"]),
        (HEAD + "[grid]\nspeed_kmh = []\n", ["grid.speed_kmh is empty"]),
        (HEAD + "[grid]\nspeed_kmh = [30, nan]\n", ["grid.speed_kmh[1] must be a finite number; got nan"]),
        (HEAD + '[grid]\nspeed_kmh = ["fast"]\n', ["grid.speed_kmh[0] must be a number; got 'fast'"]),
        (HEAD + "[grid]\nlaps = 1.5\n", ["grid.laps[0] must be a whole number; got 1.5"]),
        (HEAD + "[grid]\nspeed_kmh = [30, 30.0]\n", ["grid.speed_kmh lists a value twice"]),
        (HEAD + "[grid]\nspeed = 30\n", ["unknown parameter grid.speed", "speed_kmh", "initial_offset_m"]),
        (HEAD + '[grid.clothoid]\nfrechet_threshold_m = "0.1"\n', ["grid.clothoid.frechet_threshold_m[0]"]),
        (HEAD + "[grid.clothoid]\nthreshold = 0.1\n", ["unknown parameter grid.clothoid.threshold", "frechet"]),
        (HEAD + "[grid.nmpc]\nhorizon_steps = 20\n", ["[grid.nmpc]", "study.controllers does not run"]),
        (HEAD + "[grid.pure-pursuit]\nlead_filter_pole_scale = 1.2\n", ["lead_filter_pole_scale", "allowed"]),
        (HEAD + "[grid]\npayload_kg = 1000\n", ["kinematic-bicycle have no payload", "tractor-semitrailer"]),
        (HEAD + "[random]\nspeed_kmh = {uniform = [20, 40]}\n", ["give study.samples"]),
        (HEAD.replace("]\n", "]\nsamples = 3\n", 1), ["study.samples = 3 but [random] draws nothing"]),
        (
            HEAD.replace("]\n", "]\nsamples = 3\n", 1)
            + "[grid]\nspeed_kmh = 30\n[random]\nspeed_kmh = {uniform = [20, 40]}\n",
            ["speed_kmh is both in [grid] and in [random]"],
        ),
        (
            HEAD.replace("]\n", "]\nsamples = 3\n", 1) + "[random]\nlaps = {uniform = [1, 3]}\n",
            ["random.laps: uniform draws numbers, but the parameter is a whole number", "integers"],
        ),
        (HEAD + "[optimise]\ntrials = 3\n", ["unknown table(s) optimise", "workbench optimise"]),
    ],
)
def test_bad_sweep_specs_name_the_key_and_what_is_allowed(tmp_path: Path, text: str, messages: list[str]) -> None:
    path = write_spec(tmp_path, text)
    with pytest.raises(WorkbenchInputError) as info:
        load_spec(path)
    for message in messages:
        assert message in str(info.value)
    assert str(path) in str(info.value)


TRUCK = HEAD.replace('"kinematic-bicycle"', '"tractor-semitrailer"').replace('"clothoid", ', "")
SAMPLED = HEAD.replace("]\n", "]\nsamples = 3\n", 1)


@pytest.mark.parametrize(
    ("text", "messages"),
    [
        (
            HEAD + "[grid]\nspeed_kmh = [30, 0]\n",
            ["grid.speed_kmh = 0.0: speed_kmh must be a finite number in [0.001, 400] km/h"],
        ),
        (HEAD + "[grid]\nlaps = [0]\n", ["grid.laps = 0: laps must be a whole number >= 1; got 0"]),
        (HEAD + "[grid]\ncontroller_rate_hz = [-5]\n", ["grid.controller_rate_hz = -5.0", "[1, 10000] Hz"]),
        (HEAD + "[grid]\nactuation_dead_time_s = [-0.1]\n", ["grid.actuation_dead_time_s = -0.1: "]),
        (HEAD + "[grid]\ninitial_offset_m = [0, 1000]\n", ["grid.initial_offset_m = 1000.0", "[-50, 50] m"]),
        (HEAD + "[grid]\ninitial_offset_m = -40\n", ["grid.initial_offset_m = -40.0", "< max_abs_cte_m"]),
        (HEAD + "[grid]\ninitial_heading_error_deg = 120\n", ["grid.initial_heading_error_deg = 120.0"]),
        (TRUCK + "[grid]\npayload_kg = [-100]\n", ["grid.payload_kg = -100.0: ", "payload"]),
        (TRUCK + "[grid]\ncontroller_payload_kg = [1e9]\n", ["grid.controller_payload_kg = 1000000000.0: "]),
        (HEAD + "[grid.pure-pursuit]\nlookahead_gain_s = [0.5, -1]\n", ["grid.pure-pursuit.lookahead_gain_s = -1.0"]),
        (HEAD + "[grid.clothoid]\nmax_lookahead_m = [3]\n", ["grid.clothoid.max_lookahead_m = 3.0: max_lookahead"]),
        (HEAD + "[grid.clothoid]\nlead_filter_pole_scale = [0]\n", ["lead_filter_pole_scale = 0.0: "]),
        (
            SAMPLED + "[random]\nspeed_kmh = {uniform = [-20, -10]}\n",
            ["random.speed_kmh (sample 0) = -1", "speed_kmh must be a finite number in [0.001, 400] km/h"],
        ),
        (
            SAMPLED + "[random.clothoid]\nmin_lookahead_m = {uniform = [25, 30]}\n",
            ["random.clothoid.min_lookahead_m (sample 0) = 2", "max_lookahead_m must be >= min_lookahead_m"],
        ),
        # refused in every run planned with it, though not on its own: named with the values it meets
        (
            HEAD + "[grid]\nmax_abs_cte_m = 0.5\ninitial_offset_m = [0.3, 0.7]\n",
            ["grid.initial_offset_m = 0.7: with max_abs_cte_m = 0.5: initial_offset_m = 0.7 m starts the run"],
        ),
        (
            HEAD + "[grid.clothoid]\nmin_lookahead_m = 15\nmax_lookahead_m = [10, 12]\n",
            ["grid.clothoid.min_lookahead_m = 15.0: with max_lookahead_m = 12.0: "],
        ),
        # fig17 starts 1.0 m off its path: max_abs_cte_m = 0.5 stops each of its runs at once
        (HEAD.replace('"dlc"', '"fig17"') + "[grid]\nmax_abs_cte_m = [0.5]\n", ["grid.max_abs_cte_m = 0.5: "]),
    ],
)
def test_a_value_every_run_would_refuse_is_refused_when_the_spec_loads(
    tmp_path: Path, text: str, messages: list[str]
) -> None:
    """Built at load time into the objects a run builds: the key, the value and what is allowed are named."""
    path = write_spec(tmp_path, text)
    with pytest.raises(WorkbenchInputError) as info:
        load_spec(path)
    for message in messages:
        assert message in str(info.value)
    assert str(path) in str(info.value) and "every run with it would fail" in str(info.value)


@pytest.mark.parametrize(
    "extra",
    [
        "[grid]\nmax_abs_cte_m = [0.5, 1.0]\ninitial_offset_m = [0.3, 0.7]\n",  # 0.7 completes with 1.0
        "[grid.clothoid]\nmin_lookahead_m = [5, 30]\nmax_lookahead_m = [20, 31]\n",  # 30 needs max 31
        "[grid]\ninitial_offset_m = [-49, 49]\nmax_abs_cte_m = 60\n",  # within +-50 m and max_abs_cte_m
    ],
)
def test_a_value_refused_only_in_some_combinations_is_those_runs_error(tmp_path: Path, extra: str) -> None:
    spec = load_spec(write_spec(tmp_path, HEAD + extra))
    assert spec.run_count() == len(spec.plan()) > 0


OPT = (
    '[study]\nscenarios = ["dlc"]\ncontrollers = ["clothoid"]\nvehicles = ["kinematic-bicycle"]\n'
    "[optimise]\ntrials = 4\n[optimise.objective]\nrms_cte_m = 1.0\n"
    "[optimise.search]\nfrechet_threshold_m = {log_uniform = [0.01, 0.5]}\n"
)


@pytest.mark.parametrize(
    ("text", "messages"),
    [
        (OPT.replace('["clothoid"]', '["clothoid", "stanley"]'), ["tunes one controller"]),
        (OPT.replace("trials = 4", "trials = 0"), ["optimise.trials must be a whole number >= 1; got 0"]),
        (OPT.replace("trials = 4", "trails = 4"), ["unknown key(s) optimise.trails", "allowed: trials"]),
        (OPT.replace("rms_cte_m = 1.0", "rms_cte = 1.0"), ["unknown metric optimise.objective.rms_cte", "rms_cte_m"]),
        (OPT.replace("rms_cte_m = 1.0", "step_time_median_us = 1.0"), ["step times are not"]),
        (OPT.replace("rms_cte_m = 1.0", "limit_cycle_hz = 1.0"), ["null for a run without a limit cycle"]),
        (OPT.replace("rms_cte_m = 1.0", "rms_cte_m = 0.0"), ["a weight other than 0"]),
        (OPT.replace("log_uniform = [0.01, 0.5]", "normal = [0.1, 0.01]"), ["bounded distribution"]),
        (OPT.replace("frechet_threshold_m =", "frechet_m ="), ["unknown parameter optimise.search.frechet_m"]),
        (OPT + "[grid.clothoid]\nfrechet_threshold_m = 0.1\n", ["both fixed in [grid.clothoid] and in [optimise"]),
        (OPT + "[grid.clothoid]\nmin_lookahead_m = [4, 5]\n", ["grid.clothoid.min_lookahead_m lists 2 values"]),
        (OPT.replace("[optimise]\ntrials = 4\n", "[optimise]\n"), ["[optimise] needs trials"]),
    ],
)
def test_bad_optimise_specs(tmp_path: Path, text: str, messages: list[str]) -> None:
    with pytest.raises(WorkbenchInputError) as info:
        load_spec(write_spec(tmp_path, text), "optimise")
    for message in messages:
        assert message in str(info.value)


def test_an_optimise_spec_needs_its_table(tiny_spec: Path) -> None:
    with pytest.raises(WorkbenchInputError, match=r"needs an \[optimise\] table"):
        load_spec(tiny_spec, "optimise")


def test_zandvoort_needs_its_track(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("WORKBENCH_ZANDVOORT_CSV", raising=False)
    monkeypatch.chdir(tmp_path)  # no tracks/ here, and none beside the checkout: the file is not found
    monkeypatch.setattr("workbench.simulation.scenarios.CHECKOUT_ROOT", None)
    path = write_spec(tmp_path, HEAD.replace('"dlc"', '"zandvoort"'))
    with pytest.raises(WorkbenchInputError, match="needs the TUMFTM racetrack-database file"):
        load_spec(path)
    track = tmp_path / "Zandvoort.csv"
    angles = [2 * math.pi * i / 200 for i in range(200)]  # a 100 m circle in the track file's format
    track.write_text("# x_m,y_m\n" + "".join(f"{100 * math.cos(a)},{100 * math.sin(a)}\n" for a in angles))
    monkeypatch.setenv("WORKBENCH_ZANDVOORT_CSV", str(track))
    run = load_spec(path).plan()[0]
    assert run.track_file == track.resolve()


def test_paths_in_a_spec_are_relative_to_it(tmp_path: Path) -> None:
    (tmp_path / "sub").mkdir()
    write_filter_file(tmp_path / "sub" / "lead.json", DEFAULT_FILTER, source="test")
    text = HEAD + '[grid.clothoid]\nfilter_file = "lead.json"\nmax_lookahead_growth_m_per_m = "none"\n'
    runs = load_spec(write_spec(tmp_path / "sub", text)).plan()
    options = dict(runs[0].options)
    assert options["filter_file"] == (tmp_path / "sub" / "lead.json").resolve()
    assert options["max_lookahead_growth_m_per_m"] is None
    assert math.isclose(dict(runs[0].values).get("speed_kmh", 30.0), 30.0)


# --- every file the spec names is read when it loads; the study's size is bounded -------------------------------

ONE = '[study]\nscenarios = ["dlc"]\ncontrollers = ["clothoid"]\nvehicles = ["kinematic-bicycle"]\n'


@pytest.mark.parametrize(
    ("options", "messages"),
    [
        ("[clothoid]\nfrechet_treshold_m = 0.1\n", ["unknown option 'frechet_treshold_m' for ClothoidConfig"]),
        ("[clothoid]\nfrechet_threshold_m = nan\n", ["'frechet_threshold_m' must be a finite number", "got nan"]),
        (
            "[clothoid]\nfilter_file = 'none.json'\n",
            ["controller config file", "[clothoid]: lead filter file", "none.json: no such file"],
        ),
        ("[clothoid\n", ["not valid TOML"]),
        ("[clothoid]\nx = " + "[" * 5000 + "]" * 5000 + "\n", ["nested deeper than 64 levels"]),
    ],
)
def test_the_controller_config_is_checked_when_the_spec_loads(
    tmp_path: Path, options: str, messages: list[str]
) -> None:
    (tmp_path / "options.toml").write_text(options)
    path = write_spec(tmp_path, ONE + 'controller_config = "options.toml"\n')
    with pytest.raises(WorkbenchInputError) as info:
        load_spec(path)
    for message in [str(path), *messages]:
        assert message in str(info.value)


def test_the_files_the_spec_names_are_read_when_it_loads(tmp_path: Path) -> None:
    (tmp_path / "car.toml").write_text('[model]\ntype = "kinematic-bicycle"\n[parameters]\nwheelbase = 2.5\n')
    (tmp_path / "path.csv").write_text("x,y\n0,0\n1,nan\n2,0\n")
    (tmp_path / "deep.json").write_text('{"a": ' * 5000 + "1" + "}" * 5000)
    (tmp_path / "lead.json").write_text('{"format": "lead-filter/1", "psi": 0.8}')
    (tmp_path / "folder.csv").mkdir()
    cases = [
        (ONE.replace('"kinematic-bicycle"', '"car.toml"'), "study.vehicles: ", "car.toml"),
        (ONE.replace('"dlc"', '"path.csv"'), "study.scenarios: ", "path.csv"),
        (ONE.replace('"dlc"', '"folder.csv"'), "a folder, not a file", "folder.csv"),
        (ONE + '[grid.clothoid]\nfilter_file = ["deep.json"]\n', "nested deeper than 64 levels", "deep.json"),
        (
            ONE + '[grid.clothoid]\nfilter_file = ["lead.json"]\n',
            "missing key 'omega_z_rad_s', missing key 'omega_p",
            "lead.json",
        ),
        (ONE.replace('"dlc"', '"zandvoort"') + 'track_file = "path.csv"\n', "study.track_file: ", "path.csv"),
    ]
    for text, message, name in cases:
        with pytest.raises(WorkbenchInputError) as info:
            load_spec(write_spec(tmp_path, text))
        assert message in str(info.value) and name in str(info.value), (text, str(info.value))


def test_a_payload_needs_a_vehicle_that_carries_one_also_from_a_file(tmp_path: Path) -> None:
    from workbench.vehicles import preset_text

    (tmp_path / "car.toml").write_text(preset_text("kinematic-bicycle"))
    text = ONE.replace('"kinematic-bicycle"', '"car.toml"') + "[grid]\npayload_kg = [0, 1000]\n"
    with pytest.raises(WorkbenchInputError, match=r"vehicle\(s\) .*car.toml have no payload"):
        load_spec(write_spec(tmp_path, text))


def test_a_deeply_nested_spec_is_refused(tmp_path: Path) -> None:
    path = write_spec(tmp_path, ONE + "[" + ".".join(["grid"] * 5000) + "]\nx = 1\n")
    with pytest.raises(WorkbenchInputError, match=r"spec file '.*spec\.toml': nested deeper than 64 levels"):
        load_spec(path)


def test_run_count_is_the_plans_length(tiny_spec: Path, tmp_path: Path) -> None:
    drawn = (
        HEAD.replace("]\n", "]\nsamples = 3\n", 1)
        + "[grid]\nspeed_kmh = [20, 30]\n[random]\nseed = {integers = [1, 2]}\n"
        + "[grid.clothoid]\nfrechet_threshold_m = [0.1, 0.2]\n"
    )
    for spec in (load_spec(tiny_spec), load_spec(EXAMPLES / "sweep_dlc.toml"), load_spec(write_spec(tmp_path, drawn))):
        assert spec.run_count() == len(spec.plan())
    assert spec.run_count() == 2 * 3 * 2 + 2 * 3  # clothoid: speeds x samples x thresholds; pure pursuit


@pytest.mark.parametrize(
    ("extra", "runs"),
    [
        ("[grid]\n" + "\n".join(f"{k} = {list(range(1, 101))}" for k in ("speed_kmh", "laps", "controller_rate_hz"))
         + "\n[grid.clothoid]\nmin_lookahead_m = " + str([5 + i / 100 for i in range(100)]) + "\n",
         "100,000,000"),
        ("samples = 100000000\n[random]\nspeed_kmh = {uniform = [10, 50]}\n", "100,000,000"),
    ],
)  # fmt: skip
def test_a_study_too_large_is_refused_before_planning(tmp_path: Path, extra: str, runs: str) -> None:
    path = write_spec(tmp_path, ONE + extra)
    with pytest.raises(WorkbenchInputError) as info:
        load_spec(path)
    message = str(info.value)
    assert f"the study plans {runs} runs" in message and "more than the limit of 100,000" in message
    assert "study.max_runs or --max-runs N" in message


def test_the_limit_can_be_raised(tiny_spec: Path) -> None:
    with pytest.raises(WorkbenchInputError, match=r"plans 10 runs .* more than the limit of 5"):
        load_spec(tiny_spec, max_runs=5)
    assert load_spec(tiny_spec, max_runs=10).run_count() == 10
    text = tiny_spec.read_text().replace("[study]\n", "[study]\nmax_runs = 5\n")
    with pytest.raises(WorkbenchInputError, match="more than the limit of 5"):
        load_spec(write_spec(tiny_spec.parent, text, "limited.toml"))
    assert load_spec(tiny_spec.parent / "limited.toml", max_runs=10).max_runs == 10  # the command line's wins
    with pytest.raises(WorkbenchInputError, match=r"study\.max_runs must be a whole number >= 1; got 0"):
        load_spec(write_spec(tiny_spec.parent, text.replace("max_runs = 5", "max_runs = 0"), "zero.toml"))


def test_an_optimisation_counts_trials_times_runs(tmp_path: Path) -> None:
    text = OPT.replace("trials = 4", "trials = 40000") + "[grid]\nspeed_kmh = [20, 30, 40]\n"
    with pytest.raises(WorkbenchInputError, match=r"plans 120,000 runs \(.* x 40,000 trials"):
        load_spec(write_spec(tmp_path, text), "optimise")
    assert load_spec(write_spec(tmp_path, text), "optimise", max_runs=120_000).total_runs() == 120_000
