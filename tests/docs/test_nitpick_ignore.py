"""docs/conf.py's `nitpick_ignore_regex` lets through only what cannot be a link to the workbench's own reference
(third-party types, type phrases, units, type variables): no pattern matches a class the workbench defines, so a
signature naming one of them fails the nitpicky build until the class is documented. Reads conf.py and the sources
without Sphinx and without importing them."""

from __future__ import annotations

import ast
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
PACKAGES = ("workbench", "controllers", "tuning")


def ignore_patterns(conf: Path) -> list[tuple[str, str]]:
    """The (role, target) pairs of `nitpick_ignore_regex` in the Sphinx configuration at `conf`."""
    for node in ast.parse(conf.read_text(encoding="utf-8")).body:
        if isinstance(node, ast.Assign) and any(getattr(t, "id", None) == "nitpick_ignore_regex" for t in node.targets):
            return list(ast.literal_eval(node.value))
    raise AssertionError(f"no nitpick_ignore_regex in {conf}")


def own_classes() -> list[tuple[str, str]]:
    """(module, class name) of every class defined at the top level of a module of the workbench's packages."""
    found = []
    for package in PACKAGES:
        for source in sorted((ROOT / package).rglob("*.py")):
            module = ".".join(source.relative_to(ROOT).with_suffix("").parts).removesuffix(".__init__")
            for node in ast.parse(source.read_text(encoding="utf-8")).body:
                if isinstance(node, ast.ClassDef):
                    found.append((module, node.name))
    return found


def ignored(patterns: list[tuple[str, str]], target: str) -> bool:
    """Whether Sphinx would leave a missing py:class reference to `target` unreported (it full-matches both)."""
    return any(re.fullmatch(role, "py:class") and re.fullmatch(pattern, target) for role, pattern in patterns)


def test_no_ignore_pattern_hides_a_class_of_the_workbench() -> None:
    patterns = ignore_patterns(ROOT / "docs" / "conf.py")
    classes = own_classes()
    assert len(classes) > 100, "the packages' classes were not found"
    hidden = [f"{m}.{n}" for m, n in classes if ignored(patterns, n) or ignored(patterns, f"{m}.{n}")]
    assert not hidden, f"nitpick_ignore_regex hides the workbench's own types: {hidden}"


def test_the_check_finds_a_pattern_naming_an_own_type() -> None:
    """The check can fail: a pattern naming one of the workbench's types, bare or qualified, is caught."""
    patterns = [("py:.*", r"(.*\.)?(KnownDelays|PlantLags)")]
    assert ignored(patterns, "KnownDelays")
    assert ignored(patterns, "controllers.clothoid.loop_analysis.PlantLags")
    assert not ignored(patterns, "numpy.ndarray")
