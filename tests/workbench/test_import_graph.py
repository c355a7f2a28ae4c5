"""The import graph (issue 17, items 1 and 8): the layers the folders show, imports only downward, no cycle, and
the light modules do not load the heavy libraries.

The layers, lowest first: the base (`workbench/base/`), the vehicles (`workbench/vehicles/`), the simulation
(`workbench/simulation/`), the controllers (`controllers/`), tuning (`tuning/`) and the applications
(`workbench/apps/`). Every import counts, wherever it stands (at module level, inside a function, under
`TYPE_CHECKING`): a lazy import is still a dependency, only a later one. An import of one of the module's own parent
packages is not an edge: Python runs a package's `__init__` before any module in it.
"""

from __future__ import annotations

import ast
import json
import math
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
PACKAGES = ("workbench", "controllers", "tuning")
#: The layers, lowest first: (name, module prefix).
LAYERS = (
    ("base", "workbench.base"),
    ("vehicles", "workbench.vehicles"),
    ("simulation", "workbench.simulation"),
    ("controllers", "controllers"),
    ("tuning", "tuning"),
    ("applications", "workbench.apps"),
)
#: Libraries that take most of a start-up: plotting, python-control, CasADi, OSQP, scipy.signal.
HEAVY = ("matplotlib", "casadi", "control", "osqp", "scipy.signal")


def _loaded_after_import(module: str, then: str = "") -> list[str]:
    """The heavy libraries loaded by importing `module` (and running `then`) in a fresh interpreter."""
    code = (
        f"import json, sys\nimport {module}\n{then}\n"
        f"print(json.dumps(sorted(m for m in {HEAVY!r} if m in sys.modules)))"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, check=True)
    return json.loads(done.stdout.strip().splitlines()[-1])


@pytest.mark.parametrize(
    "module", ["workbench.simulation.simulator", "workbench.base.path", "controllers", "workbench.apps.cli"]
)
def test_importing_a_light_module_loads_no_heavy_library(module: str) -> None:
    assert _loaded_after_import(module) == []


def test_the_controller_registry_imports_a_controller_only_when_it_is_looked_up() -> None:
    names = "assert list(controllers.CONTROLLERS) == "
    names += "['clothoid', 'pure-pursuit', 'stanley', 'nmpc', 'lmpc']\nassert 'nmpc' in controllers.CONTROLLERS"
    assert _loaded_after_import("controllers", names) == []
    assert _loaded_after_import("controllers", "controllers.CONTROLLERS['pure-pursuit']") == []
    assert "casadi" in _loaded_after_import("controllers", "controllers.CONTROLLERS['nmpc']")


def test_a_run_from_a_track_file_and_its_files_load_no_pandas(tmp_path: Path) -> None:
    """`workbench run` reads a track CSV, simulates and writes its trace and metrics without pandas (~0.3 s of its
    start-up, issue 19); pandas stays the trace's `to_pandas` and the studies' tool."""
    track = tmp_path / "oval.csv"
    angle = [2.0 * math.pi * k / 120 for k in range(120)]
    track.write_text(
        "# x_m,y_m,w_tr_right_m,w_tr_left_m\n"
        + "".join(f"{60.0 * math.cos(a)},{40.0 * math.sin(a)},4,4\n" for a in angle)
    )
    then = (
        "from controllers.pure_pursuit import PurePursuit\n"
        "from workbench.simulation.scenarios import ScenarioOptions, make_scenario\n"
        "from workbench.simulation.simulator import Simulation, SimulationConfig\n"
        "from workbench.vehicles import make_vehicle\n"
        "vehicle = make_vehicle('kinematic-bicycle')\n"
        f"scenario = make_scenario({str(track)!r}, ScenarioOptions(vehicle_width_m=vehicle.geometry.width_m))\n"
        "result = Simulation(scenario, vehicle, PurePursuit(vehicle.geometry), SimulationConfig()).run()\n"
        f"result.save({str(tmp_path / 'out')!r}, with_plots=False)\n"
        "assert result.completed, result.message\n"
        "print(json.dumps(['pandas'] if 'pandas' in sys.modules else []))"
    )
    code = f"import json, sys\n{then}"
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, check=False)
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout.strip().splitlines()[-1]) == []
    assert (tmp_path / "out" / "trace.parquet").stat().st_size > 0


def test_the_registry_and_the_exported_names_are_the_classes() -> None:
    import controllers

    for name, cls in controllers.CONTROLLERS.items():
        assert cls.name == name
        assert getattr(controllers, cls.__name__) is cls
        assert controllers.CONTROLLERS.get(name) is cls
    for name in controllers.__all__:
        assert getattr(controllers, name) is not None
    assert "nope" not in controllers.CONTROLLERS
    assert controllers.CONTROLLERS.get("nope") is None
    with pytest.raises(AttributeError):
        controllers.Nope  # noqa: B018


# ---------------------------------------------------------------------------------------------- the graph
def _modules() -> dict[str, Path]:
    """Every module of the project's packages: dotted name -> file."""
    out = {}
    for package in PACKAGES:
        for file in sorted((ROOT / package).rglob("*.py")):
            parts = list(file.relative_to(ROOT).with_suffix("").parts)
            if parts[-1] == "__init__":
                parts.pop()
            out[".".join(parts)] = file
    return out


def _imported_names(name: str, is_package: bool, node: ast.Import | ast.ImportFrom, modules: set[str]) -> list[str]:
    """The dotted names one import statement of module `name` loads."""
    if isinstance(node, ast.Import):
        return [alias.name for alias in node.names]
    base = node.module or ""
    if node.level:  # relative: from the package of this module
        package = name.split(".") if is_package else name.split(".")[:-1]
        package = package[: len(package) - (node.level - 1)]
        base = ".".join([*package, *([base] if base else [])])
    return [f"{base}.{a.name}" if f"{base}.{a.name}" in modules else base for a in node.names]


def _graph() -> dict[str, set[str]]:
    """module -> the project's modules it imports anywhere in its text (each parent package of a dotted import too,
    as Python imports those first; a module's own parent packages left out, see the module docstring)."""
    modules = _modules()
    graph: dict[str, set[str]] = {}
    for name, file in modules.items():
        targets: set[str] = set()
        for node in ast.walk(ast.parse(file.read_text(), str(file))):
            if not isinstance(node, ast.Import | ast.ImportFrom):
                continue
            for dotted in _imported_names(name, file.name == "__init__.py", node, set(modules)):
                parts = dotted.split(".")
                for i in range(1, len(parts) + 1):
                    target = ".".join(parts[:i])
                    if target in modules and target != name and not name.startswith(target + "."):
                        targets.add(target)
        graph[name] = targets
    return graph


def _cycles(graph: dict[str, set[str]]) -> set[tuple[str, ...]]:
    """The strongly connected components of more than one module (Tarjan), each as a sorted tuple."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: set[tuple[str, ...]] = set()

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                found.add(tuple(sorted(component)))

    sys.setrecursionlimit(max(sys.getrecursionlimit(), 10 * len(graph) + 100))
    for v in sorted(graph):
        if v not in index:
            visit(v)
    return found


def _layer(module: str) -> int | None:
    """The index of the module's layer in LAYERS (None for a top-level package's own __init__)."""
    for i, (_, prefix) in enumerate(LAYERS):
        if module == prefix or module.startswith(prefix + "."):
            return i
    return None


def test_the_graph_sees_the_imports() -> None:
    graph = _graph()
    assert {"workbench.simulation.simulator", "controllers", "tuning.cli"} <= graph.keys()
    assert "workbench.simulation.result" in graph["workbench.simulation.simulator"]
    assert "workbench.simulation.plots" in graph["workbench.simulation.result"]  # a lazy import counts
    assert "workbench.base.errors" in graph["controllers.base"]


def test_every_module_is_in_a_layer() -> None:
    outside = [m for m in _modules() if _layer(m) is None and m not in PACKAGES]
    assert outside == [], f"modules outside the layers' folders: {outside}"


def test_imports_run_only_downward() -> None:
    upward = sorted(
        f"{module} ({LAYERS[_layer(module)][0]}) imports {target} ({LAYERS[_layer(target)][0]})"
        for module, targets in _graph().items()
        if _layer(module) is not None
        for target in targets
        if _layer(target) is not None and _layer(target) > _layer(module)
    )
    assert upward == [], "imports that run up the layers:\n" + "\n".join(upward)


def test_no_import_cycle_among_the_modules() -> None:
    cycles = _cycles(_graph())
    assert cycles == set(), f"import cycles: {sorted(cycles)}"
