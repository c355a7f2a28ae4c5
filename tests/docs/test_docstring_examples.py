"""The Examples sections of the docstrings run as written: every module of the packages whose source holds an
example (a `>>>` line) is run as a doctest, and every example not marked to skip (a simulation, a study) gives the
output its docstring shows, so that an example a user copies from the reference works.

The examples run in a scratch folder (one that writes a file writes it there) that holds a link to the
repository's examples/, which some examples read as `examples/*.toml`."""

from __future__ import annotations

import doctest
import importlib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
PACKAGES = ("workbench", "controllers", "tuning")


def _modules_with_examples() -> list[str]:
    """The dotted names of the packages' modules whose source has a `>>>` line, found without importing them."""
    names = []
    for package in PACKAGES:
        for path in sorted((ROOT / package).rglob("*.py")):
            if ">>> " in path.read_text(encoding="utf-8"):
                parts = path.relative_to(ROOT).with_suffix("").parts
                names.append(".".join(parts[:-1] if parts[-1] == "__init__" else parts))
    return names


MODULES = _modules_with_examples()


def test_the_examples_are_found() -> None:
    assert {"tuning.lag_fit", "workbench.apps.studies.spec", "workbench.vehicles"} <= set(MODULES)


@pytest.mark.parametrize("name", MODULES)
def test_docstring_examples_run_as_written(name: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    (tmp_path / "examples").symlink_to(ROOT / "examples", target_is_directory=True)
    monkeypatch.chdir(tmp_path)
    module = importlib.import_module(name)
    finder = doctest.DocTestFinder(exclude_empty=True)
    runner = doctest.DocTestRunner(optionflags=doctest.NORMALIZE_WHITESPACE)
    examples = 0
    for test in finder.find(module, name):
        examples += len(test.examples)
        runner.run(test)
    results = runner.summarize(verbose=False)
    assert examples > 0, f"{name} has no docstring example"
    assert results.failed == 0, f"{results.failed} of {results.attempted} docstring examples of {name} failed"
