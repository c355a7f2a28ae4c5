"""The generated circuits' ranges as a file (`workbench.simulation.circuit_ranges`): a [circuits] table read
into CircuitRanges, its other fields at their defaults, from a ranges file or a spec that carries the table; every
problem refused naming the file, the key and what is allowed; the written table reads back to the ranges."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pytest

from workbench.apps.cli import main
from workbench.base.errors import WorkbenchInputError
from workbench.simulation.circuit_ranges import circuit_ranges_toml, read_circuit_ranges
from workbench.simulation.circuits import CircuitRanges


def _file(folder: Path, text: str, name: str = "ranges.toml") -> Path:
    path = folder / name
    path.write_text(text)
    return path


def test_a_circuits_table_is_read_with_the_other_fields_at_their_defaults(tmp_path):
    path = _file(tmp_path, "[circuits]\nmin_radius_m = 30\nmax_turns = 5\nreverse_turn_share = 0.1\n")
    ranges = read_circuit_ranges(path)
    assert ranges == dataclasses.replace(CircuitRanges(), min_radius_m=30.0, max_turns=5, reverse_turn_share=0.1)
    assert isinstance(ranges.min_radius_m, float)  # an integer in the file is taken for a float field
    assert read_circuit_ranges(_file(tmp_path, "[circuits]\n", "empty.toml")) == CircuitRanges()


def test_a_spec_carrying_the_table_is_read_for_its_circuits_table_only(tmp_path):
    text = '[study]\nscenarios = ["circuit:1"]\n[grid]\nspeed_kmh = 30\n[circuits]\nmax_radius_m = 90\n'
    spec = _file(tmp_path, text, "spec.toml")
    assert read_circuit_ranges(spec).max_radius_m == 90.0


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("[circuits]\nmin_radius = 30\n", r"\[circuits\]: unknown key 'min_radius'; allowed keys: min_radius_m, "),
        ("[circuits]\nmin_radius_m = nan\n", r"'min_radius_m' must be a finite number; got nan"),
        ("[circuits]\nmax_radius_m = inf\n", r"'max_radius_m' must be a finite number; got inf"),
        ('[circuits]\nmin_radius_m = "30"\n', r"'min_radius_m' must be a number; got '30' \(a file's numbers"),
        ("[circuits]\nmin_turns = 3.5\n", r"'min_turns' must be a whole number; got 3.5"),
        ("[circuits]\nclearance_m = true\n", r"'clearance_m' must be a number; got True"),
        (
            "[circuits]\nmin_radius_m = 1.0\n",
            r"CircuitRanges.min_radius_m must be a finite number in \[5, 500\] m; got 1.0",
        ),
        ("[circuits]\nmin_radius_m = 70.0\n", r"min_radius_m must not exceed max_radius_m; got 70.0 and 60.0 m"),
        ("circuits = 3\n", r"\[circuits\] must be a table; got 3"),
        ("[study]\nseed = 1\n", r"no \[circuits\] table \(it has study\); give one with any of min_radius_m, "),
        ("[circuits\n", r"not valid TOML"),
    ],
)
def test_a_bad_ranges_file_is_refused_naming_the_file_the_key_and_what_is_allowed(tmp_path, text, message):
    path = _file(tmp_path, text)
    with pytest.raises(WorkbenchInputError, match=message) as err:
        read_circuit_ranges(path)
    assert str(err.value).startswith(f"circuit ranges file {str(path)!r}: ")


def test_a_missing_file_is_refused_naming_it(tmp_path):
    with pytest.raises(WorkbenchInputError, match=r"circuit ranges file '.*nowhere.toml': no such file"):
        read_circuit_ranges(tmp_path / "nowhere.toml")


def test_the_written_table_reads_back_to_the_ranges_written(tmp_path):
    ranges = CircuitRanges(min_radius_m=31.25, max_curvature_rate_1pm2=0.0031, min_turns=4, clearance_m=21.5)
    assert read_circuit_ranges(_file(tmp_path, circuit_ranges_toml(ranges))) == ranges
    assert read_circuit_ranges(_file(tmp_path, circuit_ranges_toml(), "defaults.toml")) == CircuitRanges()
    with pytest.raises(WorkbenchInputError, match="ranges must be a CircuitRanges; got"):
        circuit_ranges_toml({"min_radius_m": 30.0})  # type: ignore[arg-type]


def test_workbench_scenarios_prints_the_default_ranges_or_a_files(tmp_path, capsys):
    assert main(["scenarios", "--circuit-ranges"]) == 0
    assert capsys.readouterr().out == circuit_ranges_toml()
    path = _file(tmp_path, "[circuits]\nmax_turns = 5\n")
    assert main(["scenarios", "--circuit-ranges", str(path)]) == 0
    assert read_circuit_ranges(_file(tmp_path, capsys.readouterr().out, "shown.toml")).max_turns == 5
    assert main(["scenarios", "--circuit-ranges", str(tmp_path / "nowhere.toml")]) == 2
    assert "circuit ranges file" in capsys.readouterr().err
