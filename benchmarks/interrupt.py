"""Interrupt benchmark: how long `workbench sweep` takes to exit after SIGINT (Ctrl-C) and after SIGTERM while its
workers are in the middle of runs that take about a minute each.

The sweep (written to a temporary folder) has two fast runs (the kinematic car) and two slow ones (CommonRoad's
multi-body car, pure Python: four laps of the figure-8, about 70 s each on an idle CPU) on 2 workers; each signal
is sent one second after the fast runs' rows are written, both workers then busy with a slow run. Each measurement
is the wall time from the signal to the process's exit. It also checks that the exit code is 130, that the rows of
the fast runs are kept and no other row was written, and that no worker process outlives the sweep.

Goal: on the local backend, exit within 2 s of either signal (every measurement). The Dask backend (a
LocalCluster of 2 workers, stopped through its nannies) is measured once per signal and reported without a goal.

Prints the figures and writes JSON (like benchmarks/run.py); `--check` exits non-zero when a goal is missed.

    python benchmarks/interrupt.py [--out benchmarks/results/interrupt.json] [--repeat 3] [--no-dask] [--check]
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import signal
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import psutil

from workbench.apps.studies import load_spec

#: The local backend exits within this long (s) after SIGINT or SIGTERM.
EXIT_GOAL_S = 2.0
#: How long (s) the fast runs may take before the signal (the workers compile, the machine may be busy), and the
#: sweep to exit after it before it counts as hung.
READY_TIMEOUT_S = 300.0
HUNG_S = 120.0
SPEC = """
[study]
scenarios = ["figure8"]
controllers = ["pure-pursuit"]
vehicles = ["kinematic-bicycle", "commonroad-mb"]

[grid]
speed_kmh = [25, 30]
laps = 4
"""


def _alive(pid: int) -> bool:
    try:
        return psutil.Process(pid).status() != psutil.STATUS_ZOMBIE
    except psutil.NoSuchProcess:
        return False


def measure(signum: int, backend: str, folder: Path) -> dict[str, object]:
    """One interrupted sweep into a fresh folder under `folder`: seconds from the signal to the exit, and what the
    sweep left behind."""
    spec = folder / "spec.toml"
    spec.write_text(SPEC)
    fast = {run.run_id for run in load_spec(spec).plan()[:2]}
    out = Path(tempfile.mkdtemp(prefix=f"{backend}-{signal.Signals(signum).name}-", dir=folder))
    command = [sys.executable, "-m", "workbench.apps.cli", "sweep", str(spec), "--out", str(out)]
    command += ["--backend", backend, "--workers", "2", "--no-plots"]
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + READY_TIMEOUT_S
        while not fast <= {p.stem for p in (out / "runs").glob("*.json")}:
            if process.poll() is not None or time.monotonic() > deadline:
                raise RuntimeError(f"the sweep ended or stalled before the signal: {process.stderr.read()}")
            time.sleep(0.02)
        time.sleep(1.0)
        descendants = [p.pid for p in psutil.Process(process.pid).children(recursive=True)]
        start = time.perf_counter()
        process.send_signal(signum)
        _, stderr = process.communicate(timeout=HUNG_S)
        exit_s = time.perf_counter() - start
    finally:
        if process.poll() is None:
            process.kill()
            process.communicate()
    time.sleep(0.5)  # a LocalCluster's killed worker may need a moment to be reaped
    rows = {p.stem for p in (out / "runs").glob("*.json")}
    return {
        "signal": signal.Signals(signum).name,
        "backend": backend,
        "exit_s": exit_s,
        "exit_code": process.returncode,
        "rows_kept": rows == fast,
        "workers_started": len(descendants),
        "workers_outliving": sum(_alive(pid) for pid in descendants),
        "stderr_last_line": stderr.strip().splitlines()[-1] if stderr.strip() else "",
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path(__file__).parent / "results" / "interrupt.json")
    parser.add_argument("--repeat", type=int, default=3, metavar="N", help="local measurements per signal (3)")
    parser.add_argument("--no-dask", action="store_true", help="measure the local backend only")
    parser.add_argument("--check", action="store_true", help="exit 1 if a goal is missed")
    args = parser.parse_args(argv)
    if args.repeat < 1:
        parser.error("--repeat must be >= 1")

    load_before = os.getloadavg()
    measurements = []
    with tempfile.TemporaryDirectory(prefix="interrupt-") as tmp:
        for signum in (signal.SIGINT, signal.SIGTERM):
            for backend in ["local"] * args.repeat + ([] if args.no_dask else ["dask"]):
                m = measure(signum, backend, Path(tmp))
                measurements.append(m)
                print(
                    f"{m['backend']:<5} {m['signal']:<7}: exit {m['exit_code']} after {m['exit_s']:6.2f} s; rows kept: "
                    f"{'yes' if m['rows_kept'] else 'NO'}; workers outliving it: {m['workers_outliving']} of "
                    f"{m['workers_started']}"
                )

    def clean(m: dict[str, object]) -> bool:
        return m["exit_code"] == 130 and m["rows_kept"] is True and m["workers_outliving"] == 0

    local = [m for m in measurements if m["backend"] == "local"]
    summary = {}
    for name in ("SIGINT", "SIGTERM"):
        times = [float(m["exit_s"]) for m in local if m["signal"] == name]
        summary[name] = {"median_s": statistics.median(times), "max_s": max(times)}
        print(f"local {name}: median {summary[name]['median_s']:.2f} s, worst {summary[name]['max_s']:.2f} s")
    goal_met = all(float(m["exit_s"]) <= EXIT_GOAL_S and clean(m) for m in local)
    all_clean = all(clean(m) for m in measurements)
    print(
        f"local backend exits within {EXIT_GOAL_S:g} s of SIGINT and SIGTERM, with exit code 130, its rows kept and "
        f"no worker left: {'met' if goal_met else 'MISSED'}"
    )
    document = {
        "machine": {"python": sys.version.split()[0], "platform": platform.platform(), "cpus": os.cpu_count()},
        "created_unix_s": time.time(),
        "load_average_before": load_before,
        "spec": SPEC,
        "repeat": args.repeat,
        "measurements": measurements,
        "local_summary": summary,
        "exit_goal_s": EXIT_GOAL_S,
        "goal_met": goal_met,
        "every_measurement_clean": all_clean,
        "goals_met": goal_met and all_clean,
    }
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(document, indent=2) + "\n")
    print(f"wrote {args.out}")
    return 1 if (args.check and not document["goals_met"]) else 0


if __name__ == "__main__":
    sys.exit(main())
