"""Lateral controllers and their registry.

Every controller implements `controllers.base.Controller`; `make_controller(name, geometry)` builds one by its
registered name and `CONTROLLERS` lists them.
"""

from __future__ import annotations

from controllers.base import Controller, Measurement
from controllers.clothoid import ClothoidConfig, ClothoidController
from controllers.mpc import LMPCConfig, LMPCController, NMPCConfig, NMPCController
from controllers.pure_pursuit import PurePursuit, PurePursuitConfig
from controllers.stanley import Stanley, StanleyConfig
from workbench.errors import WorkbenchInputError
from workbench.vehicles.base import VehicleGeometry

#: name -> controller class, in the order `workbench controllers` lists them.
CONTROLLERS: dict[str, type[Controller]] = {
    ClothoidController.name: ClothoidController,
    PurePursuit.name: PurePursuit,
    Stanley.name: Stanley,
    NMPCController.name: NMPCController,
    LMPCController.name: LMPCController,
}


def make_controller(
    name: str, geometry: VehicleGeometry, config: object | None = None, vehicle: object | None = None
) -> Controller:
    """Build the controller registered under `name` for a vehicle, with its default config unless one is given.
    `vehicle` (the steered `VehicleModel`) gives model-based controllers (the MPCs) their prediction parameters."""
    try:
        cls = CONTROLLERS[name]
    except KeyError:
        raise WorkbenchInputError(f"unknown controller {name!r}; choose one of {', '.join(CONTROLLERS)}") from None
    return cls(geometry, config, vehicle=vehicle)


__all__ = [
    "CONTROLLERS",
    "ClothoidConfig",
    "ClothoidController",
    "Controller",
    "LMPCConfig",
    "LMPCController",
    "Measurement",
    "NMPCConfig",
    "NMPCController",
    "PurePursuit",
    "PurePursuitConfig",
    "Stanley",
    "StanleyConfig",
    "make_controller",
]
