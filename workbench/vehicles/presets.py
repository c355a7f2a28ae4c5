"""Vehicle presets: TOML files naming a model type and every parameter of it, one to one.

A preset (workbench/presets/<name>.toml, shipped with the package) or a user's copy of one looks like

    [model]
    type = "tractor-semitrailer"           # one of MODEL_TYPES
    description = "..."                     # optional, shown by `workbench vehicles`
    [parameters]
    payload_kg = 17000.0                    # every field of the model's params dataclass, nothing else

Unknown or missing keys are rejected naming the key, the file and the allowed keys; values are then validated
by the params dataclass (which names the field and its allowed range).
"""

from __future__ import annotations

import dataclasses
import os
from importlib import resources
from pathlib import Path
from typing import Any

from workbench.errors import WorkbenchInputError, value_text
from workbench.input_files import parse_toml, read_text
from workbench.vehicles.base import VehicleModel
from workbench.vehicles.commonroad_mb import CommonRoadMB, CommonRoadMBParams
from workbench.vehicles.dynamic_bicycle import DynamicBicycle, DynamicBicycleParams
from workbench.vehicles.kinematic_bicycle import KinematicBicycle, KinematicBicycleParams
from workbench.vehicles.tractor_semitrailer import TractorSemitrailer, TractorSemitrailerParams

#: model type -> (model class, params dataclass).
MODEL_TYPES: dict[str, tuple[type[VehicleModel], type]] = {
    KinematicBicycle.name: (KinematicBicycle, KinematicBicycleParams),
    DynamicBicycle.name: (DynamicBicycle, DynamicBicycleParams),
    TractorSemitrailer.name: (TractorSemitrailer, TractorSemitrailerParams),
    CommonRoadMB.name: (CommonRoadMB, CommonRoadMBParams),
}
_TOP_KEYS = ("model", "parameters")
_MODEL_KEYS = ("type", "description")


def _preset_dir() -> Any:
    return resources.files("workbench").joinpath("presets")


def list_presets() -> dict[str, str]:
    """Preset name -> its description, for every TOML file shipped in workbench/presets."""
    found = {}
    for entry in sorted(_preset_dir().iterdir(), key=lambda e: e.name):
        if entry.name.endswith(".toml"):
            model = parse_toml(entry.read_text(encoding="utf-8"), f"preset {entry.name}").get("model", {})
            found[entry.name.removesuffix(".toml")] = str(model.get("description", model.get("type", "")))
    return found


def preset_text(name: str) -> str:
    """The TOML text of a shipped preset (to copy and edit)."""
    if name not in list_presets():
        raise WorkbenchInputError(f"unknown vehicle preset {name!r}; choose one of {', '.join(list_presets())}")
    return _preset_dir().joinpath(f"{name}.toml").read_text(encoding="utf-8")


def _check_keys(kind: str, got: dict[str, Any], allowed: tuple[str, ...], source: str, required: bool) -> None:
    for key in got:
        if key not in allowed:
            raise WorkbenchInputError(f"{source}: unknown {kind} key {key!r}; allowed keys: {', '.join(allowed)}")
    if required:
        for key in allowed:
            if key not in got:
                raise WorkbenchInputError(
                    f"{source}: missing {kind} key {key!r}; every one of these must be given: {', '.join(allowed)}"
                )


def _coerce(name: str, value: Any, annotation: Any, source: str) -> Any:
    """TOML integers are accepted for float fields; anything else must already have the field's type."""
    want = annotation if isinstance(annotation, str) else getattr(annotation, "__name__", str(annotation))
    if want == "float" and isinstance(value, int | float) and not isinstance(value, bool):
        return float(value)
    if want == "int" and isinstance(value, int) and not isinstance(value, bool):
        return value
    raise WorkbenchInputError(f"{source}: parameter {name!r} must be a number ({want}); got {value_text(value)}")


def params_from_toml(text: str, source: str) -> tuple[str, Any]:
    """Parse preset TOML text into (model type, params instance). `source` names the file in messages."""
    doc = parse_toml(text, source)
    _check_keys("top-level", doc, _TOP_KEYS, source, required=True)
    model, given = doc["model"], doc["parameters"]
    if not isinstance(model, dict) or not isinstance(given, dict):
        raise WorkbenchInputError(f"{source}: [model] and [parameters] must be tables")
    _check_keys("[model]", model, _MODEL_KEYS, source, required=False)
    kind = model.get("type")
    if kind not in MODEL_TYPES:
        raise WorkbenchInputError(f"{source}: [model] type must be one of {', '.join(MODEL_TYPES)}; got {kind!r}")
    params_cls = MODEL_TYPES[kind][1]
    fields = {f.name: f for f in dataclasses.fields(params_cls)}
    _check_keys("[parameters]", given, tuple(fields), source, required=True)
    values = {name: _coerce(name, value, fields[name].type, source) for name, value in given.items()}
    try:
        return kind, params_cls(**values)
    except WorkbenchInputError as exc:
        raise WorkbenchInputError(f"{source}: {exc}") from None


def load_vehicle(name_or_file: str, payload_kg: float | None = None) -> VehicleModel:
    """Build a vehicle from a shipped preset name or a TOML file; payload_kg overrides the preset's payload."""
    if name_or_file in list_presets():
        source = f"preset {name_or_file!r}"
        text = _preset_dir().joinpath(f"{name_or_file}.toml").read_text(encoding="utf-8")
    else:
        path = Path(name_or_file)
        if not os.path.lexists(path):
            raise WorkbenchInputError(
                f"unknown vehicle {name_or_file!r}: neither a preset ({', '.join(list_presets())}) "
                "nor an existing TOML file"
            )
        source = str(path)
        text = read_text(path, f"vehicle file {source}")
    kind, params = params_from_toml(text, source)
    if payload_kg is not None:
        if "payload_kg" not in {f.name for f in dataclasses.fields(params)}:
            carriers = [k for k, (_, cls) in MODEL_TYPES.items() if "payload_kg" in cls.__dataclass_fields__]
            raise WorkbenchInputError(f"vehicle {kind!r} has no payload; a payload applies to: {', '.join(carriers)}")
        if isinstance(payload_kg, bool) or not isinstance(payload_kg, int | float):
            raise WorkbenchInputError(f"payload_kg must be a number; got {value_text(payload_kg)}")
        params = dataclasses.replace(params, payload_kg=float(payload_kg))
    return MODEL_TYPES[kind][0](params)
