"""The benchmarks are scripts, not a package: their tests load each from its file."""

from __future__ import annotations

import importlib.util
import sys
from collections.abc import Iterator
from pathlib import Path
from types import ModuleType

import pytest

#: The benchmarks' folder (the repository's root is two levels up).
BENCHMARKS = Path(__file__).resolve().parents[2] / "benchmarks"
if str(BENCHMARKS) not in sys.path:  # the scripts import their shared module (benchmark_report) as when run
    sys.path.insert(0, str(BENCHMARKS))


def _script(file_name: str) -> Iterator[ModuleType]:
    """benchmarks/<file_name> loaded as the module benchmark_<its stem>, unloaded afterwards."""
    spec = importlib.util.spec_from_file_location(f"benchmark_{Path(file_name).stem}", BENCHMARKS / file_name)
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # dataclasses look their module up while being built
    spec.loader.exec_module(module)
    yield module
    del sys.modules[spec.name]


@pytest.fixture(scope="module")
def steering() -> Iterator[ModuleType]:
    yield from _script("steering.py")


@pytest.fixture(scope="module")
def breakdown() -> Iterator[ModuleType]:
    yield from _script("cte_breakdown.py")


@pytest.fixture(scope="module")
def fmu_plant() -> Iterator[ModuleType]:
    yield from _script("fmu_plant.py")
