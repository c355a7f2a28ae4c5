"""The `tuning` command line: tools that turn vehicle logs into the parameter files the controllers read."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from pathlib import Path

from tuning.data_generation import generate_open_loop_log
from tuning.maneuvers import Maneuver
from workbench.errors import WorkbenchInputError
from workbench.vehicles import make_vehicle

EXIT_INPUT_ERROR = 2


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="tuning", description="Identify vehicle lag and tune controller filters.")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    gen = sub.add_parser(
        "generate-data",
        help="drive a plant open loop with a steering profile and write a CSV log (the fit-lag input format)",
    )
    gen.add_argument("--vehicle", help="vehicle model (see `workbench vehicles`)")
    gen.add_argument("--vehicle-file", type=Path, help="a vehicle TOML file instead of a named preset")
    gen.add_argument("--payload-kg", type=float, help="payload of vehicles that carry one (tractor-semitrailer)")
    gen.add_argument("--maneuver", required=True, choices=Maneuver.KINDS, help="steering-wheel profile")
    gen.add_argument("--speed", type=float, required=True, metavar="KMH", help="held speed, km/h")
    gen.add_argument("--amplitude-deg", type=float, default=90.0, help="steering-wheel amplitude (default 90 deg)")
    gen.add_argument("--duration-s", type=float, default=20.0, help="log length (default 20 s)")
    gen.add_argument("--sample-rate-hz", type=float, default=100.0, help="log sample rate (default 100 Hz)")
    gen.add_argument("--out", type=Path, required=True, metavar="FILE.csv", help="output CSV")
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    args = _parser().parse_args(argv)
    try:
        if args.vehicle is None and args.vehicle_file is None:
            raise WorkbenchInputError("give --vehicle NAME or --vehicle-file FILE")
        vehicle = make_vehicle(args.vehicle, payload_kg=args.payload_kg, vehicle_file=args.vehicle_file)
        maneuver = Maneuver(args.maneuver, amplitude_deg=args.amplitude_deg, duration_s=args.duration_s)
        log = generate_open_loop_log(vehicle, maneuver, args.speed, sample_rate_hz=args.sample_rate_hz)
    except WorkbenchInputError as exc:
        print(f"tuning: error: {exc}", file=sys.stderr)
        return EXIT_INPUT_ERROR
    args.out.parent.mkdir(parents=True, exist_ok=True)
    log.to_csv(args.out, index=False, float_format="%.9g")
    print(
        f"wrote {len(log)} rows ({log['t_s'].iloc[-1]:.1f} s of {args.maneuver} at {args.speed:g} km/h) to {args.out}"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
