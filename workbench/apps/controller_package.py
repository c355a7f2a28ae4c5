"""A controller packed in a folder, to be built elsewhere exactly as `workbench run` builds it: the resources an
exported controller FMU carries (`fmu_export` writes them, `fmu_slave` reads them inside the FMU).

The folder holds

    manifest.json     the controller's name, the controller period (s), the path's sample spacing (m), closure
                      and name, and the workbench version that packed it
    vehicle.toml      the vehicle as a vehicle file: its model type and every parameter (the payload included);
                      a file a parameter names (a plant FMU) copied under files/vehicle/
    controller.toml   one [NAME] table with every option of the controller's config; a file option names a copy
                      under files/<option>/ (a lead filter, limits, a lag, a tuning directory, a prediction vehicle)
    path.csv          the reference path the controller is reset on, as `workbench run` plans it: its samples
                      (x, y, heading, curvature, planned speed, and track widths when it has them) at 17 significant
                      digits, so that they read back bit for bit

The clothoid controller's vehicle tuning (`tuning.own_tuning.tuned_controller`) is packed as a tuning directory
(`tuning_dir`), so the target never looks for a tuning of its own. Everything is read back through the readers a
run uses (`load_vehicle`, `read_controller_config`, `tuned_controller`), so the packed controller is the run's.
"""

from __future__ import annotations

import dataclasses
import json
import shutil
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from workbench.base.errors import WorkbenchInputError, require_positive
from workbench.base.input_files import parse_json, read_text
from workbench.base.path import ReferencePath
from workbench.base.toml_text import toml_key, toml_value

if TYPE_CHECKING:
    from _typeshed import DataclassInstance

    from controllers.base import Controller
    from workbench.vehicles.base import VehicleModel

MANIFEST_FILE = "manifest.json"
VEHICLE_FILE = "vehicle.toml"
CONTROLLER_FILE = "controller.toml"
PATH_FILE = "path.csv"
#: The folder of the files the controller's file options name.
FILES_DIR = "files"
#: The path file's columns, without and with track widths.
PATH_COLUMNS = ("x_m", "y_m", "heading_rad", "curvature_1pm", "speed_mps")
WIDTH_COLUMNS = ("width_right_m", "width_left_m")
#: The manifest's format: a folder of another format is refused rather than misread.
PACKAGE_FORMAT = 1


@dataclass(frozen=True)
class PackedController:
    """A controller built from a package and reset on its path.

    controller: the controller, reset on `path` with steps every `period_s` (s); path: the packed reference
    path; period_s: the controller period (s); description: one line naming the controller, vehicle and path."""

    controller: Controller
    path: ReferencePath
    period_s: float
    description: str


def pack_controller(
    folder: Path,
    controller: str,
    vehicle: VehicleModel,
    options: DataclassInstance,
    named_files: dict[str, Path],
    path: ReferencePath,
    period_s: float,
) -> None:
    """Write the package (module docstring) into the empty or missing `folder`.

    Parameters
    ----------
    folder : Path
        Where to write it.
    controller : str
        The registered controller's name.
    vehicle : VehicleModel
        The vehicle (a model with a params dataclass, as every vehicle file builds), payload included.
    options : config_type
        The controller's config as `read_controller_config` built it (before the vehicle's own tuning).
    named_files : dict of str to Path
        The files (or tuning directories) the file options name, by option (`FILE_OPTIONS`), resolved.
    path : ReferencePath
        The path with its planned speed, as the controller is reset on it.
    period_s : float
        The controller period (s).
    """
    from tuning.own_tuning import tuning_dir_for, with_vehicle_tuning
    from workbench.apps.controller_config import FILE_OPTIONS
    from workbench.base.version import installed_version

    require_positive("period_s", period_s)
    files = dict(named_files)
    if "tuning_dir" not in files and with_vehicle_tuning(options, vehicle) is not options:
        files["tuning_dir"] = tuning_dir_for(vehicle)  # the vehicle's own tuning, which the run would use
    folder.mkdir(parents=True, exist_ok=True)
    by_field = {option.field: name for name, option in FILE_OPTIONS.items()}
    lines = [f"# {controller}'s options, packed by workbench export-fmu", f"[{toml_key(controller)}]"]
    for f in dataclasses.fields(options):
        if not f.init:
            continue
        if f.name in by_field:
            name = by_field[f.name]
            if name in files:
                lines.append(f"{toml_key(name)} = {toml_value(_copy_named(folder, name, files[name]))}")
            continue
        lines.append(f"{toml_key(f.name)} = {toml_value(getattr(options, f.name))}")
    (folder / CONTROLLER_FILE).write_text("\n".join(lines) + "\n", encoding="utf-8")
    _write_vehicle(folder, vehicle)
    _write_path(folder / PATH_FILE, path)
    manifest = {
        "format": PACKAGE_FORMAT,
        "controller": controller,
        "period_s": float(period_s),
        "path_name": path.name,
        "path_spacing_m": path.spacing_m,
        "path_closed": path.closed,
        "workbench_version": installed_version(),
    }
    (folder / MANIFEST_FILE).write_text(json.dumps(manifest, indent=2) + "\n", encoding="utf-8")


def _write_vehicle(folder: Path, vehicle: VehicleModel) -> None:
    """The vehicle as a vehicle file in `folder`: its model type and every parameter, a file a parameter names (a
    plant FMU) copied under files/vehicle/ and named relative to the file (read back by `load_vehicle`)."""
    params = getattr(vehicle, "params", None)
    if not dataclasses.is_dataclass(params):
        raise WorkbenchInputError(
            f"vehicle {vehicle.name!r} has no parameters dataclass to pack; a packed controller needs a vehicle that a "
            "vehicle file builds"
        )
    lines = ["# the vehicle, packed by workbench export-fmu", "[model]", f"type = {toml_value(vehicle.name)}", ""]
    lines.append("[parameters]")
    for f in dataclasses.fields(params):
        value = getattr(params, f.name)
        if isinstance(value, Path):
            value = _copy_named(folder, "vehicle", value)
        lines.append(f"{toml_key(f.name)} = {toml_value(value)}")
    (folder / VEHICLE_FILE).write_text("\n".join(lines) + "\n", encoding="utf-8")


def _copy_named(folder: Path, option: str, source: Path) -> str:
    """Copy the file or directory a file option names into files/<option>/; its path relative to `folder`. A
    name that is no file (a vehicle preset's, which `vehicle_file` takes) is packed as that preset's file."""
    target = folder / FILES_DIR / option / source.name
    target.parent.mkdir(parents=True, exist_ok=True)
    if not source.exists():
        from workbench.vehicles import preset_text

        target = target.with_name(f"{source.name}.toml")
        target.write_text(preset_text(source.name), encoding="utf-8")
    elif source.is_dir():
        shutil.copytree(source, target, ignore=shutil.ignore_patterns("__pycache__"))
    else:
        shutil.copy2(source, target)
    return target.relative_to(folder).as_posix()


def _write_path(file: Path, path: ReferencePath) -> None:
    """The path's samples as CSV, every value at 17 significant digits (it reads back bit for bit)."""
    if path.speed_mps is None:
        raise WorkbenchInputError(f"{path.name}: a packed path carries its planned speed; this one has none")
    columns: Iterable[np.ndarray] = [path.x_m, path.y_m, path.heading_rad, path.curvature_1pm, path.speed_mps]
    names: tuple[str, ...] = PATH_COLUMNS
    if path.width_right_m is not None and path.width_left_m is not None:
        columns = [*columns, path.width_right_m, path.width_left_m]
        names = (*PATH_COLUMNS, *WIDTH_COLUMNS)
    np.savetxt(file, np.column_stack(list(columns)), fmt="%.17g", delimiter=",", header=",".join(names), comments="")


def _read_path(file: Path, manifest: dict[str, Any]) -> ReferencePath:
    text = read_text(file, f"packed path {str(file)!r}")
    header, _, body = text.partition("\n")
    names = tuple(header.strip().split(","))
    if names not in (PATH_COLUMNS, (*PATH_COLUMNS, *WIDTH_COLUMNS)):
        raise WorkbenchInputError(
            f"packed path {str(file)!r}: columns {','.join(names)}; expected {','.join(PATH_COLUMNS)}"
        )
    try:
        table = np.loadtxt(body.splitlines(), delimiter=",", ndmin=2)
    except ValueError as exc:
        raise WorkbenchInputError(f"packed path {str(file)!r}: {exc}") from None
    if table.shape[1] != len(names) or table.shape[0] < 2 or not np.isfinite(table).all():
        raise WorkbenchInputError(f"packed path {str(file)!r}: needs at least two rows of {len(names)} finite numbers")
    widths = {} if len(names) == len(PATH_COLUMNS) else {"width_right_m": table[:, 5], "width_left_m": table[:, 6]}
    return ReferencePath(
        table[:, 0],
        table[:, 1],
        table[:, 2],
        table[:, 3],
        float(manifest["path_spacing_m"]),
        bool(manifest["path_closed"]),
        table[:, 4],
        name=str(manifest["path_name"]),
        **widths,
    )


def read_manifest(folder: Path) -> dict[str, Any]:
    """The package's manifest, checked for the keys and format this version reads.

    Parameters
    ----------
    folder : pathlib.Path
        A package folder (`pack_controller`).

    Returns
    -------
    dict
        The manifest's keys: format, controller, period_s, path_name, path_spacing_m, path_closed and the others
        written.

    Raises
    ------
    WorkbenchInputError
        The manifest is missing, not JSON, lacks a key, or is of another format.
    """
    file = folder / MANIFEST_FILE
    label = f"controller package manifest {str(file)!r}"
    manifest = parse_json(read_text(file, label), label, allow_nan=False)
    keys = ("format", "controller", "period_s", "path_name", "path_spacing_m", "path_closed")
    missing = [k for k in keys if not isinstance(manifest, dict) or k not in manifest]
    if missing:
        raise WorkbenchInputError(f"{label} lacks {', '.join(missing)}")
    if manifest["format"] != PACKAGE_FORMAT:
        raise WorkbenchInputError(
            f"{label}: format {manifest['format']!r}; this workbench reads format {PACKAGE_FORMAT} (pack it again)"
        )
    return manifest


def load_packed_controller(folder: Path) -> PackedController:
    """Build the packed controller as `workbench run` would (the vehicle from its file, the options from
    controller.toml, `tuned_controller`) and reset it on the packed path.

    Parameters
    ----------
    folder : pathlib.Path
        A package folder (`pack_controller`).

    Returns
    -------
    PackedController
        The controller, reset on the packed path, with the path, its period (s) and a description.

    Raises
    ------
    WorkbenchInputError
        A manifest refused (`read_manifest`), a controller not installed here, or a packed file that cannot be
        read.
    """
    from controllers import CONTROLLERS
    from tuning.own_tuning import tuned_controller
    from workbench.apps.controller_config import read_controller_config
    from workbench.vehicles import load_vehicle

    manifest = read_manifest(folder)
    name = manifest["controller"]
    if name not in CONTROLLERS:
        raise WorkbenchInputError(
            f"the package's controller {name!r} is not installed here; installed: {', '.join(CONTROLLERS)}"
        )
    vehicle = load_vehicle(str(folder / VEHICLE_FILE))
    config_type = CONTROLLERS[name].config_type
    options = read_controller_config(folder / CONTROLLER_FILE, name, config_type, (), vehicle.geometry)
    controller = tuned_controller(name, vehicle, options)
    path = _read_path(folder / PATH_FILE, manifest)
    period_s = float(manifest["period_s"])
    controller.reset(path, period_s)
    description = (
        f"{name} controller for the {vehicle.name} along {path.name} ({path.length_m:.0f} m), a step every "
        f"{period_s:g} s"
    )
    return PackedController(controller, path, period_s, description)
