"""Vehicle-aware tuning: every preset ships its own lead-filter schedule, lags and curvature limits, current with its
preset and with PRESET_TUNING_OPTIONS; tuning_for finds them (payload aside); any other vehicle gets its own, made
once into a cache; a generation that fails names the commands to run by hand."""

from __future__ import annotations

import dataclasses
import itertools
import json
import math
import shutil
from pathlib import Path

import numpy as np
import pytest
from quick_tuning import QUICK

import tuning.preset_tuning as preset_tuning
from controllers.clothoid.curvature_limits import CurvatureLimits
from controllers.clothoid.filter_schedule import DEFAULT_FILTER, FilterSchedule
from controllers.clothoid.lead_filter import LeadFilterParams
from controllers.clothoid.preview_model import HANDLING_GRID_G
from controllers.clothoid.sideslip_release import SideslipRelease
from controllers.clothoid.vehicle_tuning import VehicleTuning
from tuning.cli import _parser as tuning_parser
from tuning.filter_file import read_filter_file
from tuning.lag_fit import DELAY_FIT_MAX_ZETA
from tuning.own_tuning import cache_key, generate_vehicle_tuning, tuning_for
from tuning.preset_tuning import PRESET_TUNING_OPTIONS, PresetTuningOptions, regenerate_command
from tuning.tuning_dirs import (
    CACHE_ENV,
    LEAD_FILE,
    LIMITS_FILE,
    MANIFEST_FILE,
    VEHICLE_FILE,
    canonical_vehicle_toml,
    files_sha256,
    params_sha256,
    read_manifest,
    read_vehicle_tuning,
    shipped_tuning_root,
)
from workbench.base.errors import WorkbenchInputError
from workbench.base.user_cache import UnsafeCacheError
from workbench.vehicles import list_presets, make_vehicle, preset_text
from workbench.vehicles.presets import params_from_toml
from workbench.vehicles.steering_lag import SteeringLag

PRESETS = tuple(list_presets())
pytestmark = pytest.mark.usefixtures("private_cache")  # no test reads or writes the user's cache


@pytest.mark.parametrize("name", PRESETS)
def test_the_shipped_tuning_is_made_for_the_current_preset_and_options(name: str) -> None:
    manifest = read_manifest(shipped_tuning_root() / name)
    vehicle = make_vehicle(name)
    regenerate = f"stale: regenerate with `{regenerate_command(name)}` (and commit the files)"
    assert manifest["preset"] == name
    assert manifest["params_sha256"] == params_sha256(vehicle), f"{name} preset parameters changed; {regenerate}"
    assert manifest["options"] == PRESET_TUNING_OPTIONS.for_model(vehicle.name).to_dict(), (
        f"PRESET_TUNING_OPTIONS changed; {regenerate}"
    )
    assert preset_tuning.stale_reasons(name, shipped_tuning_root() / name) == []
    # the commands recorded are the tuning CLI's, for this preset, and parse as such
    assert len(manifest["commands"]) == 2
    for command in manifest["commands"]:
        argv = command.split()
        assert argv[0] == "tuning" and argv[argv.index("--vehicle") + 1] == name
        tuning_parser().parse_args(argv[1:])
    assert manifest["commands"][0].startswith("tuning schedule") and " --delay" in manifest["commands"][0]
    assert " --design margins --controller-rate-hz 50 --prediction-time-s 0.2 " in manifest["commands"][0]
    assert " --preview-past-s 8 --preview-future-s 2 " in manifest["commands"][0]
    limits = "rollover-limits" if name == "tractor-semitrailer" else "steering-limits"
    assert manifest["commands"][1].startswith(f"tuning {limits}")
    assert manifest["package_version"] and manifest["date"]


def test_check_reports_the_shipped_files_current(capsys: pytest.CaptureFixture[str]) -> None:
    assert preset_tuning.main(["--check"]) == 0
    assert "up to date" in capsys.readouterr().out


def test_check_names_a_stale_preset_and_the_command(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "tuning"
    source = shipped_tuning_root() / "kinematic-bicycle"
    (out / "kinematic-bicycle").mkdir(parents=True)
    for name in (LEAD_FILE, LIMITS_FILE, MANIFEST_FILE):
        (out / "kinematic-bicycle" / name).write_bytes((source / name).read_bytes())
    manifest = json.loads((out / "kinematic-bicycle" / MANIFEST_FILE).read_text())
    manifest["options"]["max_lead_gain"] = 3.0
    (out / "kinematic-bicycle" / MANIFEST_FILE).write_text(json.dumps(manifest))
    assert preset_tuning.main(["--check", "--only", "kinematic-bicycle", "--out-dir", str(out)]) == 1
    printed = capsys.readouterr().out
    assert "stale: kinematic-bicycle" in printed and "max_lead_gain" in printed
    assert regenerate_command("kinematic-bicycle") in printed


@pytest.mark.parametrize("name", PRESETS)
def test_the_shipped_files_parse_and_the_lags_are_sane(name: str) -> None:
    tuning = read_vehicle_tuning(shipped_tuning_root() / name)
    schedule, limits = tuning.filter_schedule, tuning.limits
    assert tuning.lag_speeds_kmh == schedule.speeds_kmh
    assert schedule.speeds_kmh == PRESET_TUNING_OPTIONS.schedule_speeds_kmh, "a speed was dropped; see the manifest"
    assert [s for s, _ in tuning.measured_lags] == list(schedule.speeds_kmh)
    design = json.loads((shipped_tuning_root() / name / LEAD_FILE).read_text())["design"]
    assert tuning.floors == tuple((row["speed_kmh"], row["lookahead_floor_m"]) for row in design["per_speed"])
    assert design["method"] == "margins" and design["maneuvers"] == ["dlc", "step-series", "chirp"]
    for (speed, lag), (_, measured), row in zip(tuning.lags, tuning.measured_lags, design["per_speed"], strict=True):
        for one in (lag, measured):
            assert 3.0 < one.omega_n_rad_s < 100.0 and 0.1 < one.zeta <= DELAY_FIT_MAX_ZETA, (name, speed, one)
            assert 0.0 <= one.delay_s < 0.3, (name, speed, one)
            assert 0.5 < one.steady_state_gain < 1.5, (name, speed, one)
            assert one.nrmse < 0.05, (name, speed, one)
        assert measured.delay_s <= lag.delay_s + 1e-3, (name, speed)  # the yaw rate leads the path curvature
        # the margins design: a floor within the controller's range, no longer than without the lead
        floor = row.get("lookahead_floor_m")
        assert floor is not None and 3.0 <= floor <= 40.0, (name, speed, row)
        assert floor <= row.get("floor_without_lead_m", math.inf), (name, speed, row)
    for params in schedule.params:
        assert 1.0 <= params.peak_gain <= PRESET_TUNING_OPTIONS.max_lead_gain * (1 + 1e-6)
    assert limits.speeds_kmh[-1] >= 150.0 and all(k > 0 for k in limits.max_curvature_1pm)
    assert all(b <= a * (1 + 1e-9) for a, b in itertools.pairwise(limits.max_curvature_1pm))
    assert schedule.params != (DEFAULT_FILTER,) or name == "tractor-semitrailer"


@pytest.mark.parametrize("name", PRESETS)
def test_the_shipped_lags_vary_smoothly_with_speed(name: str) -> None:
    """The delay fit with the chirp and zeta <= 2: from one schedule speed to the next the lag's low-frequency
    delay (the pure delay + 2 zeta / omega_n) changes by at most 0.12 s and the pure delay by at most 0.07 s. (The
    loaded truck's path lag changes character between 20 and 30 km/h, from a resonance at 11 rad/s (zeta 0.41) to
    a first-order lag behind 0.25 s (zeta at its bound, omega_n 34 rad/s), so omega_n itself may jump there.)"""
    tuning = read_vehicle_tuning(shipped_tuning_root() / name)
    for lags in (tuning.lags, tuning.measured_lags):
        for (s0, a), (s1, b) in itertools.pairwise(lags):
            assert abs(b.group_delay_s - a.group_delay_s) < 0.12, (name, s0, s1, a, b)
            assert abs(b.delay_s - a.delay_s) < 0.07, (name, s0, s1, a, b)


def test_no_two_presets_share_a_filter() -> None:
    schedules = {name: read_vehicle_tuning(shipped_tuning_root() / name).filter_schedule for name in PRESETS}
    for a in PRESETS:
        for b in PRESETS:
            if a < b:
                assert schedules[a].params != schedules[b].params, (a, b)


@pytest.mark.parametrize("name", PRESETS)
def test_tuning_for_a_preset_is_its_shipped_files(name: str, private_cache: Path, capsys) -> None:
    # (stale files would make tuning_for generate a tuning, for minutes: the staleness test says what to run)
    assert not preset_tuning.stale_reasons(name, shipped_tuning_root() / name), "stale; see the staleness test"
    tuning = tuning_for(make_vehicle(name))
    assert tuning == read_vehicle_tuning(shipped_tuning_root() / name)
    assert str(shipped_tuning_root() / name) in tuning.source
    assert not private_cache.exists() and capsys.readouterr().err == ""  # nothing generated


@pytest.mark.parametrize("payload_kg", [0.0, 5000.0, 25000.0])
def test_the_trucks_payload_does_not_change_its_tuning(payload_kg: float, private_cache: Path) -> None:
    truck = make_vehicle("tractor-semitrailer", payload_kg=payload_kg)
    assert params_sha256(truck) == params_sha256(make_vehicle("tractor-semitrailer"))
    assert tuning_for(truck) == read_vehicle_tuning(shipped_tuning_root() / "tractor-semitrailer")
    assert not private_cache.exists()


def test_lag_at_interpolates_between_the_identified_speeds_and_clamps() -> None:
    slow = SteeringLag(4.0, 0.8, 0.2, steady_state_gain=0.9)
    fast = SteeringLag(2.0, 1.2, 0.1, steady_state_gain=0.7)
    schedule = FilterSchedule((30.0, 60.0), (LeadFilterParams.from_lag(4.0, 0.8), LeadFilterParams.from_lag(2.0, 1.2)))
    limits = CurvatureLimits((0.0, 100.0), (0.1, 0.01), (0.1, 0.1))
    tuning = VehicleTuning(schedule, limits, ((30.0, slow), (60.0, fast)), "test")
    assert tuning.lag_at(30.0) is slow and tuning.lag_at(10.0) is slow and tuning.lag_at(90.0) is fast
    mid = tuning.lag_at(40.0)
    assert (mid.omega_n_rad_s, mid.zeta, mid.delay_s, mid.steady_state_gain) == pytest.approx(
        (10 / 3, 28 / 30, 0.5 / 3, 25 / 30)
    )
    with pytest.raises(WorkbenchInputError, match="speed_kmh must be a finite number"):
        tuning.lag_at(float("nan"))
    with pytest.raises(WorkbenchInputError, match="increase strictly"):
        VehicleTuning(schedule, limits, ((60.0, fast), (30.0, slow)), "test")
    # without measured lags: None (the controller then uses the path lag)
    assert tuning.measured_lags == () and tuning.measured_lag_at(40.0) is None
    with pytest.raises(WorkbenchInputError, match="speed_kmh must be a finite number"):
        tuning.measured_lag_at(float("inf"))


def test_measured_lag_at_interpolates_like_lag_at() -> None:
    path = ((30.0, SteeringLag(30.0, 2.0, 0.25)), (60.0, SteeringLag(8.0, 2.0, 0.18)))
    slow = SteeringLag(10.0, 0.9, 0.06, steady_state_gain=0.94)
    fast = SteeringLag(13.0, 2.0, 0.07, steady_state_gain=0.84)
    schedule = FilterSchedule((30.0, 60.0), (LeadFilterParams(6.0, 1.0, 20.0), LeadFilterParams(4.8, 1.4, 17.0)))
    limits = CurvatureLimits((0.0, 100.0), (0.1, 0.01), (0.1, 0.1))
    tuning = VehicleTuning(schedule, limits, path, "test", ((30.0, slow), (60.0, fast)))
    assert tuning.measured_lag_at(30.0) is slow and tuning.measured_lag_at(10.0) is slow
    assert tuning.measured_lag_at(90.0) is fast
    mid = tuning.measured_lag_at(40.0)
    assert (mid.omega_n_rad_s, mid.zeta, mid.delay_s, mid.steady_state_gain) == pytest.approx(
        (11.0, 0.9 + 1.1 / 3, 0.06 + 0.01 / 3, 0.94 - 0.1 / 3)
    )
    assert "measured lags" in mid.source
    with pytest.raises(WorkbenchInputError, match="measured_lags' speeds"):
        VehicleTuning(schedule, limits, path, "test", ((30.0, slow),))
    grid = (0.0,) + (-0.01,) * (len(HANDLING_GRID_G) - 1)
    with pytest.raises(WorkbenchInputError, match=r"releases must be \(speed_kmh, SideslipRelease\) at the lags'"):
        VehicleTuning(schedule, limits, path, "test", releases=((30.0, SideslipRelease(grid)),))
    with pytest.raises(WorkbenchInputError, match="releases must be"):
        VehicleTuning(schedule, limits, path, "test", releases=((30.0, SideslipRelease(grid)), (60.0, 0.1)))


def _copy_shipped(name: str, directory: Path) -> Path:
    directory.mkdir(parents=True)
    for file in (LEAD_FILE, LIMITS_FILE, MANIFEST_FILE):
        (directory / file).write_bytes((shipped_tuning_root() / name / file).read_bytes())
    return directory


def _write_lead(directory: Path, doc: dict) -> None:
    """Write lead.json and record its digest in the manifest, as a tuning made with that file would have it."""
    (directory / LEAD_FILE).write_text(json.dumps(doc))
    manifest = json.loads((directory / MANIFEST_FILE).read_text())
    manifest["files_sha256"] = files_sha256(directory)
    (directory / MANIFEST_FILE).write_text(json.dumps(manifest))


def test_a_lead_file_without_measured_lags_still_reads(tmp_path: Path) -> None:
    """Files made before the measured lag was recorded: no measured_* keys in per_speed (nor the preview responses,
    recorded later still)."""
    directory = _copy_shipped("tractor-semitrailer", tmp_path / "old")
    doc = json.loads((directory / LEAD_FILE).read_text())
    for row in doc["design"]["per_speed"]:
        for key in [k for k in row if k.startswith("measured_")]:
            del row[key]
    _write_lead(directory, doc)
    with pytest.raises(WorkbenchInputError, match="previews need the measured lags"):
        read_vehicle_tuning(directory)
    for row in doc["design"]["per_speed"]:
        for key in [k for k in row if k.startswith("preview_")]:
            del row[key]
    _write_lead(directory, doc)
    tuning = read_vehicle_tuning(directory)
    assert tuning.measured_lags == () and tuning.measured_lag_at(60.0) is None
    shipped = read_vehicle_tuning(shipped_tuning_root() / "tractor-semitrailer").lag_at(60.0)
    assert dataclasses.replace(tuning.lag_at(60.0), source="") == dataclasses.replace(shipped, source="")


def test_a_lead_file_with_the_measured_lag_at_some_speeds_only_is_refused(tmp_path: Path) -> None:
    directory = _copy_shipped("tractor-semitrailer", tmp_path / "partial")
    doc = json.loads((directory / LEAD_FILE).read_text())
    del doc["design"]["per_speed"][3]["measured_zeta"]
    _write_lead(directory, doc)
    with pytest.raises(WorkbenchInputError, match=r"per_speed\[3\] must hold both of"):
        read_vehicle_tuning(directory)
    for row in doc["design"]["per_speed"][3:]:
        for key in [k for k in row if k.startswith("measured_")]:
            del row[key]
    _write_lead(directory, doc)
    with pytest.raises(WorkbenchInputError, match=r"holds the measured lag .* at 3 of 10 speeds"):
        read_vehicle_tuning(directory)


def test_the_shipped_measured_lags_are_read() -> None:
    tuning = read_vehicle_tuning(shipped_tuning_root() / "tractor-semitrailer")
    rows = json.loads((shipped_tuning_root() / "tractor-semitrailer" / LEAD_FILE).read_text())["design"]["per_speed"]
    at_60 = next(r for r in rows if r["speed_kmh"] == 60.0)
    measured = tuning.measured_lag_at(60.0)
    assert measured.omega_n_rad_s == at_60["measured_omega_n_rad_s"] and measured.zeta == at_60["measured_zeta"]
    assert measured.delay_s == at_60["measured_delay_s"]
    assert measured.steady_state_gain == at_60["measured_steady_state_gain"]
    assert tuning.lag_at(60.0).omega_n_rad_s == at_60["omega_n_rad_s"]


def test_the_shipped_preview_responses_are_read_and_chosen_where_the_lag_misfits() -> None:
    """Every preset ships its preview responses at its lags' speeds; the controller's 'auto' takes them where the
    lag of Eq. 5 does not explain the vehicle's logs (the truck and the multi-body car), not where it does."""
    for name in PRESETS:
        tuning = read_vehicle_tuning(shipped_tuning_root() / name)
        assert tuple(s for s, _ in tuning.previews) == tuning.lag_speeds_kmh
        rows = json.loads((shipped_tuning_root() / name / LEAD_FILE).read_text())["design"]["per_speed"]
        assert tuning.previews[2][1].measured_taps == tuple(rows[2]["preview_measured_taps"])
        first, spacing, steering, measured = tuning.preview_tables
        assert steering.shape == measured.shape == (len(rows), len(rows[0]["preview_steering_taps"]))
        assert (first, spacing) == (rows[0]["preview_first_tap_s"], rows[0]["preview_tap_spacing_s"])
    explained = {name: read_vehicle_tuning(shipped_tuning_root() / name).lag_explains_logs for name in PRESETS}
    assert explained == {
        "tractor-semitrailer": False, "dynamic-bicycle": True, "kinematic-bicycle": True, "commonroad-mb": False,
    }  # fmt: skip


def test_a_lead_file_with_preview_responses_at_some_speeds_only_is_refused(tmp_path: Path) -> None:
    directory = _copy_shipped("tractor-semitrailer", tmp_path / "partial")
    doc = json.loads((directory / LEAD_FILE).read_text())
    del doc["design"]["per_speed"][4]["preview_measured_taps"]
    _write_lead(directory, doc)
    with pytest.raises(
        WorkbenchInputError, match=r"per_speed\[4\] lacks some of \['preview_first_tap_s'.*at every speed or at none"
    ):
        read_vehicle_tuning(directory)
    doc["design"]["per_speed"][4]["preview_measured_taps"] = [0.5] * len(
        doc["design"]["per_speed"][4]["preview_steering_taps"]
    )
    _write_lead(directory, doc)
    with pytest.raises(
        WorkbenchInputError, match=r"per_speed\[4\] \(preview responses\): measured_taps must sum to one"
    ):
        read_vehicle_tuning(directory)
    for row in doc["design"]["per_speed"]:
        for key in [k for k in row if k.startswith("preview_")]:
            del row[key]
    _write_lead(directory, doc)
    assert read_vehicle_tuning(directory).previews == ()  # files made before they were recorded


def test_the_handling_gain_is_read_checked_and_optional(tmp_path: Path) -> None:
    """The shipped truck's handling gain is its rows' `preview_handling_gain`; a gain out of range is refused naming
    the row; a file without it (made before it was identified) reads as gains of one."""
    directory = _copy_shipped("tractor-semitrailer", tmp_path / "handling")
    doc = json.loads((directory / LEAD_FILE).read_text())
    rows = doc["design"]["per_speed"]
    tuning = read_vehicle_tuning(directory)
    assert tuning.handling_table.tolist() == [row["preview_handling_gain"] for row in rows]
    assert tuning.handling_table[2, -1] > 1.02  # 30 km/h: the loaded truck understeers more at 0.4 g
    rows[3]["preview_handling_gain"] = [1.0] * 8 + [3.0]
    _write_lead(directory, doc)
    with pytest.raises(WorkbenchInputError, match=r"per_speed\[3\] \(preview responses\): handling_gain must be 9"):
        read_vehicle_tuning(directory)
    for row in rows:
        del row["preview_handling_gain"]
    _write_lead(directory, doc)
    assert np.all(read_vehicle_tuning(directory).handling_table == 1.0)


def test_the_sideslip_release_is_read_checked_and_optional(tmp_path: Path) -> None:
    """The shipped truck's release is its rows' steady sideslip and release rate (0: not identified) in
    `VehicleTuning.release_table`; a row without it while others have it, or with a rate out of range, is refused
    naming the row; a file without any (made before it was identified) reads as none."""
    directory = _copy_shipped("tractor-semitrailer", tmp_path / "release")
    doc = json.loads((directory / LEAD_FILE).read_text())
    rows = doc["design"]["per_speed"]
    table = read_vehicle_tuning(directory).release_table
    for row, got in zip(rows, table, strict=True):
        assert got[0] == pytest.approx(row["release_rate_1ps"], rel=1e-15)
        assert got[1:].tolist() == row["release_steady_sideslip_rad"]
    assert table[1, 0] > 5.0  # 20 km/h: the loaded truck's push released within 0.2 s
    rows[3]["release_rate_1ps"] = -1.0
    _write_lead(directory, doc)
    with pytest.raises(WorkbenchInputError, match=r"per_speed\[3\] \(sideslip release\): release_rate_1ps must be"):
        read_vehicle_tuning(directory)
    del rows[3]["release_rate_1ps"]
    _write_lead(directory, doc)
    with pytest.raises(WorkbenchInputError, match=r"per_speed\[3\] lacks some of \['release_steady_sideslip_rad'"):
        read_vehicle_tuning(directory)
    for row in rows:
        for key in [k for k in row if k.startswith("release_")]:
            del row[key]
    _write_lead(directory, doc)
    tuning = read_vehicle_tuning(directory)
    assert tuning.releases == () and tuning.release_table.shape == (0, 1 + len(HANDLING_GRID_G))


def _longer_car(tmp_path: Path) -> Path:
    """A user's vehicle file (`workbench vehicles --show kinematic-bicycle`, edited): a longer wheelbase."""
    path = tmp_path / "longer.toml"
    text = preset_text("kinematic-bicycle")
    assert "wheelbase_m = 2.579" in text
    path.write_text(text.replace("wheelbase_m = 2.579", "wheelbase_m = 2.9"))
    return path


def test_another_vehicle_is_tuned_once_into_the_cache(tmp_path: Path, private_cache: Path, monkeypatch, capsys) -> None:
    car = make_vehicle(vehicle_file=_longer_car(tmp_path))
    first = tuning_for(car, QUICK)
    directory = private_cache / cache_key(car, QUICK)
    assert str(directory) in first.source
    err = capsys.readouterr().err
    assert "no clothoid-controller tuning yet" in err and str(directory) in err and "done in" in err
    manifest = read_manifest(directory)
    assert manifest["preset"] is None and manifest["params_sha256"] == params_sha256(car)
    assert manifest["commands"][0].startswith("tuning schedule --vehicle-file vehicle.toml --speeds 40 ")
    # the cache's vehicle file is the vehicle, so the recorded commands can be re-run
    assert params_from_toml((directory / VEHICLE_FILE).read_text(), "x")[1] == car.params
    assert first.filter_schedule.speeds_kmh == (40.0,)
    assert first.filter_schedule.params != read_filter_file(shipped_tuning_root() / "kinematic-bicycle" / LEAD_FILE)
    assert [p.name for p in private_cache.iterdir()] == [directory.name]  # no temporary directory left
    # the second call reads the cache: nothing is generated
    monkeypatch.setattr(preset_tuning, "write_tuning_files", _must_not_generate)
    assert tuning_for(car, QUICK) == first
    assert capsys.readouterr().err == ""


def _must_not_generate(*args, **kwargs):
    raise AssertionError("the cached tuning was generated again")


def test_changed_options_make_another_cache_entry(tmp_path: Path) -> None:
    car = make_vehicle(vehicle_file=_longer_car(tmp_path))
    assert cache_key(car, QUICK) != cache_key(car, dataclasses.replace(QUICK, max_lead_gain=3.0))
    assert cache_key(car, QUICK) == cache_key(make_vehicle(vehicle_file=_longer_car(tmp_path)), QUICK)
    assert "wheelbase_m = 2.9\n" in canonical_vehicle_toml(car)


def test_a_failing_generation_names_the_commands_and_options(tmp_path: Path, monkeypatch) -> None:
    car = make_vehicle(vehicle_file=_longer_car(tmp_path))

    def refuse(*args, **kwargs):
        raise WorkbenchInputError("at 40 km/h: the fit ran to the bound of zeta")

    monkeypatch.setattr(preset_tuning, "identify_schedule", refuse)
    with pytest.raises(WorkbenchInputError) as info:
        tuning_for(car, QUICK)
    message = str(info.value)
    assert "the fit ran to the bound of zeta" in message
    assert "`tuning schedule --vehicle-file " in message and " --speeds 40 " in message and "--delay" in message
    assert "`tuning steering-limits --vehicle-file " in message
    assert "filter_file = 'lead.json'" in message and "limits_file = 'limits.csv'" in message
    named = Path(message.split("--vehicle-file ")[1].split()[0])
    assert params_from_toml(named.read_text(), "x")[1] == car.params  # the file the commands name exists


def test_an_unwritable_cache_gives_the_same_clear_error(tmp_path: Path, monkeypatch) -> None:
    blocker = tmp_path / "not-a-directory"
    blocker.write_text("")
    monkeypatch.setenv(CACHE_ENV, str(blocker))
    with pytest.raises(WorkbenchInputError, match=r"generating it in .* failed: .*`tuning schedule --vehicle-file "):
        tuning_for(make_vehicle(vehicle_file=_longer_car(tmp_path)), QUICK)


def test_options_are_validated() -> None:
    with pytest.raises(WorkbenchInputError, match="max_lead_gain must be a finite number in"):
        dataclasses.replace(PRESET_TUNING_OPTIONS, max_lead_gain=0.5)
    with pytest.raises(WorkbenchInputError, match="speeds must increase strictly"):
        PresetTuningOptions((30.0, 20.0), True, 6.0, 1.0, 0.1, (10.0,), 0.4)
    with pytest.raises(WorkbenchInputError, match="fit_delay must be True or False"):
        dataclasses.replace(PRESET_TUNING_OPTIONS, fit_delay=1)
    with pytest.raises(WorkbenchInputError, match="design must be one of cancel, margins"):
        dataclasses.replace(PRESET_TUNING_OPTIONS, design="loop")
    with pytest.raises(WorkbenchInputError, match="controller_rate_hz must be a finite number in"):
        dataclasses.replace(PRESET_TUNING_OPTIONS, controller_rate_hz=0.0)
    with pytest.raises(WorkbenchInputError, match="prediction_time_s must be a finite number in"):
        dataclasses.replace(PRESET_TUNING_OPTIONS, prediction_time_s=-0.1)
    with pytest.raises(WorkbenchInputError, match="preview_past_s must be a finite number in"):
        dataclasses.replace(PRESET_TUNING_OPTIONS, preview_past_s=40.0)
    with pytest.raises(WorkbenchInputError, match="preview_future_s must be a finite number in"):
        dataclasses.replace(PRESET_TUNING_OPTIONS, preview_future_s=math.nan)
    with pytest.raises(WorkbenchInputError, match="preview_lat_accel_g must be a finite number in"):
        dataclasses.replace(PRESET_TUNING_OPTIONS, preview_lat_accel_g=0.0)


def test_the_preset_options_are_the_margins_design_with_a_delay() -> None:
    resolved = PRESET_TUNING_OPTIONS.for_model("tractor-semitrailer").to_dict()
    assert resolved["design"] == "margins" and resolved["fit_delay"] is True
    assert resolved["controller_rate_hz"] == 50.0 and resolved["prediction_time_s"] == 0.2


def test_a_generation_finishing_second_keeps_the_first_ones_files(tmp_path: Path, monkeypatch) -> None:
    """Two sweep workers generating the same tuning at once: the first rename wins, the second keeps its files."""
    car = make_vehicle(vehicle_file=_longer_car(tmp_path))
    target = tmp_path / "cache" / "key"
    generate_vehicle_tuning(car, target, QUICK)
    before = read_vehicle_tuning(target)

    def other_worker(vehicle, directory, options, vehicle_args, preset):
        for name in (LEAD_FILE, LIMITS_FILE, MANIFEST_FILE):
            (Path(directory) / name).write_text("a concurrent worker's files, never read")

    monkeypatch.setattr(preset_tuning, "write_tuning_files", other_worker)
    assert generate_vehicle_tuning(car, target, QUICK) == target
    assert read_vehicle_tuning(target) == before
    assert sorted(p.name for p in target.parent.iterdir()) == ["key"]  # the loser's temporary directory is gone


def test_an_edited_tuning_directory_is_refused(tmp_path: Path) -> None:
    directory = tmp_path / "tuning"
    shutil.copytree(shipped_tuning_root() / "kinematic-bicycle", directory)
    read_vehicle_tuning(directory)  # as made: read
    lead = directory / LEAD_FILE
    lead.write_text(lead.read_text().replace('"omega_p_rad_s": ', '"omega_p_rad_s": 1', 1))
    with pytest.raises(WorkbenchInputError, match=r"lead\.json is not the file its manifest records .* filter_file"):
        read_vehicle_tuning(directory)


def test_an_edited_cache_entry_is_made_again_never_used(tmp_path: Path, private_cache: Path, monkeypatch, capsys):
    car = make_vehicle(vehicle_file=_longer_car(tmp_path))
    first = tuning_for(car, QUICK)
    directory = private_cache / cache_key(car, QUICK)
    limits = directory / LIMITS_FILE
    limits.write_text(limits.read_text() + "\n")  # any change, even one that reads the same
    capsys.readouterr()
    assert tuning_for(car, QUICK) == first  # made again, the same
    assert "the cached tuning cannot be used" in capsys.readouterr().err
    assert sorted(p.name for p in private_cache.iterdir()) == [directory.name]  # the old entry is gone
    read_vehicle_tuning(directory)  # and the new one matches its manifest


def test_a_cache_others_may_write_is_refused(tmp_path: Path, private_cache: Path) -> None:
    private_cache.mkdir()
    private_cache.chmod(0o777)
    with pytest.raises(UnsafeCacheError, match="is writable by others"):
        tuning_for(make_vehicle(vehicle_file=_longer_car(tmp_path)), QUICK)


def test_the_cache_is_made_private(tmp_path: Path, private_cache: Path) -> None:
    tuning_for(make_vehicle(vehicle_file=_longer_car(tmp_path)), QUICK)
    assert private_cache.stat().st_mode & 0o777 == 0o700


def test_only_a_margins_design_with_its_loop_gives_floors() -> None:
    """A lead file's floors are read only from a margins design that names the loop they were computed for; a
    malformed one is refused naming the file."""
    from controllers.clothoid.vehicle_tuning import FloorDesign
    from tuning.tuning_dirs import _floors

    loop = {"controller_rate_hz": 50, "prediction_time_s": 0.2, "arc_lateral_accel_g": 0.4}
    loop["lookahead_range_m"] = [3, 40, 0.5]
    rows = [{"speed_kmh": 30, "lookahead_floor_m": 8.5}, {"speed_kmh": 60}]
    assert _floors(Path("lead.json"), {"method": "cancel", **loop, "per_speed": rows}) == ((), None)
    assert _floors(Path("lead.json"), {"method": "margins", "per_speed": rows}) == ((), None)
    floors, design = _floors(Path("lead.json"), {"method": "margins", **loop, "per_speed": rows, "gain_margin_db": 8})
    assert floors == ((30.0, 8.5),) and design == FloorDesign(0.02, 0.2, 0.4, (3.0, 40.0, 0.5), 45.0, 8.0)
    with pytest.raises(WorkbenchInputError, match=r"^lead\.json: design's floors"):
        _floors(Path("lead.json"), {"method": "margins", **loop, "lookahead_range_m": [3, 40], "per_speed": rows})
