"""The clothoid controller's tuning of every vehicle preset, made by the `tuning` CLI: `python -m tuning.preset_tuning`.

    python -m tuning.preset_tuning [--only NAME] [--out-dir DIR] [--check]

For each preset (workbench/presets/<name>.toml) it runs, in a fresh directory,

    tuning schedule --vehicle NAME --speeds ... [--delay] --design margins ... --drop-refused --out lead.json
    tuning rollover-limits --vehicle NAME --speeds ... --out limits.csv       (a model with load transfer: the truck)
    tuning steering-limits --vehicle NAME --speeds ... --out limits.csv       (the cars: no roll model)

and writes manifest.json (the commands, the options, the hash of the preset's parameters, the package version,
the date, the speeds dropped and why), then moves the directory to workbench/presets/tuning/<name>/, where
`tuning.own_tuning.tuning_for` reads it. `--check` changes nothing and exits 1 listing the
presets whose files are stale: made for other parameters or other options than the current ones (the test
tests/tuning/test_tuning_dirs.py fails the same way).

Every design option is in PRESET_TUNING_OPTIONS below: change it there and re-run the script. A user's own vehicle
gets the same chain with the same options (`tuning_for` calls `write_tuning_files`, the functions these commands
call), cached per vehicle.
"""

from __future__ import annotations

import argparse
import datetime
import json
import shlex
import shutil
import subprocess
import sys
import tempfile
import time
from collections.abc import Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

from tuning.lag_fit import LagFitOptions
from tuning.limits_file import write_limits_file
from tuning.preview_fit import FUTURE_RANGE_S, PAST_RANGE_S, PreviewFitOptions
from tuning.rollover import LTR_OUTPUT, rollover_limits
from tuning.rollover import to_curvature_limits as rollover_curvature_limits
from tuning.schedule import (
    DEFAULT_CONTROLLER_RATE_HZ,
    DEFAULT_PREDICTION_TIME_S,
    DESIGNS,
    MARGINS_LOOKAHEAD_M,
    identify_schedule,
)
from tuning.speeds import check_speeds
from tuning.steering_limits import steering_limits
from tuning.steering_limits import to_curvature_limits as steering_curvature_limits
from tuning.tuning_dirs import (
    LEAD_FILE,
    LIMITS_FILE,
    MANIFEST_FILE,
    MANIFEST_FORMAT,
    files_sha256,
    params_sha256,
    read_manifest,
    read_vehicle_tuning,
    shipped_tuning_root,
)
from workbench.base.errors import WorkbenchInputError, require_in_range
from workbench.base.version import installed_version
from workbench.vehicles import list_presets, make_vehicle
from workbench.vehicles.base import VehicleModel

EXIT_STALE = 1
EXIT_INPUT_ERROR = 2


#: The preview fit's defaults (`tuning/preview_fit.py`), the tuning options' too.
PREVIEW_DEFAULTS = PreviewFitOptions()


@dataclass(frozen=True)
class SpeedOverride:
    """Schedule speeds (km/h) for one model type instead of the common ones, and why."""

    model: str
    speeds_kmh: tuple[float, ...]
    reason: str


@dataclass(frozen=True)
class VehicleTuningOptions:
    """The options as they apply to one model type (what a manifest records)."""

    schedule_speeds_kmh: tuple[float, ...]
    fit_delay: bool
    max_lead_gain: float
    max_cascade_peak_db: float
    lat_accel_g: float
    limits_speeds_kmh: tuple[float, ...]
    limit_lat_accel_g: float
    speeds_note: str = ""
    design: str = "cancel"
    controller_rate_hz: float = DEFAULT_CONTROLLER_RATE_HZ
    prediction_time_s: float = DEFAULT_PREDICTION_TIME_S
    preview_past_s: float = PREVIEW_DEFAULTS.past_s
    preview_future_s: float = PREVIEW_DEFAULTS.future_s
    preview_lat_accel_g: float = PREVIEW_DEFAULTS.lat_accel_g

    def to_dict(self) -> dict[str, Any]:
        out = asdict(self)
        out["schedule_speeds_kmh"] = list(self.schedule_speeds_kmh)
        out["limits_speeds_kmh"] = list(self.limits_speeds_kmh)
        return out


@dataclass(frozen=True)
class PresetTuningOptions:
    """Every design option of the presets' tuning (and of a user vehicle's, made on first use).

    schedule_speeds_kmh: where the lag is identified and the lead filter designed (`tuning schedule --speeds`;
    a speed whose identification or design is refused is dropped and recorded, `--drop-refused`);
    fit_delay: fit Eq. 5 with a pure delay (`--delay`; the truck at 30 km/h has |G(j8)| = 0.73 where Eq. 5 without
    a delay gives 0.25, with one 0.64); max_lead_gain, max_cascade_peak_db: the lead design's bounds
    (`--max-lead-gain`, `--max-cascade-peak-db`, `tuning/lead_design.py`); lat_accel_g: the kinematic lateral
    acceleration of the identification maneuvers (`--lat-accel-g`, 0.1 g: linear, far from rollover);
    limits_speeds_kmh: the speeds of the curvature limits (`rollover-limits` or `steering-limits --speeds`; up to
    150 km/h, as the controller's default limits, because the table is held constant beyond its last speed);
    limit_lat_accel_g: the lateral-acceleration bound of `steering-limits` (vehicles without a roll model; 0.4 g,
    the controller's default); speed_overrides: other schedule speeds for a model type, with the reason;
    design: the lead design at each speed (`--design`: "cancel", zeros on the path lag's poles, or "margins", the
    shortest lookahead floor of the clothoid loop with 45 deg / 6 dB margins, from the path and measured lags);
    controller_rate_hz, prediction_time_s: the clothoid controller's rate and pose prediction the margins design
    analyses (`--controller-rate-hz`, `--prediction-time-s`; its defaults, 50 Hz and 0.2 s); preview_past_s,
    preview_future_s: how far before and after the present the preview responses reach (`--preview-past-s`,
    `--preview-future-s`, `tuning/preview_fit.py`; 8 s holds the truck's trailer settling, 2 s its lag's preview);
    preview_lat_accel_g: the kinematic lateral acceleration of their maneuvers (`--preview-lat-accel-g`, 0.2 g: the
    feed-forward's operating range, `PreviewFitOptions.lat_accel_g`).
    """

    schedule_speeds_kmh: tuple[float, ...]
    fit_delay: bool
    max_lead_gain: float
    max_cascade_peak_db: float
    lat_accel_g: float
    limits_speeds_kmh: tuple[float, ...]
    limit_lat_accel_g: float
    speed_overrides: tuple[SpeedOverride, ...] = field(default=())
    design: str = "cancel"
    controller_rate_hz: float = DEFAULT_CONTROLLER_RATE_HZ
    prediction_time_s: float = DEFAULT_PREDICTION_TIME_S
    preview_past_s: float = PREVIEW_DEFAULTS.past_s
    preview_future_s: float = PREVIEW_DEFAULTS.future_s
    preview_lat_accel_g: float = PREVIEW_DEFAULTS.lat_accel_g

    def __post_init__(self) -> None:
        for name in ("schedule_speeds_kmh", "limits_speeds_kmh"):
            object.__setattr__(self, name, tuple(check_speeds(getattr(self, name), 5.0, 200.0)))
        for o in self.speed_overrides:
            check_speeds(o.speeds_kmh, 5.0, 200.0)
        if not isinstance(self.fit_delay, bool):
            raise WorkbenchInputError(f"fit_delay must be True or False; got {self.fit_delay!r}")
        require_in_range("max_lead_gain", self.max_lead_gain, 1.0, 1000.0)
        require_in_range("max_cascade_peak_db", self.max_cascade_peak_db, 0.0, 20.0, "dB")
        require_in_range("lat_accel_g", self.lat_accel_g, 0.001, 1.0, "g")
        require_in_range("limit_lat_accel_g", self.limit_lat_accel_g, 0.001, 2.0, "g")
        if self.design not in DESIGNS:
            raise WorkbenchInputError(f"design must be one of {', '.join(DESIGNS)}; got {self.design!r}")
        require_in_range("controller_rate_hz", self.controller_rate_hz, 1.0, 1000.0, "Hz")
        require_in_range("prediction_time_s", self.prediction_time_s, 0.0, 2.0, "s")
        require_in_range("preview_past_s", self.preview_past_s, *PAST_RANGE_S, "s")
        require_in_range("preview_future_s", self.preview_future_s, *FUTURE_RANGE_S, "s")
        require_in_range("preview_lat_accel_g", self.preview_lat_accel_g, 0.001, 1.0, "g")

    def for_model(self, model_type: str) -> VehicleTuningOptions:
        override = next((o for o in self.speed_overrides if o.model == model_type), None)
        return VehicleTuningOptions(
            schedule_speeds_kmh=tuple(float(s) for s in override.speeds_kmh) if override else self.schedule_speeds_kmh,
            fit_delay=self.fit_delay,
            max_lead_gain=float(self.max_lead_gain),
            max_cascade_peak_db=float(self.max_cascade_peak_db),
            lat_accel_g=float(self.lat_accel_g),
            limits_speeds_kmh=self.limits_speeds_kmh,
            limit_lat_accel_g=float(self.limit_lat_accel_g),
            speeds_note=override.reason if override else "",
            design=self.design,
            controller_rate_hz=float(self.controller_rate_hz),
            prediction_time_s=float(self.prediction_time_s),
            preview_past_s=float(self.preview_past_s),
            preview_future_s=float(self.preview_future_s),
            preview_lat_accel_g=float(self.preview_lat_accel_g),
        )


#: The options the shipped tunings are made with. Change a value here, then run `python -m tuning.preset_tuning`.
PRESET_TUNING_OPTIONS = PresetTuningOptions(
    schedule_speeds_kmh=(10.0, 20.0, 30.0, 40.0, 50.0, 60.0, 70.0, 80.0, 90.0, 100.0),
    fit_delay=True,
    max_lead_gain=6.0,
    max_cascade_peak_db=1.0,
    lat_accel_g=0.1,
    limits_speeds_kmh=tuple(float(s) for s in range(10, 151, 10)),
    limit_lat_accel_g=0.4,
    speed_overrides=(),
    design="margins",
    controller_rate_hz=50.0,
    prediction_time_s=0.2,
    preview_past_s=8.0,
    preview_future_s=2.0,
    preview_lat_accel_g=0.2,
)


def options_dict(options: PresetTuningOptions, model_type: str) -> dict[str, Any]:
    """The options as resolved for one model type, as recorded in a manifest."""
    return options.for_model(model_type).to_dict()


#: Rough generation time per schedule speed (s), by model type, for the message of a first use (measured with the
#: margins design, a delay and the sideslip's braked turn, the limits included, two tunings at once on two cores:
#: 60-68 s for the truck's ten speeds, 74-75 s for the dynamic bicycle's; the kinematic bicycle's and the
#: CommonRoad plant's, pure Python, measured before the braked turn was added, 46-52 s and 115 s).
SECONDS_PER_SPEED = {
    "kinematic-bicycle": 5.0,
    "dynamic-bicycle": 7.5,
    "tractor-semitrailer": 6.5,
    "commonroad-mb": 12.0,
}


def _number(value: float) -> str:
    value = float(value)
    return str(int(value)) if value.is_integer() else repr(value)


def _speeds(speeds: Sequence[float]) -> str:
    return ",".join(_number(s) for s in speeds)


def has_roll_model(vehicle: VehicleModel) -> bool:
    """Whether the vehicle has load transfer (LTR), so that its limits come from rollover."""
    return LTR_OUTPUT in vehicle.output_names


def tuning_commands(
    vehicle: VehicleModel, vehicle_args: Sequence[str], options: VehicleTuningOptions
) -> list[list[str]]:
    """The `tuning` commands (argv lists) that make lead.json and limits.csv in the current directory."""
    schedule = ["tuning", "schedule", *vehicle_args, "--speeds", _speeds(options.schedule_speeds_kmh)]
    schedule += ["--lat-accel-g", _number(options.lat_accel_g), "--max-lead-gain", _number(options.max_lead_gain)]
    schedule += ["--max-cascade-peak-db", _number(options.max_cascade_peak_db)]
    schedule += ["--delay"] if options.fit_delay else []
    schedule += ["--design", options.design]
    if options.design == "margins":
        schedule += ["--controller-rate-hz", _number(options.controller_rate_hz)]
        schedule += ["--prediction-time-s", _number(options.prediction_time_s)]
    schedule += ["--preview-past-s", _number(options.preview_past_s)]
    schedule += ["--preview-future-s", _number(options.preview_future_s)]
    schedule += ["--preview-lat-accel-g", _number(options.preview_lat_accel_g)]
    schedule += ["--drop-refused", "--out", LEAD_FILE]
    if has_roll_model(vehicle):
        limits = ["tuning", "rollover-limits", *vehicle_args, "--speeds", _speeds(options.limits_speeds_kmh)]
    else:
        limits = ["tuning", "steering-limits", *vehicle_args, "--speeds", _speeds(options.limits_speeds_kmh)]
        limits += ["--lat-accel-g", _number(options.limit_lat_accel_g)]
    return [schedule, [*limits, "--out", LIMITS_FILE]]


def write_manifest(
    directory: Path,
    vehicle: VehicleModel,
    preset: str | None,
    options: PresetTuningOptions,
    commands: list[list[str]],
    seconds: dict[str, float],
) -> Path:
    """manifest.json of a tuning directory whose lead.json and limits.csv are written (module docstring)."""
    resolved = options.for_model(vehicle.name)
    lead = json.loads((directory / LEAD_FILE).read_text(encoding="utf-8"))
    dropped = lead.get("design", {}).get("dropped_speeds", [])
    notes = [f"lead.json: {lead.get('source', '')}"]
    if resolved.speeds_note:
        notes.append(f"schedule speeds {_speeds(resolved.schedule_speeds_kmh)}: {resolved.speeds_note}")
    notes += [f"{d['speed_kmh']:g} km/h dropped from the schedule: {d['reason']}" for d in dropped]
    if resolved.design == "margins":
        rows = lead.get("design", {}).get("per_speed", [])
        notes += [
            f"{r['speed_kmh']:g} km/h: no lookahead up to {MARGINS_LOOKAHEAD_M[1]:g} m keeps 45 deg / 6 dB with any "
            f"lead filter of the grid; the filter is the one with the best margins at {MARGINS_LOOKAHEAD_M[1]:g} m "
            f"(margin score {r.get('margin_score', float('nan')):.2f}, 1 meeting them)"
            for r in rows
            if "lookahead_floor_m" not in r
        ]
    limits = commands[1][1]
    notes.append(
        f"limits.csv by `tuning {limits}`: "
        + (
            "the curvature at which LTR reaches 1 in a step steer (steering lock where it does not), at the preset's "
            "payload; rate from the steering-rate limit"
            if limits == "rollover-limits"
            else f"steering lock, {resolved.limit_lat_accel_g:g} g and the steering-rate limit (no roll model)"
        )
    )
    manifest = {
        "format": MANIFEST_FORMAT,
        "vehicle": vehicle.name,
        "preset": preset,
        "params_sha256": params_sha256(vehicle),
        "options": options_dict(options, vehicle.name),
        "commands": [shlex.join(c) for c in commands],
        "dropped_speeds": dropped,
        "notes": notes,
        "package_version": installed_version() or "unknown",
        "date": datetime.datetime.now(datetime.UTC).date().isoformat(),
        "generation_time_s": {k: round(v, 1) for k, v in seconds.items()},
        "files_sha256": files_sha256(directory),
    }
    path = directory / MANIFEST_FILE
    path.write_text(json.dumps(manifest, indent=2) + "\n", encoding="utf-8")
    return path


def write_tuning_files(
    vehicle: VehicleModel,
    directory: str | Path,
    options: PresetTuningOptions,
    vehicle_args: Sequence[str],
    preset: str | None,
) -> Path:
    """Make lead.json, limits.csv and manifest.json in `directory` in-process, by the functions the commands of
    `tuning_commands` call (for a vehicle that is not a preset: `tuning_for`'s first use). vehicle_args: how the
    recorded commands name the vehicle (e.g. --vehicle-file vehicle.toml)."""
    directory = Path(directory)
    resolved = options.for_model(vehicle.name)
    commands = tuning_commands(vehicle, vehicle_args, resolved)
    start = time.perf_counter()
    result = identify_schedule(
        vehicle,
        resolved.schedule_speeds_kmh,
        lat_accel_g=resolved.lat_accel_g,
        fit_options=LagFitOptions(fit_delay=resolved.fit_delay),
        max_lead_gain=resolved.max_lead_gain,
        max_cascade_peak_db=resolved.max_cascade_peak_db,
        drop_refused=True,
        design=resolved.design,
        controller_rate_hz=resolved.controller_rate_hz,
        prediction_time_s=resolved.prediction_time_s,
        preview_options=PreviewFitOptions(
            past_s=resolved.preview_past_s,
            future_s=resolved.preview_future_s,
            lat_accel_g=resolved.preview_lat_accel_g,
        ),
    )
    result.write(directory / LEAD_FILE)
    middle = time.perf_counter()
    if has_roll_model(vehicle):
        limits = rollover_curvature_limits(rollover_limits(vehicle, resolved.limits_speeds_kmh), vehicle)
    else:
        table = steering_limits(vehicle.geometry, resolved.limits_speeds_kmh, resolved.limit_lat_accel_g)
        limits = steering_curvature_limits(table, vehicle.name, resolved.limit_lat_accel_g)
    write_limits_file(limits, directory / LIMITS_FILE)
    seconds = {"schedule": middle - start, "limits": time.perf_counter() - middle}
    write_manifest(directory, vehicle, preset, options, commands, seconds)
    return directory


def _run_cli(command: list[str], cwd: Path) -> float:
    """Run one `tuning` command (as `python -m tuning.cli`) in cwd, echoing its output; its wall time (s)."""
    print(f"$ {shlex.join(command)}", flush=True)
    start = time.perf_counter()
    done = subprocess.run([sys.executable, "-m", "tuning.cli", *command[1:]], cwd=cwd, check=False)
    if done.returncode != 0:
        raise WorkbenchInputError(
            f"`{shlex.join(command)}` failed (exit code {done.returncode}); see its message above"
        )
    return time.perf_counter() - start


def generate_preset(name: str, out_dir: Path, options: PresetTuningOptions = PRESET_TUNING_OPTIONS) -> Path:
    """Run the `tuning` commands for preset `name` and put the files in out_dir/name (replacing any there)."""
    vehicle = make_vehicle(name)
    commands = tuning_commands(vehicle, ["--vehicle", name], options.for_model(vehicle.name))
    out_dir.mkdir(parents=True, exist_ok=True)
    work = Path(tempfile.mkdtemp(prefix=f".{name}.", suffix=".tmp", dir=out_dir))
    try:
        seconds = {}
        for command, key in zip(commands, ("schedule", "limits"), strict=True):
            seconds[key] = _run_cli(command, work)
        write_manifest(work, vehicle, name, options, commands, seconds)
        read_vehicle_tuning(work)  # what tuning_for will read must read
        target = out_dir / name
        old = out_dir / f".{name}.old"
        shutil.rmtree(old, ignore_errors=True)
        if target.exists():
            target.rename(old)
        work.rename(target)
        target.chmod(0o755)  # mkdtemp made it private; the files are shipped
        shutil.rmtree(old, ignore_errors=True)
        return target
    finally:
        shutil.rmtree(work, ignore_errors=True)


def stale_reasons(name: str, directory: Path, options: PresetTuningOptions = PRESET_TUNING_OPTIONS) -> list[str]:
    """Why the tuning in `directory` is not the one preset `name` would get now (empty: it is current)."""
    try:
        manifest = read_manifest(directory)
        read_vehicle_tuning(directory)
    except WorkbenchInputError as exc:
        return [str(exc)]
    vehicle = make_vehicle(name)
    reasons = []
    if manifest["params_sha256"] != params_sha256(vehicle):
        reasons.append(f"made for other parameters (params sha256 {manifest['params_sha256'][:12]}, the preset's now "
                       f"{params_sha256(vehicle)[:12]})")  # fmt: skip
    current = options_dict(options, vehicle.name)
    if manifest["options"] != current:
        changed = sorted(
            k for k in set(current) | set(manifest["options"]) if manifest["options"].get(k) != current.get(k)
        )
        reasons.append(f"made with other options (differing: {', '.join(changed)})")
    if manifest["preset"] != name:
        reasons.append(f"the manifest names preset {manifest['preset']!r}")
    return reasons


def regenerate_command(name: str) -> str:
    return f"python -m tuning.preset_tuning --only {name}"


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="python -m tuning.preset_tuning",
        description="Make the clothoid controller's tuning (lead filter schedule, curvature limits) of every vehicle "
        "preset by running the `tuning` CLI; or check that the shipped files are current.",
    )
    parser.add_argument("--only", metavar="NAME", action="append", help="this preset only (repeatable)")
    parser.add_argument(
        "--out-dir", type=Path, help="where the <preset>/ directories go (default: workbench/presets/tuning)"
    )
    parser.add_argument("--check", action="store_true", help="change nothing; exit 1 listing the stale presets")
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    args = _parser().parse_args(argv)
    presets = list(list_presets())
    names = args.only or presets
    unknown = [n for n in names if n not in presets]
    if unknown:
        print(f"preset_tuning: error: unknown preset(s) {unknown}; choose from {presets}", file=sys.stderr)
        return EXIT_INPUT_ERROR
    out_dir = args.out_dir or shipped_tuning_root()
    if args.check:
        stale = {n: stale_reasons(n, out_dir / n) for n in names}
        stale = {n: r for n, r in stale.items() if r}
        for name, reasons in stale.items():
            print(f"stale: {name}: {'; '.join(reasons)}; regenerate with `{regenerate_command(name)}`")
        if not stale:
            print(f"up to date: {', '.join(names)} ({out_dir})")
        return EXIT_STALE if stale else 0
    for name in names:
        start = time.perf_counter()
        try:
            target = generate_preset(name, out_dir)
        except WorkbenchInputError as exc:
            print(f"preset_tuning: error: {name}: {exc}", file=sys.stderr)
            return EXIT_INPUT_ERROR
        manifest = read_manifest(target)
        for note in manifest["notes"]:
            print(f"  note: {note}")
        print(f"{name}: wrote {target} in {time.perf_counter() - start:.0f} s", flush=True)
    return 0


__all__ = [
    "PRESET_TUNING_OPTIONS",
    "PresetTuningOptions",
    "SpeedOverride",
    "VehicleTuningOptions",
    "generate_preset",
    "main",
    "stale_reasons",
    "tuning_commands",
    "write_tuning_files",
]

if __name__ == "__main__":
    sys.exit(main())
