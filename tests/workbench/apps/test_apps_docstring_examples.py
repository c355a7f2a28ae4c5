"""The Examples sections of the comparison, report and studies docstrings run as written, from the repository's
root (they read the shipped example specs under examples/): every example that is not marked to skip (a
simulation, a study) gives the output its docstring shows, so that an example a user copies from the reference
works."""

from __future__ import annotations

import doctest
import importlib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[3]

#: The modules whose docstrings carry examples, each run as a doctest.
MODULES = (
    "workbench.apps.comparison",
    "workbench.apps.controller_config",
    "workbench.apps.fig17",
    "workbench.apps.fmu_export",
    "workbench.apps.lookahead_study",
    "workbench.apps.paper",
    "workbench.apps.report",
    "workbench.apps.robustness",
    "workbench.apps.studies.backends",
    "workbench.apps.studies.circuit_parameters",
    "workbench.apps.studies.condition_parameters",
    "workbench.apps.studies.distributions",
    "workbench.apps.studies.optimise",
    "workbench.apps.studies.plots",
    "workbench.apps.studies.results",
    "workbench.apps.studies.run_build",
    "workbench.apps.studies.runner",
    "workbench.apps.studies.spec",
    "workbench.apps.studies.sweep",
    "workbench.apps.studies.tournament",
    "workbench.apps.studies.tournament_judging",
    "workbench.apps.studies.tournament_report",
    "workbench.apps.studies.tournament_spec",
)


@pytest.mark.parametrize("name", MODULES)
def test_docstring_examples_run_as_written(name: str, monkeypatch) -> None:
    monkeypatch.chdir(ROOT)  # the examples name examples/*.toml relative to the repository
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
