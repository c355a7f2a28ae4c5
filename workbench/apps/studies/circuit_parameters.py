"""The run parameter circuit_ranges: a file whose [circuits] table the generated circuits (circuit:SEED) of a run are
drawn within (`workbench.simulation.circuit_ranges`), so that a sweep's [grid] can vary the ranges and a
tournament's sets can name them. A spec may name itself when it carries the [circuits] table.

It shapes the generated circuits among a study's scenarios only: a run on any other scenario does not carry it
(`scenario_values`), so that run plans the id it has without it. A run's id takes the ranges the file holds
(`ranges_identity`), not its name or its other tables. Refused when the spec loads (`planned_circuit_ranges`):
a file that cannot be read as ranges (naming the key and the file), a study with no generated circuit among its
scenarios, and more than one file in [grid] beside a scenario that is not a circuit (whose runs would repeat alike,
once per file). A spec's [circuits] table that no run reads is refused too (`check_circuits_table`).
"""

from __future__ import annotations

import dataclasses
import functools
import json
import os
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

from workbench.apps.studies.study_size import planned_values
from workbench.base.errors import WorkbenchInputError
from workbench.simulation.circuit_ranges import CIRCUITS_TABLE, CircuitRanges, read_circuit_ranges
from workbench.simulation.circuits import circuit_seed
from workbench.simulation.scenario import ScenarioOptions

#: The run parameter's name.
CIRCUIT_RANGES = "circuit_ranges"


def is_circuit(scenario: str) -> bool:
    """Whether a study's scenario (a name or an absolute file path) is a generated circuit, circuit:SEED.

    Parameters
    ----------
    scenario : str
        A scenario name or a waypoint file's path.

    Returns
    -------
    bool
        True for circuit:SEED.

    Examples
    --------
    >>> from workbench.apps.studies.circuit_parameters import is_circuit
    >>> is_circuit("circuit:7"), is_circuit("dlc")
    (True, False)
    """
    return circuit_seed(scenario) is not None


def scenario_values(scenario: str, values: Mapping[str, Any]) -> dict[str, Any]:
    """A run's parameters on `scenario`: circuit_ranges left out unless the scenario is a generated circuit.

    Parameters
    ----------
    scenario : str
        The run's scenario.
    values : mapping
        The run's parameters.

    Returns
    -------
    dict
        The parameters the run carries (and its id is made of).
    """
    if is_circuit(scenario):
        return dict(values)
    return {k: v for k, v in values.items() if k != CIRCUIT_RANGES}


def ranges_identity(path: Path) -> dict[str, Any]:
    """What a run's id takes of its circuit_ranges file: the ranges it holds, field by field (not the file's name
    or its other tables, so that a spec that names itself plans the same ids when its other tables change).
    Read once per file version (its path, size and modification time).

    Parameters
    ----------
    path : pathlib.Path
        A circuit_ranges file.

    Returns
    -------
    dict
        {"circuits": the ranges' fields}.

    Raises
    ------
    WorkbenchInputError
        The file is missing or cannot be read as ranges.
    """
    try:
        stat = os.stat(path)
    except OSError:
        return {CIRCUITS_TABLE: dataclasses.asdict(read_circuit_ranges(path))}  # a file gone: refused, named
    return _identity(str(Path(path).resolve()), stat.st_size, stat.st_mtime_ns)


def drawn_ranges_key(path: Path | None) -> str:
    """Which circuits a run's circuit_ranges file draws, as text: "" for none or for a file of the default ranges
    (the same circuits), else the ranges it holds, so that two files of the same ranges give the same key.

    Parameters
    ----------
    path : pathlib.Path or None
        A circuit_ranges file (None: none).

    Returns
    -------
    str
        "" or the ranges as JSON, keys sorted.

    Raises
    ------
    WorkbenchInputError
        The file is missing or cannot be read as ranges.
    """
    if path is None:
        return ""
    ranges = ranges_identity(path)[CIRCUITS_TABLE]
    if ranges == dataclasses.asdict(CircuitRanges()):
        return ""
    return json.dumps(ranges, sort_keys=True)


@functools.lru_cache(maxsize=64)
def _identity(path: str, size: int, mtime_ns: int) -> dict[str, Any]:
    return {CIRCUITS_TABLE: dataclasses.asdict(read_circuit_ranges(path))}


def planned_circuit_ranges(spec: Any) -> dict[Path, CircuitRanges]:
    """Each circuit_ranges file `spec` (a typed StudySpec) plans, read, by its (absolute) path; empty when it plans
    none. WorkbenchInputError for the refusals of the module docstring, naming the spec key.

    Parameters
    ----------
    spec : StudySpec
        The study, its values typed.

    Returns
    -------
    dict
        Absolute path -> the CircuitRanges it holds.

    Raises
    ------
    WorkbenchInputError
        A file that cannot be read as ranges, a study without a generated circuit, or several files in [grid]
        beside a scenario that is not a circuit.
    """
    planned = planned_values(spec).get(CIRCUIT_RANGES)
    if planned is None:
        return {}
    where, files = planned
    others = [s for s in spec.scenarios if not is_circuit(s)]
    if len(others) == len(spec.scenarios):
        raise WorkbenchInputError(
            f"{where} gives the ranges of generated circuits (circuit:SEED), and study.scenarios has none "
            f"({', '.join(spec.scenarios)}): add a circuit or drop {where}"
        )
    if others and where.startswith("grid.") and len(files) > 1:
        raise WorkbenchInputError(
            f"{where} lists {len(files)} files, and study.scenarios has {others[0]!r}, which is not a generated "
            "circuit: its runs would repeat alike, once per file; run it in a study of its own"
        )
    ranges: dict[Path, CircuitRanges] = {}
    for path in files:
        if path not in ranges:
            try:
                ranges[path] = read_circuit_ranges(path)
            except WorkbenchInputError as exc:
                raise WorkbenchInputError(f"{where}: {exc}") from None
    return ranges


def ranged_options(
    scenario: str, options: ScenarioOptions, ranges: Mapping[Path, CircuitRanges], base_dir: Path
) -> dict[str, ScenarioOptions]:
    """The ScenarioOptions the runs on `scenario` build it with, by a label for messages: a generated circuit's
    with each ranges planned ("circuit:7 (circuit_ranges 'ranges.toml')", the file relative to base_dir), any
    other scenario's (or every one when no ranges are planned) as given, under its own name.

    Parameters
    ----------
    scenario : str
        A scenario of the study.
    options : ScenarioOptions
        The options the scenario is built with, before the ranges.
    ranges : mapping
        Absolute path -> CircuitRanges (`planned_circuit_ranges`).
    base_dir : pathlib.Path
        The spec's folder, that the labels' paths are relative to.

    Returns
    -------
    dict
        Label -> ScenarioOptions, one per ranges file for a circuit, else one under the scenario's name.
    """
    if not ranges or not is_circuit(scenario):
        return {scenario: options}
    return {
        f"{scenario} ({CIRCUIT_RANGES} {os.path.relpath(path, base_dir)!r})": dataclasses.replace(
            options, circuit_ranges=circuit_ranges
        )
        for path, circuit_ranges in ranges.items()
    }


def check_circuits_table(document: Mapping[str, Any], spec_file: Path, named: Iterable[Path], how: str) -> None:
    """Refuse a spec's [circuits] table that no run reads: one is read only by runs whose circuit_ranges names the
    spec file itself (`named`: the circuit_ranges files the spec plans, absolute). how: where the spec names a
    file for circuit_ranges, for the message.

    Parameters
    ----------
    document : mapping
        The parsed spec.
    spec_file : pathlib.Path
        The spec's file.
    named : iterable of pathlib.Path
        The circuit_ranges files the spec plans, absolute.
    how : str
        Where the spec would name the file (e.g. "in [grid]"), for the message.

    Raises
    ------
    WorkbenchInputError
        The document has a [circuits] table and no planned circuit_ranges names the spec file.
    """
    if CIRCUITS_TABLE not in document:
        return
    own = Path(spec_file).resolve()
    if any(Path(path).resolve() == own for path in named):
        return
    raise WorkbenchInputError(
        f"[{CIRCUITS_TABLE}] holds circuit ranges, read by the runs whose circuit_ranges names this spec file, and "
        f"none does: give circuit_ranges = {own.name!r} {how}, or drop the table"
    )


__all__ = [
    "CIRCUIT_RANGES",
    "check_circuits_table",
    "drawn_ranges_key",
    "is_circuit",
    "planned_circuit_ranges",
    "ranged_options",
    "ranges_identity",
    "scenario_values",
]
