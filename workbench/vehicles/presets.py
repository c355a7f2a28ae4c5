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

from workbench.base.errors import WorkbenchInputError, value_text
from workbench.base.input_files import parse_toml, read_text
from workbench.base.typed_tables import check_keys, dataclass_from_table
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


def carries_payload(model_type: str) -> bool:
    """Whether vehicles of this model type (a key of MODEL_TYPES) carry a payload (`payload_kg`)."""
    return "payload_kg" in MODEL_TYPES[model_type][1].__dataclass_fields__


def params_from_toml(text: str, source: str) -> tuple[str, Any]:
    """Parse preset TOML text into (model type, params instance). `source` names the file in messages."""
    doc = check_keys(f"{source}: top level", parse_toml(text, source), _TOP_KEYS, _TOP_KEYS)
    model = check_keys(f"{source}: [model]", doc["model"], _MODEL_KEYS)
    kind = model.get("type")
    if kind not in MODEL_TYPES:
        raise WorkbenchInputError(f"{source}: [model] type must be one of {', '.join(MODEL_TYPES)}; got {kind!r}")
    try:
        return kind, dataclass_from_table(MODEL_TYPES[kind][1], doc["parameters"], "[parameters]", required=True)
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
        if not carries_payload(kind):
            carriers = [k for k in MODEL_TYPES if carries_payload(k)]
            raise WorkbenchInputError(f"vehicle {kind!r} has no payload; a payload applies to: {', '.join(carriers)}")
        if isinstance(payload_kg, bool) or not isinstance(payload_kg, int | float):
            raise WorkbenchInputError(f"payload_kg must be a number; got {value_text(payload_kg)}")
        params = dataclasses.replace(params, payload_kg=float(payload_kg))
    return MODEL_TYPES[kind][0](params)
