"""A vehicle's clothoid-controller tuning directory: its files (docs/formats.md), the vehicle's
identity it is made for (its canonical parameters and their sha256, the payload set to its preset's: the lag
hardly depends on it), where the shipped and the cached directories live, and reading one into a `VehicleTuning`.
Which directory a vehicle gets, and making one, is `own_tuning.py`."""

from __future__ import annotations

import dataclasses
import functools
import hashlib
import json
import math
from collections.abc import Callable, Mapping
from importlib import resources
from pathlib import Path
from typing import Any, TypeVar

from controllers.clothoid.filter_schedule import FilterSchedule
from controllers.clothoid.loop_requirements import REQUIRED_GAIN_MARGIN_DB, REQUIRED_PHASE_MARGIN_DEG
from controllers.clothoid.preview_model import PreviewResponse
from controllers.clothoid.sideslip_release import SideslipRelease
from controllers.clothoid.vehicle_tuning import FloorDesign, VehicleTuning
from tuning.filter_file import read_filter_file
from tuning.limits_file import read_limits_file
from workbench.base.errors import WorkbenchInputError, shown_all, value_text
from workbench.base.input_files import read_json
from workbench.base.toml_text import toml_value
from workbench.base.user_cache import private_cache_dir
from workbench.vehicles.base import VehicleModel
from workbench.vehicles.presets import MODEL_TYPES, params_from_toml, preset_text
from workbench.vehicles.steering_lag import SteeringLag

#: Environment variable naming the directory generated tunings are cached in.
CACHE_ENV = "WORKBENCH_TUNING_CACHE"
MANIFEST_FORMAT = "vehicle-tuning/1"
LEAD_FILE = "lead.json"
LIMITS_FILE = "limits.csv"
MANIFEST_FILE = "manifest.json"
VEHICLE_FILE = "vehicle.toml"
MANIFEST_KEYS = (
    "format",
    "vehicle",
    "preset",
    "params_sha256",
    "options",
    "commands",
    "dropped_speeds",
    "notes",
    "package_version",
    "date",
    "generation_time_s",
    "files_sha256",
)
#: The files of a tuning directory whose SHA-256 its manifest records (`files_sha256`), checked on every read.
DIGESTED_FILES = (LEAD_FILE, LIMITS_FILE)
PAYLOAD_FIELD = "payload_kg"
LAG_KEYS = ("speed_kmh", "omega_n_rad_s", "zeta")
#: The per_speed keys of the measured lag (prefix + the path lag's key); the first two are required for it.
MEASURED_PREFIX = "measured_"
MEASURED_LAG_KEYS = ("measured_omega_n_rad_s", "measured_zeta")
#: The per_speed keys of the preview responses (`tuning.schedule.ScheduleEntry.row`); all of them or none.
PREVIEW_KEYS = ("preview_first_tap_s", "preview_tap_spacing_s", "preview_steering_taps", "preview_measured_taps")
#: The preview responses' handling gain, optional (files made before it was identified: gains of one).
HANDLING_KEY = "preview_handling_gain"
#: What a per_speed model read by `_per_speed` is.
T = TypeVar("T")
#: The per_speed keys of the sideslip's release (`tuning.release_fit`): the steady sideslip on the handling grid
#: (rad) and the release rate (1/s; 0: not identified); at every speed or at none (files made before it was
#: identified: none).
RELEASE_KEYS = ("release_steady_sideslip_rad", "release_rate_1ps")


# ---- the vehicle's identity -------------------------------------------------------------------------------------


@functools.cache
def _preset_payload_kg(model_type: str) -> float | None:
    """The payload of the preset of this model type (None for a model without one)."""
    _, params = params_from_toml(preset_text(model_type), f"preset {model_type!r}")
    return getattr(params, PAYLOAD_FIELD, None)


def reference_params(vehicle: VehicleModel) -> Any:
    """The vehicle's parameters dataclass with the payload (of a vehicle that carries one) set to its preset's:
    what its tuning is made for (module docstring)."""
    params = getattr(vehicle, "params", None)
    name = getattr(vehicle, "name", None)
    if name not in MODEL_TYPES or not dataclasses.is_dataclass(params) or not isinstance(params, MODEL_TYPES[name][1]):
        raise WorkbenchInputError(
            f"cannot tell which tuning vehicle {vehicle!r} needs: vehicle-aware tuning needs a model of "
            f"{', '.join(MODEL_TYPES)} with its params dataclass; pass filter_file and limits_file instead"
        )
    payload = _preset_payload_kg(name)
    if payload is not None and getattr(params, PAYLOAD_FIELD) != payload:
        params = dataclasses.replace(params, **{PAYLOAD_FIELD: payload})
    return params


def canonical_vehicle_toml(vehicle: VehicleModel) -> str:
    """The vehicle's reference parameters as a vehicle file (every field, in declaration order, numbers by repr; a
    file a field names, a plant FMU, with its content's sha256 in a comment): one text per vehicle, hashed for its
    identity and written as the cache's vehicle.toml."""
    params = reference_params(vehicle)
    lines = ["# canonical parameters (payload set to the preset's) of a vehicle tuned by tuning_for", "[model]"]
    lines += [f'type = "{vehicle.name}"', "", "[parameters]"]
    for f in dataclasses.fields(params):
        value = getattr(params, f.name)
        if value is None or isinstance(value, str | Path):  # text, a file (an FMU's) or "none"
            digest = _file_sha256(value) if isinstance(value, Path) else None
            lines.append(f"{f.name} = {toml_value(value)}" + (f"  # sha256 {digest}" if digest else ""))
        else:
            lines.append(f"{f.name} = {value!r}")
    text = "\n".join(lines) + "\n"
    params_from_toml(text, "canonical vehicle file")  # it must read back as the same vehicle
    return text


def _file_sha256(path: Path) -> str | None:
    """sha256 (hex) of a file a vehicle's parameters name (a plant FMU: its content is the vehicle, so a changed
    FMU is another vehicle); None when it is not a readable file. Computed once per file version (path, size and
    modification time), as an FMU may be large."""
    try:
        stat = path.stat()
    except OSError:
        return None
    return _sha256_of(str(path.resolve()), stat.st_size, stat.st_mtime_ns)


@functools.cache
def _sha256_of(path: str, size: int, mtime_ns: int) -> str | None:
    """sha256 (hex) of the file at `path` (size and mtime_ns: the version cached)."""
    digest = hashlib.sha256()
    try:
        with open(path, "rb") as handle:
            for block in iter(lambda: handle.read(1 << 20), b""):
                digest.update(block)
    except OSError:
        return None
    return digest.hexdigest()


def params_sha256(vehicle: VehicleModel) -> str:
    """sha256 (hex) of the vehicle's canonical parameters."""
    return hashlib.sha256(canonical_vehicle_toml(vehicle).encode("utf-8")).hexdigest()


# ---- where the files are ----------------------------------------------------------------------------------------


def shipped_tuning_root() -> Path:
    """workbench/presets/tuning, where the presets' tunings are shipped."""
    return Path(str(resources.files("workbench").joinpath("presets", "tuning")))


def cache_dir() -> Path:
    """$WORKBENCH_TUNING_CACHE, else $XDG_CACHE_HOME/lateral-workbench/tuning (~/.cache/...): made private when
    missing; UnsafeCacheError when it is not the user's own (`workbench.base.user_cache`)."""
    return private_cache_dir(CACHE_ENV, "tuning")


def files_sha256(directory: Path) -> dict[str, str]:
    """SHA-256 (hex) of each of DIGESTED_FILES in `directory`, as a manifest records them."""
    return {name: hashlib.sha256((directory / name).read_bytes()).hexdigest() for name in DIGESTED_FILES}


def shipped_index() -> dict[tuple[str, str], Path]:
    """(params_sha256, options as JSON) -> the shipped directory made for them."""
    index = {}
    root = shipped_tuning_root()
    if root.is_dir():
        for manifest_path in sorted(root.glob(f"*/{MANIFEST_FILE}")):
            manifest = read_manifest(manifest_path.parent)
            index[(manifest["params_sha256"], json.dumps(manifest["options"], sort_keys=True))] = manifest_path.parent
    return index


# ---- reading ----------------------------------------------------------------------------------------------------


def read_manifest(directory: str | Path) -> dict[str, Any]:
    """The manifest.json of a tuning directory, its keys checked."""
    path = Path(directory) / MANIFEST_FILE
    doc = read_json(path, f"tuning manifest {str(path)!r}")
    if not isinstance(doc, dict) or doc.get("format") != MANIFEST_FORMAT:
        raise WorkbenchInputError(f"tuning manifest {str(path)!r}: format must be {MANIFEST_FORMAT!r}")
    missing = [k for k in MANIFEST_KEYS if k not in doc]
    unknown = [k for k in doc if k not in MANIFEST_KEYS]
    if missing or unknown:
        raise WorkbenchInputError(
            f"tuning manifest {str(path)!r}: missing keys {missing}, unknown keys {unknown}; "
            f"keys: {list(MANIFEST_KEYS)}"
        )
    return doc


def _design(path: Path) -> Mapping[str, Any]:
    """The lead file's design table (`tuning.schedule.ScheduleResult.write`), read at the boundary into the typed
    lags and floors of a `VehicleTuning` (`_lags`, `_floors`); the file is a valid lead-filter file
    (`read_filter_file` read it first)."""
    design = read_json(path, f"lead filter file {str(path)!r}").get("design", {})
    return design if isinstance(design, Mapping) else {}


def _lags(
    path: Path, design: Mapping[str, Any], schedule: FilterSchedule
) -> tuple[tuple[tuple[float, SteeringLag], ...], tuple[tuple[float, SteeringLag], ...]]:
    """(the path lags, the measured lags) of design.per_speed; the measured ones empty when no row has them (files
    made before they were recorded), refused when only some rows have them."""
    rows = design.get("per_speed")
    if not isinstance(rows, list) or not rows:
        raise WorkbenchInputError(f"{path}: design.per_speed (the lag identified at each speed) is missing")
    lags, measured = [], []
    for i, row in enumerate(rows):
        if not isinstance(row, Mapping) or any(k not in row for k in LAG_KEYS):
            raise WorkbenchInputError(f"{path}: design.per_speed[{i}] must hold {list(LAG_KEYS)}; got {row!r}")
        speed = row["speed_kmh"]
        if isinstance(speed, bool) or not isinstance(speed, int | float):
            raise WorkbenchInputError(
                f"{path}: design.per_speed[{i}].speed_kmh must be a number; got {value_text(speed)}"
            )
        lags.append((float(speed), _row_lag(path, i, row, "", speed)))
        if any(k in row for k in MEASURED_LAG_KEYS):
            if any(k not in row for k in MEASURED_LAG_KEYS):
                raise WorkbenchInputError(
                    f"{path}: design.per_speed[{i}] must hold both of {list(MEASURED_LAG_KEYS)} or neither"
                )
            measured.append((float(speed), _row_lag(path, i, row, MEASURED_PREFIX, speed)))
    if measured and len(measured) != len(lags):
        raise WorkbenchInputError(
            f"{path}: design.per_speed holds the measured lag ({list(MEASURED_LAG_KEYS)}) at {len(measured)} of "
            f"{len(lags)} speeds; give it at every speed or at none"
        )
    speeds = tuple(speed for speed, _ in lags)
    if speeds != schedule.speeds_kmh:
        raise WorkbenchInputError(
            f"{path}: the lags' speeds {shown_all(speeds)} differ from the schedule's {shown_all(schedule.speeds_kmh)}"
        )
    return tuple(lags), tuple(measured)


#: The design keys that say how the margins design computed its floors (`tuning.schedule.ScheduleResult.write`).
FLOOR_DESIGN_KEYS = ("controller_rate_hz", "prediction_time_s", "arc_lateral_accel_g", "lookahead_range_m")


def _previews(path: Path, design: Mapping[str, Any]) -> tuple[tuple[float, PreviewResponse], ...]:
    """(speed_kmh, the preview responses) of design.per_speed (PREVIEW_KEYS, and HANDLING_KEY where given); empty
    when no row has them (files made before they were recorded), refused when only some rows have them or a row's
    are not a valid response."""

    def response(row: Mapping[str, Any]) -> PreviewResponse:
        handling = {"handling_gain": row[HANDLING_KEY]} if HANDLING_KEY in row else {}
        return PreviewResponse(*(row[k] for k in PREVIEW_KEYS), **handling)

    return _per_speed(path, design, PREVIEW_KEYS, "the preview responses", "preview responses", response)


def _releases(path: Path, design: Mapping[str, Any]) -> tuple[tuple[float, SideslipRelease], ...]:
    """(speed_kmh, the sideslip's release) of design.per_speed (RELEASE_KEYS; a release rate 0: not identified);
    empty when no row has them, refused when only some rows have them or a row's are not a valid release."""

    def release(row: Mapping[str, Any]) -> SideslipRelease:
        return SideslipRelease.from_rate(tuple(row["release_steady_sideslip_rad"]), row["release_rate_1ps"])

    return _per_speed(path, design, RELEASE_KEYS, "the sideslip's release", "sideslip release", release)


def _per_speed(
    path: Path,
    design: Mapping[str, Any],
    keys: tuple[str, ...],
    what: str,
    label: str,
    make: Callable[[Mapping[str, Any]], T],
) -> tuple[tuple[float, T], ...]:
    """(speed_kmh, make(row)) of each row of design.per_speed when any row has one of `keys`; every row must then
    have all of them (else refused naming the row and `what`), and make's refusal names the row and `label`."""
    rows = design["per_speed"]  # checked by _lags
    if not any(k in row for row in rows for k in keys):
        return ()
    out = []
    for i, row in enumerate(rows):
        if any(k not in row for k in keys):
            raise WorkbenchInputError(
                f"{path}: design.per_speed[{i}] lacks some of {list(keys)}, which other speeds give; give {what} at "
                "every speed or at none"
            )
        try:
            made = make(row)
        except (WorkbenchInputError, TypeError, ValueError) as exc:
            raise WorkbenchInputError(f"{path}: design.per_speed[{i}] ({label}): {exc}") from None
        out.append((float(row["speed_kmh"]), made))
    return tuple(out)


def _floors(path: Path, design: Mapping[str, Any]) -> tuple[tuple[tuple[float, float], ...], FloorDesign | None]:
    """((speed_kmh, lookahead_floor_m) of the rows of design.per_speed that have one, what they were computed for):
    ((), None) unless the design is "margins" with its loop (FLOOR_DESIGN_KEYS). The margins kept are the design's
    phase_margin_deg and gain_margin_db; a file without them was made with `loop_requirements`' (the shipped
    files: the margins design keeps those)."""
    if design.get("method") != "margins" or any(k not in design for k in FLOOR_DESIGN_KEYS):
        return (), None
    try:
        rate_hz, prediction_s, arc_g = (float(design[k]) for k in FLOOR_DESIGN_KEYS[:3])
        low, high, step = (float(v) for v in design["lookahead_range_m"])
        floors = tuple(
            (float(row["speed_kmh"]), float(row["lookahead_floor_m"]))
            for row in design["per_speed"]
            if "lookahead_floor_m" in row
        )
    except (TypeError, ValueError) as exc:
        raise WorkbenchInputError(f"{path}: design's floors ({list(FLOOR_DESIGN_KEYS)}, per_speed): {exc}") from None
    try:
        phase_deg = float(design.get("phase_margin_deg", REQUIRED_PHASE_MARGIN_DEG))
        gain_db = float(design.get("gain_margin_db", REQUIRED_GAIN_MARGIN_DB))
    except (TypeError, ValueError) as exc:
        raise WorkbenchInputError(f"{path}: design's phase_margin_deg, gain_margin_db: {exc}") from None
    return floors, FloorDesign(1.0 / rate_hz, prediction_s, arc_g, (low, high, step), phase_deg, gain_db)


def _row_lag(path: Path, i: int, row: Mapping[str, Any], prefix: str, speed: float) -> SteeringLag:
    """The lag of one per_speed row: its keys with `prefix` ("" for the path lag, "measured_" for the other)."""
    what = "measured lag" if prefix else "lag"
    try:
        return SteeringLag(
            row[f"{prefix}omega_n_rad_s"],
            row[f"{prefix}zeta"],
            row.get(f"{prefix}delay_s", 0.0),
            steady_state_gain=row.get(f"{prefix}steady_state_gain", 1.0),
            nrmse=row.get(f"{prefix}nrmse", math.nan),
            source=f"{what} identified at {speed:g} km/h ({path})",
        )
    except (WorkbenchInputError, TypeError) as exc:
        raise WorkbenchInputError(f"{path}: design.per_speed[{i}] ({what}): {exc}") from None


def _check_digests(path: Path, recorded: object) -> None:
    """Refuse a tuning directory whose files are not the ones its manifest's files_sha256 records: a tuning is
    used only as it was made."""
    if not isinstance(recorded, Mapping) or sorted(recorded) != sorted(DIGESTED_FILES):
        raise WorkbenchInputError(
            f"tuning manifest {str(path / MANIFEST_FILE)!r}: files_sha256 must map each of {list(DIGESTED_FILES)} "
            f"to its SHA-256; got {recorded!r}"
        )
    for name, actual in files_sha256(path).items():
        if recorded[name] != actual:
            raise WorkbenchInputError(
                f"tuning directory {str(path)!r}: {name} is not the file its manifest records (SHA-256 "
                f"{str(recorded[name])[:12]}..., the file's {actual[:12]}...): it was changed after the tuning was "
                "made, and a tuning is used only as it was made; make it again, or give an edited filter as the "
                "controller's filter_file"
            )


@functools.lru_cache(maxsize=64)
def _read(directory: str, _stamp: tuple[int, ...]) -> VehicleTuning:
    path = Path(directory)
    manifest = read_manifest(path)
    _check_digests(path, manifest["files_sha256"])
    lead = path / LEAD_FILE
    schedule = read_filter_file(lead)
    limits = read_limits_file(path / LIMITS_FILE)
    who = f"preset {manifest['preset']!r}" if manifest["preset"] else f"vehicle {manifest['vehicle']!r}"
    source = f"{path} ({who}, params sha256 {str(manifest['params_sha256'])[:12]}, made {manifest['date']})"
    design = _design(lead)
    lags, measured = _lags(lead, design, schedule)
    floors, floor_design = _floors(lead, design)
    previews = _previews(lead, design)
    releases = _releases(lead, design)
    try:
        return VehicleTuning(schedule, limits, lags, source, measured, floors, floor_design, previews, releases)
    except WorkbenchInputError as exc:
        raise WorkbenchInputError(f"{lead}: {exc}") from None


def read_vehicle_tuning(directory: str | Path) -> VehicleTuning:
    """Read a tuning directory (lead.json, limits.csv, manifest.json); WorkbenchInputError naming the file and the
    problem for anything it cannot use. Reads are remembered while the files are unchanged."""
    path = Path(directory)
    stamp = []
    for name in (MANIFEST_FILE, LEAD_FILE, LIMITS_FILE):
        try:
            stamp.append((path / name).stat().st_mtime_ns)
        except OSError:
            raise WorkbenchInputError(f"tuning directory {str(path)!r} has no {name}") from None
    return _read(str(path.resolve()), tuple(stamp))
