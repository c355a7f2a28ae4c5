"""The synopses of the user guide's CLI pages (docs/guide/cli.md, docs/guide/tuning.md) agree with the parsers:
every long option a command takes is in its synopsis, and every option its synopsis offers (`[--x`, `(--x`,
`| --x`) is one the command takes."""

from __future__ import annotations

import argparse
import re
from pathlib import Path

import pytest

from tuning.cli import _parser as tuning_parser
from workbench.apps.cli import _parser as workbench_parser

GUIDE = Path(__file__).resolve().parents[2] / "docs" / "guide"
#: Options every command has, said once in the page's text rather than in each synopsis.
SAID_ONCE = {"workbench": {"--help"}, "tuning": {"--help", "--overwrite"}}
#: A command whose synopsis refers to another's options ("compare ... and run's other ... options").
INHERITS = {("workbench", "compare"): "run"}
_OFFERED = re.compile(r"(?:\[|\(|\|\s?)(--[a-z][a-z0-9-]*)")


def _commands(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return dict(sub.choices)


def _long_options(parser: argparse.ArgumentParser) -> set[str]:
    return {o for action in parser._actions for o in action.option_strings if o.startswith("--")}


def synopses(page: Path, program: str) -> dict[str, str]:
    """Each command's synopsis text in the page's first code block that shows `program COMMAND` lines: from its
    first line to the next command's (continuation lines included)."""
    blocks = re.findall(r"```(?:text)?\n(.*?)```", page.read_text(encoding="utf-8"), re.DOTALL)
    block = next(b for b in blocks if re.search(rf"^{program} [a-z]", b, re.MULTILINE))
    found: dict[str, str] = {}
    command = None
    for line in block.splitlines():
        start = re.match(rf"{program} ([a-z][a-z0-9-]*)", line)
        if start:
            command = start.group(1)
        elif not line.startswith(" "):
            command = None
        if command:
            found[command] = found.get(command, "") + line + "\n"
    return found


def _pages() -> list[tuple[str, Path, argparse.ArgumentParser]]:
    return [("workbench", GUIDE / "cli.md", workbench_parser()), ("tuning", GUIDE / "tuning.md", tuning_parser())]


@pytest.mark.parametrize(("program", "page", "parser"), _pages(), ids=["workbench", "tuning"])
def test_every_option_of_every_command_is_in_its_synopsis(program, page, parser) -> None:
    texts = synopses(page, program)
    missing = {}
    for name, command in _commands(parser).items():
        text = texts.get(name, "") + texts.get(INHERITS.get((program, name), ""), "")
        absent = sorted(o for o in _long_options(command) - SAID_ONCE[program] if not re.search(rf"{o}\b", text))
        if absent:
            missing[name] = absent
    assert not missing, f"{page.name}: options missing from the synopses: {missing}"


@pytest.mark.parametrize(("program", "page", "parser"), _pages(), ids=["workbench", "tuning"])
def test_every_option_a_synopsis_offers_exists(program, page, parser) -> None:
    commands = _commands(parser)
    unknown = {}
    for name, text in synopses(page, program).items():
        assert name in commands, f"{page.name}: `{program} {name}` is not a command"
        wrong = sorted(set(_OFFERED.findall(text)) - _long_options(commands[name]))
        if wrong:
            unknown[name] = wrong
    assert not unknown, f"{page.name}: synopses offer options the commands do not take: {unknown}"


def test_the_check_sees_a_missing_and_an_unknown_option() -> None:
    """The checks can fail: a synopsis without one of the command's options, and one offering an unknown one."""
    text = "workbench fig17 --out DIR [--speed 30] [--no-such-option]\n"
    command = _commands(workbench_parser())["fig17"]
    assert "--allow-long-run" in _long_options(command) and "--allow-long-run" not in text
    assert set(_OFFERED.findall(text)) - _long_options(command) == {"--no-such-option"}
