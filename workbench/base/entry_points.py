"""What installed packages register with the workbench: entry points of a group, read once, by name.

A package outside this repository adds a controller or a vehicle model by declaring an entry point in its
pyproject.toml (`[project.entry-points."lateral_workbench.controllers"]`, `..."lateral_workbench.vehicles"`); the
registries (`controllers.CONTROLLERS`, `workbench.vehicles.presets.MODEL_TYPES`) read them here.
"""

from __future__ import annotations

import sys
from importlib.metadata import entry_points


def installed_entry_points(group: str, taken: set[str]) -> dict[str, tuple[str, str, str]]:
    """name -> (module, attribute, package) of each entry point installed packages declare in `group`. One whose
    name is in `taken` (a built-in's) or another package's, or whose value is not "module:attribute", is left out
    with a warning on stderr saying which and why."""
    found: dict[str, tuple[str, str, str]] = {}
    for point in entry_points(group=group):
        package = point.dist.name if point.dist is not None else "an unknown package"
        module, _, attr = (part.strip() for part in point.value.partition(":"))
        if point.name in taken or point.name in found:
            why = f"the name {point.name!r} is taken"
        elif not module or not attr:
            why = f"its value {point.value!r} is not 'module:attribute'"
        else:
            found[point.name] = (module, attr, package)
            continue
        print(f"lateral-workbench: warning: {group} entry point of {package} left out: {why}", file=sys.stderr)
    return found
