"""CommonRoad's single-track car (`commonroad_st_plant.py`) as an FMI 2.0 co-simulation FMU, with PythonFMU.

Inputs: `delta_cmd` (front road-wheel angle command, rad, positive left) and `accel_cmd` (m/s^2); parameter `v0`
(initial speed, m/s); outputs `commonroad_st_plant.OUTPUT_NAMES` at the rear-axle centre (SI units, x east, y north,
yaw counter-clockwise). Each `doStep` integrates its communication step with the inputs held.
"""

from commonroad_st_plant import OUTPUT_NAMES
from plant_slave import PlantSlave
from pythonfmu import Fmi2Causality, Fmi2Slave, Fmi2Variability, Real


class CommonRoadST(PlantSlave, Fmi2Slave):
    author = "lateral-workbench example"
    description = "CommonRoad single-track car (vehiclemodels.vehicle_dynamics_st) with a steering actuator"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self._init_plant()
        self.register_variable(Real("delta_cmd", causality=Fmi2Causality.input))
        self.register_variable(Real("accel_cmd", causality=Fmi2Causality.input))
        self.register_variable(Real("v0", causality=Fmi2Causality.parameter, variability=Fmi2Variability.fixed))
        for name in OUTPUT_NAMES:
            self.register_variable(Real(name, causality=Fmi2Causality.output))

    def do_step(self, current_time, step_size):
        self._advance(step_size)
        return True
