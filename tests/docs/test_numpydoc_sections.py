"""Every public function and method of the reference's modules (`test_public_api.MODULES`) has the numpydoc
sections its signature calls for: Parameters when it takes any, Returns when it returns a value, Raises when its
own body raises the workbench's input error. Properties need none; a dataclass documents its fields beside them."""

from __future__ import annotations

import ast
import importlib
import inspect
import itertools
import textwrap
from collections.abc import Callable, Iterator
from typing import Any

import pytest

from tests.docs.test_public_api import _public_names

_PROJECT = ("workbench", "controllers", "tuning")


def _section(doc: str, name: str) -> bool:
    lines = doc.splitlines()
    return any(a.strip() == name and set(b.strip()) == {"-"} for a, b in itertools.pairwise(lines))


def _public_callables() -> Iterator[tuple[str, Callable[..., Any]]]:
    seen: set[int] = set()
    for module_name, name in _public_names():
        obj = getattr(importlib.import_module(module_name), name)
        if inspect.isfunction(obj) and obj.__module__.startswith(_PROJECT) and id(obj) not in seen:
            seen.add(id(obj))
            yield f"{obj.__module__}.{obj.__qualname__}", obj
        if inspect.isclass(obj) and obj.__module__.startswith(_PROJECT):
            for member_name, member in vars(obj).items():
                function = member.__func__ if isinstance(member, classmethod | staticmethod) else member
                if member_name.startswith("_") or not inspect.isfunction(function) or id(function) in seen:
                    continue
                seen.add(id(function))
                yield f"{obj.__module__}.{obj.__qualname__}.{member_name}", function


def _raises_input_error(function: Callable[..., Any]) -> bool:
    """Whether the function's own body (not a nested function's) raises WorkbenchInputError by name."""
    try:
        tree = ast.parse(textwrap.dedent(inspect.getsource(function)))
    except (OSError, TypeError, SyntaxError):
        return False
    body = tree.body[0]
    nodes = list(ast.iter_child_nodes(body))
    while nodes:
        node = nodes.pop()
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef | ast.Lambda | ast.ClassDef):
            continue
        if isinstance(node, ast.Raise) and node.exc is not None:
            call = node.exc.func if isinstance(node.exc, ast.Call) else node.exc
            if isinstance(call, ast.Name) and call.id == "WorkbenchInputError":
                return True
        nodes.extend(ast.iter_child_nodes(node))
    return False


_CALLABLES = sorted(_public_callables())


def test_the_check_sees_the_public_api() -> None:
    names = {name for name, _ in _CALLABLES}
    assert "workbench.vehicles.presets.make_vehicle" in names or any(n.endswith(".make_vehicle") for n in names)
    assert any(n.endswith("Simulation.run") for n in names)
    assert len(_CALLABLES) > 150


@pytest.mark.parametrize(("name", "function"), _CALLABLES, ids=[name for name, _ in _CALLABLES])
def test_numpydoc_sections(name: str, function: Callable[..., Any]) -> None:
    doc = inspect.getdoc(function) or ""
    signature = inspect.signature(function)
    parameters = [p for p in signature.parameters if p not in ("self", "cls")]
    missing = []
    if parameters and not _section(doc, "Parameters"):
        missing.append("Parameters")
    returns = signature.return_annotation
    if returns not in (None, "None", inspect.Signature.empty) and not (
        _section(doc, "Returns") or _section(doc, "Yields")
    ):
        missing.append("Returns")
    if _raises_input_error(function) and not _section(doc, "Raises"):
        missing.append("Raises")
    assert not missing, f"{name}'s docstring has no numpydoc {', '.join(missing)} section"


def test_a_missing_section_is_found() -> None:
    def documented(speed_kmh: float) -> float:
        """Twice the speed.

        Parameters
        ----------
        speed_kmh : float, km/h
            The speed.

        Returns
        -------
        float
            Twice it.
        """
        return 2 * speed_kmh

    def prose(speed_kmh: float) -> float:
        """Twice the speed (km/h)."""
        if speed_kmh < 0:
            raise WorkbenchInputError(f"speed_kmh must be >= 0; got {speed_kmh!r}")  # noqa: F821
        return 2 * speed_kmh

    test_numpydoc_sections("documented", documented)
    with pytest.raises(AssertionError, match="Parameters, Returns, Raises"):
        test_numpydoc_sections("prose", prose)
