"""Docstrings and comments of the packages say what the code does and why, not its history: no issue numbers, no
dates. Measured figures with their dates belong in the benchmark results, the history in CHANGELOG.md.

A date or an issue number that is data (a format string, an example value a docstring must show) goes in ALLOWED
with the reason it is there.
"""

import ast
import io
import re
import tokenize
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("workbench", "controllers", "tuning", "benchmarks", "examples")

#: "issue 18", "Issue 19's", "(issues 3 and 4)", "issue #228"; a link to a third-party issue (".../issues/228") is
#: a citation and is not matched.
ISSUE = re.compile(r"\bissues?\s*#?\d+", re.IGNORECASE)
#: An ISO date, "2026-12-02".
DATE = re.compile(r"\b(?:19|20)\d{2}-(?:0[1-9]|1[0-2])-(?:0[1-9]|[12]\d|3[01])\b")

#: (path relative to the repository, text of the line) -> why that issue number or date is data, not history.
ALLOWED: dict[tuple[str, str], str] = {}


def _docstrings(tree: ast.AST) -> list[tuple[int, str]]:
    """(first line, text) of every module, class and function docstring and of every attribute docstring (a string
    statement right after an assignment in a module or class body)."""
    found = []
    for node in ast.walk(tree):
        if not isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)):
            continue
        body = node.body
        for i, statement in enumerate(body):
            is_string = (
                isinstance(statement, ast.Expr)
                and isinstance(statement.value, ast.Constant)
                and isinstance(statement.value.value, str)
            )
            documents = i == 0 or isinstance(body[i - 1], (ast.Assign, ast.AnnAssign))
            if is_string and documents:
                found.append((statement.lineno, statement.value.value))
    return found


def history_lines(source: str) -> list[tuple[int, str]]:
    """(line number, text) of each comment or docstring line of `source` that names an issue number or a date."""
    hits = []
    for token in tokenize.generate_tokens(io.StringIO(source).readline):
        if token.type == tokenize.COMMENT:
            hits.append((token.start[0], token.string))
    for first_line, text in _docstrings(ast.parse(source)):
        hits += [(first_line + k, line) for k, line in enumerate(text.splitlines())]
    return sorted((n, text.strip()) for n, text in hits if ISSUE.search(text) or DATE.search(text))


def _package_files() -> list[Path]:
    return sorted(p for package in PACKAGES for p in (ROOT / package).rglob("*.py"))


def test_packages_are_scanned():
    files = _package_files()
    assert {p.relative_to(ROOT).parts[0] for p in files} == set(PACKAGES)


@pytest.mark.parametrize("package", PACKAGES)
def test_no_issue_numbers_or_dates_in_comments_and_docstrings(package):
    found = []
    for path in sorted((ROOT / package).rglob("*.py")):
        relative = path.relative_to(ROOT).as_posix()
        for line_number, text in history_lines(path.read_text(encoding="utf-8")):
            if (relative, text) not in ALLOWED:
                found.append(f"{relative}:{line_number}: {text}")
    assert not found, "history in comments or docstrings (say what and why instead):\n" + "\n".join(found)


def test_history_lines_finds_each_kind_and_ignores_data():
    source = '''"""Module (issue 15)."""
import time

#: Attribute docstring follows.
LIMIT = 3
"""Measured 2026-12-02."""

FORMAT = "%Y-%m-%d"  # a date format: data
STAMP = "2026-12-03 issue 4"


class Thing:
    """See https://github.com/owner/repo/issues/228 for the upstream report."""

    def go(self):
        """Goes, as before Issue 19's change."""
        return time.time()  # cheaper since issue #7
'''
    assert history_lines(source) == [
        (1, "Module (issue 15)."),
        (6, "Measured 2026-12-02."),
        (16, "Goes, as before Issue 19's change."),
        (17, "# cheaper since issue #7"),
    ]


def test_allowed_entries_still_exist():
    """An allow-list entry whose line is gone would hide a future hit of the same text: keep the list exact."""
    present = {
        (path.relative_to(ROOT).as_posix(), text)
        for path in _package_files()
        for _, text in history_lines(path.read_text(encoding="utf-8"))
    }
    assert set(ALLOWED) <= present
