"""Metrics on a hand-computable trace, the steering oscillation against its analytic value, and a limit cycle found
in a real run."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from workbench.apps.comparison import RunSpec, compare
from workbench.base.clothoid_chain import ClothoidChain
from workbench.base.errors import WorkbenchInputError
from workbench.base.path import ReferencePath
from workbench.simulation.metrics import METRIC_KEYS, Metrics, compute_metrics

G = 9.80665


def _straight_trace(n: int = 101, dt: float = 0.1, speed: float = 5.0) -> dict[str, np.ndarray]:
    t = np.arange(n) * dt
    cte = np.where(np.arange(n) % 2 == 0, 0.3, -0.3)  # RMS 0.3, max 0.3
    cte[50] = -0.5  # max |CTE| 0.5
    steer = np.radians(10.0) * t  # 10 deg/s ramp
    return {
        "t_s": t,
        "x_m": speed * t,
        "y_m": cte.copy(),
        "cte_m": cte,
        "heading_error_rad": np.radians(np.linspace(-2.0, 4.0, n)),
        "steer_wheel_rad": steer,
        "lat_accel_mps2": np.full(n, 0.2 * G),
        "speed_mps": np.full(n, speed),
        "step_time_s": np.arange(1, n + 1) * 1e-6,  # 1..101 us
    }


def _metrics(trace: dict[str, np.ndarray]) -> Metrics:
    path = ClothoidChain().straight(100.0).to_path("straight")
    return compute_metrics(
        trace, path, scenario="s", controller="c", vehicle="v", completed=True, path_length_m=path.length_m
    )


def test_hand_computed_values() -> None:
    trace = _straight_trace()
    m = _metrics(trace)
    assert m.distance_m == pytest.approx(5.0 * 10.0, rel=1e-12)
    assert m.path_length_m == pytest.approx(100.0, rel=1e-12)
    assert m.max_abs_cte_m == pytest.approx(0.5, abs=1e-12)
    expected_rms = math.sqrt((100 * 0.09 + 0.25) / 101)
    assert m.rms_cte_m == pytest.approx(expected_rms, rel=1e-12)
    assert m.max_abs_heading_error_deg == pytest.approx(4.0, rel=1e-9)
    assert m.max_abs_steer_wheel_deg == pytest.approx(100.0, rel=1e-9)
    assert m.max_abs_steer_rate_deg_s == pytest.approx(10.0, rel=1e-9)
    assert m.rms_steer_rate_deg_s == pytest.approx(10.0, rel=1e-9)
    assert m.max_abs_lat_accel_g == pytest.approx(0.2, rel=1e-12)
    assert m.step_time_median_us == pytest.approx(51.0, rel=1e-9)
    assert m.step_time_p99_us == pytest.approx(np.percentile(np.arange(1, 102), 99), rel=1e-9)
    assert m.max_ltr is None and m.max_offtracking_m is None
    assert m.steer_oscillation_deg == pytest.approx(0.0, abs=1e-9)  # a ramp is its own moving average
    assert (m.limit_cycle, m.limit_cycle_hz, m.limit_cycle_amplitude_deg) == (False, None, None)


def test_vehicle_fields_filled_when_the_trace_has_them() -> None:
    trace = _straight_trace()
    trace["ltr"] = np.linspace(-0.2, 0.7, trace["t_s"].size)
    trace["trailer_x_m"] = trace["x_m"] - 10.0 + 20.0  # stays on the 0..100 m straight
    trace["trailer_y_m"] = np.full(trace["t_s"].size, -0.8)
    m = _metrics(trace)
    assert m.max_ltr == pytest.approx(0.7, rel=1e-12)
    assert m.max_offtracking_m == pytest.approx(0.8, abs=1e-9)


def test_keys_are_the_stable_metrics_json_names() -> None:
    assert tuple(_metrics(_straight_trace()).to_dict()) == METRIC_KEYS
    assert METRIC_KEYS == (
        "scenario", "controller", "vehicle", "completed", "distance_m", "path_length_m", "max_abs_cte_m",
        "max_abs_cte_on_path_m", "rms_cte_m", "max_abs_heading_error_deg", "max_abs_steer_wheel_deg",
        "max_abs_steer_rate_deg_s",
        "rms_steer_rate_deg_s", "steer_oscillation_deg", "limit_cycle", "limit_cycle_hz", "limit_cycle_amplitude_deg",
        "max_abs_lat_accel_g", "max_ltr", "max_offtracking_m", "step_time_median_us", "step_time_p99_us",
        "min_track_margin_m", "left_track",
    )  # fmt: skip


def test_max_cte_on_path_leaves_out_the_approach_of_a_run_started_off_the_path() -> None:
    trace = _straight_trace()
    assert _metrics(trace).max_abs_cte_on_path_m == _metrics(trace).max_abs_cte_m == pytest.approx(0.5)
    # started 1 m off: approaching until the first sample within CONVERGED_CTE_M, then an overshoot of 0.25 m
    n = trace["t_s"].size
    cte = np.concatenate([np.linspace(1.0, 0.12, 20), [0.05], -0.25 * np.sin(np.linspace(0.0, np.pi, n - 21))])
    trace["cte_m"] = cte
    m = _metrics(trace)
    assert m.max_abs_cte_m == pytest.approx(1.0)
    assert m.max_abs_cte_on_path_m == pytest.approx(np.max(np.abs(cte[20:])), rel=1e-12)
    assert m.max_abs_cte_on_path_m == pytest.approx(0.25, rel=1e-3)
    # one that never comes within the band is measured whole
    trace["cte_m"] = np.linspace(1.0, 0.5, n)
    assert _metrics(trace).max_abs_cte_on_path_m == pytest.approx(1.0)


def test_empty_trace_gives_nulls_not_nan() -> None:
    trace = {k: v[:0] for k, v in _straight_trace().items()}
    m = _metrics(trace)
    assert m.distance_m == 0.0
    for key in (
        "max_abs_cte_m",
        "max_abs_cte_on_path_m",
        "rms_cte_m",
        "max_abs_steer_rate_deg_s",
        "rms_steer_rate_deg_s",
        "steer_oscillation_deg",
        "limit_cycle_hz",
        "limit_cycle_amplitude_deg",
        "step_time_median_us",
    ):
        assert getattr(m, key) is None
    assert m.limit_cycle is False


def test_rms_steer_rate_of_a_sine() -> None:
    trace = _straight_trace(n=2001, dt=0.01)
    trace["steer_wheel_rad"] = np.radians(30.0) * np.sin(2 * np.pi * 0.5 * trace["t_s"])  # 30 deg at 0.5 Hz
    m = _metrics(trace)
    peak_rate = 30.0 * 2 * np.pi * 0.5  # deg/s
    assert m.max_abs_steer_rate_deg_s == pytest.approx(peak_rate, rel=1e-3)
    assert m.rms_steer_rate_deg_s == pytest.approx(peak_rate / math.sqrt(2), rel=1e-3)


def _sine_trace(freq_hz: float, amp_deg: float, duration_s: float = 60.0, dt: float = 0.02) -> dict[str, np.ndarray]:
    trace = _straight_trace(n=round(duration_s / dt), dt=dt)
    trace["steer_wheel_rad"] = np.radians(amp_deg) * np.sin(2 * np.pi * freq_hz * trace["t_s"])
    return trace


@pytest.mark.parametrize(("freq_hz", "dt"), [(2.0, 0.02), (0.5, 0.02), (1.3, 0.02), (2.0, 0.01)])
def test_steer_oscillation_of_a_sine_is_its_rms_times_the_moving_average_s_residual_gain(
    freq_hz: float, dt: float
) -> None:
    amp = 30.0
    m = _metrics(_sine_trace(freq_hz, amp, dt=dt))
    k = max(3, round(1.0 / dt)) | 1  # the 1 s centred window
    x = math.pi * freq_hz * dt
    boxcar_gain = math.sin(k * x) / (k * math.sin(x))  # the discrete moving average's gain at freq_hz
    assert m.steer_oscillation_deg == pytest.approx(amp / math.sqrt(2) * abs(1.0 - boxcar_gain), rel=0.02)
    assert m.limit_cycle and m.limit_cycle_hz == pytest.approx(freq_hz, rel=0.02)
    assert m.limit_cycle_amplitude_deg == pytest.approx(amp, rel=0.05)


@settings(max_examples=40, deadline=None)
@given(
    offset=st.floats(-10.0, 10.0),
    slope=st.floats(-2.0, 2.0),
    dt=st.sampled_from([0.01, 0.02, 0.05]),
)
def test_a_constant_or_a_ramp_added_to_the_steering_leaves_the_oscillation(
    offset: float, slope: float, dt: float
) -> None:
    trace = _sine_trace(1.3, 20.0, duration_s=20.0, dt=dt)
    trace["steer_wheel_rad"] += np.radians(5.0) * np.sin(2 * np.pi * 0.3 * trace["t_s"])
    plain = _metrics(trace)
    assert plain.steer_oscillation_deg > 10.0
    trace["steer_wheel_rad"] = trace["steer_wheel_rad"] + offset + slope * trace["t_s"]
    shifted = _metrics(trace)
    assert shifted.steer_oscillation_deg == pytest.approx(plain.steer_oscillation_deg, abs=1e-9)
    assert shifted.limit_cycle == plain.limit_cycle


def test_a_nan_steering_angle_is_refused_naming_the_column() -> None:
    trace = _sine_trace(1.0, 30.0)
    trace["steer_wheel_rad"][100] = math.nan
    with pytest.raises(WorkbenchInputError, match="steer_wheel_rad must be finite numbers; entry 100 is nan"):
        _metrics(trace)


def test_a_limit_cycle_is_found_in_a_simulated_run() -> None:
    # Stanley at 8/s on the loaded truck weaves at about 0.8 Hz through the dlc; at its default 1.5/s it does not
    runs = (RunSpec("stanley", "tractor-semitrailer"), RunSpec("stanley", "tractor-semitrailer", ("gain_per_s=8",)))
    quiet, weaving = (r.metrics for r in compare("dlc", runs).results)
    assert not quiet.limit_cycle and quiet.limit_cycle_hz is None
    assert weaving.limit_cycle and 0.5 < weaving.limit_cycle_hz < 1.2 and weaving.limit_cycle_amplitude_deg > 50.0
    assert weaving.steer_oscillation_deg > 2 * quiet.steer_oscillation_deg


def test_offtracking_is_the_signed_sideways_distance_from_the_path() -> None:
    """Beside a straight path along x: the offset is y, left positive; behind its start still sideways only."""
    from workbench.simulation.metrics import offtracking

    path = ClothoidChain().straight(100.0).to_path("straight")
    assert offtracking(path, [10, 20, 30], [1, -2, 0]).tolist() == pytest.approx([1.0, -2.0, 0.0], abs=1e-9)
    assert offtracking(path, np.array([-5.0]), np.array([0.5])) == pytest.approx([0.5], abs=1e-9)


def test_the_run_is_named_as_given() -> None:
    path = ClothoidChain().straight(100.0).to_path("straight")
    m = compute_metrics(
        _straight_trace(), path, scenario="dlc", controller="nmpc", vehicle="truck", completed=False, path_length_m=1.0
    )
    assert (m.scenario, m.controller, m.vehicle, m.completed) == ("dlc", "nmpc", "truck", False)


@pytest.mark.parametrize("n", [1, 2])
def test_one_or_two_samples(n: int) -> None:
    """One sample: no distance, no rate; two: the distance and the one rate between them."""
    m = _metrics({k: v[:n] for k, v in _straight_trace(dt=0.1, speed=5.0).items()})
    assert m.distance_m == pytest.approx(0.5 * (n - 1), abs=1e-12)
    if n == 1:
        assert m.max_abs_steer_rate_deg_s is None and m.rms_steer_rate_deg_s is None
    else:
        assert m.max_abs_steer_rate_deg_s == pytest.approx(10.0, rel=1e-9)
        assert m.rms_steer_rate_deg_s == pytest.approx(10.0, rel=1e-9)


def test_touching_the_track_edge_is_not_leaving_it() -> None:
    """A car 1.6 m wide on the centre line of a track 0.8 m either side: margin 0, on the track."""
    from workbench.simulation.track_margin import VehicleOutline

    plain = ClothoidChain().straight(100.0).to_path("straight")
    n = plain.x_m.size
    path = ReferencePath(
        plain.x_m, plain.y_m, plain.heading_rad, plain.curvature_1pm, plain.spacing_m, plain.closed,
        name="track", width_left_m=np.full(n, 0.8), width_right_m=np.full(n, 0.8),
    )  # fmt: skip
    trace = _straight_trace()
    trace["y_m"] = np.zeros(trace["t_s"].size)
    trace["yaw_rad"] = np.zeros(trace["t_s"].size)
    trace["path_s_m"] = trace["x_m"].copy()
    outline = VehicleOutline(width_m=1.6, front_m=3.4, rear_m=1.1)
    m = compute_metrics(
        trace, path, scenario="s", controller="c", vehicle="v", completed=True, path_length_m=100.0, outline=outline
    )
    assert m.min_track_margin_m == 0.0 and m.left_track is False
    trace["y_m"] = np.full(trace["t_s"].size, 0.01)
    m = compute_metrics(
        trace, path, scenario="s", controller="c", vehicle="v", completed=True, path_length_m=100.0, outline=outline
    )
    assert m.min_track_margin_m == pytest.approx(-0.01, abs=1e-9) and m.left_track is True
