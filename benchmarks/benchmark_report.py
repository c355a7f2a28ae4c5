"""What every benchmark script writes at its end: the machine it measured on, the results as JSON, and the exit
code of `--check` (1 when a goal was missed).

The scripts run as `python benchmarks/<name>.py`, which puts this folder on the module path; their tests put it
there too (tests/benchmarks/conftest.py)."""

from __future__ import annotations

import json
import os
import platform
import sys
from collections.abc import Iterable
from pathlib import Path
from typing import Protocol


class GoalEntry(Protocol):
    """A benchmark entry with a goal: its name, and whether the goal was met (None: it has no goal)."""

    name: str
    goal_met: bool | None


def machine() -> dict[str, object]:
    """The machine the benchmark ran on: Python's version, the platform, the CPU count and, where the system
    tells it, the load average (1, 5, 15 min) the timings were taken under."""
    return {
        "python": sys.version.split()[0],
        "platform": platform.platform(),
        "cpus": os.cpu_count(),
        "load_average": os.getloadavg() if hasattr(os, "getloadavg") else None,
    }


def write_results(out: Path, document: dict[str, object], note: str = "") -> None:
    """Write `document` to `out` as indented JSON (its folder made if missing) and say so, with `note` after."""
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(document, indent=2) + "\n")
    print(f"wrote {out}{note}")


def exit_code(entries: Iterable[GoalEntry], check: bool) -> int:
    """1 with `check` when an entry missed its goal, else 0."""
    missed = [e.name for e in entries if e.goal_met is False]
    return 1 if (check and missed) else 0
