"""Shared helpers of the studies tests: small specs written to files, and a serial in-process backend that records
which runs it was given."""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

import pandas as pd

from workbench.apps.studies import TIMING_COLUMNS, PlannedRun, execute_run
from workbench.apps.studies.runner import failed_row

#: Small tight circuits (no trailer to make room for): 150-400 m laps of 12-20 m turns.
SMALL_CIRCUITS = """[circuits]
min_radius_m = 12.0
max_radius_m = 20.0
max_curvature_rate_1pm2 = 0.02
offtracking_length_m = 0.0
clearance_m = 14.0
min_length_m = 150.0
max_length_m = 400.0
"""

#: Pure pursuit and the clothoid controller on the kinematic car through the dlc at two speeds, started 0.3 m off
#: the path; the clothoid runs with min_lookahead_m = 30 and max_lookahead_m = 20 fail (a combination: each value
#: alone is planned in runs that complete): 10 runs, 2 errors.
TINY_SPEC = """
[study]
scenarios = ["dlc"]
controllers = ["pure-pursuit", "clothoid"]
vehicles = ["kinematic-bicycle"]

[grid]
speed_kmh = [20, 30]
initial_offset_m = 0.3

[grid.clothoid]
min_lookahead_m = [5.0, 30.0]
max_lookahead_m = [20.0, 31.0]
"""


def write_spec(folder: Path, text: str, name: str = "spec.toml") -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / name
    path.write_text(text)
    return path


class SerialBackend:
    """Runs in this process, one after another; `given` lists the run ids of every map_runs call."""

    name = "serial"
    workers = 1

    def __init__(self) -> None:
        self.given: list[list[str]] = []
        self._started = False

    @property
    def started(self) -> bool:
        return self._started

    def start(self) -> None:
        self._started = True

    def close(self) -> None:
        self._started = False

    def __enter__(self) -> SerialBackend:
        self.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def describe(self) -> str:
        return "serial, in process"

    def map_runs(self, runs: Sequence[PlannedRun]) -> Iterator[dict[str, Any]]:
        self.given.append([r.run_id for r in runs])
        for run in runs:
            yield execute_run(run)


class NotSimulating(SerialBackend):
    """Records the runs it is given (`given`) and returns each as an error row without simulating it: what a study
    would run, without running it."""

    def map_runs(self, runs: Sequence[PlannedRun]) -> Iterator[dict[str, Any]]:
        self.given.append([r.run_id for r in runs])
        for run in runs:
            yield failed_row(run, "not simulated in this test")


def assert_same_results(a: pd.DataFrame, b: pd.DataFrame) -> None:
    """Equal bit for bit, column for column, except the wall-clock TIMING_COLUMNS."""
    drop = [c for c in TIMING_COLUMNS if c in a.columns]
    pd.testing.assert_frame_equal(a.drop(columns=drop), b.drop(columns=drop), check_exact=True)
