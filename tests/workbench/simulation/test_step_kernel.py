"""The simulator's compiled per-step work against the Python it replaced: the projection and the checks that end a
run, the speed reference and its slope, and the trace row with the PI speed command, equal to the last bit."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from workbench.base.clothoid_chain import ClothoidChain
from workbench.base.errors import WorkbenchInputError
from workbench.base.path import ReferencePath, wrap_angle
from workbench.base.path_search import PATH_RECORD, PATH_SPEED
from workbench.simulation.speed_control import PI_INTEGRAL, PISpeedController, PISpeedGains
from workbench.simulation.step_kernel import (
    FOOT_AT_END,
    FOOT_S,
    N_SIGNALS,
    PROJECTED_COMPLETED,
    PROJECTED_NOT_FINITE,
    PROJECTED_OFF_PATH,
    PROJECTED_ON_PATH,
    PROJECTED_PAST_END,
    SET_PI,
    SIGNALS,
    compiled_path,
    finish_step,
    project_pose,
    run_settings,
    speed_reference,
)

DT_S = 0.02


def _with_speed(path: ReferencePath) -> ReferencePath:
    """The path carrying a speed that varies along it (a planned profile's ramps, in miniature)."""
    return path.with_speed(6.0 + 2.5 * np.sin(path.s_m / 7.0) + 0.01 * path.s_m)


OPEN = _with_speed(ClothoidChain().straight(20.0).clothoid_to(0.05, 15.0).arc(20.0).to_path("open"))
CLOSED = _with_speed(ClothoidChain(curvature_1pm=1 / 15).arc(2 * math.pi * 15).to_path("loop", closed=True))


def _settings(tracker, limits=(5.0, 30.0, math.inf), feedforward: bool = True) -> np.ndarray:
    """A run's settings: (max_past_end_m, max_abs_cte_m, the distance to cover), the default PI gains."""
    return run_settings(*limits, DT_S, feedforward, PISpeedGains())


def _project(path: ReferencePath, tracker, x: float, y: float, limits=(5.0, 30.0, math.inf)) -> int:
    compiled = compiled_path(tracker)
    return project_pose(x, y, compiled.table, compiled.record, tracker.state, tracker.out, _settings(tracker, limits))


def test_the_tables_hold_the_paths_samples_and_the_runs_settings() -> None:
    """The simulator reads the tracker's compiled path, the one its controllers read (made once per path and
    window), and the run's own constants."""
    tracker = CLOSED.tracker(0.0)
    compiled = compiled_path(tracker)
    assert compiled is CLOSED.compiled() is tracker.compiled
    table = compiled.table
    assert table.shape == (5, CLOSED.s_m.size) and table.flags.c_contiguous
    assert table[PATH_SPEED].tolist() == CLOSED.speed_mps.tolist()
    assert compiled.record.dtype == PATH_RECORD and compiled.record.shape == (1,)
    assert compiled.record[0].tolist() == (
        CLOSED.spacing_m, CLOSED.length_m, True, tracker.extent_m, tracker.min_window_m, CLOSED.max_segment_m
    )
    settings = run_settings(5.0, 30.0, 2 * CLOSED.length_m, DT_S, False, PISpeedGains(kp_per_s=0.5))
    assert settings.tolist() == [5.0, 30.0, 2 * CLOSED.length_m, DT_S, 0.0, 0.5, 0.2, 2.0, 4.0, 0.0]
    with pytest.raises(WorkbenchInputError, match="carries no planned speed"):
        compiled_path(ClothoidChain().straight(10.0).to_path("bare").tracker(0.0))


@settings(max_examples=300, deadline=None)
@given(closed=st.booleans(), where=st.floats(-0.2, 2.5), sample=st.booleans())
def test_the_speed_reference_is_the_paths_speed_and_slope(closed: bool, where: float, sample: bool) -> None:
    path = CLOSED if closed else OPEN
    s = where * path.length_m
    if sample:  # exactly on a sample, where the slope is the segment ahead's
        s = float(path.s_m[min(max(round(s / path.spacing_m), 0), path.s_m.size - 1)])
    v_ref, slope = speed_reference(path.speed_mps, path.spacing_m, path.length_m, path.closed, s)
    assert v_ref == path.speed(s)
    assert slope == path.speed_gradient(s)


@pytest.mark.parametrize("path", [OPEN, CLOSED], ids=["open", "closed"])
def test_the_projection_is_the_trackers_update(path: ReferencePath) -> None:
    """Along a weaving drive (one lap and a half of the loop), the kernel advances a tracker exactly as `update`
    does, and says the run goes on."""
    python, compiled = path.tracker(0.0), path.tracker(0.0)
    s = np.linspace(0.0, path.length_m * (1.5 if path.closed else 0.97), 700)
    x, y = path.position(s)
    for px, py, offset in zip(x.tolist(), y.tolist(), (0.8 * np.sin(s / 5.0)).tolist(), strict=True):
        foot = python.update(px + offset, py - offset)
        assert _project(path, compiled, px + offset, py - offset) == PROJECTED_ON_PATH
        assert compiled.state.tobytes() == python.state.tobytes()
        assert compiled.out.tolist() == [
            foot.s_m, foot.progress_m, foot.x_m, foot.y_m, foot.heading_rad, foot.curvature_1pm, foot.cte_m,
            float(foot.at_end), foot.past_end_m, foot.distance_m,
        ]  # fmt: skip


def test_the_projection_ends_the_run_where_the_simulator_did() -> None:
    """In the simulator's order: past an end by more than max_past_end, further than max_abs_cte, then at the end of
    an open path or the distance asked travelled."""
    path = OPEN
    end_x, end_y = float(path.x_m[-1]), float(path.y_m[-1])
    heading = float(path.heading_rad[-1])
    ahead_x, ahead_y = math.cos(heading), math.sin(heading)
    cases = [
        ((end_x + 6.0 * ahead_x, end_y + 6.0 * ahead_y), (5.0, 30.0, math.inf), PROJECTED_PAST_END),
        ((end_x + 6.0 * ahead_x, end_y + 6.0 * ahead_y), (10.0, 30.0, math.inf), PROJECTED_COMPLETED),
        ((end_x + 6.0 * ahead_x, end_y + 6.0 * ahead_y), (10.0, 5.0, math.inf), PROJECTED_OFF_PATH),
        ((float(path.x_m[100]), float(path.y_m[100]) + 8.0), (5.0, 7.0, math.inf), PROJECTED_OFF_PATH),
        ((float(path.x_m[100]), float(path.y_m[100])), (5.0, 7.0, 9.0), PROJECTED_COMPLETED),
        ((float(path.x_m[100]), float(path.y_m[100])), (5.0, 7.0, 11.0), PROJECTED_ON_PATH),
    ]
    for (x, y), limits, expected in cases:
        tracker = path.tracker(0.0)
        assert _project(path, tracker, x, y, limits) == expected
    tracker = path.tracker(0.0)
    assert _project(path, tracker, end_x + ahead_x, end_y + ahead_y) == PROJECTED_COMPLETED
    assert tracker.out[FOOT_AT_END] == 1.0


@pytest.mark.parametrize(("x", "y"), [(math.nan, 0.0), (1.0, math.inf), (-math.inf, math.nan)])
def test_a_position_not_finite_leaves_the_tracker_as_it_was(x: float, y: float) -> None:
    tracker = OPEN.tracker(0.0)
    _project(OPEN, tracker, 3.0, 0.2)
    state, out = tracker.state.copy(), tracker.out.copy()
    assert _project(OPEN, tracker, x, y) == PROJECTED_NOT_FINITE
    assert tracker.state.tobytes() == state.tobytes() and tracker.out.tobytes() == out.tobytes()


@pytest.mark.parametrize("path", [OPEN, CLOSED], ids=["open", "closed"])
@pytest.mark.parametrize("feedforward", [True, False])
def test_the_row_is_what_the_python_loop_logged(path: ReferencePath, feedforward: bool) -> None:
    """Row by row along a drive: the time, the outputs, the simulator's signals (the speed reference and the
    PI command of the Python controller, the foot point's values, the wrapped heading error) and the diagnostics;
    the columns after them untouched."""
    rng = np.random.default_rng(7)
    n_out, n_diag, n_after = 9, 3, 2
    table = np.full((60, 1 + n_out + N_SIGNALS + n_diag + n_after), np.nan)
    tracker, python_pi = path.tracker(0.0), PISpeedController()
    compiled, settings = compiled_path(tracker), _settings(tracker, feedforward=feedforward)
    s = np.linspace(0.0, 0.9 * path.length_m, table.shape[0])
    for row, (px, py) in enumerate(zip(*path.position(s), strict=True)):
        outputs = rng.normal(size=n_out)
        outputs[2] = rng.uniform(-12.0, 12.0)  # a yaw several turns away from the path's heading
        diagnostics = rng.normal(size=n_diag)
        speed, steer, step_time, t = rng.uniform(0.0, 15.0), rng.normal(), rng.uniform(1e-6, 1e-4), row * DT_S
        foot = tracker.update(px + 0.3, py)
        expected_ref, rate = path.speed(foot.s_m), speed * path.speed_gradient(foot.s_m) if feedforward else 0.0
        expected_accel = python_pi.step(expected_ref, speed, DT_S, rate)
        accel = finish_step(
            table, row, t, outputs, steer, speed, step_time, diagnostics, tracker.out, compiled.table,
            compiled.record, settings,
        )  # fmt: skip
        assert accel == expected_accel
        signals = dict(
            zip(SIGNALS, table[row, 1 + n_out : 1 + n_out + N_SIGNALS].tolist(), strict=True)
        )  # fmt: skip
        assert signals == {
            "steer_wheel_cmd_rad": steer,
            "accel_cmd_mps2": expected_accel,
            "speed_mps": speed,
            "speed_ref_mps": expected_ref,
            "path_s_m": foot.s_m,
            "progress_m": foot.progress_m,
            "cte_m": foot.signed_distance_m,
            "heading_error_rad": float(wrap_angle(outputs[2] - foot.heading_rad)),
            "path_curvature_1pm": foot.curvature_1pm,
            "step_time_s": step_time,
        }
        assert table[row, 0] == t
        assert table[row, 1 : 1 + n_out].tolist() == outputs.tolist()
        assert table[row, 1 + n_out + N_SIGNALS : -n_after].tolist() == diagnostics.tolist()
        assert np.isnan(table[row, -n_after:]).all()
    assert settings[SET_PI + PI_INTEGRAL] == python_pi.integral_m


@pytest.mark.parametrize("speed", [math.nan, math.inf])
def test_a_speed_not_finite_writes_nothing_and_keeps_the_integrator(speed: float) -> None:
    table = np.full((2, 1 + 9 + N_SIGNALS + 2), np.nan)
    tracker = OPEN.tracker(0.0)
    tracker.update(5.0, 0.1)
    settings = _settings(tracker)
    settings[SET_PI + PI_INTEGRAL] = 0.25
    before = settings.copy()
    compiled = compiled_path(tracker)
    accel = finish_step(
        table, 1, 0.02, np.zeros(9), 0.0, speed, 1e-5, np.zeros(2), tracker.out, compiled.table, compiled.record,
        settings,
    )  # fmt: skip
    assert math.isnan(accel)
    assert np.isnan(table).all() and settings.tolist() == before.tolist()
    assert tracker.out[FOOT_S] > 0.0  # the foot point the reference was read at
