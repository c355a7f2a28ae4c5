"""The MPCs' shared parts, one concept a module: the options (`config`), the controller period assumed before a
run gives its own (`DEFAULT_PERIOD_S`, the solver's budget until then), and constructors typed by the config."""

from __future__ import annotations

import pytest

from controllers.mpc import LMPCConfig, LMPCController, MPCConfig, MPCController, NMPCConfig, NMPCController
from controllers.mpc.config import DEFAULT_PERIOD_S
from controllers.mpc.controller import MPCConfigT
from workbench.base.clothoid_chain import ClothoidChain
from workbench.vehicles import make_vehicle

VARIANTS = [(NMPCController, NMPCConfig), (LMPCController, LMPCConfig)]


@pytest.mark.parametrize(("cls", "config_type"), VARIANTS)
def test_the_solve_budget_is_the_default_period_until_a_run_gives_its_own(cls, config_type) -> None:
    vehicle = make_vehicle("dynamic-bicycle")
    controller = cls(vehicle.geometry, config_type(codegen=False), vehicle=vehicle)
    assert DEFAULT_PERIOD_S == pytest.approx(1.0 / 50.0, abs=1e-15)  # the simulator's default rate, 50 Hz
    assert controller.solver.qp.settings.time_limit_s == DEFAULT_PERIOD_S
    controller.reset(ClothoidChain().straight(60.0).to_path("straight"), 0.05)
    assert controller._solve_budget_s() == 0.05
    budgeted = cls(vehicle.geometry, config_type(codegen=False, max_solve_time_s=0.3), vehicle=vehicle)
    assert budgeted.solver.qp.settings.time_limit_s == 0.3


@pytest.mark.parametrize(("cls", "config_type"), VARIANTS)
def test_the_constructors_are_typed_by_the_config(cls, config_type) -> None:
    assert "__init__" not in vars(cls)  # the shared constructor, no pass-through of its own
    assert MPCConfigT.__bound__ is MPCConfig
    assert MPCController.__init__.__annotations__["config"] == "MPCConfigT | None"
    assert cls.__orig_bases__ == (MPCController[config_type],)  # its config is the one it is built with
    assert cls.config_type is config_type
