"""The type check CI runs: mypy, from the `test` extra, over the three packages with the strictness pyproject.toml
sets, in the README's test command that `.ci/run` runs verbatim; its missing-import exceptions name only
third-party packages that ship no type information."""

from __future__ import annotations

import importlib.util
import re
import sys
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def _pyproject() -> dict:
    return tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))


def _readme_test_command() -> str:
    """The bash block under the README's "The tests:" paragraph."""
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    found = re.search(r"^The tests:.*?```bash\n(.+?)\n```", readme, re.DOTALL | re.MULTILINE)
    assert found is not None, "README.md has no test command after 'The tests:'"
    return found.group(1)


def test_the_test_extra_brings_mypy() -> None:
    requirements = _pyproject()["project"]["optional-dependencies"]["test"]
    names = [re.split(r"[<>=!~ \[]", r, maxsplit=1)[0] for r in requirements]
    assert "mypy" in names


def test_mypy_checks_the_three_packages_with_untyped_and_incomplete_defs_checked() -> None:
    config = _pyproject()["tool"]["mypy"]
    assert sorted(config["packages"]) == ["controllers", "tuning", "workbench"]
    assert config["check_untyped_defs"] is True
    assert config["disallow_incomplete_defs"] is True
    assert "ignore_missing_imports" not in config  # only per module, below


def test_ci_runs_the_readme_command_with_mypy_after_ruff() -> None:
    command = _readme_test_command()
    ci = (ROOT / ".ci" / "run").read_text(encoding="utf-8").strip().splitlines()[-1]
    assert ci == command
    steps = [step.strip() for step in command.split("&&")]
    assert steps.index(".venv/bin/mypy") == steps.index(".venv/bin/ruff check .") + 1


def _untyped_overrides() -> list[str]:
    overrides = _pyproject()["tool"]["mypy"].get("overrides", [])
    modules = [m for o in overrides if o.get("ignore_missing_imports") for m in o["module"]]
    assert modules, "no per-module ignore_missing_imports override"
    return modules


@pytest.mark.parametrize("pattern", _untyped_overrides())
def test_a_missing_import_is_ignored_only_for_an_installed_package_without_types(pattern: str) -> None:
    package = pattern.removesuffix(".*")
    assert "." not in package and "*" not in package, f"{pattern}: name a top-level package as NAME.*"
    spec = importlib.util.find_spec(package)
    assert spec is not None, f"{package} is not installed"
    folders = [Path(p) for p in spec.submodule_search_locations or ()]  # none for a one-file module
    assert not any((f / "py.typed").exists() for f in folders), f"{package} ships types (py.typed): check it"
    stubs = [Path(p) / f"{package}-stubs" for p in sys.path if (Path(p) / f"{package}-stubs").is_dir()]
    assert not stubs, f"{package} has stubs installed ({stubs[0]}): check it"
