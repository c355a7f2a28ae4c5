"""Generated circuits (`workbench.simulation.circuits`): closed and curvature-continuous, within their ranges, never
near themselves, the same for the same seed; named circuit:SEED by make_scenario, `workbench run`, `workbench
scenarios` and the study specs; written to a TUMFTM file that reads back as the same path; refused, as any path,
where a vehicle cannot follow them."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from pyclothoids import Clothoid

from workbench.apps.cli import main
from workbench.apps.studies import load_spec
from workbench.base.errors import WorkbenchInputError
from workbench.simulation.circuits import (
    MAX_ATTEMPTS,
    MAX_SEED,
    CircuitRanges,
    circuit_seed,
    draw_circuit,
    generate_circuit,
    write_circuit_file,
)
from workbench.simulation.feasibility import STEERING_LOCK, check_path, path_feasibility_warnings, refuse_infeasible
from workbench.simulation.run_config import SimulationConfig
from workbench.simulation.scenarios import ScenarioOptions, describe_scenarios, make_scenario
from workbench.simulation.simulator import plan_path_speed
from workbench.vehicles import make_vehicle

RANGES = CircuitRanges()
#: The tractor-semitrailer preset's width (m).
TRUCK_WIDTH_M = 2.59
SEEDS = st.integers(min_value=0, max_value=MAX_SEED)
PRESETS = ("kinematic-bicycle", "dynamic-bicycle", "commonroad-mb", "tractor-semitrailer")


def _pieces(seed: int):
    """The chain's pieces with the arc length each starts at."""
    chain = draw_circuit(seed).chain()
    starts = np.concatenate(([0.0], np.cumsum([p.length_m for p in chain.pieces])))
    return chain, list(zip(starts[:-1], chain.pieces, strict=True))


# ---------------------------------------------------------------------------------------------- properties
@settings(max_examples=20, deadline=None)
@given(SEEDS)
def test_a_circuit_closes_on_itself_in_position_heading_and_curvature(seed):
    chain = draw_circuit(seed).chain()
    x, y, heading = chain.end_pose()
    x0, y0, heading0 = chain.start
    assert math.hypot(x - x0, y - y0) < 1e-6  # m
    assert abs(heading - heading0 - round((heading - heading0) / (2 * math.pi)) * 2 * math.pi) < 1e-9  # rad
    assert abs(round((heading - heading0) / (2 * math.pi))) == 1  # once round, either way
    assert chain.end_curvature_1pm == chain.start_curvature_1pm == 0.0  # the seam lies on a straight
    # Every piece starts at the curvature the previous one ends at.
    ends = [p.end_curvature_1pm for p in chain.pieces]
    assert [p.start_curvature_1pm for p in chain.pieces[1:]] == ends[:-1]


@settings(max_examples=20, deadline=None)
@given(SEEDS)
def test_curvature_curvature_rate_straights_and_length_stay_in_their_ranges(seed):
    path = generate_circuit(seed, vehicle_width_m=TRUCK_WIDTH_M).path
    kappa = path.curvature_1pm
    # The sampled path: the tightest curvature and the steepest change of curvature between samples.
    assert np.max(np.abs(kappa)) <= (1 + 1e-9) / RANGES.min_radius_m
    assert np.max(np.abs(np.diff(kappa))) / path.spacing_m <= RANGES.max_curvature_rate_1pm2 * (1 + 1e-6)
    assert RANGES.min_length_m <= path.length_m <= RANGES.max_length_m
    circuit = draw_circuit(seed)
    assert RANGES.min_turns <= len(circuit.turns) <= RANGES.max_turns
    for turn in circuit.turns:  # each turn peaks within the radii
        assert 1 / RANGES.max_radius_m * (1 - 1e-9) <= abs(turn.curvature_1pm) <= (1 + 1e-9) / RANGES.min_radius_m
    _, pieces = _pieces(seed)
    straights = []
    for _, piece in pieces:
        if piece.start_curvature_1pm == piece.end_curvature_1pm == 0.0:
            straights.append(piece.length_m)
        elif piece.start_curvature_1pm != piece.end_curvature_1pm:  # a clothoid
            rate = abs(piece.curvature_rate_1pm2)
            assert RANGES.min_curvature_rate_1pm2 * (1 - 1e-9) <= rate <= RANGES.max_curvature_rate_1pm2 * (1 + 1e-9)
    straights = [straights[0] + straights[-1], *straights[1:-1]]  # the first straight is split at the seam
    assert len(straights) == len(circuit.turns)
    assert min(straights) >= RANGES.min_straight_m and max(straights) <= RANGES.max_straight_m


@settings(max_examples=20, deadline=None)
@given(SEEDS)
def test_a_circuit_never_comes_near_itself(seed):
    """Brute force over 1 m samples: points of the centre line farther apart along it than pi/2 clearance_m (the
    short way round) are at least clearance_m apart (less 0.5 m for the samples), so that the tracks of even the
    widest vehicle (4 m) never overlap."""
    path = generate_circuit(seed).path
    step = round(1.0 / path.spacing_m)
    x, y, s = path.x_m[:-1:step], path.y_m[:-1:step], path.s_m[:-1:step]
    along = np.abs(s[:, None] - s[None, :])
    along = np.minimum(along, path.length_m - along)
    distance = np.hypot(x[:, None] - x[None, :], y[:, None] - y[None, :])
    apart = along > 0.5 * math.pi * RANGES.clearance_m
    assert np.min(distance[apart]) >= RANGES.clearance_m - 0.5
    assert RANGES.clearance_m - 0.5 > 2 * RANGES.side_width_m(4.0)


@settings(max_examples=20, deadline=None)
@given(SEEDS)
def test_the_same_seed_gives_the_same_circuit_bit_for_bit_and_the_next_another(seed):
    first = generate_circuit(seed, vehicle_width_m=1.61).path
    again = generate_circuit(seed, vehicle_width_m=1.61).path
    for name in ("x_m", "y_m", "heading_rad", "curvature_1pm", "width_left_m", "width_right_m"):
        assert np.array_equal(getattr(first, name), getattr(again, name)), name
    other = generate_circuit(seed + 1 if seed < MAX_SEED else seed - 1).path
    assert other.length_m != first.length_m or not np.array_equal(other.curvature_1pm, first.curvature_1pm)


# ---------------------------------------------------------------------------------------------- geometry
def test_a_turns_clothoid_is_the_one_pyclothoids_fits_between_two_of_its_samples():
    """Independently of the chain's own construction: pyclothoids' G1 Hermite solution between the path's first and
    last samples inside the first clothoid (position and heading) has the arc length between them, the clothoid's
    curvature there and its rate, and passes through the samples in between."""
    path = generate_circuit(7).path
    _, pieces = _pieces(7)
    start, piece = next((s, p) for s, p in pieces if p.start_curvature_1pm != p.end_curvature_1pm)
    inside = np.flatnonzero((path.s_m > start) & (path.s_m < start + piece.length_m))
    first, last = inside[0], inside[-1]
    fitted = Clothoid.G1Hermite(
        path.x_m[first], path.y_m[first], path.heading_rad[first],
        path.x_m[last], path.y_m[last], path.heading_rad[last],
    )  # fmt: skip
    assert fitted.length == pytest.approx(path.s_m[last] - path.s_m[first], abs=1e-9)
    expected_kappa = piece.start_curvature_1pm + piece.curvature_rate_1pm2 * (path.s_m[first] - start)
    assert fitted.KappaStart == pytest.approx(expected_kappa, abs=1e-9)
    assert fitted.dk == pytest.approx(piece.curvature_rate_1pm2, rel=1e-7)
    along = path.s_m[inside] - path.s_m[first]
    gaps = np.hypot([fitted.X(v) for v in along] - path.x_m[inside], [fitted.Y(v) for v in along] - path.y_m[inside])
    assert np.max(gaps) < 1e-9  # m


def test_the_track_is_sized_for_the_vehicle_and_its_off_tracking():
    """Each side: half the vehicle's width, the semitrailer's steady off-tracking at the tightest radius (R -
    sqrt(R^2 - l^2) = 4.13 m at 25 m with l = 13.768 m) and the side margin."""
    scenario = generate_circuit(3, vehicle_width_m=TRUCK_WIDTH_M)
    expected = 0.5 * TRUCK_WIDTH_M + (25.0 - math.sqrt(25.0**2 - 13.768**2)) + 1.5
    assert expected == pytest.approx(6.93, abs=0.01)
    assert np.all(scenario.path.width_left_m == expected) and np.all(scenario.path.width_right_m == expected)
    assert generate_circuit(3).path.width_left_m is None  # no vehicle: no track
    with pytest.raises(WorkbenchInputError, match=r"vehicle_width_m must be a finite number in \[0.5, 4\] m; got 5.0"):
        generate_circuit(3, vehicle_width_m=5.0)
    assert scenario.name == "circuit:3" and "seed 3" in scenario.description
    assert scenario.path.closed


# ---------------------------------------------------------------------------------------------- names and ranges
def test_circuit_seed_reads_the_name_and_leaves_other_names_alone():
    assert circuit_seed("circuit:12") == 12
    assert circuit_seed("circuit:0") == 0
    assert circuit_seed(f"circuit:{MAX_SEED}") == MAX_SEED
    assert circuit_seed("figure8") is None
    assert circuit_seed("tracks/circuit.csv") is None


@pytest.mark.parametrize(
    "name", ["circuit:", "circuit:-1", "circuit:abc", "circuit:012", "circuit: 7", "circuit:7.0", f"circuit:{2**63}"]
)
def test_a_circuit_name_without_a_valid_seed_is_refused_naming_it(name):
    with pytest.raises(WorkbenchInputError, match="circuit:SEED, SEED a whole number from 0 to 2\\*\\*63 - 1") as err:
        circuit_seed(name)
    assert repr(name[len("circuit:") :]) in str(err.value)
    with pytest.raises(WorkbenchInputError, match="circuit:SEED"):
        make_scenario(name, ScenarioOptions(vehicle_width_m=1.61))


def test_make_scenario_builds_the_circuit_for_the_vehicle_and_needs_its_width():
    built = make_scenario("circuit:7", ScenarioOptions(vehicle_width_m=TRUCK_WIDTH_M))
    direct = generate_circuit(7, vehicle_width_m=TRUCK_WIDTH_M)
    assert built.name == "circuit:7" and np.array_equal(built.path.x_m, direct.path.x_m)
    with pytest.raises(WorkbenchInputError, match="vehicle_width_m=None"):
        make_scenario("circuit:7")
    with pytest.raises(WorkbenchInputError, match="circuit:SEED"):
        make_scenario("circuit")  # unknown: the message names the circuits too


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        ({"min_radius_m": 70.0}, "min_radius_m must not exceed max_radius_m"),
        ({"max_curvature_rate_1pm2": math.nan}, "max_curvature_rate_1pm2 must be a finite number"),
        ({"min_turns": 2}, "min_turns must be a whole number in \\[3, 24\\]; got 2"),
        ({"max_turns": True}, "max_turns must be a whole number"),
        ({"clearance_m": 12.0}, "clearance_m must exceed the widest track"),
        ({"offtracking_length_m": 24.0, "min_radius_m": 24.0}, "offtracking_length_m must be below min_radius_m"),
        ({"max_curvature_rate_1pm2": 0.0007}, "peaks at a radius of"),
        ({"max_reverse_turn_deg": 10.0}, "min_turn_deg must not exceed max_reverse_turn_deg"),
    ],
)
def test_ranges_out_of_bounds_or_inconsistent_are_refused(changes, message):
    with pytest.raises(WorkbenchInputError, match=message):
        CircuitRanges(**changes)


def test_ranges_no_draw_can_meet_are_refused_after_the_bounded_attempts():
    impossible = CircuitRanges(min_length_m=5000.0, max_length_m=6000.0)
    with pytest.raises(WorkbenchInputError, match=f"circuit:5: none of {MAX_ATTEMPTS} circuits drawn") as err:
        draw_circuit(5, impossible)
    assert "lap length outside its range" in str(err.value) or "straights" in str(err.value)
    with pytest.raises(WorkbenchInputError, match="circuit seed must be a whole number"):
        draw_circuit(-1)


# ---------------------------------------------------------------------------------------------- file
def test_a_written_circuit_reads_back_as_the_same_path(tmp_path):
    """The TUMFTM file's waypoints are the circuit's samples; the path a waypoint file gives (a quintic spline
    through them, resampled) has the same samples to 1e-9 m, heading to 1e-6 rad, curvature to 1e-4 1/m (the
    spline's, across the jumps of the curvature rate) and the same track widths."""
    file = write_circuit_file(tmp_path / "c7.csv", 7, vehicle_width_m=TRUCK_WIDTH_M)
    assert file.read_text().startswith("# x_m,y_m,w_tr_right_m,w_tr_left_m\n")
    generated = make_scenario("circuit:7", ScenarioOptions(TRUCK_WIDTH_M)).path
    read = make_scenario(str(file), ScenarioOptions(TRUCK_WIDTH_M)).path
    assert read.closed and read.x_m.size == generated.x_m.size
    assert np.max(np.hypot(read.x_m - generated.x_m, read.y_m - generated.y_m)) < 1e-9
    assert np.max(np.abs(read.heading_rad - generated.heading_rad)) < 1e-6
    assert np.max(np.abs(read.curvature_1pm - generated.curvature_1pm)) < 1e-4
    assert np.array_equal(read.width_left_m, generated.width_left_m)
    with pytest.raises(WorkbenchInputError, match="give vehicle_width_m"):
        write_circuit_file(tmp_path / "c.csv", 7)


# ---------------------------------------------------------------------------------------------- feasibility
@pytest.fixture(scope="module")
def presets():
    return {name: make_vehicle(name) for name in PRESETS}


@settings(max_examples=8, deadline=None)
@given(SEEDS)
def test_every_preset_follows_a_default_circuit_at_40_kmh_under_the_papers_profile(presets, seed):
    path = plan_path_speed(generate_circuit(seed).path, SimulationConfig(speed_kmh=40.0, max_lateral_accel_g=0.3))
    for name, vehicle in presets.items():
        assert path_feasibility_warnings(path, vehicle) == [], name


def test_a_circuit_tighter_than_a_vehicle_turns_is_refused_by_the_shared_check(presets):
    """Radii of 6-10 m: wider than the car's lock radius (1.43 m), some tighter than the truck's (9.19 m)."""
    tight = CircuitRanges(
        min_radius_m=6.0, max_radius_m=10.0, max_curvature_rate_1pm2=0.03, offtracking_length_m=0.0,
        side_margin_m=0.5, clearance_m=10.0, min_length_m=100.0,
    )  # fmt: skip
    path = plan_path_speed(generate_circuit(4, tight).path, SimulationConfig(speed_kmh=10.0))
    spans = check_path(path, presets["tractor-semitrailer"])
    assert any(span.reason == STEERING_LOCK for span in spans)
    with pytest.raises(WorkbenchInputError, match="circuit:4 curves tighter than the tractor-semitrailer"):
        refuse_infeasible(path_feasibility_warnings(path, presets["tractor-semitrailer"]))
    assert not any(s.reason == STEERING_LOCK for s in check_path(path, presets["kinematic-bicycle"]))


def test_workbench_run_refuses_a_circuit_beyond_the_trucks_rollover_threshold(capsys, tmp_path):
    code = main(
        ["run", "circuit:3", "--vehicle", "tractor-semitrailer", "--speed", "60", "--lat-accel-g", "0.6",
         "--out", str(tmp_path / "out")]
    )  # fmt: skip
    assert code == 2
    err = capsys.readouterr().err
    assert "circuit:3 asks the tractor-semitrailer" in err and "rollover threshold" in err
    assert "--allow-infeasible runs it anyway" in err


# ---------------------------------------------------------------------------------------------- commands
def test_workbench_run_drives_a_circuit_and_reports_its_track_margin(capsys, tmp_path):
    out = tmp_path / "run"
    code = main(["run", "circuit:7", "--controller", "pure-pursuit", "--speed", "40", "--no-plots", "--out", str(out)])
    assert code == 0, capsys.readouterr().err
    metrics = json.loads((out / "metrics.json").read_text())
    assert metrics["scenario"] == "circuit:7" and metrics["status"] == "completed"
    assert metrics["left_track"] is False and metrics["min_track_margin_m"] > 1.0
    assert "least track margin" in capsys.readouterr().out


def test_workbench_scenarios_describes_the_circuit_family(capsys):
    assert main(["scenarios"]) == 0
    line = next(ln for ln in capsys.readouterr().out.splitlines() if ln.startswith("circuit:SEED"))
    assert "300-700 m" in line and "radius 25-60 m" in line
    assert dict(describe_scenarios())["circuit:SEED"] == line.split(None, 1)[1]


def _spec(folder: Path, scenarios: str, grid: str = "speed_kmh = [30.0]", vehicles: str = '["kinematic-bicycle"]'):
    folder.mkdir(parents=True, exist_ok=True)
    spec = folder / "spec.toml"
    spec.write_text(
        f'[study]\nscenarios = {scenarios}\ncontrollers = ["pure-pursuit"]\nvehicles = {vehicles}\n[grid]\n{grid}\n'
    )
    return spec


def test_a_study_spec_plans_runs_on_circuits(tmp_path):
    spec = load_spec(_spec(tmp_path, '["circuit:7", "circuit:8", "fig17"]'))
    runs = spec.plan()
    assert [run.scenario for run in runs] == ["circuit:7", "circuit:8", "fig17"]
    assert len({run.run_id for run in runs}) == 3


def test_a_study_spec_refuses_a_bad_circuit_name_and_an_infeasible_circuit(tmp_path):
    with pytest.raises(WorkbenchInputError, match=r"study\.scenarios: scenario 'circuit:x'"):
        load_spec(_spec(tmp_path / "a", '["circuit:x"]'))
    with pytest.raises(WorkbenchInputError, match=r"study\.scenarios: circuit:3 cannot be followed by tractor-semi"):
        load_spec(
            _spec(tmp_path / "b", '["circuit:3"]', "speed_kmh = [60.0]\nmax_lateral_accel_g = [0.6]",
                  '["tractor-semitrailer"]')
        )  # fmt: skip


def test_robustness_checks_a_circuit_by_its_name_not_as_a_file(tmp_path):
    """`workbench robustness circuit:7` plans the circuit (a name is not a file relative to the spec's folder)."""
    from workbench.apps.robustness import _check_path

    _check_path("circuit:7", "kinematic-bicycle", 30.0, None, tmp_path, False, False, print)  # raises nothing


# ---------------------------------------------------------------------------------------------- given ranges
#: Small tight circuits (a car's; no trailer to make room for): 150-400 m laps of 12-20 m turns.
SMALL_RANGES = CircuitRanges(
    min_radius_m=12.0, max_radius_m=20.0, max_curvature_rate_1pm2=0.02, offtracking_length_m=0.0, clearance_m=14.0,
    min_length_m=150.0, max_length_m=400.0,
)  # fmt: skip
SMALL_RANGES_TOML = """[circuits]
min_radius_m = 12.0
max_radius_m = 20.0
max_curvature_rate_1pm2 = 0.02
offtracking_length_m = 0.0
clearance_m = 14.0
min_length_m = 150.0
max_length_m = 400.0
"""


def test_make_scenario_draws_a_circuit_within_the_ranges_given_and_other_scenarios_refuse_them(tmp_path):
    options = ScenarioOptions(vehicle_width_m=1.8, circuit_ranges=SMALL_RANGES)
    built = make_scenario("circuit:7", options)
    direct = generate_circuit(7, SMALL_RANGES, vehicle_width_m=1.8)
    assert np.array_equal(built.path.x_m, direct.path.x_m) and np.array_equal(built.path.y_m, direct.path.y_m)
    assert built.path.length_m < SMALL_RANGES.max_length_m < generate_circuit(7, vehicle_width_m=1.8).path.length_m
    waypoints = tmp_path / "loop.csv"
    waypoints.write_text("x,y\n0,0\n10,0\n20,5\n")
    for other in ("dlc", "figure8", str(waypoints)):
        with pytest.raises(WorkbenchInputError, match=f"scenario {other!r} is not one: drop the ranges"):
            make_scenario(other, options)
    with pytest.raises(WorkbenchInputError, match="circuit_ranges must be a CircuitRanges or None; got dict"):
        ScenarioOptions(circuit_ranges={"min_radius_m": 12.0})  # type: ignore[arg-type]


def test_workbench_run_and_compare_draw_the_circuit_within_the_ranges_file(capsys, tmp_path):
    ranges = tmp_path / "ranges.toml"
    ranges.write_text(SMALL_RANGES_TOML)
    length = generate_circuit(7, SMALL_RANGES).path.length_m
    run = ["run", "circuit:7", "--controller", "pure-pursuit", "--circuit-ranges", str(ranges), "--no-plots"]
    assert main([*run, "--out", str(tmp_path / "run")]) == 0, capsys.readouterr().err
    metrics = json.loads((tmp_path / "run" / "metrics.json").read_text())
    assert metrics["path_length_m"] == pytest.approx(length, abs=0.5) and metrics["status"] == "completed"
    compare = ["compare", "circuit:7", "--controllers", "pure-pursuit", "--vehicle", "kinematic-bicycle"]
    assert main([*compare, "--circuit-ranges", str(ranges), "--no-plots", "--out", str(tmp_path / "cmp")]) == 0
    (compared,) = (tmp_path / "cmp" / "runs").glob("*/metrics.json")
    assert json.loads(compared.read_text())["path_length_m"] == metrics["path_length_m"]
    capsys.readouterr()
    assert main(["run", "dlc", "--circuit-ranges", str(ranges), "--out", str(tmp_path / "dlc")]) == 2
    assert "scenario 'dlc' is not one: drop the ranges (--circuit-ranges)" in capsys.readouterr().err
    missing = ["run", "circuit:7", "--circuit-ranges", str(tmp_path / "none.toml"), "--out", str(tmp_path / "x")]
    assert main(missing) == 2
    assert "--circuit-ranges" in capsys.readouterr().err and not (tmp_path / "dlc").exists()


def test_robustness_runs_carry_the_ranges_file_and_a_scenario_that_is_not_a_circuit_refuses_it(capsys, tmp_path):
    from workbench.apps.robustness import plan_robustness

    (tmp_path / "ranges.toml").write_text(SMALL_RANGES_TOML)
    runs = plan_robustness(
        "circuit:7", ["pure-pursuit"], "kinematic-bicycle", base_dir=tmp_path, circuit_ranges=Path("ranges.toml")
    )
    assert runs and all(dict(run.values)["circuit_ranges"] == tmp_path / "ranges.toml" for run in runs)
    robustness = ["robustness", "dlc", "--controllers", "pure-pursuit", "--vehicle", "kinematic-bicycle"]
    code = main([*robustness, "--circuit-ranges", str(tmp_path / "ranges.toml"), "--out", str(tmp_path / "rob")])
    assert code == 2 and "scenario 'dlc' is not one" in capsys.readouterr().err
