"""The public API the reference documents: each module below declares `__all__`, every name in it has a docstring
(a constant: a string or `#:` comment beside its assignment, which autodoc shows), and every name is documented
on a page of docs/api/ by an autodoc directive (a name a package re-exports may be documented once, where it is
defined). Runs without Sphinx: it reads the pages' directives and the modules' sources."""

from __future__ import annotations

import ast
import dataclasses
import functools
import importlib
import inspect
import re
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest

ROOT = Path(__file__).resolve().parents[2]
API_PAGES = ROOT / "docs" / "api"

#: The modules whose `__all__` is the public API the reference documents.
MODULES = (
    "workbench.simulation.simulator",
    "workbench.simulation.scenarios",
    "workbench.simulation.conditions",
    "workbench.simulation.metrics",
    "workbench.simulation.result",
    "workbench.vehicles",
    "workbench.vehicles.base",
    "workbench.vehicles.kinematic_bicycle",
    "workbench.vehicles.dynamic_bicycle",
    "workbench.vehicles.single_track",
    "workbench.vehicles.tractor_semitrailer",
    "workbench.vehicles.commonroad_mb",
    "workbench.vehicles.fmu_plant_params",
    "controllers",
    "controllers.base",
    "controllers.clothoid",
    "controllers.clothoid.controller",
    "controllers.pure_pursuit",
    "controllers.stanley",
    "controllers.mpc",
    "controllers.mpc.controller",
    "controllers.mpc.config",
    "workbench.apps.comparison",
    "workbench.apps.report",
    "workbench.apps.studies",
    "workbench.apps.studies.tournament",
    "tuning.lag_fit",
    "tuning.lead_design",
    "tuning.preview_fit",
    "tuning.schedule",
    "tuning.own_tuning",
)

_DIRECTIVE = re.compile(r"^\s*\.\. auto(class|function|data|exception|module)::\s*(\S+)\s*$", re.MULTILINE)


def _public_names() -> list[tuple[str, str]]:
    return [(m, n) for m in MODULES for n in getattr(importlib.import_module(m), "__all__", ())]


def _is_code_object(obj: Any) -> bool:
    return inspect.isclass(obj) or inspect.isfunction(obj) or inspect.isbuiltin(obj)


def _own_docstring(obj: Any) -> str:
    """The object's own docstring: not one inherited, not the signature a dataclass writes when there is none."""
    doc = obj.__dict__.get("__doc__") if inspect.isclass(obj) else getattr(obj, "__doc__", None)
    if not isinstance(doc, str):
        return ""
    if inspect.isclass(obj) and dataclasses.is_dataclass(obj) and doc.startswith(f"{obj.__name__}("):
        return ""
    return doc.strip()


def _assigns_name(node: ast.stmt, name: str) -> bool:
    """Whether the statement assigns `name` (plainly or with an annotation)."""
    targets = node.targets if isinstance(node, ast.Assign) else [node.target] if isinstance(node, ast.AnnAssign) else []
    return any(isinstance(t, ast.Name) and t.id == name for t in targets)


def _assignment_doc(module: ModuleType, name: str, seen: frozenset[str] = frozenset()) -> str | None:
    """The doc of the module-level constant `name`: the string after its assignment or the `#:` comment before it
    (or on its line), followed through `from X import name` to the module that assigns it; None if not found."""
    if module.__name__ in seen:
        return None
    source = inspect.getsource(module)
    lines = source.splitlines()
    body = ast.parse(source).body
    for index, node in enumerate(body):
        if _assigns_name(node, name):
            after = body[index + 1] if index + 1 < len(body) else None
            if isinstance(after, ast.Expr) and isinstance(after.value, ast.Constant) and isinstance(
                after.value.value, str
            ):
                return after.value.value.strip()
            comments = []
            row = node.lineno - 2
            while row >= 0 and lines[row].strip().startswith("#:"):
                comments.insert(0, lines[row].strip()[2:].strip())
                row -= 1
            if "#:" in lines[node.lineno - 1]:
                comments.append(lines[node.lineno - 1].split("#:", 1)[1].strip())
            return " ".join(comments).strip()
        if isinstance(node, ast.ImportFrom) and any((a.asname or a.name) == name for a in node.names):
            package = module.__name__ if hasattr(module, "__path__") else module.__name__.rpartition(".")[0]
            origin = importlib.import_module("." * node.level + (node.module or ""), package if node.level else None)
            return _assignment_doc(origin, name, seen | {module.__name__})
    for node in ast.walk(ast.Module(body=body, type_ignores=[])):  # a lazy import, in the package's __getattr__
        if isinstance(node, ast.ImportFrom) and node.level == 0 and any(a.name == name for a in node.names):
            return _assignment_doc(importlib.import_module(node.module or ""), name, seen | {module.__name__})
    return None


@functools.cache
def _documented(pages: Path) -> tuple[set[int], set[tuple[str, str]], set[str]]:
    """Ids of the classes and functions the API pages document, the (module, name) of their constants, and the
    modules they document."""
    objects: set[int] = set()
    constants: set[tuple[str, str]] = set()
    modules: set[str] = set()
    for page in sorted(pages.glob("*.md")):
        for kind, path in _DIRECTIVE.findall(page.read_text(encoding="utf-8")):
            if kind == "module":
                modules.add(path)
                continue
            module_name, _, name = path.rpartition(".")
            try:
                parent: Any = importlib.import_module(module_name)
            except ImportError:  # a method or nested class: module.Class.member
                outer, _, cls = module_name.rpartition(".")
                parent = getattr(importlib.import_module(outer), cls)
            obj = getattr(parent, name)
            if kind == "data":
                constants.add((module_name, name))
            else:
                objects.add(id(obj))
    return objects, constants, modules


def test_each_module_of_the_reference_declares_its_public_names() -> None:
    missing = [m for m in MODULES if not hasattr(importlib.import_module(m), "__all__")]
    assert not missing, f"no __all__ in {missing}"
    unknown = [(m, n) for m, n in _public_names() if not hasattr(importlib.import_module(m), n)]
    assert not unknown, f"__all__ names what the module does not have: {unknown}"


@pytest.mark.parametrize(("module", "name"), _public_names(), ids=lambda v: str(v))
def test_a_public_name_has_a_docstring(module: str, name: str) -> None:
    mod = importlib.import_module(module)
    obj = getattr(mod, name)
    doc = _own_docstring(obj) if _is_code_object(obj) else _assignment_doc(mod, name)
    assert doc, f"{module}.{name} has no docstring (a constant: a #: comment or a string beside its assignment)"


@pytest.mark.parametrize(("module", "name"), _public_names(), ids=lambda v: str(v))
def test_a_public_name_is_in_the_reference(module: str, name: str) -> None:
    objects, constants, modules = _documented(API_PAGES)
    assert module in modules, f"docs/api/ has no automodule of {module}"
    obj = getattr(importlib.import_module(module), name)
    if _is_code_object(obj):
        assert id(obj) in objects, f"{module}.{name} is documented on no page of docs/api/"
    else:
        places = [m for m, n in constants if n == name and getattr(importlib.import_module(m), n) is obj]
        assert places, f"the constant {module}.{name} is documented on no page of docs/api/"


def test_the_reference_finds_a_missing_name(tmp_path: Path) -> None:
    """The check above can fail: with one directive taken out of the pages, its object is no longer found."""
    page = API_PAGES / "tuning.md"
    text = page.read_text(encoding="utf-8")
    assert ".. autofunction:: tuning.lag_fit.fit_lag\n" in text
    (tmp_path / "tuning.md").write_text(text.replace(".. autofunction:: tuning.lag_fit.fit_lag\n", ""), "utf-8")
    from tuning.lag_fit import fit_lag

    assert id(fit_lag) in _documented(API_PAGES)[0]
    assert id(fit_lag) not in _documented(tmp_path)[0]


def test_a_dataclass_without_its_own_docstring_counts_as_undocumented() -> None:
    @dataclasses.dataclass(frozen=True)
    class Undocumented:
        value: float = 1.0

    @dataclasses.dataclass(frozen=True)
    class Documented:
        """Says what it is."""

        value: float = 1.0

    assert _own_docstring(Undocumented) == ""
    assert _own_docstring(Documented) == "Says what it is."


def _assigns(module: ModuleType, name: str) -> bool:
    """Whether the module's own top level assigns `name` (not an import of it)."""
    return any(_assigns_name(node, name) for node in ast.parse(inspect.getsource(module)).body)


def test_a_constant_is_documented_where_it_is_assigned() -> None:
    """Sphinx reads a constant's `#:` comment from the module the directive names: named through a package that
    re-exports it, the page shows the docstring of its type (a tuple's, a float's) instead."""
    elsewhere = []
    for page in sorted(API_PAGES.glob("*.md")):
        for kind, path in _DIRECTIVE.findall(page.read_text(encoding="utf-8")):
            module_name, _, name = path.rpartition(".")
            if kind == "data" and not _assigns(importlib.import_module(module_name), name):
                elsewhere.append(f"{page.name}: {path}")
    assert not elsewhere, f"autodata naming a module that only imports the constant: {elsewhere}"


def test_the_assignment_check_tells_an_import_from_an_assignment() -> None:
    assert _assigns(importlib.import_module("workbench.vehicles.base"), "STANDARD_OUTPUTS")
    assert not _assigns(importlib.import_module("workbench.vehicles"), "STANDARD_OUTPUTS")
