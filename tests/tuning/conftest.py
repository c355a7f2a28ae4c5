"""Fixtures shared by the tuning tests: the truck and its lead-filter schedule at 30, 60 and 90 km/h (identified
once per session: a few seconds), and a private tuning cache (`private_cache`)."""

from __future__ import annotations

from pathlib import Path

import pytest

from tuning.schedule import ScheduleResult, identify_schedule
from tuning.tuning_dirs import CACHE_ENV
from workbench.vehicles import make_vehicle
from workbench.vehicles.base import VehicleModel


@pytest.fixture(scope="session")
def truck() -> VehicleModel:
    return make_vehicle("tractor-semitrailer")


@pytest.fixture(scope="session")
def result(truck: VehicleModel) -> ScheduleResult:
    return identify_schedule(truck, [30.0, 60.0, 90.0])


@pytest.fixture
def private_cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A tuning cache of the test's own (not yet made), so that no test reads or writes the user's cache."""
    cache = tmp_path / "cache"
    monkeypatch.setenv(CACHE_ENV, str(cache))
    return cache
