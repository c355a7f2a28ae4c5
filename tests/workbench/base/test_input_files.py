"""Reading input files safely: every problem a WorkbenchInputError `<label>: <problem>`, never an OSError,
UnicodeDecodeError or RecursionError."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from workbench.base.errors import WorkbenchInputError
from workbench.base.input_files import (
    MAX_NESTING,
    check_input_file,
    nesting_depth,
    parse_json,
    parse_toml,
    read_json,
    read_toml,
)

#: TOML nested 5000 deep three ways: inline arrays and inline tables (tomllib recurses: RecursionError), and a
#: dotted table header (tomllib builds the dict without recursing: only the depth check sees it).
DEEP_TOML = {
    "arrays": "x = " + "[" * 5000 + "]" * 5000 + "\n",
    "inline tables": "x = " + "{a = " * 5000 + "1" + "}" * 5000 + "\n",
    "dotted header": "[" + ".".join(["a"] * 5000) + "]\nx = 1\n",
}


@pytest.mark.parametrize("text", DEEP_TOML.values(), ids=DEEP_TOML.keys())
def test_deeply_nested_toml_is_refused_naming_the_file(tmp_path: Path, text: str) -> None:
    path = tmp_path / "deep.toml"
    path.write_text(text)
    with pytest.raises(WorkbenchInputError, match=rf"^spec file 'x': nested deeper than {MAX_NESTING} levels"):
        read_toml(path, "spec file 'x'")


@pytest.mark.parametrize("text", ["[" * 5000 + "]" * 5000, '{"a": ' * 5000 + "1" + "}" * 5000, "[" * 100 + "]" * 100])
def test_deeply_nested_json_is_refused(text: str) -> None:
    with pytest.raises(WorkbenchInputError, match=r"lag\.json: nested deeper than 64 levels"):
        parse_json(text, "lag.json")


def test_the_formats_own_nesting_is_fine() -> None:
    spec = parse_toml("[random.clothoid]\nx = { choice = [[1, 2], [3, 4]] }\n", "spec")
    assert nesting_depth(spec) == 6  # random, clothoid, x, choice, the list, its lists
    assert parse_json('{"schedule": [{"speed_kmh": 20}]}', "lead.json") == {"schedule": [{"speed_kmh": 20}]}
    assert nesting_depth(3.0) == 0 and nesting_depth([]) == 1


@pytest.mark.parametrize(
    ("make", "problem"),
    [
        (lambda d: d / "missing.toml", "no such file"),
        (lambda d: d, "a folder, not a file"),
        (lambda d: d / "file.txt" / "x.toml", "no such file ('{d}/file.txt' is a file, not a folder)"),
        (lambda d: d / "latin1.toml", "not UTF-8 text (byte 11: invalid continuation byte)"),
        (lambda d: d / "broken.toml", "not valid TOML: Expected ']' at the end of a table declaration (at line 1"),
    ],
)
def test_unreadable_toml_files_are_named(tmp_path: Path, make, problem: str) -> None:
    (tmp_path / "file.txt").write_text("x")
    (tmp_path / "latin1.toml").write_bytes('name = "caf\xe9 au lait"\n'.encode("latin-1"))
    (tmp_path / "broken.toml").write_text("[clothoid\n")
    with pytest.raises(WorkbenchInputError) as info:
        read_toml(make(tmp_path), "controller config file 'c.toml'")
    assert str(info.value).startswith(f"controller config file 'c.toml': {problem.format(d=tmp_path)}")


def test_json_problems_are_named(tmp_path: Path) -> None:
    with pytest.raises(WorkbenchInputError, match=r"^lead\.json: not valid JSON: Expecting property name enclosed"):
        parse_json("{nope", "lead.json")
    with pytest.raises(WorkbenchInputError, match=r"^f: not valid JSON: NaN is not a number JSON allows"):
        parse_json('{"psi": NaN}', "f", allow_nan=False)
    assert parse_json('{"psi": 1.5}', "f", allow_nan=False) == {"psi": 1.5}
    with pytest.raises(WorkbenchInputError, match=r"^f: a folder, not a file"):
        read_json(tmp_path, "f")


def test_check_input_file(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    good = tmp_path / "good.csv"
    good.write_text("x,y\n")
    assert check_input_file(good, "--track") == good
    with pytest.raises(WorkbenchInputError, match=r"^--track: no such file$"):
        check_input_file(tmp_path / "nope.csv", "--track")
    with pytest.raises(WorkbenchInputError, match=r"^--track: a folder, not a file$"):
        check_input_file(tmp_path, "--track")
    with pytest.raises(WorkbenchInputError, match=r"^--track: no such file \('.*good.csv' is a file, not a folder\)"):
        check_input_file(good / "x.csv", "--track")
    monkeypatch.setattr(os, "access", lambda *_args, **_kw: False)  # as for a user without read permission
    with pytest.raises(WorkbenchInputError, match=r"^--track: not readable \(permission denied\)$"):
        check_input_file(good, "--track")


@pytest.mark.skipif(os.name != "posix" or os.geteuid() == 0, reason="root reads any file")
def test_an_unreadable_file_is_refused(tmp_path: Path) -> None:
    path = tmp_path / "secret.toml"
    path.write_text("x = 1\n")
    path.chmod(0)
    try:
        with pytest.raises(WorkbenchInputError, match="not readable"):
            check_input_file(path, "--controller-config")
        with pytest.raises(WorkbenchInputError, match="not readable"):
            read_toml(path, "--controller-config")
    finally:
        path.chmod(0o600)
