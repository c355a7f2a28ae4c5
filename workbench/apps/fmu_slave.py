"""The FMI 2.0 co-simulation slave of an exported controller (`workbench export-fmu`): PythonFMU's `Fmi2Slave`
around a controller packed in the FMU's resources (`controller_package`).

The FMU's own script subclasses `ControllerSlave`; PythonFMU's binary starts a Python interpreter in the
importing tool, which imports that script and, through it, this module: the target needs a Python with this
package (and PythonFMU) installed.

Inputs are the fields of the `Measurement` a controller sees (SI units: time stamp, reference-point position,
velocity in the vehicle frame, yaw, yaw rate, measured steering-wheel angle); outputs are the steering-wheel
command (rad) and the controller's diagnostics, `ctrl_<name>` as in a run's trace. The controller samples its
inputs at its own period (the FMU's default step): at the first `doStep` that starts at or past (within half a
step) its next sample instant, it steps once and its outputs hold until the next; a communication step longer than
the period, or a controller that raises, fails the `doStep` with a logged message saying why.
"""

from __future__ import annotations

import ctypes
from pathlib import Path
from typing import Any

from pythonfmu import DefaultExperiment, Fmi2Causality, Fmi2Initial, Fmi2Slave, Fmi2Variability, Real
from pythonfmu.enums import Fmi2Status

from workbench.apps.controller_package import load_packed_controller
from workbench.simulation.control_interface import Measurement

#: The folder, inside the FMU's resources, that holds the packed controller.
PACKAGE_DIR = "controller"
#: The inputs, the `Measurement` fields in order, with what each is.
INPUTS = (
    ("t_s", "time stamp of the measurement (s)"),
    ("x_m", "x of the reference point (m; the tractor's rear-axle centre)"),
    ("y_m", "y of the reference point (m)"),
    ("vx_mps", "longitudinal velocity in the vehicle frame (m/s)"),
    ("vy_mps", "lateral velocity in the vehicle frame (m/s)"),
    ("yaw_rad", "yaw (rad, counter-clockwise from x)"),
    ("yaw_rate_rad_s", "yaw rate (rad/s)"),
    ("steer_wheel_rad", "measured steering-wheel angle (rad, positive left)"),
)
#: The steering command output.
COMMAND = "steer_wheel_cmd_rad"
#: A diagnostic's output name is this prefix and its name, as a run's trace columns.
DIAGNOSTIC_PREFIX = "ctrl_"
#: How much longer than the period a communication step may be (relative), for rounding in the master's time.
STEP_TOLERANCE = 1e-9


def keep_script_namespace(namespace: dict[str, Any]) -> None:
    """Add one reference to `namespace`, the FMU script module's globals, for the one PythonFMU's binary drops:
    the script calls this at its top level.

    PythonFMU's binary (0.7.0) runs the script module's code in the module's namespace each time it instantiates
    the FMU, then releases that namespace, which it only borrowed (`findClass` decrefs the `PyModule_GetDict`
    result): without a reference added back the namespace is freed, and a second instance in one process fails
    or the interpreter crashes later (https://github.com/NTNU-IHB/PythonFMU/issues/228). Each run of the script
    balances one release; a run without one (the first import, the builder's) keeps one small dict alive for good,
    which is harmless."""
    ctypes.pythonapi.Py_IncRef(ctypes.py_object(namespace))


class ControllerSlave(Fmi2Slave):
    """An exported controller: built from the package in the FMU's resources when instantiated (module
    docstring); subclassed by the FMU's own script, whose class name is the FMU's model identifier."""

    author = "lateral-workbench"

    def __init__(self, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        packed = load_packed_controller(Path(self.resources) / PACKAGE_DIR)
        self._controller, self._path, self._period_s = packed.controller, packed.path, packed.period_s
        self.description = packed.description
        self.default_experiment = DefaultExperiment(start_time=0.0, step_size=self._period_s)
        self._start_s = 0.0
        self._samples = 0
        for name, what in INPUTS:
            setattr(self, name, 0.0)
            self.register_variable(
                Real(name, causality=Fmi2Causality.input, variability=Fmi2Variability.continuous, description=what)
            )
        self.steer_wheel_cmd_rad = 0.0
        self.register_variable(
            Real(
                COMMAND,
                causality=Fmi2Causality.output,
                initial=Fmi2Initial.exact,
                variability=Fmi2Variability.discrete,
                description="steering-wheel angle command (rad, positive left), within the vehicle's lock",
            )
        )
        values = self._controller.diagnostic_values
        for i, name in enumerate(self._controller.diagnostic_names):
            self.register_variable(
                Real(
                    DIAGNOSTIC_PREFIX + name,
                    causality=Fmi2Causality.output,
                    initial=Fmi2Initial.exact,
                    variability=Fmi2Variability.discrete,
                    description=f"the controller's diagnostic {name}",
                    getter=lambda i=i: float(values[i]),
                )
            )

    def setup_experiment(self, start_time: float, stop_time: float | None, tolerance: float | None) -> None:
        """The first sample instant is the experiment's start."""
        self._start_s = float(start_time)

    def do_step(self, current_time: float, step_size: float) -> bool:
        """Step the controller when this communication step reaches its next sample instant (module docstring)."""
        if step_size > self._period_s * (1.0 + STEP_TOLERANCE):
            self.log(
                f"communication step {step_size:g} s is longer than the controller's period {self._period_s:g} s; "
                "step at the period or a fraction of it",
                Fmi2Status.error,
            )
            return False
        if current_time + 0.5 * step_size < self._start_s + self._samples * self._period_s:
            return True
        measurement = Measurement(*(float(getattr(self, name)) for name, _ in INPUTS))
        try:
            self.steer_wheel_cmd_rad = self._controller.step(measurement, self._path)
        except Exception as exc:  # the master is told, as a run's status tells it
            self.log(f"the controller raised {type(exc).__name__}: {exc}", Fmi2Status.error)
            return False
        self._samples += 1
        return True
