"""Lateral controllers and their registry.

Every controller implements `controllers.base.Controller`; `make_controller(name, geometry)` builds one by its
registered name and `CONTROLLERS` lists them.

Importing this package is cheap (issue 17): `CONTROLLERS` knows each controller's name and where it lives, and
imports a controller's module (python-control for the clothoid controller's lead filter, CasADi and OSQP for the
MPCs) only when that controller is looked up by name (`CONTROLLERS[name]`, `.items()`, `.values()`). The classes
and configs exported here (`from controllers import PurePursuit`) are imported on first access too.
"""

from __future__ import annotations

import importlib
from collections.abc import Iterator, Mapping
from typing import TYPE_CHECKING, Any

from workbench.base.compiled_cache import use_versioned_numba_cache

use_versioned_numba_cache()  # before any controller module imports numba (workbench/base/compiled_cache.py)

if TYPE_CHECKING:
    from controllers.base import Controller, Measurement
    from controllers.clothoid import ClothoidConfig, ClothoidController
    from controllers.mpc import LMPCConfig, LMPCController, NMPCConfig, NMPCController
    from controllers.pure_pursuit import PurePursuit, PurePursuitConfig
    from controllers.stanley import Stanley, StanleyConfig
    from workbench.vehicles.geometry import VehicleGeometry

#: Exported name -> the module that defines it (imported on first access, `__getattr__`).
_EXPORTS = {
    "Controller": "controllers.base",
    "Measurement": "controllers.base",
    "ClothoidConfig": "controllers.clothoid",
    "ClothoidController": "controllers.clothoid",
    "LMPCConfig": "controllers.mpc",
    "LMPCController": "controllers.mpc",
    "NMPCConfig": "controllers.mpc",
    "NMPCController": "controllers.mpc",
    "PurePursuit": "controllers.pure_pursuit",
    "PurePursuitConfig": "controllers.pure_pursuit",
    "Stanley": "controllers.stanley",
    "StanleyConfig": "controllers.stanley",
}


class ControllerRegistry(Mapping[str, "type[Controller]"]):
    """name -> controller class, in a fixed order; a class's module is imported when it is first looked up.

    `name in CONTROLLERS`, `len(CONTROLLERS)` and iterating the names import nothing; `CONTROLLERS[name]`,
    `.get`, `.items()` and `.values()` import the modules of the classes they return.
    """

    def __init__(self, entries: Mapping[str, tuple[str, str]]) -> None:
        self._entries = dict(entries)  # name -> (module, class name)
        self._loaded: dict[str, type[Controller]] = {}

    def __getitem__(self, name: str) -> type[Controller]:
        try:
            return self._loaded[name]
        except KeyError:
            pass
        module, attr = self._entries[name]  # KeyError for an unknown name, as a dict
        cls = getattr(importlib.import_module(module), attr)
        if cls.name != name:
            raise RuntimeError(f"controllers: {module}.{attr}.name is {cls.name!r}, registered as {name!r}")
        self._loaded[name] = cls
        return cls

    def __contains__(self, name: object) -> bool:
        return name in self._entries

    def __iter__(self) -> Iterator[str]:
        return iter(self._entries)

    def __len__(self) -> int:
        return len(self._entries)

    def __repr__(self) -> str:
        return f"ControllerRegistry({', '.join(self._entries)})"


#: name -> controller class, in the order `workbench controllers` lists them.
CONTROLLERS: ControllerRegistry = ControllerRegistry(
    {
        "clothoid": ("controllers.clothoid", "ClothoidController"),
        "pure-pursuit": ("controllers.pure_pursuit", "PurePursuit"),
        "stanley": ("controllers.stanley", "Stanley"),
        "nmpc": ("controllers.mpc", "NMPCController"),
        "lmpc": ("controllers.mpc", "LMPCController"),
    }
)


def make_controller(
    name: str, geometry: VehicleGeometry, config: object | None = None, vehicle: object | None = None
) -> Controller:
    """Build the controller registered under `name` for a vehicle, with its default config unless one is given.
    `vehicle` (the steered `VehicleModel`) gives model-based controllers (the MPCs) their prediction parameters."""
    if name not in CONTROLLERS:
        from workbench.base.errors import WorkbenchInputError

        raise WorkbenchInputError(f"unknown controller {name!r}; choose one of {', '.join(CONTROLLERS)}")
    return CONTROLLERS[name](geometry, config, vehicle=vehicle)


def __getattr__(name: str) -> Any:
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value  # later lookups skip this function
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_EXPORTS))


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
