"""The `workbench` CLI's dispatch: one table of commands, the one the parser offers, and an unknown controller
refused by the registry that knows the names, before anything is built."""

from __future__ import annotations

import argparse
from pathlib import Path

import pytest

import controllers
from controllers import CONTROLLERS
from workbench.apps import cli
from workbench.base.errors import WorkbenchInputError


def test_the_table_holds_exactly_the_commands_the_parser_offers() -> None:
    (sub,) = [a for a in cli._parser(None)._actions if isinstance(a, argparse._SubParsersAction)]
    assert set(cli.COMMANDS) == set(sub.choices)


def test_main_runs_the_command_the_table_names(monkeypatch, capsys) -> None:
    seen: list[str] = []
    monkeypatch.setitem(cli.COMMANDS, "vehicles", lambda args: seen.append(args.command) or 7)
    assert cli.main(["vehicles"]) == 7 and seen == ["vehicles"]
    assert capsys.readouterr().out == ""


def test_the_cli_module_resolves_no_attribute_lazily() -> None:
    assert "__getattr__" not in vars(cli)
    with pytest.raises(AttributeError):
        cli.Simulation  # noqa: B018  (the simulator is patched where it is defined)


def test_the_registry_refuses_an_unknown_name_naming_the_registered_ones() -> None:
    with pytest.raises(WorkbenchInputError, match=r"^unknown controller 'magic'; choose one of clothoid, pure-pursuit"):
        CONTROLLERS.require("magic")
    CONTROLLERS.require("stanley")  # a registered name passes


@pytest.mark.parametrize(
    "argv",
    [
        ["run", "dlc", "--controller", "magic", "--out", "OUT"],
        ["export-fmu", "magic", "--path", "dlc", "--out", "OUT.fmu"],
        ["controllers", "--show", "magic"],
    ],
)
def test_an_unknown_controller_is_refused_without_building_one(argv, tmp_path: Path, monkeypatch, capsys) -> None:
    def build(*_args, **_kwargs):
        raise AssertionError("a controller was built to learn that its name is unknown")

    monkeypatch.setattr(controllers, "make_controller", build)
    argv = [str(tmp_path / a) if a.startswith("OUT") else a for a in argv]
    assert cli.main(argv) == 2
    assert "workbench: error: unknown controller 'magic'; choose one of clothoid" in capsys.readouterr().err


@pytest.mark.parametrize(
    "argv",
    [
        ["run", "dlc", "--out", "o"],
        ["compare", "dlc", "--controllers", "stanley", "--out", "o"],
        ["export-fmu", "stanley", "--path", "dlc", "--out", "o.fmu"],
    ],
)
def test_the_speed_plan_and_rate_options_are_one_set_with_one_set_of_defaults(argv) -> None:
    args = cli._parser(argv[0]).parse_args(argv)
    assert (args.speed, args.lat_accel_g, args.controller_rate_hz) == (30.0, 0.3, 50.0)
    options = ["--speed", "45", "--lat-accel-g", "0.2", "--controller-rate-hz", "100"]
    changed = cli._parser(argv[0]).parse_args([*argv, *options])
    assert (changed.speed, changed.lat_accel_g, changed.controller_rate_hz) == (45.0, 0.2, 100.0)
