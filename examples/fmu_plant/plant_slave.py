"""What the example's FMI 2.0 and FMI 3.0 slaves (`commonroad_st_fmi2.py`, `commonroad_st_fmi3.py`) share: the
plant, its inputs and parameter as the slave's attributes, and the outputs published after each step. Each slave
registers the variables with its own FMI version's types."""

from commonroad_st_plant import OUTPUT_NAMES, CommonRoadSTPlant

#: The initial speed (m/s) the parameter `v0` holds until the importer sets it.
DEFAULT_V0_MPS = 10.0


class PlantSlave:
    """The slave's state and steps, mixed in before the FMI version's slave class."""

    def _init_plant(self):
        """The plant, at rest, its inputs at zero and every output at zero until initialisation ends."""
        self.plant = CommonRoadSTPlant()
        self.delta_cmd = 0.0
        self.accel_cmd = 0.0
        self.v0 = DEFAULT_V0_MPS
        for name in OUTPUT_NAMES:
            setattr(self, name, 0.0)

    def _publish(self):
        for name, value in zip(OUTPUT_NAMES, self.plant.outputs(), strict=True):
            setattr(self, name, value)

    def exit_initialization_mode(self):
        self.plant.start(self.v0)
        self._publish()

    def _advance(self, step_size):
        """Integrate one communication step with the inputs held, and publish the outputs."""
        self.plant.delta_cmd, self.plant.accel_cmd = self.delta_cmd, self.accel_cmd
        self.plant.step(step_size)
        self._publish()
