"""Metrics on a hand-computable trace."""

from __future__ import annotations

import math

import numpy as np
import pytest

from workbench.clothoid_chain import ClothoidChain
from workbench.metrics import METRIC_KEYS, Metrics, compute_metrics

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
        "rms_cte_m", "max_abs_heading_error_deg", "max_abs_steer_wheel_deg", "max_abs_steer_rate_deg_s",
        "rms_steer_rate_deg_s", "max_abs_lat_accel_g", "max_ltr", "max_offtracking_m", "step_time_median_us",
        "step_time_p99_us",
    )  # fmt: skip


def test_empty_trace_gives_nulls_not_nan() -> None:
    trace = {k: v[:0] for k, v in _straight_trace().items()}
    m = _metrics(trace)
    assert m.distance_m == 0.0
    for key in (
        "max_abs_cte_m",
        "rms_cte_m",
        "max_abs_steer_rate_deg_s",
        "rms_steer_rate_deg_s",
        "step_time_median_us",
    ):
        assert getattr(m, key) is None


def test_rms_steer_rate_of_a_sine() -> None:
    trace = _straight_trace(n=2001, dt=0.01)
    trace["steer_wheel_rad"] = np.radians(30.0) * np.sin(2 * np.pi * 0.5 * trace["t_s"])  # 30 deg at 0.5 Hz
    m = _metrics(trace)
    peak_rate = 30.0 * 2 * np.pi * 0.5  # deg/s
    assert m.max_abs_steer_rate_deg_s == pytest.approx(peak_rate, rel=1e-3)
    assert m.rms_steer_rate_deg_s == pytest.approx(peak_rate / math.sqrt(2), rel=1e-3)
