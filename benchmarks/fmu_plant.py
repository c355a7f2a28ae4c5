"""FMU plant benchmark: the cost of a plant step through FMI against the same model stepped natively, at the
workbench's 1 kHz plant rate, and the truck's dlc through an FMU plant end to end.

Plant step: the example FMU of CommonRoad's single-track car (examples/fmu_plant/: PythonFMU for FMI 2.0,
pythonfmu3 for FMI 3.0) against its own model (`commonroad_st_plant.CommonRoadSTPlant.step`, 1 ms) called
directly, on a steady turn at 10 m/s. "In a run" is what the simulator pays: `FmuPlant.advance` of one 50 Hz
controller step (20 doSteps of 1 ms, the inputs set and the outputs read once), per plant step; "doStep alone" is
one `fmi2DoStep`/`fmi3DoStep` of 1 ms. The FMI overhead is the median minus the native median. Goal: at most 25 us
a plant step in a run with the PythonFMU FMU (FMI 2.0). Beside them a C FMU of the same model
(benchmarks/fmu_plant_c/commonroad_st.c, built with the machine's C compiler against FMPy's FMI 2.0 headers; not
measured without a compiler): its model step costs a fraction of a microsecond, so its time is FMI's own floor.

Truck dlc end to end: the workbench's tractor-semitrailer preset wrapped in a PythonFMU FMU (each doStep one RK4
step of its compiled model) and driven through its vehicle file, the clothoid controller with the truck's shipped
tuning, the dlc at 60 km/h; against the same run on the native truck: the largest difference of the traces and the
wall time of each.

    python benchmarks/fmu_plant.py [--out benchmarks/results/fmu_plant.json] [--calls 3000] [--check]
"""

from __future__ import annotations

import argparse
import dataclasses
import importlib.util
import sys
import tempfile
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np
from benchmark_report import exit_code, machine, write_results

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "fmu_plant"
#: Goal: FMI overhead of a plant step in a run, PythonFMU FMI 2.0 FMU (us).
OVERHEAD_GOAL_US = 25.0
#: Interleaved timing rounds of the plant steps.
ROUNDS = 5
#: The dlc speed of the end-to-end truck run (km/h).
TRUCK_SPEED_KMH = 60.0

TRUCK_SLAVE = '''
"""The workbench's tractor-semitrailer preset as an FMI 2.0 co-simulation FMU (benchmarks/fmu_plant.py)."""

from pythonfmu import Fmi2Causality, Fmi2Slave, Fmi2Variability, Real

from workbench.vehicles import make_vehicle

OUTPUTS = ("x_m", "y_m", "yaw_rad", "vx_mps", "vy_mps", "yaw_rate_rad_s", "road_wheel_angle_rad", "lat_accel_mps2",
           "ltr", "trailer_x_m", "trailer_y_m", "articulation_rad")


class WorkbenchTruck(Fmi2Slave):
    description = "the workbench's tractor-semitrailer preset"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.truck = make_vehicle("tractor-semitrailer")
        self.index = [self.truck.output_names.index(name) for name in OUTPUTS]
        self.delta_cmd = self.accel_cmd = 0.0
        self.v0 = 10.0
        self.register_variable(Real("delta_cmd", causality=Fmi2Causality.input))
        self.register_variable(Real("accel_cmd", causality=Fmi2Causality.input))
        self.register_variable(Real("v0", causality=Fmi2Causality.parameter, variability=Fmi2Variability.fixed))
        for name in OUTPUTS:
            setattr(self, name, 0.0)
            self.register_variable(Real(name, causality=Fmi2Causality.output))

    def _publish(self, steer_wheel):
        out = self.truck.outputs(self.state, steer_wheel, self.accel_cmd).tolist()
        for name, i in zip(OUTPUTS, self.index):
            setattr(self, name, out[i])

    def exit_initialization_mode(self):
        self.state = self.truck.initial_state(0.0, 0.0, 0.0, self.v0)
        self._publish(0.0)

    def do_step(self, current_time, step_size):
        steer_wheel = self.delta_cmd * self.truck.geometry.steering_ratio
        self.state = self.truck.advance(self.state, steer_wheel, self.accel_cmd, step_size, 1)
        self._publish(steer_wheel)
        return True
'''


@dataclass
class Entry:
    name: str
    median_us: float | None = None
    p99_us: float | None = None
    overhead_us: float | None = None
    wall_s: float | None = None
    goal: str | None = None
    goal_met: bool | None = None
    note: str | None = None


def _example_builder():
    """examples/fmu_plant/build_fmu.py as a module (its folder on sys.path, where PythonFMU finds the slaves)."""
    sys.path.insert(0, str(EXAMPLE))
    spec = importlib.util.spec_from_file_location("build_fmu", EXAMPLE / "build_fmu.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _times_us(fn: Callable[[], object], calls: int, per: int = 1) -> np.ndarray:
    """Wall time (us) of each of `calls` calls of fn, divided by `per`, after 50 warm-up calls."""
    for _ in range(50):
        fn()
    out = np.empty(calls)
    clock = time.perf_counter
    for i in range(calls):
        start = clock()
        fn()
        out[i] = (clock() - start) * 1e6 / per
    return out


def _vehicle_file(folder: Path, name: str, fields: dict[str, object]) -> Path:
    """A vehicle file of model type fmu with these [parameters]."""
    from workbench.base.toml_text import toml_value

    lines = ["[model]", 'type = "fmu"', "", "[parameters]"] + [f"{k} = {toml_value(v)}" for k, v in fields.items()]
    path = folder / f"{name}.toml"
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


#: The plant FMUs timed: key -> what (the C FMU when a compiler is found).
KINDS = {"2": "FMI 2.0 (PythonFMU)", "3": "FMI 3.0 (pythonfmu3)", "C": "FMI 2.0 (C, the same model ported)"}


def plant_step_entries(folder: Path, calls: int, rounds: int = ROUNDS) -> list[Entry]:
    """The plant step entries (module docstring): native, then each FMU in a run and doStep alone. Each is timed in
    `rounds` interleaved rounds, so that a busy spell of the machine falls on all of them alike."""
    builder = _example_builder()
    from commonroad_st_plant import CommonRoadSTPlant  # the example's model (its folder put on sys.path above)

    from workbench.vehicles import load_vehicle

    native = CommonRoadSTPlant()
    native.start(10.0)
    native.delta_cmd = 0.02
    timed: dict[str, tuple[Callable[[], object], int, int]] = {"native": (lambda: native.step(0.001), calls, 1)}
    template = (EXAMPLE / "commonroad_st.toml").read_text(encoding="utf-8")
    fmus = {version: builder.build(folder / f"commonroad_st_fmi{version}.fmu", version) for version in ("2", "3")}
    c_fmu = build_c_fmu(folder)
    if c_fmu is not None:
        fmus["C"] = c_fmu
    plants = []
    for kind, fmu in fmus.items():
        vehicle_file = folder / f"commonroad_st_{kind}.toml"
        vehicle_file.write_text(template.replace('"commonroad_st.fmu"', f'"{fmu.name}"'), encoding="utf-8")
        plant = load_vehicle(str(vehicle_file))
        plants.append(plant)
        steer = 0.02 * plant.geometry.steering_ratio
        holder = [plant.initial_state(0.0, 0.0, 0.0, 10.0)]

        def run_step(plant=plant, holder=holder, steer=steer) -> None:
            holder[0] = plant.advance(holder[0], steer, 0.0, 0.02, 20)

        timed[f"{kind} in a run"] = (run_step, max(calls // 20, 50), 20)
        timed[f"{kind} alone"] = (lambda step=plant._fmu.step: step(0.001), calls, 1)
    samples: dict[str, list[np.ndarray]] = {key: [] for key in timed}
    for _ in range(rounds):
        for key, (fn, n, per) in timed.items():
            samples[key].append(_times_us(fn, max(n // rounds, 10), per))
    for plant in plants:
        plant._fmu.close()
    stats = {key: (float(np.median(np.concatenate(v))), float(np.percentile(np.concatenate(v), 99)))
             for key, v in samples.items()}  # fmt: skip
    native_median = stats["native"][0]
    entries = [Entry("CommonRoad single track, native: one 1 ms RK4 step", *stats["native"])]
    for kind, what in KINDS.items():
        if kind not in fmus:
            entries.append(Entry(what, note="not measured: no C compiler found"))
            continue
        python = kind != "C"  # the C FMU runs another implementation: no native twin to subtract, the time is FMI's
        median, p99 = stats[f"{kind} in a run"]
        goal = kind == "2"
        entries.append(
            Entry(
                f"{what}: a plant step in a run (advance of 20 doSteps / 20)",
                median,
                p99,
                median - native_median if python else None,
                goal=f"FMI overhead <= {OVERHEAD_GOAL_US:g} us a plant step" if goal else None,
                goal_met=(median - native_median <= OVERHEAD_GOAL_US) if goal else None,
                note=None if python else "the C model's own step is a fraction of a microsecond: the rest is FMI's",
            )
        )
        median, p99 = stats[f"{kind} alone"]
        overhead = median - native_median if python else None
        entries.append(Entry(f"{what}: doStep of 1 ms alone", median, p99, overhead))
    return entries


#: The C port of the example's model (an FMI 2.0 co-simulation FMU built here when a C compiler is found).
C_SOURCE = Path(__file__).resolve().parent / "fmu_plant_c" / "commonroad_st.c"
#: The C FMU's model identifier and GUID.
C_IDENTIFIER, C_GUID = "CommonRoadSTC", "{5b0d2e54-6c1e-4f5e-9d0a-commonroad-st-c}"
#: Its variables, in value-reference order: (name, causality, start) (the example's names).
C_VARIABLES = (
    ("delta_cmd", "input", 0.0),
    ("accel_cmd", "input", 0.0),
    ("v0", "parameter", 10.0),
    *((name, "output", None) for name in ("x_rear", "y_rear", "psi", "vx_rear", "vy_rear", "yaw_rate", "delta")),
    ("ay_rear", "output", None),
)


def build_c_fmu(folder: Path) -> Path | None:
    """The C FMU (C_SOURCE, CommonRoad's parameters_vehicle2 written to its params.h), compiled with the machine's C
    compiler against FMPy's FMI 2.0 headers; None when there is no C compiler."""
    import shutil
    import subprocess
    import zipfile

    import fmpy
    from vehiclemodels.parameters_vehicle2 import parameters_vehicle2

    compiler = shutil.which("cc") or shutil.which("gcc")
    if compiler is None:
        return None
    sys.path.insert(0, str(EXAMPLE))
    import commonroad_st_plant as model

    p = parameters_vehicle2()
    values = {
        "P_A": p.a, "P_B": p.b, "P_H_S": p.h_s, "P_M": p.m, "P_I_Z": p.I_z, "P_MU": p.tire.p_dy1,
        "P_C_S": -p.tire.p_ky1 / p.tire.p_dy1, "STEER_MIN": p.steering.min, "STEER_MAX": p.steering.max,
        "STEER_V_MIN": p.steering.v_min, "STEER_V_MAX": p.steering.v_max, "LONG_V_MIN": p.longitudinal.v_min,
        "LONG_V_MAX": p.longitudinal.v_max, "V_SWITCH": p.longitudinal.v_switch, "A_MAX": p.longitudinal.a_max,
        "STEERING_TIME_CONSTANT_S": model.STEERING_TIME_CONSTANT_S, "STEP_S": model.STEP_S,
    }  # fmt: skip
    build = folder / "c_build"
    (build / "binaries" / fmpy.platform).mkdir(parents=True, exist_ok=True)
    (build / "params.h").write_text("".join(f"#define {k} ({float(v)!r})\n" for k, v in values.items()))
    library = build / "binaries" / fmpy.platform / f"{C_IDENTIFIER}.so"
    headers = Path(fmpy.__file__).parent / "c-code"
    flags = ["-O2", "-shared", "-fPIC", "-I", str(headers), "-I", str(build)]
    subprocess.run([compiler, *flags, str(C_SOURCE), "-o", str(library), "-lm"], check=True, capture_output=True)
    rows = []
    for name, causality, start in C_VARIABLES:
        variability = ' variability="fixed"' if causality == "parameter" else ""
        real = f'<Real start="{start!r}"/>' if start is not None else "<Real/>"
        attributes = f'name="{name}" valueReference="{len(rows)}" causality="{causality}"{variability}'
        rows.append(f"    <ScalarVariable {attributes}>{real}</ScalarVariable>")
    outputs = "".join(f'<Unknown index="{i + 1}"/>' for i, v in enumerate(C_VARIABLES) if v[1] == "output")
    (build / "modelDescription.xml").write_text(
        f'<?xml version="1.0" encoding="UTF-8"?>\n<fmiModelDescription fmiVersion="2.0" modelName="{C_IDENTIFIER}" '
        f'guid="{C_GUID}">\n  <CoSimulation modelIdentifier="{C_IDENTIFIER}" '
        'canHandleVariableCommunicationStepSize="true"/>\n  <ModelVariables>\n'
        + "\n".join(rows)
        + "\n  </ModelVariables>\n"
        f"  <ModelStructure><Outputs>{outputs}</Outputs></ModelStructure>\n</fmiModelDescription>\n"
    )
    fmu = folder / "commonroad_st_c.fmu"
    with zipfile.ZipFile(fmu, "w") as archive:
        archive.write(build / "modelDescription.xml", "modelDescription.xml")
        archive.write(library, f"binaries/{fmpy.platform}/{library.name}")
    return fmu


def _truck_fmu_vehicle_file(folder: Path) -> Path:
    """Build the truck FMU (TRUCK_SLAVE) and its vehicle file: the preset's geometry, single track and limits."""
    from pythonfmu import FmuBuilder

    from workbench.vehicles import make_vehicle

    slave = folder / "workbench_truck_fmi2.py"
    slave.write_text(TRUCK_SLAVE, encoding="utf-8")
    fmu = FmuBuilder.build_FMU(slave, dest=folder)
    truck = make_vehicle("tractor-semitrailer")
    g, st, p = truck.geometry, truck.single_track(), truck.params
    track = st.single_track
    fields: dict[str, object] = {
        "fmu_file": str(fmu),
        "communication_step_s": 0.001,
        "wheelbase_m": g.wheelbase_m,
        "steering_ratio": g.steering_ratio,
        "max_road_wheel_angle_rad": g.max_road_wheel_angle_rad,
        "max_road_wheel_rate_rad_s": g.max_steer_wheel_rate_rad_s / g.steering_ratio,
        "width_m": g.width_m,
        "max_accel_mps2": p.max_accel_mps2,
        "max_decel_mps2": p.max_decel_mps2,
        "steering_time_constant_s": st.steering_time_constant_s,
        "mass_kg": track.mass_kg,
        "yaw_inertia_kgm2": track.yaw_inertia_kgm2,
        "cg_to_front_axle_m": track.cg_to_front_axle_m,
        "front_cornering_stiffness_n_per_rad": track.front_cornering_stiffness_n_per_rad,
        "rear_cornering_stiffness_n_per_rad": track.rear_cornering_stiffness_n_per_rad,
        "front_peak_force_n": track.front_peak_force_n,
        "rear_peak_force_n": track.rear_peak_force_n,
        "lag_file": None,
        "rollover_threshold_g": truck.derived.rollover_threshold_g,
        "hitch_to_trailer_axle_m": p.hitch_to_trailer_axle_m,
        "steering_input": "delta_cmd",
        "steering_input_is": "road_wheel_angle",
        "steering_input_scale": 1.0,
        "longitudinal_input_is": "acceleration",
        "accel_input": "accel_cmd",
        "accel_input_scale": 1.0,
        "throttle_input": None,
        "throttle_input_scale": 1.0,
        "brake_input": None,
        "brake_input_scale": 1.0,
    }
    outputs = {
        "x": "x_m",
        "y": "y_m",
        "yaw": "yaw_rad",
        "vx": "vx_mps",
        "vy": "vy_mps",
        "yaw_rate": "yaw_rate_rad_s",
        "steering": "road_wheel_angle_rad",
        "lat_accel": "lat_accel_mps2",
        "ltr": "ltr",
        "trailer_x": "trailer_x_m",
        "trailer_y": "trailer_y_m",
        "articulation": "articulation_rad",
    }
    for key, variable in outputs.items():
        fields[f"{key}_output"] = variable
        if key == "steering":
            fields["steering_output_is"] = "road_wheel_angle"
        fields[f"{key}_output_scale"] = 1.0
    fields.update(
        speed_parameter="v0", payload_parameter=None, payload_kg=None, friction_parameter=None, road_friction=None
    )
    return _vehicle_file(folder, "workbench_truck", fields)


def truck_dlc_entries(folder: Path) -> tuple[list[Entry], dict[str, float]]:
    """The truck's dlc on the native truck and through its FMU (module docstring): entries and the comparison."""
    from controllers import CONTROLLERS
    from tuning.own_tuning import tuned_controller, tuning_for
    from workbench.apps.controller_config import build_config
    from workbench.simulation.scenarios import ScenarioOptions, make_scenario
    from workbench.simulation.simulator import Simulation, SimulationConfig
    from workbench.vehicles import load_vehicle, make_vehicle

    native = make_vehicle("tractor-semitrailer")
    through_fmu = load_vehicle(str(_truck_fmu_vehicle_file(folder)))
    config = dataclasses.replace(build_config(CONTROLLERS["clothoid"].config_type, {}, ()), tuning=tuning_for(native))
    results, entries = {}, []
    for label, vehicle in (("native", native), ("FMU", through_fmu)):
        scenario = make_scenario("dlc", ScenarioOptions(vehicle.geometry.width_m))
        controller = tuned_controller("clothoid", vehicle, config)
        sim = Simulation(scenario, vehicle, controller, SimulationConfig(speed_kmh=TRUCK_SPEED_KMH))
        sim.run()  # compiled kernels and caches warmed
        start = time.perf_counter()
        result = sim.run()
        wall = time.perf_counter() - start
        results[label] = result
        simulated = float(result.trace["t_s"][-1])
        entries.append(
            Entry(
                f"truck dlc {TRUCK_SPEED_KMH:g} km/h, clothoid, {label} plant: whole run",
                wall_s=wall,
                note=f"{result.status.value}; {simulated:.1f} s simulated, real-time factor {simulated / wall:.0f}; "
                f"max |CTE| {result.metrics.max_abs_cte_m:.4f} m",
            )
        )
    a, b = results["native"].trace, results["FMU"].trace
    n = min(a["t_s"].size, b["t_s"].size)
    comparison = {
        name: float(np.max(np.abs(a[name][:n] - b[name][:n])))
        for name in ("x_m", "y_m", "cte_m", "steer_wheel_rad", "ltr", "articulation_rad")
    }
    comparison["rows_native"], comparison["rows_fmu"] = a["t_s"].size, b["t_s"].size
    return entries, comparison


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path(__file__).parent / "results" / "fmu_plant.json")
    parser.add_argument("--calls", type=int, default=3000, help="timed calls of each step (default 3000)")
    parser.add_argument("--check", action="store_true", help="exit 1 when a goal is missed")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        entries = plant_step_entries(Path(tmp), args.calls)
        truck_entries, comparison = truck_dlc_entries(Path(tmp))
    entries += truck_entries
    print(f"{'what':<74} {'median us':>10} {'p99 us':>9} {'FMI us':>8} {'wall s':>7}  goal")
    for e in entries:
        def f(v: float | None, spec: str) -> str:
            return format(v, spec) if v is not None else "-"

        goal = "" if e.goal is None else f"{e.goal}: {'met' if e.goal_met else 'MISSED'}"
        note = f" [{e.note}]" if e.note else ""
        times = f"{f(e.median_us, '10.1f')} {f(e.p99_us, '9.1f')} {f(e.overhead_us, '8.1f')} {f(e.wall_s, '7.3f')}"
        print(f"{e.name:<74} {times}  {goal}{note}")
    differences = ", ".join(f"{k} {v:.3g}" for k, v in comparison.items())
    print(f"truck dlc, FMU against native, largest difference: {differences}")
    document = {
        "machine": machine(),
        "created_unix_s": time.time(),
        "entries": [asdict(e) for e in entries],
        "truck_dlc_fmu_vs_native_max_difference": comparison,
    }
    write_results(args.out, document)
    return exit_code(entries, args.check)


if __name__ == "__main__":
    sys.exit(main())
