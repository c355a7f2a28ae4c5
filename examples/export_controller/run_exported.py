"""Take the clothoid controller home: export it as an FMI 2.0 co-simulation FMU (`workbench export-fmu`) and steer
a plant with it through FMPy, as a user's own simulation tool would; the same controller, built in this process
as `workbench run` builds it, is stepped beside it on the same measurements to show that the FMU's commands are
the workbench's.

    python examples/export_controller/run_exported.py                       # the dynamic bicycle's dlc at 30 km/h
    python examples/export_controller/run_exported.py --vehicle tractor-semitrailer --path lane-change --speed 40

The plant here is the workbench's own vehicle model stepped in Python at 1 kHz (the FMU would be connected to the
user's plant instead); the FMU runs its Python code in the Python that loads it, so this package must be installed
there.
"""

from __future__ import annotations

import argparse
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

#: The measurement inputs of the FMU, in the order of `Measurement`'s fields.
INPUTS = ("t_s", "x_m", "y_m", "vx_mps", "vy_mps", "yaw_rad", "yaw_rate_rad_s", "steer_wheel_rad")
#: Plant integration steps per controller step (the workbench's 1 kHz plant under a 50 Hz controller).
SUBSTEPS = 20


@dataclass(frozen=True)
class Drive:
    """One closed-loop drive: per controller step, the time (s), the FMU's command and the in-process controller's
    (rad), their diagnostics (one row a step, columns `diagnostic_names`), the cross-track error (m)."""

    t_s: np.ndarray
    fmu_command_rad: np.ndarray
    in_process_command_rad: np.ndarray
    diagnostic_names: tuple[str, ...]
    fmu_diagnostics: np.ndarray
    in_process_diagnostics: np.ndarray
    cte_m: np.ndarray


def export(out: Path, vehicle: str, path: str, speed_kmh: float) -> Path:
    """`workbench export-fmu clothoid` for the vehicle preset and the path (scenario name or waypoint file)."""
    from workbench.apps.cli import main

    argv = ["export-fmu", "clothoid", "--vehicle", vehicle, "--path", path, "--speed", f"{speed_kmh:g}"]
    if main([*argv, "--out", str(out), "--overwrite"]) != 0:
        raise SystemExit("run_exported: the export failed (see the error above)")
    return out


def drive(fmu_file: Path, vehicle_name: str, path_name: str, speed_kmh: float) -> Drive:
    """Steer the vehicle preset along the path with the FMU (stepped by FMPy at its default step), and step the
    in-process controller on the same measurements, until the path's end."""
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave

    from tuning.own_tuning import tuned_controller
    from workbench.simulation.control_interface import Measurement
    from workbench.simulation.scenarios import ScenarioOptions, make_scenario
    from workbench.simulation.simulator import SimulationConfig, plan_path_speed
    from workbench.vehicles import make_vehicle

    vehicle = make_vehicle(vehicle_name)
    scenario = make_scenario(path_name, ScenarioOptions(vehicle_width_m=vehicle.geometry.width_m))
    path = plan_path_speed(scenario.path, SimulationConfig(speed_kmh=speed_kmh))
    description = read_model_description(str(fmu_file), validate=True)
    dt = float(description.defaultExperiment.stepSize)
    refs = {v.name: v.valueReference for v in description.modelVariables}
    outputs = [v.name for v in description.modelVariables if v.causality == "output"]
    diagnostic_names = tuple(name.removeprefix("ctrl_") for name in outputs[1:])

    in_process = tuned_controller("clothoid", vehicle)
    in_process.reset(path, dt)
    unzipped = extract(str(fmu_file))
    fmu = FMU2Slave(
        guid=description.guid,
        unzipDirectory=unzipped,
        modelIdentifier=description.coSimulation.modelIdentifier,
        instanceName="controller",
    )
    fmu.instantiate()
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()

    x0, y0, yaw0 = scenario.initial_pose()
    state = vehicle.initial_state(x0, y0, yaw0, float(path.speed_mps[0]))
    tracker = path.tracker(0.0)
    rows: dict[str, list] = {k: [] for k in ("t", "fmu", "own", "fmu_diag", "own_diag", "cte")}
    command, t = 0.0, 0.0
    max_steps = int(3.0 * path.length_m / float(path.speed_mps.min()) / dt)
    try:
        for _ in range(max_steps):
            x, y, yaw, vx, vy, yaw_rate, steer_wheel = (float(v) for v in vehicle.outputs(state, command, 0.0)[:7])
            foot = tracker.update(x, y)
            if foot.at_end:
                break
            measured = (t, x, y, vx, vy, yaw, yaw_rate, steer_wheel)
            fmu.setReal([refs[name] for name in INPUTS], list(measured))
            fmu.doStep(currentCommunicationPoint=t, communicationStepSize=dt)
            values = fmu.getReal([refs[name] for name in outputs])
            command = values[0]
            rows["t"].append(t)
            rows["fmu"].append(command)
            rows["own"].append(in_process.step(Measurement(*measured), path))
            rows["fmu_diag"].append(values[1:])
            rows["own_diag"].append(in_process.diagnostic_values.copy())
            rows["cte"].append(foot.cte_m)
            state = vehicle.advance(state, command, 0.0, dt, SUBSTEPS)  # the speed held: no longitudinal command
            t += dt
    finally:
        fmu.terminate()
        fmu.freeInstance()
    return Drive(
        np.array(rows["t"]),
        np.array(rows["fmu"]),
        np.array(rows["own"]),
        diagnostic_names,
        np.array(rows["fmu_diag"]).reshape(-1, len(diagnostic_names)),
        np.array(rows["own_diag"]).reshape(-1, len(diagnostic_names)),
        np.array(rows["cte"]),
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--vehicle", default="dynamic-bicycle", help="vehicle preset (default dynamic-bicycle)")
    parser.add_argument("--path", default="dlc", help="scenario name or waypoint CSV (default dlc)")
    parser.add_argument("--speed", type=float, default=30.0, help="planned top speed, km/h (default 30)")
    parser.add_argument("--out", type=Path, help="where to keep the FMU (default: a temporary folder)")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        fmu_file = export(args.out or Path(tmp) / "clothoid.fmu", args.vehicle, args.path, args.speed)
        run = drive(fmu_file, args.vehicle, args.path, args.speed)
    difference = float(np.max(np.abs(run.fmu_command_rad - run.in_process_command_rad)))
    print(f"{run.t_s.size} controller steps over {run.t_s[-1]:.1f} s along {args.path} on the {args.vehicle}")
    print(f"  max |CTE| {np.max(np.abs(run.cte_m)):.3f} m, max |steering-wheel command| "
          f"{np.degrees(np.max(np.abs(run.fmu_command_rad))):.1f} deg")  # fmt: skip
    print(f"  FMU against the in-process controller: max |command difference| {difference:.3g} rad")


if __name__ == "__main__":
    main()
