"""The import graph (issue 17, items 1 and 8): the light modules do not load the heavy libraries, and the project's
modules import each other without a cycle at module level.

A module-level import is one the module runs when it is imported: not inside a function, and not under
`if TYPE_CHECKING:`. An import of one of the module's own parent packages is not an edge: Python runs a package's
`__init__` before any module in it, so a module may always import from its parents (the usual
`workbench.vehicles.base` from `workbench.vehicles`' models).
"""

from __future__ import annotations

import ast
import json
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
PACKAGES = ("workbench", "controllers", "tuning")
#: Libraries that take most of a start-up: plotting, python-control, CasADi, OSQP, scipy.signal.
HEAVY = ("matplotlib", "casadi", "control", "osqp", "scipy.signal")

# Module-level import cycles among the project's modules that exist today: none (issue 17 item 1 broke the one
# through plots, result and simulator). A new cycle fails the test; one that must stay for a while is listed here,
# as a sorted tuple of its modules, with the issue that will break it.
ALLOWED_MODULE_CYCLES: set[tuple[str, ...]] = set()

# Package-level imports (module level) today (issue 17 item 1): workbench and controllers import each other
# (controllers use workbench.errors, workbench.path and workbench.vehicles; workbench.comparison, .simulator and
# .studies use the controllers), and tuning imports both; neither imports tuning at module level. The set must not
# grow: an import of tuning from workbench or controllers, at module level, fails the test.
ALLOWED_PACKAGE_EDGES = {
    ("workbench", "controllers"),
    ("controllers", "workbench"),
    ("tuning", "workbench"),
    ("tuning", "controllers"),
}


def _loaded_after_import(module: str, then: str = "") -> list[str]:
    """The heavy libraries loaded by importing `module` (and running `then`) in a fresh interpreter."""
    code = (
        f"import json, sys\nimport {module}\n{then}\n"
        f"print(json.dumps(sorted(m for m in {HEAVY!r} if m in sys.modules)))"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, check=True)
    return json.loads(done.stdout.strip().splitlines()[-1])


@pytest.mark.parametrize("module", ["workbench.simulator", "workbench.path", "controllers", "workbench.cli"])
def test_importing_a_light_module_loads_no_heavy_library(module: str) -> None:
    assert _loaded_after_import(module) == []


def test_the_controller_registry_imports_a_controller_only_when_it_is_looked_up() -> None:
    names = "assert list(controllers.CONTROLLERS) == "
    names += "['clothoid', 'pure-pursuit', 'stanley', 'nmpc', 'lmpc']\nassert 'nmpc' in controllers.CONTROLLERS"
    assert _loaded_after_import("controllers", names) == []
    assert _loaded_after_import("controllers", "controllers.CONTROLLERS['pure-pursuit']") == []
    assert "casadi" in _loaded_after_import("controllers", "controllers.CONTROLLERS['nmpc']")


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


def _is_type_checking(test: ast.expr) -> bool:
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING"
    )


def _module_level_imports(statements: list[ast.stmt]) -> Iterator[ast.Import | ast.ImportFrom]:
    """The imports a module runs when it is imported (not in functions or classes, not under TYPE_CHECKING)."""
    for node in statements:
        if isinstance(node, ast.Import | ast.ImportFrom):
            yield node
        elif isinstance(node, ast.If):
            if not _is_type_checking(node.test):
                yield from _module_level_imports(node.body)
            yield from _module_level_imports(node.orelse)
        elif isinstance(node, ast.Try):
            for block in (node.body, *(h.body for h in node.handlers), node.orelse, node.finalbody):
                yield from _module_level_imports(block)
        elif isinstance(node, ast.With):
            yield from _module_level_imports(node.body)


def _graph() -> dict[str, set[str]]:
    """module -> the project's modules it imports at module level (each parent package of a dotted import too,
    as Python imports those first; a module's own parent packages left out, see the module docstring)."""
    modules = _modules()
    graph: dict[str, set[str]] = {}
    for name, file in modules.items():
        is_package = file.name == "__init__.py"
        targets: set[str] = set()
        for node in _module_level_imports(ast.parse(file.read_text(), str(file)).body):
            if isinstance(node, ast.Import):
                imported = [alias.name for alias in node.names]
            else:
                base = node.module or ""
                if node.level:  # relative: from the package of this module
                    package = name.split(".") if is_package else name.split(".")[:-1]
                    package = package[: len(package) - (node.level - 1)]
                    base = ".".join([*package, *([base] if base else [])])
                imported = [f"{base}.{a.name}" if f"{base}.{a.name}" in modules else base for a in node.names]
            for dotted in imported:
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


def _reachable(graph: dict[str, set[str]], start: str) -> set[str]:
    seen, todo = set(), [start]
    while todo:
        for w in graph[todo.pop()] - seen:
            seen.add(w)
            todo.append(w)
    return seen


def test_the_graph_sees_the_imports() -> None:
    graph = _graph()
    assert {"workbench.simulator", "controllers", "tuning.cli"} <= graph.keys()
    assert "workbench.result" in graph["workbench.simulator"]
    assert "controllers.base" in graph["workbench.simulator"]
    assert "workbench.plots" not in graph["workbench.plots"]


def test_no_import_cycle_among_the_modules() -> None:
    cycles = _cycles(_graph())
    assert cycles <= ALLOWED_MODULE_CYCLES, f"new module-level import cycles: {sorted(cycles - ALLOWED_MODULE_CYCLES)}"


def test_plots_result_and_simulator_do_not_cycle() -> None:
    """Issue 17 item 1: plotting is imported where a figure is drawn, so the simulator does not load it."""
    graph = _graph()
    assert "workbench.plots" not in graph["workbench.result"]
    assert "workbench.plots" not in graph["workbench.comparison"]
    assert "workbench.plots" not in _reachable(graph, "workbench.simulator")
    for module in ("workbench.plots", "workbench.result", "workbench.simulator"):
        assert not any(module in cycle for cycle in _cycles(graph))


def test_the_package_imports_do_not_grow() -> None:
    edges = {
        (module.split(".")[0], target.split(".")[0])
        for module, targets in _graph().items()
        for target in targets
        if module.split(".")[0] != target.split(".")[0]
    }
    assert edges <= ALLOWED_PACKAGE_EDGES, f"new package-level imports: {sorted(edges - ALLOWED_PACKAGE_EDGES)}"
