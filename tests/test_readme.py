"""The README is the front door and the user guide holds the rest: the README stays short and free of history,
shows the pictures it names, gives the documentation's build command and names every command of both CLIs; the
Getting started page and the user guide exist, and the guide documents every command."""

from __future__ import annotations

import argparse
import re
from pathlib import Path

import pytest

from tuning.cli import _parser as tuning_parser
from workbench.apps.cli import _parser as workbench_parser

ROOT = Path(__file__).resolve().parent.parent
README = (ROOT / "README.md").read_text(encoding="utf-8")
GUIDE = ROOT / "docs" / "guide"
GUIDE_PAGES = ("index", "scenarios", "vehicles", "conditions", "controllers", "cli", "tuning", "reports", "studies")
DOCS_BUILD = (
    'python3 -m venv .venv && .venv/bin/pip install -q -e ".[docs]" && '
    ".venv/bin/sphinx-build -W -n -b html docs docs/_build/html"
)


def _commands(parser: argparse.ArgumentParser) -> list[str]:
    """The sub-command names of a CLI's parser."""
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return sorted(sub.choices)


def test_the_readme_is_a_front_door_of_150_to_250_lines() -> None:
    assert 150 <= len(README.splitlines()) <= 250


@pytest.mark.parametrize(
    "history",
    [r"\bissue\s+#?\d+", r"\b20\d\d-\d\d-\d\d\b", r"\bre-measured\b", r"\bsession\b", r"\bbefore issue\b"],
)
def test_the_readme_holds_no_dates_issue_numbers_or_history(history: str) -> None:
    assert re.search(history, README, re.IGNORECASE) is None


def test_the_readme_pictures_are_committed_files_the_code_makes() -> None:
    """The Figure 17 picture (docs/_static/, made by `workbench fig17`) leads; the error breakdown's figure is the
    benchmark's own (benchmarks/figures/, made by `benchmarks/cte_breakdown.py`). Both render where the README is
    read, a repository browser included."""
    pictures = re.findall(r"!\[[^\]]*\]\(([^)]+)\)", README)
    assert pictures[0] == "docs/_static/fig17_trajectories.png"
    assert pictures[1:] == ["benchmarks/figures/cte_breakdown_tractor-semitrailer.png"]
    for picture in pictures:
        assert (ROOT / picture).is_file(), picture


def test_the_readme_gives_the_docs_build_command_and_where_to_open_it() -> None:
    assert DOCS_BUILD in README
    assert "docs/_build/html/index.html" in README


def test_every_docs_page_the_readme_names_exists() -> None:
    named = set(re.findall(r"`(docs/[\w/.-]+)`", README))
    assert "docs/getting-started.md" in named
    for path in named - {"docs/_build/html/index.html"}:  # the build's output, there only after a build
        assert (ROOT / path).exists(), path


def test_the_readme_tour_names_every_workbench_command() -> None:
    tour = README.split("## A short tour", 1)[1].split("\n## ", 1)[0]
    for command in _commands(workbench_parser()):
        assert re.search(rf"\b{re.escape(command)}\b", tour), command
    assert "tuning " in tour


def test_getting_started_and_every_guide_page_exist_with_a_title() -> None:
    for page in [ROOT / "docs" / "getting-started.md", *(GUIDE / f"{name}.md" for name in GUIDE_PAGES)]:
        assert page.read_text(encoding="utf-8").startswith("# "), page


def test_the_guide_index_lists_every_guide_page() -> None:
    index = (GUIDE / "index.md").read_text(encoding="utf-8")
    toctree = index.split("```{toctree}", 1)[1].split("```", 1)[0]
    assert sorted(line.strip() for line in toctree.splitlines()[2:] if line.strip()) == sorted(GUIDE_PAGES[1:])


def test_the_cli_reference_shows_every_workbench_command() -> None:
    reference = (GUIDE / "cli.md").read_text(encoding="utf-8")
    for command in _commands(workbench_parser()):
        assert f"workbench {command}" in reference, command


def test_the_tuning_page_shows_every_tuning_command() -> None:
    page = (GUIDE / "tuning.md").read_text(encoding="utf-8")
    for command in _commands(tuning_parser()):
        assert f"tuning {command}" in page, command


@pytest.mark.parametrize("page", ["getting-started.md", *(f"guide/{name}.md" for name in GUIDE_PAGES)])
def test_the_guide_holds_no_dates_or_issue_numbers(page: str) -> None:
    text = (ROOT / "docs" / page).read_text(encoding="utf-8")
    assert re.search(r"\bissue\s+\d+|\b20\d\d-\d\d-\d\d\b|\bre-measured\b", text, re.IGNORECASE) is None
