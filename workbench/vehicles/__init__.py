"""Vehicle models (plants), their presets and their registry.

`make_vehicle(name)` builds a model from its shipped preset (workbench/presets/<name>.toml);
`make_vehicle(vehicle_file=path)` from a user's TOML copy; `payload_kg` overrides the payload of vehicles that
have one. `VEHICLES` lists the names. Every model implements `workbench.vehicles.base.VehicleModel`.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import partial
from os import PathLike

from workbench.base.errors import WorkbenchInputError
from workbench.vehicles.base import STANDARD_OUTPUTS, VehicleGeometry, VehicleModel
from workbench.vehicles.commonroad_mb import CommonRoadMB, CommonRoadMBParams
from workbench.vehicles.dynamic_bicycle import DynamicBicycle, DynamicBicycleParams
from workbench.vehicles.kinematic_bicycle import KinematicBicycle, KinematicBicycleParams
from workbench.vehicles.presets import (
    MODEL_TYPES,
    TEMPLATE_ONLY_TYPES,
    list_presets,
    load_vehicle,
    preset_text,
    template_only_text,
)
from workbench.vehicles.tractor_semitrailer import TractorSemitrailer, TractorSemitrailerParams

#: name -> factory taking no arguments (the shipped preset of that name); a model type that exists only as a user's
#: vehicle file (`fmu`: TEMPLATE_ONLY_TYPES) has none.
VEHICLES: dict[str, Callable[[], VehicleModel]] = {
    name: partial(load_vehicle, name) for name in MODEL_TYPES if name not in TEMPLATE_ONLY_TYPES
}


def make_vehicle(
    name: str | None = None, payload_kg: float | None = None, vehicle_file: str | PathLike[str] | None = None
) -> VehicleModel:
    """Build a vehicle by registered name (its preset) or from a TOML vehicle file.

    With a file, `name` may be omitted; if given it must match the file's model type. `payload_kg` (kg) is only
    accepted by vehicles with a payload (the tractor-semitrailer); others raise WorkbenchInputError.
    """
    if vehicle_file is not None:
        vehicle = load_vehicle(str(vehicle_file), payload_kg)
        if name is not None and name != vehicle.name:
            raise WorkbenchInputError(
                f"vehicle {name!r} requested but {vehicle_file} describes a {vehicle.name!r}; drop one of them"
            )
        return vehicle
    if name in TEMPLATE_ONLY_TYPES:
        raise WorkbenchInputError(template_only_text(name))
    if name not in VEHICLES:
        raise WorkbenchInputError(f"unknown vehicle {name!r}; choose one of {', '.join(VEHICLES)}")
    return load_vehicle(name, payload_kg)


__all__ = [
    "STANDARD_OUTPUTS",
    "VEHICLES",
    "CommonRoadMB",
    "CommonRoadMBParams",
    "DynamicBicycle",
    "DynamicBicycleParams",
    "KinematicBicycle",
    "KinematicBicycleParams",
    "TractorSemitrailer",
    "TractorSemitrailerParams",
    "VehicleGeometry",
    "VehicleModel",
    "list_presets",
    "load_vehicle",
    "make_vehicle",
    "preset_text",
]
