"""Sphinx configuration of the workbench's documentation site.

Pages are MyST Markdown, the notebooks in ``notebooks/`` are rendered by myst-nb (executed once and cached, so a
rebuild re-runs only a notebook whose code changed), and the API reference is autodoc over the modules' ``__all__``.
The build needs no network: no intersphinx, and the third-party types that cannot be resolved offline are listed in
``nitpick_ignore_regex`` below, so that ``sphinx-build -W -n`` fails on a broken link to the workbench's own API.
"""

from __future__ import annotations

import dataclasses
import os
import re
import shutil
import sys
import tomllib
from pathlib import Path
from typing import Any

from sphinx.ext.napoleon import Config as NapoleonConfig
from sphinx.ext.napoleon.docstring import NumpyDocstring

DOCS = Path(__file__).resolve().parent
ROOT = DOCS.parent
sys.path.insert(0, str(ROOT))
if (DOCS / "_ext" / "workbench_figures.py").exists():
    sys.path.insert(0, str(Path(__file__).parent / "_ext"))

# The notebooks' kernels inherit the environment: without MPLBACKEND, IPython's inline backend shows each cell's
# figures in its output (with MPLBACKEND=Agg, as the tests run them, a figure would be drawn and never shown).
os.environ.pop("MPLBACKEND", None)

project = "Lateral-control workbench"
author = "The workbench's authors"
copyright = "the workbench's authors, MIT licence"
release = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]["version"]
version = release

extensions = [
    "myst_nb",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    # MathJax served from the built site (_static/mathjax), not from a CDN: the equations render offline too.
    "sphinx-mathjax-offline",
]
if (DOCS / "_ext" / "workbench_figures.py").exists():
    extensions.append("workbench_figures")

exclude_patterns = ["_build", "_generated/benchmarks", "benchmark-results", "**.ipynb_checkpoints"]
templates_path: list[str] = []
html_theme = "furo"
html_title = project
html_static_path = ["_static"] if (DOCS / "_static").is_dir() else []
html_css_files = ["workbench.css"] if (DOCS / "_static" / "workbench.css").is_file() else []

# MyST: pages and notebooks.
myst_enable_extensions = ["colon_fence", "deflist", "dollarmath", "amsmath"]
myst_heading_anchors = 3
suppress_warnings: list[str] = []

# The notebooks are executed during the build (they are stored without outputs) and their outputs cached under
# docs/_build/.jupyter_cache, so only a notebook whose code changed runs again; a failing cell fails the build.
nb_execution_mode = "cache"
nb_execution_cache_path = str(DOCS / "_build" / ".jupyter_cache")
nb_execution_timeout = 300
nb_execution_raise_on_error = True
nb_execution_in_temp = True
nb_merge_streams = True

# The notebooks live in notebooks/ (the tests run them there); Sphinx reads sources only under docs/, so they are
# copied into docs/_generated/notebooks, rewritten only when they differ so that an unchanged one is not reread.
NOTEBOOKS_SOURCE = ROOT / "notebooks"
NOTEBOOKS_COPY = DOCS / "_generated" / "notebooks"
NOTEBOOKS_COPY.mkdir(parents=True, exist_ok=True)
for _notebook in sorted(NOTEBOOKS_SOURCE.glob("*.ipynb")):
    _copy = NOTEBOOKS_COPY / _notebook.name
    if not _copy.exists() or _copy.read_bytes() != _notebook.read_bytes():
        shutil.copyfile(_notebook, _copy)

# API reference: autodoc of each module's __all__, numpydoc sections through napoleon.
autodoc_default_options = {"member-order": "bysource"}
autodoc_typehints = "description"
autodoc_typehints_format = "short"
# Types are added to the parameters and return values a docstring documents; a dataclass lists its fields
# (`_field_lines`), so its signature is not listed a second time as bare parameters.
autodoc_typehints_description_target = "documented"
autodoc_preserve_defaults = True
autodoc_class_signature = "mixed"
autosummary_generate = False
# numpydoc sections (Parameters, Returns, Raises, ...) through napoleon's parser, called from `_numpy_sections`
# below rather than as the napoleon extension: napoleon would read an attribute docstring's first "words: text"
# as "type: description".
NAPOLEON = NapoleonConfig(napoleon_google_docstring=False, napoleon_numpy_docstring=True, napoleon_use_rtype=False)
add_module_names = False

nitpicky = True
# Types from third-party packages (no intersphinx at build time: no network) and the plain-language type
# phrases of the numpydoc sections ("array of shape (n,)", "optional") are not cross-referenced.
nitpick_ignore_regex = [
    ("py:.*", r"(numpy|np|npt|pandas|pd|scipy|matplotlib|casadi|ca|optuna|control|dask|distributed|pyarrow|fmpy)"
     r"(\..*)?"),
    ("py:.*", r"(collections\.abc|typing|typing_extensions|pathlib|os|io|subprocess|concurrent\.futures|"
     r"multiprocessing|threading|dataclasses|enum|types|argparse|datetime|random|logging|numbers)\..*"),
    ("py:.*", r"(NDArray|ArrayLike|DTypeLike|Figure|Axes|DataFrame|Series|ndarray|Path|Callable|Iterable|"
     r"Iterator|Sequence|Mapping|MutableMapping|Any|Literal|Self|Protocol|ClassVar|TextIO|Generator)(\[.*)?"),
    ("py:.*", r".*\s.*"),  # a phrase rather than a name ("array of shape (n,)", "float or None")
    ("py:.*", r"(optional|default.*|array_like|array-like|callable|sequence|mapping|iterable|path-like|file-like)"),
    ("py:.*", r"(float|int|str|bool|bytes|None|object|tuple|list|dict|set|frozenset|type|complex)(\[.*)?"),
    ("py:.*", r"(Ellipsis|NoneType|T|_T|P|R|abc\.ABC|DataclassInstance)"),
    ("py:.*", r"[a-z_][a-z0-9_]*"),  # a lowercase bare word in a type phrase: a unit ("s") or a field name
    # a unit after the type ("float, km/h", "float, 1/(m s)", split at the parentheses) or a size in a shape
    ("py:.*", r"(1/|1/m(\^2)?|1/s|km/h|m/s(\^2)?|rad/s|deg/s|Hz|dB|N|Nm|\d+)"),
    ("py:.*", r"(.*\.)?(ConfigT|ParamsT|MPCConfigT|T)"),  # type variables
]


# A config dataclass documents each field beside the field: an option's unit, range and meaning in its metadata
# (controllers.config_checks.option), a parameter's in the comment that follows it. The reference lists them.
def _trailing_comments(cls: type) -> dict[str, str]:
    """The comment at the end of each ``name: type = value  # comment`` line of the class body (_ext/field_comments)."""
    from field_comments import trailing_comments  # docs/_ext, on the path above

    return trailing_comments(cls)


def _rst_text(text: str) -> str:
    """Plain text safe in reStructuredText: no emphasis, role, substitution or reference markup."""
    text = text.replace("\\", "\\\\").replace("`", "").replace("*", r"\*").replace("|", r"\|")
    return re.sub(r"_(?=\W|$)", r"\\_", text)


def _default_text(field: dataclasses.Field[Any]) -> str:
    if field.default is not dataclasses.MISSING:
        return repr(field.default)
    if field.default_factory is not dataclasses.MISSING:
        return f"{field.default_factory.__name__}()"
    return "required"


def _field_lines(cls: type) -> list[str]:
    comments = _trailing_comments(cls)
    lines = ["", ".. rubric:: Fields", ""]
    for field in dataclasses.fields(cls):
        if field.name.startswith("_") or not field.init:
            continue
        doc = field.metadata.get("doc") or comments.get(field.name, "")
        if doc and not doc.endswith("."):  # a comment is a phrase; the Allowed and Default sentences follow it
            doc += "."
        rule = field.metadata.get("rule")
        allowed = rule.allowed() if rule is not None and hasattr(rule, "allowed") else ""
        parts = [p for p in (doc, f"Allowed: {allowed}." if allowed else "", f"Default: ``{_default_text(field)}``.")
                 if p]
        lines.append(f"``{field.name}``")
        lines.append("   " + _rst_text(" ".join(parts)))
        lines.append("")
    return lines


def _numpy_sections(app: Any, what: str, name: str, obj: Any, options: Any, lines: list[str]) -> None:
    """The numpydoc sections of a docstring as reStructuredText fields; an attribute's docstring is plain text."""
    kind = "" if what in ("attribute", "property", "data") else what
    lines[:] = NumpyDocstring(lines, NAPOLEON, app, kind, name, obj, options).lines()


def _escape_bars(app: Any, what: str, name: str, obj: Any, options: Any, lines: list[str]) -> None:
    """Docstrings write an absolute value as |x|, which reStructuredText would read as a substitution."""
    lines[:] = [re.sub(r"(?<!\\)\|", r"\\|", line) for line in lines]


def _add_dataclass_fields(app: Any, what: str, name: str, obj: Any, options: Any, lines: list[str]) -> None:
    if what == "class" and dataclasses.is_dataclass(obj) and isinstance(obj, type) and dataclasses.fields(obj):
        lines.extend(_field_lines(obj))


def setup(app: Any) -> None:
    app.connect("autodoc-process-docstring", _numpy_sections, priority=400)
    app.connect("autodoc-process-docstring", _escape_bars)
    app.connect("autodoc-process-docstring", _add_dataclass_fields)
