"""The `tuning` command line: tools that turn vehicle logs into the parameter files the controllers read.

    tuning generate-data    drive a plant open loop with a steering profile, write a vehicle log (CSV)
    tuning fit-lag          fit the lag of Eq. 5 to vehicle logs, write lag.json (steering-lag/1)
    tuning design-lead      design the lead filter of Eq. 6 for a lag, write lead.json/.toml (lead-filter/1)
    tuning rollover-limits  step-steer series: curvature at LTR = 1 per speed, write limits.csv
    tuning steering-limits  steering lock, lateral acceleration and steering rate per speed (vehicles without a
                            roll model), write limits.csv
    tuning schedule         lag and lead filter at each speed, write a scheduled lead-filter file
    tuning margins          the clothoid loop's margins against lookahead per speed and the lookahead floor,
                            write margins.csv

Every input file and output file is checked before any work (`workbench.base.input_files`, `workbench.base.output_dir`):
a missing or unreadable input, a folder where a file is wanted, a parent that is a file, an unwritable folder or
file are refused, and so is an output file that exists already unless --overwrite is given.

`tuning --version` (as `workbench --version`: `workbench.base.version`) prints the installed distribution's
version and, run from a git checkout, its commit.

Exit codes: 0 done; 2 bad input (one line on stderr naming the value and what is allowed).
"""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING

from workbench.base.console import console_exit
from workbench.base.errors import WorkbenchInputError
from workbench.base.version import VersionAction

if TYPE_CHECKING:
    from tqdm import tqdm

    from tuning.lag_fit import SteeringGeometry
    from workbench.vehicles.base import VehicleGeometry, VehicleModel
    from workbench.vehicles.steering_lag import SteeringLag

# The tuning modules (python-control, SciPy, the controllers, the simulator) are imported inside the command that
# needs them and the parser builds only the options of the command being run, so that `tuning --help` starts fast
# (benchmarks/startup.py measures it).

EXIT_INPUT_ERROR = 2
FORMATS = ("json", "toml")
#: The input-file options of the commands: argparse dest -> (the option, or None for a positional; what it is).
INPUT_FILES: dict[str, tuple[str | None, str]] = {
    "logs": (None, "vehicle log"),
    "validate": ("--validate", "vehicle log"),
    "vehicle_file": ("--vehicle-file", "vehicle file"),
    "lag": ("--lag", "steering-lag file"),
    "measured_lag": ("--measured-lag", "steering-lag file"),
    "lead": ("--lead", "lead filter file"),
}
#: The output-file options: argparse dest -> the option.
OUTPUT_FILES = {"out": "--out", "plot": "--plot", "validate_plot": "--validate-plot"}


def _vehicle_options(parser: argparse.ArgumentParser, required: bool = True) -> None:
    what = "" if required else " (or --wheelbase-m and --steering-ratio)"
    parser.add_argument("--vehicle", help=f"vehicle model (see `workbench vehicles`){what}")
    parser.add_argument("--vehicle-file", type=Path, help="a vehicle TOML file instead of a named preset")
    parser.add_argument("--payload-kg", type=float, help="payload of vehicles that carry one (tractor-semitrailer)")


def _geometry_options(parser: argparse.ArgumentParser) -> None:
    _vehicle_options(parser, required=False)
    parser.add_argument("--wheelbase-m", type=float, help="wheelbase of a vehicle without a model here (m)")
    parser.add_argument("--steering-ratio", type=float, help="its steering ratio (steering wheel / road wheel)")


def _format_option(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--format", choices=FORMATS, help="file format (default: by the --out suffix, .json or .toml)")


def _overwrite_option(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--overwrite",
        action="store_true",
        help="replace output files (--out, --plot, ...) that exist already (default: an existing one is refused)",
    )


def _design_options(parser: argparse.ArgumentParser) -> None:
    from tuning.lead_design import DEFAULT_MAX_CASCADE_PEAK_DB, DEFAULT_MAX_LEAD_GAIN

    parser.add_argument(
        "--max-lead-gain",
        type=float,
        default=DEFAULT_MAX_LEAD_GAIN,
        help=f"bound on the peak gain of the lead filter, which bounds how much it raises the steering rate "
        f"(linear; default {DEFAULT_MAX_LEAD_GAIN:g} = {20 * math.log10(DEFAULT_MAX_LEAD_GAIN):.0f} dB)",
    )
    parser.add_argument(
        "--max-cascade-peak-db",
        type=float,
        default=DEFAULT_MAX_CASCADE_PEAK_DB,
        help=f"bound on the resonance of lead x lag (dB; default {DEFAULT_MAX_CASCADE_PEAK_DB:g})",
    )


def _command_word(argv: Sequence[str]) -> str:
    """The command argv names (its first word that is not an option), or "" without one."""
    return next((word for word in argv if not word.startswith("-")), "")


def _builds(command: str | None, name: str) -> bool:
    """Whether the parser adds the options of command `name`: the one being run, or every one (command None)."""
    return command is None or command == name


def _parser(command: str | None = None) -> argparse.ArgumentParser:
    """The parser. `command` (the one being run, "" for none) limits the options built, and the modules their
    defaults are read from, to that command's; None: every command's."""
    parser = argparse.ArgumentParser(prog="tuning", description="Identify vehicle lag and tune controller filters.")
    parser.add_argument("--version", action=VersionAction)
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    gen = sub.add_parser(
        "generate-data",
        help="drive a plant open loop with a steering profile and write a CSV log (the fit-lag input format)",
    )
    if _builds(command, "generate-data"):
        from tuning.maneuvers import Maneuver

        _vehicle_options(gen)
        gen.add_argument("--maneuver", required=True, choices=Maneuver.KINDS, help="steering-wheel profile")
        gen.add_argument("--speed", type=float, required=True, metavar="KMH", help="held speed, km/h")
        size = gen.add_mutually_exclusive_group()
        size.add_argument("--amplitude-deg", type=float, help="steering-wheel amplitude (default 90 deg)")
        size.add_argument(
            "--lat-accel-g", type=float, help="size the amplitude for this kinematic lateral acceleration (g) instead"
        )
        gen.add_argument("--duration-s", type=float, default=20.0, help="log length (default 20 s)")
        gen.add_argument(
            "--chirp-hz",
            default="0.1:2",
            metavar="LOW:HIGH",
            help="frequency band of --maneuver chirp, swept exponentially over the log (default 0.1:2 Hz)",
        )
        gen.add_argument(
            "--max-rate-deg-s",
            type=float,
            help="limit the steering-wheel rate of the profile (deg/s; steps become ramps, the chirp's amplitude falls "
            "at high frequency; default: no limit)",
        )
        gen.add_argument("--sample-rate-hz", type=float, default=100.0, help="log sample rate (default 100 Hz)")
        gen.add_argument("--out", type=Path, required=True, metavar="FILE.csv", help="output CSV")
        _overwrite_option(gen)

    fit = sub.add_parser("fit-lag", help="fit the steering lag of Eq. 5 to vehicle logs; write lag.json")
    if _builds(command, "fit-lag"):
        from tuning.lag_fit import CURVATURE_SOURCES

        fit.add_argument("logs", type=Path, nargs="+", metavar="FILE.csv", help="vehicle logs at one speed")
        fit.add_argument("--out", type=Path, required=True, metavar="lag.json", help="output steering-lag file")
        fit.add_argument("--plot", type=Path, metavar="FILE.png", help="Figure 8: kinematic, actual, with lag")
        _overwrite_option(fit)
        _geometry_options(fit)
        fit.add_argument(
            "--curvature-from",
            choices=CURVATURE_SOURCES,
            default="auto",
            help="realised curvature: of the rear-axle path x, y (auto when present) or yaw rate / speed",
        )
        fit.add_argument("--smooth-s", type=float, default=0.3, help="window of the path derivatives (default 0.3 s)")
        fit.add_argument("--delay", action="store_true", help="also fit a pure time delay")
        fit.add_argument("--unit-gain", action="store_true", help="fix the steady-state gain at 1 (Eq. 5 strictly)")
        fit.add_argument(
            "--max-speed-variation",
            type=float,
            default=0.15,
            help="largest (max - min) / mean speed over the logs (default 0.15)",
        )

    lead = sub.add_parser("design-lead", help="design the lead filter of Eq. 6 for a lag; write lead.json/.toml")
    if _builds(command, "design-lead"):
        lead.add_argument("--lag", type=Path, required=True, metavar="lag.json", help="steering-lag file (fit-lag)")
        lead.add_argument("--out", type=Path, required=True, metavar="lead.json", help="output lead-filter file")
        _format_option(lead)
        lead.add_argument("--plot", type=Path, metavar="FILE.png", help="Figure 10: Bode of plant, filter, cascade")
        _overwrite_option(lead)
        _design_options(lead)
        lead.add_argument(
            "--phase-at-rad-s", type=float, help="report the phases at this frequency (default: the plant's bandwidth)"
        )
        lead.add_argument(
            "--validate", type=Path, nargs="+", metavar="FILE.csv", help="vehicle logs for Figure 9 (time domain)"
        )
        lead.add_argument(
            "--validate-plot", type=Path, metavar="FILE.png", help="where Figure 9 goes (default: beside --out)"
        )
        _geometry_options(lead)

    roll = sub.add_parser("rollover-limits", help="curvature at LTR = 1 per speed (Figure 6); write limits.csv")
    if _builds(command, "rollover-limits"):
        _vehicle_options(roll)
        roll.add_argument("--speeds", required=True, metavar="10,20,...,100", help="speeds, km/h")
        roll.add_argument("--out", type=Path, required=True, metavar="limits.csv", help="output curvature-limits CSV")
        roll.add_argument("--plot", type=Path, metavar="FILE.png", help="Figure 6")
        _overwrite_option(roll)

    steer = sub.add_parser(
        "steering-limits",
        help="curvature limits of a vehicle without a roll model: steering lock, lateral acceleration, steering "
        "rate; write limits.csv",
    )
    if _builds(command, "steering-limits"):
        from controllers.clothoid.curvature_limits import DEFAULT_LIMIT_LATERAL_ACCEL_G

        _vehicle_options(steer)
        steer.add_argument("--speeds", required=True, metavar="10,20,...,150", help="speeds, km/h")
        steer.add_argument(
            "--lat-accel-g",
            type=float,
            default=DEFAULT_LIMIT_LATERAL_ACCEL_G,
            help=f"lateral-acceleration bound (default {DEFAULT_LIMIT_LATERAL_ACCEL_G:g} g, the controller's default)",
        )
        steer.add_argument("--out", type=Path, required=True, metavar="limits.csv", help="output curvature-limits CSV")
        _overwrite_option(steer)

    sched = sub.add_parser("schedule", help="lag and lead filter at each speed; write a scheduled lead-filter file")
    if _builds(command, "schedule"):
        from tuning.preview_fit import PreviewFitOptions
        from tuning.schedule import DEFAULT_CONTROLLER_RATE_HZ, DEFAULT_LAT_ACCEL_G, DEFAULT_PREDICTION_TIME_S, DESIGNS

        _vehicle_options(sched)
        sched.add_argument("--speeds", required=True, metavar="20,30,...,90", help="speeds, km/h")
        sched.add_argument("--out", type=Path, required=True, metavar="schedule.json", help="output lead-filter file")
        _format_option(sched)
        _overwrite_option(sched)
        sched.add_argument(
            "--delay",
            action="store_true",
            help="fit the lag of Eq. 5 with a pure delay at each speed (as fit-lag --delay); per_speed records delay_s",
        )
        sched.add_argument(
            "--design",
            choices=DESIGNS,
            default="cancel",
            help="the lead filter at each speed: cancel (default; zeros on the path lag's poles, design-lead's) or "
            "margins (the shortest lookahead floor of the clothoid loop with 45 deg / 6 dB margins, from the path and "
            "the measured lag; records lookahead_floor_m and floor_without_lead_m per speed; a few s a speed)",
        )
        sched.add_argument(
            "--controller-rate-hz",
            type=float,
            default=DEFAULT_CONTROLLER_RATE_HZ,
            help=f"the clothoid controller's rate for --design margins (default {DEFAULT_CONTROLLER_RATE_HZ:g} Hz)",
        )
        sched.add_argument(
            "--prediction-time-s",
            type=float,
            default=DEFAULT_PREDICTION_TIME_S,
            help=f"its pose prediction for --design margins (default {DEFAULT_PREDICTION_TIME_S:g} s)",
        )
        sched.add_argument(
            "--preview-past-s",
            type=float,
            default=PreviewFitOptions.past_s,
            help="how far before the present the preview responses reach (default "
            f"{PreviewFitOptions.past_s:g} s; the slow responses' settling, tuning/preview_fit.py)",
        )
        sched.add_argument(
            "--preview-future-s",
            type=float,
            default=PreviewFitOptions.future_s,
            help=f"how far after the present they reach (default {PreviewFitOptions.future_s:g} s; the lag's preview)",
        )
        sched.add_argument(
            "--preview-lat-accel-g",
            type=float,
            default=PreviewFitOptions.lat_accel_g,
            help="the kinematic lateral acceleration of the maneuvers the preview responses are fitted to (default "
            f"{PreviewFitOptions.lat_accel_g:g} g: the feed-forward's operating range; the lags stay at --lat-accel-g)",
        )
        sched.add_argument(
            "--drop-refused",
            action="store_true",
            help="leave out a speed whose lag fit or lead design is refused (saying why, on stderr and in the file's "
            "design.dropped_speeds) instead of refusing the schedule",
        )
        sched.add_argument(
            "--lat-accel-g",
            type=float,
            default=DEFAULT_LAT_ACCEL_G,
            help=f"kinematic lateral acceleration of the identification maneuvers (default {DEFAULT_LAT_ACCEL_G:g} g)",
        )
        sched.add_argument(
            "--nominal-speed",
            type=float,
            metavar="KMH",
            help="speed of the top-level filter and of --compare's fixed filter, one of --speeds (default: the first "
            "speed; with --compare, 30 km/h, the paper's, when it is one of the speeds)",
        )
        _design_options(sched)
        sched.add_argument("--plot", type=Path, metavar="FILE.png", help="lag and filter against speed")
        sched.add_argument(
            "--compare",
            metavar="60,80",
            help="then run the clothoid controller on --compare-scenario at these speeds with the schedule, the fixed "
            "filter of --nominal-speed and no filter, and print the tracking and whether the schedule tracks better",
        )
        sched.add_argument("--compare-scenario", default="dlc", help="scenario of --compare (default dlc)")
    _add_margins_parser(sub, command)
    return parser


def _vehicle(args: argparse.Namespace) -> VehicleModel:
    from workbench.vehicles import make_vehicle

    if args.vehicle is None and args.vehicle_file is None:
        raise WorkbenchInputError("give --vehicle NAME or --vehicle-file FILE")
    return make_vehicle(args.vehicle, payload_kg=args.payload_kg, vehicle_file=args.vehicle_file)


def _geometry(args: argparse.Namespace) -> SteeringGeometry | VehicleGeometry:
    """The vehicle's geometry, or --wheelbase-m and --steering-ratio for a vehicle without a model here."""
    from tuning.lag_fit import SteeringGeometry

    manual = (args.wheelbase_m, args.steering_ratio)
    if any(v is not None for v in manual):
        if args.vehicle is not None or args.vehicle_file is not None:
            raise WorkbenchInputError("give either --vehicle/--vehicle-file or --wheelbase-m and --steering-ratio")
        if any(v is None for v in manual):
            raise WorkbenchInputError("--wheelbase-m and --steering-ratio go together; give both")
        return SteeringGeometry(args.wheelbase_m, args.steering_ratio)
    if args.vehicle is None and args.vehicle_file is None:
        raise WorkbenchInputError(
            "the kinematic curvature needs the vehicle: give --vehicle NAME, --vehicle-file FILE, or "
            "--wheelbase-m and --steering-ratio"
        )
    return _vehicle(args).geometry


def _filter_path(args: argparse.Namespace) -> Path:
    suffix = args.out.suffix.lower().lstrip(".")
    if args.format is not None and suffix != args.format:
        raise WorkbenchInputError(f"--out {str(args.out)!r} must end in .{args.format} for --format {args.format}")
    if suffix not in FORMATS:
        raise WorkbenchInputError(f"--out {str(args.out)!r} must end in .json or .toml; got {suffix or 'no suffix'!r}")
    return args.out


def _prepare(path: Path) -> Path:
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise WorkbenchInputError(f"cannot create the directory of {str(path)!r}: {exc}") from None
    return path


def _check_paths(args: argparse.Namespace) -> None:
    """Every input file must be a readable file and every output file writable and, without --overwrite, not there
    yet (INPUT_FILES, OUTPUT_FILES; and the default place of design-lead's validation figure): checked before any
    work."""
    from workbench.base.input_files import check_input_file
    from workbench.base.output_dir import check_output_file

    for dest, (flag, what) in INPUT_FILES.items():
        value = getattr(args, dest, None)
        for path in value if isinstance(value, list) else [] if value is None else [value]:
            check_input_file(path, f"{what} {str(path)!r}" + (f" ({flag})" if flag else ""))
    for dest, flag in OUTPUT_FILES.items():
        value = getattr(args, dest, None)
        if value is not None:
            check_output_file(value, flag, args.overwrite)
    if getattr(args, "validate", None) and getattr(args, "validate_plot", None) is None:
        check_output_file(_validation_plot(args.out), "the --validate figure", args.overwrite)


def _validation_plot(out: Path) -> Path:
    """Where design-lead draws Figure 9 without --validate-plot: beside --out."""
    return out.with_name(f"{out.stem}_validation.png")


def _read_lag(flag: str, path: Path) -> SteeringLag:
    """A steering-lag file; its JSON read safely first (deep nesting, not JSON), then checked as a lag."""
    from workbench.base.input_files import read_json
    from workbench.vehicles.steering_lag import read_lag_file

    label = f"steering-lag file {str(path)!r} ({flag})"
    read_json(path, label)
    try:
        return read_lag_file(path)
    except (OSError, RecursionError) as exc:
        raise WorkbenchInputError(f"{label}: cannot be read ({exc})") from None


def _generate_data(args: argparse.Namespace) -> int:
    from tuning.data_generation import check_log_size, generate_open_loop_log
    from tuning.maneuvers import Maneuver
    from tuning.schedule import steer_amplitude_deg

    check_log_size(args.duration_s, args.sample_rate_hz, names=("--duration-s", "--sample-rate-hz"))
    vehicle = _vehicle(args)
    amplitude = args.amplitude_deg if args.amplitude_deg is not None else 90.0
    if args.lat_accel_g is not None:
        if not (isinstance(args.lat_accel_g, float) and 0.0 < args.lat_accel_g <= 1.0):
            raise WorkbenchInputError(f"--lat-accel-g must be in (0, 1] g; got {args.lat_accel_g!r}")
        if not args.speed > 0:
            raise WorkbenchInputError(f"speed_kmh must be > 0; got {args.speed!r}")
        amplitude = steer_amplitude_deg(vehicle, args.speed, args.lat_accel_g)
    low, high = _band(args.chirp_hz)
    maneuver = Maneuver(
        args.maneuver,
        amplitude_deg=amplitude,
        duration_s=args.duration_s,
        start_hz=low,
        end_hz=high,
        max_rate_deg_s=args.max_rate_deg_s,
    )
    log = generate_open_loop_log(vehicle, maneuver, args.speed, sample_rate_hz=args.sample_rate_hz)
    _prepare(args.out)
    log.to_csv(args.out, index=False, float_format="%.9g")
    print(
        f"wrote {len(log)} rows ({log['t_s'].iloc[-1]:.1f} s of {args.maneuver}, amplitude {amplitude:.1f} deg, at "
        f"{args.speed:g} km/h) to {args.out}"
    )
    return 0


def _band(text: str) -> tuple[float, float]:
    """--chirp-hz LOW:HIGH as two numbers (Hz)."""
    parts = text.split(":")
    try:
        low, high = (float(p) for p in parts)
    except ValueError:
        raise WorkbenchInputError(f"--chirp-hz {text!r}: give LOW:HIGH in Hz, e.g. 0.1:2") from None
    return low, high


def _fit_lag(args: argparse.Namespace) -> int:
    from tuning.lag_fit import LagFitOptions, fit_lag
    from tuning.log_file import read_log
    from workbench.vehicles.steering_lag import write_lag_file

    geometry = _geometry(args)
    options = LagFitOptions(
        curvature_from=args.curvature_from,
        smooth_s=args.smooth_s,
        fit_delay=args.delay,
        unit_gain=args.unit_gain,
        max_speed_variation=args.max_speed_variation,
    )
    logs = [read_log(path) for path in args.logs]
    fit = fit_lag(logs, geometry, options)
    write_lag_file(fit.lag, _prepare(args.out))
    print(fit.summary())
    for log in fit.logs:
        print(f"  {log.name}: NRMSE {log.nrmse:.4f} (curvature from {log.curvature_from})")
    print(f"wrote {args.out}")
    if args.plot:
        from tuning.plots import lag_fit_figure

        print(f"wrote {lag_fit_figure(fit, args.plot)}")
    return 0


def _design_lead(args: argparse.Namespace) -> int:
    from tuning.filter_file import write_filter_file
    from tuning.lead_design import design_lead, validate
    from tuning.log_file import read_log

    out = _filter_path(args)
    lag = _read_lag("--lag", args.lag)
    design = design_lead(
        lag,
        max_lead_gain=args.max_lead_gain,
        max_cascade_peak_db=args.max_cascade_peak_db,
        phase_frequency_rad_s=args.phase_at_rad_s,
    )
    metadata = design.metadata()
    traces = []
    if args.validate:
        geometry = _geometry(args)
        traces = [validate(design, read_log(path), geometry) for path in args.validate]
        metadata["validation"] = [
            {"log": t.name, "nrmse_lagged": t.nrmse_lagged, "nrmse_compensated": t.nrmse_compensated} for t in traces
        ]
    speed = design.speed_kmh
    write_filter_file(
        _prepare(out),
        design.params,
        source=f"tuning design-lead from {args.lag.name}" + (f" ({lag.source})" if lag.source else ""),
        plant={"omega_n_rad_s": lag.omega_n_rad_s, "zeta": lag.zeta},
        speed_kmh=speed,
        extra=metadata,
    )
    print(design.summary())
    for t in traces:
        print(
            f"  {t.name}: NRMSE (normalised RMS error: against the kinematic curvature, over its range): "
            f"lagged {t.nrmse_lagged:.4f}, compensated {t.nrmse_compensated:.4f}"
        )
    print(f"wrote {out}")
    if args.plot or traces:
        from tuning.plots import bode_figure, validation_figure

        if args.plot:
            print(f"wrote {bode_figure(design, args.plot)}")
        if traces:
            target = args.validate_plot or _validation_plot(out)
            print(f"wrote {validation_figure(traces, target)}")
    return 0


def _rollover_limits(args: argparse.Namespace) -> int:
    from tuning.limits_file import write_limits_file
    from tuning.rollover import rollover_limits, table, to_curvature_limits
    from tuning.speeds import parse_speeds

    vehicle = _vehicle(args)
    speeds = parse_speeds(args.speeds)
    limits = rollover_limits(vehicle, speeds)
    write_limits_file(to_curvature_limits(limits, vehicle), _prepare(args.out))
    print(table(limits))
    print(f"wrote {args.out}")
    if args.plot:
        from tuning.plots import rollover_figure

        print(f"wrote {rollover_figure(limits, args.plot, vehicle.name)}")
    return 0


def _steering_limits(args: argparse.Namespace) -> int:
    from tuning.limits_file import write_limits_file
    from tuning.speeds import parse_speeds
    from tuning.steering_limits import steering_limits
    from tuning.steering_limits import table as steering_table
    from tuning.steering_limits import to_curvature_limits as steering_curvature_limits

    vehicle = _vehicle(args)
    limits = steering_limits(vehicle.geometry, parse_speeds(args.speeds), args.lat_accel_g)
    write_limits_file(steering_curvature_limits(limits, vehicle.name, args.lat_accel_g), _prepare(args.out))
    print(steering_table(limits))
    print(f"wrote {args.out}")
    return 0


def _schedule(args: argparse.Namespace) -> int:
    from tuning.filter_comparison import compare_closed_loop, fixed_and_scheduled_filters, scheduled_against_fixed
    from tuning.lag_fit import LagFitOptions
    from tuning.preview_fit import FUTURE_RANGE_S, PAST_RANGE_S, PreviewFitOptions
    from tuning.schedule import PAPER_SPEED_KMH, SPEED_MATCH_KMH, identify_schedule
    from tuning.speeds import parse_speeds
    from workbench.base.errors import require_in_range

    out = _filter_path(args)
    vehicle = _vehicle(args)
    speeds = parse_speeds(args.speeds)
    compare_speeds = parse_speeds(args.compare) if args.compare else None
    nominal = args.nominal_speed
    if compare_speeds and nominal is None and PAPER_SPEED_KMH in speeds:
        nominal = PAPER_SPEED_KMH  # the paper's fixed filter
    if compare_speeds and nominal is None:
        raise WorkbenchInputError(
            f"--compare needs --nominal-speed, one of the --speeds {speeds}, for the fixed filter to compare with "
            f"(default {PAPER_SPEED_KMH:g} km/h, the paper's, when it is one of them)"
        )
    if nominal is not None and not any(abs(nominal - s) <= SPEED_MATCH_KMH for s in speeds):
        raise WorkbenchInputError(
            f"--nominal-speed {nominal:g} km/h is not one of the --speeds ({', '.join(f'{s:g}' for s in speeds)} "
            "km/h); the nominal (top-level) filter is the one designed at one of the speeds identified: give one "
            "of them, or add it to --speeds"
        )
    require_in_range("--preview-past-s", args.preview_past_s, *PAST_RANGE_S, "s")
    require_in_range("--preview-future-s", args.preview_future_s, *FUTURE_RANGE_S, "s")
    require_in_range("--preview-lat-accel-g", args.preview_lat_accel_g, 0.001, 1.0, "g")
    preview = PreviewFitOptions(
        past_s=args.preview_past_s, future_s=args.preview_future_s, lat_accel_g=args.preview_lat_accel_g
    )
    with _progress_bar(len(speeds), "speed", "tuning schedule") as bar:
        bar.set_postfix_str(f"{speeds[0]:g} km/h")

        def progress(line: str) -> None:
            """One call per speed (`identify_schedule`): its line above the bar, the bar on to the next speed."""
            bar.write(f"tuning schedule: {line}", file=sys.stderr)
            bar.update(1)
            if bar.n < len(speeds):
                bar.set_postfix_str(f"{speeds[bar.n]:g} km/h")

        result = identify_schedule(
            vehicle,
            speeds,
            lat_accel_g=args.lat_accel_g,
            fit_options=LagFitOptions(fit_delay=args.delay),
            max_lead_gain=args.max_lead_gain,
            max_cascade_peak_db=args.max_cascade_peak_db,
            drop_refused=args.drop_refused,
            progress=progress,
            design=args.design,
            controller_rate_hz=args.controller_rate_hz,
            prediction_time_s=args.prediction_time_s,
            preview_options=preview,
        )
    if nominal is not None:
        result.entry_at(nominal, "--nominal-speed")  # dropped by --drop-refused: refused, saying why
    result.write(_prepare(out), nominal_speed_kmh=nominal)
    print(result.table())
    print(f"wrote {out}")
    if args.plot:
        from tuning.plots import schedule_figure

        print(f"wrote {schedule_figure(result, args.plot)}")
    if compare_speeds:
        files: dict[str, Path | None] = dict(fixed_and_scheduled_filters(vehicle, result, nominal))
        fixed_label = next(label for label in files if label != "scheduled")
        files["no filter"] = None
        runs = [(speed, label) for speed in compare_speeds for label in files]
        rows, fresh_vehicle = [], partial(_vehicle, args)
        with _progress_bar(len(runs), "run", "closed loop") as bar:
            for speed, label in runs:  # one run at a time, for the bar: compare_closed_loop's order
                bar.set_postfix_str(f"{label} at {speed:g} km/h")
                rows += compare_closed_loop(fresh_vehicle, {label: files[label]}, [speed], args.compare_scenario)
                bar.update(1)
        print(f"clothoid controller (default options) on {args.compare_scenario} ({vehicle.name}):")
        print("speed_kmh  filter            completed  max_abs_cte_m  rms_cte_m  max_steer_rate_deg_s  driven_kmh")
        for row in rows:
            print(
                f"{row.speed_kmh:9.1f}  {row.filter:16s}  {row.completed!s:9s}  {row.max_abs_cte_m:13.3f}  "
                f"{row.rms_cte_m:9.3f}  {row.max_abs_steer_rate_deg_s:20.0f}  "
                f"{row.min_speed_kmh:.0f}-{row.max_speed_kmh:.0f}"
            )
        for verdict in scheduled_against_fixed(rows, fixed_label):
            print(verdict.line())
    return 0


@contextmanager
def _progress_bar(total: int, unit: str, desc: str) -> Iterator[tqdm]:
    """A progress bar on stderr, as `workbench run` and `sweep` show: only on a terminal; left on screen when the
    work is done, taken away when it stops with an error (so that the message stands alone)."""
    from tqdm import tqdm

    bar = tqdm(total=total, unit=unit, desc=desc, leave=True, disable=not sys.stderr.isatty(), file=sys.stderr)
    try:
        yield bar
    except BaseException:
        bar.leave = False
        raise
    finally:
        bar.close()


def _add_margins_parser(sub: argparse._SubParsersAction, command: str | None = None) -> None:
    marg = sub.add_parser(
        "margins",
        help="the clothoid loop's phase and gain margins against lookahead per speed, and the lookahead floor; "
        "write a table (CSV) and a plot",
    )
    if not _builds(command, "margins"):
        return
    from controllers.clothoid import ClothoidConfig
    from controllers.clothoid.loop_analysis import REQUIRED_GAIN_MARGIN_DB, REQUIRED_PHASE_MARGIN_DEG

    default_max_lookahead = ClothoidConfig().max_lookahead_m

    marg.add_argument(
        "--lag", type=Path, metavar="lag.json", help="path-curvature lag (fit-lag; default: the vehicle's)"
    )
    marg.add_argument(
        "--measured-lag",
        type=Path,
        metavar="yawlag.json",
        help="lag to the measured (yaw-rate) curvature (fit-lag --curvature-from yaw-rate; default: the vehicle's "
        "with --vehicle alone, else the path lag)",
    )
    lead = marg.add_mutually_exclusive_group()
    lead.add_argument(
        "--lead",
        type=Path,
        metavar="lead.json|lead.toml",
        help="lead filter (design-lead or schedule; default: the vehicle's with --vehicle alone, else none)",
    )
    lead.add_argument("--no-lead", action="store_true", help="analyse the loop without a lead filter")
    _vehicle_options(marg)
    marg.add_argument("--speeds", required=True, metavar="20,30,...,90", help="speeds, km/h")
    marg.add_argument(
        "--lookahead", default="3:40:0.5", metavar="LOW:HIGH:STEP", help="lookaheads, m (default 3:40:0.5)"
    )
    marg.add_argument("--out", type=Path, required=True, metavar="margins.csv", help="output table (CSV)")
    marg.add_argument("--plot", type=Path, metavar="FILE.png", help="margins against lookahead per speed")
    _overwrite_option(marg)
    marg.add_argument(
        "--max-lookahead-m",
        type=float,
        default=default_max_lookahead,
        help=f"the clothoid controller's max_lookahead_m: a floor above it is named, with what the controller then "
        f"does (default {default_max_lookahead:g} m, its default)",
    )
    marg.add_argument("--prediction-time-s", type=float, default=0.2, help="pose prediction (default 0.2 s)")
    marg.add_argument("--controller-rate-hz", type=float, default=50.0, help="controller rate (default 50 Hz)")
    marg.add_argument(
        "--measurement-delay-s", type=float, default=0.0, help="extra delay of the measurements (default 0 s)"
    )
    marg.add_argument(
        "--arc-lateral-accel-g",
        type=float,
        default=0.4,
        help="also analyse about an arc of this lateral acceleration at each speed, capped at the curvature limit "
        "(default 0.4 g, the controller's; 0: the straight only)",
    )
    marg.add_argument(
        "--phase-margin-deg",
        type=float,
        default=REQUIRED_PHASE_MARGIN_DEG,
        help=f"required phase margin (default {REQUIRED_PHASE_MARGIN_DEG:g} deg)",
    )
    marg.add_argument(
        "--gain-margin-db",
        type=float,
        default=REQUIRED_GAIN_MARGIN_DB,
        help=f"required gain margin, both ways (default {REQUIRED_GAIN_MARGIN_DB:g} dB)",
    )


def _margin_lookaheads(text: str) -> tuple[float, ...]:
    from tuning.margins import lookahead_grid

    parts = text.split(":")
    usage = "give LOW:HIGH:STEP in m, e.g. 3:40:0.5"
    if len(parts) != 3:
        raise WorkbenchInputError(f"--lookahead {text!r}: {usage}")
    try:
        low, high, step = (float(p) for p in parts)
    except ValueError:
        raise WorkbenchInputError(f"--lookahead {text!r}: not numbers; {usage}") from None
    try:
        return lookahead_grid(low, high, step)
    except WorkbenchInputError as exc:
        raise WorkbenchInputError(f"--lookahead {text!r}: {exc}") from None


def _margins(args: argparse.Namespace) -> int:
    from controllers.clothoid.controller import MAX_LOOKAHEAD_M
    from controllers.clothoid.loop_analysis import PlantLags
    from tuning.filter_file import read_filter_file
    from tuning.margins import MarginStudy, run_margins
    from tuning.speeds import parse_speeds
    from workbench.base.errors import require_in_range

    for flag, value, low, high, unit in (
        ("--prediction-time-s", args.prediction_time_s, 0.0, 2.0, "s"),
        ("--controller-rate-hz", args.controller_rate_hz, 1.0, 1000.0, "Hz"),
        ("--measurement-delay-s", args.measurement_delay_s, 0.0, 2.0, "s"),
        ("--arc-lateral-accel-g", args.arc_lateral_accel_g, 0.0, 2.0, "g"),
        ("--phase-margin-deg", args.phase_margin_deg, 0.0, 180.0, "deg"),
        ("--gain-margin-db", args.gain_margin_db, 0.0, 60.0, "dB"),
        ("--max-lookahead-m", args.max_lookahead_m, 0.5, MAX_LOOKAHEAD_M, "m"),
    ):
        require_in_range(flag, value, low, high, unit)
    try:
        speeds = parse_speeds(args.speeds)
    except WorkbenchInputError as exc:
        raise WorkbenchInputError(f"--speeds {args.speeds!r}: {exc}") from None
    lookaheads = _margin_lookaheads(args.lookahead)

    vehicle = _vehicle(args) if args.vehicle is not None or args.vehicle_file is not None else None
    limits = None
    # the lags at a speed (km/h): the vehicle's tuning's, or the one read from a file at every speed
    path_at: Callable[[float], SteeringLag]
    measured_at: Callable[[float], SteeringLag | None] | None
    if args.lag is None:
        if vehicle is None:
            raise WorkbenchInputError(
                "give --lag lag.json (and optionally --measured-lag, --lead), or --vehicle NAME / --vehicle-file F "
                "for the lags and lead filter of the vehicle's own tuning"
            )
        from tuning.own_tuning import tuning_for

        tuning = tuning_for(vehicle)
        path_at, measured_at = tuning.lag_at, tuning.measured_lag_at
        lead, limits = tuning.filter_schedule, tuning.limits
        source = f"the tuning of {vehicle.name}: {tuning.source}"
    else:
        path_lag = _read_lag("--lag", args.lag)

        def path_lag_at(_speed: float) -> SteeringLag:
            return path_lag

        path_at, measured_at, lead, source = path_lag_at, None, None, f"lag {args.lag}"
    if args.measured_lag is not None:
        measured_lag = _read_lag("--measured-lag", args.measured_lag)

        def measured_lag_at(_speed: float) -> SteeringLag:
            return measured_lag

        measured_at = measured_lag_at
        source += f", measured lag {args.measured_lag}"
    if args.lead is not None:
        lead = read_filter_file(args.lead)
        source += f", lead filter {args.lead}"
    elif args.no_lead:
        lead = None
    if lead is None:
        source += ", no lead filter"

    def lags_at(speed: float) -> PlantLags:
        return PlantLags(path_at(speed), measured_at(speed) if measured_at is not None else None)

    study = MarginStudy(
        lags_at,
        lead,
        tuple(speeds),
        lookaheads,
        path_curvatures_1pm=(0.0,),
        sample_time_s=1.0 / args.controller_rate_hz,
        prediction_time_s=args.prediction_time_s,
        measurement_delay_s=args.measurement_delay_s,
        phase_margin_deg=args.phase_margin_deg,
        gain_margin_db=args.gain_margin_db,
        geometry=vehicle.geometry if vehicle is not None else None,
        arc_lateral_accel_g=args.arc_lateral_accel_g,
        limits=limits,
        max_lookahead_m=args.max_lookahead_m,
    )
    result = run_margins(study)
    try:
        result.table.to_csv(_prepare(args.out), index=False, float_format="%.9g")
    except OSError as exc:
        raise WorkbenchInputError(f"cannot write --out {str(args.out)!r}: {exc}") from None
    print(f"clothoid loop margins ({source}; {args.controller_rate_hz:g} Hz, prediction {args.prediction_time_s:g} s)")
    print(result.summary())
    print(f"wrote {args.out} ({len(result.table)} rows)")
    if args.plot:
        from tuning.plots import margins_figure

        print(f"wrote {margins_figure(result, args.plot)}")
    return 0


COMMANDS = {
    "generate-data": _generate_data,
    "fit-lag": _fit_lag,
    "design-lead": _design_lead,
    "rollover-limits": _rollover_limits,
    "steering-limits": _steering_limits,
    "schedule": _schedule,
    "margins": _margins,
}


def console() -> int:
    """The console script: `main` on sys.argv (`workbench.base.console`: no collections at exit)."""
    return console_exit(main)


def main(argv: Sequence[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    args = _parser(_command_word(argv)).parse_args(argv)
    try:
        _check_paths(args)
        return COMMANDS[args.command](args)
    except WorkbenchInputError as exc:
        print(f"tuning: error: {exc}", file=sys.stderr)
        return EXIT_INPUT_ERROR


if __name__ == "__main__":
    sys.exit(main())
