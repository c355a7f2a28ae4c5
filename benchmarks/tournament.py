"""Tournament overhead benchmark: what the tournament itself costs per trial (the sampler's asks and tells, planning
the runs, the run store, the Pareto front, the configuration files, the backend's start and hand-overs) against the
time of the runs it makes.

A small tournament (pure pursuit, Stanley and the clothoid controller on the given vehicle; training cases dlc and
figure8 at 30 km/h, test case fig17; batches of 4) runs on a local pool of one worker into an empty folder, without
the report (its judging and figures are timed by their own tests), once with a quarter of `--trials` trials per
controller and once with `--trials`. A tournament's overhead is the wall time of `run_tournament` minus its runs'
own wall times (run_time_s, measured in the worker around each run): with one worker the runs go one after another,
so what is left is the tournament's. The overhead per trial is its growth from the small to the large tournament
per added trial; the rest is paid once per tournament. Goal: the overhead per trial under 5 % of a trial's runs.

Prints the figures and writes JSON (like benchmarks/sweep.py); `--check` exits non-zero when the goal is missed.

    python benchmarks/tournament.py [--vehicle tractor-semitrailer] [--trials 16]
                                    [--out benchmarks/results/tournament.json] [--check]
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import tempfile
import time
from pathlib import Path

from workbench.apps.studies import LocalBackend, load_tournament, run_tournament

#: The overhead goal: the tournament's own time, as a share of its runs' time.
OVERHEAD_GOAL = 0.05
CONTROLLERS = ("pure-pursuit", "stanley", "clothoid")

SPEC = """
[tournament]
controllers = {controllers}
vehicles = ["{vehicle}"]
trials = {trials}
batch_size = 4
front_points = 2
inform_delays = false

[train]
scenarios = ["dlc", "figure8"]
speeds_kmh = [30]

[test]
scenarios = ["fig17"]
speeds_kmh = [30]
"""


def measure(vehicle: str, trials: int) -> dict[str, float | int]:
    """Run the small tournament once into a fresh folder; its wall time, its runs' time and the difference."""
    with tempfile.TemporaryDirectory(prefix="tournament-bench-") as folder:
        spec_file = Path(folder) / "spec.toml"
        spec_file.write_text(
            SPEC.format(controllers=json.dumps(list(CONTROLLERS)), vehicle=vehicle, trials=trials), encoding="utf-8"
        )
        start = time.perf_counter()
        spec = load_tournament(spec_file)
        loaded, cpu = time.perf_counter(), time.process_time()
        result = run_tournament(spec, Path(folder) / "out", LocalBackend(workers=1), report=False, log=None)
        wall, cpu = time.perf_counter() - loaded, time.process_time() - cpu
    distinct = result.results.drop_duplicates("run_id")  # a run judged twice (tuned and a front point) ran once
    runs_s = float(distinct["run_time_s"].sum())
    trials_total = len(result.history)
    return {
        "spec_load_s": loaded - start,
        "wall_s": wall,
        "runs": len(distinct),
        "runs_s": runs_s,
        "overhead_s": wall - runs_s,
        "parent_cpu_s": cpu,
        "trials": trials_total,
        "overhead_per_trial_ms": 1000.0 * (wall - runs_s) / trials_total,
        "run_s_per_trial": runs_s / trials_total,
        "overhead_share": (wall - runs_s) / runs_s,
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--vehicle", default="tractor-semitrailer", help="the vehicle (default: the loaded truck)")
    parser.add_argument("--trials", type=int, default=16, help="trials per controller of the larger run (default 16)")
    parser.add_argument("--out", type=Path, default=Path(__file__).parent / "results" / "tournament.json")
    parser.add_argument("--check", action="store_true", help="exit 1 if the goal is missed")
    args = parser.parse_args(argv)

    load_before = os.getloadavg()
    small_trials = max(1, args.trials // 4)
    measure(args.vehicle, small_trials)  # warm-up: this process's first imports, the kernels' caches
    small = measure(args.vehicle, small_trials)
    large = measure(args.vehicle, args.trials)
    # What one more trial costs: the overhead's growth from the small to the large tournament, per added trial;
    # what is left of the overhead is paid once per tournament (the pool's start, the tuning read to write a scaled
    # lead filter's configuration).
    added = large["trials"] - small["trials"]
    per_trial_s = (large["overhead_s"] - small["overhead_s"]) / added
    cpu_per_trial_s = (large["parent_cpu_s"] - small["parent_cpu_s"]) / added
    fixed_s = large["overhead_s"] - per_trial_s * large["trials"]
    run_s_per_trial = large["run_s_per_trial"]
    share = per_trial_s / run_s_per_trial
    met = share < OVERHEAD_GOAL
    for trials, figures in ((small_trials, small), (args.trials, large)):
        print(
            f"{len(CONTROLLERS)} controllers x {trials} trials on {args.vehicle} (local pool, 1 worker): "
            f"{figures['wall_s']:.1f} s, of which {figures['runs']} runs {figures['runs_s']:.1f} s; overhead "
            f"{figures['overhead_s']:.2f} s ({figures['overhead_share']:.1%} of the runs' time)"
        )
    print(
        f"overhead per trial {1000 * per_trial_s:.1f} ms against {run_s_per_trial:.2f} s of runs per trial: "
        f"{share:.1%} (goal < {OVERHEAD_GOAL:.0%}: {'met' if met else 'MISSED'}); once per tournament {fixed_s:.2f} s; "
        f"the spec loads in {large['spec_load_s']:.2f} s"
    )
    print(f"the tournament's process works {1000 * cpu_per_trial_s:.1f} ms of CPU per trial (the rest is waiting)")
    document = {
        "machine": {"python": sys.version.split()[0], "platform": platform.platform(), "cpus": os.cpu_count()},
        "created_unix_s": time.time(),
        "load_average_before": load_before,
        "controllers": list(CONTROLLERS),
        "vehicle": args.vehicle,
        "small": {"trials_per_controller": small_trials, **small},
        "large": {"trials_per_controller": args.trials, **large},
        "overhead_per_trial_s": per_trial_s,
        "overhead_once_s": fixed_s,
        "parent_cpu_per_trial_s": cpu_per_trial_s,
        "run_s_per_trial": run_s_per_trial,
        "overhead_share_per_trial": share,
        "overhead_goal": OVERHEAD_GOAL,
        "goal_met": met,
    }
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(document, indent=2) + "\n")
    print(f"wrote {args.out}")
    return 1 if (args.check and not met) else 0


if __name__ == "__main__":
    sys.exit(main())
