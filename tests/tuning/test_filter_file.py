"""The lead-filter file: JSON and TOML round trips, speed schedules and their interpolation, and bad files."""

from __future__ import annotations

import dataclasses
import json
import math
import re
import tempfile
import tomllib
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from controllers.clothoid.filter_schedule import DEFAULT_FILTER, FilterSchedule
from controllers.clothoid.lead_filter import LeadFilterParams
from tuning.filter_file import FORMAT_TAG, read_filter_file, write_filter_file
from workbench.base.errors import WorkbenchInputError
from workbench.base.input_files import read_json, read_toml

SLOW, FAST = LeadFilterParams(5.0, 0.7, 15.0), LeadFilterParams(3.0, 0.9, 12.0)
SCHEDULE = FilterSchedule((20.0, 60.0), (SLOW, FAST))
PLANT = {"omega_n_rad_s": 4.44, "zeta": 0.8}
GOOD = {"format": FORMAT_TAG, "omega_z_rad_s": 4.44, "psi": 0.8, "omega_p_rad_s": 13.3, "dc_gain": 1.0, "source": "x"}


def test_default_filter_is_the_documented_design() -> None:
    assert DEFAULT_FILTER == LeadFilterParams.from_lag(4.44, 0.80)
    assert DEFAULT_FILTER.omega_p_rad_s == pytest.approx(13.32, rel=1e-12)


@pytest.mark.parametrize("suffix", [".json", ".toml", ".TOML"])
def test_single_filter_round_trip(tmp_path: Path, suffix: str) -> None:
    path = tmp_path / f"lead{suffix}"
    source = 'fit of Eq. 5, "loaded" truck\nline 2: é ∑ \t \x7f'
    extra = {"bandwidth_rad_s": 6.78, "ok": True, "steps": [1, 2.5, "x"], "per_speed": {"30 km/h": {"bw": 6.0}}}
    write_filter_file(path, DEFAULT_FILTER, source=source, plant=PLANT, speed_kmh=30, extra=extra)
    back = read_filter_file(path)
    assert back.params == (DEFAULT_FILTER,) and back.speeds_kmh == (30.0,) and back.source == source
    assert back.at_speed(0.0) == back.at_speed(120.0) == DEFAULT_FILTER  # one filter: the same at every speed
    doc = (read_json if suffix == ".json" else read_toml)(path, "the lead filter file")  # the rest, as written
    assert doc["plant"] == PLANT and doc["design"] == extra
    assert doc["dc_gain"] == pytest.approx(1.0, abs=1e-12) and doc["speed_kmh"] == 30.0


@pytest.mark.parametrize("suffix", [".json", ".toml"])
def test_schedule_round_trip_keeps_every_entry_and_the_nominal_filter(tmp_path: Path, suffix: str) -> None:
    path = tmp_path / f"lead{suffix}"
    write_filter_file(path, SCHEDULE, source="two speeds", speed_kmh=40.0)
    back = read_filter_file(path)
    assert back == FilterSchedule((20.0, 60.0), (SLOW, FAST), "two speeds")
    doc = (json.loads if suffix == ".json" else tomllib.loads)(path.read_text())
    assert doc["omega_z_rad_s"] == pytest.approx(4.0, rel=1e-12)  # the top level is the filter at speed_kmh


def test_schedule_interpolates_linearly_and_clamps() -> None:
    assert SCHEDULE.at_speed(20.0) == SLOW and SCHEDULE.at_speed(60.0) == FAST  # at the listed speeds
    mid = SCHEDULE.at_speed(30.0)  # a quarter of the way
    assert (mid.omega_z_rad_s, mid.psi, mid.omega_p_rad_s) == pytest.approx((4.5, 0.75, 14.25), rel=1e-12)
    assert SCHEDULE.at_speed(0.0) == SLOW and SCHEDULE.at_speed(150.0) == FAST  # clamped beyond the ends
    three = FilterSchedule((10.0, 20.0, 30.0), (SLOW, FAST, SLOW))
    assert three.at_speed(25.0) == LeadFilterParams(4.0, 0.8, 13.5)


@settings(max_examples=100, deadline=None)
@given(
    st.lists(st.tuples(st.floats(0.01, 1000.0), st.floats(1e-3, 5.0), st.floats(1.0, 100.0)), min_size=1, max_size=4),
    st.floats(-10.0, 400.0),
    st.sampled_from([".json", ".toml"]),
)
def test_random_schedules_round_trip_exactly_and_interpolate_between_neighbours(
    rows: list[tuple[float, float, float]], speed: float, suffix: str
) -> None:
    params = tuple(LeadFilterParams(wz, psi, min(wz * ratio, 1000.0)) for wz, psi, ratio in rows)
    schedule = FilterSchedule(tuple(float(20 * i) for i in range(len(params))), params)
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / f"s{suffix}"
        write_filter_file(path, schedule, source="random")
        back = read_filter_file(path)
    assert back.params == params and back.speeds_kmh == schedule.speeds_kmh  # floats survive exactly
    p = back.at_speed(speed)  # always a valid filter, each parameter between its neighbours' values
    i = min(max(int(speed // 20), 0), len(params) - 1)
    j = min(i + 1, len(params) - 1)
    for key in ("omega_z_rad_s", "psi", "omega_p_rad_s"):
        lo, hi = sorted((getattr(params[i], key), getattr(params[j], key)))
        assert lo <= getattr(p, key) <= hi


def write(tmp_path: Path, doc: object, name: str = "f.json") -> Path:
    path = tmp_path / name
    path.write_text(json.dumps(doc) if isinstance(doc, dict | list) else str(doc))
    return path


@pytest.mark.parametrize(
    ("doc", "needle"),
    [
        ("{not json", r"not valid JSON"),
        ([1, 2], r"top level must be a table; got \[1, 2\]"),
        ({**GOOD, "format": "lead-filter/2"}, r"format is 'lead-filter/2'; expected 'lead-filter/1'"),
        ({k: v for k, v in GOOD.items() if k != "format"}, r"top level: missing key 'format'"),
        ({k: v for k, v in GOOD.items() if k != "psi"}, r"missing key 'psi'; allowed keys: format, omega_z_rad_s, psi"),
        ({**GOOD, "omega_z": 4.0}, r"unknown key 'omega_z'; allowed keys: .*schedule, design$"),
        ({**GOOD, "psi": "0.8"}, r"psi must be a number; got '0.8'"),
        ({**GOOD, "psi": True}, r"psi must be a number; got True"),
        ({**GOOD, "psi": 0}, r"psi must be a finite number in \(0, 5\]; got 0.0"),
        ({**GOOD, "omega_z_rad_s": -4.0}, r"omega_z_rad_s must be a finite number in \[0.01, 1000\] rad/s; got -4.0"),
        ({**GOOD, "omega_p_rad_s": 2.0}, r"omega_p_rad_s / omega_z_rad_s must be in \[1.0, 100.0\]"),
        ({**GOOD, "dc_gain": 2.0}, r"dc_gain must be 1 \(Eq. 6 has unit DC gain\); got 2.0"),
        ({**GOOD, "source": 3}, r"source must be text; got 3"),
        ({**GOOD, "speed_kmh": 500}, r"speed_kmh must be a finite number in \[0, 300\] km/h; got 500.0"),
        ({**GOOD, "plant": {"omega_n_rad_s": 4.0}}, r"plant: missing key 'zeta'; allowed keys: omega_n_rad_s, zeta"),
        ({**GOOD, "plant": {"omega_n_rad_s": 4.0, "zeta": 9}}, r"plant.zeta must be a finite number in \(0, 5\]"),
        ({**GOOD, "design": 3}, r"design must be a table/object; got 3"),
        ({**GOOD, "schedule": []}, r"schedule must be a non-empty list of tables; got \[\]"),
        (
            {**GOOD, "schedule": [{"speed_kmh": 20, "omega_z_rad_s": 4, "psi": 0.8, "omega_p": 12}]},
            r"schedule\[0\]: unknown key 'omega_p', missing key 'omega_p_rad_s'",
        ),
        (
            {**GOOD, "schedule": [{"speed_kmh": 20, "omega_z_rad_s": 4, "psi": 0.8, "omega_p_rad_s": 1e4}]},
            r"schedule\[0\].omega_p_rad_s must be a finite number in \[0.01, 1000\] rad/s; got 10000.0",
        ),
        (
            {**GOOD, "schedule": [{**dataclasses.asdict(p), "speed_kmh": s} for p, s in ((SLOW, 40), (FAST, 20))]},
            r"schedule speeds_kmh must be strictly increasing; got \[40.0, 20.0\]",
        ),
    ],
)
def test_bad_json_files_are_rejected_naming_the_file_and_problem(tmp_path: Path, doc: object, needle: str) -> None:
    path = write(tmp_path, doc)
    with pytest.raises(WorkbenchInputError, match=rf"lead filter file {re.escape(str(path))}: .*{needle}"):
        read_filter_file(path)


def test_bad_toml_missing_file_and_bad_suffix_are_rejected(tmp_path: Path) -> None:
    bad = write(tmp_path, 'format = "lead-filter/1"\npsi = \n', "f.toml")
    with pytest.raises(WorkbenchInputError, match=r"f.toml: not valid TOML"):
        read_filter_file(bad)
    with pytest.raises(WorkbenchInputError, match=r"missing.json: no such file"):
        read_filter_file(tmp_path / "missing.json")
    with pytest.raises(WorkbenchInputError, match=r"f.yaml: the name must end in .json or .toml; got '.yaml'"):
        read_filter_file(write(tmp_path, GOOD, "f.yaml"))
    with pytest.raises(WorkbenchInputError, match=r"the name must end in .json or .toml; got 'no suffix'"):
        write_filter_file(tmp_path / "f", DEFAULT_FILTER, source="x")


@pytest.mark.parametrize(
    ("kwargs", "needle"),
    [
        ({"extra": {"bw": math.nan}}, r"extra.bw must be finite; got nan"),
        ({"extra": {"x": [1, None]}}, r"extra.x\[1\] must be text, a boolean, a number, a list or a table; got None"),
        ({"plant": {"omega_n_rad_s": 4.0}}, r"plant must have exactly the keys \['omega_n_rad_s', 'zeta'\]"),
        (
            {"plant": {"omega_n_rad_s": 0.0, "zeta": 0.8}},
            r"omega_n_rad_s must be a finite number in \[0.01, 1000\] rad/s",
        ),
        ({"speed_kmh": -5.0}, r"speed_kmh must be a finite number in \[0, 300\] km/h; got -5.0"),
        ({"source": None}, r"source must be text; got None"),
    ],
)
def test_bad_write_arguments_are_rejected(tmp_path: Path, kwargs: dict, needle: str) -> None:
    with pytest.raises(WorkbenchInputError, match=needle):
        write_filter_file(tmp_path / "f.json", DEFAULT_FILTER, **{"source": "x", **kwargs})
    assert not (tmp_path / "f.json").exists()


def test_schedule_validation() -> None:
    with pytest.raises(WorkbenchInputError, match=r"one filter per speed and at least one; got 2 speeds and 1"):
        FilterSchedule((10.0, 20.0), (SLOW,))
    with pytest.raises(WorkbenchInputError, match=r"strictly increasing; got \[10.0, 10.0\]"):
        FilterSchedule((10.0, 10.0), (SLOW, FAST))
    with pytest.raises(WorkbenchInputError, match=r"schedule\[1\].speed_kmh must be a finite number"):
        FilterSchedule((10.0, math.nan), (SLOW, FAST))
    with pytest.raises(WorkbenchInputError, match=r"speed_kmh must be a finite number; got nan"):
        SCHEDULE.at_speed(math.nan)
    assert FilterSchedule.single(SLOW, 30.0).at_speed(90.0) == SLOW
