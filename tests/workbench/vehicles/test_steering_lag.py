"""The steering-lag file (Eq. 5) shared by the tuning CLI, the clothoid controller and the MPC."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from workbench.errors import WorkbenchInputError
from workbench.vehicles.steering_lag import SteeringLag, read_lag_file, write_lag_file


@given(
    wn=st.floats(0.05, 200.0),
    zeta=st.floats(0.05, 10.0),
    delay=st.floats(0.0, 2.0),
    gain=st.floats(0.05, 20.0),
    nrmse=st.one_of(st.just(math.nan), st.floats(0.0, 1.0)),
)
def test_round_trip(wn: float, zeta: float, delay: float, gain: float, nrmse: float, tmp_path_factory) -> None:
    lag = SteeringLag(wn, zeta, delay, steady_state_gain=gain, nrmse=nrmse, speed_range_mps=(5.0, 9.0), source="t")
    back = read_lag_file(write_lag_file(lag, tmp_path_factory.mktemp("lag") / "lag.json"))
    assert back.omega_n_rad_s == wn and back.zeta == zeta and back.delay_s == delay and back.steady_state_gain == gain
    assert back.speed_range_mps == (5.0, 9.0) and back.source == "t"
    assert (math.isnan(back.nrmse) and math.isnan(nrmse)) or back.nrmse == nrmse


@pytest.mark.parametrize(
    ("content", "needle"),
    [
        ("{", "not valid JSON"),
        ("[1, 2]", "must hold a JSON object"),
        ('{"format": "steering-lag/1", "zeta": 0.8}', "missing keys ['omega_n_rad_s']"),
        ('{"format": "steering-lag/1", "omega_n_rad_s": 4, "zeta": 0.8, "wn": 3}', "unknown keys ['wn']"),
        ('{"format": "lead-filter/1", "omega_n_rad_s": 4, "zeta": 0.8}', "format must be 'steering-lag/1'"),
        ('{"format": "steering-lag/1", "omega_n_rad_s": -4, "zeta": 0.8}', "omega_n_rad_s must be in"),
        ('{"format": "steering-lag/1", "omega_n_rad_s": 4, "zeta": 0.8, "speed_range_mps": [9]}', "[low, high]"),
        ('{"format": "steering-lag/1", "omega_n_rad_s": 4, "zeta": 0.8, "steady_state_gain": 0}', "steady_state_gain"),
    ],
)
def test_bad_files_get_a_clear_error(content: str, needle: str, tmp_path: Path) -> None:
    path = tmp_path / "lag.json"
    path.write_text(content)
    with pytest.raises(WorkbenchInputError) as info:
        read_lag_file(path)
    assert needle in str(info.value) and "lag.json" in str(info.value)


def test_missing_file_and_nan_values() -> None:
    with pytest.raises(WorkbenchInputError, match=r"lag\.json': no such file"):
        read_lag_file("/nonexistent/lag.json")
    with pytest.raises(WorkbenchInputError, match="zeta"):
        SteeringLag(4.0, float("nan"))
    assert json.loads(json.dumps(SteeringLag(4.0, 0.8).to_dict()))["format"] == "steering-lag/1"


def test_a_folder_or_a_deeply_nested_file_is_refused(tmp_path: Path) -> None:
    with pytest.raises(WorkbenchInputError, match="a folder, not a file"):
        read_lag_file(tmp_path)
    deep = tmp_path / "deep.json"
    deep.write_text("[" * 5000 + "]" * 5000)
    with pytest.raises(WorkbenchInputError, match=r"deep\.json': nested deeper than 64 levels"):
        read_lag_file(deep)
