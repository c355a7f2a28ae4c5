"""The site's own stylesheet (docs/_static/workbench.css) is loaded by the build and keeps a notebook's wide output
(a DataFrame with many columns) inside the page's column, scrolling sideways, instead of running under the page's
table of contents. Read from the files, without Sphinx."""

from __future__ import annotations

import ast
import re
from pathlib import Path

DOCS = Path(__file__).resolve().parents[2] / "docs"


def test_the_build_loads_the_stylesheet() -> None:
    tree = ast.parse((DOCS / "conf.py").read_text(encoding="utf-8"))
    assigned = {t.id: node.value for node in tree.body if isinstance(node, ast.Assign) for t in node.targets
                if isinstance(t, ast.Name)}  # fmt: skip
    assert "html_css_files" in assigned
    assert "workbench.css" in ast.unparse(assigned["html_css_files"])
    assert (DOCS / "_static" / "workbench.css").is_file()


def test_a_notebook_output_scrolls_sideways_within_the_column() -> None:
    css = (DOCS / "_static" / "workbench.css").read_text(encoding="utf-8")
    rule = re.search(r"div\.cell_output div\.output\s*\{([^}]*)\}", css)
    assert rule is not None, "no rule for the notebooks' outputs"
    assert re.search(r"overflow-x:\s*auto", rule.group(1))
