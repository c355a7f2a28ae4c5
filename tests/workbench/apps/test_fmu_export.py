"""`workbench export-fmu` (workbench/apps/fmu_export.py, fmu_slave.py, controller_package.py): the clothoid
controller exported as an FMI 2.0 co-simulation FMU, driven by FMPy in closed loop with a shipped plant, gives the
in-process controller's commands and diagnostics within 1e-9; the FMU passes FMPy's validation; it samples at its
own period under a shorter communication step and refuses a longer one; bad inputs are refused cleanly.

The clothoid FMU is built once per session (`clothoid_fmu`); the closed loop is the example's
(examples/export_controller/run_exported.py), so the example is what is tested."""

from __future__ import annotations

import dataclasses
import importlib.util
import json
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest

from workbench.apps.cli import main

ROOT = Path(__file__).resolve().parents[3]
EXAMPLE = ROOT / "examples" / "export_controller" / "run_exported.py"
#: The reproduction the FMU must reach against the in-process controller (rad, and the diagnostics' units).
TOLERANCE = 1e-9
#: The path and plant of the closed loop: the shipped dynamic bicycle's double lane change at 30 km/h.
VEHICLE, PATH, SPEED_KMH = "dynamic-bicycle", "dlc", 30.0


def _example():
    """examples/export_controller/run_exported.py as a module (registered: its dataclass needs it)."""
    if "run_exported" not in sys.modules:
        spec = importlib.util.spec_from_file_location("run_exported", EXAMPLE)
        module = importlib.util.module_from_spec(spec)
        sys.modules["run_exported"] = module
        spec.loader.exec_module(module)
    return sys.modules["run_exported"]


@pytest.fixture(scope="session")
def clothoid_fmu(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The clothoid controller for the dynamic bicycle's dlc, exported by the example (`workbench export-fmu`)."""
    out = tmp_path_factory.mktemp("export_fmu") / "clothoid.fmu"
    return _example().export(out, VEHICLE, PATH, SPEED_KMH)


@pytest.fixture(scope="session")
def closed_loop(clothoid_fmu: Path):
    """The FMU steering the dynamic bicycle along the dlc through FMPy, the in-process controller beside it."""
    return _example().drive(clothoid_fmu, VEHICLE, PATH, SPEED_KMH)


def _slave(fmu: Path, name: str = "controller", logging: bool = False):
    """(the FMU instantiated and initialised by FMPy, its variables' value references by name); `logging`: FMPy
    prints the FMU's log messages."""
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave

    description = read_model_description(str(fmu))
    slave = FMU2Slave(
        guid=description.guid,
        unzipDirectory=extract(str(fmu)),
        modelIdentifier=description.coSimulation.modelIdentifier,
        instanceName=name,
    )
    slave.instantiate(loggingOn=logging)
    slave.setupExperiment(startTime=0.0)
    slave.enterInitializationMode()
    slave.exitInitializationMode()
    return slave, {v.name: v.valueReference for v in description.modelVariables}


def test_the_fmu_steers_the_plant_with_the_in_process_controllers_commands(closed_loop) -> None:
    run = closed_loop
    assert run.t_s.size > 900  # the whole lane change: about 23 s at 50 Hz
    assert np.max(np.abs(run.fmu_command_rad)) > np.radians(30.0)  # the lane change steers: not a vacuous match
    np.testing.assert_allclose(run.fmu_command_rad, run.in_process_command_rad, rtol=0.0, atol=TOLERANCE)
    np.testing.assert_allclose(run.fmu_diagnostics, run.in_process_diagnostics, rtol=0.0, atol=TOLERANCE)
    assert "lookahead_m" in run.diagnostic_names and "measurement_rejected" in run.diagnostic_names
    assert np.max(np.abs(run.cte_m)) < 0.2  # and the FMU's commands follow the path


def test_the_fmu_passes_fmpys_validation(clothoid_fmu: Path) -> None:
    from fmpy import read_model_description
    from fmpy.validation import validate_fmu

    assert validate_fmu(str(clothoid_fmu)) == []
    description = read_model_description(str(clothoid_fmu), validate=True)
    assert description.fmiVersion == "2.0" and description.coSimulation is not None
    assert description.modelExchange is None
    assert float(description.defaultExperiment.stepSize) == pytest.approx(0.02, rel=1e-12)  # the 50 Hz period
    inputs = [v.name for v in description.modelVariables if v.causality == "input"]
    assert inputs == ["t_s", "x_m", "y_m", "vx_mps", "vy_mps", "yaw_rad", "yaw_rate_rad_s", "steer_wheel_rad"]
    outputs = [v.name for v in description.modelVariables if v.causality == "output"]
    assert outputs[0] == "steer_wheel_cmd_rad" and "ctrl_lookahead_m" in outputs
    assert all(v.type == "Real" for v in description.modelVariables)


def test_the_fmu_packs_the_path_options_and_the_vehicles_own_tuning(clothoid_fmu: Path) -> None:
    from tuning.own_tuning import shipped_tuning_dir
    from workbench.vehicles import make_vehicle

    shipped = shipped_tuning_dir(make_vehicle(VEHICLE))
    assert shipped is not None
    with zipfile.ZipFile(clothoid_fmu) as fmu:
        names = set(fmu.namelist())
        manifest = json.loads(fmu.read("resources/controller/manifest.json"))
        options = fmu.read("resources/controller/controller.toml").decode()
        packed = {p.name: fmu.read(f"resources/controller/files/tuning_dir/{shipped.name}/{p.name}") for p in
                  shipped.iterdir() if p.is_file()}  # fmt: skip
    assert {"resources/controller/path.csv", "resources/controller/vehicle.toml"} <= names
    assert manifest["controller"] == "clothoid" and manifest["period_s"] == 0.02 and manifest["path_name"] == "dlc"
    assert f'tuning_dir = "files/tuning_dir/{shipped.name}"' in options
    assert packed and all(data == (shipped / name).read_bytes() for name, data in packed.items())


def test_a_shorter_communication_step_holds_the_command_between_the_controllers_samples(clothoid_fmu: Path) -> None:
    slave, refs = _slave(clothoid_fmu)
    step = 0.005  # a quarter of the 20 ms period
    commands = []
    try:
        slave.setReal([refs["vx_mps"], refs["y_m"]], [8.0, 0.3])  # off the path to the left: it steers right
        for k in range(16):
            slave.setReal([refs["t_s"], refs["x_m"]], [k * step, 8.0 * k * step])
            slave.doStep(currentCommunicationPoint=k * step, communicationStepSize=step)
            commands.append(slave.getReal([refs["steer_wheel_cmd_rad"]])[0])
    finally:
        slave.terminate()
        slave.freeInstance()
    changes = [k for k in range(1, 16) if commands[k] != commands[k - 1]]
    assert commands[0] < 0.0
    assert set(changes) <= {4, 8, 12} and len(changes) >= 2  # it steps at 0, 20, 40, 60 ms only


#: Drives one doStep longer than the controller's period in a fresh Python (argv: the FMU) and says how it ended.
_LONG_STEP_SCRIPT = """
import sys
from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Slave

fmu = sys.argv[1]
description = read_model_description(fmu)
slave = FMU2Slave(guid=description.guid, unzipDirectory=extract(fmu),
                  modelIdentifier=description.coSimulation.modelIdentifier, instanceName="too-long")
slave.instantiate(loggingOn=True)
slave.setupExperiment(startTime=0.0)
slave.enterInitializationMode()
slave.exitInitializationMode()
try:
    slave.doStep(currentCommunicationPoint=0.0, communicationStepSize=0.05)
    print("doStep: no error")
except FMICallException:
    print("doStep: FMICallException")
slave.freeInstance()
"""


def test_a_communication_step_longer_than_the_period_fails_the_step_saying_why(clothoid_fmu: Path) -> None:
    """In a fresh process: PythonFMU's binaries share the host's one interpreter, and a test worker that has already
    instantiated other PythonFMU FMUs (the plant tests') has been seen to crash (an illegal instruction) in this
    error path, which would take the worker down with it; the FMU's own behaviour is what is checked here."""
    import subprocess
    import sys

    done = subprocess.run(
        [sys.executable, "-c", _LONG_STEP_SCRIPT, str(clothoid_fmu)], capture_output=True, text=True, timeout=300
    )
    assert done.returncode == 0, done.stderr[-2000:]
    assert "doStep: FMICallException" in done.stdout
    assert "[ERROR] communication step 0.05 s is longer than the controller's period 0.02 s" in done.stdout


def test_a_waypoint_file_is_packed_as_the_path_run_plans(tmp_path: Path) -> None:
    from workbench.apps.controller_package import PATH_FILE, load_packed_controller
    from workbench.simulation.scenarios import make_scenario
    from workbench.simulation.simulator import SimulationConfig, plan_path_speed

    waypoints = tmp_path / "bend.csv"
    waypoints.write_text("x_m,y_m\n" + "".join(f"{x},{0.002 * x * x:.4f}\n" for x in range(0, 61, 5)))
    out = tmp_path / "pp.fmu"
    argv = ["export-fmu", "pure-pursuit", "--path", str(waypoints), "--speed", "20", "--out", str(out)]
    assert main([*argv, "--set", "lookahead_gain_s=0.7", "--controller-rate-hz", "25"]) == 0
    folder = tmp_path / "unpacked"
    with zipfile.ZipFile(out) as fmu:
        fmu.extractall(folder)
    packed = load_packed_controller(folder / "resources" / "controller")
    planned = plan_path_speed(make_scenario(str(waypoints)).path, SimulationConfig(speed_kmh=20.0))
    for name in ("x_m", "y_m", "heading_rad", "curvature_1pm", "speed_mps"):
        np.testing.assert_array_equal(getattr(packed.path, name), getattr(planned, name))
    assert packed.path.spacing_m == planned.spacing_m and packed.period_s == 1.0 / 25.0
    assert packed.controller.config.lookahead_gain_s == 0.7
    assert (folder / "resources" / "controller" / PATH_FILE).is_file()


@pytest.mark.parametrize(
    ("argv", "named"),
    [
        (["export-fmu", "stanly", "--path", "dlc", "--out", "{tmp}/c.fmu"], "stanly"),
        (["export-fmu", "clothoid", "--path", "dlc", "--out", "{tmp}/c.zip"], "c.zip"),
        (["export-fmu", "clothoid", "--path", "dlc", "--out", "{tmp}"], "is a folder"),
        (["export-fmu", "clothoid", "--path", "dlc", "--out", "{tmp}/no/c.fmu"], "does not exist"),
        (["export-fmu", "clothoid", "--path", "{tmp}/none.csv", "--out", "{tmp}/c.fmu"], "none.csv"),
        (["export-fmu", "clothoid", "--path", "moon", "--out", "{tmp}/c.fmu"], "moon"),
        (["export-fmu", "clothoid", "--path", "dlc", "--speed", "nan", "--out", "{tmp}/c.fmu"], "nan"),
        (["export-fmu", "clothoid", "--path", "dlc", "--controller-rate-hz", "0", "--out", "{tmp}/c.fmu"], "rate"),
        (["export-fmu", "clothoid", "--path", "dlc", "--vehicle", "hovercraft", "--out", "{tmp}/c.fmu"], "hovercraft"),
        (
            ["export-fmu", "clothoid", "--path", "dlc", "--set", "prediction_time=1", "--out", "{tmp}/c.fmu"],
            "prediction_time",
        ),
        (["export-fmu", "pure-pursuit", "--path", "dlc", "--payload-kg", "100", "--out", "{tmp}/c.fmu"], "payload"),
    ],
)
def test_bad_input_is_refused_with_one_line_naming_it(argv, named, tmp_path: Path, capsys) -> None:
    argv = [a.replace("{tmp}", str(tmp_path)) for a in argv]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("workbench: error: ") and "Traceback" not in err
    assert named in err.splitlines()[-1]
    assert not (tmp_path / "c.fmu").exists()


def test_an_existing_fmu_is_replaced_only_with_overwrite(tmp_path: Path, capsys) -> None:
    out = tmp_path / "c.fmu"
    out.write_bytes(b"an earlier file")
    argv = ["export-fmu", "stanley", "--path", "dlc", "--out", str(out)]
    assert main(argv) == 2
    assert "--overwrite" in capsys.readouterr().err and out.read_bytes() == b"an earlier file"
    assert main([*argv, "--overwrite"]) == 0
    assert zipfile.is_zipfile(out)
    assert not list(tmp_path.glob(".*partial*"))  # no leftover beside it


def test_a_controller_for_a_plant_fmu_packs_the_plant_fmu_its_vehicle_file_names(
    example_plant_fmus: dict[str, Path], tmp_path: Path
) -> None:
    from workbench.apps.controller_package import VEHICLE_FILE, load_packed_controller
    from workbench.vehicles import make_vehicle

    vehicle_file = example_plant_fmus["2"]
    out = tmp_path / "pp.fmu"
    assert (
        main(["export-fmu", "pure-pursuit", "--vehicle-file", str(vehicle_file), "--path", "dlc", "--out", str(out)])
        == 0
    )
    folder = tmp_path / "unpacked"
    with zipfile.ZipFile(out) as fmu:
        fmu.extractall(folder)
    package = folder / "resources" / "controller"
    text = (package / VEHICLE_FILE).read_text()
    plant = make_vehicle(vehicle_file=vehicle_file)
    packed_plant = package / "files" / "vehicle" / plant.params.fmu_file.name
    assert f'fmu_file = "files/vehicle/{packed_plant.name}"' in text
    assert packed_plant.read_bytes() == plant.params.fmu_file.read_bytes()
    packed = load_packed_controller(package)
    assert packed.controller.geometry == plant.geometry


def test_the_files_a_controller_config_names_are_packed_and_read_back(tmp_path: Path) -> None:
    from tuning.own_tuning import shipped_tuning_dir
    from workbench.apps.controller_config import read_controller_config
    from workbench.apps.controller_package import CONTROLLER_FILE, load_packed_controller
    from workbench.vehicles import make_vehicle

    vehicle = make_vehicle(VEHICLE)
    lead = tmp_path / "filters" / "my_lead.json"
    lead.parent.mkdir()
    lead.write_bytes((shipped_tuning_dir(vehicle) / "lead.json").read_bytes())
    config = tmp_path / "options.toml"
    config.write_text('[clothoid]\nfilter_file = "filters/my_lead.json"\nprediction_time_s = 0.25\n')
    out = tmp_path / "c.fmu"
    argv = ["export-fmu", "clothoid", "--vehicle", VEHICLE, "--controller-config", str(config), "--path", "dlc"]
    assert main([*argv, "--set", "lookahead_hysteresis_m=0.3", "--out", str(out)]) == 0
    folder = tmp_path / "unpacked"
    with zipfile.ZipFile(out) as fmu:
        fmu.extractall(folder)
    package = folder / "resources" / "controller"
    options = (package / CONTROLLER_FILE).read_text()
    assert 'filter_file = "files/filter_file/my_lead.json"' in options
    assert (package / "files" / "filter_file" / "my_lead.json").read_bytes() == lead.read_bytes()
    packed = load_packed_controller(package).controller.config
    given = read_controller_config(config, "clothoid", type(packed), ["lookahead_hysteresis_m=0.3"], vehicle.geometry)
    assert packed.lead_filter == given.lead_filter and packed.lead_filter is not None
    assert packed.prediction_time_s == 0.25 and packed.lookahead_hysteresis_m == 0.3
    assert packed.tuning is not None  # the vehicle's own tuning, packed beside the file given


@pytest.mark.parametrize(
    ("damage", "named"),
    [
        (
            lambda p: (p / "manifest.json").write_text(
                (p / "manifest.json").read_text().replace('"format": 1', '"format": 9')
            ),
            "format 9",
        ),
        (lambda p: (p / "manifest.json").write_text("{}"), "lacks format, controller"),
        (lambda p: (p / "manifest.json").unlink(), "manifest.json"),
        (lambda p: (p / "path.csv").write_text((p / "path.csv").read_text().replace("\n0,", "\nnan,", 1)), "finite"),
        (lambda p: (p / "path.csv").write_text("a,b\n1,2\n"), "columns a,b"),
        (
            lambda p: (p / "manifest.json").write_text(
                (p / "manifest.json").read_text().replace('"pure-pursuit"', '"stanly"')
            ),
            "stanly",
        ),
    ],
)
def test_a_damaged_package_is_refused_naming_what(damage, named, tmp_path: Path) -> None:
    from workbench.apps.controller_package import load_packed_controller
    from workbench.base.errors import WorkbenchInputError

    out = tmp_path / "pp.fmu"
    assert main(["export-fmu", "pure-pursuit", "--path", "dlc", "--out", str(out)]) == 0
    with zipfile.ZipFile(out) as fmu:
        fmu.extractall(tmp_path / "unpacked")
    package = tmp_path / "unpacked" / "resources" / "controller"
    load_packed_controller(package)  # whole, it builds
    damage(package)
    with pytest.raises(WorkbenchInputError, match=named):
        load_packed_controller(package)


def test_a_prediction_vehicle_named_by_its_preset_is_packed_as_that_presets_file(tmp_path: Path) -> None:
    from workbench.apps.controller_config import read_controller_config
    from workbench.apps.controller_package import CONTROLLER_FILE, load_packed_controller
    from workbench.vehicles import make_vehicle

    out = tmp_path / "lmpc.fmu"
    argv = ["export-fmu", "lmpc", "--vehicle", VEHICLE, "--set", f"vehicle_file={VEHICLE}", "--path", "dlc"]
    assert main([*argv, "--out", str(out)]) == 0
    with zipfile.ZipFile(out) as fmu:
        fmu.extractall(tmp_path / "unpacked")
    package = tmp_path / "unpacked" / "resources" / "controller"
    assert f'vehicle_file = "files/vehicle_file/{VEHICLE}.toml"' in (package / CONTROLLER_FILE).read_text()
    packed = load_packed_controller(package).controller.config
    given = read_controller_config(
        None, "lmpc", type(packed), [f"vehicle_file={VEHICLE}"], make_vehicle(VEHICLE).geometry
    )
    assert packed.prediction_vehicle is not None and given.prediction_vehicle is not None
    same_source = dataclasses.replace(packed.prediction_vehicle, source=given.prediction_vehicle.source)
    assert same_source == given.prediction_vehicle  # the same numbers, read from the packed file
