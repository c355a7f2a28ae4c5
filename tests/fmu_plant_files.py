"""The example plant FMUs (examples/fmu_plant/) for the tests: building them and writing their vehicle files (the
session fixture `example_plant_fmus` in tests/conftest.py builds them once)."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

#: The example's folder: its build script, its slaves and its vehicle file.
FMU_EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "fmu_plant"


def fmu_example_builder():
    """examples/fmu_plant/build_fmu.py as a module (its folder on sys.path, where PythonFMU imports the slaves)."""
    if str(FMU_EXAMPLE) not in sys.path:
        sys.path.insert(0, str(FMU_EXAMPLE))
    spec = importlib.util.spec_from_file_location("build_fmu", FMU_EXAMPLE / "build_fmu.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def write_fmu_vehicle_file(fmu: Path, out: Path, **changes: str) -> Path:
    """The example's vehicle file with fmu_file set to `fmu` and each `key = value` line in `changes` replaced (the
    values as TOML text)."""
    lines = []
    changes = {"fmu_file": f'"{fmu}"', **changes}
    for line in (FMU_EXAMPLE / "commonroad_st.toml").read_text(encoding="utf-8").splitlines():
        key = line.split("=", 1)[0].strip()
        lines.append(f"{key} = {changes.pop(key)}" if key in changes and "=" in line else line)
    assert not changes, f"no such keys in the example's vehicle file: {changes}"
    out.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return out
