"""`tuning margins`: the table (one row per speed, lookahead and path curvature), the floor it prints against
`loop_analysis.lookahead_floor`, its margins against python-control's own, the plot, and bad input (exit 2)."""

from __future__ import annotations

import contextlib
import io
import math
import re
import warnings
from pathlib import Path

import control
import numpy as np
import pandas as pd
import pytest

from controllers.clothoid.filter_schedule import FilterSchedule
from controllers.clothoid.lead_filter import LeadFilterParams
from controllers.clothoid.loop_analysis import LoopSettings, PlantLags, lookahead_floor, loop_margins, loop_transfer
from tuning.cli import main
from tuning.filter_file import write_filter_file
from tuning.margins import COLUMNS, G_MPS2, MAX_LOOKAHEADS, MAX_STUDY_PAIRS, MarginStudy, run_margins
from tuning.own_tuning import tuning_for
from workbench.base.errors import WorkbenchInputError
from workbench.vehicles import make_vehicle
from workbench.vehicles.steering_lag import SteeringLag, write_lag_file

#: A car-like path lag (with delay), a faster yaw-rate lag, and the lead filter of Eq. 6 designed on the path lag.
PATH_LAG = SteeringLag(18.6, 0.48, 0.087)
MEASURED_LAG = SteeringLag(12.0, 0.7, 0.03)
LEAD = LeadFilterParams.from_lag(18.6, 0.48)
LAGS = PlantLags(PATH_LAG, MEASURED_LAG)
SPEEDS = (30.0, 45.0)
LOOKAHEADS = (10.0, 15.0, 20.0, 25.0, 30.0, 35.0, 40.0)
VEHICLE = "dynamic-bicycle"


def _arc(speed_kmh: float) -> float:
    geometry = make_vehicle(VEHICLE).geometry
    lock = math.tan(geometry.max_road_wheel_angle_rad) / geometry.wheelbase_m
    return min(0.4 * G_MPS2 / (speed_kmh / 3.6) ** 2, lock)


@pytest.fixture(scope="module")
def files(tmp_path_factory) -> dict[str, Path]:
    folder = tmp_path_factory.mktemp("margins")
    out = {
        "lag": write_lag_file(PATH_LAG, folder / "lag.json"),
        "measured": write_lag_file(MEASURED_LAG, folder / "yawlag.json"),
        "lead": write_filter_file(folder / "lead.toml", LEAD, source="test"),
    }
    return out


@pytest.fixture(scope="module")
def run(files, tmp_path_factory) -> dict:
    folder = tmp_path_factory.mktemp("margins_out")
    argv = [
        "margins", "--lag", str(files["lag"]), "--measured-lag", str(files["measured"]), "--lead", str(files["lead"]),
        "--vehicle", VEHICLE, "--speeds", ",".join(f"{s:g}" for s in SPEEDS), "--lookahead", "10:40:5",
        "--out", str(folder / "margins.csv"), "--plot", str(folder / "margins.png"),
    ]  # fmt: skip
    stdout = io.StringIO()
    with contextlib.redirect_stdout(stdout):
        code = main(argv)
    return {"code": code, "stdout": stdout.getvalue(), "csv": folder / "margins.csv", "png": folder / "margins.png"}


def test_writes_one_row_per_speed_lookahead_and_curvature(run) -> None:
    """Every (speed, lookahead, curvature) but the arcs too short for a target that far (|kappa| L >= 1.8: at 30
    km/h the 0.4 g arc, 0.056 1/m, reaches 32 m), which the floor search leaves out too."""
    assert run["code"] == 0
    table = pd.read_csv(run["csv"])
    assert tuple(table.columns) == COLUMNS
    expected = {(s, la, 0.0) for s in SPEEDS for la in LOOKAHEADS}
    expected |= {(s, la, round(_arc(s), 9)) for s in SPEEDS for la in LOOKAHEADS if _arc(s) * la < 1.8}
    got = [(r.speed_kmh, r.lookahead_m, round(r.path_curvature_1pm, 9)) for r in table.itertuples()]
    assert len(got) == len(set(got)) == len(expected) == 26
    assert set(got) == expected
    assert table["stable"].dtype == bool and table["meets"].dtype == bool


def test_printed_floor_is_lookahead_floor(run) -> None:
    for speed in SPEEDS:
        match = re.search(rf"^\s*{speed:g} km/h: floor (\S+)", run["stdout"], re.MULTILINE)
        assert match, run["stdout"]
        v = speed / 3.6
        settings = LoopSettings(0.02, 0.2, lead=LEAD)
        expected = lookahead_floor(LAGS, settings, v, 10.0, 40.0, 5.0, (0.0, _arc(speed)))
        assert float(match.group(1)) == pytest.approx(expected)
    assert "floor none" not in run["stdout"]  # both floors inside the range: the comparison means something


@pytest.mark.parametrize(("speed", "lookahead", "arc"), [(30.0, 20.0, False), (45.0, 35.0, True), (30.0, 10.0, True)])
def test_table_margins_agree_with_python_control(run, speed: float, lookahead: float, arc: bool) -> None:
    table = pd.read_csv(run["csv"])
    kr = _arc(speed) if arc else 0.0
    rows = table[(table["speed_kmh"] == speed) & (table["lookahead_m"] == lookahead)]
    row = rows.iloc[int(np.argmin(np.abs(rows["path_curvature_1pm"] - kr)))]
    loop = loop_transfer(
        LAGS, LoopSettings(0.02, 0.2, lead=LEAD), speed / 3.6, lookahead, float(row.path_curvature_1pm)
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        gm, pm, _, _, wgc, _ = control.stability_margins(loop, returnall=True)
    pm, gm = np.asarray(pm)[np.asarray(wgc) > 0], np.asarray(gm)
    assert row.phase_margin_deg == pytest.approx(np.min(np.abs(pm)), abs=0.5)
    if np.any(gm > 1):
        assert row.gain_margin_db == pytest.approx(20 * np.log10(np.min(gm[gm > 1])), abs=0.2)
    if np.any(gm < 1):
        assert row.gain_reduction_margin_db == pytest.approx(20 * np.log10(np.max(gm[gm < 1])), abs=0.2)
    assert bool(row.stable) == bool(np.all(np.abs(control.feedback(loop, 1).poles()) < 1))


def test_plot_is_a_png(run) -> None:
    data = run["png"].read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 20_000


def test_vehicle_alone_takes_its_own_tuning(tmp_path: Path, capsys) -> None:
    """--vehicle without --lag: the lags, lead filter and curvature limits of the vehicle's shipped tuning."""
    out = tmp_path / "m.csv"
    argv = ["margins", "--vehicle", VEHICLE, "--speeds", "60", "--lookahead", "20:30:5", "--out", str(out)]
    assert main(argv) == 0
    table = pd.read_csv(out)
    assert len(table) == 6
    tuning = tuning_for(make_vehicle(VEHICLE))
    measured = getattr(tuning, "measured_lag_at", None)
    lags = PlantLags(tuning.lag_at(60.0), measured(60.0) if measured else None)
    settings = LoopSettings(0.02, 0.2, lead=tuning.filter_schedule.at_speed(60.0))
    v = 60 / 3.6
    arc = min(0.4 * G_MPS2 / v**2, tuning.limits.at_speed(v)[0])
    row = table[(table["lookahead_m"] == 25.0) & (table["path_curvature_1pm"] != 0.0)].iloc[0]
    assert row.path_curvature_1pm == pytest.approx(arc, rel=1e-6)
    expected = loop_margins(lags, settings, v, 25.0, float(row.path_curvature_1pm))
    assert row.phase_margin_deg == pytest.approx(expected.phase_margin_deg, abs=1e-6)
    assert "the tuning of dynamic-bicycle" in capsys.readouterr().out


def test_study_predicts_limit_cycles_where_the_loop_is_unstable() -> None:
    """Short lookaheads on this plant are unstable; with the geometry the table gives the rate limit's cycle, and
    the summary names them."""
    geometry = make_vehicle(VEHICLE).geometry
    study = MarginStudy(lambda _s: LAGS, None, (30.0,), (3.0, 4.0, 8.0), geometry=geometry, arc_lateral_accel_g=0.0)
    result = run_margins(study)
    table = result.table
    assert list(table["path_curvature_1pm"]) == [0.0, 0.0, 0.0]
    assert list(table["stable"]) == [False, False, True]
    assert np.isfinite(table["limit_cycle_hz"][:2]).all() and np.isnan(table["limit_cycle_hz"][2])
    assert 0.5 < table["limit_cycle_hz"][0] < 2.0 and table["limit_cycle_steer_wheel_deg"][0] > 10.0
    assert math.isnan(result.floors[30.0])
    summary = result.summary()
    assert "floor none" in summary and "limit cycle predicted at 3-4 m" in summary


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--lag", "missing.json"], "missing.json"),
        (["--lag", "LAG", "--lead", "nolead.json"], "nolead.json"),
        (["--vehicle", "hovercraft"], "hovercraft"),
        ([], "give --lag"),
        (["--lag", "LAG", "--lookahead", "3:40"], "LOW:HIGH:STEP"),
        (["--lag", "LAG", "--lookahead", "3:x:0.5"], "not numbers"),
        (["--lag", "LAG", "--lookahead", "3:40:0"], "lookahead step"),
        (["--lag", "LAG", "--lookahead", "nan:40:1"], "lowest lookahead"),
        (["--lag", "LAG", "--lookahead", "30:10:1"], "longest lookahead"),
        (["--lag", "LAG", "--speeds", "0,30"], "--speeds"),
        (["--lag", "LAG", "--speeds", "30,nan"], "--speeds"),
        (["--lag", "LAG", "--prediction-time-s", "nan"], "--prediction-time-s"),
        (["--lag", "LAG", "--controller-rate-hz", "0"], "--controller-rate-hz"),
        (["--lag", "LAG", "--arc-lateral-accel-g", "-1"], "--arc-lateral-accel-g"),
        (["--lag", "LAG", "--phase-margin-deg", "inf"], "--phase-margin-deg"),
        (["--lag", "LAG", "--max-lookahead-m", "0"],
         "--max-lookahead-m must be a finite number in [0.5, 200] m; got 0.0"),
        (["--lag", "LAG", "--speeds", "1,2,...,200", "--lookahead", "3:40:0.25"],
         "200 speeds x 149 lookaheads = 29,800 cases to analyse; at most 20,000 (about 20 ms each): fewer speeds"),
    ],
)
def test_bad_input_exits_2_naming_it(files, tmp_path: Path, capsys, extra: list[str], message: str) -> None:
    extra = [str(files["lag"]) if a == "LAG" else str(tmp_path / a) if a.endswith(".json") else a for a in extra]
    argv = ["margins", "--speeds", "30", "--lookahead", "10:12:1", "--out", str(tmp_path / "m.csv"), *extra]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("tuning: error: ") and message in err
    assert err.count("\n") == 1
    assert not (tmp_path / "m.csv").exists()


def test_a_study_is_bounded_in_speeds_x_lookaheads() -> None:
    lookaheads = tuple(0.5 + 0.05 * i for i in range(MAX_LOOKAHEADS))
    speeds = tuple(float(s) for s in range(1, MAX_STUDY_PAIRS // MAX_LOOKAHEADS + 1))
    assert len(MarginStudy(lambda _s: LAGS, None, speeds, lookaheads).speeds_kmh) * MAX_LOOKAHEADS == MAX_STUDY_PAIRS
    with pytest.raises(WorkbenchInputError, match=f"= {MAX_STUDY_PAIRS + MAX_LOOKAHEADS:,} cases to analyse; at most"):
        MarginStudy(lambda _s: LAGS, None, (*speeds, 100.0), lookaheads)


def _floor_study(lookaheads: tuple[float, ...], max_lookahead_m: float | None) -> MarginStudy:
    lead = FilterSchedule((0.0,), (LEAD,))
    return MarginStudy(lambda _s: LAGS, lead, (30.0, 90.0), lookaheads, arc_lateral_accel_g=0.0,
                       max_lookahead_m=max_lookahead_m)  # fmt: skip


def test_a_floor_above_max_lookahead_and_none_are_explained_in_words() -> None:
    result = run_margins(_floor_study((10.0, 20.0, 30.0, 40.0), 15.0))
    assert result.floors[30.0] == 20.0 and math.isnan(result.floors[90.0])  # above 15 m; none in 10-40 m
    summary = result.summary()
    assert (
        "floor above max_lookahead_m (15 m): the clothoid controller would hold its lookahead at 20 m, outside its "
        "range, and its Fréchet search would not act: raise max_lookahead_m to at least 20 m or use a lead filter "
        "with more phase margin"
    ) in summary
    assert (
        "the clothoid controller would hold its lookahead at the top of its floor search, 40 m, without these "
        "margins, and its Fréchet search would not act: use a lead filter with more phase margin"
    ) in summary
    assert "floor above" not in run_margins(_floor_study((10.0, 20.0, 30.0, 40.0), 20.0)).summary()  # 20 m: inside
    assert "clothoid controller" not in run_margins(_floor_study((10.0, 20.0, 30.0, 40.0), None)).summary()


def test_none_below_the_controllers_search_top_asks_for_a_longer_range() -> None:
    summary = run_margins(_floor_study((10.0, 20.0, 30.0), 15.0)).summary()
    assert "floor none (no lookahead in 10-30 m" in summary
    assert "analyse up to 40 m (the top of the clothoid controller's floor search)" in summary
