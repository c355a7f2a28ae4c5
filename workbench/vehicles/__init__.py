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

    Parameters
    ----------
    name : str or None
        A registered vehicle (`VEHICLES`: "kinematic-bicycle", "dynamic-bicycle", "tractor-semitrailer",
        "commonroad-mb" and any an installed package registers); None with `vehicle_file`.
    payload_kg : float or None
        The payload (kg, 0 to 40000 for the tractor-semitrailer) in place of the preset's or the file's; None
        keeps it.
    vehicle_file : str or os.PathLike or None
        A TOML vehicle file (`workbench vehicles --show NAME` prints one to copy and edit); None for the preset.

    Returns
    -------
    VehicleModel
        The vehicle, ready to simulate; ``vehicle.geometry`` is what controllers are built for.

    Raises
    ------
    WorkbenchInputError
        An unknown name (the message lists the registered ones), a model type that needs its own file (``fmu``), a
        name that does not match the file's model type, a malformed file or a parameter out of its range, or a
        payload for a vehicle without one.

    Examples
    --------
    >>> from workbench.vehicles import make_vehicle
    >>> car = make_vehicle("kinematic-bicycle")
    >>> car.geometry.wheelbase_m
    2.579
    >>> truck = make_vehicle("tractor-semitrailer", payload_kg=10000.0)
    >>> truck.params.payload_kg
    10000.0
    >>> mine = make_vehicle(vehicle_file="my_car.toml")  # doctest: +SKIP
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
