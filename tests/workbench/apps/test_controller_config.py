"""Controller options from TOML files and key=value overrides."""

from __future__ import annotations

import tomllib
from pathlib import Path

import pytest

from controllers import CONTROLLERS
from controllers.clothoid import ClothoidConfig
from controllers.clothoid.filter_schedule import DEFAULT_FILTER
from tuning.filter_file import read_filter_file, write_filter_file
from workbench.apps.controller_config import build_config, config_template, read_controller_config
from workbench.base.errors import WorkbenchInputError


def test_file_then_overrides_with_types_and_relative_paths(tmp_path: Path) -> None:
    write_filter_file(tmp_path / "lead.json", DEFAULT_FILTER, source="test")
    path = tmp_path / "options.toml"
    path.write_text(
        '[clothoid]\nlookahead_mode = "fixed"\nfixed_lookahead_m = 12\nfilter_file = "lead.json"\n'
        "use_lead_filter = true\n\n[pure-pursuit]\nlookahead_gain_s = 0.5\n"
    )
    config = read_controller_config(path, "clothoid", ClothoidConfig, ["use_lead_filter=off", "min_lookahead_m=6"])
    assert config.lookahead_mode == "fixed"
    assert config.fixed_lookahead_m == 12.0 and isinstance(config.fixed_lookahead_m, float)
    # A file option is read where the config is loaded (relative to the config file), into its object.
    assert config.lead_filter == read_filter_file(tmp_path / "lead.json")
    assert config.use_lead_filter is False
    assert config.min_lookahead_m == 6.0
    assert read_controller_config(None, "clothoid", ClothoidConfig) == ClothoidConfig()
    assert build_config(ClothoidConfig, {}, ["filter_file=none"]).lead_filter is None


@pytest.mark.parametrize(
    ("overrides", "needle"),
    [
        (["frechet_threshold=0.3"], "unknown option 'frechet_threshold' for ClothoidConfig; allowed: lookahead_mode"),
        (["frechet_threshold_m"], "must look like key=value"),
        (["frechet_threshold_m=abc"], "option 'frechet_threshold_m' must be a number; got 'abc'"),
        (["use_lead_filter=maybe"], "option 'use_lead_filter' must be a boolean"),
        (["frechet_threshold_m=-1"], "frechet_threshold_m must be"),
    ],
)
def test_bad_overrides_name_the_key_and_what_is_allowed(overrides: list[str], needle: str) -> None:
    with pytest.raises(WorkbenchInputError) as info:
        build_config(ClothoidConfig, {}, overrides)
    assert needle in str(info.value)


def test_bad_files_are_named(tmp_path: Path) -> None:
    broken = tmp_path / "broken.toml"
    broken.write_text("[clothoid\n")
    with pytest.raises(WorkbenchInputError, match=r"broken\.toml.*not valid TOML"):
        read_controller_config(broken, "clothoid", ClothoidConfig)
    with pytest.raises(WorkbenchInputError, match=r"none\.toml': no such file"):
        read_controller_config(tmp_path / "none.toml", "clothoid", ClothoidConfig)
    wrong = tmp_path / "wrong.toml"
    wrong.write_text("[clothoid]\nfrechet_threshold_m = true\n")
    with pytest.raises(WorkbenchInputError, match=r"wrong.toml.*\[clothoid\].*frechet_threshold_m"):
        read_controller_config(wrong, "clothoid", ClothoidConfig)


@pytest.mark.parametrize("name", sorted(CONTROLLERS))
def test_every_controller_template_reads_back_to_its_defaults(name: str, tmp_path: Path) -> None:
    config_type = CONTROLLERS[name].config_type
    text = config_template(name, config_type)
    tomllib.loads(text)
    path = tmp_path / "template.toml"
    path.write_text(text)
    assert read_controller_config(path, name, config_type) == config_type()
