"""The console scripts' exit (`workbench.base.console`): main's exit code passed on, the collector frozen after it,
and both console scripts installed on it."""

from __future__ import annotations

import gc
import tomllib
from pathlib import Path

from workbench.base.console import console_exit


def test_the_exit_code_is_mains_and_the_collector_is_frozen_after_it() -> None:
    before = gc.get_freeze_count()
    try:
        assert console_exit(lambda: 3) == 3
        assert gc.get_freeze_count() > before  # every tracked object moved out of the collector's reach
    finally:
        gc.unfreeze()


def test_both_console_scripts_exit_through_it() -> None:
    project = tomllib.loads((Path(__file__).parents[3] / "pyproject.toml").read_text())
    assert project["project"]["scripts"] == {"workbench": "workbench.apps.cli:console", "tuning": "tuning.cli:console"}
