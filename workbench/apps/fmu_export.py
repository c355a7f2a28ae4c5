"""`workbench export-fmu`: a controller, tuned for a vehicle and a path, as an FMI 2.0 co-simulation FMU built by
PythonFMU, to be stepped by the user's own simulation tool.

The FMU's resources hold the packed controller (`controller_package`: the vehicle, every controller option, the
files its options name, the vehicle's own tuning, the path as planned); its script subclasses
`fmu_slave.ControllerSlave`, which builds the controller from them when the FMU is instantiated. Building the FMU
instantiates it once (PythonFMU writes modelDescription.xml from an instance), so a package that cannot be built
back into its controller is refused here, not on the target.
"""

from __future__ import annotations

import os
import re
import sys
import tempfile
from collections.abc import Iterable
from pathlib import Path
from typing import TYPE_CHECKING, Any

from workbench.base.errors import WorkbenchInputError

if TYPE_CHECKING:
    from _typeshed import DataclassInstance

    from workbench.base.path import ReferencePath
    from workbench.vehicles.base import VehicleModel

#: The FMU's script: PythonFMU takes the model class from it, and its class name is the model identifier.
_SCRIPT = '''"""The {controller} controller exported by workbench export-fmu (PythonFMU loads this module)."""

from workbench.apps.fmu_slave import ControllerSlave, keep_script_namespace

keep_script_namespace(globals())  # PythonFMU's binary releases this namespace once per instance


class {identifier}(ControllerSlave):
    """The packed controller in resources/{package} (workbench.apps.fmu_slave.ControllerSlave)."""
'''


def model_identifier(controller: str) -> str:
    """The FMU's model identifier for a controller name: its words capitalised, then "Controller" (a C name:
    `pure-pursuit` gives PurePursuitController).

    Parameters
    ----------
    controller : str
        A controller's registered name.

    Returns
    -------
    str
        A C identifier.

    Examples
    --------
    >>> from workbench.apps.fmu_export import model_identifier
    >>> model_identifier("pure-pursuit"), model_identifier("nmpc")
    ('PurePursuitController', 'NmpcController')
    """
    words = [w for w in re.split(r"[^A-Za-z0-9]+", controller) if w]
    identifier = "".join(w[0].upper() + w[1:] for w in words) + "Controller"
    return identifier if identifier[0].isalpha() else f"X{identifier}"


def check_fmu_target(out: Path, overwrite: bool) -> None:
    """Refuse an --out that is not a writable FILE.fmu: another suffix, a folder, an existing file without
    --overwrite, a parent that is missing or not a folder.

    Parameters
    ----------
    out : pathlib.Path
        The FMU file to write.
    overwrite : bool
        Whether an existing file may be replaced.

    Raises
    ------
    WorkbenchInputError
        Any of those, naming --out.
    """
    if out.is_dir():
        raise WorkbenchInputError(f"--out {str(out)!r} is a folder; name the FMU file to write")
    if out.suffix.lower() != ".fmu":
        raise WorkbenchInputError(f"--out {str(out)!r}: an FMU file name ends in .fmu")
    if os.path.lexists(out) and not overwrite:
        raise WorkbenchInputError(f"--out {str(out)!r} exists; --overwrite replaces it")
    parent = out.parent
    if not parent.is_dir():
        raise WorkbenchInputError(f"--out {str(out)!r}: its folder {str(parent)!r} does not exist or is not a folder")
    if not os.access(parent, os.W_OK):
        raise WorkbenchInputError(f"--out {str(out)!r}: its folder {str(parent)!r} is not writable")


def named_files(config_path: Path | None, controller: str, overrides: Iterable[str]) -> dict[str, Path]:
    """The files the file options (`FILE_OPTIONS`) of the controller's config file table and of the `--set`
    overrides name, resolved as `read_controller_config` resolves them (the last one given wins; "none" drops
    one). The options are checked by `read_controller_config` first; this only finds their files to pack.

    Parameters
    ----------
    config_path : pathlib.Path or None
        The controller-config file (None: none).
    controller : str
        The controller whose table is read.
    overrides : iterable of str
        The ``key=value`` overrides (`--set`).

    Returns
    -------
    dict of str to pathlib.Path
        File option -> the file or folder it names.
    """
    from workbench.apps.controller_config import FILE_OPTIONS, read_config_tables
    from workbench.base.typed_tables import typed_value

    items: list[tuple[str, Any, bool]] = []
    base_dir = None
    if config_path is not None:
        items += [(k, v, False) for k, v in read_config_tables(config_path).get(controller, {}).items()]
        base_dir = config_path.resolve().parent
    for override in overrides:
        key, _, text = override.partition("=")
        items.append((key.strip(), text.strip(), True))
    named: dict[str, Path] = {}
    for key, value, is_text in items:
        if key in FILE_OPTIONS:
            path = typed_value(f"option {key!r}", value, Path | None, base_dir, from_text=is_text)
            if path is None:
                named.pop(key, None)
            else:
                named[key] = path
    return named


def build_controller_fmu(
    out: Path,
    controller: str,
    vehicle: VehicleModel,
    options: DataclassInstance,
    files: dict[str, Path],
    path: ReferencePath,
    period_s: float,
) -> Path:
    """Pack the controller (`controller_package.pack_controller`, whose arguments these are) and build the FMU at
    `out` (replaced whole: written beside it, then renamed); returns `out`.

    Parameters
    ----------
    out : pathlib.Path
        The FMU file (`check_fmu_target`).
    controller, vehicle, options, files, path, period_s
        As `controller_package.pack_controller` takes them (files: its named_files).

    Returns
    -------
    pathlib.Path
        `out`.

    Raises
    ------
    WorkbenchInputError
        PythonFMU could not build the FMU, or packing refused a value.
    """
    from pythonfmu import FmuBuilder

    from workbench.apps.controller_package import pack_controller
    from workbench.apps.fmu_slave import PACKAGE_DIR

    identifier = model_identifier(controller)
    with tempfile.TemporaryDirectory(prefix="workbench-fmu-") as work:
        folder = Path(work)
        pack_controller(folder / PACKAGE_DIR, controller, vehicle, options, files, path, period_s)
        script = folder / f"{identifier.lower()}_fmu.py"
        script.write_text(_SCRIPT.format(controller=controller, identifier=identifier, package=PACKAGE_DIR))
        partial = out.with_name(f".{out.stem}.partial.fmu")
        path_before = list(sys.path)
        try:
            FmuBuilder.build_FMU(script, dest=partial, project_files=[folder / PACKAGE_DIR])
            os.replace(partial, out)
        except WorkbenchInputError:
            raise
        except Exception as exc:  # PythonFMU's own failures (a platform without its binary, an unwritable file)
            raise WorkbenchInputError(f"PythonFMU could not build {str(out)!r}: {type(exc).__name__}: {exc}") from None
        finally:
            sys.path[:] = path_before  # the builder puts the script's folder on the path
            partial.unlink(missing_ok=True)
    return out
