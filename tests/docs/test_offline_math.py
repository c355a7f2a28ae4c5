"""The equations on the built pages render without network: the site serves its own MathJax (the
sphinx-mathjax-offline extension copies it into _static/mathjax) rather than loading it from a CDN, which a page
opened from disk, or on a machine without network, cannot reach. Read from the files, without Sphinx."""

from __future__ import annotations

import ast
import importlib.util
import re
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
OFFLINE_MATHJAX = "sphinx-mathjax-offline"


def _extensions() -> list[str]:
    for node in ast.parse((ROOT / "docs" / "conf.py").read_text(encoding="utf-8")).body:
        if isinstance(node, ast.Assign) and any(getattr(t, "id", None) == "extensions" for t in node.targets):
            return list(ast.literal_eval(node.value))
    raise AssertionError("docs/conf.py has no extensions list")


def test_the_docs_serve_their_own_mathjax() -> None:
    extensions = _extensions()
    assert "sphinx.ext.mathjax" in extensions and OFFLINE_MATHJAX in extensions, extensions
    assert not any("mathjax_path" in line and "http" in line
                   for line in (ROOT / "docs" / "conf.py").read_text(encoding="utf-8").splitlines())  # fmt: skip


def test_the_docs_extra_installs_the_offline_mathjax() -> None:
    extra = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]["optional-dependencies"]
    assert OFFLINE_MATHJAX in {re.split(r"[<>=!~ \[]", r, maxsplit=1)[0] for r in extra["docs"]}


def test_the_installed_extension_ships_mathjax() -> None:
    """Where the docs extra is installed, the extension holds the MathJax build it copies (tex-chtml.js)."""
    spec = importlib.util.find_spec(OFFLINE_MATHJAX)
    if spec is None or spec.origin is None:
        pytest.skip("the docs extra is not installed")
    assert (Path(spec.origin).parent / "static" / "mathjax" / "tex-chtml.js").is_file()
