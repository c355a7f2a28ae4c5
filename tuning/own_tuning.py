"""A vehicle's own clothoid-controller tuning (lead filter, curvature limits, identified lags), found or made on
first use, and the controller built with it.

`tuning_for(vehicle)` gives the vehicle's own tuning, never another vehicle's: the shipped directory of the preset
whose parameters it has (`workbench/presets/tuning/<preset>/`, made by `python -m tuning.preset_tuning`; the
manifest records the parameters' hash), else its own in a user cache (`$WORKBENCH_TUNING_CACHE`, else
`$XDG_CACHE_HOME/lateral-workbench/tuning`), one directory per vehicle and tuning options named by the sha256 of
both. On first use the cache directory is made by the same chain the `tuning` commands run, in a temporary
directory renamed into place when complete, so that concurrent sweep workers never see half a tuning; if that
fails, the error names the `tuning` commands to run by hand.

The payload is left out of a vehicle's identity (set to its preset's before comparing or hashing): the lag hardly
depends on it, so a truck with another payload uses the preset's filter; its rollover limits are those at the
preset's payload, conservative for a lighter truck and a little optimistic for a heavier one.

`tuned_controller(name, vehicle)` is how the applications build a controller: the clothoid controller's config
gets the vehicle's tuning (`ClothoidConfig.tuning`), so the controller itself reads no file.
"""

from __future__ import annotations

import hashlib
import json
import os
import shlex
import shutil
import sys
import tempfile
import time
from pathlib import Path
from typing import TYPE_CHECKING, Protocol, Self, TypeVar, runtime_checkable

from workbench.base.errors import WorkbenchInputError
from workbench.base.user_cache import check_private_tree
from workbench.vehicles.base import VehicleModel

if TYPE_CHECKING:  # the clothoid controller and the tuning tools (python-control, SciPy: ~2 s to import) are
    # imported where a tuning is looked up, not by every run that imports this module (pure pursuit's)
    from _typeshed import DataclassInstance

    from controllers.base import Controller
    from controllers.clothoid.vehicle_tuning import VehicleTuning
    from tuning.preset_tuning import PresetTuningOptions
    from workbench.simulation.known_delays import KnownDelays


#: The version of what the tuning chain identifies (2: the preview responses' handling gain from steady turns): a
#: cached tuning made by an earlier chain lacks what this one adds, so the version is part of `cache_key`.
CHAIN_VERSION = 2


def cache_key(vehicle: VehicleModel, options: PresetTuningOptions) -> str:
    """Name of the vehicle's cache directory: sha256 of CHAIN_VERSION, the vehicle's canonical parameters and the
    tuning options resolved for it (so that a changed chain or options make a new tuning rather than reuse one
    made with the old).

    Parameters
    ----------
    vehicle : VehicleModel
        The vehicle (its payload is left out of its identity: module docstring).
    options : PresetTuningOptions
        The tuning options, resolved for the vehicle's model.

    Returns
    -------
    str
        64 hexadecimal digits.
    """
    from tuning.preset_tuning import options_dict
    from tuning.tuning_dirs import canonical_vehicle_toml

    text = f"chain {CHAIN_VERSION}\n" + canonical_vehicle_toml(vehicle)
    text += json.dumps(options_dict(options, vehicle.name), sort_keys=True)
    return hashlib.sha256(text.encode("utf-8")).hexdigest()


def shipped_tuning_dir(vehicle: VehicleModel, options: PresetTuningOptions | None = None) -> Path | None:
    """The shipped tuning made for exactly this vehicle (payload aside) and these options, or None.

    Parameters
    ----------
    vehicle : VehicleModel
        The vehicle whose parameters are looked up among the shipped presets' manifests.
    options : PresetTuningOptions or None
        The tuning options (None: `tuning.preset_tuning.PRESET_TUNING_OPTIONS`, those the shipped files were made
        with).

    Returns
    -------
    pathlib.Path or None
        The shipped directory (``workbench/presets/tuning/<preset>/``), or None when none was made for this
        vehicle and these options.
    """
    from tuning.preset_tuning import PRESET_TUNING_OPTIONS, options_dict
    from tuning.tuning_dirs import params_sha256, shipped_index

    options = options or PRESET_TUNING_OPTIONS
    key = (params_sha256(vehicle), json.dumps(options_dict(options, vehicle.name), sort_keys=True))
    return shipped_index().get(key)


def _stale_preset_hint(vehicle: VehicleModel) -> str:
    """When a shipped tuning was made for this vehicle with other options: how to bring it up to date."""
    from tuning.tuning_dirs import params_sha256, shipped_index

    digest = params_sha256(vehicle)
    for (params_digest, _), directory in shipped_index().items():
        if params_digest == digest:
            return (
                f" (the shipped tuning in {directory} was made for it with other options: "
                f"`python -m tuning.preset_tuning --only {directory.name}` brings it up to date)"
            )
    return ""


def manual_instructions(vehicle: VehicleModel, options: PresetTuningOptions, vehicle_file: str) -> str:
    """The `tuning` commands that make this vehicle's files by hand, and the options that then use them.

    Parameters
    ----------
    vehicle : VehicleModel
        The vehicle to tune.
    options : PresetTuningOptions
        The tuning options the commands apply.
    vehicle_file : str
        The vehicle TOML file the commands name (``--vehicle-file``).

    Returns
    -------
    str
        One sentence: the commands, joined by ``&&``, and the controller options filter_file and limits_file that
        use their files.
    """
    from tuning.preset_tuning import tuning_commands
    from tuning.tuning_dirs import LEAD_FILE, LIMITS_FILE

    commands = tuning_commands(vehicle, ["--vehicle-file", vehicle_file], options.for_model(vehicle.name))
    return (
        "make them by hand: "
        + " && ".join(f"`{shlex.join(c)}`" for c in commands)
        + f", then pass the controller options filter_file = {LEAD_FILE!r} and limits_file = {LIMITS_FILE!r} "
        f"(e.g. --set filter_file={LEAD_FILE} --set limits_file={LIMITS_FILE})"
    )


def generate_vehicle_tuning(vehicle: VehicleModel, directory: str | Path, options: PresetTuningOptions) -> Path:
    """Make the vehicle's tuning in `directory` (which must not exist yet) by the tuning chain, atomically: in a
    temporary sibling directory renamed to `directory` when complete. If another process completed it first, its
    files are kept. Returns `directory`.

    Parameters
    ----------
    vehicle : VehicleModel
        The vehicle to tune.
    directory : str or pathlib.Path
        The tuning's directory, not existing yet; its parent is made when missing.
    options : PresetTuningOptions
        The tuning options (speeds, design, ...).

    Returns
    -------
    pathlib.Path
        ``directory``, holding the vehicle file, the lead-filter and limits files and the manifest.

    Raises
    ------
    WorkbenchInputError
        A step of the tuning chain refuses the vehicle (an identification or design that fails, saying why).
    OSError
        The directory cannot be written.
    """
    from tuning.tuning_dirs import MANIFEST_FILE, VEHICLE_FILE, canonical_vehicle_toml

    target = Path(directory)
    target.parent.mkdir(parents=True, exist_ok=True)
    work = Path(tempfile.mkdtemp(prefix=f".{target.name}.", suffix=".tmp", dir=target.parent))
    try:
        (work / VEHICLE_FILE).write_text(canonical_vehicle_toml(vehicle), encoding="utf-8")
        from tuning.preset_tuning import write_tuning_files

        write_tuning_files(vehicle, work, options, vehicle_args=["--vehicle-file", VEHICLE_FILE], preset=None)
        try:
            os.rename(work, target)
        except OSError:
            if not (target / MANIFEST_FILE).is_file():
                raise
    finally:
        shutil.rmtree(work, ignore_errors=True)
    return target


def _discard(directory: Path) -> None:
    """Remove a cache entry: renamed aside first, so that a concurrent reader sees it whole or not at all."""
    aside = Path(tempfile.mkdtemp(prefix=f".{directory.name}.", suffix=".discarded", dir=directory.parent))
    try:
        os.replace(directory, aside / directory.name)
    except OSError:  # removed meanwhile by another process
        pass
    shutil.rmtree(aside, ignore_errors=True)


def _estimate_s(vehicle: VehicleModel, options: PresetTuningOptions) -> float:

    resolved = options.for_model(vehicle.name)
    from tuning.preset_tuning import SECONDS_PER_SPEED

    return SECONDS_PER_SPEED.get(vehicle.name, 60.0) * len(resolved.schedule_speeds_kmh)


def _duration(seconds: float) -> str:
    return f"{seconds:.0f} s" if seconds < 120 else f"{seconds / 60:.0f} min"


def tuning_for(vehicle: VehicleModel, options: PresetTuningOptions | None = None) -> VehicleTuning:
    """The tuning the clothoid controller uses for `vehicle` (module docstring): the shipped files of the preset it
    equals (payload aside), else its own from the cache, generated there on first use. options: the tuning options
    (default `tuning.preset_tuning.PRESET_TUNING_OPTIONS`, those the shipped files were made with).

    Parameters
    ----------
    vehicle : VehicleModel
        The vehicle to be steered.
    options : PresetTuningOptions or None
        The tuning options (None: the shipped files' options).

    Returns
    -------
    VehicleTuning
        The vehicle's lead-filter schedule, curvature limits, identified lags and lookahead floors.

    Raises
    ------
    WorkbenchInputError
        No shipped tuning fits and generating one in the cache fails (the message gives the `tuning` commands to
        run by hand), or the cache directory is not private to the user.

    Examples
    --------
    A preset's tuning is shipped, so this reads files and identifies nothing:

    >>> from tuning.own_tuning import tuning_for
    >>> from workbench.vehicles import make_vehicle
    >>> tuning = tuning_for(make_vehicle("dynamic-bicycle"))
    >>> tuning.filter_schedule.speeds_kmh[:3]
    (10.0, 20.0, 30.0)
    """
    from tuning.tuning_dirs import read_vehicle_tuning

    return read_vehicle_tuning(tuning_dir_for(vehicle, options))


def tuning_dir_for(vehicle: VehicleModel, options: PresetTuningOptions | None = None) -> Path:
    """The directory of the tuning `tuning_for` reads for `vehicle` (the shipped preset's, else the cache's,
    generated there on first use), for a caller that copies the files (`workbench export-fmu` packs them).

    Parameters
    ----------
    vehicle : VehicleModel
        The vehicle to be steered.
    options : PresetTuningOptions or None
        The tuning options (None: the shipped files' options).

    Returns
    -------
    pathlib.Path
        The shipped preset's directory, else the cache's (``$WORKBENCH_TUNING_CACHE``, else
        ``$XDG_CACHE_HOME/lateral-workbench/tuning``) named by `cache_key`.

    Raises
    ------
    WorkbenchInputError
        Generating the tuning fails (the message gives the `tuning` commands to run by hand), or the cache
        directory is not private to the user.
    """
    from tuning.preset_tuning import PRESET_TUNING_OPTIONS
    from tuning.tuning_dirs import (
        CACHE_ENV,
        MANIFEST_FILE,
        VEHICLE_FILE,
        cache_dir,
        canonical_vehicle_toml,
        params_sha256,
        read_vehicle_tuning,
    )

    options = options or PRESET_TUNING_OPTIONS
    shipped = shipped_tuning_dir(vehicle, options)
    if shipped is not None:
        return shipped
    base = cache_dir()
    key = cache_key(vehicle, options)
    directory = base / key
    if (directory / MANIFEST_FILE).is_file():
        check_private_tree(directory, CACHE_ENV)
        try:
            read_vehicle_tuning(directory)  # an entry that reads is used
            return directory
        except WorkbenchInputError as exc:  # an edited or damaged entry: never used, made again
            print(f"lateral-workbench: the cached tuning cannot be used ({exc}): making it again", file=sys.stderr)
            _discard(directory)
    estimate = _estimate_s(vehicle, options)
    print(
        f"lateral-workbench: no clothoid-controller tuning yet for this {vehicle.name} (params sha256 "
        f"{params_sha256(vehicle)[:12]}): identifying its lag and designing its lead filter and limits by the "
        f"tuning chain into {directory}, once (about {_duration(estimate)}){_stale_preset_hint(vehicle)}",
        file=sys.stderr,
        flush=True,
    )
    start = time.perf_counter()
    try:
        generate_vehicle_tuning(vehicle, directory, options)
    except (WorkbenchInputError, OSError) as exc:
        vehicle_file = base / f"{key}.{VEHICLE_FILE}"
        try:
            vehicle_file.parent.mkdir(parents=True, exist_ok=True)
            vehicle_file.write_text(canonical_vehicle_toml(vehicle), encoding="utf-8")
            named = str(vehicle_file)
        except OSError:
            named = "YOUR_VEHICLE.toml"
        raise WorkbenchInputError(
            f"no clothoid-controller tuning for this {vehicle.name}, and generating it in {directory} failed: "
            f"{exc}; {manual_instructions(vehicle, options, named)}"
        ) from None
    print(
        f"lateral-workbench: tuning of this {vehicle.name} done in {time.perf_counter() - start:.0f} s",
        file=sys.stderr,
        flush=True,
    )
    return directory


# ---- the controller with its vehicle's tuning ------------------------------------------------------------------


#: A controller's config, returned as it came or with the vehicle's tuning.
ConfigT = TypeVar("ConfigT")


@runtime_checkable
class TunableConfig(Protocol):
    """A controller config that takes its vehicle's own tuning (`ClothoidConfig`): its tuning (None: not given) and
    the config with one. A protocol, so that telling such a config from another imports no controller's module."""

    @property
    def tuning(self) -> VehicleTuning | None:
        """The vehicle's own tuning the config carries (None: not given)."""
        ...

    def with_tuning(self, tuning: VehicleTuning) -> Self:
        """The config with this tuning.

        Parameters
        ----------
        tuning : VehicleTuning
            The vehicle's own tuning.

        Returns
        -------
        Self
            A copy of the config with ``tuning`` set.
        """
        ...


def with_vehicle_tuning(config: ConfigT, vehicle: VehicleModel) -> ConfigT:
    """`config` with the vehicle's own tuning (`tuning_for`) when it takes one (`TunableConfig`) and has none; any
    other config as it is.

    Parameters
    ----------
    config : ConfigT
        A controller's config (any type).
    vehicle : VehicleModel
        The vehicle whose tuning a `TunableConfig` without one is given.

    Returns
    -------
    ConfigT
        The config with the vehicle's tuning, or the config as it came.

    Raises
    ------
    WorkbenchInputError
        The vehicle's tuning cannot be found or made (`tuning_for`).
    """
    if isinstance(config, TunableConfig) and config.tuning is None:
        return config.with_tuning(tuning_for(vehicle))
    return config


def tuned_controller(
    name: str, vehicle: VehicleModel, config: DataclassInstance | None = None, delays: KnownDelays | None = None
) -> Controller:
    """The controller registered under `name` for `vehicle`, its config (the default when None) given the
    vehicle's own tuning where it takes one (the clothoid controller), then told `delays` when given
    (`Controller.informed_config`; None: untold): how the applications build controllers.

    Parameters
    ----------
    name : str
        A registered controller's name (``workbench controllers`` lists them: "clothoid", "stanley", ...).
    vehicle : VehicleModel
        The vehicle to steer: its geometry, its tuning (clothoid) and its model (the MPCs).
    config : DataclassInstance or None
        The controller's config, of its `config_type` (None: the defaults).
    delays : KnownDelays or None
        The run's nominal delays, which a controller that compensates them is told (None: untold).

    Returns
    -------
    Controller
        The controller, ready for `Controller.reset`.

    Raises
    ------
    WorkbenchInputError
        An unknown controller name, a config the controller refuses, or a tuning that cannot be found or made.

    Examples
    --------
    >>> from tuning.own_tuning import tuned_controller
    >>> from workbench.vehicles import make_vehicle
    >>> controller = tuned_controller("clothoid", make_vehicle("dynamic-bicycle"))
    >>> controller.name, controller.config.tuning is not None
    ('clothoid', True)
    """
    from controllers import CONTROLLERS, make_controller

    if config is None and name in CONTROLLERS:
        config = CONTROLLERS[name].config_type()
    config = with_vehicle_tuning(config, vehicle)
    if delays is not None and name in CONTROLLERS:
        config = CONTROLLERS[name].informed_config(config, delays)
    return make_controller(name, vehicle.geometry, config, vehicle=vehicle)


__all__ = [
    "TunableConfig",
    "cache_key",
    "generate_vehicle_tuning",
    "manual_instructions",
    "shipped_tuning_dir",
    "tuned_controller",
    "tuning_dir_for",
    "tuning_for",
    "with_vehicle_tuning",
]
