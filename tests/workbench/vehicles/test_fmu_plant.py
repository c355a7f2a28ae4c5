"""A plant from an FMU (`workbench/vehicles/fmu_plant.py`), tested on third-party pieces: FMUs built by PythonFMU
(FMI 2.0) and pythonfmu3 (FMI 3.0) around CommonRoad's own single-track car (examples/fmu_plant/, built once per
session by tests/conftest.py), against the same CommonRoad model stepped directly; the FMUs refused when the vehicle
file is read; a doStep that fails ending the run with its own status."""

from __future__ import annotations

import dataclasses
import math
import pickle
import re
import subprocess
import sys
import zipfile
from pathlib import Path
from typing import ClassVar

import numpy as np
import pytest
from fmu_plant_files import FMU_EXAMPLE, fmu_example_builder, write_fmu_vehicle_file

from controllers import PurePursuit
from workbench.apps.cli import main
from workbench.base.errors import WorkbenchInputError
from workbench.simulation.conditions import CONDITIONS
from workbench.simulation.result import Status
from workbench.simulation.scenarios import ScenarioOptions, make_scenario
from workbench.simulation.simulator import Simulation, SimulationConfig
from workbench.vehicles import VEHICLES, VehicleModel, load_vehicle, make_vehicle
from workbench.vehicles.fmu_plant import FmuPlant
from workbench.vehicles.presets import preset_text

sys.path.insert(0, str(FMU_EXAMPLE))
from commonroad_st_plant import CommonRoadSTPlant  # the example's model, stepped directly


class DirectCommonRoadST(VehicleModel):
    """The example FMU's model stepped in-process with no FMI between: CommonRoad's single track started directly
    at the pose asked for (its CG state in the world frame), the same actuator and RK4."""

    name: ClassVar[str] = "commonroad-st-direct"
    state_names: ClassVar[tuple[str, ...]] = ("x_cg_m", "y_cg_m", "delta_rad", "v_mps", "yaw_rad", "r", "beta")

    def __init__(self, like: FmuPlant) -> None:
        self.params, self._geometry = like.params, like.geometry
        self.plant = CommonRoadSTPlant()

    def initial_state(self, x_m: float, y_m: float, yaw_rad: float, speed_mps: float) -> np.ndarray:
        b = self.plant.p.b
        return np.array([x_m + b * math.cos(yaw_rad), y_m + b * math.sin(yaw_rad), 0.0, speed_mps, yaw_rad, 0, 0])

    def _load(self, state: np.ndarray, steer: float, accel: float) -> CommonRoadSTPlant:
        self.plant.x = state.tolist()
        self.plant.delta_cmd, self.plant.accel_cmd = self._inputs(steer, accel)
        return self.plant

    def advance(self, state, steer, accel, dt_s, substeps):
        plant = self._load(state, steer, accel)
        plant.step(dt_s)
        return np.array(plant.x)

    def outputs(self, state, steer, accel):
        out = self._load(state, steer, accel).outputs()
        return np.array([*out[:6], out[6] * self.params.steering_ratio, *out[6:]])


def _dlc_run(
    vehicle: VehicleModel, speed_kmh: float = 60.0, offset_m: float = 0.0, heading_error_rad: float = 0.0, **config
):
    scenario = make_scenario("dlc", ScenarioOptions(vehicle_width_m=vehicle.geometry.width_m))
    scenario = dataclasses.replace(scenario, initial_offset_m=offset_m, initial_heading_error_rad=heading_error_rad)
    controller = PurePursuit(vehicle.geometry)
    return Simulation(scenario, vehicle, controller, SimulationConfig(speed_kmh=speed_kmh, **config)).run()


#: Closed-loop agreement of the FMU plant with the model stepped directly (SI units: m, rad, m/s, m/s^2): the same
#: arithmetic, but the FMU integrates in its own frame (started at its origin) and the workbench turns and moves its
#: outputs onto the path's, so they differ by rounding: measured 1.2e-12 (x, 15 s dlc at 60 km/h); 1e-9 allows 800x.
AGREEMENT = 1e-9


@pytest.mark.parametrize("version", ["2", "3"])
def test_a_closed_loop_run_through_the_fmu_matches_commonroad_stepped_directly(example_plant_fmus, version) -> None:
    fmu_plant = load_vehicle(str(example_plant_fmus[version]))
    assert isinstance(fmu_plant, FmuPlant) and fmu_plant.interface.fmi_major == int(version)
    # Started 0.5 m aside and 0.1 rad off the path's heading: the FMU's frame is turned and moved onto the path's.
    through_fmu = _dlc_run(fmu_plant, offset_m=0.5, heading_error_rad=0.1)
    direct = _dlc_run(DirectCommonRoadST(fmu_plant), offset_m=0.5, heading_error_rad=0.1)
    assert through_fmu.status is Status.COMPLETED, through_fmu.message
    assert direct.status is Status.COMPLETED
    assert through_fmu.trace["t_s"].size == direct.trace["t_s"].size > 300
    for name in ("x_m", "y_m", "yaw_rad", "cte_m", "steer_wheel_rad", "vy_mps", "lat_accel_mps2"):
        np.testing.assert_allclose(through_fmu.trace[name], direct.trace[name], rtol=0.0, atol=AGREEMENT, err_msg=name)
    # The run did steer: a lane change of 3.5 m or so at 60 km/h.
    assert np.ptp(through_fmu.trace["y_m"]) > 3.0


FOREIGN_SLAVE = '''
import math

from commonroad_st_plant import CommonRoadSTPlant
from pythonfmu import Fmi2Causality, Fmi2Slave, Fmi2Variability, Real

OUTPUTS = ("x_rear", "y_right", "psi_cw", "v_kmh", "vy_right", "yaw_rate_cw", "sw_deg_out", "ay_right")


class ForeignST(Fmi2Slave):
    """The example car with another tool's conventions: y, yaw and every lateral quantity positive to the right,
    speeds in km/h, the steering-wheel angle in degrees (ratio 15), and a throttle and a brake (fractions of full
    travel: full throttle 3 m/s^2, full brake 8 m/s^2) instead of an acceleration."""

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.plant = CommonRoadSTPlant()
        self.sw_deg = self.throttle = self.brake = 0.0
        self.v0_kmh = 36.0
        for name in ("sw_deg", "throttle", "brake"):
            self.register_variable(Real(name, causality=Fmi2Causality.input))
        self.register_variable(Real("v0_kmh", causality=Fmi2Causality.parameter, variability=Fmi2Variability.fixed))
        for name in OUTPUTS:
            setattr(self, name, 0.0)
            self.register_variable(Real(name, causality=Fmi2Causality.output))

    def _publish(self):
        x, y, psi, vx, vy, r, delta, ay = self.plant.outputs()
        values = (x, -y, -psi, vx * 3.6, -vy, -r, -math.degrees(delta * 15.0), -ay)
        for name, value in zip(OUTPUTS, values):
            setattr(self, name, value)

    def exit_initialization_mode(self):
        self.plant.start(self.v0_kmh / 3.6)
        self._publish()

    def do_step(self, current_time, step_size):
        self.plant.delta_cmd = -math.radians(self.sw_deg) / 15.0
        self.plant.accel_cmd = 3.0 * self.throttle - 8.0 * self.brake
        self.plant.step(step_size)
        self._publish()
        return True
'''
#: The mapping of ForeignST's conventions onto the workbench's (its scales: FMU value = scale x workbench value).
FOREIGN_MAPPING = {
    "steering_input": '"sw_deg"',
    "steering_input_is": '"steering_wheel_angle"',
    "steering_input_scale": "-57.29577951308232",
    "longitudinal_input_is": '"throttle_brake"',
    "accel_input": '"none"',
    "throttle_input": '"throttle"',
    "brake_input": '"brake"',
    "y_output": '"y_right"',
    "y_output_scale": "-1.0",
    "yaw_output": '"psi_cw"',
    "yaw_output_scale": "-1.0",
    "vx_output": '"v_kmh"',
    "vx_output_scale": "3.6",
    "vy_output": '"vy_right"',
    "vy_output_scale": "-1.0",
    "yaw_rate_output": '"yaw_rate_cw"',
    "yaw_rate_output_scale": "-1.0",
    "steering_output": '"sw_deg_out"',
    "steering_output_is": '"steering_wheel_angle"',
    "steering_output_scale": "-57.29577951308232",
    "lat_accel_output": '"ay_right"',
    "lat_accel_output_scale": "-1.0",
    "speed_parameter": '"v0_kmh"',
}


def test_another_tools_units_and_signs_mapped_by_scales_give_the_same_run(example_plant_fmus, tmp_path) -> None:
    """Signs flipped, degrees, km/h, throttle and brake: mapped by the vehicle file's scales and kinds, the FMU is
    the same car, so the closed loop is the example's to rounding (the degree and km/h conversions)."""
    slave = tmp_path / "foreign_st.py"
    slave.write_text(FOREIGN_SLAVE, encoding="utf-8")
    fmu = fmu_example_builder().build(tmp_path / "foreign.fmu", "2", slave=slave)
    foreign = load_vehicle(str(write_fmu_vehicle_file(fmu, tmp_path / "foreign.toml", **FOREIGN_MAPPING)))
    plain = load_vehicle(str(example_plant_fmus["2"]))
    a = _dlc_run(foreign, offset_m=0.5, heading_error_rad=0.1)
    b = _dlc_run(plain, offset_m=0.5, heading_error_rad=0.1)
    assert a.status is b.status is Status.COMPLETED
    assert a.trace["t_s"].size == b.trace["t_s"].size
    for name in ("x_m", "y_m", "yaw_rad", "vx_mps", "steer_wheel_rad", "road_wheel_angle_rad", "lat_accel_mps2"):
        np.testing.assert_allclose(a.trace[name], b.trace[name], rtol=0.0, atol=AGREEMENT, err_msg=name)


def test_conditions_between_plant_and_controller_act_on_the_fmu_plant_as_on_the_model(example_plant_fmus) -> None:
    """The automotive conditions (sensor noise and latency, a steering dead time whose segments split a controller
    step into plant steps of whole milliseconds): through the FMU as with the model stepped directly."""
    fmu_plant = load_vehicle(str(example_plant_fmus["2"]))
    automotive = {"conditions": CONDITIONS["automotive"], "seed": 3}
    through_fmu = _dlc_run(fmu_plant, **automotive)
    direct = _dlc_run(DirectCommonRoadST(fmu_plant), **automotive)
    assert through_fmu.status is direct.status is Status.COMPLETED
    for name in ("x_m", "y_m", "steer_wheel_rad", "seen_y_m", "applied_steer_wheel_cmd_rad"):
        np.testing.assert_allclose(through_fmu.trace[name], direct.trace[name], rtol=0.0, atol=AGREEMENT, err_msg=name)
    assert np.max(np.abs(through_fmu.trace["seen_y_m"] - through_fmu.trace["y_m"])) > 1e-3  # the noise was there


def test_the_template_is_the_example_vehicle_file_and_the_cli_shows_it(capsys) -> None:
    assert preset_text("fmu") == (FMU_EXAMPLE / "commonroad_st.toml").read_text(encoding="utf-8")
    assert main(["vehicles", "--show", "fmu"]) in (0, None)
    assert 'type = "fmu"' in capsys.readouterr().out
    assert main(["vehicles"]) in (0, None)
    assert re.search(r"^fmu +your own model: `workbench vehicles --show fmu`", capsys.readouterr().out, re.M)
    assert "fmu" not in VEHICLES  # nothing shipped to run: only a user's file has an FMU
    for build in (make_vehicle, load_vehicle):
        with pytest.raises(WorkbenchInputError, match="'fmu' is your own model and needs its vehicle file"):
            build("fmu")


def test_the_example_script_builds_both_fmi_versions(tmp_path) -> None:
    """`python examples/fmu_plant/build_fmu.py [--fmi 3] --out FILE`, as the README runs it, in a fresh process."""
    for version in ("2", "3"):
        out = tmp_path / f"car{version}.fmu"
        done = subprocess.run(
            [sys.executable, str(FMU_EXAMPLE / "build_fmu.py"), "--fmi", version, "--out", str(out)],
            capture_output=True, text=True, check=False, timeout=120,
        )  # fmt: skip
        assert done.returncode == 0, done.stderr
        plant = load_vehicle(str(write_fmu_vehicle_file(out, tmp_path / f"car{version}.toml")))
        assert plant.interface.fmi_major == int(version)


def test_a_relative_fmu_path_is_relative_to_the_vehicle_file(example_plant_fmus, tmp_path) -> None:
    folder = tmp_path / "plants"
    folder.mkdir()
    fmu = Path(str(example_plant_fmus["2"]).replace(".toml", ".fmu"))
    (folder / "car.fmu").write_bytes(fmu.read_bytes())
    vehicle_file = write_fmu_vehicle_file(Path("car.fmu"), folder / "car.toml")
    assert make_vehicle(vehicle_file=vehicle_file).params.fmu_file == folder / "car.fmu"


def _rewritten(fmu: Path, out: Path, rewrite) -> Path:
    """A copy of `fmu` with its modelDescription.xml passed through `rewrite`."""
    with zipfile.ZipFile(fmu) as src, zipfile.ZipFile(out, "w") as dst:
        for item in src.infolist():
            data = src.read(item)
            if item.filename == "modelDescription.xml":
                data = rewrite(data.decode("utf-8")).encode("utf-8")
            dst.writestr(item, data)
    return out


def _as_real_to_integer(text: str, name: str) -> str:
    """FMI 2.0 description text with variable `name`'s type Real made Integer."""
    pattern = re.compile(rf'(<ScalarVariable\s+name="{name}".*?)<Real(\s*[^>]*)/>', re.S)
    return pattern.sub(lambda m: m.group(1) + "<Integer/>", text, count=1)


BAD_FMUS = {
    "not a zip": (lambda fmu, out: out.write_bytes(b"not a zip archive") and out, {}, "not an FMU"),
    "FMI 1.0": (
        lambda fmu, out: _rewritten(fmu, out, lambda t: t.replace('fmiVersion="2.0"', 'fmiVersion="1.0"')),
        {},
        "FMI version '1.0'; the workbench steps FMI 2.0 and 3.0",
    ),
    "model exchange only": (
        lambda fmu, out: _rewritten(fmu, out, lambda t: t.replace("<CoSimulation", "<ModelExchange")),
        {},
        "co-simulation is needed",
    ),
    "missing variable": (lambda fmu, out: fmu, {"lat_accel_output": '"ay"'}, "has no variable 'ay'"),
    "wrong causality": (
        lambda fmu, out: fmu,
        {"steering_input": '"delta"'},
        "variable 'delta' has causality 'output'; mapped as it is, it must be input",
    ),
    "wrong type": (
        lambda fmu, out: _rewritten(fmu, out, lambda t: _as_real_to_integer(t, "psi")),
        {},
        "variable 'psi' is of type 'Integer'",
    ),
    "fixed friction parameter": (
        lambda fmu, out: fmu,
        {"friction_parameter": '"v0"', "road_friction": "1.0"},
        "parameter 'v0' is 'fixed'",
    ),
}


@pytest.mark.parametrize("case", sorted(BAD_FMUS))
def test_a_bad_fmu_is_refused_when_the_vehicle_file_is_read(example_plant_fmus, tmp_path, case) -> None:
    make_bad, changes, needle = BAD_FMUS[case]
    good = Path(str(example_plant_fmus["2"]).replace(".toml", ".fmu"))
    bad = make_bad(good, tmp_path / "bad.fmu")
    vehicle_file = write_fmu_vehicle_file(bad, tmp_path / "bad.toml", **changes)
    with pytest.raises(WorkbenchInputError, match=re.escape(needle)) as info:
        load_vehicle(str(vehicle_file))
    assert str(vehicle_file) in str(info.value)


def test_the_cli_refuses_a_bad_fmu_in_one_line(example_plant_fmus, tmp_path, capsys) -> None:
    vehicle_file = write_fmu_vehicle_file(tmp_path / "none.fmu", tmp_path / "x.toml")
    (tmp_path / "none.fmu").write_text("plain text")
    out = str(tmp_path / "out")
    code = main(["run", "dlc", "--controller", "pure-pursuit", "--vehicle-file", str(vehicle_file), "--out", out])
    err = capsys.readouterr().err
    assert code == 2
    assert "not an FMU" in err and "Traceback" not in err


FAILING_SLAVE = '''
from commonroad_st_fmi2 import CommonRoadST


class FailingST(CommonRoadST):
    """The example car, whose doStep fails from t = 1 s."""

    def do_step(self, current_time, step_size):
        if current_time >= 1.0 - 1e-9:
            self.log("the tyre model lost its footing")
            return False
        return super().do_step(current_time, step_size)
'''


def test_a_failing_do_step_ends_the_run_with_a_status_that_says_so(tmp_path) -> None:
    slave = tmp_path / "failing_st.py"
    slave.write_text(FAILING_SLAVE, encoding="utf-8")
    fmu = fmu_example_builder().build(tmp_path / "failing.fmu", "2", slave=slave)
    vehicle = load_vehicle(str(write_fmu_vehicle_file(fmu, tmp_path / "failing.toml")))
    result = _dlc_run(vehicle)
    assert result.status is Status.PLANT_FAILED
    assert "the plant FMU failed its step at t = 1.000 s" in result.message
    assert result.trace["t_s"][-1] == pytest.approx(1.0, abs=1e-9)  # the trace up to the step that failed is kept
    assert np.all(np.isfinite(result.trace["x_m"]))


def test_the_plant_continues_only_from_its_own_state(example_plant_fmus) -> None:
    plant = load_vehicle(str(example_plant_fmus["2"]))
    state = plant.initial_state(0.0, 0.0, 0.0, 10.0)
    moved = plant.advance(state, 0.0, 0.0, 0.02, 20)
    with pytest.raises(WorkbenchInputError, match="continues only from the state it last returned"):
        plant.advance(state, 0.0, 0.0, 0.02, 20)
    assert moved[-1] == pytest.approx(0.02)  # the FMU's time


def test_a_period_that_is_not_a_multiple_of_the_step_ends_with_a_shorter_step(example_plant_fmus) -> None:
    plant = load_vehicle(str(example_plant_fmus["2"]))
    state = plant.advance(plant.initial_state(0.0, 0.0, 0.0, 10.0), 0.0, 0.0, 0.0125, 12)
    assert state[-1] == pytest.approx(0.0125, abs=1e-12)
    assert state[0] == pytest.approx(0.125, abs=1e-9)  # 10 m/s straight for 12.5 ms


def test_a_pickled_plant_opens_its_fmu_again(example_plant_fmus) -> None:
    plant = load_vehicle(str(example_plant_fmus["3"]))
    copy = pickle.loads(pickle.dumps(plant))
    assert copy.params == plant.params and copy.interface == plant.interface
    a = plant.advance(plant.initial_state(1.0, 2.0, 0.3, 8.0), 0.5, 1.0, 0.02, 20)
    b = copy.advance(copy.initial_state(1.0, 2.0, 0.3, 8.0), 0.5, 1.0, 0.02, 20)
    np.testing.assert_array_equal(a, b)


def test_road_friction_needs_a_friction_parameter(example_plant_fmus) -> None:
    plant = load_vehicle(str(example_plant_fmus["2"]))
    plant.set_road_friction(1.0)
    with pytest.raises(WorkbenchInputError, match=re.escape("road_friction 0.5 needs a friction parameter")):
        plant.set_road_friction(0.5)


PARAMETER_SLAVE = '''
from commonroad_st_fmi2 import CommonRoadST
from pythonfmu import Fmi2Causality, Fmi2Variability, Real


class ParameterST(CommonRoadST):
    """The example car with a tunable friction parameter `mu` and a fixed payload parameter `load`, which its outputs
    `mu_seen` and `load_seen` report after each step."""

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.mu, self.load = 1.0, 0.0
        self.mu_seen = self.load_seen = 0.0
        self.register_variable(Real("mu", causality=Fmi2Causality.parameter, variability=Fmi2Variability.tunable))
        self.register_variable(Real("load", causality=Fmi2Causality.parameter, variability=Fmi2Variability.fixed))
        self.register_variable(Real("mu_seen", causality=Fmi2Causality.output))
        self.register_variable(Real("load_seen", causality=Fmi2Causality.output))

    def do_step(self, current_time, step_size):
        self.mu_seen, self.load_seen = self.mu, self.load
        return super().do_step(current_time, step_size)
'''


@pytest.fixture(scope="module")
def parameter_plant_file(tmp_path_factory) -> Path:
    """A vehicle file of ParameterST mapping its friction (road_friction 0.9) and payload (500 kg) parameters."""
    folder = tmp_path_factory.mktemp("parameter_st")
    slave = folder / "parameter_st.py"
    slave.write_text(PARAMETER_SLAVE, encoding="utf-8")
    fmu = fmu_example_builder().build(folder / "parameter.fmu", "2", slave=slave)
    changes = {
        "friction_parameter": '"mu"',
        "road_friction": "0.9",
        "payload_parameter": '"load"',
        "payload_kg": "500.0",
    }
    return write_fmu_vehicle_file(fmu, folder / "parameter.toml", **changes)


def _seen(plant: FmuPlant, name: str) -> float:
    """The value of the FMU's output `name` after the last step."""
    import fmpy

    variables = fmpy.read_model_description(str(plant.params.fmu_file)).modelVariables
    return plant._fmu.outputs([v.valueReference for v in variables if v.name == name])[0]


def test_road_friction_is_written_to_the_friction_parameter_between_steps(parameter_plant_file) -> None:
    plant = load_vehicle(str(parameter_plant_file))
    state = plant.initial_state(0.0, 0.0, 0.0, 10.0)
    state = plant.advance(state, 0.0, 0.0, 0.02, 20)
    assert _seen(plant, "mu_seen") == 0.9  # the vehicle file's road_friction, at scale 1
    plant.set_road_friction(0.5)
    plant.advance(state, 0.0, 0.0, 0.02, 20)
    assert _seen(plant, "mu_seen") == pytest.approx(0.45, rel=1e-15)
    plant.advance(plant.initial_state(0.0, 0.0, 0.0, 10.0), 0.0, 0.0, 0.02, 20)  # a new run: the scale in force
    assert _seen(plant, "mu_seen") == pytest.approx(0.45, rel=1e-15)


def test_the_payload_is_written_to_the_payload_parameter(parameter_plant_file) -> None:
    for payload_kg, expected in ((None, 500.0), (2000.0, 2000.0)):
        plant = load_vehicle(str(parameter_plant_file), payload_kg)
        plant.advance(plant.initial_state(0.0, 0.0, 0.0, 10.0), 0.0, 0.0, 0.02, 20)
        assert _seen(plant, "load_seen") == expected


#: Vehicle-file values refused before the FMU is opened (`FmuPlantParams`), each with the words of its message.
BAD_VALUES = {
    "communication step": (
        {"communication_step_s": "0.5"},
        "communication_step_s must be a finite number in [0.0001, 0.1] s; got 0.5",
    ),
    "half a single track": ({"mass_kg": '"none"'}, "the single track is given all together or not at all"),
    "steering kind": ({"steering_input_is": '"handlebar"'}, "steering_input_is must be one of road_wheel_angle"),
    "longitudinal kind": ({"longitudinal_input_is": '"pedal"'}, "longitudinal_input_is must be one of acceleration"),
    "no throttle": ({"longitudinal_input_is": '"throttle_brake"'}, "'throttle_brake' needs throttle_input"),
    "zero scale": ({"yaw_output_scale": "0.0"}, "yaw_output_scale must be a finite number other than 0; got 0.0"),
    "one trailer coordinate": ({"trailer_x_output": '"x_rear"'}, "trailer_x_output and trailer_y_output are given"),
    "payload without parameter": ({"payload_kg": "1000.0"}, "payload_parameter and payload_kg are given together"),
    "text for a number": ({"wheelbase_m": '"2.5"'}, "'wheelbase_m' must be a number"),
}


@pytest.mark.parametrize("case", sorted(BAD_VALUES))
def test_bad_vehicle_file_values_are_refused_naming_them(example_plant_fmus, tmp_path, case) -> None:
    changes, needle = BAD_VALUES[case]
    fmu = Path(str(example_plant_fmus["2"]).replace(".toml", ".fmu"))
    with pytest.raises(WorkbenchInputError, match=re.escape(needle)):
        load_vehicle(str(write_fmu_vehicle_file(fmu, tmp_path / "bad.toml", **changes)))


def test_a_payload_needs_a_payload_parameter(example_plant_fmus) -> None:
    with pytest.raises(WorkbenchInputError, match="payload_parameter and payload_kg are given together"):
        load_vehicle(str(example_plant_fmus["2"]), payload_kg=2000.0)


def test_the_feasibility_check_takes_the_rollover_threshold_of_the_vehicle_file(example_plant_fmus, tmp_path) -> None:
    from workbench.simulation.feasibility import VehicleLimits

    fmu = Path(str(example_plant_fmus["2"]).replace(".toml", ".fmu"))
    stated = load_vehicle(str(write_fmu_vehicle_file(fmu, tmp_path / "r.toml", rollover_threshold_g="0.35")))
    assert VehicleLimits.of(stated).rollover_threshold_g == 0.35
    assert VehicleLimits.of(load_vehicle(str(example_plant_fmus["2"]))).rollover_threshold_g is None


def test_an_identified_lag_file_is_what_the_mpcs_predict_with(example_plant_fmus, tmp_path) -> None:
    from workbench.vehicles.steering_lag import SteeringLag, write_lag_file

    lag = SteeringLag(omega_n_rad_s=7.29, zeta=0.753, source="tuning fit-lag")
    write_lag_file(lag, tmp_path / "lag.json")
    fmu = Path(str(example_plant_fmus["2"]).replace(".toml", ".fmu"))
    plant = load_vehicle(str(write_fmu_vehicle_file(fmu, tmp_path / "car.toml", lag_file='"lag.json"')))
    predicted = plant.single_track()
    assert predicted.lag.omega_n_rad_s == 7.29 and predicted.lag.zeta == 0.753
    assert predicted.default_kind() == "kinematic-lag"
    assert load_vehicle(str(example_plant_fmus["2"])).single_track().default_kind() == "dynamic"
