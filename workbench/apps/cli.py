"""The `workbench` command line: list scenarios, vehicles and controllers; run a closed-loop simulation; compare
controllers side by side (`compare`, and the paper's Figure 17 set-up, `fig17`); run parameter sweeps and tune
controllers from a study spec (`sweep`, `optimise`), and tune and judge every controller alike on held-out cases
(`tournament`; `workbench.apps.studies`); and pack a controller, tuned for a vehicle and a path, as an FMI 2.0
co-simulation FMU for the user's own simulation tool (`export-fmu`; `workbench.apps.fmu_export`).

Every input file and output folder is checked before any work starts (`workbench.base.input_files`,
`workbench.base.output_dir`): a missing or unreadable file, a folder where a file is wanted or a file where a folder is,
a parent that is a file, an unwritable folder, and a non-empty output folder without --overwrite are refused with
`workbench: error: ...` and exit code 2.

`run` and `compare` take the same options (`_run_options`): the controllers' options, the vehicle's file and
payload, the simulation's speed, rates and time-out, the conditions and the output. `run` steers with the clothoid
controller, the project's subject, unless --controller names another; every controller is built with the vehicle's
own tuning (`tuning.own_tuning.tuned_controller`). `workbench --version` prints the installed version and, run
from a git checkout, its commit.

Exit codes: 0 done; 1 a run did not complete (run, compare, fig17), a sweep run raised an error, no optimisation
trial completed, or a study's worker died; 2 bad input; 130 interrupted.
"""

from __future__ import annotations

import argparse
import math
import os
import re
import shutil
import signal
import sys
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypeVar

from controllers import CONTROLLERS
from workbench.base.console import console_exit, warn_on_stderr
from workbench.base.errors import WorkbenchInputError
from workbench.base.output_dir import MANIFEST
from workbench.base.version import VersionAction

if TYPE_CHECKING:
    from _typeshed import DataclassInstance

    from workbench.apps.comparison import Comparison
    from workbench.apps.stage_progress import StageProgress
    from workbench.apps.studies.backends import Backend
    from workbench.base.output_dir import OutputDir
    from workbench.simulation.circuit_ranges import CircuitRanges
    from workbench.simulation.plot_worker import PlotWorker
    from workbench.simulation.result import SimulationResult
    from workbench.simulation.run_config import SimulationConfig
    from workbench.simulation.scenario import Scenario
    from workbench.simulation.simulator import Simulation
    from workbench.vehicles.base import VehicleModel

# Heavy modules (the simulator, the scenarios' paths, plotting, the controllers' solvers, the studies' backends)
# are imported inside the command that needs them, so that `workbench --help` and `workbench scenarios` start
# fast (benchmarks/startup.py measures it).

#: A study's spec, as its command loads it (`_start_study`).
SpecT = TypeVar("SpecT")

EXIT_INPUT_ERROR = 2
EXIT_RUN_FAILED = 1
EXIT_INTERRUPTED = 130
#: The controller `workbench run` steers with unless --controller names another: the project's subject.
DEFAULT_CONTROLLER = "clothoid"
#: The vehicle `workbench run` steers without --vehicle or --vehicle-file.
DEFAULT_VEHICLE = "kinematic-bicycle"
#: What shortens a run refused as too long (`run_size.check_run_size`), for `run` and `compare`.
_SHORTEN_RUN = "a higher --speed (now {speed:g} km/h), fewer --laps or a --max-time-s shortens it"
#: compare's `--controller-config NAME=FILE.toml` and `--set NAME:KEY=VALUE`: a controller name's shape.
_CONTROLLER_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_-]*")

#: The scenario that --track gives the track of (the paper's Zandvoort lap).
TRACK_SCENARIO = "zandvoort"
#: The input-file options of the commands (argparse dest -> what the message calls it).
INPUT_FILES = {
    "track": "--track",
    "circuit_ranges": "--circuit-ranges",
    "controller_config": "--controller-config",
    "vehicle_file": "--vehicle-file",
    "spec": "the spec",
}


def _command_word(argv: Sequence[str]) -> str:
    """The command argv names (its first word that is not an option), or "" without one."""
    return next((word for word in argv if not word.startswith("-")), "")


def _parser(command: str | None = None) -> argparse.ArgumentParser:
    """The parser of every command. `command` (the one being run, "" for none) limits the imports a command's
    options need (the studies' default size) to that command's; None: every command's, as `workbench sweep -h`."""
    parser = argparse.ArgumentParser(
        prog="workbench", description="Design, tune and compare lateral (steering) controllers."
    )
    parser.add_argument("--version", action=VersionAction)
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    scen = sub.add_parser("scenarios", help="list the named scenarios")
    scen.add_argument("--track", type=Path, help="Zandvoort track CSV (TUMFTM racetrack-database format)")
    scen.add_argument(
        "--circuit-ranges",
        dest="show_circuit_ranges",
        nargs="?",
        const="",
        metavar="FILE.toml",
        help="print instead the ranges circuit:SEED is drawn within, as a [circuits] table: the defaults, or those "
        "of FILE (copy, edit, give with --circuit-ranges)",
    )
    veh = sub.add_parser("vehicles", help="list the vehicle models and presets")
    veh.add_argument("--show", metavar="NAME", help="print a preset's TOML (copy, edit, pass with --vehicle-file)")
    cond = sub.add_parser("conditions", help="list the sensing, actuation and road conditions presets")
    cond.add_argument("--show", metavar="NAME", help="print a preset as TOML (copy, edit, pass with --conditions)")
    ctl = sub.add_parser("controllers", help="list the controllers")
    ctl.add_argument("--show", metavar="NAME", help="print a controller's options as TOML (for --controller-config)")
    ctl.add_argument(
        "--search-space",
        action="store_true",
        help="with --show NAME: print instead the options the controller offers to tuning, as the [search.NAME] "
        "table a tournament spec copies",
    )

    run = sub.add_parser("run", help="simulate one controller on one vehicle along one scenario")
    run.add_argument("scenario", help="a scenario name (`workbench scenarios`), circuit:SEED or a waypoint CSV file")
    run.add_argument(
        "--controller",
        default=DEFAULT_CONTROLLER,
        metavar="NAME",
        help=f"controller name (default: {DEFAULT_CONTROLLER}, with the vehicle's own tuning; see `workbench "
        "controllers`)",
    )
    run.add_argument("--vehicle", metavar="NAME", help=f"vehicle model (default: {DEFAULT_VEHICLE})")
    _run_options(run, several=False)

    cmp = sub.add_parser("compare", help="run several controllers (and vehicles) on one scenario; write a report")
    cmp.add_argument("scenario", help="a scenario name (`workbench scenarios`), circuit:SEED or a waypoint CSV file")
    cmp.add_argument(
        "--controllers",
        required=True,
        metavar="A,B,...",
        help=f"comma-separated controller names ({', '.join(CONTROLLERS)})",
    )
    cmp.add_argument(
        "--vehicle",
        metavar="NAME[,NAME...]",
        help="vehicle preset(s) or vehicle TOML file(s); each controller runs on each (give this, --vehicle-file or "
        "both)",
    )
    _run_options(cmp, several=True)

    fig = sub.add_parser(
        "fig17", help="the paper's Figure 17/18 comparison: clothoid vs NMPC, as published and each on each plant"
    )
    fig.add_argument("--out", type=Path, required=True, metavar="DIR", help="output directory (report.html in it)")
    fig.add_argument("--speed", type=float, default=30.0, metavar="KMH", help="target speed, km/h (default 30)")
    fig.add_argument(
        "--allow-long-run",
        action="store_true",
        help="run even when a run's time-out allows more than 2,000,000 controller steps or a trace over 1 GB",
    )
    _conditions_options(fig)
    _overwrite_option(fig)

    paper = sub.add_parser("paper", help="regenerate the paper's figures 4b-16 and a table of ours against its numbers")
    paper.add_argument("--out", type=Path, required=True, metavar="DIR", help="output directory")
    paper.add_argument("--track", type=Path, help="Zandvoort track CSV (Figures 15-16)")
    _overwrite_option(paper)

    rob = sub.add_parser(
        "robustness",
        help="each controller against actuation delay, pose latency, position noise, friction and payload mismatch",
    )
    rob.add_argument("scenario", help="a scenario name (`workbench scenarios`), circuit:SEED or a waypoint CSV file")
    rob.add_argument("--controllers", required=True, metavar="A,B,...", help="comma-separated controller names")
    rob.add_argument("--vehicle", required=True, metavar="NAME", help="vehicle preset or vehicle TOML file")
    rob.add_argument("--out", type=Path, required=True, metavar="DIR", help="output directory (rerun to resume)")
    rob.add_argument("--speed", type=float, default=30.0, metavar="KMH", help="target speed, km/h (default 30)")
    rob.add_argument("--track", type=Path, help="track CSV for the zandvoort scenario")
    _circuit_ranges_option(rob)
    rob.add_argument(
        "--max-cte", type=float, default=0.5, metavar="M", help="a run passes within this max |CTE| (default 0.5 m)"
    )
    rob.add_argument(
        "--allow-long-run",
        action="store_true",
        help="start even when each run's time-out allows more than 2,000,000 controller steps or a trace over 1 GB",
    )
    _allow_infeasible_option(rob)
    _conditions_options(rob)
    _backend_options(rob, command in (None, "robustness"))

    swp = sub.add_parser(
        "sweep", help="run every run a study spec plans (grids, random draws); resumes; DIR/results.parquet"
    )
    swp.add_argument("spec", type=Path, metavar="SPEC.toml", help="the study spec (see README: Studies)")
    swp.add_argument("--out", type=Path, required=True, metavar="DIR", help="output directory (rerun to resume)")
    _backend_options(swp, command in (None, "sweep"))
    swp.add_argument("--no-plots", action="store_true", help="write the results without the figures and report.html")
    opt = sub.add_parser(
        "optimise", help="tune a controller's options against the spec's objective (optuna TPE); DIR/best.toml"
    )
    opt.add_argument("spec", type=Path, metavar="SPEC.toml", help="the study spec with an [optimise] table")
    opt.add_argument("--out", type=Path, required=True, metavar="DIR", help="output directory (rerun to resume)")
    _backend_options(opt, command in (None, "optimise"))
    tour = sub.add_parser(
        "tournament",
        help="tune every controller with the same trial budget on training cases, judge them on held-out test "
        "cases; DIR/report.html",
    )
    tour.add_argument("spec", type=Path, metavar="SPEC.toml", help="the tournament spec (see README: Tournament)")
    tour.add_argument("--out", type=Path, required=True, metavar="DIR", help="output directory (rerun to resume)")
    _backend_options(tour, command in (None, "tournament"))

    fmu = sub.add_parser(
        "export-fmu",
        help="pack a controller, tuned for a vehicle and a path, as an FMI 2.0 co-simulation FMU (PythonFMU)",
    )
    fmu.add_argument("controller", metavar="CONTROLLER", help="controller name (see `workbench controllers`)")
    fmu.add_argument("--vehicle", metavar="NAME", help=f"vehicle model (default: {DEFAULT_VEHICLE})")
    fmu.add_argument(
        "--vehicle-file", type=Path, metavar="FILE.toml", help="a vehicle TOML file (see `workbench vehicles --show`)"
    )
    fmu.add_argument("--payload-kg", type=float, metavar="KG", help="payload of vehicles that carry one")
    fmu.add_argument(
        "--controller-config",
        type=Path,
        metavar="FILE.toml",
        help="controller options: a TOML file with a [<controller name>] table; the files it names are packed",
    )
    fmu.add_argument(
        "--set", action="append", default=[], metavar="KEY=VALUE", help="a controller option, over the config file"
    )
    fmu.add_argument(
        "--path",
        dest="scenario",
        required=True,
        metavar="WAYPOINTS",
        help="the path the controller follows, packed in the FMU: a waypoint CSV file, a scenario name or "
        "circuit:SEED",
    )
    fmu.add_argument("--track", type=Path, metavar="FILE", help="track CSV for the zandvoort scenario")
    _circuit_ranges_option(fmu)
    _plan_options(fmu, "target speed of the path's plan, km/h", "controller rate: the FMU's step is its period")
    _allow_infeasible_option(fmu, "pack")
    fmu.add_argument("--out", type=Path, required=True, metavar="FILE.fmu", help="the FMU to write")
    fmu.add_argument("--overwrite", action="store_true", help="replace an existing FILE.fmu")
    return parser


def _overwrite_option(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--overwrite",
        action="store_true",
        help="write into a non-empty DIR: first remove the files an earlier workbench output there wrote (listed in "
        f"its {MANIFEST}); other files are kept",
    )


def _backend_options(parser: argparse.ArgumentParser, shown: bool = True) -> None:
    """The options of the study commands; `shown` False: the parser of another command is being run, and the
    help text (the studies' default size, `workbench.apps.studies` imported for it) is not needed."""
    if shown:
        from workbench.apps.studies.backends import MAX_WORKERS_PER_CPU
        from workbench.apps.studies.spec import DEFAULT_MAX_RUNS

        max_runs = f"{DEFAULT_MAX_RUNS:,}"
        most_workers = f"; at most {MAX_WORKERS_PER_CPU} per CPU"
    else:
        max_runs, most_workers = "the studies' default", ""
    parser.add_argument(
        "--backend", choices=("local", "dask"), default="local", help="local process pool (default) or dask"
    )
    parser.add_argument(
        "--scheduler",
        metavar="ADDRESS",
        help="a dask scheduler, tcp://HOST:PORT (e.g. tcp://10.0.0.5:8786); default: a LocalCluster",
    )
    parser.add_argument(
        "--workers",
        type=int,
        metavar="N",
        help=f"worker processes (local pool or LocalCluster; default: the CPUs{most_workers})",
    )
    parser.add_argument(
        "--max-runs",
        type=int,
        metavar="N",
        help=f"refuse a study of more runs than N (an optimisation: trials x runs; default: the spec's "
        f"study.max_runs, else {max_runs})",
    )


def _run_options(parser: argparse.ArgumentParser, several: bool) -> None:
    """The options `run` and `compare` share, built here once so that both take the same: the controllers'
    options, the vehicle's file and payload, the simulation (speed, track, laps, rates, speed-profile bound,
    time-out), the conditions and the output. `several` (compare): --controller-config and --set may name the
    controller they are for, each --vehicle-file adds a vehicle and --payload-kg goes to each vehicle that carries
    one."""
    if several:
        parser.add_argument(
            "--controller-config",
            dest="controller_configs",
            action="append",
            default=[],
            metavar="[NAME=]FILE.toml",
            help="controller options: a TOML file with a table per controller name (see `workbench controllers "
            "--show`); NAME=FILE.toml: that controller's table from its own file (repeatable, once per controller)",
        )
        parser.add_argument(
            "--set",
            action="append",
            default=[],
            metavar="[NAME:]KEY=VALUE",
            help="a controller option, over the config files (repeatable): for every controller, or with NAME: for "
            "that one, e.g. --set clothoid:frechet_threshold_m=0.3",
        )
        parser.add_argument(
            "--vehicle-file",
            action="append",
            default=[],
            type=Path,
            metavar="FILE.toml",
            help="a vehicle TOML file, one more vehicle each controller runs on (repeatable; see `workbench vehicles "
            "--show`)",
        )
        payload = "payload of the vehicles that carry one (tractor-semitrailer); the others run as they are"
    else:
        parser.add_argument(
            "--controller-config",
            type=Path,
            metavar="FILE.toml",
            help="controller options: a TOML file with a [<controller name>] table (see `workbench controllers "
            "--show`)",
        )
        parser.add_argument(
            "--set",
            action="append",
            default=[],
            metavar="KEY=VALUE",
            help="a controller option, over the config file (repeatable), e.g. --set frechet_threshold_m=0.3",
        )
        parser.add_argument(
            "--vehicle-file",
            type=Path,
            metavar="FILE.toml",
            help="a vehicle TOML file (see `workbench vehicles --show`)",
        )
        payload = "payload of vehicles that carry one (tractor-semitrailer)"
    parser.add_argument("--payload-kg", type=float, metavar="KG", help=payload)
    _plan_options(parser, "target speed, km/h", "controller rate")
    parser.add_argument("--out", type=Path, required=True, metavar="DIR", help="output directory")
    parser.add_argument("--track", type=Path, metavar="FILE", help="track CSV for the zandvoort scenario")
    _circuit_ranges_option(parser)
    parser.add_argument("--laps", type=int, default=1, metavar="N", help="laps of a closed path (default 1)")
    parser.add_argument(
        "--plant-rate-hz", type=float, default=1000.0, metavar="HZ", help="plant integration rate (default 1 kHz)"
    )
    parser.add_argument(
        "--max-time-s",
        type=float,
        metavar="S",
        help="stop a run after this much simulated time, status timeout (default: three times the planned time "
        "plus 30 s)",
    )
    parser.add_argument(
        "--allow-long-run",
        action="store_true",
        help="run even when the time-out allows more than 2,000,000 controller steps or a trace over 1 GB (refused "
        "without it)",
    )
    _allow_infeasible_option(parser)
    _conditions_options(parser)
    parser.add_argument(
        "--perfect-prediction",
        action="store_true",
        help="hand each controller the plant's true state one actuation dead time of --conditions ahead (the "
        "commands already sent applied; --inform-delays then tells the sensing delays only): the bound a perfect "
        "delay compensation reaches (needs a dead time; an analysis, not a sensor)",
    )
    what = "trace and metrics" if not several else "traces, metrics and summary.csv, without figures or report.html"
    parser.add_argument("--no-plots", action="store_true", help=f"write the {what} only")
    _overwrite_option(parser)


def _plan_options(parser: argparse.ArgumentParser, speed_help: str, rate_help: str) -> None:
    """--speed, --lat-accel-g and --controller-rate-hz: the speed plan's target and lateral bound and the
    controller's rate, as `run`, `compare` and `export-fmu` take them (`speed_help`, `rate_help`: what each means
    there; the defaults are said after)."""
    parser.add_argument("--speed", type=float, default=30.0, metavar="KMH", help=f"{speed_help} (default 30)")
    parser.add_argument(
        "--lat-accel-g", type=float, default=0.3, metavar="G", help="speed-profile lateral bound (default 0.3 g)"
    )
    parser.add_argument(
        "--controller-rate-hz", type=float, default=50.0, metavar="HZ", help=f"{rate_help} (default 50 Hz)"
    )


def _circuit_ranges_option(parser: argparse.ArgumentParser) -> None:
    """--circuit-ranges, of run, compare and robustness: the ranges a circuit:SEED scenario is drawn within."""
    parser.add_argument(
        "--circuit-ranges",
        type=Path,
        metavar="FILE.toml",
        help="with a circuit:SEED scenario: draw it within the ranges of this file's [circuits] table (`workbench "
        "scenarios --circuit-ranges` prints the defaults; a spec carrying the table will do)",
    )


def _circuit_ranges(args: argparse.Namespace) -> CircuitRanges | None:
    """The ranges --circuit-ranges names, read (None without it)."""
    if args.circuit_ranges is None:
        return None
    from workbench.simulation.circuit_ranges import read_circuit_ranges

    return read_circuit_ranges(args.circuit_ranges)


def _allow_infeasible_option(parser: argparse.ArgumentParser, verb: str = "run") -> None:
    """--allow-infeasible, of run, compare, robustness and export-fmu (`feasibility.refuse_infeasible`); `verb`:
    what the command does with the path."""
    parser.add_argument(
        "--allow-infeasible",
        action="store_true",
        help=f"{verb} a path a vehicle cannot follow at the planned speed (too tight for its lock, curvature changing "
        "faster than its steering, beyond its rollover threshold or grip), warning where; refused without it",
    )


def _conditions_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--conditions",
        default="ideal",
        metavar="NAME|FILE.toml",
        help="sensing, actuation and road conditions: a preset (`workbench conditions`) or a TOML file "
        "(default: ideal, the plant's exact state at once)",
    )
    parser.add_argument("--seed", type=int, default=0, help="seed of the conditions' noise (default 0)")
    parser.add_argument(
        "--inform-delays",
        action="store_true",
        help="tell each controller the nominal latency, dead time and pose noise of --conditions (the clothoid "
        "controller's known_delay_s, the MPCs' delay compensation and pose filter; Stanley and pure pursuit have "
        "none; robustness: the base's, not the varied values); default: untold",
    )


def _simulation_config(args: argparse.Namespace, **fields: Any) -> SimulationConfig:
    """The SimulationConfig of a command's options: `fields` (SimulationConfig's, each of its own type) plus the
    conditions, seed and --inform-delays."""
    from workbench.simulation.conditions import load_conditions
    from workbench.simulation.simulator import SimulationConfig

    conditions = load_conditions(args.conditions)
    return SimulationConfig(**fields, conditions=conditions, seed=args.seed, inform_delays=args.inform_delays)


def _run_config(args: argparse.Namespace) -> SimulationConfig:
    """The SimulationConfig of `run`'s and `compare`'s options (`_run_options`)."""
    if args.laps < 1:
        raise WorkbenchInputError(f"--laps must be a whole number >= 1; got {args.laps}")
    return _simulation_config(
        args,
        speed_kmh=args.speed,
        laps=args.laps,
        controller_rate_hz=args.controller_rate_hz,
        plant_rate_hz=args.plant_rate_hz,
        max_lateral_accel_g=args.lat_accel_g,
        max_time_s=args.max_time_s,
        perfect_prediction=args.perfect_prediction,
    )


def _names(text: str, what: str) -> list[str]:
    names = [n.strip() for n in text.split(",") if n.strip()]
    if not names:
        raise WorkbenchInputError(f"--{what} needs at least one name; got {text!r}")
    return names


def _check_inputs(args: argparse.Namespace) -> None:
    """Every input file the command names (INPUT_FILES, each of a repeated option; and a waypoint file given as
    the scenario) must be a readable file: checked before any work."""
    from workbench.base.input_files import check_input_file
    from workbench.simulation.scenarios import SCENARIOS

    for dest, flag in INPUT_FILES.items():
        value = getattr(args, dest, None)
        for path in value if isinstance(value, list) else [] if value is None else [value]:
            check_input_file(path, f"{flag} {str(path)!r}" if flag.startswith("--") else f"spec file {str(path)!r}")
    scenario = getattr(args, "scenario", None)
    if scenario is not None and scenario not in SCENARIOS:
        if os.path.lexists(scenario) or Path(scenario).suffix.lower() in (".csv", ".txt"):
            check_input_file(scenario, f"waypoint file {scenario!r}")
    track = getattr(args, "track", None)
    if track is not None and scenario is not None and scenario != TRACK_SCENARIO:
        raise WorkbenchInputError(
            f"--track {str(track)!r} is the track of the {TRACK_SCENARIO} scenario, and scenario {scenario!r} does not "
            "read it: drop --track, or give the track file itself as the scenario"
        )


@contextmanager
def _writing(out: OutputDir) -> Iterator[None]:
    """Write a command's output into its folder (`OutputDir.writing`: the earlier output removed first, a
    manifest of what was written); an OSError while writing is reported as an error naming the folder; files the
    workbench did not write, kept there, are named."""
    try:
        with out.writing():
            yield
    except OSError as exc:
        raise WorkbenchInputError(f"--out {str(out.path)!r}: cannot write the output ({exc})") from None
    if out.foreign:
        shown = ", ".join(out.foreign[:5]) + (f" and {len(out.foreign) - 5} more" if len(out.foreign) > 5 else "")
        what = "an entry" if len(out.foreign) == 1 else f"{len(out.foreign)} entries"
        note = f"workbench: note: {out.path} also holds {what} the workbench did not write, kept: {shown}"
        print(note, file=sys.stderr)


def _print_summary(comparison: Comparison) -> None:
    table = comparison.summary()
    columns = ["controller", "vehicle", "status", "max_abs_cte_m", "rms_cte_m", "converge_distance_m"]
    columns += ["rms_steer_rate_deg_s", "steer_oscillation_deg", "step_time_median_us", "step_time_ratio"]
    print(table[columns].to_string(index=False, float_format=lambda v: f"{v:.3g}"))
    for spec, cycle in zip(comparison.specs, comparison.limit_cycles(), strict=True):
        if cycle.detected:
            print(f"  WARNING: steering limit cycle: {spec.label} at {cycle.describe()}")


def _controller_configs(values: Sequence[str], controllers: Sequence[str]) -> dict[str, Path]:
    """Each controller's --controller-config file in compare: NAME=FILE.toml for that controller (the file must
    have its [NAME] table), else the one FILE.toml given for all (a table per controller name; a controller without
    one gets its defaults, with a warning); a controller with neither is left out (its defaults). Each file is read
    and checked (`controller_config.read_config_tables`: no key outside a table, no table naming no controller). A
    text whose part before "=" is shaped like a name, and which is not itself a file, is taken as NAME=FILE, so
    that a misspelt name is refused as such rather than as a missing file."""
    from workbench.apps.controller_config import missing_table_warning, read_config_tables
    from workbench.base.input_files import check_input_file

    shared: list[str] = []
    named: dict[str, Path] = {}
    for text in values:
        name, sep, file = text.partition("=")
        if not (sep and file and _CONTROLLER_NAME.fullmatch(name) and not os.path.lexists(text)):
            shared.append(text)
            continue
        what = f"--controller-config {text!r}"
        if name not in controllers:
            raise WorkbenchInputError(f"{what}: {name!r} is not one of --controllers ({', '.join(controllers)})")
        if name in named:
            raise WorkbenchInputError(f"{what}: {name} has a file already ({str(named[name])!r}); give one each")
        check_input_file(file, what)
        if name not in read_config_tables(Path(file)):
            raise WorkbenchInputError(
                f"{what}: the file has no [{name}] table (`workbench controllers --show {name}` writes one)"
            )
        named[name] = Path(file)
    if len(shared) > 1:
        raise WorkbenchInputError(
            f"--controller-config: give one FILE.toml for every controller, got {len(shared)} "
            f"({', '.join(repr(t) for t in shared)}); give each controller its own as NAME=FILE.toml"
        )
    for text in shared:
        check_input_file(text, f"--controller-config {text!r}")
        for controller in (c for c in controllers if c not in named):
            warning = missing_table_warning(Path(text), controller)
            if warning is not None:
                warn_on_stderr(warning)
    every = {c: Path(shared[0]) for c in controllers} if shared else {}
    return every | named


def _controller_overrides(values: Sequence[str], controllers: Sequence[str]) -> dict[str, tuple[str, ...]]:
    """Each controller's --set overrides of compare: KEY=VALUE for every controller (each must have the option),
    then NAME:KEY=VALUE for that one (after, so that they win)."""
    from workbench.apps.controller_config import option_types

    shared: list[str] = []
    named: dict[str, list[str]] = {c: [] for c in controllers}
    for text in values:
        key, sep, value = text.partition("=")
        name, colon, option = key.partition(":")
        if not colon:
            shared.append(text)
            continue
        if name not in controllers:
            raise WorkbenchInputError(
                f"--set {text!r}: {name!r} is not one of --controllers ({', '.join(controllers)})"
            )
        named[name].append(f"{option}{sep}{value}")
    for text in shared:
        key = text.partition("=")[0].strip()
        having = [c for c in controllers if key in option_types(CONTROLLERS[c].config_type)]
        lacking = [c for c in controllers if c not in having]
        if having and lacking:
            raise WorkbenchInputError(
                f"--set {text!r} is for every controller, but {', '.join(lacking)} has no option {key!r}; give it to "
                f"one controller as --set NAME:{text}, e.g. --set {having[0]}:{text}"
            )
    return {c: (*shared, *named[c]) for c in controllers}


def _compared_vehicles(args: argparse.Namespace) -> list[tuple[str, float | None]]:
    """compare's vehicles (--vehicle's names or files, then each --vehicle-file), each with the --payload-kg it
    carries: the payload goes to each vehicle that carries one, and is refused when none does."""
    from workbench.vehicles.presets import MODEL_TYPES, carries_payload, load_vehicle

    vehicles = (_names(args.vehicle, "vehicle") if args.vehicle is not None else []) + [
        str(path) for path in args.vehicle_file
    ]
    if not vehicles:
        raise WorkbenchInputError("compare needs vehicles: give --vehicle NAME[,NAME...] or --vehicle-file FILE.toml")
    if args.payload_kg is None:
        return [(v, None) for v in vehicles]
    carrying = [carries_payload(load_vehicle(v).name) for v in vehicles]
    if not any(carrying):
        carriers = [k for k in MODEL_TYPES if carries_payload(k)]
        raise WorkbenchInputError(
            f"--payload-kg {args.payload_kg:g}: none of the vehicles ({', '.join(vehicles)}) carries a payload; a "
            f"payload applies to: {', '.join(carriers)}"
        )
    return [(v, args.payload_kg if carries else None) for v, carries in zip(vehicles, carrying, strict=True)]


def _compare(args: argparse.Namespace) -> int:
    from workbench.apps.comparison import RunSpec, compare
    from workbench.apps.report import ReportSection, write_report
    from workbench.base.output_dir import OutputDir
    from workbench.simulation.scenarios import ScenarioOptions

    out = OutputDir(args.out, "compare", args.overwrite)
    controllers = _names(args.controllers, "controllers")
    for name in controllers:
        CONTROLLERS.require(name)
    configs = _controller_configs(args.controller_configs, controllers)
    _check_inputs(args)
    overrides = _controller_overrides(args.set, controllers)
    runs = [
        RunSpec(controller, vehicle, overrides[controller], configs.get(controller), payload_kg)
        for vehicle, payload_kg in _compared_vehicles(args)
        for controller in controllers
    ]
    comparison = compare(
        args.scenario,
        runs,
        _run_config(args),
        ScenarioOptions(track_file=args.track, circuit_ranges=_circuit_ranges(args)),
        warn=warn_on_stderr,
        progress=sys.stderr.isatty(),
        allow_long_run=args.allow_long_run,
        allow_infeasible=args.allow_infeasible,
    )
    with _writing(out):
        comparison.save(args.out, with_plots=not args.no_plots)
        if not args.no_plots:
            report = write_report(
                args.out / "report.html",
                f"{comparison.scenario.name}: {', '.join(controllers)}",
                [ReportSection("Side by side", "", comparison)],
                intro=comparison.conditions_text(),
            )
    _print_summary(comparison)
    if args.no_plots:
        print(f"wrote {args.out / 'summary.csv'} and runs/ beside it")
    else:
        print(f"wrote {report} and summary.csv, figures and runs/ beside it")
    return 0 if all(r.completed for r in comparison.results) else EXIT_RUN_FAILED


def _paper(args: argparse.Namespace) -> int:
    from workbench.apps.paper import reproduce_paper, zandvoort_skip_reason
    from workbench.base.output_dir import OutputDir
    from workbench.simulation.scenarios import ScenarioOptions

    out = OutputDir(args.out, "paper", args.overwrite)
    _check_inputs(args)
    options = ScenarioOptions(track_file=args.track)
    if args.track is not None:  # a track that cannot be used is refused, and another track named, before any work
        why_not = zandvoort_skip_reason(options)
        if why_not is not None:
            warn_on_stderr(f"skipping {why_not}")
    with _writing(out):
        result = reproduce_paper(args.out, options)
    print(result.table.to_string(index=False, float_format=lambda v: f"{v:.3g}"))
    for reason in result.skipped:
        print(f"skipped: {reason}")
    print(f"wrote {len(result.files)} files to {args.out}")
    return 0


def _fig17(args: argparse.Namespace) -> int:
    from workbench.apps.fig17 import run_fig17
    from workbench.base.output_dir import OutputDir

    out = OutputDir(args.out, "fig17", args.overwrite)
    result = run_fig17(_simulation_config(args, speed_kmh=args.speed), allow_long_run=args.allow_long_run)
    with _writing(out):
        written = result.save(args.out)
    print("Figure 17, fair set (each controller on each plant):")
    _print_summary(result.fair)
    print(f"report: {written[-1]}")
    return 0 if all(r.completed for r in result.fair.results) else EXIT_RUN_FAILED


def _interruptible(study: Callable[[], int], out: Path, backend: Backend) -> int:
    """Run a study on `backend`. SIGINT (Ctrl-C) and SIGTERM stop it at once, whatever its runs are doing: the
    backend is closed (queued runs cancelled; runs in progress abandoned: a local pool's workers killed, a Dask
    client's runs cancelled and its LocalCluster stopped), the rows written so far stay, exit code 130, and the
    same command resumes. Further signals while it stops are ignored (a second Ctrl-C cannot cut the clean-up
    short)."""
    from workbench.apps.studies.backends import BackendError

    def stop(signum: int, frame: object) -> None:
        for stop_signal in stop_signals:
            signal.signal(stop_signal, signal.SIG_IGN)
        raise KeyboardInterrupt

    stop_signals = (signal.SIGINT, signal.SIGTERM)
    previous = {s: signal.signal(s, stop) for s in stop_signals}
    try:
        return study()
    except KeyboardInterrupt:
        backend.close()
        print(
            f"workbench: interrupted; stopped the {backend.describe()} (runs in progress abandoned); finished runs "
            f"are kept in {out / 'runs'}: rerun to resume",
            file=sys.stderr,
        )
        return EXIT_INTERRUPTED
    except BackendError as exc:
        print(f"workbench: {exc}; finished runs are kept in {out / 'runs'}: rerun to resume", file=sys.stderr)
        return EXIT_RUN_FAILED
    finally:
        for stop_signal, handler in previous.items():
            signal.signal(stop_signal, signal.SIG_DFL if handler is None else handler)


def _max_runs(args: argparse.Namespace) -> int | None:
    """A study command's --max-runs (sweep, optimise, robustness): None (the default limit) or a whole number
    >= 1."""
    if args.max_runs is not None and args.max_runs < 1:
        raise WorkbenchInputError(f"--max-runs must be a whole number >= 1; got {args.max_runs}")
    return args.max_runs


def _start_study(args: argparse.Namespace, load: Callable[[int | None], SpecT]) -> tuple[SpecT, Backend]:
    """Check the output folder (a study's resumable store: `check_study_dir`) and the spec (`load` reads it, given
    --max-runs: every file it names, the study's size), start nothing yet but the folder and the spec's copy in
    it."""
    from workbench.apps.studies import make_backend
    from workbench.base.output_dir import check_study_dir

    check_study_dir(args.out)
    _check_inputs(args)
    spec = load(_max_runs(args))
    backend = make_backend(args.backend, args.scheduler, args.workers)
    copy = args.out / "spec.toml"
    try:
        args.out.mkdir(parents=True, exist_ok=True)
        if not copy.exists() or not copy.samefile(args.spec):
            shutil.copyfile(args.spec, copy)
    except OSError as exc:
        raise WorkbenchInputError(f"--out {str(args.out)!r}: cannot write the spec's copy ({exc})") from None
    return spec, backend


def _robustness(args: argparse.Namespace) -> int:
    from workbench.apps.robustness import plan_robustness, run_robustness
    from workbench.apps.studies import make_backend
    from workbench.apps.studies.spec import DEFAULT_MAX_RUNS
    from workbench.base.errors import require_positive
    from workbench.base.output_dir import check_study_dir

    check_study_dir(args.out)
    _check_inputs(args)
    require_positive("--max-cte", args.max_cte)
    max_runs = _max_runs(args)
    controllers = _names(args.controllers, "controllers")
    runs = plan_robustness(
        args.scenario,
        controllers,
        args.vehicle,
        args.speed,
        args.conditions,
        args.seed,
        args.track,
        Path.cwd(),
        allow_long_run=args.allow_long_run,
        allow_infeasible=args.allow_infeasible,
        inform_delays=args.inform_delays,
        circuit_ranges=args.circuit_ranges,
    )
    limit = DEFAULT_MAX_RUNS if max_runs is None else max_runs
    if len(runs) > limit:
        raise WorkbenchInputError(
            f"the robustness study plans {len(runs):,} runs ({len(controllers)} controller(s), each at the base and "
            f"at every other value of each factor), more than the limit of {limit:,}: name fewer controllers or "
            "raise the limit with --max-runs N"
        )
    backend = make_backend(args.backend, args.scheduler, args.workers)

    def study() -> int:
        print(f"{len(runs)} runs on the {backend.describe()}")
        with backend:
            result = run_robustness(
                runs,
                args.out,
                backend,
                args.scenario,
                args.vehicle,
                controllers,
                args.conditions,
                args.speed,
                progress=sys.stderr.isatty(),
                max_cte_m=args.max_cte,
                inform_delays=args.inform_delays,
            )
        written = result.save(args.out)
        print(result.tolerance().to_string(index=False, float_format=lambda v: f"{v:.3g}", na_rep="-"))
        for line in result.payload_summary():
            print(line)
        print(f"wrote {', '.join(str(p) for p in written)} and {args.out / 'results.parquet'}")
        return 0

    return _interruptible(study, args.out, backend)


def _sweep(args: argparse.Namespace) -> int:
    from workbench.apps.studies import load_spec, run_sweep

    spec, backend = _start_study(args, lambda max_runs: load_spec(args.spec, "sweep", max_runs=max_runs))
    n = spec.run_count()

    def study() -> int:
        print(f"{n} runs; running those not yet in {args.out} on the {backend.describe()}")
        result = run_sweep(spec, args.out, backend, progress=sys.stderr.isatty())
        report = f"Sweep: {args.spec}"
        figures = [] if args.no_plots else [*result.save_figures(args.out), result.save_report(args.out, report)]
        written = [args.out / "results.parquet", *figures]
        counts = ", ".join(f"{v} {k}" for k, v in result.status_counts().items())
        print(f"{n} runs ({n - result.ran} already done, {result.ran} run now): {counts}")
        print(result.summary().to_string(index=False, float_format=lambda v: f"{v:.3g}"))
        errors = result.errors()
        for message in list(dict.fromkeys(errors["message"]))[:3]:
            print(f"  error: {message}")
        print(f"wrote {', '.join(str(p) for p in written)}")
        if len(errors):
            print(
                f"workbench: {len(errors)} of {n} runs raised an error (status error; the first messages above, each "
                f"run's message and traceback in {args.out / 'results.parquet'}): exit code {EXIT_RUN_FAILED}",
                file=sys.stderr,
            )
            return EXIT_RUN_FAILED
        return 0

    return _interruptible(study, args.out, backend)


def _optimise(args: argparse.Namespace) -> int:
    from workbench.apps.studies import load_spec, run_optimisation
    from workbench.apps.studies.optimise import objective_text

    spec, backend = _start_study(args, lambda max_runs: load_spec(args.spec, "optimise", max_runs=max_runs))
    trials = spec.optimise.trials if spec.optimise else 0

    def study() -> int:
        print(
            f"{trials} trials of {spec.run_count()} runs each, minimising {objective_text(spec)}, "
            f"on the {backend.describe()}"
        )
        result = run_optimisation(spec, args.out, backend, progress=sys.stderr.isatty())
        failed = int((result.history["state"] == "failed").sum())
        print(f"{len(result.history)} trials ({failed} failed); {result.ran} runs run now")
        if result.best_trial is None:
            reasons = list(dict.fromkeys(result.history["reason"]))[:3]
            print(f"workbench: no trial completed: {'; '.join(reasons)}", file=sys.stderr)
            return EXIT_RUN_FAILED
        params = ", ".join(f"{k} = {v!r}" for k, v in result.best_params.items())
        print(f"best: trial {result.best_trial}, objective {result.best_value:.6g}: {params}")
        print(f"wrote {result.config_file} (use with --controller-config), best.json, history.parquet, results.parquet")
        return 0

    return _interruptible(study, args.out, backend)


#: The leaderboard's columns `workbench tournament` prints (the report has them all).
_LEADERBOARD_COLUMNS = (
    "rank", "controller", "trial", "score", "score_low", "score_high", "default_score", "failed_fraction",
    "max_abs_cte_on_path_m", "max_abs_cte_m", "rms_cte_m", "rms_steer_rate_deg_s", "step_time_median_us",
    "step_time_p99_us", "cpu_time_s", "not_distinguishable_from",
)  # fmt: skip


def _tournament(args: argparse.Namespace) -> int:
    """`workbench tournament`: the stages on stderr, the leaderboard and what was written on stdout."""
    from workbench.apps.studies.tournament import run_tournament
    from workbench.apps.studies.tournament_spec import load_tournament

    spec, backend = _start_study(args, lambda max_runs: load_tournament(args.spec, max_runs=max_runs))

    def study() -> int:
        print(
            f"{len(spec.controllers)} controllers x {spec.trials} trials on {spec.cases_text('train')}, judged on "
            f"{spec.cases_text('test')}, on the {backend.describe()}"
        )
        result = run_tournament(spec, args.out, backend, progress=sys.stderr.isatty())
        board = result.judgement.leaderboard
        board = board[[c for c in _LEADERBOARD_COLUMNS if c in board.columns] or list(board.columns)]
        print(f"{len(result.results)} runs ({result.ran} run now); on the test set, {spec.ranking_text()}:")
        print(board.to_string(index=False, float_format=lambda v: f"{v:.4g}", na_rep="-"))
        untuned = [c for c, trial in result.chosen.items() if trial is None]
        if untuned:
            print(f"  no trial completed for {', '.join(untuned)}: tuned is the default")
        print(f"wrote {result.report}, results.parquet, history.parquet, best/<controller>.toml in {args.out}")
        return 0

    return _interruptible(study, args.out, backend)


def _run(args: argparse.Namespace) -> int:
    """`workbench run`: with a second CPU, its plots are drawn by a second process, started first so that it imports
    matplotlib while this one simulates (`workbench.simulation.plot_worker`)."""
    from workbench.simulation import plot_worker

    if args.no_plots or not plot_worker.worthwhile():
        return _run_with(args, None)
    try:
        worker = plot_worker.PlotWorker()
    except OSError:  # no second process to be had: draw here
        return _run_with(args, None)
    with worker:
        return _run_with(args, worker)


def _run_with(args: argparse.Namespace, plot_worker: PlotWorker | None) -> int:
    from workbench.apps.stage_progress import StageProgress
    from workbench.base.output_dir import OutputDir
    from workbench.simulation.limit_cycle import detect_limit_cycle

    out = OutputDir(args.out, "run", args.overwrite)
    _check_inputs(args)
    with StageProgress("run", 3) as progress:
        simulation, result, written = _run_stages(args, plot_worker, out, progress)
    scenario, controller, vehicle = simulation.scenario, simulation.controller, simulation.vehicle
    top = None if simulation.top_speed.reached else simulation.top_speed  # the planned speed falls short
    speed = f"at {args.speed:g} km/h"
    if top is not None:
        speed = f"target {args.speed:g} km/h, planned top {top.top_mps * 3.6:.3g} km/h"
    m = result.metrics

    def fmt(value: float | None, unit: str) -> str:
        return "n/a" if value is None or (isinstance(value, float) and math.isnan(value)) else f"{value:.3f} {unit}"

    print(f"{scenario.name}: {controller.name} on {vehicle.name} {speed} -> {result.status.value}")
    if top is not None:
        print(f"  the planned top speed is limited by {top.reason()}")
    run_config = simulation.config
    if not run_config.conditions.is_ideal:
        told = "told their delays" if run_config.inform_delays else "not told their delays (--inform-delays tells it)"
        if run_config.perfect_prediction:
            told += ", and handed the true state one dead time ahead (--perfect-prediction)"
        print(f"  conditions {run_config.conditions.name}, seed {run_config.seed}: the controller {told}")
    print(f"  distance {fmt(m.distance_m, 'm')} of {fmt(m.path_length_m, 'm')}")
    print(f"  max |CTE| {fmt(m.max_abs_cte_m, 'm')}, RMS CTE {fmt(m.rms_cte_m, 'm')}")
    print(
        f"  max |steering-wheel angle| {fmt(m.max_abs_steer_wheel_deg, 'deg')}, "
        f"max |lateral acceleration| {fmt(m.max_abs_lat_accel_g, 'g')}"
    )
    print(
        f"  steering oscillation {fmt(m.steer_oscillation_deg, 'deg')} (RMS about its 1 s average), "
        f"RMS steering rate {fmt(m.rms_steer_rate_deg_s, 'deg/s')}"
    )
    cycle = detect_limit_cycle(result.trace["t_s"], result.trace["steer_wheel_rad"])
    if cycle.detected:
        print(f"  WARNING: steering limit cycle at {cycle.describe()}")
    print(f"  controller step median {fmt(m.step_time_median_us, 'us')}, p99 {fmt(m.step_time_p99_us, 'us')}")
    if m.min_track_margin_m is not None:  # a path with track widths (a TUMFTM track)
        print(f"  least track margin {fmt(m.min_track_margin_m, 'm')}" + (" (LEFT THE TRACK)" if m.left_track else ""))
    print(f"  wrote {len(written)} files to {args.out}")
    if not result.completed:
        print(f"workbench: run did not complete: {result.message} (partial trace kept in {args.out})", file=sys.stderr)
        return EXIT_RUN_FAILED
    return 0


def _vehicle_and_options(
    args: argparse.Namespace, warn: Callable[[str], None]
) -> tuple[VehicleModel, DataclassInstance]:
    """The vehicle (--vehicle, --vehicle-file, --payload-kg) and the controller's options (--controller-config,
    --set; `read_controller_config`) of `run` and `export-fmu`; an unknown controller name is refused."""
    from workbench.apps.controller_config import read_controller_config
    from workbench.vehicles import make_vehicle

    name = args.vehicle if args.vehicle is not None or args.vehicle_file else DEFAULT_VEHICLE
    vehicle = make_vehicle(name, payload_kg=args.payload_kg, vehicle_file=args.vehicle_file)
    CONTROLLERS.require(args.controller)
    options = read_controller_config(
        args.controller_config,
        args.controller,
        CONTROLLERS[args.controller].config_type,
        args.set,
        vehicle.geometry,
        warn=warn,
    )
    return vehicle, options


def _scenario(args: argparse.Namespace, vehicle: VehicleModel) -> Scenario:
    """The scenario (or waypoint file) of `run` and `export-fmu`, sized for the vehicle (--track,
    --circuit-ranges)."""
    from workbench.simulation.scenarios import ScenarioOptions, make_scenario

    options = ScenarioOptions(
        vehicle_width_m=vehicle.geometry.width_m, track_file=args.track, circuit_ranges=_circuit_ranges(args)
    )
    return make_scenario(args.scenario, options)


def _export_fmu(args: argparse.Namespace) -> int:
    """`workbench export-fmu`: the controller `run` would build, with the path `run` would plan (a path the vehicle
    cannot follow refused as `run` refuses it, unless --allow-infeasible), as an FMU (`workbench.apps.fmu_export`)."""
    from tuning.own_tuning import tuned_controller
    from workbench.apps.fmu_export import build_controller_fmu, check_fmu_target, named_files
    from workbench.simulation.feasibility import refuse_infeasible
    from workbench.simulation.simulator import Simulation, SimulationConfig

    _check_inputs(args)
    check_fmu_target(args.out, args.overwrite)
    config = SimulationConfig(
        speed_kmh=args.speed, max_lateral_accel_g=args.lat_accel_g, controller_rate_hz=args.controller_rate_hz
    )
    vehicle, options = _vehicle_and_options(args, warn_on_stderr)
    controller = tuned_controller(args.controller, vehicle, options)
    simulation = Simulation(_scenario(args, vehicle), vehicle, controller, config)  # plans the path as `run` does
    if not args.allow_infeasible:
        refuse_infeasible(simulation.path_warnings())
    label = f"{simulation.scenario.name}: {controller.name} on {vehicle.name}"
    for warning in simulation.warnings(label):
        warn_on_stderr(warning)
    path = simulation.path
    files = named_files(args.controller_config, args.controller, args.set)
    period_s = 1.0 / config.controller_rate_hz
    build_controller_fmu(args.out, args.controller, vehicle, options, files, path, period_s)
    print(
        f"wrote {args.out}: {args.controller} on {vehicle.name} along {path.name} ({path.length_m:.0f} m, planned "
        f"at up to {args.speed:g} km/h), an FMI 2.0 co-simulation FMU stepping every {period_s:g} s"
    )
    return 0


def _run_stages(
    args: argparse.Namespace, plot_worker: PlotWorker | None, out: OutputDir, progress: StageProgress
) -> tuple[Simulation, SimulationResult, list[Path]]:
    """`workbench run`'s work, each stage named on `progress`: build the run (refused here when it may simulate
    more than the bounds of `run_size` without --allow-long-run), simulate, write."""
    from tuning.own_tuning import tuned_controller
    from workbench.simulation.feasibility import refuse_infeasible
    from workbench.simulation.run_size import check_run_size, duration_text
    from workbench.simulation.simulator import Simulation

    config = _run_config(args)
    progress.stage("building the vehicle, the controller and the scenario")
    vehicle, options = _vehicle_and_options(args, progress.warn)
    delays = config.known_delays
    controller = tuned_controller(args.controller, vehicle, options, delays)
    scenario = _scenario(args, vehicle)
    if args.scenario == TRACK_SCENARIO and scenario.name != TRACK_SCENARIO:  # another file given: named by it
        progress.warn(scenario.description)
    simulation = Simulation(scenario, vehicle, controller, config)
    label = f"{scenario.name}: {controller.name} on {vehicle.name}"
    if not args.allow_long_run:
        check_run_size(simulation.size, label, _SHORTEN_RUN.format(speed=args.speed), "--allow-long-run")
    if not args.allow_infeasible:  # refused before the run, as compare, robustness and the studies refuse it
        refuse_infeasible(simulation.path_warnings())
    for warning in simulation.warnings(label):
        progress.warn(warning)
    progress.stage(
        f"simulating {simulation.total_length_m:,.0f} m of {scenario.name} (time-out after "
        f"{duration_text(simulation.max_time_s)} simulated)"
    )
    result = simulation.run(progress=progress.terminal)
    progress.stage(f"writing to {args.out}")
    with _writing(out):
        written = result.save(args.out, with_plots=not args.no_plots, plot_worker=plot_worker)
    return simulation, result, written


def _scenarios(args: argparse.Namespace) -> int:
    from workbench.simulation.scenarios import ScenarioOptions, describe_scenarios, make_scenario

    _check_inputs(args)
    if args.show_circuit_ranges is not None:
        from workbench.simulation.circuit_ranges import circuit_ranges_toml, read_circuit_ranges

        path = args.show_circuit_ranges
        if args.track is not None:
            raise WorkbenchInputError("--circuit-ranges prints the circuits' ranges and reads no --track: drop one")
        print(circuit_ranges_toml(read_circuit_ranges(path) if path else None), end="")
        return 0
    options = ScenarioOptions(track_file=args.track)
    if args.track is not None:
        make_scenario(TRACK_SCENARIO, options)  # a track that cannot be used is refused, not described
    for name, description in describe_scenarios(options):
        print(f"{name:<12} {description}")
    return 0


def _vehicles(args: argparse.Namespace) -> int:
    from workbench.vehicles import VEHICLES, list_presets, preset_text
    from workbench.vehicles.presets import TEMPLATE_ONLY_TYPES

    if args.show:
        print(preset_text(args.show), end="")
    else:
        for name, description in list_presets().items():
            print(f"{name:<20} {description}\n{'':<20} {VEHICLES[name]().describe()}")
        for name in TEMPLATE_ONLY_TYPES:
            print(f"{name:<20} your own model: `workbench vehicles --show {name}` prints a vehicle file to fill in")
    return 0


def _conditions(args: argparse.Namespace) -> int:
    from workbench.simulation.conditions import CONDITIONS, conditions_to_toml, load_conditions

    if args.show:
        print(conditions_to_toml(load_conditions(args.show)), end="")
    else:
        for name, conditions in CONDITIONS.items():
            print(f"{name:<12} {conditions.describe()}")
    return 0


def _controllers(args: argparse.Namespace) -> int:
    from workbench.apps.controller_config import config_template

    if args.show:
        CONTROLLERS.require(args.show)
        if args.search_space:
            from controllers.search_space import search_space_toml

            print(search_space_toml(args.show), end="")
        else:
            print(config_template(args.show, CONTROLLERS[args.show].config_type), end="")
        return 0
    if args.search_space:
        raise WorkbenchInputError("--search-space needs --show NAME: the controller whose search space to print")
    for name in CONTROLLERS:
        try:
            summary = CONTROLLERS[name].summary()
        except WorkbenchInputError as exc:  # an installed package's controller that cannot be used
            summary = f"(not usable: {exc})"
        print(f"{name:<14} {summary}")
    return 0


COMMANDS: dict[str, Callable[[argparse.Namespace], int]] = {
    "scenarios": _scenarios,
    "vehicles": _vehicles,
    "controllers": _controllers,
    "conditions": _conditions,
    "run": _run,
    "compare": _compare,
    "fig17": _fig17,
    "paper": _paper,
    "sweep": _sweep,
    "robustness": _robustness,
    "optimise": _optimise,
    "tournament": _tournament,
    "export-fmu": _export_fmu,
}


def console() -> int:
    """The console script: `main` on sys.argv (`workbench.base.console`: no collections at exit)."""
    return console_exit(main)


def main(argv: Sequence[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    args = _parser(_command_word(argv)).parse_args(argv)
    try:
        return COMMANDS[args.command](args)
    except WorkbenchInputError as exc:
        print(f"workbench: error: {exc}", file=sys.stderr)
        return EXIT_INPUT_ERROR


if __name__ == "__main__":
    sys.exit(console())
