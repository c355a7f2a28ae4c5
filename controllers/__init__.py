"""Lateral controllers and their registry.

Every controller implements `controllers.base.Controller`; `make_controller(name, geometry)` builds one by its
registered name and `CONTROLLERS` lists them.

A controller written outside this repository is registered by the package that holds it, through the entry-point
group `lateral_workbench.controllers` (`CONTROLLER_ENTRY_POINTS`): in its pyproject.toml,

    [project.entry-points."lateral_workbench.controllers"]
    my-controller = "my_package.my_module:MyController"

once that package is installed, `my-controller` is run by `workbench run/compare`, the studies and
`make_controller` like the controllers here (examples/plugin/ is such a package).

Importing this package is cheap: `CONTROLLERS` knows each controller's name and where it lives, and
imports a controller's module (python-control for the clothoid controller's lead filter, CasADi and OSQP for the
MPCs) only when that controller is looked up by name (`CONTROLLERS[name]`, `.items()`, `.values()`). The classes
and configs exported here (`from controllers import PurePursuit`) are imported on first access too.
"""

from __future__ import annotations

import dataclasses
import importlib
from collections.abc import Iterator, Mapping
from typing import TYPE_CHECKING, Any

from workbench.base.compiled_cache import use_versioned_numba_cache

use_versioned_numba_cache()  # before any controller module imports numba (workbench/base/compiled_cache.py)

if TYPE_CHECKING:
    from _typeshed import DataclassInstance

    from controllers.base import Controller, Measurement
    from controllers.clothoid import ClothoidConfig, ClothoidController
    from controllers.mpc import LMPCConfig, LMPCController, NMPCConfig, NMPCController
    from controllers.pure_pursuit import PurePursuit, PurePursuitConfig
    from controllers.stanley import Stanley, StanleyConfig
    from workbench.vehicles.base import VehicleModel
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


#: The entry-point group in which an installed package registers controllers (name = "module:Class").
CONTROLLER_ENTRY_POINTS = "lateral_workbench.controllers"


class ControllerRegistry(Mapping[str, "type[Controller]"]):
    """name -> controller class, in a fixed order: the built-in ones, then those installed packages register in
    `entry_point_group`; a class's module is imported when it is first looked up.

    `name in CONTROLLERS`, `len(CONTROLLERS)` and iterating the names import nothing (the installed packages'
    entry points are read, once); `CONTROLLERS[name]`, `.get`, `.items()` and `.values()` import the modules of the
    classes they return. A registered controller that cannot be imported, is no `Controller`, or whose `name` is
    not the one it is registered under is refused when looked up, naming the package.
    """

    def __init__(self, entries: Mapping[str, tuple[str, str]], entry_point_group: str | None = None) -> None:
        self._builtin = dict(entries)  # name -> (module, class name)
        self._group = entry_point_group
        self._found: dict[str, tuple[str, str]] | None = None
        self._packages: dict[str, str] = {}  # name -> the installed package that registers it
        self._loaded: dict[str, type[Controller]] = {}

    @property
    def _entries(self) -> dict[str, tuple[str, str]]:
        if self._found is None:
            self._found = dict(self._builtin)
            from workbench.base.entry_points import installed_entry_points

            found = installed_entry_points(self._group, set(self._builtin)) if self._group else {}
            for name, (module, attr, package) in found.items():
                self._found[name] = (module, attr)
                self._packages[name] = package
        return self._found

    def __getitem__(self, name: str) -> type[Controller]:
        try:
            return self._loaded[name]
        except KeyError:
            pass
        module, attr = self._entries[name]  # KeyError for an unknown name, as a dict
        package = self._packages.get(name)
        if package is None:
            cls = getattr(importlib.import_module(module), attr)
            if cls.name != name:
                raise RuntimeError(f"controllers: {module}.{attr}.name is {cls.name!r}, registered as {name!r}")
        else:
            cls = _plugin_controller(name, module, attr, package)
        self._loaded[name] = cls
        return cls

    def __contains__(self, name: object) -> bool:
        return name in self._entries

    def require(self, name: str) -> None:
        """Refuse a name no controller is registered under, naming the registered ones (imports nothing).

        Parameters
        ----------
        name : str
            A controller's name, e.g. "clothoid" (``workbench controllers`` lists the registered ones).

        Raises
        ------
        WorkbenchInputError
            No controller is registered under ``name``; the message lists the registered names.
        """
        if name not in self._entries:
            from workbench.base.errors import WorkbenchInputError

            raise WorkbenchInputError(f"unknown controller {name!r}; choose one of {', '.join(self._entries)}")

    def __iter__(self) -> Iterator[str]:
        return iter(self._entries)

    def __len__(self) -> int:
        return len(self._entries)

    def __repr__(self) -> str:
        return f"ControllerRegistry({', '.join(self._entries)})"


def _plugin_controller(name: str, module: str, attr: str, package: str) -> type[Controller]:
    """The class an installed package registers as controller `name`, checked to be a Controller of that name."""
    from controllers.base import Controller
    from workbench.base.errors import WorkbenchInputError

    where = f"controller {name!r} (registered by {package} as {module}:{attr})"
    try:
        cls = getattr(importlib.import_module(module), attr)
    except (ImportError, AttributeError) as exc:
        raise WorkbenchInputError(f"{where} cannot be imported: {type(exc).__name__}: {exc}") from None
    if not (isinstance(cls, type) and issubclass(cls, Controller)):
        raise WorkbenchInputError(f"{where} is not a controllers.base.Controller subclass; got {cls!r}")
    if getattr(cls, "name", None) != name:
        raise WorkbenchInputError(f"{where}: its class's name is {getattr(cls, 'name', None)!r}, not {name!r}")
    if not dataclasses.is_dataclass(getattr(cls, "config_type", None)):
        raise WorkbenchInputError(f"{where}: its config_type must be a dataclass; got {cls.config_type!r}")
    return cls


#: name -> controller class, in the order `workbench controllers` lists them.
CONTROLLERS: ControllerRegistry = ControllerRegistry(
    {
        "clothoid": ("controllers.clothoid", "ClothoidController"),
        "pure-pursuit": ("controllers.pure_pursuit", "PurePursuit"),
        "stanley": ("controllers.stanley", "Stanley"),
        "nmpc": ("controllers.mpc", "NMPCController"),
        "lmpc": ("controllers.mpc", "LMPCController"),
    },
    CONTROLLER_ENTRY_POINTS,
)


def make_controller(
    name: str, geometry: VehicleGeometry, config: DataclassInstance | None = None, vehicle: VehicleModel | None = None
) -> Controller:
    """Build the controller registered under `name` for a vehicle, with its default config unless one is given
    (an instance of that controller's `config_type`, which the name chooses: the controller checks it).
    `vehicle` (the steered vehicle) gives model-based controllers (the MPCs) their prediction parameters.

    Parameters
    ----------
    name : str
        A registered controller name (`CONTROLLERS`: "clothoid", "pure-pursuit", "stanley", "lmpc", "nmpc" and
        any registered through the entry points).
    geometry : VehicleGeometry
        The steered vehicle's geometry (wheelbase, steering ratio and limits).
    config : dataclass instance, optional
        The controller's options, an instance of its ``config_type`` (None: the defaults).
    vehicle : VehicleModel, optional
        The steered vehicle, for the controllers that predict with its model.

    Returns
    -------
    Controller
        The controller, ready to step.

    Raises
    ------
    WorkbenchInputError
        An unknown name (the message lists the registered ones), a config the controller refuses, or a vehicle
        the controller has no tuning for.

    Examples
    --------
    >>> from controllers import make_controller
    >>> from workbench.vehicles import make_vehicle
    >>> car = make_vehicle("kinematic-bicycle")
    >>> controller = make_controller("stanley", car.geometry)

    The clothoid controller given a vehicle needs that vehicle's tuning: `tuning.own_tuning.tuned_controller`
    builds it with the tuning.
    """
    CONTROLLERS.require(name)
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
    "CONTROLLER_ENTRY_POINTS",
    "ClothoidConfig",
    "ClothoidController",
    "Controller",
    "ControllerRegistry",
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
