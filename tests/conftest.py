"""Fixtures shared across the test folders: the example plant FMUs (examples/fmu_plant/), built once per session."""

from __future__ import annotations

from pathlib import Path

import pytest
from fmu_plant_files import fmu_example_builder, write_fmu_vehicle_file


@pytest.fixture(scope="session")
def example_plant_fmus(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """FMI version ("2", "3") -> the vehicle file of the example's CommonRoad single-track FMU of that version."""
    builder = fmu_example_builder()
    folder = tmp_path_factory.mktemp("fmu_plants")
    files = {}
    for version in ("2", "3"):
        fmu = builder.build(folder / f"commonroad_st_fmi{version}.fmu", version)
        files[version] = write_fmu_vehicle_file(fmu, folder / f"commonroad_st_fmi{version}.toml")
    return files
