"""The lead-filter file: what `tuning` writes and the clothoid controller reads (JSON, or TOML by the .toml suffix).

    {"format": "lead-filter/1", "omega_z_rad_s": 4.44, "psi": 0.8, "omega_p_rad_s": 13.32, "dc_gain": 1.0,
     "source": "how it was designed", "plant": {"omega_n_rad_s": 4.44, "zeta": 0.8}, "speed_kmh": 30,
     "schedule": [{"speed_kmh": 20, "omega_z_rad_s": ..., "psi": ..., "omega_p_rad_s": ...}, ...],
     "design": {"bandwidth_rad_s": 6.8, ...}}

Required: format, omega_z_rad_s, psi, omega_p_rad_s (Eq. 6; rad/s, -, rad/s). Optional: dc_gain (must be 1: Eq. 6
has unit DC gain), source (free text), plant (the Eq. 5 lag the filter was designed for), speed_kmh (the design
speed of the top-level filter), schedule (filters against speed, km/h strictly increasing; when present it is what
the controller uses, and the top-level filter is the nominal design kept for readers that ignore schedules) and
design (free design metadata such as bandwidths; a tuning directory's lead file keeps its identified lags and
floors there, which `tuning_dirs` reads into a `VehicleTuning`; the schedule itself ignores it).
Any other key is an error, so that a misspelt key is not silently ignored.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from controllers.clothoid.filter_schedule import PARAM_KEYS, SPEED_RANGE_KMH, FilterSchedule
from controllers.clothoid.lead_filter import LeadFilterParams
from workbench.base.errors import WorkbenchInputError, require_in_range
from workbench.base.input_files import read_json, read_toml
from workbench.base.toml_text import toml_key, toml_value
from workbench.base.typed_tables import check_keys

FORMAT_TAG = "lead-filter/1"
REQUIRED_KEYS = ("format", *PARAM_KEYS)
OPTIONAL_KEYS = ("dc_gain", "source", "plant", "speed_kmh", "schedule", "design")
PLANT_KEYS = ("omega_n_rad_s", "zeta")
SCHEDULE_KEYS = ("speed_kmh", *PARAM_KEYS)


def _fail(path: Path, problem: str) -> WorkbenchInputError:
    return WorkbenchInputError(f"lead filter file {path}: {problem}")


def _suffix(path: Path) -> str:
    suffix = path.suffix.lower()
    if suffix not in (".json", ".toml"):
        raise _fail(path, f"the name must end in .json or .toml; got {suffix or 'no suffix'!r}")
    return suffix


def _check_keys(path: Path, where: str, table: object, required: tuple[str, ...], optional: tuple[str, ...]) -> dict:
    return check_keys(f"lead filter file {path}: {where}", table, (*required, *optional), required)


def _number(path: Path, name: str, value: object) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise _fail(path, f"{name} must be a number; got {value!r}")
    return float(value)


def _params(path: Path, where: str, table: Mapping) -> LeadFilterParams:
    values = [_number(path, f"{where}{k}", table[k]) for k in PARAM_KEYS]
    try:
        return LeadFilterParams(*values)
    except WorkbenchInputError as exc:
        raise _fail(path, f"{where}{exc}") from None


def read_filter_file(path: str | Path) -> FilterSchedule:
    """Read a lead-filter file (format above) into a FilterSchedule; WorkbenchInputError naming the file and the
    problem for anything it cannot use."""
    path = Path(path)
    suffix = _suffix(path)
    label = f"lead filter file {path}"
    doc = read_json(path, label) if suffix == ".json" else read_toml(path, label)
    if isinstance(doc, Mapping) and "format" in doc and doc["format"] != FORMAT_TAG:
        raise _fail(path, f"format is {doc['format']!r}; expected {FORMAT_TAG!r}")
    doc = _check_keys(path, "top level", doc, REQUIRED_KEYS, OPTIONAL_KEYS)
    nominal = _params(path, "", doc)
    if "dc_gain" in doc and abs(_number(path, "dc_gain", doc["dc_gain"]) - 1.0) > 1e-6:
        raise _fail(path, f"dc_gain must be 1 (Eq. 6 has unit DC gain); got {doc['dc_gain']!r}")
    source = doc.get("source", "")
    if not isinstance(source, str):
        raise _fail(path, f"source must be text; got {source!r}")
    speed = _number(path, "speed_kmh", doc["speed_kmh"]) if "speed_kmh" in doc else None
    if speed is not None:
        try:
            require_in_range("speed_kmh", speed, *SPEED_RANGE_KMH, "km/h")
        except WorkbenchInputError as exc:
            raise _fail(path, str(exc)) from None
    if "plant" in doc:
        plant = _check_keys(path, "plant", doc["plant"], PLANT_KEYS, ())
        try:  # the Eq. 5 lag: the same ranges as the filter's zeros
            LeadFilterParams.from_lag(*(_number(path, f"plant.{k}", plant[k]) for k in PLANT_KEYS))
        except WorkbenchInputError as exc:
            raise _fail(path, f"plant.{exc}") from None
    if "design" in doc and not isinstance(doc["design"], Mapping):
        raise _fail(path, f"design must be a table/object; got {doc['design']!r}")
    if "schedule" not in doc:
        return FilterSchedule((0.0 if speed is None else speed,), (nominal,), source)
    entries = doc["schedule"]
    if not isinstance(entries, list) or not entries:
        raise _fail(path, f"schedule must be a non-empty list of tables; got {entries!r}")
    speeds, params = [], []
    for i, entry in enumerate(entries):
        entry = _check_keys(path, f"schedule[{i}]", entry, SCHEDULE_KEYS, ())
        speeds.append(_number(path, f"schedule[{i}].speed_kmh", entry["speed_kmh"]))
        params.append(_params(path, f"schedule[{i}].", entry))
    try:
        return FilterSchedule(tuple(speeds), tuple(params), source)
    except WorkbenchInputError as exc:
        raise _fail(path, str(exc)) from None


def _check_value(name: str, value: object) -> None:
    """Design metadata must be representable in both JSON and TOML: text, booleans, finite numbers, lists, tables."""
    if isinstance(value, Mapping):
        for k, v in value.items():
            if not isinstance(k, str):
                raise WorkbenchInputError(f"{name} keys must be text; got {k!r}")
            _check_value(f"{name}.{k}", v)
    elif isinstance(value, list | tuple):
        for i, v in enumerate(value):
            _check_value(f"{name}[{i}]", v)
    elif isinstance(value, float) and not math.isfinite(value):
        raise WorkbenchInputError(f"{name} must be finite; got {value!r}")
    elif not isinstance(value, str | bool | int | float):
        raise WorkbenchInputError(f"{name} must be text, a boolean, a number, a list or a table; got {value!r}")


def _to_toml(doc: Mapping[str, Any]) -> str:
    """The few TOML shapes this format needs: top-level values, then [plant] and [[schedule]] tables."""
    tables = ("plant", "schedule")
    lines = [f"{toml_key(k)} = {toml_value(v)}" for k, v in doc.items() if k not in tables]
    if "plant" in doc:
        lines += ["", "[plant]", *(f"{k} = {toml_value(v)}" for k, v in doc["plant"].items())]
    for entry in doc.get("schedule", ()):
        lines += ["", "[[schedule]]", *(f"{k} = {toml_value(v)}" for k, v in entry.items())]
    return "\n".join(lines) + "\n"


def write_filter_file(
    path: str | Path,
    params_or_schedule: LeadFilterParams | FilterSchedule,
    *,
    source: str,
    plant: Mapping[str, float] | None = None,
    speed_kmh: float | None = None,
    extra: Mapping[str, Any] | None = None,
) -> Path:
    """Write a lead-filter file and return its path (JSON, or TOML for a .toml name). source: how the filter was
    designed (free text); plant: the Eq. 5 lag {"omega_n_rad_s", "zeta"} it was designed for; speed_kmh: the
    design speed (km/h); extra: design metadata (e.g. bandwidths), stored under "design". For a schedule, the
    top-level filter is the one at speed_kmh (by default the first speed of the schedule)."""
    path = Path(path)
    suffix = _suffix(path)
    if not isinstance(source, str):
        raise WorkbenchInputError(f"source must be text; got {source!r}")
    if isinstance(params_or_schedule, FilterSchedule):
        schedule: FilterSchedule | None = params_or_schedule
        if speed_kmh is None:
            speed_kmh = params_or_schedule.speeds_kmh[0]
        nominal = params_or_schedule.at_speed(speed_kmh)
    elif isinstance(params_or_schedule, LeadFilterParams):
        schedule, nominal = None, params_or_schedule
    else:
        raise WorkbenchInputError(
            f"write_filter_file needs LeadFilterParams or a FilterSchedule; got {params_or_schedule!r}"
        )
    doc: dict[str, Any] = {"format": FORMAT_TAG, **{k: getattr(nominal, k) for k in PARAM_KEYS}}
    doc["dc_gain"] = nominal.dc_gain
    doc["source"] = source
    if speed_kmh is not None:
        require_in_range("speed_kmh", speed_kmh, *SPEED_RANGE_KMH, "km/h")
        doc["speed_kmh"] = float(speed_kmh)
    if extra:
        _check_value("extra", dict(extra))
        doc["design"] = dict(extra)
    if plant is not None:
        if set(plant) != set(PLANT_KEYS):
            raise WorkbenchInputError(f"plant must have exactly the keys {list(PLANT_KEYS)}; got {list(plant)}")
        LeadFilterParams.from_lag(plant["omega_n_rad_s"], plant["zeta"])  # validates the ranges
        doc["plant"] = {k: float(plant[k]) for k in PLANT_KEYS}
    if schedule is not None:
        doc["schedule"] = [
            {"speed_kmh": s, **{k: getattr(p, k) for k in PARAM_KEYS}}
            for s, p in zip(schedule.speeds_kmh, schedule.params, strict=True)
        ]
    text = json.dumps(doc, indent=2, allow_nan=False) + "\n" if suffix == ".json" else _to_toml(doc)
    try:
        path.write_text(text, encoding="utf-8")
    except OSError as exc:
        raise WorkbenchInputError(f"lead filter file {path}: cannot be written: {exc}") from None
    return path
