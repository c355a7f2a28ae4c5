"""Speed benchmarks: controller steps, path projection, plant integration, whole simulations and a whole command.

Prints a table and writes JSON (median, p99, real-time factor). Goals live here, not in timed tests; each entry
names its goal, and `--check` exits non-zero when a goal is missed.

    python benchmarks/run.py [--out benchmarks/results/latest.json] [--track ZANDVOORT.csv] [--cli-runs 3] [--check]
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np
import pandas as pd
from benchmark_report import exit_code, machine, write_results

from controllers import CONTROLLERS
from controllers.base import Controller, Measurement
from tuning.own_tuning import tuned_controller
from workbench.apps.controller_config import build_config
from workbench.base.path import ReferencePath
from workbench.simulation.result import SimulationResult
from workbench.simulation.scenarios import ZANDVOORT_ENV, ScenarioOptions, make_scenario
from workbench.simulation.simulator import Simulation, SimulationConfig
from workbench.vehicles import make_vehicle

DEFAULT_TRACK = Path(__file__).resolve().parents[2] / "shared" / "tracks" / "Zandvoort_track.csv"


@dataclass
class Entry:
    name: str
    median_us: float | None = None
    p99_us: float | None = None
    real_time_factor: float | None = None
    wall_s: float | None = None
    simulated_s: float | None = None
    goal: str | None = None
    goal_met: bool | None = None
    note: str | None = None
    #: A step-time ratio against the clothoid controller's on the same run.
    ratio: float | None = None


def time_calls(fn: Callable[[], object], n: int) -> np.ndarray:
    """Wall time (us) of n calls of fn, after 20 warm-up calls."""
    for _ in range(20):
        fn()
    out = np.empty(n)
    for i in range(n):
        start = time.perf_counter()
        fn()
        out[i] = (time.perf_counter() - start) * 1e6
    return out


def bench_tracker(scenario_name: str, options: ScenarioOptions) -> Entry:
    path = make_scenario(scenario_name, options).path
    s = np.linspace(0, path.length_m, 20_001)[:-1]
    xs, ys = path.position(s)
    xs = xs + 0.5 * np.sin(s / 7.0)
    tracker = path.tracker(0.0)
    points = iter(zip(xs.tolist(), ys.tolist(), strict=True))
    times = time_calls(lambda: tracker.update(*next(points)), 19_000)
    return Entry(f"path tracker update ({scenario_name})", float(np.median(times)), float(np.percentile(times, 99)))


#: Plant step goals (median us of one 50 Hz step, 20 RK4 substeps): the compiled models leave a 200x real-time lap
#: room for the controller; CommonRoad's pure-Python MB is the slow reference and must still run a run in minutes.
PLANT_GOAL_US = {"dynamic-bicycle": 50.0, "tractor-semitrailer": 50.0, "commonroad-mb": 50_000.0}


def bench_plant(vehicle_name: str, calls: int = 5000) -> Entry:
    vehicle = make_vehicle(vehicle_name)
    state = vehicle.initial_state(0.0, 0.0, 0.0, 8.33)
    holder = [state]

    def step() -> None:
        holder[0] = vehicle.advance(holder[0], 0.3, 0.0, 0.02, 20)

    times = time_calls(step, calls)
    median = float(np.median(times))
    goal = PLANT_GOAL_US.get(vehicle_name)
    return Entry(
        f"{vehicle_name}: advance 20 RK4 substeps (one 50 Hz step at 1 kHz)",
        median,
        float(np.percentile(times, 99)),
        goal=None if goal is None else f"step median <= {goal:g} us",
        goal_met=None if goal is None else median <= goal,
    )


@dataclass(frozen=True)
class RunGoals:
    """Goals of one timed run (None: none)."""

    rtf: float | None = None
    cte_m: float | None = None
    step_us: float | None = None
    p99_us: float | None = None


def _simulation(scenario_name: str, controller_name: str, vehicle_name: str, options: ScenarioOptions,
                speed_kmh: float = 30.0, overrides: tuple[str, ...] = ()) -> Simulation:  # fmt: skip
    """The run, built and run once untimed (numba's kernels compiled, caches filled)."""
    vehicle = make_vehicle(vehicle_name)
    scenario = make_scenario(scenario_name, ScenarioOptions(vehicle.geometry.width_m, options.track_file))
    config = build_config(CONTROLLERS[controller_name].config_type, {}, overrides)
    controller = tuned_controller(controller_name, vehicle, config)
    sim = Simulation(scenario, vehicle, controller, SimulationConfig(speed_kmh=speed_kmh))
    sim.run()
    return sim


def _timed_run(sim: Simulation) -> tuple[SimulationResult, float]:
    """(the result, its wall time s)."""
    start = time.perf_counter()
    result = sim.run()
    return result, time.perf_counter() - start


def bench_run(scenario_name: str, controller_name: str, vehicle_name: str, options: ScenarioOptions,
              speed_kmh: float = 30.0, goals: RunGoals = RunGoals(),
              overrides: tuple[str, ...] = ()) -> Entry:  # fmt: skip
    sim = _simulation(scenario_name, controller_name, vehicle_name, options, speed_kmh, overrides)
    return _run_entry(*_timed_run(sim), goals, overrides)


def _run_entry(result: SimulationResult, wall: float, goals: RunGoals = RunGoals(), overrides: tuple[str, ...] = (),
               note: str = "") -> Entry:  # fmt: skip
    simulated = float(result.trace["t_s"][-1])
    rtf = simulated / wall
    m = result.metrics
    label = f" ({', '.join(overrides)})" if overrides else ""
    entry = Entry(
        f"{result.scenario.name}: {result.controller}{label} on {result.vehicle} at {result.config.speed_kmh:g} km/h, "
        "whole run",
        m.step_time_median_us,
        m.step_time_p99_us,
        rtf,
        wall,
        simulated,
        note=f"{result.status.value}; max |CTE| {m.max_abs_cte_m:.3f} m{note}",
    )
    if "ctrl_fallback" in result.trace:  # the MPCs: solves not used, and the solver's own time
        solve_us = np.median(result.trace["ctrl_solve_time_s"]) * 1e6
        entry.note += f"; {int(result.trace['ctrl_fallback'].sum())} fallbacks; solve median {solve_us:.0f} us"
    checks = []
    if goals.rtf is not None:
        checks.append((f"real-time factor >= {goals.rtf:g}", rtf >= goals.rtf))
    if goals.cte_m is not None:
        checks.append((f"max |CTE| <= {goals.cte_m:g} m", m.max_abs_cte_m <= goals.cte_m))
    if goals.step_us is not None:
        checks.append((f"step median <= {goals.step_us:g} us", m.step_time_median_us <= goals.step_us))
    if goals.p99_us is not None:
        checks.append((f"step p99 <= {goals.p99_us:g} us", m.step_time_p99_us <= goals.p99_us))
    if checks:
        entry.goal = "; ".join(text for text, _ in checks)
        entry.goal_met = all(met for _, met in checks)
    return entry


#: The goal on fig17: the NMPC's step median at least this many times the clothoid controller's, on the same
#: runs, on both vehicles.
RATIO_GOAL = 20.0


def bench_compared(scenario_name: str, options: ScenarioOptions, clothoid_goals: RunGoals = RunGoals(),
                   vehicle_name: str = "tractor-semitrailer", ratio_goal: float | None = None,
                   rounds: int = 3) -> list[Entry]:  # fmt: skip
    """The clothoid controller, the NMPC and the LTV-MPC on one scenario, timed in alternation: round k runs each
    once, so that the machine's speed, which drifts over minutes on a shared machine, is alike within a round.
    Each controller's entry is its round of least step median (timeit's convention: the others were slowed by
    something else), each ratio the median over the rounds of that round's ratio."""
    names = ("clothoid", "nmpc", "lmpc")
    sims = {name: _simulation(scenario_name, name, vehicle_name, options) for name in names}
    timed = {name: [] for name in names}
    for _ in range(rounds):
        for name in names:
            timed[name].append(_timed_run(sims[name]))
    entries = []
    for name in names:
        runs = timed[name]
        medians = [result.metrics.step_time_median_us for result, _ in runs]
        best = int(np.argmin(medians))
        spread = f"; least of {rounds} alternated rounds' step medians ({min(medians):.1f}-{max(medians):.1f} us)"
        goals = clothoid_goals if name == "clothoid" else RunGoals()
        entries.append(_run_entry(*runs[best], goals, note=spread))
    clothoid = [result.metrics.step_time_median_us for result, _ in timed["clothoid"]]
    for name in ("nmpc", "lmpc"):
        ratios = [result.metrics.step_time_median_us / c for (result, _), c in zip(timed[name], clothoid, strict=True)]
        ratio = statistics.median(ratios)
        goal = ratio_goal if name == "nmpc" else None
        entries.append(
            Entry(
                f"{scenario_name}: {name} / clothoid step median, {vehicle_name}",
                note=f"ratio {ratio:.1f}, the median of {rounds} rounds' ({', '.join(f'{r:.1f}' for r in ratios)})",
                goal=None if goal is None else f"ratio >= {goal:g}",
                goal_met=None if goal is None else ratio >= goal,
                ratio=ratio,
            )
        )
    return entries


class ZeroSteering(Controller):
    """Steers straight ahead: a run with it times the simulator's own work per step (projection, speed profile and
    control, logging) and the plant's."""

    name = "zero-steering"
    config_type = dict

    def _reset(self, path: ReferencePath, sample_time_s: float) -> None:
        pass

    def _command(self, measurement: Measurement, path: ReferencePath) -> float:
        return 0.0


def bench_simulator_overhead(vehicle_name: str, plant_us: float, goal_us: float | None = None) -> Entry:
    """The simulator's work per controller step without a controller: a whole dlc with zero steering, its wall time
    per step less the controller's (logged) and the plant's own step (`bench_plant`)."""
    vehicle = make_vehicle(vehicle_name)
    scenario = make_scenario("dlc", ScenarioOptions(vehicle.geometry.width_m))
    sim = Simulation(scenario, vehicle, ZeroSteering(vehicle.geometry, {}), SimulationConfig(speed_kmh=30.0))
    sim.run()
    start = time.perf_counter()
    result = sim.run()
    wall = time.perf_counter() - start
    steps = len(result.trace["t_s"])
    per_step = wall / steps * 1e6 - float(np.sum(result.trace["step_time_s"])) / steps * 1e6 - plant_us
    return Entry(
        f"simulator overhead per step, no controller ({vehicle_name}, dlc)",
        per_step,
        wall_s=wall,
        simulated_s=float(result.trace["t_s"][-1]),
        goal=None if goal_us is None else f"overhead <= {goal_us:g} us",
        goal_met=None if goal_us is None else per_step <= goal_us,
        note=f"{steps} steps; wall per step {wall / steps * 1e6:.1f} us less the plant's {plant_us:.1f} us",
    )


#: The goal for the whole command: the loaded truck's Zandvoort lap under pure pursuit, `workbench run` in a
#: fresh process with its plots, at least this many times real time.
CLI_LAP_GOAL_RTF = 150.0


def bench_cli_lap(track: Path, runs: int = 3) -> Entry:
    """The loaded truck's Zandvoort lap under pure pursuit as a person runs it, `workbench run ... --overwrite` with
    its plots: the wall time of the whole process (start-up, simulation, trace, metrics and plots; the median of
    `runs` after one untimed run that leaves numba's caches warm) against the simulated time."""
    name = "zandvoort: pure-pursuit on tractor-semitrailer, `workbench run` end to end with plots"
    workbench = Path(sys.executable).parent / "workbench"  # the console script, run by this interpreter
    with tempfile.TemporaryDirectory(prefix="bench-cli-") as tmp:
        out = Path(tmp) / "lap"
        argv = [
            sys.executable, str(workbench), "run", "zandvoort", "--controller", "pure-pursuit",
            "--vehicle", "tractor-semitrailer", "--track", str(track), "--out", str(out), "--overwrite",
        ]  # fmt: skip
        walls = []
        for k in range(runs + 1):
            start = time.perf_counter()
            done = subprocess.run(argv, capture_output=True, text=True, check=False)
            wall = time.perf_counter() - start
            if done.returncode != 0:
                return Entry(name, note=f"failed (exit {done.returncode}): {done.stderr.strip()[-300:]}")
            if k:  # the first run warms the caches
                walls.append(wall)
        simulated = float(pd.read_parquet(out / "trace.parquet", columns=["t_s"])["t_s"].iloc[-1])
        plots = len(list(out.glob("*.png")))
    wall = statistics.median(walls)
    rtf = simulated / wall
    return Entry(
        name,
        real_time_factor=rtf,
        wall_s=wall,
        simulated_s=simulated,
        goal=f"real-time factor >= {CLI_LAP_GOAL_RTF:g}",
        goal_met=rtf >= CLI_LAP_GOAL_RTF,
        note=f"median of {runs} runs, {min(walls):.2f}-{max(walls):.2f} s wall; {plots} plots",
    )


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path(__file__).parent / "results" / "latest.json")
    parser.add_argument("--track", type=Path, default=None, help="Zandvoort CSV (default: env or ../shared)")
    parser.add_argument("--cli-runs", type=int, default=3, metavar="N", help="timed runs of the command (default 3)")
    parser.add_argument("--check", action="store_true", help="exit 1 if a goal is missed")
    args = parser.parse_args(argv)
    if args.cli_runs < 1:
        parser.error("--cli-runs must be >= 1")
    track = args.track or (Path(os.environ[ZANDVOORT_ENV]) if os.environ.get(ZANDVOORT_ENV) else DEFAULT_TRACK)
    options = ScenarioOptions(track_file=track if track.is_file() else None)
    scenarios = ["dlc", "figure8", "fig17"] + (["zandvoort"] if options.track_file else [])

    entries = [bench_tracker("figure8", options)]
    if options.track_file:
        entries.append(bench_tracker("zandvoort", options))
    plants = {}
    for vehicle in ("kinematic-bicycle", "dynamic-bicycle", "tractor-semitrailer"):
        plants[vehicle] = bench_plant(vehicle)
        entries.append(plants[vehicle])
    # Goal: the simulator's own work <= 20 us a step.
    entries.append(bench_simulator_overhead("tractor-semitrailer", plants["tractor-semitrailer"].median_us, 20.0))
    entries.append(bench_plant("commonroad-mb", calls=200))
    for name in scenarios:
        entries.append(bench_run(name, "pure-pursuit", "kinematic-bicycle", options))
    for name in scenarios:
        # Goal: the loaded truck laps Zandvoort at 30 km/h under pure pursuit >= 500x real time.
        goal = 500.0 if name == "zandvoort" else None
        entries.append(bench_run(name, "pure-pursuit", "tractor-semitrailer", options, goals=RunGoals(rtf=goal)))
    if options.track_file:  # the same lap >= 150x real time as a command, start-up and plots included
        entries.append(bench_cli_lap(options.track_file, args.cli_runs))

    # Goals of the clothoid controller: its step (adaptive search included) median <= 100 us, <= 20 us on the dlc
    # and Zandvoort; the loaded truck at 30 km/h within 0.2 m on figure8 and zandvoort and 0.1 m on the dlc; the
    # lead filter helps on the dlc; on fig17 the NMPC's >= 20 times it on the
    # same runs, on both vehicles (each vehicle's clothoid, NMPC and LTV-MPC runs timed in alternation,
    # `bench_compared`; the other scenarios' ratios are reported).
    for name in scenarios:
        clothoid_goals = RunGoals(
            cte_m={"dlc": 0.1, "figure8": 0.2, "zandvoort": 0.2}.get(name),
            step_us=20.0 if name in ("dlc", "zandvoort") else 100.0,
        )
        ratio_goal = RATIO_GOAL if name == "fig17" else None
        entries += bench_compared(name, options, clothoid_goals, ratio_goal=ratio_goal)
    entries += bench_compared("fig17", options, vehicle_name="dynamic-bicycle", ratio_goal=RATIO_GOAL)
    entries.append(bench_run("dlc", "clothoid", "tractor-semitrailer", options, overrides=("use_lead_filter=false",)))
    entries.append(bench_run("dlc", "clothoid", "kinematic-bicycle", options))

    # The MPCs' goals, at N = 30 steps of 50 ms (the default), timed from Python with all overhead: the NMPC (RTI on
    # OSQP) step median <= 2 ms and p99 <= 10 ms, within 0.1 m on the dlc on the dynamic bicycle car at 30 km/h;
    # the LTV-MPC step median <= 0.5 ms. IPOPT (the converged reference) and the truck are reported without goals.
    car = "dynamic-bicycle"
    nmpc_goals = RunGoals(cte_m=0.1, step_us=2000.0, p99_us=10000.0)
    entries.append(bench_run("dlc", "nmpc", car, options, goals=nmpc_goals))
    entries.append(bench_run("dlc", "nmpc", car, options, overrides=("solver=ipopt",)))
    entries.append(bench_run("dlc", "lmpc", car, options, goals=RunGoals(step_us=500.0)))
    if options.track_file:  # a Zandvoort lap's real-time factor for every controller
        entries.append(bench_run("zandvoort", "stanley", "tractor-semitrailer", options))
    peak_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0  # KiB on Linux

    print(f"{'benchmark':<78} {'median us':>10} {'p99 us':>10} {'RTF':>8}  goal")
    for e in entries:

        def f(v: float | None, spec: str) -> str:
            return format(v, spec) if v is not None else "-"

        goal = "" if e.goal is None else f"{e.goal}: {'met' if e.goal_met else 'MISSED'}"
        note = f" [{e.note}]" if e.note and e.median_us is None else ""
        print(
            f"{e.name:<78} {f(e.median_us, '10.1f')} {f(e.p99_us, '10.1f')} {f(e.real_time_factor, '8.1f')}  "
            f"{goal}{note}"
        )
    print(f"peak memory (max RSS of this process) {peak_mb:.0f} MB")
    document = {
        "machine": machine(),
        "created_unix_s": time.time(),
        "entries": [asdict(e) for e in entries],
        "peak_rss_mb": peak_mb,
    }
    write_results(args.out, document)
    return exit_code(entries, args.check)


if __name__ == "__main__":
    sys.exit(main())
