"""The Examples sections of the tuning and clothoid-controller docstrings run as written: each module below has
examples, and every one of them gives the output its docstring shows (doctest), so that an example a user copies
from the reference works."""

from __future__ import annotations

import doctest
import importlib

import pytest

#: The modules whose docstrings carry examples, each run as a doctest.
MODULES = (
    "controllers.clothoid.clothoid_fit",
    "controllers.clothoid.curvature_limits",
    "controllers.clothoid.filter_schedule",
    "controllers.clothoid.frechet",
    "controllers.clothoid.lead_filter",
    "tuning.lag_fit",
    "tuning.lead_design",
    "tuning.own_tuning",
    "tuning.schedule",
)


@pytest.mark.parametrize("name", MODULES)
def test_docstring_examples_run_as_written(name: str, tmp_path, monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)  # an example that writes a file writes it here
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
