"""Build the example plant FMU: CommonRoad's single-track car (package commonroad-vehicle-models, a dependency of
the workbench) as an FMI 2.0 (PythonFMU) or FMI 3.0 (pythonfmu3) co-simulation FMU.

    python examples/fmu_plant/build_fmu.py                 # writes examples/fmu_plant/commonroad_st.fmu (FMI 2.0)
    python examples/fmu_plant/build_fmu.py --fmi 3 --out DIR

The FMU runs its Python code in the Python that loads it: run the workbench with this package installed.
"""

from __future__ import annotations

import argparse
import shutil
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
#: FMI version -> the slave's source file.
SLAVES = {"2": HERE / "commonroad_st_fmi2.py", "3": HERE / "commonroad_st_fmi3.py"}
#: The plant model and the slaves' shared part, which every slave imports, packed into the FMU beside it.
MODEL_FILES = [HERE / "commonroad_st_plant.py", HERE / "plant_slave.py"]


def build(out: Path, fmi_version: str = "2", slave: Path | None = None) -> Path:
    """Build the FMU of `slave` (default: the example's slave for `fmi_version`; another slave may import the
    example's modules, which are packed beside it) to the file `out`; its path."""
    if fmi_version not in SLAVES:
        raise SystemExit(f"build_fmu: --fmi must be one of {', '.join(SLAVES)}; got {fmi_version!r}")
    if fmi_version == "2":
        from pythonfmu import FmuBuilder
    else:
        from pythonfmu3 import FmuBuilder
    out = Path(out).resolve()
    out.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        script = Path(slave or SLAVES[fmi_version])
        extras = MODEL_FILES + ([SLAVES[fmi_version]] if script != SLAVES[fmi_version] else [])
        built = FmuBuilder.build_FMU(script, dest=tmp, project_files=extras)
        shutil.move(str(built), out)
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--fmi", default="2", choices=sorted(SLAVES), help="FMI version (default 2)")
    parser.add_argument("--out", type=Path, default=HERE / "commonroad_st.fmu", help="the FMU file to write")
    args = parser.parse_args()
    print(build(args.out, args.fmi))


if __name__ == "__main__":
    main()
