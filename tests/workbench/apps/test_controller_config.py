"""Controller options from TOML files and key=value overrides."""

from __future__ import annotations

import dataclasses
import math
import tomllib
from pathlib import Path

import pytest

from controllers import CONTROLLERS
from controllers.clothoid import ClothoidConfig
from controllers.clothoid.filter_schedule import DEFAULT_FILTER
from controllers.config_checks import Choice, Flag, Number, Whole, option_rule
from tuning.filter_file import read_filter_file, write_filter_file
from workbench.apps.controller_config import (
    FILE_OPTIONS,
    build_config,
    config_template,
    missing_table_warning,
    read_controller_config,
)
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


@pytest.mark.parametrize(
    ("text", "needle"),
    [
        ("[stanly]\ngain_per_s = 3.0\n", r"\[stanly\] names no controller; did you mean \[stanley\]\?"),
        ("[Clothoid]\nfrechet_threshold_m = 0.1\n", r"\[Clothoid\] names no controller; did you mean \[clothoid\]\?"),
        ("[nothing-alike]\n", r"\[nothing-alike\] names no controller; the tables a file may hold: \[clothoid\]"),
        ("frechet_threshold_m = 0.1\n[clothoid]\n", r"frechet_threshold_m = 0\.1 is outside any table; options go in"),
    ],
)
def test_tables_naming_no_controller_and_keys_outside_tables_are_refused(
    text: str, needle: str, tmp_path: Path
) -> None:
    path = tmp_path / "options.toml"
    path.write_text(text)
    with pytest.raises(WorkbenchInputError, match=r"options\.toml'.*" + needle):
        read_controller_config(path, "clothoid", ClothoidConfig)


def test_other_controllers_tables_are_allowed_and_a_missing_table_is_warned_about(tmp_path: Path) -> None:
    path = tmp_path / "options.toml"
    path.write_text("[stanley]\ngain_per_s = 3.0\n\n[pure-pursuit]\nlookahead_gain_s = 0.5\n")
    warnings: list[str] = []
    assert read_controller_config(path, "clothoid", ClothoidConfig, warn=warnings.append) == ClothoidConfig()
    assert warnings == [
        f"controller config file {str(path)!r} has no [clothoid] table (only [stanley], [pure-pursuit]): clothoid "
        "runs with its default options"
    ]
    stanley = CONTROLLERS["stanley"].config_type
    assert read_controller_config(path, "stanley", stanley, warn=warnings.append).gain_per_s == 3.0
    assert len(warnings) == 1  # its table is there: no warning
    empty = tmp_path / "empty.toml"
    empty.write_text("")
    assert "has no [stanley] table (no tables)" in str(missing_table_warning(empty, "stanley"))


@pytest.mark.parametrize(
    ("line", "message"),
    [
        ('frechet_threshold_m = "0.1"', "option 'frechet_threshold_m' must be a number; got '0.1' (a file's numbers"),
        ('use_lead_filter = "false"', "option 'use_lead_filter' must be a boolean; got 'false' (a file's numbers"),
        ("use_lead_filter = 0", "option 'use_lead_filter' must be a boolean; got 0"),
        ("lookahead_mode = 3", "option 'lookahead_mode' must be a text; got 3"),
    ],
)
def test_a_files_values_are_taken_as_typed_not_parsed_from_text(line: str, message: str, tmp_path: Path) -> None:
    path = tmp_path / "options.toml"
    path.write_text(f"[clothoid]\n{line}\n")
    with pytest.raises(WorkbenchInputError) as info:
        read_controller_config(path, "clothoid", ClothoidConfig)
    assert f"[clothoid]: {message}" in str(info.value)


def test_override_text_is_parsed() -> None:
    overrides = ["frechet_threshold_m=0.1", "use_lead_filter=false"]
    config = read_controller_config(None, "clothoid", ClothoidConfig, overrides)
    assert config.frechet_threshold_m == pytest.approx(0.1, abs=0.0) and config.use_lead_filter is False


def test_run_warns_of_a_file_without_its_table_and_refuses_a_misspelt_one(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from workbench.apps.cli import main

    shared = tmp_path / "pp.toml"
    shared.write_text("[pure-pursuit]\nlookahead_gain_s = 0.5\n")
    argv = ["run", "dlc", "--controller", "stanley", "--out", str(tmp_path / "out"), "--no-plots", "--max-time-s", "1"]
    main([*argv, "--controller-config", str(shared)])
    err = capsys.readouterr().err
    assert "workbench: warning: controller config file" in err and "has no [stanley] table (only [pure-pursuit])" in err
    misspelt = tmp_path / "bad.toml"
    misspelt.write_text("[stanly]\ngain_per_s = 3.0\n")
    assert main([*argv, "--overwrite", "--controller-config", str(misspelt)]) == 2
    err = capsys.readouterr().err
    assert "workbench: error: " in err and "[stanly] names no controller; did you mean [stanley]?" in err


def test_compare_checks_both_forms_of_its_config_files(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from workbench.apps.cli import main

    shared = tmp_path / "pp.toml"
    shared.write_text("[pure-pursuit]\nlookahead_gain_s = 0.5\n")
    misspelt = tmp_path / "bad.toml"
    misspelt.write_text("[pure-pursuit]\n[Stanley]\n")
    # A missing --track stops compare after its configs are checked: no run is needed to see the warning.
    argv = ["compare", "dlc", "--controllers", "stanley,pure-pursuit", "--out", str(tmp_path / "out")]
    argv += ["--track", str(tmp_path / "none.csv")]
    assert main([*argv, "--controller-config", str(shared)]) == 2
    err = capsys.readouterr().err
    assert err.count("workbench: warning:") == 1 and "has no [stanley] table (only [pure-pursuit])" in err
    for form in (str(misspelt), f"pure-pursuit={misspelt}"):
        assert main([*argv, "--controller-config", form]) == 2
        assert "[Stanley] names no controller; did you mean [stanley]?" in capsys.readouterr().err
    # Its own file for stanley: no warning about the shared file's missing table.
    own = tmp_path / "stanley.toml"
    own.write_text("[stanley]\ngain_per_s = 2.0\n")
    assert main([*argv, "--controller-config", str(shared), "--controller-config", f"stanley={own}"]) == 2
    assert "warning" not in capsys.readouterr().err


def test_a_study_specs_controller_config_is_checked_alike(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from workbench.apps.studies import load_spec

    spec = tmp_path / "spec.toml"
    study = '[study]\nscenarios = ["dlc"]\ncontrollers = ["stanley"]\nvehicles = ["kinematic-bicycle"]\n'
    spec.write_text(study + 'controller_config = "options.toml"\n')
    (tmp_path / "options.toml").write_text("[stanly]\ngain_per_s = 3.0\n")
    with pytest.raises(WorkbenchInputError, match=r"\[stanly\] names no controller; did you mean \[stanley\]\?"):
        load_spec(spec)
    (tmp_path / "options.toml").write_text('[stanley]\ngain_per_s = "3.0"\n')
    with pytest.raises(WorkbenchInputError, match=r"option 'gain_per_s' must be a number; got '3\.0'"):
        load_spec(spec)
    (tmp_path / "options.toml").write_text("[pure-pursuit]\n")
    load_spec(spec)
    assert "has no [stanley] table (only [pure-pursuit])" in capsys.readouterr().err


# ------------------------------------------------------------------------------ the options' documentation
def _documented_fields(name: str) -> list[tuple[type, dataclasses.Field]]:
    config_type = CONTROLLERS[name].config_type
    return [(config_type, f) for f in dataclasses.fields(config_type) if f.init]


@pytest.mark.parametrize("name", sorted(CONTROLLERS))
def test_every_option_has_a_unit_a_range_and_a_meaning_and_the_template_prints_them(name: str) -> None:
    config_type = CONTROLLERS[name].config_type
    template = config_template(name, config_type)
    file_options = {option.field: key for key, option in FILE_OPTIONS.items()}
    for _, f in _documented_fields(name):
        rule = option_rule(f)
        assert rule is not None, f"{config_type.__name__}.{f.name} has no rule (config_checks.option)"
        doc = f.metadata.get("doc")
        assert isinstance(doc, str) and len(doc) > 10 and "\n" not in doc, f"{f.name}: {doc!r}"
        assert rule.unit and rule.allowed(), f.name
        shown = file_options.get(f.name, f.name)
        block = template.split(f"\n# {shown}: ", 1)[1].split("\n\n", 1)[0]  # its comment and its line
        assert f"unit {rule.unit}; default " in " ".join(block.split("\n#   ")), shown
        if f.name not in file_options:
            assert rule.allowed() in " ".join(block.replace("\n#   ", " ").split()), shown
            assert f"\n{f.name} = " in f"\n{block}", shown


def _outside_and_inside(rule: object) -> tuple[list[object], list[object]]:
    """Values just outside the range a rule prints, and its ends (or its choices) inside it."""
    if isinstance(rule, Number):
        below = rule.low if rule.low_open else math.nextafter(rule.low, -math.inf)
        inside = [rule.high] + ([] if rule.low_open else [rule.low])
        return [below, math.nextafter(rule.high, math.inf), math.nan], inside
    if isinstance(rule, Whole):
        return [rule.low - 1, rule.high + 1, float(rule.low)], [rule.low, rule.high]
    if isinstance(rule, Choice):
        return ["not-a-choice"], list(rule.choices())
    if isinstance(rule, Flag):
        return [1, "true"], [True, False]
    return [3.0], [None]  # Instance: only its object or None


@pytest.mark.parametrize("name", sorted(CONTROLLERS))
def test_the_printed_range_is_the_one_the_config_checks(name: str) -> None:
    """Just outside an option's printed range its config refuses the value, naming the option and that range;
    at its ends the option's own check passes (a refusal there, if any, is of a relation to another option)."""
    for config_type, f in _documented_fields(name):
        rule = option_rule(f)
        outside, inside = _outside_and_inside(rule)
        said = {Number: "a finite number in", Whole: "a whole number in", Choice: "one of", Flag: "true or false"}
        own = f"{f.name} must be {said.get(type(rule), 'a ')}"  # the rule's own message (config_checks)
        for value in outside:
            with pytest.raises(WorkbenchInputError) as info:
                config_type(**{f.name: value})
            message = str(info.value)
            assert message.startswith(own), (f.name, value, message)
            if isinstance(rule, Number):
                interval = rule.allowed().split(" (")[0].split(", or")[0]
                assert interval in message, (f.name, value, message)
        for value in inside:
            try:
                config_type(**{f.name: value})
            except WorkbenchInputError as exc:
                assert not str(exc).startswith(own), (f.name, value, str(exc))
