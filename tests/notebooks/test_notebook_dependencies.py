"""Opening the notebooks as the README says needs no package beyond the `notebooks` extra.

Every module a notebook imports is the standard library's, this project's, or a distribution the package or its
`notebooks` extra depends on; the extra brings JupyterLab and the IPython kernel, which `jupyter lab notebooks/`
needs. The project's requirements are read from pyproject.toml, the distribution of an imported module from the
installed metadata (`importlib.metadata.packages_distributions`).
"""

from __future__ import annotations

import ast
import importlib.metadata
import re
import sys
import tomllib
from pathlib import Path

import nbformat
import pytest

ROOT = Path(__file__).resolve().parents[2]
NOTEBOOKS = sorted((ROOT / "notebooks").glob("*.ipynb"))
PROJECT_PACKAGES = {"workbench", "controllers", "tuning"}


def _requirement_name(requirement: str) -> str:
    """The normalised distribution name of a PEP 508 requirement ("dask[distributed]>=2024.1" -> "dask")."""
    name = re.match(r"[A-Za-z0-9._-]+", requirement).group(0)
    return re.sub(r"[-_.]+", "-", name).lower()


def _project() -> dict:
    return tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]


def _notebook_requirements() -> set[str]:
    project = _project()
    return {_requirement_name(r) for r in project["dependencies"] + project["optional-dependencies"]["notebooks"]}


def _imported_modules(notebook: Path) -> set[str]:
    """The top-level modules the notebook's code cells import."""
    modules: set[str] = set()
    for cell in nbformat.read(notebook, as_version=4).cells:
        if cell.cell_type != "code":
            continue
        source = "\n".join(line for line in cell.source.splitlines() if not line.lstrip().startswith(("%", "!")))
        for node in ast.walk(ast.parse(source)):
            if isinstance(node, ast.Import):
                modules.update(alias.name.partition(".")[0] for alias in node.names)
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                modules.add(node.module.partition(".")[0])
    return modules


def test_the_notebooks_extra_brings_jupyterlab_and_a_kernel() -> None:
    extra = {_requirement_name(r) for r in _project()["optional-dependencies"]["notebooks"]}
    assert {"jupyterlab", "ipykernel"} <= extra


@pytest.mark.parametrize("notebook", NOTEBOOKS, ids=lambda p: p.name)
def test_every_import_of_a_notebook_is_covered_by_the_notebooks_extra(notebook: Path) -> None:
    allowed = _notebook_requirements()
    distributions = importlib.metadata.packages_distributions()
    missing = {}
    for module in _imported_modules(notebook):
        if module in sys.stdlib_module_names or module in PROJECT_PACKAGES:
            continue
        names = {_requirement_name(d) for d in distributions.get(module, [])}
        if not names & allowed:
            missing[module] = sorted(names) or ["not installed"]
    assert not missing, f"{notebook.name} imports modules outside the notebooks extra: {missing}"


def test_the_imports_are_found() -> None:
    """The parser sees the notebooks' imports (a guard against a test that checks nothing)."""
    modules = set().union(*(_imported_modules(n) for n in NOTEBOOKS))
    assert {"numpy", "matplotlib", "workbench", "tuning"} <= modules
