"""A config takes its vehicle's own tuning where it is one that takes a tuning (`TunableConfig`), told by its type
and without importing the clothoid controller for another controller's config."""

from __future__ import annotations

import subprocess
import sys

from controllers.clothoid.controller import ClothoidConfig
from controllers.pure_pursuit import PurePursuitConfig
from tuning.own_tuning import TunableConfig, tuning_for, with_vehicle_tuning
from workbench.vehicles import make_vehicle

CAR = make_vehicle("dynamic-bicycle")


def test_a_clothoid_config_gets_the_vehicles_own_tuning_once() -> None:
    assert isinstance(ClothoidConfig(), TunableConfig) and not isinstance(PurePursuitConfig(), TunableConfig)
    tuned = with_vehicle_tuning(ClothoidConfig(prediction_time_s=0.3), CAR)
    assert tuned.tuning == tuning_for(CAR) and tuned.prediction_time_s == 0.3
    assert with_vehicle_tuning(tuned, make_vehicle("tractor-semitrailer")) is tuned  # its tuning is kept
    other = PurePursuitConfig()
    assert with_vehicle_tuning(other, CAR) is other


def test_another_controllers_config_does_not_import_the_clothoid_controller() -> None:
    code = (
        "import sys\n"
        "from controllers.pure_pursuit import PurePursuitConfig\n"
        "from tuning.own_tuning import with_vehicle_tuning\n"
        "from workbench.vehicles import make_vehicle\n"
        "config = PurePursuitConfig()\n"
        "assert with_vehicle_tuning(config, make_vehicle('dynamic-bicycle')) is config\n"
        "print('controllers.clothoid.controller' in sys.modules)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "False"
