"""Vehicle presets: TOML files naming a model type and every parameter of it, one to one.

A preset (workbench/presets/<name>.toml, shipped with the package) or a user's copy of one looks like

    [model]
    type = "tractor-semitrailer"           # one of MODEL_TYPES
    description = "..."                     # optional, shown by `workbench vehicles`
    [parameters]
    payload_kg = 17000.0                    # every field of the model's params dataclass, nothing else

Unknown or missing keys are rejected naming the key, the file and the allowed keys; values are then validated
by the params dataclass (which names the field and its allowed range).

A vehicle model written outside this repository is registered by the package that holds it, through the
entry-point group `lateral_workbench.vehicles` (`VEHICLE_ENTRY_POINTS`): `name = "module:ModelClass"`, where the
class is a `VehicleModel` whose `name` is that name and whose `params_type` is its params dataclass, every field
with a default. Its preset is those defaults (`workbench vehicles --show NAME` prints it as a vehicle file), and a
vehicle file of its type works as any other (examples/plugin/ is such a package).
"""

from __future__ import annotations

import dataclasses
import importlib
import os
import sys
from importlib import resources
from pathlib import Path
from typing import TYPE_CHECKING, Any

from workbench.base.entry_points import installed_entry_points
from workbench.base.errors import WorkbenchInputError, value_text
from workbench.base.input_files import parse_toml, read_text
from workbench.base.toml_text import toml_value
from workbench.base.typed_tables import check_keys, dataclass_from_table
from workbench.vehicles.base import VehicleModel
from workbench.vehicles.commonroad_mb import CommonRoadMB, CommonRoadMBParams
from workbench.vehicles.dynamic_bicycle import DynamicBicycle, DynamicBicycleParams
from workbench.vehicles.fmu_plant import FmuPlant
from workbench.vehicles.fmu_plant_params import FmuPlantParams
from workbench.vehicles.kinematic_bicycle import KinematicBicycle, KinematicBicycleParams
from workbench.vehicles.tractor_semitrailer import TractorSemitrailer, TractorSemitrailerParams

if TYPE_CHECKING:
    from _typeshed import DataclassInstance

#: model type -> (model class, params dataclass).
MODEL_TYPES: dict[str, tuple[type[VehicleModel], type[DataclassInstance]]] = {
    KinematicBicycle.name: (KinematicBicycle, KinematicBicycleParams),
    DynamicBicycle.name: (DynamicBicycle, DynamicBicycleParams),
    TractorSemitrailer.name: (TractorSemitrailer, TractorSemitrailerParams),
    CommonRoadMB.name: (CommonRoadMB, CommonRoadMBParams),
    FmuPlant.name: (FmuPlant, FmuPlantParams),
}
#: Model types that exist only as a user's vehicle file (they wrap the user's own model, so nothing is shipped to
#: run): `workbench vehicles --show NAME` prints the template workbench/presets/templates/NAME.toml.
TEMPLATE_ONLY_TYPES: tuple[str, ...] = (FmuPlant.name,)
#: The entry-point group in which an installed package registers vehicle models ("module:ModelClass").
VEHICLE_ENTRY_POINTS = "lateral_workbench.vehicles"
_TOP_KEYS = ("model", "parameters")
_MODEL_KEYS = ("type", "description")


def _installed_model_types() -> dict[str, tuple[type[VehicleModel], type[DataclassInstance]]]:
    """The vehicle models installed packages register (`VEHICLE_ENTRY_POINTS`), each checked; one that cannot be
    imported or breaks the rules (module docstring) is left out with a warning on stderr saying why."""
    found = {}
    for name, (module, attr, package) in installed_entry_points(VEHICLE_ENTRY_POINTS, set(MODEL_TYPES)).items():
        where = f"vehicle {name!r} (registered by {package} as {module}:{attr})"
        try:
            cls = getattr(importlib.import_module(module), attr)
        except Exception as exc:  # a third-party import may raise anything: it must not stop the workbench
            why = f"cannot be imported: {type(exc).__name__}: {exc}"
        else:
            params_type = getattr(cls, "params_type", None)
            if not (isinstance(cls, type) and issubclass(cls, VehicleModel)):
                why = f"is not a workbench.vehicles.base.VehicleModel subclass; got {cls!r}"
            elif getattr(cls, "name", None) != name:
                why = f"its class's name is {getattr(cls, 'name', None)!r}, not {name!r}"
            elif not (isinstance(params_type, type) and dataclasses.is_dataclass(params_type)):
                why = f"its params_type must be a dataclass; got {params_type!r}"
            else:
                found[name] = (cls, params_type)
                continue
        print(f"lateral-workbench: warning: {where} left out: {why}", file=sys.stderr)
    return found


#: model type -> (model class, params dataclass) of the models installed packages register.
INSTALLED_MODEL_TYPES = _installed_model_types()
MODEL_TYPES.update(INSTALLED_MODEL_TYPES)


def _preset_dir() -> Any:
    return resources.files("workbench").joinpath("presets")


def list_presets() -> dict[str, str]:
    """Preset name -> its description, for every TOML file shipped in workbench/presets, then every installed
    package's vehicle model (its preset: its params' defaults).

    Returns
    -------
    dict of str to str
        Preset name -> its one-line description, the shipped presets in alphabetical order, then the installed
        models.
    """
    found = {}
    for entry in sorted(_preset_dir().iterdir(), key=lambda e: e.name):
        if entry.name.endswith(".toml"):
            model = parse_toml(entry.read_text(encoding="utf-8"), f"preset {entry.name}").get("model", {})
            found[entry.name.removesuffix(".toml")] = str(model.get("description", model.get("type", "")))
    for name, (cls, _) in INSTALLED_MODEL_TYPES.items():
        found[name] = (cls.__doc__ or name).strip().splitlines()[0]
    return found


def preset_text(name: str) -> str:
    """The TOML text of a preset (to copy and edit): a shipped file, an installed model's defaults, or the template
    of a model type that exists only as a user's file (TEMPLATE_ONLY_TYPES).

    Parameters
    ----------
    name : str
        A preset (`list_presets`) or a template-only model type ("fmu").

    Returns
    -------
    str
        The TOML text: a [model] table with the type and description and a [parameters] table with every
        parameter of the model, which `load_vehicle` reads back.

    Raises
    ------
    WorkbenchInputError
        When `name` is neither a preset nor a template-only model type (the message lists the presets).
    """
    if name in TEMPLATE_ONLY_TYPES:
        return _preset_dir().joinpath("templates", f"{name}.toml").read_text(encoding="utf-8")
    if name not in list_presets():
        raise WorkbenchInputError(f"unknown vehicle preset {name!r}; choose one of {', '.join(list_presets())}")
    if name in INSTALLED_MODEL_TYPES:
        defaults = INSTALLED_MODEL_TYPES[name][1]()
        lines = ["[model]", f'type = "{name}"', f"description = {toml_value(list_presets()[name])}", "", "[parameters]"]
        lines += [f"{f.name} = {toml_value(getattr(defaults, f.name))}" for f in dataclasses.fields(defaults)]
        return "\n".join(lines) + "\n"
    return _preset_dir().joinpath(f"{name}.toml").read_text(encoding="utf-8")


def template_only_text(name: str) -> str:
    """The refusal of a template-only model type (TEMPLATE_ONLY_TYPES) asked for by name: it needs the user's file."""
    return (
        f"vehicle {name!r} is your own model and needs its vehicle file: `workbench vehicles --show {name} > "
        f"my.toml` prints a template; fill it in and pass --vehicle-file my.toml"
    )


def carries_payload(model_type: str) -> bool:
    """Whether vehicles of this model type (a key of MODEL_TYPES) carry a payload (`payload_kg`)."""
    return "payload_kg" in MODEL_TYPES[model_type][1].__dataclass_fields__


def params_from_toml(text: str, source: str, base_dir: Path | None = None) -> tuple[str, Any]:
    """Parse preset TOML text into (model type, params instance). `source` names the file in messages; a relative
    file path in it (an FMU's) is relative to `base_dir` (the vehicle file's folder)."""
    doc = check_keys(f"{source}: top level", parse_toml(text, source), _TOP_KEYS, _TOP_KEYS)
    model = check_keys(f"{source}: [model]", doc["model"], _MODEL_KEYS)
    kind = model.get("type")
    if kind not in MODEL_TYPES:
        raise WorkbenchInputError(f"{source}: [model] type must be one of {', '.join(MODEL_TYPES)}; got {kind!r}")
    try:
        params = dataclass_from_table(MODEL_TYPES[kind][1], doc["parameters"], "[parameters]", base_dir, required=True)
        return kind, params
    except WorkbenchInputError as exc:
        raise WorkbenchInputError(f"{source}: {exc}") from None


def load_vehicle(name_or_file: str, payload_kg: float | None = None) -> VehicleModel:
    """Build a vehicle from a shipped preset name or a TOML file; payload_kg overrides the preset's payload.

    `make_vehicle` is the same with a registered name or a file given apart; this takes either in one argument, as
    the command line's --vehicle does.

    Parameters
    ----------
    name_or_file : str
        A preset (`list_presets`) or the path of a TOML vehicle file; a relative file path inside the file (an
        FMU's) is taken relative to the file's folder.
    payload_kg : float or None
        The payload (kg) in place of the preset's or the file's, for a model type with a payload; None keeps it.

    Returns
    -------
    VehicleModel
        The vehicle the preset or file describes.

    Raises
    ------
    WorkbenchInputError
        Neither a preset nor an existing file, an unreadable or malformed file (an unknown model type, an unknown
        or missing key, a parameter out of its range: the message names the file, the key and the allowed values),
        or a payload for a vehicle without one.

    Examples
    --------
    >>> from workbench.vehicles.presets import load_vehicle, preset_text
    >>> load_vehicle("dynamic-bicycle").name
    'dynamic-bicycle'
    >>> text = preset_text("dynamic-bicycle")  # write it to my_car.toml, edit, then:
    >>> load_vehicle("my_car.toml")  # doctest: +SKIP
    """
    base_dir = None
    if name_or_file in list_presets():
        source = f"preset {name_or_file!r}"
        text = preset_text(name_or_file)
    else:
        path = Path(name_or_file)
        if name_or_file in TEMPLATE_ONLY_TYPES and not os.path.lexists(path):
            raise WorkbenchInputError(template_only_text(name_or_file))
        if not os.path.lexists(path):
            raise WorkbenchInputError(
                f"unknown vehicle {name_or_file!r}: neither a preset ({', '.join(list_presets())}) "
                "nor an existing TOML file"
            )
        source = str(path)
        text = read_text(path, f"vehicle file {source}")
        base_dir = path.parent
    kind, params = params_from_toml(text, source, base_dir)
    try:
        model = MODEL_TYPES[kind][0](params)
    except WorkbenchInputError as exc:  # a model that checks more when built (an FMU against its mapping)
        raise WorkbenchInputError(f"{source}: {exc}") from None
    return model if payload_kg is None else with_payload(model, payload_kg)


def with_payload(model: VehicleModel, payload_kg: float) -> VehicleModel:
    """The same vehicle carrying payload_kg instead of its own payload (a model type with a payload only)."""
    kind = model.name
    if not carries_payload(kind):
        carriers = [k for k in MODEL_TYPES if carries_payload(k)]
        raise WorkbenchInputError(f"vehicle {kind!r} has no payload; a payload applies to: {', '.join(carriers)}")
    if isinstance(payload_kg, bool) or not isinstance(payload_kg, int | float):
        raise WorkbenchInputError(f"payload_kg must be a number; got {value_text(payload_kg)}")
    return MODEL_TYPES[kind][0](dataclasses.replace(model.params, payload_kg=float(payload_kg)))
