"""Publish benchmark results for the documentation: copy each benchmark's last result from benchmarks/results/
into docs/benchmark-results/<name>.json (committed), reduced to what the Benchmarks page shows: the command, the
date and machine it was measured on, the summary rows and any further tables.

The docs build (docs/_ext/workbench_figures.py) renders those files as tables; the per-run lists stay in
benchmarks/results/ (git-ignored). Each benchmark records the machine it ran on (`benchmark_report.machine`); a
result without that record is refused rather than given the machine it is published on.

Usage (after running the benchmarks whose results should go to the docs):

    python benchmarks/publish.py [steering cte_breakdown fmu_plant run startup]
"""

from __future__ import annotations

import argparse
import datetime
import json
import math
import sys
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

from benchmark_report import write_results

RESULTS = Path(__file__).parent / "results"
PUBLISHED = Path(__file__).parent.parent / "docs" / "benchmark-results"

Row = dict[str, object]


@dataclass(frozen=True)
class Table:
    """A table read off a result: its title, the result's list of rows it comes from and the columns kept."""

    title: str
    key: str
    columns: tuple[str, ...]

    def rows(self, result: Mapping[str, object]) -> list[Row]:
        """The kept columns of each row of result[key] (a missing column as None)."""
        rows = result.get(self.key)
        if not isinstance(rows, list):
            return []
        return [{c: row.get(c) for c in self.columns} for row in rows if isinstance(row, Mapping)]


@dataclass(frozen=True)
class Benchmark:
    """A published benchmark: its result file in benchmarks/results/, the command that measures it, its summary
    table and any further tables."""

    result_file: str
    command: str
    summary: Table
    tables: tuple[Table, ...] = ()


_TIMED_ENTRIES = ("name", "median_us", "p99_us", "overhead_us", "real_time_factor", "wall_s", "goal", "goal_met")
_STEERING = ("vehicle", "conditions", "set", "runs", "excluded", "median_ratio", "worst_ratio", "goals_met",
             "goals_missed", "goal_vehicle")  # fmt: skip
_BREAKDOWN = ("vehicle", "conditions", "switch", "median_max_cte_vs_nominal", "median_rms_cte_vs_nominal",
              "median_gap_closed", "median_ratio_to_nmpc_same_run", "limit_cycles", "scenarios")  # fmt: skip
_LOOPS = ("vehicle", "case", "speed_kmh", "floor_m", "phase_margin_deg", "gain_margin_db", "gain_reduction_margin_db",
          "crossover_hz", "bandwidth_hz", "stable")  # fmt: skip
_MODELS = ("vehicle", "scenario", "reference_rms_1pm", "reference_max_1pm", "reference_relative", "feedforward_rms_1pm",
           "feedforward_max_1pm", "feedforward_relative", "preview_reference_relative",
           "preview_feedforward_relative", "path_curvature_rms_1pm")  # fmt: skip
_STARTUP = ("name", "median_s", "min_s", "overhead_s", "goal", "goal_met")

BENCHMARKS: dict[str, Benchmark] = {
    "steering": Benchmark(
        "steering.json",
        "python benchmarks/steering.py --check",
        Table("Summary", "summary", _STEERING),
        (Table("Set goals", "set_goals", ("where", "text", "value", "bound", "met")),),
    ),
    "cte_breakdown": Benchmark(
        "cte_breakdown.json",
        "python benchmarks/cte_breakdown.py",
        Table("Summary", "summary", _BREAKDOWN),
        (
            Table("Loop analysis", "loop_analysis", _LOOPS),
            Table("The clothoid controller's models along the NMPC's runs", "model_error", _MODELS),
        ),
    ),
    "fmu_plant": Benchmark(
        "fmu_plant.json", "python benchmarks/fmu_plant.py --check", Table("Summary", "entries", _TIMED_ENTRIES)
    ),
    "run": Benchmark(
        "latest.json", "python benchmarks/run.py --check", Table("Summary", "entries", (*_TIMED_ENTRIES, "ratio"))
    ),
    "startup": Benchmark("startup.json", "python benchmarks/startup.py --check", Table("Summary", "entries", _STARTUP)),
}


def _finite(value: object) -> object:
    """value with NaN and infinities as None (strict JSON has neither)."""
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {k: _finite(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_finite(v) for v in value]
    return value


def published_document(name: str, result: Mapping[str, object]) -> dict[str, object]:
    """What docs/benchmark-results/<name>.json holds for this benchmark's result: benchmark, command,
    measured_unix_s and measured_utc (from the result's created_unix_s), machine (the one the result records),
    summary (rows) and tables (title and rows). A result without its creation time or its machine is refused."""
    spec = BENCHMARKS[name]
    created = result.get("created_unix_s")
    if not isinstance(created, int | float):
        raise SystemExit(f"publish: {name}: the result has no created_unix_s (got {created!r}); rerun the benchmark")
    recorded = result.get("machine")
    if not isinstance(recorded, Mapping):
        raise SystemExit(f"publish: {name}: the result does not record the machine it ran on (got {recorded!r}); "
                         "rerun the benchmark")  # fmt: skip
    document: dict[str, object] = {
        "benchmark": name,
        "command": spec.command,
        "measured_unix_s": float(created),
        "measured_utc": datetime.datetime.fromtimestamp(float(created), datetime.UTC).strftime("%Y-%m-%d %H:%M UTC"),
        "machine": dict(recorded),
        "summary": spec.summary.rows(result),
        "tables": [{"title": table.title, "rows": table.rows(result)} for table in spec.tables],
    }
    return _finite(document)  # type: ignore[return-value]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("names", nargs="*", default=list(BENCHMARKS), help=f"of {', '.join(BENCHMARKS)} (default all)")
    parser.add_argument("--results", type=Path, default=RESULTS, help="the benchmarks' results folder")
    parser.add_argument("--out", type=Path, default=PUBLISHED, help="the published folder")
    args = parser.parse_args(argv)
    unknown = [n for n in args.names if n not in BENCHMARKS]
    if unknown:
        parser.error(f"unknown benchmark {', '.join(unknown)}; allowed: {', '.join(BENCHMARKS)}")
    missing = 0
    for name in args.names:
        source = args.results / BENCHMARKS[name].result_file
        if not source.is_file():
            print(f"publish: {name}: no result at {source}; run `{BENCHMARKS[name].command}` first", file=sys.stderr)
            missing += 1
            continue
        result = json.loads(source.read_text())
        write_results(args.out / f"{name}.json", published_document(name, result), f" (from {source})")
    return 1 if missing else 0


if __name__ == "__main__":
    sys.exit(main())
