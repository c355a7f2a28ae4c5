"""The documentation build: the `docs` extra installs it, CI runs it after the tests with warnings as errors and
nitpicky references, it needs no network (no intersphinx), and the site's table of contents names pages that
exist. Read from the files, without Sphinx (the test extra does not install it)."""

from __future__ import annotations

import ast
import re
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"
BUILD = "sphinx-build -W -n --keep-going -b html docs docs/_build/html"


def _conf() -> dict[str, object]:
    """The plain assignments of docs/conf.py whose value is a literal."""
    values: dict[str, object] = {}
    for node in ast.parse((DOCS / "conf.py").read_text(encoding="utf-8")).body:
        if isinstance(node, ast.Assign) and len(node.targets) == 1 and isinstance(node.targets[0], ast.Name):
            try:
                values[node.targets[0].id] = ast.literal_eval(node.value)
            except ValueError:
                continue
    return values


def test_the_docs_extra_brings_sphinx_the_theme_and_myst() -> None:
    extra = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]["optional-dependencies"]
    names = {re.split(r"[<>=!~ \[]", r, maxsplit=1)[0] for r in extra["docs"]}
    assert {"sphinx", "myst-parser", "myst-nb"} <= names
    assert names & {"furo", "pydata-sphinx-theme"}


def test_ci_builds_the_docs_after_the_tests_with_warnings_as_errors() -> None:
    ci = (ROOT / ".ci" / "run").read_text(encoding="utf-8").strip().splitlines()[-1]
    steps = [step.strip() for step in ci.split("&&")]
    build = [s for s in steps if "sphinx-build" in s]
    assert build == [f".venv/bin/{BUILD}"], f"CI's docs build: {build}"
    tests = next(i for i, s in enumerate(steps) if "pytest" in s)
    assert steps.index(build[0]) > tests
    install = next(s for s in steps if "pip install" in s)
    assert re.search(r'-e "\.\[[^\]]*\bdocs\b[^\]]*\]"', install), install


def test_the_build_is_nitpicky_and_offline() -> None:
    conf = _conf()
    assert conf["nitpicky"] is True
    extensions = conf["extensions"]
    assert isinstance(extensions, list)
    assert not [e for e in extensions if "intersphinx" in e or "linkcheck" in e]
    assert "sphinx.ext.autodoc" in extensions and "myst_nb" in extensions
    assert conf["nb_execution_mode"] in {"off", "cache"}


def test_the_table_of_contents_names_pages_that_exist() -> None:
    text = (DOCS / "index.md").read_text(encoding="utf-8")
    blocks = re.findall(r"```\{toctree\}\n(.*?)```", text, re.DOTALL)
    entries = [line.strip() for block in blocks for line in block.splitlines() if line.strip() and ":" not in line]
    assert "api/index" in entries and "changelog" in entries and "guide/index" in entries
    missing = []
    for entry in entries:
        if entry.startswith("_generated/notebooks/"):
            found = (ROOT / "notebooks" / f"{Path(entry).name}.ipynb").exists()
        else:
            found = (DOCS / f"{entry}.md").exists()
        if not found:
            missing.append(entry)
    assert not missing, f"docs/index.md names pages that do not exist: {missing}"


def test_every_notebook_is_on_the_site() -> None:
    text = (DOCS / "index.md").read_text(encoding="utf-8")
    notebooks = sorted(p.stem for p in (ROOT / "notebooks").glob("*.ipynb"))
    assert notebooks
    assert [n for n in notebooks if f"_generated/notebooks/{n}" not in text] == []
