"""Steering-quality goals of issue 15: the clothoid controller against the NMPC on the same runs, every vehicle.

For each vehicle and scenario at 30 km/h, the clothoid controller and the NMPC (the reference) are run, and the
goals checked: no limit cycle; steer_oscillation_deg at most 1.5 x the NMPC's or 3 deg, whichever is larger; RMS
steering-wheel rate at most 1.5 x the NMPC's; max |CTE| within the tracking goals; on fig17, |CTE| within 0.1 m
after at most 1.5 x the NMPC's distance. Prints a table and writes JSON; `--check` exits 1 when a goal is missed.

    python benchmarks/steering.py [--out benchmarks/results/steering.json] [--track ZANDVOORT.csv]
        [--vehicles a,b] [--scenarios a,b] [--workers 2] [--check]
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import asdict, dataclass
from pathlib import Path

from tuning.own_tuning import tuned_controller
from workbench.apps.comparison import converge_distance_m
from workbench.simulation.scenarios import ZANDVOORT_ENV, ScenarioOptions, make_scenario
from workbench.simulation.simulator import Simulation, SimulationConfig
from workbench.vehicles import make_vehicle

DEFAULT_TRACK = Path(__file__).resolve().parents[2] / "shared" / "tracks" / "Zandvoort_track.csv"
VEHICLES = ("kinematic-bicycle", "dynamic-bicycle", "tractor-semitrailer", "commonroad-mb")
SCENARIOS = ("dlc", "figure8", "fig17", "zandvoort")
#: Issue 15's tracking goals, max |CTE| (m), by (vehicle, scenario).
CTE_GOALS_M = {
    ("tractor-semitrailer", "dlc"): 0.08,
    ("tractor-semitrailer", "figure8"): 0.1,
    ("tractor-semitrailer", "zandvoort"): 0.15,
    ("dynamic-bicycle", "dlc"): 0.06,
    ("dynamic-bicycle", "figure8"): 0.06,
}
OSCILLATION_RATIO, OSCILLATION_FLOOR_DEG, RATE_RATIO, CONVERGE_RATIO = 1.5, 3.0, 1.5, 1.5


@dataclass
class Run:
    vehicle: str
    scenario: str
    controller: str
    status: str
    max_abs_cte_m: float
    steer_oscillation_deg: float
    rms_steer_rate_deg_s: float
    limit_cycle: bool
    limit_cycle_text: str
    converge_distance_m: float
    wall_s: float


def run_one(job: tuple[str, str, str, str | None]) -> Run:
    vehicle_name, scenario_name, controller_name, track = job
    vehicle = make_vehicle(vehicle_name)
    options = ScenarioOptions(vehicle.geometry.width_m, Path(track) if track else None)
    scenario = make_scenario(scenario_name, options)
    controller = tuned_controller(controller_name, vehicle)
    start = time.perf_counter()
    result = Simulation(scenario, vehicle, controller, SimulationConfig(speed_kmh=30.0)).run()
    m, trace = result.metrics, result.trace
    cycle = (
        f"{m.limit_cycle_hz:.2f} Hz, ±{m.limit_cycle_amplitude_deg:.0f}°" if m.limit_cycle else "no"
    )  # the metrics' own words
    return Run(
        vehicle_name, scenario_name, controller_name, result.status.value, m.max_abs_cte_m,
        m.steer_oscillation_deg or math.nan, m.rms_steer_rate_deg_s or math.nan, bool(m.limit_cycle), cycle,
        converge_distance_m(trace["progress_m"], trace["cte_m"]), time.perf_counter() - start,
    )  # fmt: skip


def goals(clothoid: Run, reference: Run) -> list[tuple[str, bool]]:
    """(goal in words, met) for one vehicle and scenario."""
    out = [("no limit cycle", not clothoid.limit_cycle)]
    osc_bound = max(OSCILLATION_RATIO * reference.steer_oscillation_deg, OSCILLATION_FLOOR_DEG)
    out.append((f"oscillation <= {osc_bound:.1f} deg", clothoid.steer_oscillation_deg <= osc_bound))
    rate_bound = RATE_RATIO * reference.rms_steer_rate_deg_s
    out.append((f"RMS rate <= {rate_bound:.0f} deg/s", clothoid.rms_steer_rate_deg_s <= rate_bound))
    cte_goal = CTE_GOALS_M.get((clothoid.vehicle, clothoid.scenario))
    if cte_goal is not None:
        out.append((f"max |CTE| <= {cte_goal:g} m", clothoid.max_abs_cte_m <= cte_goal))
    if clothoid.scenario == "fig17":
        bound = CONVERGE_RATIO * reference.converge_distance_m
        out.append((f"within 0.1 m after <= {bound:.0f} m", clothoid.converge_distance_m <= bound))
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path(__file__).parent / "results" / "steering.json")
    parser.add_argument("--track", type=Path, default=None)
    parser.add_argument("--vehicles", default=",".join(VEHICLES))
    parser.add_argument("--scenarios", default=",".join(SCENARIOS))
    parser.add_argument("--workers", type=int, default=os.cpu_count() or 1)
    parser.add_argument("--check", action="store_true", help="exit 1 if a goal is missed")
    args = parser.parse_args(argv)
    track = args.track or (Path(os.environ[ZANDVOORT_ENV]) if os.environ.get(ZANDVOORT_ENV) else DEFAULT_TRACK)
    scenarios = [s for s in args.scenarios.split(",") if s != "zandvoort" or track.is_file()]
    jobs = [
        (v, s, c, str(track) if track.is_file() else None)
        for v in args.vehicles.split(",")
        for s in scenarios
        for c in ("clothoid", "nmpc")
    ]
    with ProcessPoolExecutor(max_workers=args.workers) as pool:
        runs = list(pool.map(run_one, jobs))
    by_key = {(r.vehicle, r.scenario, r.controller): r for r in runs}
    rows, missed = [], []
    header = f"{'vehicle':<20} {'scenario':<10} {'ctrl':<9} {'max|CTE|':>8} {'osc deg':>8} {'RMS rate':>9} {'LC':<16}"
    print(header + " goals")
    for v in args.vehicles.split(","):
        for s in scenarios:
            c, ref = by_key[(v, s, "clothoid")], by_key[(v, s, "nmpc")]
            checks = goals(c, ref)
            for r in (c, ref):
                text = "" if r is ref else "; ".join(f"{g}: {'met' if ok else 'MISSED'}" for g, ok in checks)
                print(
                    f"{r.vehicle:<20} {r.scenario:<10} {r.controller:<9} {r.max_abs_cte_m:8.3f} "
                    f"{r.steer_oscillation_deg:8.1f} {r.rms_steer_rate_deg_s:9.1f} {r.limit_cycle_text:<16} {text}"
                )
            missed += [f"{v} {s}: {g}" for g, ok in checks if not ok]
            rows.append({"clothoid": asdict(c), "nmpc": asdict(ref), "goals": [[g, ok] for g, ok in checks]})
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps({"created_unix_s": time.time(), "runs": rows, "missed": missed}, indent=2) + "\n")
    print(f"{len(missed)} goals missed" + ("" if not missed else ":\n  " + "\n  ".join(missed)))
    print(f"wrote {args.out}")
    return 1 if (args.check and missed) else 0


if __name__ == "__main__":
    sys.exit(main())
