"""Fixtures shared by the tuning tests: the truck and its lead-filter schedule at 30, 60 and 90 km/h (identified
once per session: a few seconds)."""

from __future__ import annotations

import pytest

from tuning.schedule import ScheduleResult, identify_schedule
from workbench.vehicles import make_vehicle
from workbench.vehicles.base import VehicleModel


@pytest.fixture(scope="session")
def truck() -> VehicleModel:
    return make_vehicle("tractor-semitrailer")


@pytest.fixture(scope="session")
def result(truck: VehicleModel) -> ScheduleResult:
    return identify_schedule(truck, [30.0, 60.0, 90.0])
