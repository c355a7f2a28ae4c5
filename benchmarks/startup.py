"""Start-up benchmark of the command lines: how long `workbench --help`, `workbench scenarios` (with and
without the Zandvoort track) and `tuning --help` take, each in a fresh process, against a bare `python -c pass` in
the same run.

Each command runs N times (default 5) in a subprocess, interleaved with the others so that a slow spell of the
machine falls on all of them; the table gives the median wall time and its overhead over the bare interpreter.
Writes JSON like benchmarks/run.py. Goal: `workbench --help` and `workbench scenarios` (without a track) in 0.5 s
or less; `--check` exits 1 when one is missed.

    python benchmarks/startup.py [--runs 5] [--out benchmarks/results/startup.json] [--track ZANDVOORT.csv] [--check]
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import time
from dataclasses import asdict, dataclass
from pathlib import Path

from benchmark_report import exit_code, machine, write_results

ROOT = Path(__file__).resolve().parents[1]
DEFAULT_TRACK = ROOT.parent / "shared" / "tracks" / "Zandvoort_track.csv"
#: Wall-time goal of the commands that have one (s).
GOAL_S = 0.5


@dataclass
class Entry:
    name: str
    argv: list[str]
    times_s: list[float]
    median_s: float | None = None
    min_s: float | None = None
    overhead_s: float | None = None
    goal: str | None = None
    goal_met: bool | None = None
    returncode: int | None = None


def _script(name: str) -> list[str]:
    """A console script of this environment, run by this interpreter (the same as `.venv/bin/<name>`)."""
    path = Path(sys.executable).parent / name
    if not path.is_file():
        raise SystemExit(f"startup: {path} not found; install the project (pip install -e .) into this environment")
    return [sys.executable, str(path)]


def _time(argv: list[str]) -> tuple[float, int]:
    """Wall time (s) of one run of argv in a fresh process, its output discarded; and its exit code."""
    env = dict(os.environ, PYTHONDONTWRITEBYTECODE="1")
    env.pop("WORKBENCH_ZANDVOORT_CSV", None)  # `workbench scenarios` without --track reads no track
    start = time.perf_counter()
    done = subprocess.run(argv, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env, cwd=ROOT, check=False)
    return time.perf_counter() - start, done.returncode


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=5, metavar="N", help="runs of each command (default 5)")
    parser.add_argument("--out", type=Path, default=Path(__file__).parent / "results" / "startup.json")
    parser.add_argument("--track", type=Path, default=None, help=f"Zandvoort CSV (default: {DEFAULT_TRACK})")
    parser.add_argument("--check", action="store_true", help=f"exit 1 if a command with a goal takes > {GOAL_S} s")
    args = parser.parse_args(argv)
    if args.runs < 1:
        parser.error("--runs must be >= 1")
    track = args.track or DEFAULT_TRACK

    workbench, tuning = _script("workbench"), _script("tuning")
    commands: list[tuple[str, list[str], bool]] = [
        ("python -c pass", [sys.executable, "-c", "pass"], False),
        ("workbench --help", [*workbench, "--help"], True),
        ("workbench scenarios", [*workbench, "scenarios"], True),
    ]
    if track.is_file():
        with_track = [*workbench, "scenarios", "--track", str(track)]
        commands.append(("workbench scenarios --track Zandvoort", with_track, False))
    commands.append(("tuning --help", [*tuning, "--help"], False))

    for _name, command, _goal in commands:  # warm-up: byte code, the OS's file cache, numba's cache
        _time(command)
    entries = [Entry(name, command, []) for name, command, _ in commands]
    for _ in range(args.runs):
        for entry in entries:
            elapsed, entry.returncode = _time(entry.argv)
            entry.times_s.append(elapsed)
    bare = statistics.median(entries[0].times_s)
    for entry, (_name, _command, has_goal) in zip(entries, commands, strict=True):
        entry.median_s = statistics.median(entry.times_s)
        entry.min_s = min(entry.times_s)
        entry.overhead_s = entry.median_s - bare
        if has_goal:
            entry.goal = f"median <= {GOAL_S:g} s"
            entry.goal_met = entry.median_s <= GOAL_S and entry.returncode == 0

    print(f"{'command':<40} {'median s':>9} {'min s':>7} {'over python s':>14}  goal")
    for e in entries:
        goal = "" if e.goal is None else f"{e.goal}: {'met' if e.goal_met else 'MISSED'}"
        if e.returncode:
            goal += f" (exit code {e.returncode})"
        print(f"{e.name:<40} {e.median_s:9.3f} {e.min_s:7.3f} {e.overhead_s:14.3f}  {goal}")
    host = machine()
    entries_out = [asdict(e) for e in entries]
    document = {"machine": host, "created_unix_s": time.time(), "runs": args.runs, "entries": entries_out}
    load = host["load_average"]
    write_results(args.out, document, f" (load average {load[0]:.1f} on {host['cpus']} CPUs)" if load else "")
    return exit_code(entries, args.check)


if __name__ == "__main__":
    sys.exit(main())
