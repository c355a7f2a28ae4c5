"""A plant FMU checked against its mapping when the vehicle file is read: the one place that says whether an FMU
can be a workbench plant, before any run.

Refused, each with a WorkbenchInputError naming the file and what is wrong: a file that is not a zip archive or
has no readable modelDescription.xml; an FMI version other than 2.0 or 3.0; an FMU without co-simulation (a
model-exchange-only FMU needs a solver the workbench does not bring: co-simulation is needed); an FMU without a
binary for this platform; a mapped variable the FMU does not have, or has with another causality (inputs must be
inputs; outputs outputs or locals; start values parameters, the road friction a tunable one) or a type other than
a real (FMI 2.0 Real, FMI 3.0 Float64 or Float32). FMPy reads the description (`fmpy.read_model_description`).
"""

from __future__ import annotations

import zipfile
from dataclasses import dataclass
from pathlib import Path

from workbench.base.errors import WorkbenchInputError
from workbench.vehicles.fmu_plant_params import FmuPlantParams

#: FMI versions the workbench steps, as modelDescription.xml's fmiVersion starts.
FMI_VERSIONS: tuple[str, ...] = ("2.", "3.")
#: The variable types taken as reals: FMI 2.0's Real, FMI 3.0's Float64 and Float32.
REAL_TYPES: tuple[str, ...] = ("Real", "Float64", "Float32")
#: Causalities a mapped output may have (a local is readable as an output is).
OUTPUT_CAUSALITIES: tuple[str, ...] = ("output", "local")


@dataclass(frozen=True)
class FmuInterface:
    """What the workbench needs from a checked FMU: fmi_major (2 or 3), guid (FMI 2.0 guid or FMI 3.0
    instantiationToken), model_identifier (of its co-simulation interface), variable_step (whether it handles a
    variable communication step), value_references (variable name -> value reference, for the mapped ones), and
    description (modelDescription.xml's, for messages)."""

    path: Path
    fmi_major: int
    guid: str
    model_identifier: str
    variable_step: bool
    value_references: dict[str, int]
    description: str


def read_fmu_interface(params: FmuPlantParams) -> FmuInterface:
    """The checked interface of `params.fmu_file` under `params`' mapping (module docstring: what is refused)."""
    import fmpy

    path = Path(params.fmu_file)
    where = f"plant FMU {str(path)!r}"
    if not path.is_file():
        raise WorkbenchInputError(f"{where}: no such file (fmu_file names the .fmu; a relative path is relative to "
                                  "the vehicle file's folder)")
    if not zipfile.is_zipfile(path):
        raise WorkbenchInputError(f"{where}: not an FMU (an FMU is a zip archive holding modelDescription.xml)")
    version = _fmi_version(path, where)
    if not version.startswith(FMI_VERSIONS):
        raise WorkbenchInputError(f"{where}: FMI version {version!r}; the workbench steps FMI 2.0 and 3.0 FMUs")
    try:
        md = fmpy.read_model_description(str(path), validate=False)
    except Exception as exc:  # FMPy raises what its XML and zip readers raise: the file is not a usable FMU
        raise WorkbenchInputError(f"{where}: not a readable FMU ({type(exc).__name__}: {exc})") from None
    if md.coSimulation is None:
        kinds = [kind for kind, it in (("model exchange", md.modelExchange),) if it is not None]
        offered = f" (it offers {' and '.join(kinds)} only)" if kinds else ""
        raise WorkbenchInputError(
            f"{where}: no co-simulation interface{offered}; co-simulation is needed (the FMU brings its own solver); "
            "export the model as a co-simulation FMU"
        )
    platforms = fmpy.supported_platforms(str(path))
    if fmpy.platform not in platforms:
        raise WorkbenchInputError(
            f"{where}: no binary for this platform ({fmpy.platform}); it has: {', '.join(platforms) or 'none'}"
        )
    variables = {v.name: v for v in md.modelVariables}
    # (variable name, the causalities it may have, the variability it must have (None: any)); name None: not used
    checks: list[tuple[str | None, tuple[str, ...], str | None]]
    checks = [(name, ("input",), None) for name in params.input_names()]
    checks += [(getattr(params, field), OUTPUT_CAUSALITIES, None) for field in params.output_fields()]
    checks += [(name, ("parameter",), None) for name in (params.speed_parameter, params.payload_parameter)]
    checks.append((params.friction_parameter, ("parameter",), "tunable"))
    refs = {}
    for name, causalities, variability in checks:
        if name is None:
            continue
        variable = variables.get(name)
        if variable is None:
            raise WorkbenchInputError(
                f"{where} has no variable {name!r} (mapped in the vehicle file); its {' or '.join(causalities)} "
                f"variables: {', '.join(_names_with(variables, causalities)) or 'none'}"
            )
        if variable.causality not in causalities:
            raise WorkbenchInputError(
                f"{where}: variable {name!r} has causality {variable.causality!r}; mapped as it is, it must be "
                f"{' or '.join(causalities)}"
            )
        if variable.type not in REAL_TYPES:
            raise WorkbenchInputError(
                f"{where}: variable {name!r} is of type {variable.type!r}; a mapped variable must be a real "
                f"({', '.join(REAL_TYPES)})"
            )
        if variability is not None and variable.variability != variability:
            raise WorkbenchInputError(
                f"{where}: parameter {name!r} is {variable.variability!r}; the road friction changes during a run, "
                f"so it must be {variability!r}"
            )
        refs[name] = int(variable.valueReference)
    cs = md.coSimulation
    return FmuInterface(
        path=path,
        fmi_major=int(version[0]),
        guid=str(md.guid if version.startswith("2.") else md.instantiationToken),
        model_identifier=str(cs.modelIdentifier),
        variable_step=bool(cs.canHandleVariableCommunicationStepSize),
        value_references=refs,
        description=str(md.description or md.modelName),
    )


def _fmi_version(path: Path, where: str) -> str:
    """The fmiVersion attribute of the FMU's modelDescription.xml (read before FMPy, which reads each version's
    layout and fails on another's with messages that do not say so)."""
    from xml.etree import ElementTree

    try:
        with zipfile.ZipFile(path) as archive, archive.open("modelDescription.xml") as xml:
            for _, element in ElementTree.iterparse(xml, events=("start",)):
                return str(element.get("fmiVersion"))
    except (KeyError, OSError, zipfile.BadZipFile, ElementTree.ParseError) as exc:
        raise WorkbenchInputError(f"{where}: not a readable FMU (no readable modelDescription.xml: {exc})") from None
    raise WorkbenchInputError(f"{where}: not a readable FMU (an empty modelDescription.xml)")


def _names_with(variables: dict, causalities: tuple[str, ...]) -> list[str]:
    """The names of the variables with one of these causalities, at most 12 (a large FMU has thousands)."""
    names = [name for name, v in variables.items() if v.causality in causalities]
    return names[:12] + ([f"... ({len(names) - 12} more)"] if len(names) > 12 else [])
