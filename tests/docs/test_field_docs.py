"""Every dataclass of the reference documents each field beside it: the doc of a controller's `option(...)` or
the comment at the end of the field's line (its meaning, unit and allowed range), which the reference lists under
the class's Fields with the default (docs/conf.py, `_field_lines`). Reads the sources through the reader conf.py
uses (docs/_ext/field_comments.py), so that the test and the reference cannot disagree about what counts as a
field's comment; needs no Sphinx."""

from __future__ import annotations

import dataclasses
import functools
import importlib
import importlib.util
import inspect
from pathlib import Path
from types import ModuleType

import pytest

from tests.docs.test_public_api import MODULES

ROOT = Path(__file__).resolve().parents[2]
#: The packages of the project: a third-party dataclass a module re-exports is documented by its own project.
PROJECT_PACKAGES = ("workbench", "controllers", "tuning")


@functools.cache
def _field_comments() -> ModuleType:
    """docs/_ext/field_comments.py, the reader docs/conf.py lists the fields with (standard library only)."""
    spec = importlib.util.spec_from_file_location("_docs_field_comments", ROOT / "docs" / "_ext" / "field_comments.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _reference_dataclasses() -> list[type]:
    found: dict[int, type] = {}
    for module_name in MODULES:
        module = importlib.import_module(module_name)
        for name in getattr(module, "__all__", ()):
            obj = getattr(module, name)
            if (
                inspect.isclass(obj)
                and dataclasses.is_dataclass(obj)
                and obj.__module__.split(".")[0] in PROJECT_PACKAGES
            ):
                found.setdefault(id(obj), obj)
    return sorted(found.values(), key=lambda cls: f"{cls.__module__}.{cls.__qualname__}")


def undocumented_fields(cls: type) -> list[str]:
    """The fields of `cls` the reference lists without a doc: neither metadata "doc" nor a comment on their line
    (a tool's pragma, such as ``# type: ignore[...]``, is not a doc)."""
    comments = _field_comments().trailing_comments(cls)
    return [
        f.name
        for f in dataclasses.fields(cls)
        if not f.name.startswith("_") and f.init and not (f.metadata.get("doc") or comments.get(f.name))
    ]


def test_the_check_sees_the_reference_dataclasses() -> None:
    names = {cls.__qualname__ for cls in _reference_dataclasses()}
    assert {"Conditions", "FmuPlantParams", "LeadFilterParams", "LagFitOptions"} <= names


@pytest.mark.parametrize("cls", _reference_dataclasses(), ids=lambda cls: f"{cls.__module__}.{cls.__qualname__}")
def test_each_field_is_documented_beside_it(cls: type) -> None:
    missing = undocumented_fields(cls)
    assert not missing, (
        f"{cls.__module__}.{cls.__qualname__}: give each field a comment at the end of its line (meaning, unit, "
        f"allowed range): {', '.join(missing)}"
    )


def test_the_check_sees_a_field_without_its_comment() -> None:
    @dataclasses.dataclass(frozen=True)
    class Example:
        documented: float = 1.0  # a length (m), > 0
        bare: float = 2.0
        # a comment on a line of its own documents nothing
        below: float = 3.0
        pragma: float = 4.0  # fmt: skip
        from_metadata: float = dataclasses.field(default=5.0, metadata={"doc": "a time (s), >= 0"})

    assert undocumented_fields(Example) == ["bare", "below", "pragma"]
