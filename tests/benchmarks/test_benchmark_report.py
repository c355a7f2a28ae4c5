"""benchmarks/benchmark_report.py: the machine record, the JSON file and the --check exit code every benchmark
script ends with."""

from __future__ import annotations

import json
import os
from dataclasses import dataclass
from pathlib import Path

import benchmark_report  # on the path through conftest.py, as the scripts find it when run


@dataclass
class _Entry:
    name: str
    goal_met: bool | None


def test_the_machine_names_python_platform_cpus_and_load() -> None:
    host = benchmark_report.machine()
    assert set(host) == {"python", "platform", "cpus", "load_average"}
    assert host["cpus"] == os.cpu_count()
    assert host["load_average"] is None or len(host["load_average"]) == 3


def test_the_results_are_written_as_json_in_a_new_folder(tmp_path: Path, capsys) -> None:
    out = tmp_path / "deep" / "results.json"
    benchmark_report.write_results(out, {"entries": [1.5, None]}, " (note)")
    assert json.loads(out.read_text()) == {"entries": [1.5, None]}
    assert capsys.readouterr().out == f"wrote {out} (note)\n"


def test_a_missed_goal_fails_only_a_check() -> None:
    missed = [_Entry("a", True), _Entry("b", None), _Entry("c", False)]
    assert benchmark_report.exit_code(missed, check=True) == 1
    assert benchmark_report.exit_code(missed, check=False) == 0
    assert benchmark_report.exit_code([_Entry("a", True), _Entry("b", None)], check=True) == 0
