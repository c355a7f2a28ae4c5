"""CHANGELOG.md is in Keep a Changelog form (https://keepachangelog.com): one "## [X.Y.Z] - YYYY-MM-DD" heading per
release, newest first, the newest being pyproject.toml's version and 0.1.0 the first; only the standard change
types as sections; no issue numbers (the history is told for users, not by tracker)."""

import datetime
import re
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
RELEASE = re.compile(r"^## \[(\d+)\.(\d+)\.(\d+)\] - (\d{4}-\d{2}-\d{2})$")
CHANGE_TYPES = {"Added", "Changed", "Deprecated", "Removed", "Fixed", "Security"}


def _lines() -> list[str]:
    return (ROOT / "CHANGELOG.md").read_text(encoding="utf-8").splitlines()


def _releases() -> list[tuple[tuple[int, int, int], datetime.date]]:
    found = []
    for line in _lines():
        if line.startswith("## ") and not line.startswith("## [Unreleased]"):
            match = RELEASE.match(line)
            assert match, f"release heading not in Keep a Changelog form: {line!r}"
            version = (int(match[1]), int(match[2]), int(match[3]))
            found.append((version, datetime.date.fromisoformat(match[4])))
    return found


def test_releases_newest_first_from_0_1_0():
    releases = _releases()
    assert releases, "no release heading"
    versions = [version for version, _ in releases]
    dates = [date for _, date in releases]
    assert versions == sorted(versions, reverse=True) and len(set(versions)) == len(versions)
    assert dates == sorted(dates, reverse=True)
    assert versions[-1] == (0, 1, 0)


def test_newest_release_is_the_package_version():
    project = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    newest = ".".join(str(part) for part in _releases()[0][0])
    assert project["version"] == newest


def test_sections_are_change_types_and_each_release_has_one():
    release_count = 0
    sections_in_release = 0
    for line in [*_lines(), "## [0.0.0] - 1970-01-01"]:  # a sentinel closes the last release
        if line.startswith("## "):
            assert release_count == 0 or sections_in_release > 0, "a release without a change-type section"
            release_count += 1
            sections_in_release = 0
        elif line.startswith("### "):
            assert line[4:] in CHANGE_TYPES, f"section {line[4:]!r} is not one of {sorted(CHANGE_TYPES)}"
            sections_in_release += 1


def test_no_issue_numbers():
    found = [line for line in _lines() if re.search(r"\bissues?\s*#?\d+", line, re.IGNORECASE)]
    assert not found, found
