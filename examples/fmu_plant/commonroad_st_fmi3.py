"""CommonRoad's single-track car (`commonroad_st_plant.py`) as an FMI 3.0 co-simulation FMU, with pythonfmu3: the
same variables as the FMI 2.0 one (`commonroad_st_fmi2.py`), plus FMI 3.0's independent variable `time`."""

from commonroad_st_plant import OUTPUT_NAMES
from plant_slave import PlantSlave
from pythonfmu3 import Float64, Fmi3Causality, Fmi3Slave, Fmi3Variability


class CommonRoadST(PlantSlave, Fmi3Slave):
    author = "lateral-workbench example"
    description = "CommonRoad single-track car (vehiclemodels.vehicle_dynamics_st) with a steering actuator"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self._init_plant()
        self.time = 0.0
        independent = Float64("time", causality=Fmi3Causality.independent, variability=Fmi3Variability.continuous)
        self.register_variable(independent)
        self.register_variable(Float64("delta_cmd", causality=Fmi3Causality.input))
        self.register_variable(Float64("accel_cmd", causality=Fmi3Causality.input))
        self.register_variable(Float64("v0", causality=Fmi3Causality.parameter, variability=Fmi3Variability.fixed))
        for name in OUTPUT_NAMES:
            self.register_variable(Float64(name, causality=Fmi3Causality.output))

    def do_step(self, current_time, step_size):
        self._advance(step_size)
        self.time = current_time + step_size
        return True
