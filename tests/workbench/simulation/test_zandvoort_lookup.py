"""Where `zandvoort` finds its track file without --track (issue 20, item 14): $WORKBENCH_ZANDVOORT_CSV, then
tracks/ of the current directory, then ../shared/tracks/ beside the checkout, under either name; and the message
naming every place when none holds it. Only the TUMFTM file itself (its SHA-256) is named zandvoort and given the
paper's verdict; any other file is named by its file."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from workbench.apps.cli import main
from workbench.apps.paper import zandvoort_skip_reason
from workbench.base.errors import WorkbenchInputError
from workbench.simulation import scenarios
from workbench.simulation.scenarios import (
    ZANDVOORT_ENV,
    ScenarioOptions,
    is_zandvoort_file,
    make_scenario,
    zandvoort_places,
    zandvoort_track_file,
)

SHARED_TRACK = Path(__file__).resolve().parents[4] / "shared" / "tracks" / "Zandvoort_track.csv"


def _track(folder: Path, name: str, side_m: float) -> Path:
    """A small closed TUMFTM file: a square of side `side_m` (so each file's path length tells which was read)."""
    folder.mkdir(parents=True, exist_ok=True)
    rows = [(0, 0), (side_m, 0), (side_m, side_m), (0, side_m)]
    file = folder / name
    file.write_text("# x_m,y_m,w_tr_right_m,w_tr_left_m\n" + "".join(f"{x},{y},4,4\n" for x, y in rows))
    return file


@pytest.fixture
def nowhere(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> Path:
    """No --track, no environment variable, an empty current directory and a checkout with nothing beside it."""
    monkeypatch.delenv(ZANDVOORT_ENV, raising=False)
    (tmp_path / "cwd").mkdir()
    monkeypatch.chdir(tmp_path / "cwd")
    monkeypatch.setattr(scenarios, "CHECKOUT_ROOT", tmp_path / "checkout")
    return tmp_path


def test_every_place_looked_in_is_named(nowhere: Path) -> None:
    with pytest.raises(WorkbenchInputError) as info:
        zandvoort_track_file()
    message = str(info.value)
    places = [nowhere / "cwd" / "tracks", nowhere / "shared" / "tracks"]
    expected = [folder / name for folder in places for name in ("Zandvoort_track.csv", "Zandvoort.csv")]
    assert zandvoort_places() == expected
    assert f"none of these exists: {', '.join(str(p) for p in expected)}; download it" in message
    assert "--track FILE" in message and ZANDVOORT_ENV in message


def test_a_tracks_folder_of_the_current_directory_is_used(nowhere: Path) -> None:
    found = _track(nowhere / "cwd" / "tracks", "Zandvoort.csv", 50.0)
    beside = _track(nowhere / "shared" / "tracks", "Zandvoort_track.csv", 80.0)
    assert zandvoort_track_file() == found.resolve()  # the current directory before the checkout's neighbour
    scenario = make_scenario("zandvoort")
    # The loop through the 50 m square's corners: nearly the circle through them.
    assert scenario.path.length_m == pytest.approx(math.pi * 50.0 * math.sqrt(2.0), rel=0.03)
    assert str(found.resolve()) in scenario.description
    found.unlink()
    assert zandvoort_track_file() == beside


def test_the_environment_variable_and_track_option_come_first(nowhere: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    _track(nowhere / "cwd" / "tracks", "Zandvoort_track.csv", 50.0)
    named = _track(nowhere / "elsewhere", "mine.csv", 60.0)
    monkeypatch.setenv(ZANDVOORT_ENV, str(named))
    assert zandvoort_track_file() == named
    option = _track(nowhere / "other", "option.csv", 70.0)
    assert zandvoort_track_file(option) == option
    missing = nowhere / "gone.csv"
    with pytest.raises(WorkbenchInputError, match=r"track file '.*gone\.csv' does not exist \(named by --track\)"):
        zandvoort_track_file(missing)
    monkeypatch.setenv(ZANDVOORT_ENV, str(missing))
    with pytest.raises(WorkbenchInputError, match=rf"does not exist \(named by \${ZANDVOORT_ENV}\)"):
        zandvoort_track_file()  # a file named explicitly is not replaced by one found elsewhere


@pytest.mark.skipif(not SHARED_TRACK.is_file(), reason=f"{SHARED_TRACK} not found (third-party data)")
def test_this_checkout_finds_the_shared_track_beside_it(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    monkeypatch.delenv(ZANDVOORT_ENV, raising=False)
    monkeypatch.chdir(tmp_path)
    assert zandvoort_track_file() == SHARED_TRACK
    assert make_scenario("zandvoort").path.has_widths


def _line(folder: Path, name: str, length_m: float = 60.0) -> Path:
    """A straight open path (x,y CSV): nothing like Zandvoort."""
    folder.mkdir(parents=True, exist_ok=True)
    file = folder / name
    file.write_text("x,y\n" + "".join(f"{x:g},0\n" for x in np.linspace(0.0, length_m, 13)))
    return file


def test_another_file_given_for_zandvoort_is_named_by_the_file(nowhere: Path, capsys: pytest.CaptureFixture) -> None:
    """A 60 m line given with --track is run as itself: named by its file, said to be another track, and given no
    verdict of the paper's; even a copy of it named Zandvoort_track.csv where the real one is looked for."""
    good = _line(nowhere / "mine", "good.csv")
    assert not is_zandvoort_file(good)
    scenario = make_scenario("zandvoort", ScenarioOptions(track_file=good))
    assert scenario.name == "good" and scenario.path.length_m == pytest.approx(60.0, abs=1e-6)
    assert "not the TUMFTM Zandvoort track file" in scenario.description and str(good) in scenario.description
    reason = zandvoort_skip_reason(ScenarioOptions(track_file=good))
    assert reason is not None and f"the track file {good} is not the TUMFTM Zandvoort track" in reason
    found = _track(nowhere / "cwd" / "tracks", "Zandvoort_track.csv", 50.0)
    assert make_scenario("zandvoort").name == "Zandvoort_track"
    assert str(found.resolve()) in (zandvoort_skip_reason(ScenarioOptions()) or "")

    out = nowhere / "run"
    args = ["run", "zandvoort", "--track", str(good), "--controller", "pure-pursuit", "--no-plots", "--out", str(out)]
    assert main(args) == 0
    captured = capsys.readouterr()
    assert captured.out.startswith("good: pure-pursuit on kinematic-bicycle")
    assert "zandvoort" not in captured.out.lower()
    assert f"workbench: warning: waypoints from {good}, given for zandvoort but not the TUMFTM" in captured.err


@pytest.mark.skipif(not SHARED_TRACK.is_file(), reason=f"{SHARED_TRACK} not found (third-party data)")
def test_the_tumftm_file_is_zandvoort_and_gets_the_papers_verdict(tmp_path: Path) -> None:
    """The real file, under any name, is recognised by its bytes; one byte changed and it is another track."""
    copy = tmp_path / "any name.csv"
    copy.write_bytes(SHARED_TRACK.read_bytes())
    assert is_zandvoort_file(SHARED_TRACK) and is_zandvoort_file(copy)
    assert make_scenario("zandvoort", ScenarioOptions(track_file=copy)).name == "zandvoort"
    assert zandvoort_skip_reason(ScenarioOptions(track_file=SHARED_TRACK)) is None
    edited = tmp_path / "edited.csv"
    edited.write_bytes(SHARED_TRACK.read_bytes().replace(b"5.074", b"5.075", 1))
    assert not is_zandvoort_file(edited)
    assert make_scenario("zandvoort", ScenarioOptions(track_file=edited)).name == "edited"
